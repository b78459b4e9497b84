#include "bench_mode.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- --instances N: a crowd on host threads ---- */

static int crowd_wanted(const sw_bench_ctx *c) {
    return c->instances > 0;
}

static sinew_result crowd_run(sw_bench_ctx *c, sw_error *err) {
    sw_crowd_bench *cb = &c->cb;
    sinew_result r = sw_crowd_bench_run(c->ch, c->blob, c->instances, c->threads,
                                        c->lod == SW_BENCH_LOD_AUTO, cb, err);
    if (r != SINEW_OK) return r;
    c->failed += cb->failed;
    fprintf(stderr,
            "sinew-bench: crowd of %d instances on %d threads (%d frames after %d warm-up): "
            "%.3f ms a frame (%.1f us an instance), 1 thread %.3f ms, scaling %.2fx; lone "
            "instance %.4f ms, crowd/lone %.2f\n",
            cb->instances, cb->threads, cb->frames, cb->warmup_frames, cb->ms, cb->us_per_instance,
            cb->ms_1thread, cb->scaling, cb->lone_ms, cb->vs_lone);
    if (cb->lod_auto)
        fprintf(stderr,
                "sinew-bench: crowd levels by distance: %.1f full, %.1f reduced, %.1f "
                "pose-space instances a frame\n",
                cb->at_level[0], cb->at_level[1], cb->at_level[2]);
    fprintf(stderr,
            "sinew-bench: crowd memory: %zu bytes an instance without scratch, %zu a thread's "
            "workspace, %.1f MB in all\n",
            cb->instance_bytes, cb->workspace_bytes, cb->crowd_bytes / 1e6);
    return SINEW_OK;
}

static void crowd_json(const sw_bench_ctx *c) {
    const sw_crowd_bench *cb = &c->cb;
    printf(",\"crowd_instances\":%d,\"crowd_threads\":%d,\"crowd_frames\":%d,"
           "\"crowd_ms\":%.4f,\"crowd_us_per_instance\":%.3f,\"crowd_scaling\":%.3f,"
           "\"crowd_vs_lone\":%.3f,\"crowd_ms_1thread\":%.4f,\"crowd_lone_ms\":%.4f,"
           "\"crowd_lone_median_ms\":%.4f,\"crowd_instance_bytes\":%zu,"
           "\"crowd_workspace_bytes\":%zu,\"crowd_bytes\":%.0f",
           cb->instances, cb->threads, cb->frames, cb->ms, cb->us_per_instance, cb->scaling,
           cb->vs_lone, cb->ms_1thread, cb->lone_ms, cb->lone_median_ms, cb->instance_bytes,
           cb->workspace_bytes, cb->crowd_bytes);
    if (cb->lod_auto)
        printf(",\"crowd_lod\":\"auto\",\"crowd_at_level\":[%.2f,%.2f,%.2f]", cb->at_level[0],
               cb->at_level[1], cb->at_level[2]);
}

/* ---- --sc-compare: self-contact, pose-space against exhaustive ---- */

static float clip_dt(const sw_bench_ctx *c) {
    return 1.0f / (float)(c->ch->clip.fps > 0 ? c->ch->clip.fps : 30);
}

static int sc_wanted(const sw_bench_ctx *c) {
    return c->sc_compare;
}

static sinew_result sc_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r = sw_sc_bench_run(c->blob, c->ch->clip.T, c->nf, clip_dt(c), 3, &c->scb, err);
    if (r != SINEW_OK) return r;
    c->failed += c->scb.failed;
    sw_sc_bench_print(&c->scb, stderr, 0);
    return SINEW_OK;
}

static void sc_json(const sw_bench_ctx *c) {
    sw_sc_bench_print(&c->scb, stdout, 1);
}

/* ---- --novel: self-contact nobody trained, with and without patches ---- */

static int novel_wanted(const sw_bench_ctx *c) {
    return c->novel;
}

static sinew_result novel_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r =
        sw_novel_bench_run(c->blob, c->ch, c->ch->clip.T, c->full_x, c->kf, &c->nvb, err);
    if (r != SINEW_OK) return r;
    c->failed += c->nvb.failed;
    sw_novel_bench_print(&c->nvb, stderr, 0);
    return SINEW_OK;
}

static void novel_json(const sw_bench_ctx *c) {
    sw_novel_bench_print(&c->nvb, stdout, 1);
}

/* ---- --pair: two copies pressed together, against the two-body reference ---- */

static int pair_wanted(const sw_bench_ctx *c) {
    return c->pair;
}

static sinew_result pair_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r = sw_pair_bench_run(c->blob, c->ch, c->ch->clip.T, c->nf, c->fp, &c->pb, err);
    if (r != SINEW_OK) return r;
    c->failed += c->pb.sub_failed;
    sw_pair_bench_print(&c->pb, stderr, 0);
    return SINEW_OK;
}

static void pair_json(const sw_bench_ctx *c) {
    sw_pair_bench_print(&c->pb, stdout, 1);
}

/* ---- --newton-compare: Newton on the current and on the rest Hessian ---- */

static int newton_wanted(const sw_bench_ctx *c) {
    return c->newton_compare;
}

static sinew_result newton_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r =
        sw_newton_bench_run(c->blob, c->ch->clip.T, c->nf, clip_dt(c), 3, &c->nwb, err);
    if (r != SINEW_OK) return r;
    c->failed += c->nwb.failed;
    sw_newton_bench_print(&c->nwb, stderr, 0);
    return SINEW_OK;
}

static void newton_json(const sw_bench_ctx *c) {
    sw_newton_bench_print(&c->nwb, stdout, 1);
}

/* ---- --error-gap: the runtime against its basis's projection ---- */

static int gap_wanted(const sw_bench_ctx *c) {
    return c->error_gap;
}

static sinew_result gap_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r = sw_gap_bench_run(c->blob, c->res, c->self_mode, &c->gap, err);
    if (r == SINEW_OK) sw_gap_bench_print(&c->gap, stderr, 0);
    return r;
}

static void gap_json(const sw_bench_ctx *c) {
    sw_gap_bench_print(&c->gap, stdout, 1);
}

/* ---- --world FILE: reference and runtime against a world file ---- */

static int world_wanted(const sw_bench_ctx *c) {
    return c->world_path != NULL;
}

static void cond_print(const sw_world_bench *wb) {
    for (int k = 0; k < wb->ncond; ++k) {
        const sw_cond_bench *cb = &wb->cond[k];
        fprintf(stderr,
                "sinew-bench: condensed (rho %.4g of the diagonal, budget %u): err_world_cond "
                "%.4f (subspace %.4f); speedup mean %.1f worst %.1f; patch %.2f%% mean, "
                "%.2f%% max; frame p100/p50 %.2f; %d frames truncated; pop %.2f; frames with a "
                "patch %.1f ms at %.0f vertices, %.0f tets (means)\n",
                cb->rho, cb->budget, cb->err_world_cond, wb->err_world_sub, cb->speedup_mean,
                cb->speedup_worst, 100 * cb->patch_frac_mean, 100 * cb->patch_frac_max,
                cb->p100_over_p50, cb->truncated_frames, cb->pop_max, cb->patch_ms_mean,
                cb->patch_verts_mean, cb->patch_tets_mean);
    }
}

static sinew_result world_run(sw_bench_ctx *c, sw_error *err) {
    sw_world_scene ws;
    sw_world_bench *wb = &c->wb;
    sinew_result r = sw_world_scene_load(c->world_path, &ws, err);
    if (r != SINEW_OK) return r;
    r = sw_world_bench_run(c->ch, c->blob, &ws, c->fp, c->clip_frames, c->contract_steps, c->cond,
                           wb, err);
    sw_world_scene_free(&ws);
    if (r != SINEW_OK) return r;
    c->failed += wb->sub_failed + wb->ref_failed;
    fprintf(stderr,
            "sinew-bench: world %s: %d frames, %d with contact; err_world_sub %.4f; "
            "penetration full %.5f sub %.5f; world query %.4f ms, %.0f queries, %.1f "
            "contacts a step; allocs %ld, locks %ld\n",
            c->world_path, wb->frames, wb->world_contact_frames, wb->err_world_sub,
            wb->pen_world_full, wb->pen_world_sub, wb->world_query_ms, wb->world_queries,
            wb->world_contacts, wb->allocs, wb->locks);
    for (int k = 0; k < wb->ncond; ++k)
        c->failed += wb->cond[k].failed;
    cond_print(wb);
    return SINEW_OK;
}

static void cond_json(const sw_world_bench *wb) {
    for (int k = 1; k < wb->ncond; ++k) {
        const sw_cond_bench *cb = &wb->cond[k];
        if (k == 1) printf(",\"cond_sweep\":[");
        printf("%s{\"rho\":%.5g,\"err_world_cond\":%.5f,\"speedup_cond_mean\":%.2f,"
               "\"speedup_cond_worst\":%.2f,\"patch_frac_mean\":%.5f,\"patch_frac_max\":%.5f,"
               "\"cond_ms_max\":%.4f,\"patch_ms_mean\":%.4f,\"patch_verts_mean\":%.1f,"
               "\"patch_tets_mean\":%.1f}%s",
               k > 1 ? "," : "", cb->rho, cb->err_world_cond, cb->speedup_mean, cb->speedup_worst,
               cb->patch_frac_mean, cb->patch_frac_max, cb->ms_max, cb->patch_ms_mean,
               cb->patch_verts_mean, cb->patch_tets_mean, k == wb->ncond - 1 ? "]" : "");
    }
    if (wb->ncond == 0) return;
    const sw_cond_bench *c0 = &wb->cond[0];
    printf(",\"rho\":%.5g,\"patch_budget\":%u,\"err_world_cond\":%.5f,"
           "\"speedup_cond_mean\":%.2f,\"speedup_cond_worst\":%.2f,\"patch_frac_mean\":%.5f,"
           "\"patch_frac_max\":%.5f,\"frame_p100_over_p50\":%.3f,"
           "\"patch_truncated_frames\":%d,\"pop_max\":%.3f,\"cond_ms_median\":%.4f,"
           "\"cond_ms_max\":%.4f,\"pcg_iters_max\":%u,\"patch_ms_mean\":%.4f,"
           "\"patch_verts_mean\":%.1f,\"patch_tets_mean\":%.1f",
           c0->rho, c0->budget, c0->err_world_cond, c0->speedup_mean, c0->speedup_worst,
           c0->patch_frac_mean, c0->patch_frac_max, c0->p100_over_p50, c0->truncated_frames,
           c0->pop_max, c0->ms_median, c0->ms_max, c0->pcg_iters_max, c0->patch_ms_mean,
           c0->patch_verts_mean, c0->patch_tets_mean);
}

static void world_json(const sw_bench_ctx *c) {
    const sw_world_bench *wb = &c->wb;
    printf(",\"world\":\"%s\",\"world_frames\":%d,\"world_contact_frames\":%d,"
           "\"err_world_sub\":%.5f,\"pen_world_full\":%.6g,\"pen_world_sub\":%.6g,"
           "\"world_query_ms\":%.5f,\"world_queries\":%.1f,\"world_contacts\":%.1f,"
           "\"world_full_ms\":%.3f,\"world_sub_ms\":%.4f,\"world_ref_unsettled\":%d,"
           "\"world_allocs_in_step\":%ld,\"world_locks_in_step\":%ld",
           c->world_path, wb->frames, wb->world_contact_frames, wb->err_world_sub,
           wb->pen_world_full, wb->pen_world_sub, wb->world_query_ms, wb->world_queries,
           wb->world_contacts, wb->full_ms, wb->sub_ms, wb->ref_unsettled, wb->allocs, wb->locks);
    cond_json(wb);
}

/* ---- --dynamic: the dynamic step against the reference's backward Euler ---- */

static int dyn_wanted(const sw_bench_ctx *c) {
    return c->dynamic;
}

static sinew_result dyn_run(sw_bench_ctx *c, sw_error *err) {
    sw_dyn_bench *db = &c->db;
    sinew_result r = sw_dyn_bench_run(c->ch, c->blob, c->fp, c->hold_frames ? c->hold_frames : 30,
                                      c->kf == c->nf ? c->full_x : NULL, db, err);
    if (r != SINEW_OK) return r;
    c->failed += db->sub_failed + db->ref_failed;
    sw_dyn_cost *dc = &c->dcost;
    r = sw_dyn_bench_cost(c->blob, &c->ch->clip, c->nf, c->timing_passes > 3 ? c->timing_passes : 3,
                          dc, err);
    if (r != SINEW_OK) return r;
    c->failed += dc->failed;
    fprintf(stderr,
            "sinew-bench: dynamic (dt %g, Rayleigh %g %g, %d + %d hold frames): err_dynamic "
            "%.4f (hold %.4f; the reference's own spread %.4f, hold %.4f; against the tighter "
            "reference %.4f); overshoot sub %.5g full %.5g ratio %.3f; settle sub %.3g "
            "full %.3g; dynamic increment error %.4f (rms %.3g; the runtime's %.3g of it, "
            "cosine %.3f); %.2f / %.3f ms a step\n",
            db->dt, db->rayleigh_alpha, db->rayleigh_beta, db->frames, db->hold_frames,
            db->err_dynamic, db->err_dynamic_hold, db->err_dynamic_ref[0], db->err_dynamic_ref[1],
            db->err_dynamic_tight, db->overshoot_sub, db->overshoot_full, db->overshoot_ratio,
            db->settle_sub, db->settle_full, db->err_increment, db->increment_rms,
            db->increment_ratio, db->increment_cos, db->full_ms, db->sub_ms);
    fprintf(stderr,
            "sinew-bench: dynamic step %.4f ms (%.2f cubature passes, %.2f factorisations) "
            "against quasistatic %.4f ms (%.2f, %.2f), timed in turns: %.2fx\n",
            dc->dyn_ms, dc->dyn_evals, dc->dyn_factors, dc->qs_ms, dc->qs_evals, dc->qs_factors,
            dc->dyn_ms / dc->qs_ms);
    return SINEW_OK;
}

/* v with `digits` decimals into b (32 chars), or null when it is not finite. */
static const char *json_or_null(char b[32], double v, int digits) {
    if (isfinite(v))
        snprintf(b, 32, "%.*f", digits, v);
    else
        snprintf(b, 32, "null");
    return b;
}

static void dyn_json(const sw_bench_ctx *c) {
    const sw_dyn_bench *db = &c->db;
    /* null: no reference overshoot (ratio), no reference quasistatic clip (the increment's
       figures, --full-frames) */
    char ratio[32], inc[32], inc_ratio[32], inc_cos[32];
    json_or_null(ratio, db->overshoot_ratio, 4);
    json_or_null(inc, db->err_increment, 5);
    json_or_null(inc_ratio, db->increment_ratio, 5);
    json_or_null(inc_cos, db->increment_cos, 5);
    printf(",\"dyn_dt\":%.9g,\"dyn_rayleigh_alpha\":%g,\"dyn_rayleigh_beta\":%g,"
           "\"hold_frames\":%d,\"err_dynamic\":%.5f,\"err_dynamic_hold\":%.5f,"
           "\"err_dynamic_ref\":%.5f,\"err_dynamic_ref_hold\":%.5f,\"err_dynamic_tight\":%.5f,"
           "\"overshoot_sub\":%.6g,\"overshoot_full\":%.6g,\"overshoot_ratio\":%s,"
           "\"settle_sub\":%.6g,\"settle_full\":%.6g,\"dyn_full_ms\":%.3f,"
           "\"dyn_sub_ms\":%.4f,\"dyn_ref_failed\":%d,\"dyn_ref_unconverged\":%d,"
           "\"dyn_ref_unsettled\":%d,\"dyn_sub_failed\":%d,\"err_dyn_increment\":%s,"
           "\"dyn_increment_ratio\":%s,\"dyn_increment_cos\":%s,"
           "\"dyn_increment_rms\":%.6g,\"dyn_sub_limited\":%d,\"dyn_sub_teleport\":%d,"
           "\"dyn_sub_guard\":%d,\"dyn_sub_converged\":%d,\"dyn_step_ms\":%.4f,"
           "\"dyn_qs_step_ms\":%.4f,\"dyn_vs_qs\":%.3f,\"dyn_step_evals\":%.3f,"
           "\"dyn_qs_step_evals\":%.3f",
           db->dt, db->rayleigh_alpha, db->rayleigh_beta, db->hold_frames, db->err_dynamic,
           db->err_dynamic_hold, db->err_dynamic_ref[0], db->err_dynamic_ref[1],
           db->err_dynamic_tight, db->overshoot_sub, db->overshoot_full, ratio, db->settle_sub,
           db->settle_full, db->full_ms, db->sub_ms, db->ref_failed, db->ref_unconverged,
           db->ref_unsettled, db->sub_failed, inc, inc_ratio, inc_cos, db->increment_rms,
           db->sub_limited, db->sub_teleport, db->sub_guard, db->sub_converged, c->dcost.dyn_ms,
           c->dcost.qs_ms, c->dcost.dyn_ms / c->dcost.qs_ms, c->dcost.dyn_evals, c->dcost.qs_evals);
}

/* ---- --lod: every level of detail ---- */

static int lod_wanted(const sw_bench_ctx *c) {
    return c->lod;
}

static sinew_result lod_run(sw_bench_ctx *c, sw_error *err) {
    sinew_result r = sw_lod_bench_run(c->blob, &c->ch->clip, c->nf, clip_dt(c), c->timing_passes,
                                      c->err_res, &c->lb, err);
    if (r != SINEW_OK) return r;
    c->failed += c->lb.failed;
    sw_lod_bench_print(&c->lb, stderr, 0);
    return SINEW_OK;
}

static void lod_json(const sw_bench_ctx *c) {
    sw_lod_bench_print(&c->lb, stdout, 1);
}

/* In the order of the JSON line's members. */
const sw_bench_mode sw_bench_modes[] = {
    {"--instances", crowd_wanted, crowd_run, crowd_json, "crowd run failed: "},
    {"--sc-compare", sc_wanted, sc_run, sc_json, "self-contact comparison failed: "},
    {"--newton-compare", newton_wanted, newton_run, newton_json, "Newton comparison failed: "},
    {"--error-gap", gap_wanted, gap_run, gap_json, ""},
    {"--world", world_wanted, world_run, world_json, "world run failed: "},
    {"--dynamic", dyn_wanted, dyn_run, dyn_json, "dynamic run failed: "},
    {"--novel", novel_wanted, novel_run, novel_json, "novel-contact run failed: "},
    {"--pair", pair_wanted, pair_run, pair_json, "pair run failed: "},
    {"--lod", lod_wanted, lod_run, lod_json, "level-of-detail run failed: "},
};
const int sw_bench_nmodes = (int)(sizeof sw_bench_modes / sizeof sw_bench_modes[0]);
