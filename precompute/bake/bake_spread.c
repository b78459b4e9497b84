/* How well the bake's held-out references are defined (sw_bake_reference_spread, bake.h;
 * sinew-bake --reference-spread).
 *
 * The reference solves each held-out pose from the solution of the pose before it: a
 * quasistatic equilibrium reached along a path. Where the flesh can rest in more than one
 * equilibrium (a fold that buckles one way or the other, contact that holds or slips), a
 * solve from another start ends elsewhere, and the held-out error then measures which
 * equilibrium the runtime found as much as how well. Three more full-space solves a
 * pose say how much: one from plain skinning (what a simulator that had not walked the
 * path would find), one from the reference itself (a fresh solve there: how far the
 * reference is from a point a solve stays at, its own precision), one from the runtime's
 * own state (the nearest full-space equilibrium to what the runtime shows: if it is the
 * reference, the runtime is simply off; if it is not, the runtime sits in another
 * basin). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "blob_load.h"
#include "instance.h"

typedef struct {
    const double *mass, *T; /* vertex masses; the held-out path (sw_bake_heldout_path) */
    int32_t pre, every, nv, nb;
    sw_fullsim *sim;
    double *xs, *cnt, *xd; /* the runtime's state, its copy counts, plain skinning */
    /* sums over the measured poses of squared mass norms, as sw_eval_acc sums them */
    double runtime, from_skin, from_ref, polished, moved, den;
    int32_t poses, unconverged, failed;
    sw_bake_spread_pose *per_pose; /* room for every measured pose */
} spread_ctx;

/* sum_v m_v |a_v - b_v|^2 */
static double mass_dist2(const double *m, const double *a, const double *b, int32_t nv) {
    double s = 0;
    for (int32_t v = 0; v < nv; ++v)
        for (int k = 0; k < 3; ++k) {
            double d = a[3 * v + k] - b[3 * v + k];
            s += m[v] * d * d;
        }
    return s;
}

/* The full-space solve at pose T from x into *sq (its squared distances to the reference
 * xr and to the runtime's state); 0 when it did not stay finite. */
static int solve_from(spread_ctx *c, const double *T, const double *x, const double *xr,
                      double sq[2]) {
    sw_fullsim_stats st;
    sw_fullsim_set_state(c->sim, T, x, NULL); /* at T: the warm start moves nothing */
    if (sw_fullsim_step(c->sim, T, &st) == SINEW_ERROR_NOT_FINITE) return 0;
    c->unconverged += !st.converged;
    const double *y = sw_fullsim_positions(c->sim);
    sq[0] = mass_dist2(c->mass, y, xr, c->nv);
    sq[1] = mass_dist2(c->mass, y, c->xs, c->nv);
    return 1;
}

static void spread_pose(void *vctx, int32_t pose, const sinew_instance *inst, const double *xr) {
    spread_ctx *c = vctx;
    if ((pose - c->pre) % c->every != c->every - 1) return;
    const double *T = c->T + (size_t)pose * 12 * c->nb;
    sw_instance_full_positions(inst, c->xs, c->cnt); /* what sw_eval_acc measures */
    sw_instance_dqs_positions(inst, c->xd);
    double skin[2], ref[2], pol[2]; /* in this order: each solve's PCG starts from the last */
    if (!solve_from(c, T, c->xd, xr, skin) || !solve_from(c, T, xr, xr, ref) ||
        !solve_from(c, T, c->xs, xr, pol)) {
        c->failed++;
        return;
    }
    double rt = mass_dist2(c->mass, c->xs, xr, c->nv), den = mass_dist2(c->mass, xr, c->xd, c->nv);
    c->from_skin += skin[0];
    c->from_ref += ref[0];
    c->polished += pol[0];
    c->moved += pol[1];
    c->runtime += rt;
    c->den += den;
    /* the pose's own shares (0 where it has no correction to miss, as the bake's frames) */
    double inv = den > 0 ? 1 / den : 0;
    c->per_pose[c->poses] = (sw_bake_spread_pose){.heldout = pose - c->pre,
                                                  .runtime = sqrt(rt * inv),
                                                  .from_skin = sqrt(skin[0] * inv),
                                                  .from_reference = sqrt(ref[0] * inv),
                                                  .polished = sqrt(pol[0] * inv),
                                                  .correction = sqrt(den)};
    c->poses++;
}

sinew_result sw_bake_reference_spread(const sw_character *ch, const sw_bake_params *p,
                                      const sinew_blob *blob, const sw_bake_result *res,
                                      sinew_self_contact sc, int32_t every, sw_bake_spread *out,
                                      sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = blob ? sw_blob_get_view(blob) : NULL;
    if (!ch || !p || !v || !res || !res->mass)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "reference spread: no bake");
    if (every < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "reference spread: every %d-th held-out pose (1 or more)", every);
    if (v->nverts != ch->mesh.nverts || v->nbones != ch->skel.nbones)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "reference spread: the blob has %d vertices and %d bones, the "
                            "character %d and %d",
                            v->nverts, v->nbones, ch->mesh.nverts, ch->skel.nbones);
    spread_ctx c;
    memset(&c, 0, sizeof c);
    c.mass = res->mass;
    c.every = every;
    c.nv = v->nverts;
    c.nb = v->nbones;
    int32_t n;
    double *T = sw_bake_heldout_path(res, c.nb, &c.pre, &n);
    c.T = T;
    size_t n3 = (size_t)c.nv * 3;
    /* the simulator's weights only move the flesh between poses (its warm start), and
       every solve here starts at its own pose: the blob's influences do */
    double *w = calloc((size_t)c.nv * c.nb + 1, sizeof(double));
    c.xs = malloc(n3 * sizeof(double) + 1);
    c.xd = malloc(n3 * sizeof(double) + 1);
    c.cnt = malloc((size_t)c.nv * sizeof(double) + 1);
    out->per_pose = c.per_pose = calloc((size_t)(res->nheldout / every) + 1, sizeof *c.per_pose);
    sinew_result r = SINEW_OK;
    if (!T || !w || !c.xs || !c.xd || !c.cnt || !c.per_pose) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "reference spread: out of memory");
        goto done;
    }
    for (int32_t i = 0; i < c.nv; ++i)
        for (int k = 0; k < SW_BLOB_INFLUENCES; ++k)
            w[(size_t)i * c.nb + v->skin_bone[SW_BLOB_INFLUENCES * i + k]] +=
                v->skin_weight[SW_BLOB_INFLUENCES * i + k];
    sw_character sim_ch = *ch;
    sim_ch.weights.w = w;
    sim_ch.weights.nverts = c.nv;
    sim_ch.weights.nbones = c.nb;
    sw_fullsim_params fp = sw_bake_sim_params(p); /* the reference's own */
    fp.threads = p->threads;
    if ((r = sw_fullsim_create(&sim_ch, &fp, &c.sim, err)) != SINEW_OK) goto done;
    sw_eval_result h;
    r = sw_bake_heldout_error(blob, res, sc, spread_pose, &c, &h, NULL, err);
    if (r == SINEW_OK && c.den > 0) {
        out->poses = c.poses;
        out->runtime = sqrt(c.runtime / c.den);
        out->from_skin = sqrt(c.from_skin / c.den);
        out->from_reference = sqrt(c.from_ref / c.den);
        out->polished = sqrt(c.polished / c.den);
        out->polish_move = sqrt(c.moved / c.den);
    }
    out->unconverged = c.unconverged;
    out->failed = c.failed + h.failed;
done:
    sw_fullsim_destroy(c.sim);
    free(T);
    free(w);
    free(c.xs);
    free(c.xd);
    free(c.cnt);
    if (r != SINEW_OK) sw_bake_spread_free(out);
    return r;
}

void sw_bake_spread_free(sw_bake_spread *s) {
    free(s->per_pose);
    s->per_pose = NULL;
    s->poses = 0;
}
