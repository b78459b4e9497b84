/* Symmetric block-sparse matrix with 3x3 blocks over the vertex adjacency of a tet
 * mesh (block compressed rows, full pattern stored: both (i,j) and (j,i)). The
 * pattern is built once; element matrices are added by a precomputed scatter map, so
 * assembly allocates nothing and, gathered per block row, is deterministic and
 * parallel without locks. */
#ifndef SW_BSR_MATRIX_H
#define SW_BSR_MATRIX_H

#include <stdint.h>

#include "sw_error.h"
#include "thread_pool.h"

typedef struct sw_bsr {
    int32_t nrows;    /* block rows = vertices */
    int64_t nblocks;  /* stored 3x3 blocks */
    int64_t *row_ptr; /* nrows + 1 */
    int32_t *col;     /* nblocks block-column ids, ascending within a row */
    int64_t *diag;    /* nrows: index of the diagonal block of each row */
    double *val;      /* 9 * nblocks, row-major blocks */
    /* Element scatter: block b receives element entries src[src_ptr[b] .. src_ptr[b+1]),
     * each an index e*16 + 4*a + c meaning element e's local block (a, c). */
    int64_t *src_ptr;
    int64_t *src;
    int32_t nelems;
} sw_bsr;

/* Pattern of all vertex pairs sharing a tet (tets: 4*ntets vertex ids < nverts). */
sinew_result sw_bsr_create_from_tets(int32_t nverts, int32_t ntets, const int32_t *tets,
                                     sw_bsr *out, sw_error *err);
void sw_bsr_free(sw_bsr *m);

/* val = sum of the element matrices Ke (ntets * 144, each 12x12 row-major in the
 * element's vertex order), gathered per block in element order. */
void sw_bsr_assemble(sw_bsr *m, const double *Ke, sw_pool *pool);

/* y = A x (3*nrows). */
void sw_bsr_multiply(const sw_bsr *m, const double *x, double *y, sw_pool *pool);

/* The 3x3 block at (i, j), or NULL when (i, j) is not in the pattern. */
double *sw_bsr_block(const sw_bsr *m, int32_t i, int32_t j);

#endif
