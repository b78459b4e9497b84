/* Small dense kernels for the per-frame step (STYLE.md §6: no BLAS/LAPACK in the
 * step, they take a global lock). Row-major n x n matrices. No allocation. */
#ifndef SW_DENSE_H
#define SW_DENSE_H

#include <stdint.h>

/* In-place Cholesky A = L L^T (lower triangle of A overwritten by L; the upper triangle
 * is not read). Returns 1 on success, 0 when a pivot is not positive. */
int sw_cholesky(double *A, int32_t n);

/* Solves L L^T x = b in place (x holds b on entry) with L from sw_cholesky. */
void sw_cholesky_solve(const double *L, int32_t n, double *x);
#endif
