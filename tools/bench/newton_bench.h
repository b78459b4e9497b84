/* sinew-bench --newton-compare: the quasistatic step with Newton on the current Hessian
 * and starting on the rest Hessian (sinew_instance_def.newton_hessian), on the same blob
 * and clip in one run: an instance of each steps every clip frame, `reps` passes after
 * one untimed pass, and gives
 *   step_ms      the median step (skin to output, sinew_step_stats' phases)
 *   evals        cubature passes a step (potential_evals)
 *   factors      factorisations a step
 *   rest         updates on the rest Hessian a step (rest_updates)
 * for each ([0] current, [1] rest-first), and
 *   speedup      step_ms[0] / step_ms[1]
 *   surface_gap  the largest distance between the two instances' output surfaces over
 *                the clip, over the rest bounding-box diagonal (the same stationary
 *                points, reached by other paths: within the step's 5% last update)
 *   auto_rest    1 when SINEW_NEWTON_HESSIAN_AUTO chose the rest Hessian for this blob
 * plus the allocations and locks the interposer counted in the rest-first steps (-1 when
 * this build cannot observe them). */
#ifndef SW_NEWTON_BENCH_H
#define SW_NEWTON_BENCH_H

#include <stdio.h>

#include "sinew/sinew.h"
#include "sw_error.h"

typedef struct sw_newton_bench {
    int steps; /* timed steps of each mode */
    double step_ms[2], evals[2], factors[2], rest[2];
    double speedup, surface_gap;
    int auto_rest;
    long failed;        /* steps that did not return SINEW_OK (both modes) */
    long allocs, locks; /* in the rest-first timed steps */
} sw_newton_bench;

/* Runs both over the clip's nframes poses T (12 doubles a bone each) at dt. */
sinew_result sw_newton_bench_run(const sinew_blob *blob, const double *T, int nframes, float dt,
                                 int reps, sw_newton_bench *out, sw_error *err);

/* The figures as a line for people (json 0) or as JSON members, each preceded by a
 * comma: newton_steps, newton_step_ms_current, newton_step_ms_rest_first,
 * newton_rest_first_speedup, newton_evals_current, newton_evals_rest_first,
 * newton_factors_current, newton_factors_rest_first, newton_rest_updates,
 * newton_surface_gap, newton_auto_rest, newton_rest_allocs_in_step,
 * newton_rest_locks_in_step. */
void sw_newton_bench_print(const sw_newton_bench *b, FILE *f, int json);

#endif
