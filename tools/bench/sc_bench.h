/* sinew-bench --sc-compare: self-contact in the modes of the runtime, on the same blob
 * and clip in one run (issue 16, thesis Table 3.2): a pose-space instance, an exhaustive
 * one and, when the blob has per-pair sections, a pose-pairs one
 * (sinew_instance_def.self_contact) each step every clip frame, `reps` passes over the
 * clip after one untimed pass, and the step's own figures give
 *   ms_mean, ms_max      self-contact ms a step (sinew_step_stats.ms_self_contact)
 *   step_mean            the whole step's ms
 *   tests_mean           candidates tested a step (self_contact_tests: the pose-space
 *                        pairs in use, or the exhaustive (vertex, tet) candidates)
 *   pairs_mean           pairs in the solve a step (self_contacts)
 *   novel_mean           pairs of domains with novel contact a step (pose-pairs)
 *   apart_mean           pose-space pairs left out a step as come apart (pose_contact.h)
 * for each mode ([0] pose-space, [1] exhaustive, [2] pose-pairs), and
 *   speedup_mean = ms_mean[1] / ms_mean[0], speedup_max = ms_max[1] / ms_max[0],
 *   frame_share = the pose-space mode's self-contact time over its steps' time,
 * the same three for pose-pairs against exhaustive (pp_*), plus the allocations and locks
 * the interposer counted in the exhaustive and the pose-pairs steps (-1 when this build
 * cannot observe them). */
#ifndef SW_SC_BENCH_H
#define SW_SC_BENCH_H

#include <stdio.h>

#include "sinew/sinew.h"
#include "sw_error.h"

typedef struct sw_sc_bench {
    int steps; /* timed steps of each mode */
    double ms_mean[3], ms_max[3], step_mean[3], tests_mean[3], pairs_mean[3], novel_mean[3],
        apart_mean[3];
    double speedup_mean, speedup_max, frame_share;
    int pairs_mode; /* the blob has per-pair sections: [2] and pp_* were measured */
    double pp_speedup_mean, pp_speedup_max, pp_frame_share;
    long failed;              /* steps that did not return SINEW_OK (every mode) */
    long allocs[3], locks[3]; /* in the exhaustive [1] and pose-pairs [2] timed steps */
} sw_sc_bench;

/* Runs the modes over the clip's nframes poses T (12 doubles a bone each) at dt. */
sinew_result sw_sc_bench_run(const sinew_blob *blob, const double *T, int nframes, float dt,
                             int reps, sw_sc_bench *out, sw_error *err);

/* The figures as a line for people (json 0) or as JSON members, each preceded by a
 * comma, for sinew-bench's object: sc_steps, sc_ms_mean, sc_ms_max, sc_exh_ms_mean,
 * sc_exh_ms_max, sc_speedup_mean, sc_speedup_max, sc_frame_share, sc_exh_frame_share,
 * sc_pairs (pose-space pairs tested), sc_exh_pairs (exhaustive candidates tested),
 * sc_exh_contacts, sc_step_ms, sc_exh_step_ms, sc_exh_allocs_in_step,
 * sc_exh_locks_in_step, sc_apart (pose-space pairs left out as come apart); with a
 * pose-pairs pass sc_pp_ms_mean, sc_pp_ms_max, sc_pp_speedup_mean, sc_pp_speedup_max,
 * sc_pp_frame_share, sc_pp_pairs, sc_pp_novel, sc_pp_allocs_in_step, sc_pp_locks_in_step. */
void sw_sc_bench_print(const sw_sc_bench *b, FILE *f, int json);

#endif
