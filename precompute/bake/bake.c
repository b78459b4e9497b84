/* The bake's orchestrator (bake.h): its stages as one table, and the loop that runs,
 * times and reports them. Each stage is a file of its own (bake_state.h lists them); what
 * they share lives below them (bake_state.c, bake_params.c, bake_eval.c, bake_shapes.c,
 * bake_cache.c); no stage includes bake.h (tests/bake_includes.cmake). */
#include "bake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "clock.h"

/* The parameters sw_bake takes. */
static sinew_result check_params(const sw_bake_params *pp, sw_error *err) {
    sw_bake_params p = *pp;
    if (p.max_rank < 1 || p.max_rank > 1024 || !(p.pca_energy > 0 && p.pca_energy <= 1) ||
        !(p.pca_strain >= 0 && p.pca_strain <= 1) || !(p.cubature_tol > 0 && p.cubature_tol < 1) ||
        p.cubature_max < 1 || p.sweep_samples < 1 || p.sweep_samples > 1000 ||
        p.max_train_frames < 1 || !(p.heldout_fraction >= 0 && p.heldout_fraction < 1) ||
        !(p.spring_k >= 0) || !isfinite(p.spring_k) || !(p.fold_share >= 0 && p.fold_share < 0.5) ||
        !(p.contact_cubature_tol >= 0 && p.contact_cubature_tol < 1))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "bake parameters out of range (rank %d, energy %g, strain share %g, "
                            "cubature tol %g, "
                            "max %d, sweep %d, frames %d, held-out %g, spring %g, fold share %g, "
                            "contact cubature tol %g)",
                            p.max_rank, p.pca_energy, p.pca_strain, p.cubature_tol, p.cubature_max,
                            p.sweep_samples, p.max_train_frames, p.heldout_fraction, p.spring_k,
                            p.fold_share, p.contact_cubature_tol);
    if (p.random_poses < 0 || p.heldout_steps < 1 || p.heldout_steps > 64 ||
        (int64_t)p.random_poses * p.heldout_steps > 1000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "random held-out poses: %d poses in %d steps each (steps 1..64, "
                            "at most 1000000 poses in all)",
                            p.random_poses, p.heldout_steps);
    if (p.ntrain_clips < 0 || p.nheldout_clips < 0 || (p.ntrain_clips > 0 && !p.train_clips) ||
        (p.nheldout_clips > 0 && !p.heldout_clips) || (p.nheldout_clips > 0 && !p.ntrain_clips))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "bake clips: %d training and %d held-out clips (held-out clips need "
                            "training clips)",
                            p.ntrain_clips, p.nheldout_clips);
    int32_t chain = p.extra_chain > 0 ? p.extra_chain : p.nextra_poses;
    if (p.nextra_poses < 0 || p.extra_chain < 0 || (p.nextra_poses > 0 && !p.extra_poses) ||
        (p.nextra_poses > 0 && (p.nextra_poses + chain - 1) / chain > 1024))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "bake extra poses: %d poses in paths of %d (at most 1024 paths)",
                            p.nextra_poses, p.extra_chain);
    return SINEW_OK;
}

/* A motion the caller hands the bake (a clip, the joint range): the skeleton's bones and
 * only finite values (sw_clip_validate), else INVALID_ARGUMENT (NOT_FINITE for a value)
 * naming it as `what`. */
static sinew_result check_motion(const sw_clip *k, int32_t nbones, const char *what,
                                 sw_error *err) {
    sinew_result r = sw_clip_validate(k, nbones, err);
    if (r == SINEW_OK) return r;
    if (r == SINEW_ERROR_PARSE) r = SINEW_ERROR_INVALID_ARGUMENT; /* the caller's, not a file */
    if (err) { /* the check names the motion: say which */
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        sw_error_set(err, r, "bake: %s: %s", what, msg);
    }
    return r;
}

/* The start of every bake: the parameters and motions checked and the worker pool
 * started. On an error the caller frees the state (sw_bake_state_free) as after any
 * stage. */
static sinew_result bake_begin(sw_bake_state *s, const sw_bake_params *p, const sw_character *c,
                               sw_error *err) {
    memset(s, 0, sizeof *s);
    pthread_mutex_init(&s->progress_lock, NULL);
    s->p = p;
    s->c = c;
    if (!c) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "no character");
    sinew_result r = check_params(p, err);
    for (int32_t i = 0; r == SINEW_OK && i < p->ntrain_clips + p->nheldout_clips; ++i) {
        const int train = i < p->ntrain_clips;
        char what[48];
        snprintf(what, sizeof what, "%s clip %d", train ? "training" : "held-out",
                 train ? i : i - p->ntrain_clips);
        r = check_motion(train ? &p->train_clips[i] : &p->heldout_clips[i - p->ntrain_clips],
                         c->skel.nbones, what, err);
    }
    if (r == SINEW_OK && c->clip.nframes != 0)
        r = check_motion(&c->clip, c->skel.nbones, "the character's clip", err);
    if (r == SINEW_OK && c->range.nframes != 0)
        r = check_motion(&c->range, c->skel.nbones, "joint range", err);
    for (int64_t i = 0; r == SINEW_OK && i < (int64_t)p->nextra_poses * 12 * c->skel.nbones; ++i)
        if (!isfinite(p->extra_poses[i]))
            r = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                             "bake extra poses: pose %lld has a value that is not finite",
                             (long long)(i / (12 * c->skel.nbones)));
    if (r == SINEW_OK && !(s->pool = sw_pool_create(p->threads)))
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cannot start threads");
    return r;
}

/* Each stage's line in the bake's log (sw_bake_params.progress): its figures. */
static int sum_prepare(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)o;
    snprintf(m, n, "%s", s->c->weights.w ? "asset weights" : "heat-diffusion weights");
    return 1;
}

static int sum_embed(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    const int32_t nr = s->c->render.nverts;
    if (nr == 0) return 0;
    int at = snprintf(m, n,
                      "%d render vertices (%d welded duplicates), %d outside the tets by %.3g at "
                      "most, |barycentric| <= %.3g",
                      nr, o->render_welded, o->render_outside, o->render_max_outside,
                      o->render_max_bary);
    if (o->render_outside > 0 && at > 0 && (size_t)at < n)
        snprintf(m + at, n - (size_t)at,
                 "\nsinew-bake: warning: %d of %d render vertices lie outside the tets: they "
                 "follow the nearest tet's deformation, extrapolated",
                 o->render_outside, nr);
    return 1;
}

static int sum_domains(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)o;
    snprintf(m, n, "%d domains", s->domains.nd);
    return 1;
}

static int sum_poses(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)o;
    int32_t nt = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        nt += s->poses.train[i].npose;
    snprintf(m, n, "%d training poses in %d paths, %d held-out", nt, s->poses.ntrain_seq,
             s->poses.heldout.npose);
    return 1;
}

static int sum_simulate(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    snprintf(m, n,
             "%d training and %d held-out full-space solutions (%d and %d with a contact set "
             "left unsettled by the round cap), %d of them solved, the rest read from the cache",
             o->ntrain, o->nheldout, o->train_unsettled, o->heldout_unsettled, o->simulate_solved);
    return 1;
}

/* " held-out E", or " held-out: no poses" when the bake holds none out (a blob baked on
 * its whole clip): an error over no poses is no figure. */
static const char *heldout_figure(const sw_bake_state *s, double e, char buf[32]) {
    if (s->poses.heldout.npose == 0) return " held-out: no poses";
    snprintf(buf, 32, " held-out %.4f", e);
    return buf;
}

static int sum_basis(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    char h[32];
    snprintf(m, n, "total rank %d, projection error train %.4f%s", s->basis.rank_total,
             o->train_proj_error, heldout_figure(s, o->heldout_proj_error, h));
    return 1;
}

static int sum_cubature(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    int32_t total = 0;
    for (int32_t d = 0; d < s->domains.nd; ++d)
        total += s->cubature.n[d];
    snprintf(m, n, "%d cubature tets, worst fit %.4f", total, o->cubature_error_max);
    return 1;
}

static int sum_contacts(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)o;
    snprintf(m, n, "%d pose-space contact pairs", s->contacts.ncontacts);
    return 1;
}

static int sum_reduce(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    snprintf(m, n, "springs at unit stiffness, mass, inertia, surface (rank %d)",
             o->view.rank_total);
    return 1;
}

static int sum_render(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    if (o->view.nrender_verts == 0) return 0;
    snprintf(m, n, "%d render vertices in %d tets", o->view.nrender_verts, o->view.nembed_tets);
    return 1;
}

static int sum_cond(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    snprintf(m, n, "the tet mesh: %d tets", o->view.ntets);
    return 1;
}

static int sum_pairs(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    snprintf(m, n, "%d groups of domains", o->view.npair_groups);
    return 1;
}

static int sum_springs(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    int at = snprintf(m, n, "springs k = %.4g", o->spring_k);
    for (int32_t k = 0; k < o->nspring_tried && at > 0 && (size_t)at < n; ++k)
        at += snprintf(m + at, n - (size_t)at, "%s%g E h: %.4f", k ? ", " : " (training error at ",
                       o->spring_tried_mult[k], o->spring_tried_err[k]);
    if (o->nspring_tried && at > 0 && (size_t)at < n) snprintf(m + at, n - (size_t)at, ")");
    return 1;
}

static int sum_galerkin(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    char h[32];
    snprintf(m, n, "linearised projection error train %.4f%s", o->train_galerkin_error,
             heldout_figure(s, o->heldout_galerkin_error, h));
    return 1;
}

static int sum_equilibrium(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    (void)s;
    snprintf(m, n, "equilibrium forces at %d of %d training poses", o->force_poses, o->ntrain);
    return 1;
}

static int sum_lod(const sw_bake_state *s, const sw_bake_result *o, char *m, size_t n) {
    int at =
        snprintf(m, n, "pose-space level: %d modes (%.3f of the displacements dropped), ridge %g",
                 o->view.lod_rank, o->lod_kept, o->lod_ridge);
    if (at < 0 || (size_t)at >= n || s->poses.heldout.npose == 0) return 1;
    snprintf(m + at, n - (size_t)at,
             "; held-out surface error by level: full %.4f, reduced %.4f, pose-space %.4f",
             o->lod_heldout[0], o->lod_heldout[1], o->lod_heldout[2]);
    return 1;
}

/* The stages, in order. A stage reads the state groups of the stages before it
 * (bake_state.h) and writes its own group and its part of the result; "view" is the blob
 * view in sw_bake_result, whose sections reduce, render, cond and pairs assemble, and
 * springs and equilibrium complete from their own state (sw_reduce_state.spring,
 * sw_bake_result.view.train_force). Those marked `solutions` (prepare, domains, poses,
 * simulate) are what sw_bake_solutions runs. */
const sw_bake_stage sw_bake_stages[SW_BAKE_NSTAGES] = {
    /* weights (heat diffusion when the asset has none), bone-driven vertices rigid,
       top-4 influences, lumped masses */
    {"prepare", sw_bake_prepare, sum_prepare, 1, "character", "rig"},
    /* the render mesh in the tets right after prepare: a mesh that does not fit fails
       before the long stages (nothing without one) */
    {"embed", sw_bake_embed, sum_embed, 0, "character.render", "embed, render_*"},
    /* each tet to the strongest bone of the majority of its vertices (thesis §2.3) */
    {"domains", sw_bake_domains, sum_domains, 1, "rig", "domains"},
    /* training: joint sweeps, clip frames, the way home, the caller's extra poses;
       held-out: the clip's last frames, held-out clips or random combined poses */
    {"poses", sw_bake_poses, sum_poses, 1, "rig, domains", "poses"},
    /* full-space quasistatic solutions with self-contact on every core, through the cache */
    {"simulate", sw_bake_simulate, sum_simulate, 1, "rig, poses",
     "poses (solutions, contact sets), train_*, heldout_*, mass"},
    /* un-skinned snapshots -> per-domain PCA (thesis eq. 4.13), optional inertia and
       contact modes */
    {"basis", sw_bake_basis, sum_basis, 0, "rig, domains, poses", "basis, *_proj_error"},
    /* per domain on the reduced elastic forces (thesis eqs. 2.11-2.19) */
    {"cubature", sw_bake_cubature, sum_cubature, 0, "rig, domains, poses, basis",
     "cubature, selector_*"},
    /* the training solutions' self-contact pairs for the pose-space contact */
    {"contacts", sw_bake_contacts, sum_contacts, 0, "rig, poses, basis", "contacts"},
    /* interface-spring Hessian at unit stiffness (thesis eq. 4.20), reduced mass,
       inertial projections, the view's reduced sections */
    {"reduce", sw_bake_reduce, sum_reduce, 0, "rig, domains, basis, cubature, contacts",
     "reduce, view"},
    {"render", sw_bake_render, sum_render, 0, "embed, domains, basis, rig", "view (render, asset)"},
    {"cond", sw_bake_cond, sum_cond, 0, "rig, domains, cubature", "view (tet mesh)"},
    {"pairs", sw_bake_pairs, sum_pairs, 0, "rig, domains, basis, poses, view",
     "view (per-pair contact)"},
    /* the springs' stiffness: the caller's, or of sw_bake_spring_mult the one whose blob
       has the lowest training error */
    {"springs", sw_bake_springs, sum_springs, 0, "reduce, view, train_*", "view.spring, spring_*"},
    {"galerkin", sw_bake_galerkin, sum_galerkin, 0, "rig, domains, poses, basis, view",
     "*_galerkin_error"},
    /* the pose-space equilibrium force of every training pose */
    {"equilibrium", sw_bake_equilibrium, sum_equilibrium, 0, "view, train_*",
     "view.train_force, force_poses, model_train_error"},
    /* the pose-space level of detail, then every level's held-out error */
    {"lod", sw_bake_lod, sum_lod, 0, "view, train_*, heldout_*", "view (lod), lod_*"},
};

/* Runs the stages (only those of sw_bake_solutions with `solutions`), timing each into
 * out->stage_seconds and logging its line. */
static sinew_result run_stages(sw_bake_state *s, sw_bake_result *out, int solutions,
                               sw_error *err) {
    for (int i = 0; i < SW_BAKE_NSTAGES; ++i) {
        const sw_bake_stage *st = &sw_bake_stages[i];
        if (solutions && !st->solutions) continue;
        const double t0 = sw_now_seconds();
        sinew_result r = st->run(s, out, err);
        if (r != SINEW_OK) return r;
        out->stage_seconds[i] = sw_now_seconds() - t0;
        char msg[512];
        if (s->p->progress && !solutions && st->summary(s, out, msg, sizeof msg))
            fprintf(stderr, "sinew-bake: %-11s %7.2f s  %s\n", st->name, out->stage_seconds[i],
                    msg);
    }
    return SINEW_OK;
}

sinew_result sw_bake_solutions(const sw_character *c, const sw_bake_params *params,
                               sw_bake_result *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    sw_bake_params p = params ? *params : sw_bake_params_default();
    sw_bake_state s;
    sinew_result r = bake_begin(&s, &p, c, err);
    if (r == SINEW_OK) r = run_stages(&s, out, 1, err);
    sw_bake_state_free(&s);
    if (r != SINEW_OK) sw_bake_result_free(out);
    return r;
}

sinew_result sw_bake(const sw_character *c, const sw_bake_params *params, sw_bake_result *out,
                     sw_error *err) {
    memset(out, 0, sizeof *out);
    sw_bake_params p = params ? *params : sw_bake_params_default();
    sw_bake_state s;
    sinew_result r = bake_begin(&s, &p, c, err);
    /* a plan or a shard: the stages that make the solutions, the simulate stage only
       listing its items or solving a shard's of them */
    if (r == SINEW_OK) r = run_stages(&s, out, p.plan_only || p.shard_count > 0, err);
    sw_bake_state_free(&s);
    if (r != SINEW_OK) sw_bake_result_free(out);
    return r;
}

int sw_bake_ships_whole_clip(const sw_character *c, const sw_bake_params *p) {
    return c && p && !p->ship_split && p->ntrain_clips == 0 && p->nextra_poses == 0 &&
           c->clip.nframes >= 2 && p->heldout_fraction > 0;
}

sinew_result sw_bake_whole_clip(const sw_character *c, const sw_bake_params *params,
                                sw_bake_result *out, sw_error *err) {
    sw_bake_params p = params ? *params : sw_bake_params_default();
    p.heldout_fraction = 0;
    /* the split trains on the way home by default (its held-out frames continue the
       clip): so does the whole clip */
    if (p.return_path < 0) p.return_path = 1;
    p.random_poses = 0;
    return sw_bake(c, &p, out, err);
}
