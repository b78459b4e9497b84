/* sinew-bench --world: the reference and the runtime with the same world, mesh and
 * motion, and the figures the collision-world issue asks of them. */
#ifndef SW_WORLD_BENCH_H
#define SW_WORLD_BENCH_H

#include "cond_bench.h"
#include "fullsim.h"
#include "sinew/sinew.h"
#include "world_scene.h"

typedef struct sw_world_bench {
    int frames;
    int world_contact_frames; /* frames where the reference touches a collider */
    double err_world_sub;     /* correction error over those frames, subspace vs reference */
    double pen_world_full;    /* deepest penetration into a collider, reference (world units) */
    double pen_world_sub;     /* the same for the runtime's output surface */
    double world_query_ms;    /* median ms_world of a step */
    double world_queries;     /* mean collider queries a step */
    double world_contacts;    /* mean vertex copies in contact a step (runtime) */
    double full_ms, sub_ms;   /* median ms a frame with the world */
    int ref_unsettled, ref_failed, sub_failed;
    long allocs, locks; /* in contract_steps steps with world contact; -1: not observable */
    int contract_steps;
    sw_cond_bench cond[SW_COND_MAX_RHO]; /* the condensed runs, one a radius */
    int ncond;
} sw_world_bench;

/* Runs the scene `ws` on the character (its clip or rest pose, as the file says; at
 * most `frames` frames when > 0): the reference with params fp, then a quasistatic
 * instance of `blob`, then `contract_steps` counted steps over the same motion; then,
 * with cp and a blob that has the tet mesh, a condensed instance (cond_bench.h). */
sinew_result sw_world_bench_run(const sw_character *ch, const sinew_blob *blob, sw_world_scene *ws,
                                const sw_fullsim_params *fp, int frames, int contract_steps,
                                const sw_cond_bench_params *cp, sw_world_bench *out, sw_error *err);

#endif
