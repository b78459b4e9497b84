/* An instance of a baked character: the per-frame step (DESIGN.md §3-§4).
 *
 * State is the stacked reduced vector q. Every frame:
 *   1. skin the active vertices (cubature tet corners and output-surface vertices)
 *      with dual quaternions: (R_v, t_v);
 *   2. reduced Newton on  Phi(q) = E_cub(q) + 1/2 q^T H_s q  [+ dynamics terms]:
 *        E_cub = sum_c w_c E_c(x_c(q)),  x_k = R_k (rest_k + U_k q_d) + t_k   (eq. 2.11)
 *        gradient  - sum_c w_c J_c^T f_c,  Hessian  sum_c w_c J_c^T K_c J_c (eq. 2.12)
 *        with J_c = blockdiag(R_k) U_c; H_s the constant interface-spring Hessian;
 *      dense Cholesky, an energy guard (halve the step while Phi grows), warm start;
 *   3. dynamics (backward Euler in q): + 1/(2h^2) |q - q_n - h qdot_n|_M^2
 *        + 1/(2h) |q - q_n|_D^2 - q^T f_in, D = alpha M + beta H(q_n), where f_in are
 *      the inertial forces of each domain riding its bone (frame acceleration, angular
 *      acceleration, centrifugal, Coriolis) from precomputed projections, O(r^2);
 *   4. the output surface: each vertex the mean of its domain copies, and normals.
 * Nothing in the step allocates, locks or touches a vertex that is not active: the
 * cost depends on the cubature and surface sizes, not on the tet count. All memory is
 * reserved at creation through the allocator hook. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "dense.h"
#include "dqs.h"
#include "fem_corot.h"
#include "instance.h"
#include "penalty.h"

/* ranks per domain are validated <= SW_BLOB_MAX_RANK by the loader */
#define SW_BLOB_MAX_RANK_STEP SW_BLOB_MAX_RANK

struct sinew_instance {
    const sinew_blob *blob;
    const sw_blob_view *v;
    sinew_allocator allocator;
    sinew_step_mode mode;
    uint32_t max_newton;
    int32_t R, rmax, nact;
    double size; /* rest bounding-box diagonal */
    /* pose */
    sw_dualquat *bone_dq;             /* nbones */
    double *T_cur, *T_prev, *T_prev2; /* 12 nbones each */
    int pose_set, history;            /* frames of pose history available (0..2) */
    int looked_up;                    /* feature_last holds a pose */
    /* active vertices */
    int32_t *act_vert; /* nact global ids */
    int32_t *cub_act;  /* 4 ncub */
    int32_t *copy_act; /* nsurf_copies */
    double *act_R, *act_t;
    /* reduced state and scratch */
    double *q, *qn, *qdot, *g, *H, *Hn, *L, *dq, *qtrial, *fin, *tmp, *tmp2;
    double *Je; /* 12 x rmax: the Jacobian of one cubature tet */
    /* output */
    double *surf_x, *surf_n;
    double *feature;      /* 4 nbones: the current pose's feature */
    int32_t *contact_act; /* 4 per pose-space contact: active index of p, t0, t1, t2 */
    double *Jc, *hc;      /* 4 x 3 x rmax each: one contact's Jacobians, and N G */
    int32_t nearest;      /* training pose nearest to the current pose, or -1 */
    int32_t second;       /* the second nearest, or -1 */
    double blend;         /* pose-space weight of `second` (0: `nearest` alone) */
    double *feature_last; /* 4 nbones: the pose feature of the last lookup */
    double *motion;       /* 4 nbones: the last change of pose between two lookups */
    int32_t *twin_next;   /* ntrain: the next training pose storing the same pose (a
                             cycle over its branches; itself when it has one) */
    double *svd_V;        /* 9 per cubature tet: last SVD rotation (warm start) */
    int32_t *blk_off, *blk_size, *blk_order; /* domain blocks of H, leaves first */
    int32_t *blk_pos;                        /* domain -> its place in blk_order */
    unsigned char *blk_nz;                   /* ndomains^2 scratch of the factorisation */
    unsigned char *blk_adj;                  /* ndomains^2: spring-coupled domain pairs */
    sinew_step_stats stats;
};

/* ---- memory ------------------------------------------------------------------ */

static void *mem_alloc(const sinew_allocator *a, size_t size) {
    if (size == 0) size = 1;
    size = (size + 63) & ~(size_t)63;
    void *p = NULL;
    if (a->alloc)
        p = a->alloc(size, 64, a->user);
    else if (posix_memalign(&p, 64, size) != 0)
        p = NULL;
    if (p) memset(p, 0, size);
    return p;
}

static void mem_free(const sinew_allocator *a, void *p) {
    if (!p) return;
    if (a->free)
        a->free(p, a->user);
    else
        free(p);
}

/* The instance's arrays, listed once for allocation and release. */
enum { NBUF = 38 };
static void buffers(sinew_instance *in, void **b[NBUF], size_t sz[NBUF]) {
    const sw_blob_view *v = in->v;
    size_t R = (size_t)in->R, nb = (size_t)v->nbones, d = sizeof(double);
    void **p[NBUF] = {(void **)&in->bone_dq,  (void **)&in->T_cur,       (void **)&in->T_prev,
                      (void **)&in->T_prev2,  (void **)&in->act_vert,    (void **)&in->cub_act,
                      (void **)&in->copy_act, (void **)&in->act_R,       (void **)&in->act_t,
                      (void **)&in->q,        (void **)&in->qn,          (void **)&in->qdot,
                      (void **)&in->g,        (void **)&in->H,           (void **)&in->Hn,
                      (void **)&in->L,        (void **)&in->dq,          (void **)&in->qtrial,
                      (void **)&in->fin,      (void **)&in->tmp,         (void **)&in->tmp2,
                      (void **)&in->Je,       (void **)&in->surf_x,      (void **)&in->surf_n,
                      (void **)&in->feature,  (void **)&in->contact_act, (void **)&in->Jc,
                      (void **)&in->hc,       (void **)&in->svd_V,       (void **)&in->blk_off,
                      (void **)&in->blk_size, (void **)&in->blk_order,   (void **)&in->blk_nz,
                      (void **)&in->blk_adj,  (void **)&in->blk_pos,     (void **)&in->feature_last,
                      (void **)&in->motion,   (void **)&in->twin_next};
    size_t s[NBUF] = {nb * sizeof(sw_dualquat),
                      12 * nb * d,
                      12 * nb * d,
                      12 * nb * d,
                      (size_t)in->nact * sizeof(int32_t),
                      4 * (size_t)v->ncub * sizeof(int32_t),
                      (size_t)v->nsurf_copies * sizeof(int32_t),
                      9 * (size_t)in->nact * d,
                      3 * (size_t)in->nact * d,
                      R * d,
                      R * d,
                      R * d,
                      R * d,
                      R * R * d,
                      R * R * d,
                      R * R * d,
                      R * d,
                      R * d,
                      R * d,
                      R * d,
                      R * d,
                      12 * (size_t)in->rmax * d,
                      3 * (size_t)v->nsurf_verts * d,
                      3 * (size_t)v->nsurf_verts * d,
                      4 * nb * d,
                      4 * (size_t)v->ncontacts * sizeof(int32_t),
                      12 * (size_t)in->rmax * d,
                      12 * (size_t)in->rmax * d,
                      9 * (size_t)v->ncub * d,
                      (size_t)v->ndomains * sizeof(int32_t),
                      (size_t)v->ndomains * sizeof(int32_t),
                      (size_t)v->ndomains * sizeof(int32_t),
                      (size_t)v->ndomains * (size_t)v->ndomains,
                      (size_t)v->ndomains * (size_t)v->ndomains,
                      (size_t)v->ndomains * sizeof(int32_t),
                      4 * nb * d,
                      4 * nb * d,
                      (size_t)v->ntrain * sizeof(int32_t)};
    memcpy(b, p, sizeof p);
    memcpy(sz, s, sizeof s);
}

/* ---- creation ----------------------------------------------------------------- */

static void identity_pose(double *T, int32_t nb) {
    for (int32_t b = 0; b < nb; ++b) {
        memset(T + 12 * b, 0, 12 * sizeof(double));
        T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
    }
}

/* twin_next: links the training poses stored more than once (one per branch of the
 * reference's path: on its return path a fold that buckled on the way in may stay
 * buckled on the way out) into cycles in stored order, once at creation. */
static void link_twins(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    size_t f = (size_t)4 * v->nbones;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        int32_t next = t;
        for (int32_t k = 1; k < v->ntrain && next == t; ++k) { /* t+1, ..., wrapping round */
            int32_t u = (t + k) % v->ntrain;
            if (sw_pose_distance(v->train_pose + f * t, v->train_pose + f * u, v->nbones) <= 1e-14)
                next = u;
        }
        in->twin_next[t] = next;
    }
}

/* Elimination order of the domain blocks: repeatedly the block with the fewest
 * remaining neighbours (ties: lower index), connecting its neighbours (fill). The block
 * graph comes from the spring Hessian's nonzero blocks. adj: nd*nd scratch. */
static void block_order_min_degree(const sw_blob_view *v, const int32_t *off, const int32_t *size,
                                   unsigned char *springs, unsigned char *adj, int32_t *order) {
    int32_t nd = v->ndomains, R = v->rank_total;
    for (int32_t i = 0; i < nd; ++i)
        for (int32_t j = 0; j < nd; ++j) {
            int any = 0;
            for (int32_t r = 0; r < size[i] && !any && i != j; ++r)
                for (int32_t c = 0; c < size[j]; ++c)
                    if (v->spring_hessian[(int64_t)(off[i] + r) * R + off[j] + c] != 0.0) {
                        any = 1;
                        break;
                    }
            adj[i * nd + j] = springs[i * nd + j] = (unsigned char)any;
        }
    /* 2: eliminated */
    for (int32_t step = 0; step < nd; ++step) {
        int32_t best = -1, bestdeg = 0;
        for (int32_t i = 0; i < nd; ++i) {
            if (adj[i * nd + i] == 2) continue;
            int32_t deg = 0;
            for (int32_t j = 0; j < nd; ++j)
                deg += j != i && adj[i * nd + j] == 1 && adj[j * nd + j] != 2;
            if (best < 0 || deg < bestdeg) best = i, bestdeg = deg;
        }
        order[step] = best;
        for (int32_t j = 0; j < nd; ++j) /* neighbours of best become a clique */
            for (int32_t k = 0; k < nd; ++k)
                if (j != k && adj[best * nd + j] == 1 && adj[best * nd + k] == 1 &&
                    adj[j * nd + j] != 2 && adj[k * nd + k] != 2)
                    adj[j * nd + k] = 1;
        adj[best * nd + best] = 2;
    }
}

SINEW_API void sinew_instance_destroy(sinew_instance *inst) {
    if (!inst) return;
    void **b[NBUF];
    size_t sz[NBUF];
    buffers(inst, b, sz);
    sinew_allocator a = inst->allocator;
    for (int i = 0; i < NBUF; ++i)
        mem_free(&a, *b[i]);
    mem_free(&a, inst);
}

SINEW_API sinew_result sinew_instance_create(const sinew_blob *blob, const sinew_instance_def *def,
                                             sinew_instance **out) {
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance_def d = sinew_instance_def_default();
    if (def) {
        if (def->struct_size < sizeof(uint32_t) + sizeof(sinew_step_mode) ||
            def->struct_size > 4096)
            return SINEW_ERROR_INVALID_ARGUMENT;
        memcpy(&d, def, def->struct_size < sizeof d ? def->struct_size : sizeof d);
        d.struct_size = sizeof d;
    }
    if (d.mode != SINEW_STEP_QUASISTATIC && d.mode != SINEW_STEP_DYNAMIC)
        return SINEW_ERROR_INVALID_ARGUMENT;
    if (d.max_newton_iters > 100) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_allocator a = d.allocator;
    if (!a.alloc != !a.free) return SINEW_ERROR_INVALID_ARGUMENT;
    if (!a.alloc) a = blob->allocator;

    sinew_instance *in = mem_alloc(&a, sizeof *in);
    if (!in) return SINEW_ERROR_OUT_OF_MEMORY;
    in->blob = blob;
    in->v = v;
    in->allocator = a;
    in->mode = d.mode;
    in->max_newton = d.max_newton_iters ? d.max_newton_iters : 5;
    in->R = v->rank_total;
    for (int32_t k = 0; k < v->ndomains; ++k)
        if (v->domains[k].rank > in->rmax) in->rmax = v->domains[k].rank;
    /* active vertices: cubature corners and surface copies (a mark pass at creation) */
    int32_t *mark = mem_alloc(&a, (size_t)v->nverts * sizeof(int32_t));
    if (!mark) {
        mem_free(&a, in);
        return SINEW_ERROR_OUT_OF_MEMORY;
    }
    for (int32_t i = 0; i < v->nverts; ++i)
        mark[i] = -1;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c)
            for (int j = 0; j < 4; ++j)
                mark[v->domain_verts[D->vert_begin + v->cub_tets[4 * c + j]]] = 0;
    }
    for (int32_t i = 0; i < v->nsurf_copies; ++i) {
        const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
        mark[v->domain_verts[D->vert_begin + v->surf_copies[2 * i + 1]]] = 0;
    }
    for (int32_t c = 0; c < v->ncontacts; ++c)
        for (int k = 0; k < 4; ++k) {
            const sw_blob_domain *D = &v->domains[v->contact_verts[8 * c + 2 * k]];
            mark[v->domain_verts[D->vert_begin + v->contact_verts[8 * c + 2 * k + 1]]] = 0;
        }
    for (int32_t i = 0; i < v->nverts; ++i)
        if (mark[i] == 0) mark[i] = in->nact++;
    void **b[NBUF];
    size_t sz[NBUF];
    buffers(in, b, sz);
    int ok = 1;
    for (int i = 0; i < NBUF; ++i)
        ok = ok && (*b[i] = mem_alloc(&a, sz[i])) != NULL;
    if (!ok) {
        mem_free(&a, mark);
        sinew_instance_destroy(in);
        return SINEW_ERROR_OUT_OF_MEMORY;
    }
    for (int32_t i = 0; i < v->nverts; ++i)
        if (mark[i] >= 0) in->act_vert[mark[i]] = i;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c)
            for (int j = 0; j < 4; ++j)
                in->cub_act[4 * c + j] =
                    mark[v->domain_verts[D->vert_begin + v->cub_tets[4 * c + j]]];
    }
    for (int32_t i = 0; i < v->nsurf_copies; ++i) {
        const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
        in->copy_act[i] = mark[v->domain_verts[D->vert_begin + v->surf_copies[2 * i + 1]]];
    }
    for (int32_t c = 0; c < v->ncontacts; ++c)
        for (int k = 0; k < 4; ++k) {
            const sw_blob_domain *D = &v->domains[v->contact_verts[8 * c + 2 * k]];
            in->contact_act[4 * c + k] =
                mark[v->domain_verts[D->vert_begin + v->contact_verts[8 * c + 2 * k + 1]]];
        }
    mem_free(&a, mark);
    /* H's domain blocks and their elimination order: greedy minimum degree on the block
     * graph of the interface springs (with the fill it creates). Springs follow the
     * skeleton, but vertices shared by three or more domains couple siblings too. */
    for (int32_t k = 0; k < v->ndomains; ++k) {
        in->blk_off[k] = v->domains[k].q_offset;
        in->blk_size[k] = v->domains[k].rank;
    }
    block_order_min_degree(v, in->blk_off, in->blk_size, in->blk_adj, in->blk_nz, in->blk_order);
    for (int32_t e = 0; e < v->ndomains; ++e)
        in->blk_pos[in->blk_order[e]] = e;
    link_twins(in);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < v->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], v->rest[3 * i + k]);
            hi[k] = fmax(hi[k], v->rest[3 * i + k]);
        }
    in->size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
    sinew_instance_reset(in);
    *out = in;
    return SINEW_OK;
}

SINEW_API sinew_result sinew_instance_reset(sinew_instance *inst) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    int32_t R = inst->R, nb = inst->v->nbones;
    memset(inst->q, 0, (size_t)R * sizeof(double));
    memset(inst->qdot, 0, (size_t)R * sizeof(double));
    identity_pose(inst->T_cur, nb);
    memcpy(inst->T_prev, inst->T_cur, 12 * (size_t)nb * sizeof(double));
    memcpy(inst->T_prev2, inst->T_cur, 12 * (size_t)nb * sizeof(double));
    for (int32_t b = 0; b < nb; ++b)
        sw_dq_from_transform(inst->T_cur + 12 * b, &inst->bone_dq[b]);
    inst->pose_set = 0;
    inst->history = 0;
    inst->nearest = inst->second = -1;
    inst->blend = 0;
    inst->looked_up = 0; /* no motion yet: a pose on two branches takes the first stored */
    memset(inst->motion, 0, 4 * (size_t)nb * sizeof(double));
    for (int32_t c = 0; c < inst->v->ncub; ++c) { /* identity: a cold start */
        double *V = inst->svd_V + 9 * (int64_t)c;
        memset(V, 0, 9 * sizeof(double));
        V[0] = V[4] = V[8] = 1;
    }
    memset(&inst->stats, 0, sizeof inst->stats);
    inst->stats.struct_size = sizeof inst->stats;
    return SINEW_OK;
}

/* ---- pose ---------------------------------------------------------------------- */

/* A bone transform must be finite (else NOT_FINITE) with a proper orthonormal rotation
 * part (else INVALID_ARGUMENT). */
static sinew_result check_transform(const double *T) {
    for (int i = 0; i < 12; ++i)
        if (!isfinite(T[i])) return SINEW_ERROR_NOT_FINITE;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = T[i] * T[j] + T[3 + i] * T[3 + j] + T[6 + i] * T[6 + j];
            if (fabs(d - (i == j)) > 1e-3) return SINEW_ERROR_INVALID_ARGUMENT;
        }
    double det = T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                 T[2] * (T[3] * T[7] - T[4] * T[6]);
    return det > 0 ? SINEW_OK : SINEW_ERROR_INVALID_ARGUMENT;
}

/* Accepts the pose (all bones valid) or leaves everything as it was. */
static sinew_result set_pose(sinew_instance *inst, const double *Td, const float *Tf) {
    int32_t nb = inst->v->nbones;
    for (int32_t b = 0; b < nb; ++b) {
        double T[12];
        for (int i = 0; i < 12; ++i)
            T[i] = Td ? Td[12 * b + i] : (double)Tf[12 * b + i];
        sinew_result r = check_transform(T);
        if (r != SINEW_OK) return r;
    }
    for (int32_t i = 0; i < 12 * nb; ++i)
        inst->T_cur[i] = Td ? Td[i] : (double)Tf[i];
    for (int32_t b = 0; b < nb; ++b)
        sw_dq_from_transform(inst->T_cur + 12 * b, &inst->bone_dq[b]);
    inst->pose_set = 1;
    return SINEW_OK;
}

sinew_result sw_instance_set_pose_d(sinew_instance *inst, const double *T) {
    if (!inst || !T) return SINEW_ERROR_INVALID_ARGUMENT;
    return set_pose(inst, T, NULL);
}

SINEW_API sinew_result sinew_instance_set_pose(sinew_instance *inst, const float *transforms,
                                               uint32_t bone_count) {
    if (!inst || !transforms || bone_count != (uint32_t)inst->v->nbones)
        return SINEW_ERROR_INVALID_ARGUMENT;
    return set_pose(inst, NULL, transforms);
}

/* ---- the reduced model ---------------------------------------------------------- */

static void skin_active(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    for (int32_t a = 0; a < in->nact; ++a) {
        int32_t gv = in->act_vert[a];
        sw_dqs_blend(in->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4,
                     in->act_R + 9 * a, in->act_t + 3 * a);
    }
}

/* Position of copy (domain D, local vertex lv, active index a) for reduced q_d;
 * also J = R U (3 x r, row-major) when J != NULL. */
static void copy_position(const sinew_instance *in, const sw_blob_domain *D, int32_t lv, int32_t a,
                          const double *qd, double x[3], double *J) {
    const sw_blob_view *v = in->v;
    int32_t r = D->rank, gv = v->domain_verts[D->vert_begin + lv];
    const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r;
    const double *Rm = in->act_R + 9 * a, *t = in->act_t + 3 * a, *X = v->rest + 3 * (int64_t)gv;
    double y[3];
    for (int i = 0; i < 3; ++i) {
        double acc = X[i];
        for (int32_t j = 0; j < r; ++j)
            acc += U[i * r + j] * qd[j];
        y[i] = acc;
    }
    for (int i = 0; i < 3; ++i)
        x[i] = Rm[3 * i] * y[0] + Rm[3 * i + 1] * y[1] + Rm[3 * i + 2] * y[2] + t[i];
    if (J)
        for (int i = 0; i < 3; ++i)
            for (int32_t j = 0; j < r; ++j)
                J[i * r + j] =
                    Rm[3 * i] * U[j] + Rm[3 * i + 1] * U[r + j] + Rm[3 * i + 2] * U[2 * r + j];
}

/* Cubature energy at q; with want_grad, adds -sum w J^T f to g; with want_hess, adds the
 * domain blocks sum w J^T K J to H (both must be initialised by the caller). */
static double cubature_eval(sinew_instance *in, const double *q, int want_grad, int want_hess) {
    const sw_blob_view *v = in->v;
    double E = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank, o = D->q_offset;
        const double *qd = q + o;
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c) {
            double x[12], f[12], wm[9], gm[108], h[SW_BLOB_MAX_RANK_STEP];
            for (int j = 0; j < 4; ++j)
                copy_position(in, D, v->cub_tets[4 * c + j], in->cub_act[4 * c + j], qd, x + 3 * j,
                              want_grad ? in->Je + 3 * j * r : NULL);
            double w = v->cub_weight[c];
            E += w * sw_corot_eval_modes(x, v->cub_dminv + 9 * c, v->cub_vol[c], v->mu, v->lambda,
                                         want_grad ? f : NULL, want_hess ? wm : NULL, gm,
                                         in->svd_V + 9 * (int64_t)c, SW_COROT_PROJECT_PSD);
            if (!want_grad) continue;
            for (int32_t j = 0; j < r; ++j) {
                double acc = 0;
                for (int row = 0; row < 12; ++row)
                    acc += in->Je[row * r + j] * f[row];
                in->g[o + j] -= w * acc;
            }
            if (!want_hess) continue;
            /* eq. 2.12 through the element's modes: J^T K J = sum_k w_k (J^T g_k)(J^T g_k)^T */
            for (int k = 0; k < 9; ++k) {
                if (wm[k] == 0.0) continue;
                const double *gk = gm + 12 * k;
                for (int32_t j = 0; j < r; ++j) {
                    double acc = 0;
                    for (int row = 0; row < 12; ++row)
                        acc += in->Je[row * r + j] * gk[row];
                    h[j] = acc;
                }
                double wk = w * wm[k];
                for (int32_t i = 0; i < r; ++i) {
                    double *Hi = in->H + (int64_t)(o + i) * in->R + o, hi = wk * h[i];
                    for (int32_t j = i; j < r; ++j)
                        Hi[j] += hi * h[j];
                }
            }
        }
    }
    /* the domain blocks were filled in their upper triangle: mirror */
    if (want_hess)
        for (int32_t k = 0; k < v->ndomains; ++k) {
            const sw_blob_domain *D = &v->domains[k];
            int32_t o = D->q_offset;
            for (int32_t i = 0; i < D->rank; ++i)
                for (int32_t j = i + 1; j < D->rank; ++j)
                    in->H[(int64_t)(o + j) * in->R + o + i] =
                        in->H[(int64_t)(o + i) * in->R + o + j];
        }
    return E;
}

/* Pose-space self-contact (blob_view.h, thesis eqs. 3.4-3.6 and §3.2.3): the nearest
 * training pose's pairs, each the reference's penalty E = 1/2 k ka d^T N d with
 * d = sum b_i x_ti - x_p, N = (1 - alpha) n n^T + alpha I and n = R_p n_rest, applied
 * while the pair collides (the Heaviside of eq. 3.12: p behind the triangle along n).
 * Per pair the slots of one domain are summed into G_d = sum coef_m J_m (3 x r_d), so
 * the gradient is k ka G_d^T N d and the Hessian blocks k ka G_a^T N G_b, which may
 * couple two domains. Added after the cubature so it lands on the full (mirrored)
 * matrix. */
static double contact_pairs(sinew_instance *in, int32_t pose, double weight, const double *q,
                            int want_grad, int want_hess) {
    const sw_blob_view *v = in->v;
    double E = 0, k = weight * v->contact_k, al = SW_CONTACT_ALPHA;
    int32_t rm = in->rmax;
    for (int32_t c = v->contact_ptr[pose]; c < v->contact_ptr[pose + 1]; ++c) {
        const int32_t *cv = v->contact_verts + 8 * (int64_t)c;
        const double *cd = v->contact_data + 7 * (int64_t)c;
        const double coef[4] = {-1.0, cd[0], cd[1], cd[2]};
        const sw_blob_domain *D[4];
        double x[4][3], d[3] = {0, 0, 0};
        for (int m = 0; m < 4; ++m) {
            D[m] = &v->domains[cv[2 * m]];
            copy_position(in, D[m], cv[2 * m + 1], in->contact_act[4 * c + m], q + D[m]->q_offset,
                          x[m], want_grad ? in->Jc + 3 * m * rm : NULL);
            for (int i = 0; i < 3; ++i)
                d[i] += coef[m] * x[m][i];
        }
        const double *Rp = in->act_R + 9 * in->contact_act[4 * c];
        double n[3], g = 0;
        for (int i = 0; i < 3; ++i)
            n[i] = Rp[3 * i] * cd[3] + Rp[3 * i + 1] * cd[4] + Rp[3 * i + 2] * cd[5];
        for (int i = 0; i < 3; ++i)
            g += n[i] * d[i];
        if (!(g > 0)) continue;
        double kk = k * cd[6], Nd[3];
        for (int i = 0; i < 3; ++i)
            Nd[i] = al * d[i] + (1 - al) * g * n[i];
        E += 0.5 * kk * (d[0] * Nd[0] + d[1] * Nd[1] + d[2] * Nd[2]);
        if (!want_grad) continue;
        /* G per distinct domain (slot `lead[m]` holds the sum of its domain's slots) */
        int lead[4], nlead = 0, leads[4];
        for (int m = 0; m < 4; ++m) {
            int32_t r = D[m]->rank;
            double *Jm = in->Jc + 3 * m * rm;
            lead[m] = m;
            for (int l = 0; l < nlead; ++l)
                if (D[leads[l]] == D[m]) lead[m] = leads[l];
            if (lead[m] == m) {
                leads[nlead++] = m;
                for (int32_t j = 0; j < 3 * r; ++j)
                    Jm[j] *= coef[m];
            } else {
                double *Jl = in->Jc + 3 * lead[m] * rm;
                for (int32_t j = 0; j < 3 * r; ++j)
                    Jl[j] += coef[m] * Jm[j];
            }
        }
        for (int l = 0; l < nlead; ++l) {
            const sw_blob_domain *Dl = D[leads[l]];
            int32_t r = Dl->rank;
            const double *G = in->Jc + 3 * leads[l] * rm;
            double *P = in->hc + 3 * l * rm; /* N G */
            for (int32_t j = 0; j < r; ++j) {
                double gn = n[0] * G[j] + n[1] * G[r + j] + n[2] * G[2 * r + j];
                for (int i = 0; i < 3; ++i)
                    P[i * r + j] = al * G[i * r + j] + (1 - al) * n[i] * gn;
                in->g[Dl->q_offset + j] +=
                    kk * (G[j] * Nd[0] + G[r + j] * Nd[1] + G[2 * r + j] * Nd[2]);
            }
        }
        if (!want_hess) continue;
        for (int a = 0; a < nlead; ++a)
            for (int b = 0; b < nlead; ++b) {
                const sw_blob_domain *Da = D[leads[a]], *Db = D[leads[b]];
                int32_t ra = Da->rank, rb = Db->rank;
                const double *Ga = in->Jc + 3 * leads[a] * rm, *Pb = in->hc + 3 * b * rm;
                for (int32_t i = 0; i < ra; ++i) {
                    double *Hi = in->H + (int64_t)(Da->q_offset + i) * in->R + Db->q_offset;
                    double g0 = kk * Ga[i], g1 = kk * Ga[ra + i], g2 = kk * Ga[2 * ra + i];
                    for (int32_t j = 0; j < rb; ++j)
                        Hi[j] += g0 * Pb[j] + g1 * Pb[rb + j] + g2 * Pb[2 * rb + j];
                }
            }
    }
    return E;
}

/* The contact pairs of the two nearest training poses with their pose-space blend
 * weights (DESIGN.md §8, thesis §3.2.3: the two schemes' forces interpolated). */
static double contact_eval(sinew_instance *in, const double *q, int want_grad, int want_hess) {
    if (in->nearest < 0) return 0;
    double E = contact_pairs(in, in->nearest, 1 - in->blend, q, want_grad, want_hess);
    if (in->blend > 0) E += contact_pairs(in, in->second, in->blend, q, want_grad, want_hess);
    return E;
}

/* Training pose t is stored on the branch cycle of u (the same pose: the bake stores a
 * pose once per branch of the reference's path, twin_next). */
static int same_pose(const sinew_instance *in, int32_t t, int32_t u) {
    if (u < 0) return 0;
    int32_t w = u;
    do {
        if (w == t) return 1;
        w = in->twin_next[w];
    } while (w != u);
    return 0;
}

/* Of the branches stored for training pose `rep`, the one the instance is on. The
 * bake solved the training poses in the order it stored them, each from the one before
 * (a path, blob_view.h), so a stored pose's arrival direction is its feature minus
 * its predecessor's: on the way into a bend or on the way out. The branch whose
 * arrival is most aligned with the instance's own last motion wins (the first stored
 * on a tie, e.g. before the pose ever moved): a fold that buckled while the joint
 * bent stays buckled while it unbends. */
static int32_t pick_branch(const sinew_instance *in, int32_t rep) {
    const sw_blob_view *v = in->v;
    size_t f = (size_t)4 * v->nbones;
    int32_t best = rep, t = rep;
    double best_s = -INFINITY;
    do { /* rep's branches, from rep round its cycle */
        double s = 0, n = 0;
        for (size_t i = 0; t > 0 && i < f; ++i) {
            double a = v->train_pose[f * t + i] - v->train_pose[f * (t - 1) + i];
            s += a * in->motion[i];
            n += a * a;
        }
        s = n > 0 ? s / sqrt(n) : 0;
        if (s > best_s || (s == best_s && t < best)) best_s = s, best = t;
        t = in->twin_next[t];
    } while (t != rep);
    return best;
}

/* The two training poses nearest to the current pose (feature distance) and the
 * pose-space blend weight of the second (DESIGN.md §8: one sample when the nearest is
 * within 1e-3 or the second is more than 4 times as far, else a blend by distance).
 * A pose stored on several branches counts once; the instance's motion picks the
 * branch (pick_branch). Sets in->nearest (-1 without training poses), in->second and
 * in->blend. */
static void nearest_training_poses(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    int32_t n0 = -1, n1 = -1;
    in->nearest = in->second = -1;
    in->blend = 0;
    if (v->ntrain < 1) return;
    sw_pose_feature(in->T_cur, v->bone_parent, v->nbones, in->feature);
    double d0 = INFINITY, d1 = INFINITY;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        double d =
            sw_pose_distance(in->feature, v->train_pose + (size_t)4 * v->nbones * t, v->nbones);
        if ((d == d0 && same_pose(in, t, n0)) || (d == d1 && same_pose(in, t, n1))) continue;
        if (d < d0) {
            d1 = d0, n1 = n0;
            d0 = d, n0 = t;
        } else if (d < d1) {
            d1 = d, n1 = t;
        }
    }
    /* the feature distance is sum (1 - cos^2(theta_b / 2)): its root is linear in the
       angles for small ones */
    double s0 = sqrt(d0), s1 = sqrt(d1);
    if (n1 >= 0 && s0 >= 1e-3 && s1 <= 4 * s0) in->blend = s0 / (s0 + s1);
    /* the last motion: kept while the pose holds still, so a pause does not switch branch */
    size_t f = (size_t)4 * v->nbones;
    double moved = 0;
    for (size_t i = 0; i < f; ++i)
        moved += fabs(in->feature[i] - in->feature_last[i]);
    if (moved > 1e-9 && in->looked_up)
        for (size_t i = 0; i < f; ++i)
            in->motion[i] = in->feature[i] - in->feature_last[i];
    memcpy(in->feature_last, in->feature, f * sizeof(double));
    in->looked_up = 1;
    in->nearest = pick_branch(in, n0);
    in->second = in->blend > 0 ? pick_branch(in, n1) : n1;
}

/* y = A x for a dense R x R matrix. */
static void matvec(const double *A, int32_t R, const double *x, double *y) {
    for (int32_t i = 0; i < R; ++i) {
        double acc = 0;
        for (int32_t j = 0; j < R; ++j)
            acc += A[(int64_t)i * R + j] * x[j];
        y[i] = acc;
    }
}

static double dot(const double *a, const double *b, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* Phi(q): cubature + springs + (dynamic) inertia, damping and inertial forces. With
 * want_grad, also g (and H with want_hess); H_n frozen at the first iteration. */
typedef struct {
    double h, cm, cd, alpha, beta;
    int dynamic;
} dyn_coef;

static double potential(sinew_instance *in, const double *q, const dyn_coef *dc, int want_grad,
                        int want_hess) {
    int32_t R = in->R;
    const sw_blob_view *v = in->v;
    if (want_grad) memset(in->g, 0, (size_t)R * sizeof(double));
    if (want_hess) memcpy(in->H, v->spring_hessian, (size_t)R * R * sizeof(double));
    double phi = cubature_eval(in, q, want_grad, want_hess);
    phi += contact_eval(in, q, want_grad, want_hess);
    matvec(v->spring_hessian, R, q, in->tmp);
    phi += 0.5 * dot(q, in->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            in->g[i] += in->tmp[i];
    if (!dc->dynamic) return phi;
    /* inertia: cm/2 |q - qhat|_M^2 with qhat = qn + h qdot */
    double *e = in->tmp2;
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - in->qn[i] - dc->h * in->qdot[i];
    matvec(v->mass, R, e, in->tmp);
    phi += 0.5 * dc->cm * dot(e, in->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            in->g[i] += dc->cm * in->tmp[i];
    /* damping: cd/2 |q - qn|_D^2, D = alpha M + beta Hn */
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - in->qn[i];
    matvec(v->mass, R, e, in->tmp);
    double dm = dot(e, in->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            in->g[i] += dc->cd * dc->alpha * in->tmp[i];
    matvec(in->Hn, R, e, in->tmp);
    double dk = dot(e, in->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            in->g[i] += dc->cd * dc->beta * in->tmp[i] - in->fin[i];
    phi += 0.5 * dc->cd * (dc->alpha * dm + dc->beta * dk) - dot(q, in->fin, R);
    if (want_hess)
        for (int64_t i = 0; i < (int64_t)R * R; ++i)
            in->H[i] +=
                dc->cm * v->mass[i] + dc->cd * (dc->alpha * v->mass[i] + dc->beta * in->Hn[i]);
    return phi;
}

/* Body-frame angular velocity of the rotation from Ra to Rb over h: log(Ra^T Rb) / h. */
static void angular_velocity(const double *Ta, const double *Tb, double h, double w[3]) {
    double M[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            M[3 * i + j] = Ta[i] * Tb[j] + Ta[3 + i] * Tb[3 + j] + Ta[6 + i] * Tb[6 + j];
    double c = 0.5 * (M[0] + M[4] + M[8] - 1.0);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    double th = acos(c), s = sin(th);
    double k = th < 1e-8 ? 0.5 : (s > 1e-8 ? th / (2 * s) : 0.0);
    w[0] = k * (M[7] - M[5]) / h;
    w[1] = k * (M[2] - M[6]) / h;
    w[2] = k * (M[3] - M[1]) / h;
}

/* Inertial forces of every domain riding its bone (explicit, at q_n and qdot_n). */
static void inertial_forces(sinew_instance *in, double h) {
    const sw_blob_view *v = in->v;
    memset(in->fin, 0, (size_t)in->R * sizeof(double));
    if (in->history < 1) return;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t b = D->bone, r = D->rank, o = D->q_offset;
        const double *Tc = in->T_cur + 12 * b, *Tp = in->T_prev + 12 * b,
                     *Tq = in->T_prev2 + 12 * b;
        double acc[3], c[3], w1[3], w0[3], al[3];
        for (int i = 0; i < 3; ++i)
            acc[i] = in->history >= 2 ? (Tc[9 + i] - 2 * Tp[9 + i] + Tq[9 + i]) / (h * h) : 0.0;
        for (int i = 0; i < 3; ++i)
            c[i] = Tc[i] * acc[0] + Tc[3 + i] * acc[1] + Tc[6 + i] * acc[2];
        angular_velocity(Tp, Tc, h, w1);
        if (in->history >= 2)
            angular_velocity(Tq, Tp, h, w0);
        else
            memcpy(w0, w1, sizeof w0);
        for (int i = 0; i < 3; ++i)
            al[i] = (w1[i] - w0[i]) / h;
        double W[9] = {0, -w1[2], w1[1], w1[2], 0, -w1[0], -w1[1], w1[0], 0};
        double A[9] = {0, -al[2], al[1], al[2], 0, -al[0], -al[1], al[0], 0};
        for (int i = 0; i < 3; ++i) /* A = [alpha]x + [w]x^2 */
            for (int j = 0; j < 3; ++j)
                A[3 * i + j] += W[3 * i] * W[j] + W[3 * i + 1] * W[3 + j] + W[3 * i + 2] * W[6 + j];
        const double *P = v->inertia_u + D->inertia_offset;
        for (int32_t i = 0; i < r; ++i) {
            double f = 0;
            for (int a = 0; a < 3; ++a)
                f += v->inertia_s[3 * (o + i) + a] * c[a];
            for (int ab = 0; ab < 9; ++ab) {
                if (A[ab] == 0 && W[ab] == 0) continue;
                const double *Pab = P + (int64_t)ab * r * r + (int64_t)i * r;
                double pq = 0, pqd = 0;
                for (int32_t j = 0; j < r; ++j) {
                    pq += Pab[j] * in->qn[o + j];
                    pqd += Pab[j] * in->qdot[o + j];
                }
                f += A[ab] * (v->inertia_x[9 * (o + i) + ab] + pq) + 2 * W[ab] * pqd;
            }
            in->fin[o + i] = -f;
        }
    }
}

/* The structural block pattern of H: spring-coupled domains and the domains the
 * contact pairs in use (contact_eval) join (no scan of H's values). */
static void block_pattern(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    int32_t nd = v->ndomains;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < a; ++b)
            in->blk_nz[a * nd + b] = in->blk_adj[in->blk_order[a] * nd + in->blk_order[b]];
    for (int s = 0; s < 2; ++s) {
        int32_t pose = s == 0 ? in->nearest : in->blend > 0 ? in->second : -1;
        if (pose < 0) continue;
        for (int32_t c = v->contact_ptr[pose]; c < v->contact_ptr[pose + 1]; ++c)
            for (int m = 0; m < 4; ++m)
                for (int k = 0; k < 4; ++k) {
                    int32_t a = in->blk_pos[v->contact_verts[8 * c + 2 * m]];
                    int32_t b = in->blk_pos[v->contact_verts[8 * c + 2 * k]];
                    if (a > b) in->blk_nz[a * nd + b] = 1;
                }
    }
}

/* Solves H dq = -g by the block-sparse Cholesky, shifting the diagonal if H is not
 * positive definite. */
static int newton_direction(sinew_instance *in) {
    int32_t R = in->R, nd = in->v->ndomains;
    double tr = 0;
    for (int32_t i = 0; i < R; ++i)
        tr += fabs(in->H[(int64_t)i * R + i]);
    double shift = 0;
    for (int attempt = 0; attempt < 8; ++attempt) {
        if (sw_block_cholesky(in->H, R, nd, in->blk_off, in->blk_size, in->blk_order, in->blk_nz,
                              in->L)) {
            for (int32_t i = 0; i < R; ++i)
                in->dq[i] = -in->g[i];
            sw_block_cholesky_solve(in->L, R, nd, in->blk_off, in->blk_size, in->blk_order,
                                    in->blk_nz, in->dq);
            return 1;
        }
        double next = shift == 0 ? 1e-10 * tr / R + 1e-300 : shift * 100;
        for (int32_t i = 0; i < R; ++i)
            in->H[(int64_t)i * R + i] += next - shift; /* H is rebuilt next pass */
        shift = next;
    }
    return 0;
}

static void write_surface(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    for (int32_t s = 0; s < v->nsurf_verts; ++s) {
        double acc[3] = {0, 0, 0};
        int32_t b = v->surf_copy_ptr[s], e = v->surf_copy_ptr[s + 1];
        for (int32_t i = b; i < e; ++i) {
            const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
            double x[3];
            copy_position(in, D, v->surf_copies[2 * i + 1], in->copy_act[i], in->q + D->q_offset, x,
                          NULL);
            for (int k = 0; k < 3; ++k)
                acc[k] += x[k];
        }
        for (int k = 0; k < 3; ++k)
            in->surf_x[3 * s + k] = acc[k] / (double)(e - b);
    }
    memset(in->surf_n, 0, 3 * (size_t)v->nsurf_verts * sizeof(double));
    for (int32_t t = 0; t < v->nsurf_tris; ++t) {
        const int32_t *tri = v->surf_tris + 3 * t;
        const double *a = in->surf_x + 3 * tri[0], *b = in->surf_x + 3 * tri[1],
                     *c = in->surf_x + 3 * tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
               e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                in->surf_n[3 * tri[k] + j] += n[j]; /* area weighted */
    }
    for (int32_t s = 0; s < v->nsurf_verts; ++s) {
        double *n = in->surf_n + 3 * s, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (l > 0)
            for (int k = 0; k < 3; ++k)
                n[k] /= l;
    }
}

/* Pose-space start of a quasistatic step: q = the blend of the two nearest training
 * poses' reduced solutions. The reduced energy has several minima once a fold buckles
 * or a contact engages, and a warm start from the previous frame can converge to one the
 * full-space solution does not take (measured on a folding finger: the previous frame's
 * q converged to energy 80.8 and 46% correction error where the training solution's
 * minimum at 83.0 is within 2.5%). Starting from the pose-space prediction every frame
 * makes the quasistatic shape a function of the pose alone (no drift, no dependence on
 * the frames before). O(ntrain nbones + R). */
static void pose_space_start(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    if (in->nearest < 0) return;
    const double *q0 = v->train_q + (size_t)in->R * in->nearest;
    if (in->blend == 0) {
        memcpy(in->q, q0, (size_t)in->R * sizeof(double));
        return;
    }
    const double *q1 = v->train_q + (size_t)in->R * in->second;
    for (int32_t i = 0; i < in->R; ++i)
        in->q[i] = (1 - in->blend) * q0[i] + in->blend * q1[i];
}

/* A pose jump no animation makes in one frame (a teleport): no inertia from it. */
static int teleported(const sinew_instance *in) {
    for (int32_t b = 0; b < in->v->nbones; ++b) {
        const double *Tc = in->T_cur + 12 * b, *Tp = in->T_prev + 12 * b;
        double d2 = 0, tr = 0;
        for (int i = 0; i < 3; ++i)
            d2 += (Tc[9 + i] - Tp[9 + i]) * (Tc[9 + i] - Tp[9 + i]);
        for (int i = 0; i < 3; ++i)
            tr += Tc[i] * Tp[i] + Tc[3 + i] * Tp[3 + i] + Tc[6 + i] * Tp[6 + i];
        if (d2 > 0.25 * in->size * in->size || tr < 0.0) return 1; /* > half size, > 90 deg */
    }
    return 0;
}

SINEW_API sinew_result sinew_instance_step(sinew_instance *inst, float dt) {
    if (!inst || !(dt > 0) || !(dt <= 1.0f)) return SINEW_ERROR_INVALID_ARGUMENT;
    int32_t R = inst->R;
    const sw_blob_view *v = inst->v;
    sinew_step_stats st;
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    dyn_coef dc = {dt, 0, 0, v->rayleigh_alpha, v->rayleigh_beta, inst->mode == SINEW_STEP_DYNAMIC};
    memcpy(inst->qn, inst->q, (size_t)R * sizeof(double));
    if (dc.dynamic) {
        dc.cm = 1.0 / ((double)dt * dt);
        dc.cd = 1.0 / dt;
        if (inst->history >= 1 && teleported(inst)) {
            memset(inst->qdot, 0, (size_t)R * sizeof(double));
            inst->history = 0;
            st.status |= SINEW_STEP_TELEPORT;
        }
        inertial_forces(inst, dt);
    }
    skin_active(inst);
    nearest_training_poses(inst);
    block_pattern(inst); /* fixed for the step: the factorisations add their fill to it */
    if (!dc.dynamic && inst->nearest >= 0) {
        pose_space_start(inst);
        st.status |= SINEW_STEP_POSE_SPACE;
    }
    if (dc.dynamic) { /* Rayleigh stiffness H(q_n), frozen for the step */
        dyn_coef statics = dc;
        statics.dynamic = 0;
        potential(inst, inst->q, &statics, 1, 1);
        memcpy(inst->Hn, inst->H, (size_t)R * R * sizeof(double));
    }
    /* Newton with an energy guard. The trial point's evaluation (energy, gradient and
     * Hessian) is the next iteration's, so an accepted step costs one cubature pass; a
     * rejected one halves the step and evaluates again. */
    double phi = potential(inst, inst->q, &dc, 1, 1);
    double gn = sqrt(dot(inst->g, inst->g, R)), g0 = gn;
    for (uint32_t it = 0;; ++it) {
        if (!isfinite(phi) || !isfinite(gn)) {
            memcpy(inst->q, inst->qn, (size_t)R * sizeof(double));
            inst->stats = st;
            inst->stats.status |= SINEW_STEP_FAILED;
            return SINEW_ERROR_NOT_FINITE;
        }
        /* 1e-5 of the step's first gradient: the position error it leaves is far below
         * the subspace's own (measured: tighter costs iterations, not accuracy) */
        if (gn <= 1e-5 * g0 || gn == 0) {
            st.status |= SINEW_STEP_CONVERGED;
            break;
        }
        if (it == inst->max_newton || !newton_direction(inst)) break;
        /* An update that moves the shape by less than 0.3% of its correction (the basis
         * columns are orthonormal, so |dq| is the displacement's norm) is the last one,
         * taken without evaluating its end point (a cubature pass). Measured on the
         * finger: the correction error did not change from the 1e-5 gradient criterion
         * alone (0.0279 / 0.1679 train / held-out at 5K) while the step took 0.7 ms
         * instead of 1.6 ms at 20K. */
        if (sqrt(dot(inst->dq, inst->dq, R)) <= 3e-3 * sqrt(dot(inst->q, inst->q, R))) {
            for (int32_t i = 0; i < R; ++i)
                inst->q[i] += inst->dq[i];
            st.newton_iterations++;
            st.status |= SINEW_STEP_CONVERGED;
            break;
        }
        memcpy(inst->qtrial, inst->q, (size_t)R * sizeof(double)); /* keep q_k */
        double phi0 = phi, gn0 = gn, step = 1.0;
        int accepted = 0;
        for (int ls = 0; ls < 5; ++ls, step *= 0.5) {
            for (int32_t i = 0; i < R; ++i)
                inst->q[i] = inst->qtrial[i] + step * inst->dq[i];
            phi = potential(inst, inst->q, &dc, 1, 1);
            if (isfinite(phi) && phi <= phi0 + 1e-12 * fabs(phi0)) {
                accepted = 1;
                break;
            }
        }
        if (!accepted) { /* keep the best iterate (its energy and gradient norm are known) */
            memcpy(inst->q, inst->qtrial, (size_t)R * sizeof(double));
            phi = phi0;
            gn = gn0;
            st.status |= SINEW_STEP_GUARD;
            break;
        }
        gn = sqrt(dot(inst->g, inst->g, R));
        st.newton_iterations++;
    }
    st.residual = g0 > 0 ? gn / g0 : 0;
    st.energy = phi;
    if (dc.dynamic)
        for (int32_t i = 0; i < R; ++i)
            inst->qdot[i] = (inst->q[i] - inst->qn[i]) / dt;
    /* advance the pose history */
    memcpy(inst->T_prev2, inst->T_prev, 12 * (size_t)v->nbones * sizeof(double));
    memcpy(inst->T_prev, inst->T_cur, 12 * (size_t)v->nbones * sizeof(double));
    if (inst->history < 2) inst->history++;
    write_surface(inst);
    inst->stats = st;
    return SINEW_OK;
}

SINEW_API sinew_result sinew_instance_read_surface(const sinew_instance *inst, float *positions,
                                                   float *normals, uint32_t vertex_count) {
    if (!inst || (!positions && !normals) || vertex_count != (uint32_t)inst->v->nsurf_verts)
        return SINEW_ERROR_INVALID_ARGUMENT;
    for (uint32_t i = 0; i < 3 * vertex_count; ++i) {
        if (positions) positions[i] = (float)inst->surf_x[i];
        if (normals) normals[i] = (float)inst->surf_n[i];
    }
    return SINEW_OK;
}

SINEW_API sinew_result sinew_instance_get_stats(const sinew_instance *inst, sinew_step_stats *out) {
    if (!inst || !out || out->struct_size < sizeof(uint32_t)) return SINEW_ERROR_INVALID_ARGUMENT;
    uint32_t n =
        out->struct_size < sizeof inst->stats ? out->struct_size : (uint32_t)sizeof inst->stats;
    memcpy(out, &inst->stats, n);
    out->struct_size = n;
    return SINEW_OK;
}

const double *sw_instance_surface(const sinew_instance *inst) {
    return inst->surf_x;
}
const double *sw_instance_q(const sinew_instance *inst) {
    return inst->q;
}

void sw_instance_full_positions(const sinew_instance *inst, double *x, double *count) {
    const sw_blob_view *v = inst->v;
    memset(x, 0, 3 * (size_t)v->nverts * sizeof(double));
    memset(count, 0, (size_t)v->nverts * sizeof(double));
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank;
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            int32_t gv = v->domain_verts[D->vert_begin + lv];
            double R[9], t[3], y[3];
            sw_dqs_blend(inst->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, R, t);
            const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r;
            for (int i = 0; i < 3; ++i) {
                double acc = v->rest[3 * gv + i];
                for (int32_t j = 0; j < r; ++j)
                    acc += U[i * r + j] * inst->q[D->q_offset + j];
                y[i] = acc;
            }
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] += R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + t[i];
            count[gv] += 1;
        }
    }
    for (int32_t gv = 0; gv < v->nverts; ++gv) {
        if (count[gv] > 0) {
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] /= count[gv];
        } else {
            double R[9], t[3];
            sw_dqs_blend(inst->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, R, t);
            const double *X = v->rest + 3 * gv;
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
        }
    }
}

void sw_instance_dqs_positions(const sinew_instance *inst, double *x) {
    const sw_blob_view *v = inst->v;
    sw_dqs_skin(v->nverts, v->rest, inst->bone_dq, v->skin_bone, v->skin_weight, 4, x);
}

double sw_instance_potential(sinew_instance *inst, const double *q, double *g, double *H) {
    dyn_coef dc = {1.0 / 30, 0, 0, 0, 0, 0};
    size_t R = (size_t)inst->R;
    skin_active(inst);
    nearest_training_poses(inst);
    double phi = potential(inst, q, &dc, g || H, H != NULL);
    if (g) memcpy(g, inst->g, R * sizeof(double));
    if (H) memcpy(H, inst->H, R * R * sizeof(double));
    return phi;
}

void sw_instance_set_q(sinew_instance *inst, const double *q) {
    memcpy(inst->q, q, (size_t)inst->R * sizeof(double));
}
