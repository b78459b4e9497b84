/* Preconditioned conjugate gradients on 3-vectors per vertex with a block-Jacobi
 * (inverse 3x3 diagonal block) preconditioner and a vertex mask: constrained
 * vertices' entries are held at zero, so the solve acts on the free vertices only
 * (the "filtered" PCG of Baraff & Witkin 1998). */
#ifndef SW_PCG_H
#define SW_PCG_H

#include <stdint.h>

#include "thread_pool.h"

/* y = A x for 3*n vectors; must not read x at masked vertices' entries meaningfully
 * (they are zero) and its output there is ignored. */
typedef void (*sw_linop_fn)(void *ctx, const double *x, double *y);

/* z = P^-1 r: a preconditioner. */
typedef void (*sw_precond_fn)(void *ctx, const double *r, double *z);

/* The four vectors of a solve (m doubles each, the caller's memory). */
typedef struct sw_pcg_vectors {
    double *r, *z, *p, *Ap;
} sw_pcg_vectors;

typedef struct sw_pcg_workspace {
    int32_t n; /* vertices */
    double *r, *z, *p, *Ap;
} sw_pcg_workspace;

typedef struct sw_pcg_stats {
    int iters;
    double rel_residual; /* sqrt(r^T P^-1 r / b^T P^-1 b) at exit */
    int converged;
    int negative_curvature; /* stopped at a direction p with p^T A p <= 0 (A indefinite) */
} sw_pcg_stats;

int sw_pcg_workspace_init(sw_pcg_workspace *ws, int32_t n);
void sw_pcg_workspace_free(sw_pcg_workspace *ws);

/* Inverts the 3x3 blocks diag (9*n) into Pinv (9*n); a block that is not safely
 * invertible (non-positive pivot) is replaced by the inverse of its diagonal, or
 * identity. Masked vertices get zero (free_mask NULL: none is masked). */
void sw_block_jacobi_invert(int32_t n, const double *diag, const unsigned char *free_mask,
                            double *Pinv);

/* Solves A x = b. x holds the initial guess on entry (masked entries are zeroed).
 * Stops when sqrt(r^T z / b^T P^-1 b) <= rel_tol or after max_iters; the true
 * residual b - A x is recomputed every 50 iterations to shed round-off drift. On a
 * direction of non-positive curvature it stops (truncated CG, as in Newton-CG) and
 * reports it; x is then the last iterate, which is still a descent direction for
 * the quadratic model when the initial guess was. */
sw_pcg_stats sw_pcg_solve(sw_linop_fn A, void *ctx, const double *b, const double *Pinv,
                          const unsigned char *free_mask, double rel_tol, int max_iters,
                          sw_pcg_workspace *ws, double *x);
/* PCG on m doubles with the preconditioner P (the same stopping rule, restarts and
 * truncation as sw_pcg_solve, which is this with masked block-Jacobi): solves A x = b
 * from the guess in x. No allocation. */
sw_pcg_stats sw_pcg_run(int64_t m, sw_linop_fn A, void *actx, sw_precond_fn P, void *pctx,
                        const double *b, double rel_tol, int max_iters, const sw_pcg_vectors *ws,
                        double *x);
#endif
