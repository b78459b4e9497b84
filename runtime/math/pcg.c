/* Filtered block-Jacobi PCG (see pcg.h). Serial vector kernels with a fixed
 * summation order (deterministic); the operator itself may run in parallel. */
#include "pcg.h"

#include "mat3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int sw_pcg_workspace_init(sw_pcg_workspace *ws, int32_t n) {
    size_t bytes = (size_t)n * 3 * sizeof(double);
    ws->n = n;
    ws->r = malloc(bytes);
    ws->z = malloc(bytes);
    ws->p = malloc(bytes);
    ws->Ap = malloc(bytes);
    if (ws->r && ws->z && ws->p && ws->Ap) return 1;
    sw_pcg_workspace_free(ws);
    return 0;
}

void sw_pcg_workspace_free(sw_pcg_workspace *ws) {
    free(ws->r);
    free(ws->z);
    free(ws->p);
    free(ws->Ap);
    memset(ws, 0, sizeof *ws);
}

void sw_block_jacobi_invert(int32_t n, const double *diag, const unsigned char *free_mask,
                            double *Pinv) {
    for (int32_t v = 0; v < n; ++v) {
        const double *a = diag + 9 * v;
        double *o = Pinv + 9 * v;
        memset(o, 0, 9 * sizeof(double));
        if (free_mask && !free_mask[v]) continue;
        double C[9];
        sw_m3_cofactor(a, C);
        double det = a[0] * C[0] + a[1] * C[1] + a[2] * C[2];
        double scale = fabs(a[0]) + fabs(a[4]) + fabs(a[8]);
        /* SPD blocks have positive leading minors; anything else falls back. */
        if (a[0] > 0 && a[0] * a[4] - a[1] * a[3] > 0 && det > 1e-14 * scale * scale * scale) {
            double inv = 1.0 / det;
            for (int i = 0; i < 3; ++i) /* A^-1 = C^T / det */
                for (int j = 0; j < 3; ++j)
                    o[3 * i + j] = C[3 * j + i] * inv;
        } else {
            for (int i = 0; i < 3; ++i)
                o[4 * i] = a[4 * i] > 0 ? 1.0 / a[4 * i] : 1.0;
        }
    }
}

static void apply_prec(int32_t n, const double *Pinv, const unsigned char *free_mask,
                       const double *r, double *z) {
    for (int32_t v = 0; v < n; ++v) {
        const double *P = Pinv + 9 * v, *rv = r + 3 * v;
        if (free_mask && !free_mask[v]) {
            z[3 * v] = z[3 * v + 1] = z[3 * v + 2] = 0;
            continue;
        }
        z[3 * v] = P[0] * rv[0] + P[1] * rv[1] + P[2] * rv[2];
        z[3 * v + 1] = P[3] * rv[0] + P[4] * rv[1] + P[5] * rv[2];
        z[3 * v + 2] = P[6] * rv[0] + P[7] * rv[1] + P[8] * rv[2];
    }
}

static double dot(int64_t n, const double *a, const double *b) {
    double s = 0;
    for (int64_t i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* r = b - A x. */
static void residual(sw_linop_fn A, void *ctx, const double *b, int64_t m, double *r, double *Ap,
                     const double *x) {
    A(ctx, x, Ap);
    for (int64_t i = 0; i < m; ++i)
        r[i] = b[i] - Ap[i];
}

sw_pcg_stats sw_pcg_run(int64_t m, sw_linop_fn A, void *actx, sw_precond_fn P, void *pctx,
                        const double *b, double rel_tol, int max_iters, const sw_pcg_vectors *ws,
                        double *x) {
    sw_pcg_stats st = {0, 0.0, 0, 0};
    double *r = ws->r, *z = ws->z, *p = ws->p, *Ap = ws->Ap;
    memcpy(r, b, (size_t)m * sizeof *r);
    P(pctx, r, z);
    double bnorm = dot(m, r, z); /* b^T P^-1 b */
    if (!(bnorm > 0)) {          /* b = 0: x = 0 is the solution */
        memset(x, 0, (size_t)m * sizeof *x);
        st.converged = 1;
        return st;
    }
    residual(A, actx, b, m, r, Ap, x);
    P(pctx, r, z);
    double rz = dot(m, r, z);
    if (!(rz < bnorm)) { /* the initial guess is worse than zero: start from zero */
        memset(x, 0, (size_t)m * sizeof *x);
        memcpy(r, b, (size_t)m * sizeof *r);
        P(pctx, r, z);
        rz = bnorm;
    }
    memcpy(p, z, (size_t)m * sizeof *p);
    double tol2 = rel_tol * rel_tol * bnorm;
    while (st.iters < max_iters && rz > tol2) {
        A(actx, p, Ap);
        double pAp = dot(m, p, Ap);
        if (!(pAp > 0)) { /* not positive definite along p: stop with what we have */
            st.negative_curvature = 1;
            break;
        }
        double alpha = rz / pAp;
        for (int64_t i = 0; i < m; ++i)
            x[i] += alpha * p[i];
        st.iters++;
        if (st.iters % 50 == 0)
            residual(A, actx, b, m, r, Ap, x);
        else
            for (int64_t i = 0; i < m; ++i)
                r[i] -= alpha * Ap[i];
        P(pctx, r, z);
        double rz_new = dot(m, r, z);
        double beta = rz_new / rz;
        rz = rz_new;
        for (int64_t i = 0; i < m; ++i)
            p[i] = z[i] + beta * p[i];
    }
    st.rel_residual = sqrt(fmax(rz, 0) / bnorm);
    st.converged = rz <= tol2;
    return st;
}

/* The block-Jacobi preconditioner of sw_pcg_solve, masked. */
typedef struct {
    int32_t n;
    const double *Pinv;
    const unsigned char *free_mask;
} block_jacobi;

static void block_jacobi_apply(void *ctx, const double *r, double *z) {
    const block_jacobi *bj = ctx;
    apply_prec(bj->n, bj->Pinv, bj->free_mask, r, z);
}

/* Masked vertices' entries of x stay zero: the preconditioner zeroes them in every
 * search direction, and x starts with them zeroed. */
sw_pcg_stats sw_pcg_solve(sw_linop_fn A, void *ctx, const double *b, const double *Pinv,
                          const unsigned char *free_mask, double rel_tol, int max_iters,
                          sw_pcg_workspace *ws, double *x) {
    for (int32_t v = 0; v < ws->n; ++v)
        if (!free_mask[v]) x[3 * v] = x[3 * v + 1] = x[3 * v + 2] = 0;
    block_jacobi bj = {ws->n, Pinv, free_mask};
    sw_pcg_vectors vec = {ws->r, ws->z, ws->p, ws->Ap};
    return sw_pcg_run(3 * (int64_t)ws->n, A, ctx, block_jacobi_apply, &bj, b, rel_tol, max_iters,
                      &vec, x);
}
