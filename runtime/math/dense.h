/* Small dense kernels for the per-frame step (STYLE.md §6: no BLAS/LAPACK in the
 * step, they take a global lock). Row-major n x n matrices. No allocation. */
#ifndef SW_DENSE_H
#define SW_DENSE_H

#include <stddef.h>
#include <stdint.h>

/* In-place Cholesky A = L L^T (lower triangle of A overwritten by L; the upper triangle
 * is not read). Returns 1 on success, 0 when a pivot is not positive. */
int sw_cholesky(double *A, int32_t n);

/* Solves L L^T x = b in place (x holds b on entry) with L from sw_cholesky. */
void sw_cholesky_solve(const double *L, int32_t n, double *x);

/* Block-sparse Cholesky of a symmetric positive definite matrix stored densely
 * (row-major n x n) and split into nb diagonal blocks: block b covers rows/columns
 * [off[b], off[b] + size[b]). Blocks are eliminated in the order `order` (a
 * permutation of 0..nb-1: leaves of the coupling graph first keeps the fill small);
 * an off-diagonal block marked zero in nz is skipped (and must be zero in A), so a
 * chain or tree of couplings costs about sum of size^3 instead of n^3. nz (nb * nb
 * bytes) holds on entry, at [a * nb + b] for elimination positions a > b, whether block
 * (order[a], order[b]) may be nonzero (see sw_block_pattern); fill is added to it. A is
 * read only in those blocks and the diagonal ones; L receives the factor in the same
 * positions. pack: scratch of sw_block_cholesky_pack_size(largest size) doubles. Returns
 * 1 on success, 0 when a pivot is not positive. */
int sw_block_cholesky(const double *A, int32_t n, int32_t nb, const int32_t *off,
                      const int32_t *size, const int32_t *order, unsigned char *nz, double *L,
                      double *pack);

/* The doubles sw_block_cholesky's pack (scratch) needs for blocks of at most max_size. */
size_t sw_block_cholesky_pack_size(int32_t max_size);

/* Fills nz for sw_block_cholesky from the values of A (a block is nonzero when any
 * entry is). O(n^2): callers that know the structure fill nz themselves. */
void sw_block_pattern(const double *A, int32_t n, int32_t nb, const int32_t *off,
                      const int32_t *size, const int32_t *order, unsigned char *nz);

/* Solves A x = b in place (x holds b) with the factor from sw_block_cholesky (same nb,
 * off, size, order and nz). */
void sw_block_cholesky_solve(const double *L, int32_t n, int32_t nb, const int32_t *off,
                             const int32_t *size, const int32_t *order, const unsigned char *nz,
                             double *x);

/* Elimination order of the nb diagonal blocks of a symmetric matrix for the block
 * Cholesky (sw_block_cholesky), coupled (nb * nb) marking the pairs of distinct blocks
 * with a nonzero entry: repeatedly the block with the fewest remaining neighbours (ties:
 * the lower index), connecting its neighbours (the fill it creates). adj (nb * nb) is
 * scratch. */
void sw_block_order_min_degree(int32_t nb, const unsigned char *coupled, unsigned char *adj,
                               int32_t *order);

/* a . b over n entries, summed in index order. */
static inline double sw_dot(const double *a, const double *b, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* y = A x for a dense row-major n x n matrix (y may not alias x). */
static inline void sw_matvec(const double *A, int32_t n, const double *x, double *y) {
    for (int32_t i = 0; i < n; ++i) {
        double acc = 0;
        for (int32_t j = 0; j < n; ++j)
            acc += A[(int64_t)i * n + j] * x[j];
        y[i] = acc;
    }
}

#endif
