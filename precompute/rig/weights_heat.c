/* Heat-diffusion skin weights (see weights_heat.h). The scalar system matrix
 * A = L + H lives on the vertex-adjacency pattern of sw_bsr (only its row pointers and
 * columns are used; the values are scalars of our own). Three bones are solved at once
 * as the three components of the 3-vector PCG of pcg.h: A acts on each component
 * separately, so one pass over the matrix serves three right-hand sides. Bone groups
 * run in parallel on a thread pool; each group's solve is serial, so the result does
 * not depend on the thread count. */
#include "weights_heat.h"

#include "rig.h"
#include "vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bsr_matrix.h"
#include "pcg.h"
#include "thread_pool.h"

/* Solver limits: the weights are clamped to [0, 1] afterwards, so 1e-10 relative
 * residual is far below anything visible; the iteration cap is generous (Jacobi-PCG
 * on a 7K-vertex hand needs a few hundred). */
#define HEAT_REL_TOL 1e-10
#define HEAT_MAX_ITERS 20000
/* d(v) is clamped below at this fraction of the bounding-box diagonal: a vertex on a
 * bone is then pinned (H >> L) without an infinite diagonal. */
#define HEAT_MIN_DIST_FRACTION 1e-3
/* Bones whose distances agree to this relative tolerance are tied for "nearest". */
#define HEAT_TIE_REL 1e-12

/* Everything the per-group solves share (read-only while they run). */
typedef struct heat_system {
    int32_t n, nbones;
    const int64_t *row_ptr;
    const int32_t *col;
    double *a;                /* scalar A = L + H per pattern entry */
    double *h;                /* n: H_vv */
    double *dist;             /* n * nbones: distance of v to bone b */
    double *dmin;             /* n: distance to the nearest bone (unclamped) */
    double *Pinv;             /* 9n: Jacobi preconditioner, 1/A_vv on the block diagonal */
    unsigned char *free_mask; /* n: 0 for a vertex in no tet (left out of the solve) */
    double *W;                /* n * nbones: the raw solutions */
} heat_system;

/* y = A x on each of the three components (the linear operator of sw_pcg_solve). */
static void heat_apply(void *vctx, const double *x, double *y) {
    const heat_system *S = vctx;
    for (int32_t r = 0; r < S->n; ++r) {
        double y0 = 0, y1 = 0, y2 = 0;
        for (int64_t k = S->row_ptr[r]; k < S->row_ptr[r + 1]; ++k) {
            const double *xc = x + 3 * (int64_t)S->col[k];
            y0 += S->a[k] * xc[0];
            y1 += S->a[k] * xc[1];
            y2 += S->a[k] * xc[2];
        }
        y[3 * r] = y0;
        y[3 * r + 1] = y1;
        y[3 * r + 2] = y2;
    }
}

/* p_b(v): 1 (or 1/k for a k-way tie) when b is among v's nearest bones. */
static double target(const heat_system *S, int32_t v, int32_t b) {
    const double *d = S->dist + (size_t)v * S->nbones;
    double tol = HEAT_TIE_REL * S->dmin[v];
    if (d[b] > S->dmin[v] + tol) return 0.0;
    int k = 0;
    for (int32_t j = 0; j < S->nbones; ++j)
        k += d[j] <= S->dmin[v] + tol;
    return 1.0 / k;
}

/* Per-worker scratch. */
typedef struct heat_worker {
    sw_pcg_workspace ws;
    double *b, *x;
    int failed_group; /* -1, or a group whose solve did not converge */
    double failed_residual;
} heat_worker;

typedef struct heat_run {
    heat_system *S;
    heat_worker *workers;
} heat_run;

/* Solves bone groups [begin, end): group g holds bones 3g, 3g+1, 3g+2 (missing bones
 * of the last group are zero columns, which CG leaves at zero). */
static void solve_groups(void *vctx, int64_t begin, int64_t end, int worker) {
    heat_run *run = vctx;
    heat_system *S = run->S;
    heat_worker *w = run->workers + worker;
    for (int64_t g = begin; g < end; ++g) {
        for (int32_t v = 0; v < S->n; ++v)
            for (int k = 0; k < 3; ++k) {
                int32_t bone = (int32_t)(3 * g + k);
                double p = bone < S->nbones ? target(S, v, bone) : 0.0;
                w->b[3 * v + k] = S->h[v] * p;
                w->x[3 * v + k] = p; /* warm start: near the bones w ~ p */
            }
        sw_pcg_stats st = sw_pcg_solve(heat_apply, S, w->b, S->Pinv, S->free_mask, HEAT_REL_TOL,
                                       HEAT_MAX_ITERS, &w->ws, w->x);
        if (!st.converged && w->failed_group < 0) {
            w->failed_group = (int)g;
            w->failed_residual = st.rel_residual;
        }
        for (int32_t v = 0; v < S->n; ++v)
            for (int k = 0; k < 3; ++k)
                if (3 * g + k < S->nbones)
                    S->W[(size_t)v * S->nbones + (size_t)(3 * g + k)] = w->x[3 * v + k];
    }
}

static sinew_result validate(const sw_tetmesh *m, const sw_skeleton *s, double c, sw_error *err) {
    if (!m || !s)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "heat weights: NULL mesh or skeleton");
    if (!isfinite(c))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "heat weights: bone-term strength c = %g is not finite", c);
    if (m->nverts < 1 || !m->X)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "heat weights: mesh has no vertices");
    if (m->ntets < 1 || !m->tets)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "heat weights: mesh has no tets");
    sinew_result rc = sw_skeleton_validate(s, err);
    if (rc) return rc;
    for (int64_t i = 0; i < 3 * (int64_t)m->nverts; ++i)
        if (!isfinite(m->X[i]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "heat weights: vertex %lld has a non-finite coordinate",
                                (long long)(i / 3));
    for (int64_t i = 0; i < 4 * (int64_t)m->ntets; ++i)
        if (m->tets[i] < 0 || m->tets[i] >= m->nverts)
            return sw_error_set(err, SINEW_ERROR_PARSE,
                                "heat weights: tet %lld references vertex %d of %d",
                                (long long)(i / 4), m->tets[i], m->nverts);
    return SINEW_OK;
}

/* Distances, H, and the matrix values A = L + H on the pattern. */
static sinew_result assemble(const sw_tetmesh *m, const sw_skeleton *s, double c, heat_system *S,
                             sw_error *err) {
    double dclamp = HEAT_MIN_DIST_FRACTION * sw_rig_diagonal(m, s);
    if (!(dclamp > 0)) dclamp = 1e-300;
    for (int32_t v = 0; v < S->n; ++v) {
        double *d = S->dist + (size_t)v * S->nbones, dm = INFINITY;
        for (int32_t b = 0; b < S->nbones; ++b) {
            d[b] = sw_point_segment_distance(m->X + 3 * (size_t)v,
                                             s->joints + 3 * (size_t)s->bones[2 * b],
                                             s->joints + 3 * (size_t)s->bones[2 * b + 1]);
            dm = fmin(dm, d[b]);
        }
        S->dmin[v] = dm;
        double dc = fmax(dm, dclamp);
        S->h[v] = c / (dc * dc); /* the bone term c / d^2 */
    }
    for (int32_t r = 0; r < S->n; ++r) {
        double diag = S->h[r];
        int64_t kd = -1;
        for (int64_t k = S->row_ptr[r]; k < S->row_ptr[r + 1]; ++k) {
            int32_t j = S->col[k];
            if (j == r) {
                kd = k;
                continue;
            }
            const double *p = m->X + 3 * (size_t)r, *q = m->X + 3 * (size_t)j;
            double e2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                        (p[2] - q[2]) * (p[2] - q[2]);
            double we = 1.0 / e2; /* edge weight 1/|e|^2 */
            if (!(e2 > 0) || !isfinite(we))
                return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                    "heat weights: edge between vertices %d and %d has zero length",
                                    r, j);
            S->a[k] = -we;
            diag += we;
        }
        if (kd >= 0) S->a[kd] = diag;
        /* Every tet lists its own vertices, so each row of the pattern has a diagonal;
         * a vertex in no tet has an empty row and is left out of the solve below. */
        double *P = S->Pinv + 9 * (size_t)r;
        memset(P, 0, 9 * sizeof *P);
        P[0] = P[4] = P[8] = kd >= 0 ? 1.0 / diag : 0.0;
        S->free_mask[r] = kd >= 0;
    }
    return SINEW_OK;
}

/* Clamp to [0, 1] and normalise rows; an all-zero row goes to its nearest bone. */
static void finish_rows(const heat_system *S) {
    for (int32_t v = 0; v < S->n; ++v) {
        double *row = S->W + (size_t)v * S->nbones, sum = 0;
        for (int32_t b = 0; b < S->nbones; ++b) {
            row[b] = fmin(fmax(row[b], 0.0), 1.0);
            sum += row[b];
        }
        if (sum > 0) {
            for (int32_t b = 0; b < S->nbones; ++b)
                row[b] /= sum;
            continue;
        }
        const double *d = S->dist + (size_t)v * S->nbones;
        int32_t best = 0;
        for (int32_t b = 1; b < S->nbones; ++b)
            if (d[b] < d[best]) best = b;
        row[best] = 1.0;
    }
}

static void system_free(heat_system *S) {
    free(S->a);
    free(S->h);
    free(S->dist);
    free(S->dmin);
    free(S->Pinv);
    free(S->free_mask);
    free(S->W);
}

static sinew_result solve_all(heat_system *S, sw_error *err) {
    int64_t ngroups = (S->nbones + 2) / 3;
    sw_pool *pool = sw_pool_create(ngroups < 2 ? 1 : 0); /* NULL: run on this thread */
    int nw = sw_pool_size(pool);
    heat_worker *workers = calloc((size_t)nw, sizeof *workers);
    sinew_result rc = SINEW_OK;
    if (!workers) rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "heat weights: out of memory");
    for (int i = 0; i < nw && !rc; ++i) {
        workers[i].failed_group = -1;
        workers[i].b = malloc(3 * sizeof(double) * (size_t)S->n);
        workers[i].x = malloc(3 * sizeof(double) * (size_t)S->n);
        if (!workers[i].b || !workers[i].x || !sw_pcg_workspace_init(&workers[i].ws, S->n))
            rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "heat weights: out of memory");
    }
    if (!rc) {
        heat_run run = {S, workers};
        sw_pool_parallel_for(pool, ngroups, solve_groups, &run);
        for (int i = 0; i < nw && !rc; ++i)
            if (workers[i].failed_group >= 0)
                rc = sw_error_set(err, SINEW_ERROR_NOT_CONVERGED,
                                  "heat weights: CG for bones %d..%d stopped at relative residual "
                                  "%.3g after %d iterations",
                                  3 * workers[i].failed_group,
                                  (int)fmin(3.0 * workers[i].failed_group + 2, S->nbones - 1),
                                  workers[i].failed_residual, HEAT_MAX_ITERS);
    }
    for (int i = 0; workers && i < nw; ++i) {
        free(workers[i].b);
        free(workers[i].x);
        sw_pcg_workspace_free(&workers[i].ws);
    }
    free(workers);
    sw_pool_destroy(pool);
    return rc;
}

sinew_result sw_weights_heat(const sw_tetmesh *m, const sw_skeleton *s, double c, sw_weights *out,
                             sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "heat weights: out is NULL");
    memset(out, 0, sizeof *out);
    sinew_result rc = validate(m, s, c, err);
    if (rc) return rc;
    if (c <= 0) c = SW_WEIGHTS_HEAT_C;
    sw_bsr pattern;
    rc = sw_bsr_create_from_tets(m->nverts, m->ntets, m->tets, &pattern, err);
    if (rc) return rc;
    size_t n = (size_t)m->nverts, nb = (size_t)s->nbones;
    heat_system S = {
        m->nverts, s->nbones, pattern.row_ptr, pattern.col, NULL, NULL, NULL, NULL, NULL,
        NULL,      NULL};
    S.a = malloc((size_t)pattern.nblocks * sizeof *S.a);
    S.h = malloc(n * sizeof *S.h);
    S.dist = malloc(n * nb * sizeof *S.dist);
    S.dmin = malloc(n * sizeof *S.dmin);
    S.Pinv = malloc(9 * n * sizeof *S.Pinv);
    S.free_mask = malloc(n);
    S.W = calloc(n * nb, sizeof *S.W);
    if (!S.a || !S.h || !S.dist || !S.dmin || !S.Pinv || !S.free_mask || !S.W)
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                          "heat weights: out of memory for %d vertices x %d bones", m->nverts,
                          s->nbones);
    if (!rc) rc = assemble(m, s, c, &S, err);
    if (!rc) rc = solve_all(&S, err);
    if (!rc) {
        finish_rows(&S);
        out->nverts = m->nverts;
        out->nbones = s->nbones;
        out->w = S.W;
        S.W = NULL;
    }
    system_free(&S);
    sw_bsr_free(&pattern);
    return rc;
}
