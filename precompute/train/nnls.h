/* Non-negative least squares: min |A x - b| subject to x >= 0, A dense m x n
 * column-major (column j at A + j*m). Used by cubature training (thesis §2.2.3,
 * eq. 2.14). */
#ifndef SW_NNLS_H
#define SW_NNLS_H

#include <stdint.h>

#include "sw_error.h"

typedef enum sw_nnls_method {
    SW_NNLS_LAWSON_HANSON = 0, /* the classic active-set method (Lawson & Hanson 1974) */
    SW_NNLS_FAST = 1           /* Bro & de Jong 1997 (FNNLS): works on A^T A and A^T b */
} sw_nnls_method;

typedef struct sw_nnls_stats {
    int iterations;
    double residual; /* |A x - b| at exit */
    int converged;   /* KKT conditions met within tolerance */
} sw_nnls_stats;

/* Dot product with four partial sums in a fixed order: faster than one chain (no
 * reassociation is allowed, -ffp-contract=off) and deterministic. */
static inline double sw_dot(const double *a, const double *b, int64_t n) {
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    int64_t i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += a[i] * b[i];
        s1 += a[i + 1] * b[i + 1];
        s2 += a[i + 2] * b[i + 2];
        s3 += a[i + 3] * b[i + 3];
    }
    for (; i < n; ++i)
        s0 += a[i] * b[i];
    return (s0 + s1) + (s2 + s3);
}

/* Solves into x (n). tol is relative to |A^T b|_inf (0: 1e-10); max_iter 0: 3n.
 * Returns INVALID_ARGUMENT for bad sizes/non-finite input, OUT_OF_MEMORY, or
 * NOT_CONVERGED (x is then the best feasible iterate). */
sinew_result sw_nnls(sw_nnls_method method, const double *A, int64_t m, int64_t n, const double *b,
                     double tol, int max_iter, double *x, sw_nnls_stats *stats, sw_error *err);
/* FNNLS on precomputed normal equations: AtA = A^T A (n x n, column-major), Atb =
 * A^T b, btb = b.b (only for stats->residual). x0 (optional, n, >= 0) warm-starts the
 * passive set with supp(x0) (cubature training re-solves after small support
 * changes). Same tol/max_iter/result conventions as sw_nnls. */
sinew_result sw_nnls_normal(const double *AtA, const double *Atb, double btb, int64_t n, double tol,
                            int max_iter, const double *x0, double *x, sw_nnls_stats *stats,
                            sw_error *err);
#endif
