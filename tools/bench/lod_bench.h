/* sinew-bench --lod: every level of detail the blob holds (sinew_lod) on the same clip in
 * one run: per level the median step (pose, step and surface read, each frame's least of
 * `passes` plays after an untimed one) against plain DQS of the same surface timed between
 * them, and the held-out error on the output surface (sw_eval_result.surface_error: the
 * figure every level has) of the bench's held-out poses. */
#ifndef SW_LOD_BENCH_H
#define SW_LOD_BENCH_H

#include <stdio.h>

#include "bake.h"
#include "sinew/sinew.h"
#include "sw_error.h"

#define SW_LOD_BENCH_LEVELS 3

typedef struct sw_lod_bench {
    int levels; /* sinew_blob_lod_count */
    double ms[SW_LOD_BENCH_LEVELS], dqs_ms, cost_vs_dqs[SW_LOD_BENCH_LEVELS];
    double err_heldout[SW_LOD_BENCH_LEVELS]; /* NaN: no held-out frames, or a failed step */
    int err_frames;
    long failed;
} sw_lod_bench;

/* Times the levels over the clip's nframes at dt and measures them on res's held-out path
 * (sw_bake_heldout_level_error). */
sinew_result sw_lod_bench_run(const sinew_blob *blob, const sw_clip *clip, int nframes, float dt,
                              int passes, const sw_bake_result *res, sw_lod_bench *out,
                              sw_error *err);

/* The figures for people (json 0) or as JSON members each preceded by a comma: lod_levels,
 * lod_ms, lod_cost_vs_dqs, lod_err_heldout (arrays in sinew_lod's order; null for a level
 * the blob lacks), lod_dqs_ms, lod_err_frames. */
void sw_lod_bench_print(const sw_lod_bench *b, FILE *f, int json);

#endif
