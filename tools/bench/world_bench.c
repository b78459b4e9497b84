#include "world_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "clock.h"
#include "collision.h"
#include "instance.h"
#include "replay.h"
#include "rt_interpose.h"
#include "tool_common.h"

/* The reference over the scene: positions of every frame into x_full, which frames touch
 * a collider into touch. */
static sinew_result run_reference(const sw_character *ch, sw_world_scene *ws,
                                  const sw_fullsim_params *fp, const double *T, int nf,
                                  double *x_full, unsigned char *touch, double *mass, double *ms,
                                  sw_world_bench *out, sw_error *err) {
    sw_fullsim_params p = *fp;
    p.world = ws->world;
    sw_fullsim *sim;
    sinew_result r = sw_fullsim_create(ch, &p, &sim, err);
    if (r != SINEW_OK) return r;
    size_t nv3 = (size_t)3 * ch->mesh.nverts;
    memcpy(mass, sw_fullsim_masses(sim), sizeof(double) * ch->mesh.nverts);
    for (int f = 0; f < nf; ++f) {
        sw_fullsim_stats st;
        if ((r = sw_world_scene_at(ws, f, err)) != SINEW_OK) break;
        sinew_result sr = sw_fullsim_step(sim, T + (size_t)f * 12 * ch->skel.nbones, &st);
        out->ref_failed += sr != SINEW_OK && sr != SINEW_ERROR_NOT_CONVERGED;
        out->ref_unsettled += st.contacts_unsettled;
        out->pen_world_full = fmax(out->pen_world_full, st.world_penetration);
        touch[f] = st.world_contacts > 0;
        out->world_contact_frames += touch[f];
        ms[f] = 1e3 * st.seconds;
        memcpy(x_full + (size_t)f * nv3, sw_fullsim_positions(sim), nv3 * sizeof(double));
        fprintf(stderr,
                "sinew-bench: world reference frame %d/%d: %.1f ms, %d in contact, "
                "penetration %.4g; %d Newton, converged %d, residual %.2g, %d self-contacts, "
                "unsettled %d\n",
                f + 1, nf, ms[f], st.world_contacts, st.world_penetration, st.newton_iters,
                st.converged, st.grad_norm0 > 0 ? st.grad_norm / st.grad_norm0 : 0, st.contacts,
                st.contacts_unsettled);
    }
    double *sorted = malloc(sizeof(double) * nf);
    if (sorted) memcpy(sorted, ms, sizeof(double) * nf);
    out->full_ms = sorted ? sw_median(sorted, nf) : 0;
    free(sorted);
    sw_fullsim_destroy(sim);
    return r;
}

/* Passes of the scene the timed run makes (the median is over all their steps: one pass
 * of 30 steps moved by 1.6x between two runs on this machine). */
#define TIMED_PASSES 5

/* The timed pass's state: the scene and the figures of its steps. */
typedef struct {
    sinew_instance *inst;
    sw_world_scene *ws;
    sw_error *err;
    double *qms, *sms;
    int n;
    sw_world_bench *out;
} world_pass;

/* Each pass from rest, the colliders at the frame (a failure is counted by the step). */
static sinew_result world_before(void *user, int step, int frame) {
    world_pass *w = user;
    if (frame == 0 && step < w->n) sinew_instance_reset(w->inst);
    sw_world_scene_at(w->ws, frame, w->err);
    return SINEW_OK;
}

static void world_step(void *user, int step, int frame, double ms, const sinew_step_stats *st) {
    (void)frame;
    world_pass *w = user;
    w->sms[step] = ms;
    w->qms[step] = st->ms_world;
    w->out->world_queries += st->world_queries / (double)w->n;
    w->out->world_contacts += st->world_contacts / (double)w->n;
}

/* The timed pass: the scene's frames stepped and read back to back, as sub_ms is timed
 * (nothing else between steps evicting the caches): the median step and the median of
 * the step's own world detection time (ms_world), over TIMED_PASSES passes. */
static void time_subspace(sinew_instance *inst, sw_world_scene *ws, const double *T, int nf,
                          int32_t nbones, uint32_t ns, sw_world_bench *out, sw_error *err) {
    int n = TIMED_PASSES * nf;
    world_pass w = {inst, ws, err, malloc(sizeof(double) * n), malloc(sizeof(double) * n), n, out};
    float *pos = malloc(sizeof(float) * 3 * ns), *nrm = malloc(sizeof(float) * 3 * ns);
    if (w.qms && w.sms && pos && nrm) {
        sw_replay rp = sw_replay_clip(inst, T, nf, nbones, 1.0f / 30);
        rp.steps = n;
        rp.pos = pos;
        rp.nrm = nrm;
        rp.ns = ns;
        rp.before = world_before;
        rp.on_step = world_step;
        rp.user = &w;
        sw_replay_run(&rp);
        out->sub_failed += rp.failed;
    }
    out->world_query_ms = w.qms ? sw_median(w.qms, n) : 0;
    out->sub_ms = w.sms ? sw_median(w.sms, n) : 0;
    free(w.qms), free(w.sms), free(pos), free(nrm);
    sinew_instance_reset(inst);
}

/* The runtime over the scene: its figures, and the correction error over the frames the
 * reference touches a collider in. */
static sinew_result run_subspace(const sinew_blob *blob, sw_world_scene *ws, const double *T,
                                 int nf, const double *x_full, const unsigned char *touch,
                                 const double *mass, sw_world_bench *out, sw_error *err) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, NULL, &inst);
    if (r != SINEW_OK) return sw_error_set(err, r, "cannot create an instance");
    sinew_instance_set_world(inst, ws->world);
    int32_t n = v->nverts, ns = sw_blob_output_verts(v);
    time_subspace(inst, ws, T, nf, v->nbones, (uint32_t)ns, out, err);
    double *xs = malloc(sizeof(double) * 3 * n), *cnt = malloc(sizeof(double) * n),
           *xd = malloc(sizeof(double) * 3 * n), *xo = malloc(sizeof(double) * 3 * ns);
    double num = 0, den = 0;
    /* a render mesh: the reference's penetration is its render mesh's too, placed by the
       same embedding, not its tet boundary's (like with like) */
    if (v->nrender_verts > 0) out->pen_world_full = 0;
    for (int f = 0; f < nf && xs && cnt && xd && xo; ++f) {
        if ((r = sw_world_scene_at(ws, f, err)) != SINEW_OK) break;
        sw_instance_set_pose_d(inst, T + (size_t)f * 12 * v->nbones);
        out->sub_failed += sinew_instance_step(inst, 1.0f / 30) != SINEW_OK;
        out->pen_world_sub = fmax(
            out->pen_world_sub,
            sw_world_max_penetration(ws->world, ns, sw_instance_surface(inst), NULL, NULL, NULL));
        if (v->nrender_verts > 0) {
            sw_output_from_full(v, x_full + (size_t)f * 3 * n, xo);
            out->pen_world_full = fmax(
                out->pen_world_full, sw_world_max_penetration(ws->world, ns, xo, NULL, NULL, NULL));
        }
        if (!touch[f]) continue;
        sw_instance_full_positions(inst, xs, cnt);
        sw_instance_dqs_positions(inst, xd);
        const double *xf = x_full + (size_t)f * 3 * n;
        for (int32_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) {
                double a = xs[3 * i + k] - xf[3 * i + k], b = xf[3 * i + k] - xd[3 * i + k];
                num += mass[i] * a * a;
                den += mass[i] * b * b;
            }
    }
    out->err_world_sub = den > 0 ? sqrt(num / den) : 0;
    /* the real-time contract with world contact active */
    out->allocs = out->locks = -1;
    (void)sw_rt_interpose_active(); /* its self-check counts: outside the counted steps */
    if (out->contract_steps > 0 && r == SINEW_OK) {
        /* the colliders at each frame: inside the count (world_before, no reset past n) */
        world_pass w = {inst, ws, err, NULL, NULL, 0, out};
        sw_replay rp = sw_replay_clip(inst, T, nf, v->nbones, 1.0f / 30);
        rp.steps = out->contract_steps;
        rp.count_rt = 1;
        rp.before = world_before;
        rp.user = &w;
        sw_replay_run(&rp);
        out->sub_failed += rp.failed;
        sw_rt_counts_report(&rp.counts, &out->allocs, &out->locks);
    }
    free(xs), free(cnt), free(xd), free(xo);
    sinew_instance_destroy(inst);
    return r;
}

sinew_result sw_world_bench_run(const sw_character *ch, const sinew_blob *blob, sw_world_scene *ws,
                                const sw_fullsim_params *fp, int frames, int contract_steps,
                                const sw_cond_bench_params *cp, sw_world_bench *out,
                                sw_error *err) {
    memset(out, 0, sizeof *out);
    out->contract_steps = contract_steps;
    int nf;
    double *T =
        sw_world_scene_poses(ws, ch->clip.T, ch->clip.nframes, ch->skel.nbones, frames, &nf);
    double *x_full = T ? malloc(sizeof(double) * 3 * ch->mesh.nverts * (size_t)nf) : NULL;
    double *mass = malloc(sizeof(double) * ch->mesh.nverts);
    unsigned char *touch = calloc((size_t)(nf > 0 ? nf : 1), 1);
    double *ref_ms = malloc(sizeof(double) * (size_t)(nf > 0 ? nf : 1));
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!T || !x_full || !mass || !touch || !ref_ms) {
        sw_error_set(err, r, "out of memory for the world scene");
        goto done;
    }
    out->frames = nf;
    if ((r = run_reference(ch, ws, fp, T, nf, x_full, touch, mass, ref_ms, out, err)) != SINEW_OK)
        goto done;
    if ((r = run_subspace(blob, ws, T, nf, x_full, touch, mass, out, err)) != SINEW_OK) goto done;
    for (int k = 0; cp && sw_blob_get_view(blob)->ntets > 0 && k < (cp->nrho ? cp->nrho : 1); ++k) {
        double rho = cp->nrho ? cp->rho[k] : 0;
        r = sw_cond_bench_run(blob, ws, T, nf, x_full, ref_ms, touch, mass, cp, rho, &out->cond[k],
                              err);
        if (r != SINEW_OK) break;
        out->ncond = k + 1;
    }
done:
    free(T), free(x_full), free(mass), free(touch), free(ref_ms);
    return r;
}
