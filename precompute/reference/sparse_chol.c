/* Sparse direct Newton solve with CHOLMOD (see sparse_chol.h). */
#include "sparse_chol.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>

#include "clock.h"
#include "penalty.h"

struct sw_sparse_chol {
    int32_t nverts, nfree;
    int32_t *free_index; /* nverts: index among the free vertices, or -1 */
    cholmod_common cm;
    int started;
    /* Block pattern of the upper triangle, by block column (free index j): the block rows
     * i <= j, ascending, in rows[col_ptr[j] .. col_ptr[j+1]). */
    int64_t *col_ptr;
    int32_t *rows;
    int64_t *extra; /* sorted keys hi * nverts + lo of the contact couplings outside K */
    int64_t nextra, extra_cap;
    int64_t *scratch; /* candidate keys of the current contacts */
    int64_t scratch_cap;
    cholmod_sparse *A;
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E;
    int factored;
    sw_sparse_chol_stats st;
};

void sw_sparse_chol_destroy(sw_sparse_chol *s) {
    if (!s) return;
    if (s->started) {
        cholmod_l_free_sparse(&s->A, &s->cm);
        cholmod_l_free_factor(&s->L, &s->cm);
        cholmod_l_free_dense(&s->B, &s->cm);
        cholmod_l_free_dense(&s->X, &s->cm);
        cholmod_l_free_dense(&s->Y, &s->cm);
        cholmod_l_free_dense(&s->E, &s->cm);
        cholmod_l_finish(&s->cm);
    }
    free(s->free_index);
    free(s->col_ptr);
    free(s->rows);
    free(s->extra);
    free(s->scratch);
    free(s);
}

sinew_result sw_sparse_chol_create(int32_t nverts, const unsigned char *free_mask,
                                   sw_sparse_chol **out, sw_error *err) {
    *out = NULL;
    if (nverts < 1 || !free_mask)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sparse Cholesky: no vertices");
    sw_sparse_chol *s = calloc(1, sizeof *s);
    if (!s) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    s->nverts = nverts;
    s->free_index = malloc((size_t)nverts * sizeof(int32_t));
    if (!s->free_index) {
        sw_sparse_chol_destroy(s);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    for (int32_t v = 0; v < nverts; ++v)
        s->free_index[v] = free_mask[v] ? s->nfree++ : -1;
    if (s->nfree == 0) {
        sw_sparse_chol_destroy(s);
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sparse Cholesky: no free vertex");
    }
    cholmod_l_start(&s->cm);
    s->started = 1;
    s->cm.print = 0;
    s->cm.supernodal = CHOLMOD_SUPERNODAL; /* BLAS-3 on OpenBLAS: the fast path at this size */
    s->cm.final_ll = 1;                    /* LL^T: a failed pivot means not positive definite */
    s->cm.quick_return_if_not_posdef = 1;
    *out = s;
    return SINEW_OK;
}

static int cmp_i64(const void *a, const void *b) {
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* The contacts' couplings of free vertex pairs outside K, as sorted unique keys in
 * s->scratch; returns their count or -1 when out of memory. */
static int64_t contact_keys(sw_sparse_chol *s, const sw_bsr *K, const sw_contact *c, int32_t n) {
    int64_t need = 6 * (int64_t)n, m = 0;
    if (need > s->scratch_cap) {
        int64_t *k = realloc(s->scratch, (size_t)need * sizeof *k);
        if (!k) return -1;
        s->scratch = k;
        s->scratch_cap = need;
    }
    for (int32_t i = 0; i < n; ++i) {
        int32_t v[4];
        double a[4];
        sw_contact_slots(&c[i], v, a);
        for (int p = 0; p < 4; ++p)
            for (int q = p + 1; q < 4; ++q) {
                int32_t lo = v[p] < v[q] ? v[p] : v[q], hi = v[p] < v[q] ? v[q] : v[p];
                if (lo == hi || s->free_index[lo] < 0 || s->free_index[hi] < 0) continue;
                if (sw_bsr_block(K, lo, hi)) continue; /* the tets couple them already */
                s->scratch[m++] = (int64_t)hi * s->nverts + lo;
            }
    }
    if (m > 1) qsort(s->scratch, (size_t)m, sizeof(int64_t), cmp_i64); /* NULL when m = 0 */
    int64_t u = 0;
    for (int64_t i = 0; i < m; ++i)
        if (u == 0 || s->scratch[i] != s->scratch[u - 1]) s->scratch[u++] = s->scratch[i];
    return u;
}

/* Builds the block pattern (K's plus the extra keys) and the scalar upper-triangular
 * CSC matrix A, and analyses it. */
static sinew_result analyse(sw_sparse_chol *s, const sw_bsr *K, sw_error *err) {
    double t0 = sw_now_seconds();
    int32_t nf = s->nfree;
    free(s->col_ptr);
    free(s->rows);
    s->rows = NULL;
    s->col_ptr = calloc((size_t)nf + 1, sizeof(int64_t));
    if (!s->col_ptr) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    /* count: K's row j holds column j's rows (the pattern is symmetric) */
    for (int32_t vj = 0; vj < s->nverts; ++vj) {
        int32_t j = s->free_index[vj];
        if (j < 0) continue;
        for (int64_t b = K->row_ptr[vj]; b < K->row_ptr[vj + 1]; ++b)
            if (K->col[b] <= vj && s->free_index[K->col[b]] >= 0) s->col_ptr[j + 1]++;
    }
    for (int64_t e = 0; e < s->nextra; ++e)
        s->col_ptr[s->free_index[s->extra[e] / s->nverts] + 1]++;
    for (int32_t j = 0; j < nf; ++j)
        s->col_ptr[j + 1] += s->col_ptr[j];
    int64_t nblk = s->col_ptr[nf];
    s->rows = malloc((size_t)nblk * sizeof(int32_t));
    if (!s->rows) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    /* fill: merge K's rows (ascending) with the extras of the column (ascending) */
    int64_t e = 0;
    for (int32_t vj = 0; vj < s->nverts; ++vj) {
        int32_t j = s->free_index[vj];
        if (j < 0) continue;
        int64_t w = s->col_ptr[j], b = K->row_ptr[vj], bend = K->row_ptr[vj + 1];
        for (;;) {
            int32_t kr = -1, er = -1;
            while (b < bend && !(K->col[b] <= vj && s->free_index[K->col[b]] >= 0))
                ++b;
            if (b < bend) kr = K->col[b];
            if (e < s->nextra && s->extra[e] / s->nverts == vj)
                er = (int32_t)(s->extra[e] % s->nverts);
            if (kr < 0 && er < 0) break;
            if (er < 0 || (kr >= 0 && kr < er)) {
                s->rows[w++] = s->free_index[kr];
                ++b;
            } else {
                s->rows[w++] = s->free_index[er];
                ++e;
            }
        }
    }
    /* scalar CSC: block column j -> columns 3j+c; an off-diagonal block row i gives rows
     * 3i..3i+2, the diagonal block rows 3j..3j+c */
    int64_t nz = 0;
    for (int32_t j = 0; j < nf; ++j) {
        int64_t nb = s->col_ptr[j + 1] - s->col_ptr[j];
        nz += 3 * (3 * (nb - 1)) + 6;
    }
    cholmod_l_free_sparse(&s->A, &s->cm);
    cholmod_l_free_factor(&s->L, &s->cm);
    s->factored = 0;
    s->A = cholmod_l_allocate_sparse((size_t)3 * nf, (size_t)3 * nf, (size_t)nz, 1, 1, 1,
                                     CHOLMOD_REAL, &s->cm);
    if (!s->A) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    SuiteSparse_long *Ap = s->A->p, *Ai = s->A->i;
    int64_t w = 0;
    for (int32_t j = 0; j < nf; ++j)
        for (int c = 0; c < 3; ++c) {
            Ap[3 * j + c] = w;
            for (int64_t b = s->col_ptr[j]; b < s->col_ptr[j + 1]; ++b) {
                int32_t i = s->rows[b];
                int top = i == j ? c : 2;
                for (int r = 0; r <= top; ++r)
                    Ai[w++] = 3 * (SuiteSparse_long)i + r;
            }
        }
    Ap[3 * nf] = w;
    s->L = cholmod_l_analyze(s->A, &s->cm);
    if (!s->L) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "CHOLMOD analysis failed");
    s->st.analyses++;
    s->st.analyse_seconds += sw_now_seconds() - t0;
    return SINEW_OK;
}

/* Position in A->x of the entry (3i, 3j + c), i <= j free block indices: column 3j + c
 * holds block row i's three rows from there (on the diagonal block, rows 0..c). */
static int64_t entry(const sw_sparse_chol *s, int32_t i, int32_t j, int c) {
    int64_t lo = s->col_ptr[j], hi = s->col_ptr[j + 1] - 1; /* the last is the diagonal */
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (s->rows[mid] < i)
            lo = mid + 1;
        else
            hi = mid;
    }
    const SuiteSparse_long *Ap = s->A->p;
    return Ap[3 * j + c] + 3 * (lo - s->col_ptr[j]);
}

/* A's block (i, j), i <= j, += f * B^T for a row-major 3x3 B (upper triangle only on the
 * diagonal block). */
static void add_block(sw_sparse_chol *s, int32_t i, int32_t j, double f, const double B[9]) {
    double *Ax = s->A->x;
    for (int c = 0; c < 3; ++c) {
        int64_t pos = entry(s, i, j, c);
        int top = i == j ? c : 2;
        for (int r = 0; r <= top; ++r)
            Ax[pos + r] += f * B[3 * c + r];
    }
}

/* A->x = K (free part, upper triangle) + contact Hessians. */
static void assemble(sw_sparse_chol *s, const sw_bsr *K, const sw_contact *ct, int32_t n, double kc,
                     double alpha) {
    memset(s->A->x, 0, s->A->nzmax * sizeof(double));
    for (int32_t vj = 0; vj < s->nverts; ++vj) {
        int32_t j = s->free_index[vj];
        if (j < 0) continue;
        for (int64_t b = K->row_ptr[vj]; b < K->row_ptr[vj + 1]; ++b) {
            int32_t vi = K->col[b], i = s->free_index[vi];
            /* K's block (vj, vi) is the transpose of (vi, vj) */
            if (vi <= vj && i >= 0) add_block(s, i, j, 1.0, K->val + 9 * b);
        }
    }
    for (int32_t k = 0; k < n; ++k) {
        int32_t v[4];
        double a[4], N[9];
        sw_contact_slots(&ct[k], v, a);
        sw_penalty_N(ct[k].n, alpha, N);
        double kk = kc * ct[k].ka;
        /* block (v_p, v_q) of k J^T N J is kk a_p a_q N (N symmetric); each unordered
           vertex pair once in the upper triangle, the diagonal blocks from every ordered
           slot pair */
        for (int p = 0; p < 4; ++p)
            for (int q = 0; q < 4; ++q) {
                int32_t i = s->free_index[v[p]], j = s->free_index[v[q]];
                if (i >= 0 && j >= 0 && i <= j) add_block(s, i, j, kk * a[p] * a[q], N);
            }
    }
}

sinew_result sw_sparse_chol_factor(sw_sparse_chol *s, const sw_bsr *K, const sw_contact *c,
                                   int32_t n, double kc, double alpha, sw_error *err) {
    int64_t m = contact_keys(s, K, c, n);
    if (m < 0) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    int same = s->A && m == s->nextra &&
               (m == 0 || memcmp(s->scratch, s->extra, (size_t)m * sizeof(int64_t)) == 0);
    if (!same) {
        /* a superset of the analysed couplings would also do, but a pattern grown over a
           whole clip costs fill; analysis is cheap next to the factorisation */
        if (m > s->extra_cap) {
            int64_t *k = realloc(s->extra, (size_t)m * sizeof *k);
            if (!k) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
            s->extra = k;
            s->extra_cap = m;
        }
        if (m) memcpy(s->extra, s->scratch, (size_t)m * sizeof(int64_t));
        s->nextra = m;
        sinew_result r = analyse(s, K, err);
        if (r != SINEW_OK) return r;
    }
    double t0 = sw_now_seconds();
    assemble(s, K, c, n, kc, alpha);
    const double *Ax = s->A->x;
    for (size_t i = 0; i < s->A->nzmax; ++i)
        if (!isfinite(Ax[i]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "Newton matrix not finite");
    s->factored = 0;
    int ok = cholmod_l_factorize(s->A, s->L, &s->cm);
    s->st.factorizations++;
    s->st.factor_seconds += sw_now_seconds() - t0;
    if (s->cm.status == CHOLMOD_NOT_POSDEF)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "Newton matrix not positive definite");
    if (!ok || s->cm.status < CHOLMOD_OK)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "CHOLMOD factorisation failed (%d)",
                            s->cm.status);
    s->st.factor_nnz = (int64_t)s->cm.lnz;
    s->factored = 1;
    return SINEW_OK;
}

sinew_result sw_sparse_chol_solve(sw_sparse_chol *s, const double *b, double *x, sw_error *err) {
    if (!s->factored)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sparse Cholesky: not factored");
    double t0 = sw_now_seconds();
    size_t nf3 = (size_t)3 * s->nfree;
    if (!s->B && !(s->B = cholmod_l_allocate_dense(nf3, 1, nf3, CHOLMOD_REAL, &s->cm)))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    double *Bx = s->B->x;
    for (int32_t v = 0; v < s->nverts; ++v) {
        int32_t i = s->free_index[v];
        if (i >= 0) memcpy(Bx + 3 * (size_t)i, b + 3 * (size_t)v, 3 * sizeof(double));
    }
    if (!cholmod_l_solve2(CHOLMOD_A, s->L, s->B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "CHOLMOD solve failed (%d)",
                            s->cm.status);
    const double *Xx = s->X->x;
    for (int32_t v = 0; v < s->nverts; ++v) {
        int32_t i = s->free_index[v];
        if (i >= 0)
            memcpy(x + 3 * (size_t)v, Xx + 3 * (size_t)i, 3 * sizeof(double));
        else
            x[3 * (size_t)v] = x[3 * (size_t)v + 1] = x[3 * (size_t)v + 2] = 0;
    }
    s->st.solve_seconds += sw_now_seconds() - t0;
    return SINEW_OK;
}

sw_sparse_chol_stats sw_sparse_chol_get_stats(const sw_sparse_chol *s) {
    return s->st;
}
