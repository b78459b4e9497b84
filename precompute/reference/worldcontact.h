/* The collision world in the full-space reference (sinew_world.h): every surface vertex
 * against every collider, with the runtime's law (contact/world_penalty.h), so the
 * reference and the step compute the same contact. Candidates are detected once per
 * contact round of the step (fullsim_step.c) and frozen while Newton converges; a
 * round that finds a vertex inside a collider that was not a candidate goes on. */
#ifndef SW_WORLDCONTACT_H
#define SW_WORLDCONTACT_H

#include <stdint.h>

#include "sinew/sinew_world.h"
#include "sw_error.h"
#include "world_penalty.h"

typedef struct sw_ref_world_cand {
    sw_world_pair law;
    int32_t v;    /* the vertex */
    int32_t slot; /* the collider's slot */
} sw_ref_world_cand;

typedef struct sw_ref_world {
    const sinew_world *world;
    double radius;           /* detection radius (world units) */
    double blob_k;           /* stiffness of colliders that have none */
    sw_ref_world_cand *cand; /* the step's candidates */
    int32_t ncand, cap;
    unsigned char *is_cand; /* nv: a vertex with a candidate this round */
} sw_ref_world;

/* Detects the candidates at x (3 per vertex) among the vertices with area[v] > 0 (the
 * surface; the rest area weights the penalty). Returns how many vertices penetrate a
 * collider without having been a candidate of the previous round (0: settled), or -1
 * when memory ran out. */
int32_t sw_ref_world_detect(sw_ref_world *w, int32_t nv, const double *x, const double *area);

/* Energy at x; with f (3 per vertex) adds the contact forces on the vertices (the
 * Hessian blocks are added by the caller per candidate: sw_world_penalty). */
double sw_ref_world_eval(const sw_ref_world *w, const double *x, double *f);

void sw_ref_world_free(sw_ref_world *w);

#endif
