/* Self-contact detection of thesis §3.3.1 ("Collision Resolution", DESIGN.md §8), the
 * one rule the full-space reference (precompute/reference/selfcontact.c) and the step's
 * exhaustive self-contact mode (self_contact.h) share, so the runtime detects the very
 * pairs the reference would at the same positions.
 *
 * A surface vertex p that lies in a deformed tet not incident to it has entered the
 * flesh. Its rest position, interpolated with that tet's barycentrics, is projected to
 * the closest point of the rest surface (a static BVH over the rest triangles) and mapped
 * back to the deformed surface: v_s = sum beta_i x_{t_i}. Pairs whose rest-space distance
 * (p to the triangle) is below `neighbour_factor` times the triangle's longest rest edge
 * are p's own neighbourhood folding, not contacts. Of several tets, the deepest rest
 * point wins (ties: the lowest tet id). */
#ifndef SW_SELF_DETECT_H
#define SW_SELF_DETECT_H

#include <stdint.h>

#include "bvh.h"

/* A vertex counts as inside a tet when all its barycentrics are >= -this. */
#define SW_SELF_BARY_TOL 1e-12
/* Rest depths below this fraction of the triangle's longest edge are touching, not
 * penetration: a vertex lying on the other surface up to round-off has no normal. */
#define SW_SELF_TOUCH_TOL 1e-10
/* DESIGN.md §8's neighbour rule: ~1.8 longest rest edges. */
#define SW_SELF_NEIGHBOUR_FACTOR 1.8

typedef struct sw_contact {
    int32_t p;      /* penetrating vertex (tet-mesh vertex id) */
    int32_t tri[3]; /* tet-mesh vertex ids of the surface triangle */
    double beta[3]; /* barycentrics of the contact point on that triangle */
    double ka;      /* area weight k_a (rest units^2) */
    double n[3];    /* unit normal (v_s - v_p) / |v_s - v_p| at detection */
    double depth;   /* |v_s - v_p| at detection (world units) */
} sw_contact;

/* The rest mesh a detection reads. The arrays belong to the owner (the reference's
 * mallocs, an instance's block); tet_bvh's boxes are refit to the positions of each
 * detection, the rest stay as built. */
typedef struct sw_self_mesh {
    int32_t nverts, ntets, ntris, nsurf;
    const double *X;     /* 3 nverts rest positions */
    const int32_t *tets; /* 4 ntets */
    const int32_t *tris; /* 3 ntris surface triangles (vertex ids) */
    const int32_t *surf; /* nsurf surface vertex ids, ascending */
    double *ring;        /* nsurf: rest area of the surface triangles around the vertex */
    double *tri_area;    /* ntris rest areas */
    double *tri_edge;    /* ntris longest rest edges */
    double rest_diag;    /* rest bounding-box diagonal: finite radius of the rest query */
    double neighbour_factor;
    sw_bvh tri_bvh; /* static: rest surface triangles */
    sw_bvh tet_bvh; /* topology from the rest pose, refit per detection */
} sw_self_mesh;

/* Fills ring, tri_area, tri_edge and rest_diag from X, tris and surf (ka of eq. 3.4 needs
 * the one-ring area of the vertex and the area of the triangle; the neighbour rule the
 * longest edge). */
void sw_self_mesh_measures(sw_self_mesh *m);

/* The contact of surface vertex surf[si] at positions x (3 nverts; tet_bvh refit to them),
 * into c; 0 when it has none. With `tested`, the number of candidate tets (those whose box
 * holds the vertex) is written there. Allocation-free and read-only: threads may query one
 * mesh at once. */
int sw_self_detect_vertex(const sw_self_mesh *m, const double *x, int32_t si, sw_contact *c,
                          int32_t *tested);

/* A vertex's chosen tet and rest triangle, before its contact is made. */
typedef struct sw_self_hit {
    int32_t si;  /* the vertex's index in surf */
    int32_t tet; /* the tet it entered */
    double rest_depth;
    sw_bvh_closest hit; /* its rest point's closest rest-surface triangle */
} sw_self_hit;

/* The rule of sw_self_detect_vertex over the candidate tets tets[0..n) instead of
 * tet_bvh's query (the pose-pairs mode's test of a cubature vertex against the flesh
 * around its trained triangle, thesis §3.3.1): x must hold the vertex and the candidates'
 * corners. 0 when the vertex is in none of them. The contact is then made by
 * sw_self_detect_finish, once x also holds the corners of sw_self_hit_triangle. */
int sw_self_detect_among(const sw_self_mesh *m, const double *x, int32_t si, const int32_t *tets,
                         int32_t n, sw_self_hit *hit);
const int32_t *sw_self_hit_triangle(const sw_self_mesh *m, const sw_self_hit *hit);
void sw_self_detect_finish(const sw_self_mesh *m, const double *x, const sw_self_hit *hit,
                           sw_contact *c);

#endif
