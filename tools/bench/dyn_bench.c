/* sinew-bench --dynamic (dyn_bench.h): the reference and the runtime step the same
 * frames side by side, so no frame of the reference is stored. */
#include "dyn_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "clock.h"
#include "instance.h"
#include "replay.h"
#include "subspace_eval.h"
#include "tool_common.h"

/* The reference's own spread (sw_dyn_bench.err_dynamic_ref): a second reference whose
 * Newton and PCG tolerances are this many times tighter. */
#define SW_DYN_SPREAD_TIGHTER 100.0

/* The reference's lumped mass at each output vertex (sm), as the output places the
 * vertex: a boundary vertex's own, a render vertex's barycentric blend of its tet's
 * corners' (at least 0: an extrapolated blend may dip below). 0 when out of memory. */
static int surface_masses(const sw_blob_view *v, const double *mass, double *sm) {
    int32_t ns = sw_blob_output_verts(v);
    double *m3 = malloc(sizeof(double) * 3 * (size_t)v->nverts),
           *o3 = malloc(sizeof(double) * 3 * (size_t)ns);
    if (m3 && o3) {
        for (int32_t i = 0; i < v->nverts; ++i)
            m3[3 * i] = m3[3 * i + 1] = m3[3 * i + 2] = mass[i];
        sw_output_from_full(v, m3, o3); /* the output's own map, one component a mass */
        for (int32_t s = 0; s < ns; ++s)
            sm[s] = fmax(0, o3[3 * s]);
    }
    int ok = m3 && o3;
    free(m3), free(o3);
    return ok;
}

/* The mass-weighted RMS distance between two surfaces (3 ns each), weights m (ns). */
static double rms_m(const double *a, const double *b, const double *m, int32_t ns) {
    double s = 0, w = 0;
    for (int32_t i = 0; i < ns; ++i) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k)
            d2 += (a[3 * i + k] - b[3 * i + k]) * (a[3 * i + k] - b[3 * i + k]);
        s += m[i] * d2;
        w += m[i];
    }
    return w > 0 ? sqrt(s / w) : 0;
}

/* Overshoot (sinew-bench.c): the largest distance of a hold frame's surface from the
 * last hold frame's; settle: the last hold step's motion. hs holds H surfaces. */
static void overshoot(const double *hs, int H, const double *m, int32_t ns, double *over,
                      double *settle) {
    const double *last = hs + (size_t)(H - 1) * 3 * ns;
    *over = 0;
    for (int f = 0; f < H - 1; ++f)
        *over = fmax(*over, rms_m(hs + (size_t)f * 3 * ns, last, m, ns));
    *settle = rms_m(hs + (size_t)(H - 2) * 3 * ns, last, m, ns);
}

/* When the hold's surfaces (hs, H of them) first swing through the last one: the frame,
 * interpolated, at which their displacement from the last frame, measured along the first
 * hold frame's (mass-weighted), first changes sign; NaN when it never does (overdamped).
 * A softer character swings back later: a quarter of its period after the stop. */
static double first_crossing(const double *hs, int H, const double *m, int32_t ns) {
    const double *last = hs + (size_t)(H - 1) * 3 * ns;
    double prev = 0;
    for (int f = 0; f < H - 1; ++f) {
        double s = 0;
        for (int32_t i = 0; i < ns; ++i)
            for (int k = 0; k < 3; ++k)
                s += m[i] * (hs[(size_t)f * 3 * ns + 3 * i + k] - last[3 * i + k]) *
                     (hs[3 * i + k] - last[3 * i + k]);
        if (f > 0 && s <= 0 && prev > 0) return f - 1 + prev / (prev - s);
        prev = s;
    }
    return NAN;
}

static double mass_total(const double *m, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += m[i];
    return s;
}

typedef struct dyn_run {
    sw_fullsim *ref;
    sw_fullsim *ref2; /* the reference solved to tolerances SW_DYN_SPREAD_TIGHTER tighter */
    double *xdqs;     /* plain skinning of every vertex at the frame's pose */
    double spread_num[2], spread_den[2]; /* its distance from the reference: clip, hold */
    sinew_instance *inst;
    sw_eval_acc clip, hold, clip_tight; /* the runtime against the reference; the tighter */
    sinew_instance *qs;                 /* quasistatic runtime alongside, for the increment */
    double *xd, *xq, *cnt;              /* its and the dynamic instance's full positions */
    double inc_num, inc_den;            /* the dynamic increment's sums: error, reference */
    double inc_sub, inc_dot;            /* the runtime's, and its product with the reference's */
    double *full_ms, *sub_ms, *hs_full, *hs_sub, *sm; /* per step; hold surfaces; masses */
} dyn_run;

static void run_free(dyn_run *r) {
    sw_fullsim_destroy(r->ref);
    sw_fullsim_destroy(r->ref2);
    free(r->xdqs);
    sinew_instance_destroy(r->inst);
    sinew_instance_destroy(r->qs);
    free(r->xd);
    free(r->xq);
    free(r->cnt);
    sw_eval_acc_free(&r->clip);
    sw_eval_acc_free(&r->hold);
    sw_eval_acc_free(&r->clip_tight);
    free(r->full_ms);
    free(r->sub_ms);
    free(r->hs_full);
    free(r->hs_sub);
    free(r->sm);
}

/* Both runs settled at pose T0 (dyn_bench.h). */
static sinew_result start_settled(const sw_character *ch, const sinew_blob *blob,
                                  const sw_fullsim_params *fd, const double *T0, dyn_run *r,
                                  float h, sw_error *err) {
    sw_fullsim_params fq = *fd;
    fq.integrator = SW_QUASISTATIC;
    sw_fullsim *qs = NULL;
    sinew_result res = sw_fullsim_create(ch, &fq, &qs, err);
    if (res != SINEW_OK) return res;
    res = sw_fullsim_step(qs, T0, NULL);
    if (res == SINEW_OK || res == SINEW_ERROR_NOT_CONVERGED)
        res = sw_fullsim_create(ch, fd, &r->ref, err);
    else
        sw_error_set(err, res, "the reference's quasistatic start failed");
    sw_fullsim_params ft = *fd; /* the spread's reference */
    ft.newton_rtol /= SW_DYN_SPREAD_TIGHTER;
    ft.pcg_rtol /= SW_DYN_SPREAD_TIGHTER;
    if (res == SINEW_OK) res = sw_fullsim_create(ch, &ft, &r->ref2, err);
    if (res == SINEW_OK) {
        sw_fullsim_set_state(r->ref, T0, sw_fullsim_positions(qs), NULL);
        sw_fullsim_set_state(r->ref2, T0, sw_fullsim_positions(qs), NULL);
    }
    sw_fullsim_destroy(qs);
    if (res != SINEW_OK) return res;

    sinew_instance *q0 = NULL;
    if ((res = sinew_instance_create(blob, NULL, &q0)) != SINEW_OK)
        return sw_error_set(err, res, "cannot create an instance");
    sw_instance_set_pose_d(q0, T0);
    res = sinew_instance_step(q0, h);
    sinew_instance_def def = sinew_instance_def_default();
    def.mode = SINEW_STEP_DYNAMIC;
    if (res == SINEW_OK) res = sinew_instance_create(blob, &def, &r->inst);
    if (res == SINEW_OK) {
        sw_instance_set_q(r->inst, sw_instance_q(q0));
        sw_instance_set_pose_d(r->inst, T0);
        res = sinew_instance_step(r->inst, h);
        if (res == SINEW_OK) res = sinew_instance_step(r->inst, h);
    }
    sinew_instance_destroy(q0);
    if (res != SINEW_OK) return sw_error_set(err, res, "the runtime's settled start failed");
    return SINEW_OK;
}

/* Adds a frame to the dynamic increment: the runtime's dynamic minus quasistatic shape
 * against the reference's (xf dynamic, xfq quasistatic at the same pose). */
static void add_increment(dyn_run *r, const double *mass, int32_t nv, const double *xf,
                          const double *xfq) {
    sw_instance_full_positions(r->inst, r->xd, r->cnt);
    sw_instance_full_positions(r->qs, r->xq, r->cnt);
    for (int64_t i = 0; i < 3 * (int64_t)nv; ++i) {
        double df = xf[i] - xfq[i], ds = r->xd[i] - r->xq[i], e = ds - df;
        r->inc_num += mass[i / 3] * e * e;
        r->inc_den += mass[i / 3] * df * df;
        r->inc_sub += mass[i / 3] * ds * ds;
        r->inc_dot += mass[i / 3] * ds * df;
    }
}

/* Adds a frame to the reference's spread (k 0: clip, 1: hold): the tighter reference's
 * distance from the reference, over the reference's correction. */
static void add_spread(dyn_run *r, const double *mass, int32_t nv, int k) {
    const double *x = sw_fullsim_positions(r->ref), *y = sw_fullsim_positions(r->ref2);
    sw_instance_dqs_positions(r->inst, r->xdqs);
    for (int64_t i = 0; i < 3 * (int64_t)nv; ++i) {
        double e = y[i] - x[i], b = x[i] - r->xdqs[i];
        r->spread_num[k] += mass[i / 3] * e * e;
        r->spread_den[k] += mass[i / 3] * b * b;
    }
}

sinew_result sw_dyn_bench_run(const sw_character *ch, const sinew_blob *blob,
                              const sw_fullsim_params *fp, int hold_frames, const double *full_qs,
                              sw_dyn_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    int F = ch->clip.nframes, H = hold_frames, N = F + H;
    if (!v || F < 1 || H < 2)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "dynamic bench: bad arguments");
    /* the clip's own time step in both runs, and the blob's damping in the reference */
    double fps = ch->clip.fps > 0 ? ch->clip.fps : 30;
    float h = (float)(1.0 / fps);
    sw_fullsim_params fd = *fp;
    fd.integrator = SW_BACKWARD_EULER;
    fd.dt = h; /* the float the runtime steps with, exactly */
    fd.rayleigh_alpha = v->rayleigh_alpha;
    fd.rayleigh_beta = v->rayleigh_beta;
    out->frames = F;
    out->hold_frames = H;
    out->dt = fd.dt;
    out->rayleigh_alpha = fd.rayleigh_alpha;
    out->rayleigh_beta = fd.rayleigh_beta;

    dyn_run r;
    memset(&r, 0, sizeof r);
    int32_t ns = sw_blob_output_verts(v), nb = ch->skel.nbones;
    size_t hsz = (size_t)H * 3 * ns * sizeof(double);
    r.full_ms = malloc((size_t)N * sizeof(double));
    r.sub_ms = malloc((size_t)N * sizeof(double));
    r.hs_full = malloc(hsz);
    r.hs_sub = malloc(hsz);
    r.sm = malloc((size_t)ns * sizeof(double));
    sinew_result res = SINEW_ERROR_OUT_OF_MEMORY;
    if (!r.full_ms || !r.sub_ms || !r.hs_full || !r.hs_sub || !r.sm) {
        sw_error_set(err, res, "out of memory");
        goto done;
    }
    if ((res = start_settled(ch, blob, &fd, ch->clip.T, &r, h, err)) != SINEW_OK) goto done;
    const double *mass = sw_fullsim_masses(r.ref);
    if (!surface_masses(v, mass, r.sm)) {
        res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if ((res = sw_eval_acc_init(&r.clip, blob, mass, err)) != SINEW_OK ||
        (res = sw_eval_acc_init(&r.hold, blob, mass, err)) != SINEW_OK ||
        (res = sw_eval_acc_init(&r.clip_tight, blob, mass, err)) != SINEW_OK)
        goto done;
    sw_eval_acc_add(&r.clip, r.inst, sw_fullsim_positions(r.ref)); /* frame 0, settled */
    sw_eval_acc_add(&r.clip_tight, r.inst, sw_fullsim_positions(r.ref2));
    int32_t nv = ch->mesh.nverts;
    if (!(r.xdqs = malloc((size_t)nv * 3 * sizeof(double)))) {
        res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (full_qs) {
        r.xd = malloc((size_t)nv * 3 * sizeof(double));
        r.xq = malloc((size_t)nv * 3 * sizeof(double));
        r.cnt = malloc((size_t)nv * sizeof(double));
        if (!r.xd || !r.xq || !r.cnt || sinew_instance_create(blob, NULL, &r.qs) != SINEW_OK) {
            res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
    }
    int nstep = 0;
    for (int f = 1; f < N; ++f, ++nstep) {
        const double *T = ch->clip.T + (size_t)(f < F ? f : F - 1) * 12 * nb;
        sw_fullsim_stats st;
        sinew_result rr = sw_fullsim_step(r.ref, T, &st);
        out->ref_failed += rr != SINEW_OK && rr != SINEW_ERROR_NOT_CONVERGED;
        out->ref_unconverged += rr == SINEW_ERROR_NOT_CONVERGED;
        out->ref_unsettled += st.contacts_unsettled;
        r.full_ms[nstep] = 1e3 * st.seconds;
        rr = sw_fullsim_step(r.ref2, T, NULL);
        out->ref_failed += rr != SINEW_OK && rr != SINEW_ERROR_NOT_CONVERGED;
        double t0 = sw_now_seconds();
        sw_instance_set_pose_d(r.inst, T);
        sinew_result sr = sinew_instance_step(r.inst, h);
        r.sub_ms[nstep] = 1e3 * (sw_now_seconds() - t0);
        out->sub_failed += sr != SINEW_OK;
        sinew_step_stats ss = {.struct_size = sizeof ss};
        if (sinew_instance_get_stats(r.inst, &ss) == SINEW_OK) {
            out->sub_limited += (ss.status & SINEW_STEP_LIMITED) != 0;
            out->sub_teleport += (ss.status & SINEW_STEP_TELEPORT) != 0;
            out->sub_guard += (ss.status & SINEW_STEP_GUARD) != 0;
            out->sub_converged += (ss.status & SINEW_STEP_CONVERGED) != 0;
        }
        const double *x = sw_fullsim_positions(r.ref);
        if (sr == SINEW_OK) sw_eval_acc_add(f < F ? &r.clip : &r.hold, r.inst, x);
        if (sr == SINEW_OK && f < F)
            sw_eval_acc_add(&r.clip_tight, r.inst, sw_fullsim_positions(r.ref2));
        add_spread(&r, mass, nv, f >= F);
        if (r.qs && sr == SINEW_OK && sw_instance_set_pose_d(r.qs, T) == SINEW_OK &&
            sinew_instance_step(r.qs, h) == SINEW_OK)
            add_increment(&r, mass, nv, x, full_qs + (size_t)(f < F ? f : F - 1) * 3 * nv);
        if (f >= F) { /* the hold: both surfaces, for the overshoot */
            double *a = r.hs_full + (size_t)(f - F) * 3 * ns,
                   *b = r.hs_sub + (size_t)(f - F) * 3 * ns;
            sw_output_from_full(v, x, a); /* the reference through the output's own map */
            memcpy(b, sw_instance_surface(r.inst), 3 * (size_t)ns * sizeof(double));
        }
    }
    sw_eval_result e;
    sw_eval_acc_result(&r.clip, &e);
    out->err_dynamic = e.correction_error;
    sw_eval_acc_result(&r.hold, &e);
    out->err_dynamic_hold = e.correction_error;
    sw_eval_acc_result(&r.clip_tight, &e);
    out->err_dynamic_tight = e.correction_error;
    for (int k = 0; k < 2; ++k)
        out->err_dynamic_ref[k] =
            r.spread_den[k] > 0 ? sqrt(r.spread_num[k] / r.spread_den[k]) : NAN;
    overshoot(r.hs_sub, H, r.sm, ns, &out->overshoot_sub, &out->settle_sub);
    overshoot(r.hs_full, H, r.sm, ns, &out->overshoot_full, &out->settle_full);
    out->overshoot_ratio = out->overshoot_full > 0 ? out->overshoot_sub / out->overshoot_full : NAN;
    out->swing_sub = first_crossing(r.hs_sub, H, r.sm, ns);
    out->swing_full = first_crossing(r.hs_full, H, r.sm, ns);
    out->err_increment = r.inc_den > 0 ? sqrt(r.inc_num / r.inc_den) : NAN;
    out->increment_ratio = r.inc_den > 0 ? sqrt(r.inc_sub / r.inc_den) : NAN;
    out->increment_cos =
        r.inc_den > 0 && r.inc_sub > 0 ? r.inc_dot / sqrt(r.inc_sub * r.inc_den) : NAN;
    out->increment_rms = sqrt(r.inc_den / (N - 1) / mass_total(mass, nv));
    out->full_ms = sw_median(r.full_ms, nstep);
    out->sub_ms = sw_median(r.sub_ms, nstep);
    res = SINEW_OK;
done:
    run_free(&r);
    return res;
}

/* One mode's timing run (sw_dyn_bench_cost): each clip frame's least ms, and the counts
 * of the first timed play. */
typedef struct cost_run {
    double *ms;
    int pass;
    double evals, factors;
} cost_run;

static void cost_step(void *user, int step, int f, double ms, const sinew_step_stats *st) {
    (void)step;
    cost_run *c = user;
    c->ms[f] = c->pass == 0 ? ms : fmin(c->ms[f], ms);
    if (c->pass > 0) return;
    c->evals += st->potential_evals;
    c->factors += st->factorizations;
}

sinew_result sw_dyn_bench_cost(const sinew_blob *blob, const sw_clip *clip, int frames, int passes,
                               sw_dyn_cost *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    float h = 1.0f / (float)(clip->fps > 0 ? clip->fps : 30);
    sinew_instance *in[2] = {NULL, NULL};
    cost_run c[2] = {{malloc((size_t)frames * sizeof(double)), 0, 0, 0},
                     {malloc((size_t)frames * sizeof(double)), 0, 0, 0}};
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!c[0].ms || !c[1].ms) {
        sw_error_set(err, r, "out of memory");
        goto done;
    }
    for (int k = 0; k < 2; ++k) {
        sinew_instance_def def = sinew_instance_def_default();
        def.mode = k ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        if ((r = sinew_instance_create(blob, &def, &in[k])) != SINEW_OK) {
            sw_error_set(err, r, "cannot create an instance");
            goto done;
        }
    }
    /* the two modes take turns, a play of the clip each, so that both see the same machine;
       the first play of each settles, untimed */
    for (int p = 0; p <= (passes > 0 ? passes : 1); ++p)
        for (int k = 0; k < 2; ++k) {
            sw_replay rp = sw_replay_clip(in[k], clip->T, frames, clip->nbones, h);
            rp.warmup = p == 0 ? frames : 0;
            rp.steps = p == 0 ? 0 : frames;
            c[k].pass = p - 1;
            rp.on_step = cost_step;
            rp.user = &c[k];
            sw_replay_run(&rp);
            out->failed += rp.warmup_failed + rp.failed;
        }
    out->qs_ms = sw_median(c[0].ms, frames);
    out->dyn_ms = sw_median(c[1].ms, frames);
    out->qs_evals = c[0].evals / frames;
    out->dyn_evals = c[1].evals / frames;
    out->qs_factors = c[0].factors / frames;
    out->dyn_factors = c[1].factors / frames;
    r = SINEW_OK;
done:
    for (int k = 0; k < 2; ++k) {
        sinew_instance_destroy(in[k]);
        free(c[k].ms);
    }
    return r;
}
