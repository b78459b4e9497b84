/* Block-sparse (3x3) matrix over tet-mesh vertex adjacency: pattern, scatter map,
 * lock-free parallel assembly by gathering, and the matrix-vector product. */
#include "bsr_matrix.h"

#include <stdlib.h>
#include <string.h>

/* One element entry: block (row, col) packed as row*nverts + col, and its source. */
typedef struct {
    int64_t rc;
    int64_t e;
} entry;

static int cmp_entry(const void *a, const void *b) {
    const entry *x = a, *y = b;
    if (x->rc != y->rc) return (x->rc > y->rc) - (x->rc < y->rc);
    return (x->e > y->e) - (x->e < y->e);
}

void sw_bsr_free(sw_bsr *m) {
    if (!m) return;
    free(m->row_ptr);
    free(m->col);
    free(m->diag);
    free(m->val);
    free(m->src_ptr);
    free(m->src);
    memset(m, 0, sizeof *m);
}

sinew_result sw_bsr_create_from_tets(int32_t nverts, int32_t ntets, const int32_t *tets,
                                     sw_bsr *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    int64_t nent = (int64_t)ntets * 16;
    /* Sorting every element entry by (block, source) yields the block pattern in row
     * order and, per block, its sources in element order (a fixed gather order). */
    entry *p = malloc((size_t)nent * sizeof *p);
    out->row_ptr = calloc((size_t)nverts + 1, sizeof *out->row_ptr);
    out->diag = malloc((size_t)nverts * sizeof *out->diag);
    if (!p || !out->row_ptr || !out->diag) goto oom;
    for (int32_t t = 0; t < ntets; ++t)
        for (int a = 0; a < 4; ++a)
            for (int c = 0; c < 4; ++c) {
                int64_t k = (int64_t)t * 16 + 4 * a + c;
                p[k].rc = (int64_t)tets[4 * t + a] * nverts + tets[4 * t + c];
                p[k].e = k;
            }
    qsort(p, (size_t)nent, sizeof *p, cmp_entry);
    int64_t nb = 0;
    for (int64_t i = 0; i < nent; ++i)
        if (i == 0 || p[i].rc != p[i - 1].rc) ++nb;
    out->nrows = nverts;
    out->nblocks = nb;
    out->nelems = ntets;
    out->col = malloc((size_t)nb * sizeof *out->col);
    out->val = calloc((size_t)nb * 9, sizeof *out->val);
    out->src_ptr = malloc(((size_t)nb + 1) * sizeof *out->src_ptr);
    out->src = malloc((size_t)nent * sizeof *out->src);
    if (!out->col || !out->val || !out->src_ptr || !out->src) goto oom;
    for (int32_t r = 0; r < nverts; ++r)
        out->diag[r] = -1; /* isolated vertices keep -1 */
    int64_t b = -1;
    for (int64_t i = 0; i < nent; ++i) {
        if (i == 0 || p[i].rc != p[i - 1].rc) {
            ++b;
            int32_t r = (int32_t)(p[i].rc / nverts);
            out->col[b] = (int32_t)(p[i].rc % nverts);
            out->src_ptr[b] = i;
            out->row_ptr[r + 1]++;
            if (out->col[b] == r) out->diag[r] = b;
        }
        out->src[i] = p[i].e;
    }
    out->src_ptr[nb] = nent;
    for (int32_t r = 0; r < nverts; ++r)
        out->row_ptr[r + 1] += out->row_ptr[r];
    free(p);
    return SINEW_OK;
oom:
    free(p);
    sw_bsr_free(out);
    return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory building a %d-vertex matrix",
                        nverts);
}

typedef struct {
    sw_bsr *m;
    const double *Ke;
} assemble_ctx;

static void assemble_rows(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    assemble_ctx *ctx = vctx;
    sw_bsr *m = ctx->m;
    for (int64_t r = begin; r < end; ++r)
        for (int64_t b = m->row_ptr[r]; b < m->row_ptr[r + 1]; ++b) {
            double acc[9] = {0};
            for (int64_t s = m->src_ptr[b]; s < m->src_ptr[b + 1]; ++s) {
                int64_t e = m->src[s] / 16, loc = m->src[s] % 16;
                int a = (int)(loc / 4), c = (int)(loc % 4);
                const double *K = ctx->Ke + e * 144;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        acc[3 * i + j] += K[(3 * a + i) * 12 + 3 * c + j];
            }
            memcpy(m->val + 9 * b, acc, sizeof acc);
        }
}

void sw_bsr_assemble(sw_bsr *m, const double *Ke, sw_pool *pool) {
    assemble_ctx ctx = {m, Ke};
    sw_pool_parallel_for(pool, m->nrows, assemble_rows, &ctx);
}

typedef struct {
    const sw_bsr *m;
    const double *x;
    double *y;
} mul_ctx;

static void multiply_rows(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    mul_ctx *ctx = vctx;
    const sw_bsr *m = ctx->m;
    const double *x = ctx->x;
    for (int64_t r = begin; r < end; ++r) {
        double y0 = 0, y1 = 0, y2 = 0;
        for (int64_t b = m->row_ptr[r]; b < m->row_ptr[r + 1]; ++b) {
            const double *B = m->val + 9 * b, *xc = x + 3 * (int64_t)m->col[b];
            y0 += B[0] * xc[0] + B[1] * xc[1] + B[2] * xc[2];
            y1 += B[3] * xc[0] + B[4] * xc[1] + B[5] * xc[2];
            y2 += B[6] * xc[0] + B[7] * xc[1] + B[8] * xc[2];
        }
        ctx->y[3 * r] = y0;
        ctx->y[3 * r + 1] = y1;
        ctx->y[3 * r + 2] = y2;
    }
}

void sw_bsr_multiply(const sw_bsr *m, const double *x, double *y, sw_pool *pool) {
    mul_ctx ctx = {m, x, y};
    sw_pool_parallel_for(pool, m->nrows, multiply_rows, &ctx);
}

double *sw_bsr_block(const sw_bsr *m, int32_t i, int32_t j) {
    int64_t lo = m->row_ptr[i], hi = m->row_ptr[i + 1];
    while (lo < hi) {
        int64_t mid = (lo + hi) / 2;
        if (m->col[mid] < j)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (lo < m->row_ptr[i + 1] && m->col[lo] == j) ? m->val + 9 * lo : NULL;
}
