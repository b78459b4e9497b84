/* Stage "pairs" (bake.c, sw_bake_stages): reads s->rig, s->domains, s->basis, s->poses, the view;
 * writes the view's per-pair contact sections. */
/* Pose-space self-contact per pair of domains (thesis §3.2.3, DESIGN.md §4.4 and §8): the
 * training poses' contacts grouped by the ordered pair of domains (a, b) holding the
 * contact's vertex and its triangle, a pose feature per group, and a cubature of each
 * pose's pairs of a group.
 *
 * Feature: the thesis's uncentred PCA (6 coordinates) of b's surface in a's frame. Under
 * the bones' rigid motion b's rest points X_i sit at y_i = R X_i + t in a's frame, R, t
 * the relative transform T_bone(a)^-1 T_bone(b), linear in z = [vec(R); t] (12): the
 * snapshots are Y = M Z with M (3n x 12) fixed. Their uncentred PCA is then the
 * eigenproblem of S = G^1/2 Z Z^T G^1/2 (12 x 12) with G = M^T M, and the coordinates of a
 * pose are w_k^T G^1/2 z: the runtime's feature is a 6 x 12 map of z, whatever the size
 * of b. Where the training poses vary along fewer than six directions, the rest are the
 * rigid motions they never made (complete_directions), not LAPACK's arbitrary vectors. The feature
 * is invariant to a rigid motion of the whole character. A domain against itself has no relative
 * motion (z is constant): its groups keep a zero map and the runtime takes their samples from the
 * whole skeleton's nearest poses.
 *
 * Cubature (eqs. 3.9-3.13): per (pose, group), non-negative weights for a few of its pairs
 * whose reduced contact forces at the reference's solution sum to the group's whole
 * reduced contact force within the tolerance: the tet cubature's trainer
 * (cubature_train.h, its greedy selector) with the pairs as candidates. A pair that is apart at the
 * reference's solution carries no force and is left out, as the thesis's cubature does. */
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "cubature_train.h"
#include "penalty.h"

/* The relative transform z = [vec(R); t] of bone b in bone a's frame for transforms T,
 * taken as the step takes it (sw_pose_snap, grid: sw_bake_pose_grid), so that the step at
 * a training pose has its feature bit for bit. */
static void relative_z(const double *T, int32_t a, int32_t b, double grid, double z[12]) {
    double La[12], Lb[12];
    sw_pose_snap(T, T + 12 * (size_t)a, 1, grid, La);
    sw_pose_snap(T, T + 12 * (size_t)b, 1, grid, Lb);
    sw_relative_transform(La, Lb, z);
}

/* Training pose k (in stored order): its sequence, and k's index in it. */
static const sw_pose_seq *train_seq(const sw_bake_state *s, int32_t k, int32_t *j) {
    int32_t i = 0;
    while (k >= s->poses.train[i].npose)
        k -= s->poses.train[i++].npose;
    *j = k;
    return &s->poses.train[i];
}

/* The bone transforms of training pose k. */
static const double *train_T(const sw_bake_state *s, int32_t k) {
    int32_t j;
    const sw_pose_seq *q = train_seq(s, k, &j);
    return q->T + (size_t)j * 12 * s->rig.nb;
}

/* u = G^1/2 z: a relative transform in the coordinates where the surface's mean squared
 * displacement is |u|^2. */
static void whiten(const double Gh[144], const double z[12], double u[12]) {
    for (int i = 0; i < 12; ++i) {
        u[i] = 0;
        for (int j = 0; j < 12; ++j)
            u[i] += Gh[i * 12 + j] * z[j];
    }
}

/* An eigenvalue of the training poses' S below this share of the largest is rounding: the
 * poses do not vary along its direction, and which vector LAPACK returns for it depends
 * on the machine's kernels. */
#define SW_PAIR_FEATURE_RANK_TOL 1e-9

/* Completes W's first `kept` rows (orthonormal) toward six with the rigid motions the
 * training poses never made: b turned about each axis of a's frame, then moved along each
 * (z = [vec(E_k); 0] and [0; e_k], E_k the cross-product matrix of e_k), carried into u =
 * G^1/2 z and made orthogonal to the rows before them in this fixed order. Without them a
 * group whose training poses bend one joint about one axis (a finger's knuckle: S of rank
 * 3) has a feature blind to a twist or a sideways bend, and the novelty test
 * (SW_PAIR_NOVEL) misses poses far from every sample; its remaining PCA directions would
 * be arbitrary. Returns the rows added. */
static int complete_directions(const double Gh[144], double W[6][12], int kept) {
    int added = 0;
    for (int c = 0; c < 6 && kept + added < 6; ++c) {
        double z[12] = {0}, u[12], n0 = 0, n = 0;
        if (c < 3) { /* E_c, row-major: E[r][s] = -eps(c, r, s) */
            int r = (c + 1) % 3, q = (c + 2) % 3;
            z[3 * r + q] = -1;
            z[3 * q + r] = 1;
        } else {
            z[9 + c - 3] = 1;
        }
        whiten(Gh, z, u);
        for (int i = 0; i < 12; ++i)
            n0 += u[i] * u[i];
        for (int k = 0; k < kept + added; ++k) { /* modified Gram-Schmidt */
            double d = 0;
            for (int i = 0; i < 12; ++i)
                d += W[k][i] * u[i];
            for (int i = 0; i < 12; ++i)
                u[i] -= d * W[k][i];
        }
        for (int i = 0; i < 12; ++i)
            n += u[i] * u[i];
        if (!(n > 1e-12 * n0)) continue; /* within the directions already there */
        for (int i = 0; i < 12; ++i)
            W[kept + added][i] = u[i] / sqrt(n);
        added++;
    }
    return added;
}

/* Group g's 6 x 12 feature map (see above) from domain b's rest vertices and the training
 * poses' relative transforms. */
static int feature_map(const sw_bake_state *s, int32_t a, int32_t b, double grid, double *map) {
    double G[144] = {0}, S[144] = {0}, ev[12], H[144], Gh[144];
    memset(map, 0, 72 * sizeof(double));
    if (a == b) return 1;
    const int32_t n = s->domains.dom_vert_ptr[b + 1] - s->domains.dom_vert_ptr[b];
    for (int32_t k = s->domains.dom_vert_ptr[b]; k < s->domains.dom_vert_ptr[b + 1]; ++k) {
        const double *X = s->rig.ch.mesh.X + 3 * (size_t)s->domains.dom_verts[k];
        for (int r = 0; r < 3; ++r) /* y_r = sum_c R_rc X_c + t_r, per coordinate r */
            for (int c = 0; c < 3; ++c) {
                for (int e = 0; e < 3; ++e)
                    G[(3 * r + c) * 12 + 3 * r + e] += X[c] * X[e] / n;
                G[(3 * r + c) * 12 + 9 + r] += X[c] / n;
                G[(9 + r) * 12 + 3 * r + c] += X[c] / n;
            }
    }
    for (int r = 0; r < 3; ++r)
        G[(9 + r) * 12 + 9 + r] = 1;
    /* G^1/2 by its eigenvectors */
    memcpy(H, G, sizeof H);
    openblas_set_num_threads(1);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', 12, H, 12, ev) != 0) return 0;
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) {
            double acc = 0;
            for (int k = 0; k < 12; ++k)
                acc += H[i * 12 + k] * sqrt(fmax(ev[k], 0)) * H[j * 12 + k];
            Gh[i * 12 + j] = acc;
        }
    for (int32_t t = 0; t < s->basis.ntrain; ++t) { /* S = G^1/2 (sum z z^T) G^1/2 */
        double z[12], u[12];
        relative_z(train_T(s, t), s->domains.domain_bone[a], s->domains.domain_bone[b], grid, z);
        whiten(Gh, z, u);
        for (int i = 0; i < 12; ++i)
            for (int j = 0; j < 12; ++j)
                S[i * 12 + j] += u[i] * u[j];
    }
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', 12, S, 12, ev) != 0) return 0;
    double W[6][12]; /* the feature's directions w_k (unit, in u = G^1/2 z) */
    int kept = 0;    /* eigenvalues ascend: the top six that the training poses vary along */
    for (int k = 0; k < 6 && ev[11 - k] > SW_PAIR_FEATURE_RANK_TOL * ev[11]; ++k, ++kept)
        for (int i = 0; i < 12; ++i)
            W[k][i] = S[i * 12 + 11 - k];
    kept += complete_directions(Gh, W, kept);
    for (int k = 0; k < kept; ++k) /* the map's rows w_k^T G^1/2 (rows past `kept` stay 0) */
        for (int j = 0; j < 12; ++j) {
            double acc = 0;
            for (int i = 0; i < 12; ++i)
                acc += W[k][i] * Gh[i * 12 + j];
            map[12 * k + j] = acc;
        }
    return 1;
}

/* Reduced contact force of blob contact c at the reference solution x of a pose (global
 * vertex positions, per-vertex skinning rotations R): into f (rank_total, zeroed first).
 * Returns 0 when the pair is apart there. */
static int pair_force(const sw_bake_state *s, const sw_blob_view *v, int32_t c, const double *x,
                      const double *R, double *f) {
    const int32_t *cv = v->contact_verts + 8 * (size_t)c;
    const double *cd = v->contact_data + 7 * (size_t)c;
    const double coef[4] = {-1.0, cd[0], cd[1], cd[2]};
    int32_t gv[4];
    double d[3] = {0, 0, 0}, n[3], Nd[3];
    for (int m = 0; m < 4; ++m) {
        gv[m] = s->domains.dom_verts[s->domains.dom_vert_ptr[cv[2 * m]] + cv[2 * m + 1]];
        for (int i = 0; i < 3; ++i)
            d[i] += coef[m] * x[3 * (size_t)gv[m] + i];
    }
    const double *Rp = R + 9 * (size_t)gv[0];
    for (int i = 0; i < 3; ++i)
        n[i] = Rp[3 * i] * cd[3] + Rp[3 * i + 1] * cd[4] + Rp[3 * i + 2] * cd[5];
    memset(f, 0, (size_t)s->basis.rank_total * sizeof(double));
    if (!(sw_penalty_gap(n, d) > 0)) return 0;
    sw_penalty_apply_N(n, SW_CONTACT_ALPHA, d, Nd);
    for (int i = 0; i < 3; ++i)
        Nd[i] *= cd[6];
    for (int m = 0; m < 4; ++m) { /* f += coef_m (R_m U_m)^T (ka N d) */
        const int32_t dm = cv[2 * m], r = s->basis.rank[dm];
        const double *Rm = R + 9 * (size_t)gv[m],
                     *U = s->basis.U[dm] + 3 * (size_t)cv[2 * m + 1] * r;
        double w[3]; /* R_m^T ka N d */
        for (int i = 0; i < 3; ++i)
            w[i] = coef[m] * (Rm[i] * Nd[0] + Rm[3 + i] * Nd[1] + Rm[6 + i] * Nd[2]);
        double *fd = f + v->domains[dm].q_offset;
        for (int32_t j = 0; j < r; ++j)
            fd[j] += U[j] * w[0] + U[r + j] * w[1] + U[2 * r + j] * w[2];
    }
    return 1;
}

/* Column `candidate` of a pair cubature's matrix (ctx: A, m rows, column-major). */
typedef struct {
    const double *A;
    int64_t m;
} pair_columns;

static void pair_column(void *ctx, int64_t candidate, double *col) {
    const pair_columns *pc = ctx;
    memcpy(col, pc->A + candidate * pc->m, (size_t)pc->m * sizeof(double));
}

sinew_result sw_bake_pair_cubature(const double *A, int64_t m, int32_t n, double tol, double *w,
                                   sw_error *err) {
    memset(w, 0, (size_t)n * sizeof(double));
    double *b = calloc((size_t)m, sizeof(double));
    if (!b)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for a pair cubature");
    for (int32_t j = 0; j < n; ++j) /* the group's whole reduced force */
        for (int64_t i = 0; i < m; ++i)
            b[i] += A[j * m + i];
    sinew_result r = SINEW_OK;
    if (sw_dot(b, b, m) > 0) { /* (no force: no pair) */
        pair_columns pc = {A, m};
        sw_cubature_problem prob = {m, n, b, pair_column, &pc};
        sw_cubature_params cp = sw_cubature_params_default();
        cp.selector = SW_CUBATURE_GREEDY;
        cp.tol = tol;
        cp.max_points = n;
        cp.candidates = n; /* every pair is a candidate each round: there are few */
        sw_cubature_result cr;
        r = sw_cubature_train(&prob, &cp, &cr, err);
        if (r == SINEW_ERROR_NOT_CONVERGED) r = SINEW_OK; /* every pair kept: the best set */
        for (int32_t k = 0; r == SINEW_OK && k < cr.n; ++k)
            w[cr.ids[k]] = cr.weights[k];
        sw_cubature_result_free(&cr);
    }
    free(b);
    return r;
}

/* The groups: distinct (domain of p, domain of t0) over all contacts, ascending. */
static int32_t *find_groups(const sw_blob_view *v, int32_t *ng) {
    int32_t nd = v->ndomains, *seen = calloc((size_t)nd * nd, sizeof(int32_t)), n = 0;
    int32_t *dom = malloc(((size_t)v->ncontacts + 1) * 2 * sizeof(int32_t));
    if (!seen || !dom) {
        free(seen);
        free(dom);
        return NULL;
    }
    for (int32_t c = 0; c < v->ncontacts; ++c)
        seen[v->contact_verts[8 * (size_t)c] * nd + v->contact_verts[8 * (size_t)c + 2]] = 1;
    for (int32_t i = 0; i < nd * nd; ++i)
        if (seen[i]) dom[2 * n] = i / nd, dom[2 * n + 1] = i % nd, ++n;
    free(seen);
    *ng = n;
    return dom;
}

/* Each group's feature map and every training pose's feature in it; gi[d1 nd + d2] the
 * group of a pair of domains. */
static sinew_result group_features(sw_bake_state *s, const sw_blob_view *v, const int32_t *dom,
                                   int32_t G, int32_t *gi, double *map, double *feat,
                                   sw_error *err) {
    const int32_t nd = v->ndomains, T = v->ntrain;
    const double grid = sw_bake_pose_grid(s);
    for (int32_t g = 0; g < G; ++g) {
        gi[dom[2 * g] * nd + dom[2 * g + 1]] = g;
        if (!feature_map(s, dom[2 * g], dom[2 * g + 1], grid, map + 72 * (size_t)g))
            return sw_error_set(
                err, SINEW_ERROR_NOT_CONVERGED,
                "pose-space pairs: no eigenvectors for the feature of domains %d, %d", dom[2 * g],
                dom[2 * g + 1]);
        for (int32_t t = 0; t < T; ++t) {
            double z[12];
            relative_z(train_T(s, t), s->domains.domain_bone[dom[2 * g]],
                       s->domains.domain_bone[dom[2 * g + 1]], grid, z);
            for (int k = 0; k < 6; ++k)
                feat[6 * ((size_t)g * T + t) + k] = sw_dot(map + 72 * (size_t)g + 12 * k, z, 12);
        }
    }
    return SINEW_OK;
}

/* Each pose's contacts sorted by group in the bake's own copies of the contact arrays (a
 * counting sort keeps their order within one; cv2, cd2 scratch of their size); ptr the
 * (pose, group) ranges. Returns the most contacts of one (pose, group). */
static int32_t sort_by_group(sw_blob_view *v, const int32_t *gi, int32_t G, int32_t *cv2,
                             double *cd2, int32_t *ptr) {
    const int32_t nd = v->ndomains, T = v->ntrain;
    memcpy(cv2, v->contact_verts, (size_t)v->ncontacts * 8 * sizeof(int32_t));
    memcpy(cd2, v->contact_data, (size_t)v->ncontacts * 7 * sizeof(double));
    int32_t *cvo = (int32_t *)v->contact_verts; /* the bake's own copies (sw_bake_reduce) */
    double *cdo = (double *)v->contact_data;
    int32_t most = 0;
    for (int32_t t = 0; t < T; ++t) {
        int32_t at = v->contact_ptr[t];
        for (int32_t g = 0; g < G; ++g) {
            ptr[(size_t)t * G + g] = at;
            for (int32_t c = v->contact_ptr[t]; c < v->contact_ptr[t + 1]; ++c) {
                if (gi[cv2[8 * (size_t)c] * nd + cv2[8 * (size_t)c + 2]] != g) continue;
                memcpy(cvo + 8 * (size_t)at, cv2 + 8 * (size_t)c, 8 * sizeof(int32_t));
                memcpy(cdo + 7 * (size_t)at, cd2 + 7 * (size_t)c, 7 * sizeof(double));
                ++at;
            }
            int32_t cnt = at - ptr[(size_t)t * G + g];
            if (cnt > most) most = cnt;
        }
    }
    ptr[(size_t)G * T] = v->ncontacts;
    return most;
}

/* The cubature of every (pose, group): weights of its pairs that reproduce their reduced
 * force at the reference's solution (every pair at weight 1 without a tolerance). */
static sinew_result pair_weights(sw_bake_state *s, const sw_blob_view *v, int32_t G,
                                 const int32_t *ptr, int32_t most, double *wt, sw_error *err) {
    const int32_t T = v->ntrain, R = v->rank_total;
    const double tol = s->p->contact_cubature_tol;
    double *A = malloc((size_t)R * most * sizeof(double));
    double *Rv = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *tv = malloc((size_t)s->rig.nv * 24);
    sinew_result r = A && Rv && tv ? SINEW_OK
                                   : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                                                  "out of memory for the pose-space pairs");
    for (int32_t t = 0; t < T && r == SINEW_OK; ++t) {
        if (v->contact_ptr[t + 1] == v->contact_ptr[t]) continue;
        int32_t j;
        const double *x = train_seq(s, t, &j)->x + (size_t)j * 3 * s->rig.nv; /* the reference's */
        sw_bake_skin_transforms(s, train_T(s, t), Rv, tv);
        for (int32_t g = 0; g < G && r == SINEW_OK; ++g) {
            int32_t c0 = ptr[(size_t)t * G + g], n = ptr[(size_t)t * G + g + 1] - c0;
            if (n == 0) continue;
            if (tol <= 0) { /* no cubature: every pair at weight 1 */
                for (int32_t c = 0; c < n; ++c)
                    wt[c0 + c] = 1;
                continue;
            }
            for (int32_t c = 0; c < n; ++c)
                pair_force(s, v, c0 + c, x, Rv, A + (size_t)c * R);
            r = sw_bake_pair_cubature(A, R, n, tol, wt + c0, err);
        }
    }
    free(A);
    free(Rv);
    free(tv);
    return r;
}

sinew_result sw_bake_pairs(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    if (v->ncontacts == 0) return SINEW_OK; /* no pose touches itself: no groups */
    const int32_t nd = v->ndomains, T = v->ntrain;
    int32_t G = 0, *dom = find_groups(v, &G);
    int32_t *gi = calloc((size_t)nd * nd, sizeof(int32_t));
    int32_t *cv2 = malloc((size_t)v->ncontacts * 8 * sizeof(int32_t));
    double *cd2 = malloc((size_t)v->ncontacts * 7 * sizeof(double));
    double *map = NULL, *feat = NULL, *wt = NULL;
    int32_t *ptr = NULL, *pd = NULL;
    if (dom && gi && cv2 && cd2) {
        map = sw_bake_own(out, calloc((size_t)G * 72, sizeof(double)));
        feat = sw_bake_own(out, calloc((size_t)G * T * 6, sizeof(double)));
        wt = sw_bake_own(out, calloc((size_t)v->ncontacts, sizeof(double)));
        ptr = sw_bake_own(out, calloc((size_t)G * T + 1, sizeof(int32_t)));
        pd = sw_bake_own(out, malloc((size_t)G * 2 * sizeof(int32_t)));
    }
    sinew_result r = map && feat && wt && ptr && pd
                         ? group_features(s, v, dom, G, gi, map, feat, err)
                         : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                                        "out of memory for the pose-space pairs");
    if (r == SINEW_OK) {
        memcpy(pd, dom, (size_t)G * 2 * sizeof(int32_t));
        r = pair_weights(s, v, G, ptr, sort_by_group(v, gi, G, cv2, cd2, ptr), wt, err);
    }
    if (r == SINEW_OK) {
        v->npair_groups = G;
        v->pair_domains = pd;
        v->pair_map = map;
        v->pair_feature = feat;
        v->pair_ptr = ptr;
        v->pair_weight = wt;
    }
    free(dom);
    free(gi);
    free(cv2);
    free(cd2);
    return r;
}
