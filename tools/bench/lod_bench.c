/* sinew-bench --lod (lod_bench.h). */
#include "lod_bench.h"

#include <math.h>
#include <stdlib.h>

#include "bake_eval.h"
#include "blob_load.h"
#include "dqs_bench.h"
#include "replay.h"
#include "tool_common.h"

typedef struct level_times {
    double *ms; /* per clip frame, the least over the plays */
    int nf;
} level_times;

static void on_step(void *user, int step, int frame, double ms, const sinew_step_stats *st) {
    (void)st;
    level_times *t = user;
    t->ms[frame] = step < t->nf || ms < t->ms[frame] ? ms : t->ms[frame];
}

/* The median step of level l over the clip. */
static sinew_result time_level(const sinew_blob *blob, const sw_clip *clip, int nf, float dt,
                               int passes, sinew_lod l, double *ms, long *failed) {
    sinew_instance *inst = NULL;
    uint32_t ns = sinew_blob_surface_vertex_count(blob);
    float *pos = malloc(sizeof(float) * 3 * ns), *nrm = malloc(sizeof(float) * 3 * ns);
    level_times t = {malloc(sizeof(double) * (size_t)nf), nf};
    sinew_result r = !pos || !nrm || !t.ms ? SINEW_ERROR_OUT_OF_MEMORY
                                           : sinew_instance_create(blob, NULL, &inst);
    if (r == SINEW_OK) r = sinew_instance_set_lod(inst, l);
    if (r == SINEW_OK) {
        sw_replay rp = sw_replay_clip(inst, clip->T, nf, clip->nbones, dt);
        rp.warmup = nf;
        rp.steps = passes * nf;
        rp.pos = pos;
        rp.nrm = nrm;
        rp.ns = ns;
        rp.on_step = on_step;
        rp.user = &t;
        sw_replay_run(&rp);
        *failed += rp.failed + rp.warmup_failed;
        *ms = sw_median(t.ms, nf);
    }
    sinew_instance_destroy(inst);
    free(pos), free(nrm), free(t.ms);
    return r;
}

sinew_result sw_lod_bench_run(const sinew_blob *blob, const sw_clip *clip, int nframes, float dt,
                              int passes, const sw_bake_result *res, sw_lod_bench *out,
                              sw_error *err) {
    *out = (sw_lod_bench){.levels = (int)sinew_blob_lod_count(blob)};
    for (int l = 0; l < SW_LOD_BENCH_LEVELS; ++l)
        out->ms[l] = out->cost_vs_dqs[l] = out->err_heldout[l] = NAN;
    if (passes < 1) passes = 1;
    out->dqs_ms = sw_dqs_bench_ms(sw_blob_get_view(blob), clip, nframes, passes);
    for (int l = 0; l < out->levels; ++l) {
        sinew_result r =
            time_level(blob, clip, nframes, dt, passes, (sinew_lod)l, &out->ms[l], &out->failed);
        if (r != SINEW_OK) return sw_error_set(err, r, "level %d: %s", l, sinew_result_string(r));
        out->cost_vs_dqs[l] = out->ms[l] / out->dqs_ms;
        if (!res || res->nheldout == 0) continue;
        sw_eval_result e;
        if ((r = sw_bake_heldout_level_error(blob, res, (sinew_lod)l, &e, err)) != SINEW_OK)
            return r;
        out->failed += e.failed;
        out->err_frames = e.frames;
        if (e.failed == 0 && e.frames > 0 && !e.no_correction)
            out->err_heldout[l] = e.surface_error;
    }
    return SINEW_OK;
}

/* x as JSON: null when not finite. */
static void json_number(FILE *f, double x) {
    if (isfinite(x))
        fprintf(f, "%.5g", x);
    else
        fprintf(f, "null");
}

static void json_array(FILE *f, const char *key, const double *a) {
    fprintf(f, ",\"%s\":[", key);
    for (int l = 0; l < SW_LOD_BENCH_LEVELS; ++l) {
        if (l) fprintf(f, ",");
        json_number(f, a[l]);
    }
    fprintf(f, "]");
}

void sw_lod_bench_print(const sw_lod_bench *b, FILE *f, int json) {
    static const char *const names[SW_LOD_BENCH_LEVELS] = {"full", "reduced", "pose-space"};
    if (json) {
        fprintf(f, ",\"lod_levels\":%d,\"lod_dqs_ms\":%.5f,\"lod_err_frames\":%d", b->levels,
                b->dqs_ms, b->err_frames);
        json_array(f, "lod_ms", b->ms);
        json_array(f, "lod_cost_vs_dqs", b->cost_vs_dqs);
        json_array(f, "lod_err_heldout", b->err_heldout);
        return;
    }
    fprintf(f, "sinew-bench: levels of detail (DQS %.4f ms a frame):", b->dqs_ms);
    for (int l = 0; l < b->levels; ++l)
        fprintf(f, " %s %.4f ms (%.2fx DQS, held-out surface error %.4f)%s", names[l], b->ms[l],
                b->cost_vs_dqs[l], b->err_heldout[l], l + 1 < b->levels ? ";" : "\n");
}
