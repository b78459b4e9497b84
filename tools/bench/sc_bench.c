/* sinew-bench --sc-compare (sc_bench.h). */
#include "sc_bench.h"

#include <math.h>
#include <string.h>

#include "bake.h"
#include "blob_load.h"
#include "instance.h"
#include "replay.h"
#include "rt_interpose.h"
#include "tool_common.h"

/* Mode k's sums over its timed steps. */
typedef struct {
    sw_sc_bench *out;
    int k;
    double sc_sum, step_sum;
} sc_sums;

static void sc_step(void *user, int step, int frame, double ms, const sinew_step_stats *st) {
    (void)step, (void)frame, (void)ms;
    sc_sums *m = user;
    sw_sc_bench *out = m->out;
    const int k = m->k;
    m->sc_sum += st->ms_self_contact;
    m->step_sum += sw_step_ms(st);
    out->ms_max[k] = fmax(out->ms_max[k], st->ms_self_contact);
    out->tests_mean[k] += st->self_contact_tests;
    out->pairs_mean[k] += st->self_contacts;
    out->novel_mean[k] += st->self_contact_novel;
    out->apart_mean[k] += st->self_contacts_apart;
}

/* One mode's pass: the figures of its timed steps. */
static sinew_result run_mode(const sinew_blob *blob, sinew_self_contact mode, const double *T,
                             int nframes, float dt, int reps, int count_rt, sw_sc_bench *out,
                             sw_error *err) {
    sinew_instance_def def = sinew_instance_def_default();
    def.self_contact = mode;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    const int k = (int)mode; /* 0 pose-space, 1 exhaustive, 2 pose-pairs */
    if (r != SINEW_OK)
        return sw_error_set(err, r, "cannot create a %s instance: %s", sw_self_contact_names[k],
                            sinew_result_string(r));
    out->ms_mean[k] = out->ms_max[k] = out->tests_mean[k] = out->pairs_mean[k] = 0;
    sc_sums m = {out, k, 0, 0};
    /* an untimed pass first: the instance settles on the clip */
    sw_replay rp = sw_replay_clip(inst, T, nframes, (int)sinew_blob_bone_count(blob), dt);
    rp.warmup = nframes;
    rp.steps = reps * nframes;
    rp.count_rt = count_rt;
    rp.on_step = sc_step;
    rp.user = &m;
    sw_replay_run(&rp);
    out->failed += rp.warmup_failed + rp.failed;
    if (count_rt) sw_rt_counts_report(&rp.counts, &out->allocs[k], &out->locks[k]);
    const int steps = rp.steps;
    out->steps = steps;
    out->ms_mean[k] = m.sc_sum / steps;
    out->step_mean[k] = m.step_sum / steps;
    out->tests_mean[k] /= steps;
    out->pairs_mean[k] /= steps;
    out->novel_mean[k] /= steps;
    out->apart_mean[k] /= steps;
    if (k == 0) out->frame_share = m.step_sum > 0 ? m.sc_sum / m.step_sum : 0;
    if (k == 2) out->pp_frame_share = m.step_sum > 0 ? m.sc_sum / m.step_sum : 0;
    sinew_instance_destroy(inst);
    return SINEW_OK;
}

sinew_result sw_sc_bench_run(const sinew_blob *blob, const double *T, int nframes, float dt,
                             int reps, sw_sc_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    if (!blob || !T || nframes < 1 || reps < 1 || !(dt > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sc bench: bad arguments");
    sinew_result r =
        run_mode(blob, SINEW_SELF_CONTACT_POSE_SPACE, T, nframes, dt, reps, 0, out, err);
    if (r == SINEW_OK)
        r = run_mode(blob, SINEW_SELF_CONTACT_EXHAUSTIVE, T, nframes, dt, reps, 1, out, err);
    if (r != SINEW_OK) return r;
    out->speedup_mean = out->ms_mean[0] > 0 ? out->ms_mean[1] / out->ms_mean[0] : INFINITY;
    out->speedup_max = out->ms_max[0] > 0 ? out->ms_max[1] / out->ms_max[0] : INFINITY;
    out->pairs_mode = sw_blob_get_view(blob)->npair_groups > 0;
    if (!out->pairs_mode) return SINEW_OK;
    r = run_mode(blob, SINEW_SELF_CONTACT_POSE_PAIRS, T, nframes, dt, reps, 1, out, err);
    out->pp_speedup_mean = out->ms_mean[2] > 0 ? out->ms_mean[1] / out->ms_mean[2] : INFINITY;
    out->pp_speedup_max = out->ms_max[2] > 0 ? out->ms_max[1] / out->ms_max[2] : INFINITY;
    return r;
}

void sw_sc_bench_print(const sw_sc_bench *b, FILE *f, int json) {
    if (!json) {
        fprintf(f,
                "sinew-bench: self-contact over %d steps: pose-space %.4f ms mean, %.4f max "
                "(%.1f pairs, %.1f left apart, %.3f of the step); exhaustive %.4f ms mean, "
                "%.4f max (%.0f candidates, %.1f pairs); speedup %.1fx mean, %.1fx max; "
                "exhaustive allocs %ld, locks %ld\n",
                b->steps, b->ms_mean[0], b->ms_max[0], b->tests_mean[0], b->apart_mean[0],
                b->frame_share, b->ms_mean[1], b->ms_max[1], b->tests_mean[1], b->pairs_mean[1],
                b->speedup_mean, b->speedup_max, b->allocs[1], b->locks[1]);
        if (b->pairs_mode)
            fprintf(f,
                    "sinew-bench: pose-pairs %.4f ms mean, %.4f max (%.1f pairs, %.3f of the "
                    "step, %.2f novel pairs of domains); speedup over exhaustive %.1fx mean, "
                    "%.1fx max; allocs %ld, locks %ld\n",
                    b->ms_mean[2], b->ms_max[2], b->tests_mean[2], b->pp_frame_share,
                    b->novel_mean[2], b->pp_speedup_mean, b->pp_speedup_max, b->allocs[2],
                    b->locks[2]);
        return;
    }
    fprintf(f,
            ",\"sc_steps\":%d,\"sc_ms_mean\":%.5f,\"sc_ms_max\":%.5f,\"sc_exh_ms_mean\":%.5f,"
            "\"sc_exh_ms_max\":%.5f,\"sc_speedup_mean\":%.2f,\"sc_speedup_max\":%.2f,"
            "\"sc_frame_share\":%.4f,\"sc_exh_frame_share\":%.4f,\"sc_pairs\":%.1f,"
            "\"sc_exh_pairs\":%.1f,\"sc_exh_contacts\":%.1f,\"sc_step_ms\":%.4f,"
            "\"sc_exh_step_ms\":%.4f,\"sc_exh_allocs_in_step\":%ld,\"sc_exh_locks_in_step\":%ld,"
            "\"sc_apart\":%.2f",
            b->steps, b->ms_mean[0], b->ms_max[0], b->ms_mean[1], b->ms_max[1], b->speedup_mean,
            b->speedup_max, b->frame_share,
            b->step_mean[1] > 0 ? b->ms_mean[1] / b->step_mean[1] : 0, b->tests_mean[0],
            b->tests_mean[1], b->pairs_mean[1], b->step_mean[0], b->step_mean[1], b->allocs[1],
            b->locks[1], b->apart_mean[0]);
    if (b->pairs_mode)
        fprintf(f,
                ",\"sc_pp_ms_mean\":%.5f,\"sc_pp_ms_max\":%.5f,\"sc_pp_speedup_mean\":%.2f,"
                "\"sc_pp_speedup_max\":%.2f,\"sc_pp_frame_share\":%.4f,\"sc_pp_pairs\":%.1f,"
                "\"sc_pp_novel\":%.2f,\"sc_pp_allocs_in_step\":%ld,\"sc_pp_locks_in_step\":%ld",
                b->ms_mean[2], b->ms_max[2], b->pp_speedup_mean, b->pp_speedup_max,
                b->pp_frame_share, b->tests_mean[2], b->novel_mean[2], b->allocs[2], b->locks[2]);
}
