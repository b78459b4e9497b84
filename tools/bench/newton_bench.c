/* sinew-bench --newton-compare (newton_bench.h). */
#include "newton_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bbox.h"
#include "blob_load.h"
#include "instance.h"
#include "replay.h"
#include "rt_interpose.h"
#include "tool_common.h"

/* Mode k's sums over its timed steps. */
typedef struct {
    sw_newton_bench *out;
    int k, nframes, reps;
    sinew_instance *inst;
    uint32_t ns;
    float *surf;
    double *ms;
} newton_sums;

static void newton_step(void *user, int step, int frame, double ms, const sinew_step_stats *st) {
    (void)ms;
    newton_sums *m = user;
    m->ms[step] = sw_step_ms(st);
    m->out->evals[m->k] += st->potential_evals;
    m->out->factors[m->k] += st->factorizations;
    m->out->rest[m->k] += st->rest_updates;
    if (step / m->nframes == m->reps - 1)
        sinew_instance_read_surface(m->inst, m->surf + (size_t)frame * 3 * m->ns, NULL, m->ns);
}

/* Mode k's instance (0 current, 1 rest-first) over the clip: the timed steps' figures,
 * and each frame's output surface of the last pass in surf (3 ns floats a frame). */
static sinew_result run_mode(const sinew_blob *blob, int k, const double *T, int nframes, float dt,
                             int reps, float *surf, double *ms, sw_newton_bench *out,
                             sw_error *err) {
    sinew_instance_def def = sinew_instance_def_default();
    def.newton_hessian = k ? SINEW_NEWTON_HESSIAN_REST_FIRST : SINEW_NEWTON_HESSIAN_CURRENT;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    if (r != SINEW_OK)
        return sw_error_set(err, r, "cannot create a %s instance: %s",
                            k ? "rest-first" : "current-Hessian", sinew_result_string(r));
    newton_sums m = {out, k, nframes, reps, inst, sinew_blob_surface_vertex_count(blob), surf, ms};
    /* an untimed pass first */
    sw_replay rp = sw_replay_clip(inst, T, nframes, (int)sinew_blob_bone_count(blob), dt);
    rp.warmup = nframes;
    rp.steps = reps * nframes;
    rp.count_rt = k;
    rp.on_step = newton_step;
    rp.user = &m;
    sw_replay_run(&rp);
    out->failed += rp.warmup_failed + rp.failed;
    if (k) sw_rt_counts_report(&rp.counts, &out->allocs, &out->locks);
    const int steps = rp.steps;
    out->steps = steps;
    out->step_ms[k] = sw_median(ms, steps);
    out->evals[k] /= steps;
    out->factors[k] /= steps;
    out->rest[k] /= steps;
    if (k) {
        def.newton_hessian = SINEW_NEWTON_HESSIAN_AUTO;
        sinew_instance *a;
        if (sinew_instance_create(blob, &def, &a) == SINEW_OK) {
            sw_instance_set_pose_d(a, T);
            sinew_instance_step(a, dt);
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(a, &st);
            out->auto_rest = st.rest_updates > 0;
            sinew_instance_destroy(a);
        }
    }
    sinew_instance_destroy(inst);
    return SINEW_OK;
}

sinew_result sw_newton_bench_run(const sinew_blob *blob, const double *T, int nframes, float dt,
                                 int reps, sw_newton_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    if (!blob || !T || nframes < 1 || reps < 1 || !(dt > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "newton bench: bad arguments");
    size_t ns = sinew_blob_surface_vertex_count(blob), n = (size_t)nframes * 3 * ns;
    float *surf = malloc(2 * n * sizeof(float));
    double *ms = malloc((size_t)nframes * (size_t)reps * sizeof(double));
    if (!surf || !ms) {
        free(surf);
        free(ms);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "newton bench: out of memory");
    }
    sinew_result r = run_mode(blob, 0, T, nframes, dt, reps, surf, ms, out, err);
    if (r == SINEW_OK) r = run_mode(blob, 1, T, nframes, dt, reps, surf + n, ms, out, err);
    if (r == SINEW_OK) {
        out->speedup = out->step_ms[1] > 0 ? out->step_ms[0] / out->step_ms[1] : INFINITY;
        double gap = 0;
        for (size_t i = 0; i < n; i += 3) {
            double d2 = 0;
            for (int c = 0; c < 3; ++c)
                d2 += (double)(surf[i + c] - surf[n + i + c]) * (surf[i + c] - surf[n + i + c]);
            gap = fmax(gap, sqrt(d2));
        }
        const sw_blob_view *v = sw_blob_get_view(blob);
        double lo[3], hi[3];
        sw_bbox_empty(lo, hi);
        sw_bbox_add(lo, hi, v->nverts, v->rest);
        double size = sw_bbox_diagonal(lo, hi);
        out->surface_gap = size > 0 ? gap / size : gap;
    }
    free(surf);
    free(ms);
    return r;
}

void sw_newton_bench_print(const sw_newton_bench *b, FILE *f, int json) {
    if (!json) {
        fprintf(f,
                "sinew-bench: Newton over %d steps: current Hessian %.4f ms a step (%.2f "
                "passes, %.2f factorisations), rest-first %.4f ms (%.2f passes, %.2f "
                "factorisations, %.2f rest updates): %.2fx; surfaces apart by %.2e of the size "
                "at most; auto chooses the %s Hessian; rest-first allocs %ld, locks %ld\n",
                b->steps, b->step_ms[0], b->evals[0], b->factors[0], b->step_ms[1], b->evals[1],
                b->factors[1], b->rest[1], b->speedup, b->surface_gap,
                b->auto_rest ? "rest" : "current", b->allocs, b->locks);
        return;
    }
    fprintf(f,
            ",\"newton_steps\":%d,\"newton_step_ms_current\":%.5f,"
            "\"newton_step_ms_rest_first\":%.5f,\"newton_rest_first_speedup\":%.3f,"
            "\"newton_evals_current\":%.3f,\"newton_evals_rest_first\":%.3f,"
            "\"newton_factors_current\":%.3f,\"newton_factors_rest_first\":%.3f,"
            "\"newton_rest_updates\":%.3f,\"newton_surface_gap\":%.3e,\"newton_auto_rest\":%d,"
            "\"newton_rest_allocs_in_step\":%ld,\"newton_rest_locks_in_step\":%ld",
            b->steps, b->step_ms[0], b->step_ms[1], b->speedup, b->evals[0], b->evals[1],
            b->factors[0], b->factors[1], b->rest[1], b->surface_gap, b->auto_rest, b->allocs,
            b->locks);
}
