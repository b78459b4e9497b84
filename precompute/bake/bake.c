/* The bake's orchestration and its first stage (prepare); see bake.h. */
#include "bake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sw_mesh.h"

#include "bake_internal.h"
#include "blob_load.h"
#include "blob_write.h"
#include "fem_corot.h"
#include "weights_heat.h"

sw_bake_params sw_bake_params_default(void) {
    sw_bake_params p;
    memset(&p, 0, sizeof p);
    p.max_rank = 30;
    p.fold_share = 0;
    p.pca_energy = 0.9999;
    p.pca_strain = 0;
    p.cubature_tol = 0.05;
    p.cubature_max = 1000;
    p.selector = SW_CUBATURE_NNHTP;
    p.sweep_samples = 6;
    p.pair_sweeps = -1;
    p.sibling_sweeps = 1;
    p.max_train_frames = 40;
    p.return_path = -1;
    p.pose_force = 1;
    p.inertia_modes = 0;
    p.contact_cubature_tol = 0.05;
    p.heldout_fraction = 0.4;
    p.random_poses = 10;
    p.heldout_steps = 4;
    p.self_contact = 1;
    p.spring_k = 0;
    p.cache_dir = NULL;
    p.threads = 0;
    p.seed = 0x5eed5eedULL;
    p.progress = 0;
    p.on_progress = NULL;
    p.progress_user = NULL;
    return p;
}

void *sw_bake_own(sw_bake_result *out, void *p) {
    if (p && out->nstorage < (int)(sizeof out->storage / sizeof out->storage[0]))
        out->storage[out->nstorage++] = p;
    return p;
}

void sw_bake_result_free(sw_bake_result *r) {
    if (!r) return;
    for (int i = 0; i < r->nstorage; ++i)
        free(r->storage[i]);
    free(r->heldout_x);
    free(r->heldout_T);
    free(r->train_x);
    free(r->train_T);
    free(r->mass);
    free(r->basis_energy);
    free(r->train_clip);
    free(r->train_frame);
    free(r->heldout_clip);
    free(r->heldout_frame);
    memset(r, 0, sizeof *r);
}

void sw_bake_skin_transforms(const sw_bake_state *s, const double *T, double *R, double *t) {
    sw_dualquat dq[SW_MAX_BONES];
    for (int32_t b = 0; b < s->nb; ++b)
        sw_dq_from_transform(T + 12 * b, &dq[b]);
    for (int32_t v = 0; v < s->nv; ++v)
        sw_dqs_blend(dq, s->skin_bone + 4 * v, s->skin_weight + 4 * v, 4, R + 9 * v, t + 3 * v);
}

/* Keeps each vertex's 4 strongest influences, renormalised (the runtime blends 4). */
static void top4(const double *w, int32_t nb, int32_t *ids, double *ws) {
    for (int k = 0; k < 4; ++k) {
        ids[k] = 0;
        ws[k] = 0;
    }
    for (int32_t b = 0; b < nb; ++b) {
        if (!(w[b] > 0)) continue;
        int k = 4;
        while (k > 0 && w[b] > ws[k - 1])
            --k; /* insertion position */
        if (k == 4) continue;
        for (int j = 3; j > k; --j) {
            ids[j] = ids[j - 1];
            ws[j] = ws[j - 1];
        }
        ids[k] = b;
        ws[k] = w[b];
    }
    double sum = ws[0] + ws[1] + ws[2] + ws[3];
    if (sum > 0)
        for (int k = 0; k < 4; ++k)
            ws[k] /= sum;
    else
        ws[0] = 1.0;
}

/* prepare: the bake's own copy of the weights (heat diffusion when asked), one-hot at
 * bone-driven vertices so that skinning moves them exactly with their bone, as the
 * full-space reference does; top-4 influences; lumped masses. */
static sinew_result prepare(sw_bake_state *s, const sw_character *c, int heat, sw_error *err) {
    s->ch = *c;
    s->nv = c->mesh.nverts;
    s->nt = c->mesh.ntets;
    s->nb = c->skel.nbones;
    if (s->nb > SW_MAX_BONES)
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED, "%d bones (at most %d)", s->nb,
                            SW_MAX_BONES);
    size_t nw = (size_t)s->nv * s->nb;
    s->weights = malloc(nw * sizeof(double));
    s->skin_bone = malloc((size_t)s->nv * 4 * sizeof(int32_t));
    s->skin_weight = malloc((size_t)s->nv * 4 * sizeof(double));
    s->mass = calloc((size_t)s->nv, sizeof(double));
    if (!s->weights || !s->skin_bone || !s->skin_weight || !s->mass)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for weights");
    if (heat) {
        sw_weights hw;
        memset(&hw, 0, sizeof hw);
        sinew_result r = sw_weights_heat(&c->mesh, &c->skel, 0, &hw, err);
        if (r != SINEW_OK) return r;
        memcpy(s->weights, hw.w, nw * sizeof(double));
        sw_weights_free(&hw);
    } else {
        memcpy(s->weights, c->weights.w, nw * sizeof(double));
    }
    for (int32_t v = 0; v < s->nv; ++v) {
        int32_t b = c->bone_of_vertex[v];
        double *w = s->weights + (size_t)v * s->nb;
        if (b >= 0)
            for (int32_t k = 0; k < s->nb; ++k)
                w[k] = k == b ? 1.0 : 0.0;
        top4(w, s->nb, s->skin_bone + 4 * v, s->skin_weight + 4 * v);
    }
    s->ch.weights.w = s->weights;
    s->ch.weights.nverts = s->nv;
    s->ch.weights.nbones = s->nb;
    for (int32_t t = 0; t < s->nt; ++t) {
        double Xe[12], Dm[9], vol;
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, c->mesh.X + 3 * (int64_t)c->mesh.tets[4 * t + k], 24);
        if (!sw_tet_rest(Xe, Dm, &vol))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tet %d is degenerate at rest", t);
        sw_lumped_mass_add(c->mesh.tets + 4 * t, c->density, vol, s->mass);
    }
    return SINEW_OK;
}

static void free_state(sw_bake_state *s) {
    pthread_mutex_destroy(&s->progress_lock);
    free(s->weights);
    free(s->sweep_axis);
    free(s->sweep_angle);
    free(s->skin_bone);
    free(s->skin_weight);
    free(s->mass);
    free(s->tet_domain);
    free(s->domain_bone);
    free(s->dom_vert_ptr);
    free(s->dom_verts);
    free(s->dom_tet_ptr);
    free(s->dom_tets);
    free(s->copy_mass);
    free(s->spring_unit);
    for (int32_t i = 0; i < s->ntrain_seq; ++i) {
        free(s->train[i].T);
        free(s->train[i].x);
        free(s->train[i].contact_ptr);
        free(s->train[i].contacts);
        free(s->train[i].clip);
        free(s->train[i].frame);
    }
    free(s->train);
    free(s->heldout.T);
    free(s->heldout.x);
    free(s->heldout.contact_ptr);
    free(s->heldout.contacts);
    free(s->heldout.clip);
    free(s->heldout.frame);
    for (int32_t d = 0; d < s->nd; ++d) {
        if (s->basis) free(s->basis[d]);
        if (s->cub_local) free(s->cub_local[d]);
        if (s->cub_w) free(s->cub_w[d]);
    }
    free(s->basis);
    free(s->rank);
    free(s->train_q);
    free(s->train_pose);
    free(s->contact_ptr);
    free(s->contact_verts);
    free(s->contact_data);
    free(s->cub_n);
    free(s->cub_local);
    free(s->cub_w);
    sw_embedding_free(&s->embed);
    sw_pool_destroy(s->pool);
}

/* Keeps the poses and full-space solutions for evaluation (sinew-bench, the report). */
static sinew_result keep_solutions(const sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    size_t pt = (size_t)12 * s->nb * sizeof(double), px = (size_t)3 * s->nv * sizeof(double);
    out->train_T = malloc((size_t)out->ntrain * pt + 1);
    out->train_x = malloc((size_t)out->ntrain * px + 1);
    out->heldout_T = malloc((size_t)out->nheldout * pt + 1);
    out->heldout_x = malloc((size_t)out->nheldout * px + 1);
    size_t pl = sizeof(int32_t);
    out->train_clip = malloc((size_t)out->ntrain * pl + 1);
    out->train_frame = malloc((size_t)out->ntrain * pl + 1);
    out->heldout_clip = malloc((size_t)out->nheldout * pl + 1);
    out->heldout_frame = malloc((size_t)out->nheldout * pl + 1);
    if (!out->train_T || !out->train_x || !out->heldout_T || !out->heldout_x || !out->train_clip ||
        !out->train_frame || !out->heldout_clip || !out->heldout_frame)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for solutions");
    int32_t k = 0;
    for (int32_t i = 0; i < s->ntrain_seq; ++i)
        for (int32_t j = 0; j < s->train[i].npose; ++j, ++k) {
            memcpy((char *)out->train_T + k * pt, (const char *)s->train[i].T + j * pt, pt);
            memcpy((char *)out->train_x + k * px, (const char *)s->train[i].x + j * px, px);
            out->train_clip[k] = s->train[i].clip[j];
            out->train_frame[k] = s->train[i].frame[j];
        }
    if (out->nheldout) {
        memcpy(out->heldout_T, s->heldout.T, (size_t)out->nheldout * pt);
        memcpy(out->heldout_x, s->heldout.x, (size_t)out->nheldout * px);
        memcpy(out->heldout_clip, s->heldout.clip, (size_t)out->nheldout * pl);
        memcpy(out->heldout_frame, s->heldout.frame, (size_t)out->nheldout * pl);
    }
    return SINEW_OK;
}

void sw_bake_progress_begin(sw_bake_state *s, const char *stage, int64_t total) {
    pthread_mutex_lock(&s->progress_lock);
    s->progress_stage = stage;
    s->progress_total = total;
    s->progress_done = 0;
    s->progress_t0 = sw_now_seconds();
    pthread_mutex_unlock(&s->progress_lock);
}

void sw_bake_progress(sw_bake_state *s, int64_t units) {
    if (!s->p->on_progress) return;
    pthread_mutex_lock(&s->progress_lock); /* the bake's workers, never the frame */
    s->progress_done += units;
    s->p->on_progress(s->p->progress_user, s->progress_stage, s->progress_done, s->progress_total,
                      sw_now_seconds() - s->progress_t0);
    pthread_mutex_unlock(&s->progress_lock);
}

static void progress(const sw_bake_params *p, const char *stage, double secs, const char *what) {
    if (p->progress) fprintf(stderr, "sinew-bake: %-9s %7.2f s  %s\n", stage, secs, what);
}

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

/* The stages poses and simulate, and what the result keeps of them for evaluation. */
static sinew_result solve_poses(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sinew_result r;
    if ((r = sw_bake_poses(s, err)) != SINEW_OK ||
        (r = sw_bake_simulate_cached(s, &out->simulate_cached, err)) != SINEW_OK)
        return r;
    out->simulate_solved = (int32_t)s->solved_poses;
    out->return_poses = s->return_poses;
    out->pair_sweep_poses = s->pair_sweep_poses;
    size_t na = (size_t)s->nb * 3 * sizeof(double);
    if (!(out->sweep_axis = sw_bake_own(out, malloc(na))) ||
        !(out->sweep_angle = sw_bake_own(out, malloc(na / 3))))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    memcpy(out->sweep_axis, s->sweep_axis, na);
    memcpy(out->sweep_angle, s->sweep_angle, na / 3);
    for (int32_t i = 0; i < s->ntrain_seq; ++i) {
        out->ntrain += s->train[i].npose;
        out->train_unsettled += s->train[i].unsettled;
    }
    out->nheldout = s->heldout.npose;
    out->heldout_after = s->heldout.continues ? s->train[0].npose : 0;
    out->heldout_unsettled = s->heldout.unsettled;
    if ((r = keep_solutions(s, out, err)) != SINEW_OK) return r;
    if (!(out->mass = malloc((size_t)s->nv * sizeof(double))))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    memcpy(out->mass, s->mass, (size_t)s->nv * sizeof(double));
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

/* The start of every bake: the parameters checked, the state prepared (weights by heat
 * diffusion when the character has none) and the worker pool started. On an error the
 * caller frees the state (free_state) as after any stage. */
static sinew_result bake_begin(sw_bake_state *s, const sw_bake_params *p, const sw_character *c,
                               sw_error *err) {
    memset(s, 0, sizeof *s);
    pthread_mutex_init(&s->progress_lock, NULL);
    s->p = p;
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
    if (r == SINEW_OK) r = prepare(s, c, c->weights.w == NULL, err);
    if (r == SINEW_OK && !(s->pool = sw_pool_create(p->threads)))
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cannot start threads");
    return r;
}

sinew_result sw_bake_solutions(const sw_character *c, const sw_bake_params *params,
                               sw_bake_result *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    sw_bake_params p = params ? *params : sw_bake_params_default();
    sw_bake_state s;
    sinew_result r = bake_begin(&s, &p, c, err);
    /* the domains first: sibling joints are swept together where their flesh meets */
    if (r == SINEW_OK) r = sw_bake_domains(&s, err);
    if (r == SINEW_OK) r = solve_poses(&s, out, err);
    free_state(&s);
    if (r != SINEW_OK) sw_bake_result_free(out);
    return r;
}

sinew_result sw_bake_errors(const sinew_blob *blob, const sw_bake_result *res,
                            sinew_self_contact sc, sw_eval_result *train, sw_eval_result *heldout,
                            sw_error *err) {
    return sw_bake_errors_frames(blob, res, sc, train, heldout, NULL, NULL, err);
}

double *sw_bake_heldout_path(const sw_bake_result *res, int32_t nbones, int32_t *pre, int32_t *n) {
    *pre = res->heldout_after > 0 && res->heldout_after <= res->ntrain ? res->heldout_after : 0;
    *n = *pre + res->nheldout;
    size_t pt = (size_t)12 * nbones * sizeof(double);
    double *T = malloc((size_t)*n * pt + 1);
    if (T) {
        memcpy(T, res->train_T, (size_t)*pre * pt);
        memcpy((char *)T + (size_t)*pre * pt, res->heldout_T, (size_t)res->nheldout * pt);
    }
    return T;
}

sinew_result sw_bake_train_error(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact sc, sw_eval_result *train, double *train_frames,
                                 sw_error *err) {
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = sc};
    return sw_eval_correction_frames(blob, res->mass, res->train_T, res->train_x, res->ntrain, &o,
                                     train_frames, train, err);
}

sinew_result sw_bake_heldout_error(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_frame_fn on_frame, void *ctx,
                                   sw_eval_result *heldout, double *heldout_frames, sw_error *err) {
    memset(heldout, 0, sizeof *heldout);
    int32_t pre, n;
    double *T = sw_bake_heldout_path(res, sw_blob_get_view(blob)->nbones, &pre, &n);
    if (!T) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .skip = pre,
                         .self_contact = sc,
                         .on_frame = on_frame,
                         .frame_ctx = ctx};
    sinew_result r = sw_eval_correction_frames(blob, res->mass, T, res->heldout_x, n, &o,
                                               heldout_frames, heldout, err);
    free(T);
    return r;
}

sinew_result sw_bake_errors_frames(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_result *train,
                                   sw_eval_result *heldout, double *train_frames,
                                   double *heldout_frames, sw_error *err) {
    memset(train, 0, sizeof *train);
    memset(heldout, 0, sizeof *heldout);
    sinew_result r = sw_bake_train_error(blob, res, sc, train, train_frames, err);
    if (r != SINEW_OK) return r;
    return sw_bake_heldout_error(blob, res, sc, NULL, NULL, heldout, heldout_frames, err);
}

const char *const sw_self_contact_names[SW_BAKE_MODES + 1] = {"pose-space", "exhaustive",
                                                              "pose-pairs", NULL};
const char *const sw_self_contact_keys[SW_BAKE_MODES] = {"pose_space", "exhaustive", "pose_pairs"};

sinew_result sw_bake_mode_errors(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact measured, double measured_err,
                                 double err_mode[SW_BAKE_MODES], sw_error *err) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    for (int k = 0; k < SW_BAKE_MODES; ++k) {
        const sinew_self_contact mode = (sinew_self_contact)k;
        err_mode[k] = NAN;
        if (mode == measured) {
            err_mode[k] = measured_err;
            continue;
        }
        if (mode == SINEW_SELF_CONTACT_POSE_PAIRS && (!v || v->npair_groups == 0))
            continue; /* no per-pair sections: the mode is not available */
        sw_eval_result h;
        sinew_result r = sw_bake_heldout_error(blob, res, mode, NULL, NULL, &h, NULL, err);
        if (r != SINEW_OK) return r;
        if (h.failed == 0 && h.frames > 0) err_mode[k] = h.correction_error;
    }
    return SINEW_OK;
}

sinew_result sw_bake_result_blob(const sw_bake_result *res, void **mem, sinew_blob **blob,
                                 sw_error *err) {
    size_t size = 0;
    *blob = NULL;
    *mem = NULL;
    sinew_result r = sw_blob_write_memory(&res->view, mem, &size, err);
    if (r != SINEW_OK) return r;
    sinew_blob_def d = sinew_blob_def_default();
    d.data = *mem;
    d.data_size = size;
    if ((r = sinew_blob_load(&d, blob)) != SINEW_OK)
        return sw_error_set(err, r, "the bake's blob does not load");
    return SINEW_OK;
}

/* embed: the render mesh in the tets (embed.h), its figures into the report. */
static sinew_result embed_render(sw_bake_state *s, const sw_character *c, sw_bake_result *out,
                                 sw_error *err) {
    sinew_result r = sw_embed_render(&c->mesh, &c->render, &s->embed, err);
    if (r != SINEW_OK) return r;
    out->render_outside = s->embed.outside;
    out->render_welded = s->embed.nwelded;
    out->render_max_outside = s->embed.max_outside;
    out->render_max_bary = s->embed.max_bary;
    out->embed_seconds = s->embed.seconds;
    return SINEW_OK;
}

sinew_result sw_bake(const sw_character *c, const sw_bake_params *params, sw_bake_result *out,
                     sw_error *err) {
    memset(out, 0, sizeof *out);
    sw_bake_params p = params ? *params : sw_bake_params_default();
    sw_bake_state s;
    double t0 = sw_now_seconds(), t1;
    sinew_result r = bake_begin(&s, &p, c, err);
    if (r != SINEW_OK) goto done;
    int heat = c->weights.w == NULL;
    t1 = sw_now_seconds();
    out->stage_seconds[0] = t1 - t0;
    progress(&p, "prepare", t1 - t0, heat ? "heat-diffusion weights" : "asset weights");
    if (c->render.nverts > 0) {
        t0 = t1;
        if ((r = embed_render(&s, c, out, err)) != SINEW_OK) goto done;
        t1 = sw_now_seconds();
        char msg[160];
        snprintf(msg, sizeof msg,
                 "%d render vertices (%d welded duplicates), %d outside the tets by %.3g at "
                 "most, |barycentric| <= %.3g",
                 c->render.nverts, out->render_welded, out->render_outside, out->render_max_outside,
                 out->render_max_bary);
        progress(&p, "embed", t1 - t0, msg);
    }

    t0 = t1;
    if ((r = sw_bake_domains(&s, err)) != SINEW_OK) goto done;
    t1 = sw_now_seconds();
    out->stage_seconds[1] = t1 - t0;
    {
        char msg[64];
        snprintf(msg, sizeof msg, "%d domains", s.nd);
        progress(&p, "domains", t1 - t0, msg);
    }

    t0 = t1;
    if ((r = solve_poses(&s, out, err)) != SINEW_OK) goto done;
    t1 = sw_now_seconds();
    out->stage_seconds[2] = t1 - t0;
    {
        char msg[224];
        snprintf(msg, sizeof msg,
                 "%d training and %d held-out full-space solutions (%d and %d with a contact set "
                 "left unsettled by the round cap), %d of them solved, the rest read from the "
                 "cache",
                 out->ntrain, out->nheldout, out->train_unsettled, out->heldout_unsettled,
                 out->simulate_solved);
        progress(&p, "simulate", t1 - t0, msg);
    }

    t0 = t1;
    if ((r = sw_bake_basis(&s, out, err)) != SINEW_OK) goto done;
    t1 = sw_now_seconds();
    out->stage_seconds[3] = t1 - t0;
    {
        char msg[128];
        snprintf(msg, sizeof msg, "total rank %d, projection error train %.4f held-out %.4f",
                 s.rank_total, out->train_proj_error, out->heldout_proj_error);
        progress(&p, "basis", t1 - t0, msg);
    }

    t0 = t1;
    if ((r = sw_bake_cubature(&s, out, err)) != SINEW_OK) goto done;
    for (int32_t d = 0; d < s.nd; ++d)
        if (s.cub_n[d] < 1) { /* a blob needs one at least: say why here, not at the write */
            r = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                             "domain %d: no cubature tets (rank %d): the training poses do not "
                             "deform it; give a clip that bends its joint",
                             d, s.rank[d]);
            goto done;
        }
    t1 = sw_now_seconds();
    out->stage_seconds[4] = t1 - t0;
    {
        int32_t total = 0;
        for (int32_t d = 0; d < s.nd; ++d)
            total += s.cub_n[d];
        char msg[96];
        snprintf(msg, sizeof msg, "%d cubature tets, worst fit %.4f", total,
                 out->cubature_error_max);
        progress(&p, "cubature", t1 - t0, msg);
    }

    t0 = t1;
    if ((r = sw_bake_contacts(&s, err)) != SINEW_OK ||
        (r = sw_bake_reduce(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_render(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_cond(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_pairs(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_springs(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_galerkin(&s, out, err)) != SINEW_OK ||
        (r = sw_bake_equilibrium(&s, out, err)) != SINEW_OK)
        goto done;
    t1 = sw_now_seconds();
    out->stage_seconds[5] = t1 - t0;
    {
        char msg[320];
        int at = snprintf(msg, sizeof msg, "springs k = %.4g", out->spring_k);
        for (int32_t k = 0; k < out->nspring_tried; ++k) /* the choice: E h multiple: error */
            at += snprintf(msg + at, sizeof msg - (size_t)at, "%s%g E h: %.4f",
                           k ? ", " : " (training error at ", out->spring_tried_mult[k],
                           out->spring_tried_err[k]);
        snprintf(msg + at, sizeof msg - (size_t)at,
                 "%s, mass, inertia, surface, %d pose-space contact pairs, the tet mesh, "
                 "equilibrium forces at %d of %d training poses",
                 out->nspring_tried ? ")" : "", s.ncontacts, out->force_poses, out->ntrain);
        progress(&p, "reduce", t1 - t0, msg);
    }
    r = SINEW_OK;
done:
    free_state(&s);
    if (r != SINEW_OK) sw_bake_result_free(out);
    return r;
}
