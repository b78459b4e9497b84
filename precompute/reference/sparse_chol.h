/* A sparse direct solve of the reference's Newton systems with CHOLMOD (SuiteSparse,
 * Debian libsuitesparse-dev): supernodal Cholesky on OpenBLAS, fill-reducing ordering
 * by AMD or METIS (CHOLMOD's choice). The matrix is the elastic system in BSR form
 * (3x3 blocks over the tet adjacency) plus the self-contact penalty Hessians
 * (k J^T N J of eqs. 3.4-3.6), restricted to the free vertices.
 *
 * The symbolic analysis (ordering and supernodes) runs only when the pattern changes,
 * i.e. when a contact couples two vertices the tets do not; every Newton iteration
 * refactors numerically into the same structure.
 *
 * Licence: CHOLMOD's Supernodal module is GPL (its Core and Cholesky modules LGPL), so
 * this file is linked by the bake and the tools only, never by libsinew (README). */
#ifndef SW_SPARSE_CHOL_H
#define SW_SPARSE_CHOL_H

#include <stdint.h>

#include "bsr_matrix.h"
#include "selfcontact.h"

typedef struct sw_sparse_chol sw_sparse_chol;

typedef struct sw_sparse_chol_stats {
    int analyses;       /* symbolic analyses so far */
    int factorizations; /* numeric factorisations so far */
    int64_t factor_nnz; /* entries of L at the last factorisation */
    double analyse_seconds, factor_seconds, solve_seconds; /* totals */
} sw_sparse_chol_stats;

/* A solver for the vertices with free_mask[v] != 0 of an nverts-vertex system (the
 * mask is copied). */
sinew_result sw_sparse_chol_create(int32_t nverts, const unsigned char *free_mask,
                                   sw_sparse_chol **out, sw_error *err);
void sw_sparse_chol_destroy(sw_sparse_chol *s);

/* Factors A = K + sum of the contacts' penalty Hessians (stiffness kc ka, anisotropy
 * alpha), analysing first when the contacts couple a vertex pair the last analysis did
 * not have. Returns SINEW_OK, SINEW_ERROR_DEGENERATE when A is not positive definite
 * (the caller projects the element Hessians and tries again), SINEW_ERROR_OUT_OF_MEMORY
 * or SINEW_ERROR_NOT_FINITE. */
sinew_result sw_sparse_chol_factor(sw_sparse_chol *s, const sw_bsr *K, const sw_contact *c,
                                   int32_t n, double kc, double alpha, sw_error *err);

/* x = A^-1 b on the free vertices (3*nverts vectors; masked entries of x are zero).
 * Uses the last successful factorisation. */
sinew_result sw_sparse_chol_solve(sw_sparse_chol *s, const double *b, double *x, sw_error *err);

sw_sparse_chol_stats sw_sparse_chol_get_stats(const sw_sparse_chol *s);

#endif
