/* The column cache of cubature training: columns a_e evaluated on demand (in
 * parallel), with |a_e| and a_e . b, kept under a byte budget with LRU eviction. */
#include <math.h>
#include <stdlib.h>

#include "cubature_internal.h"

typedef struct batch_job {
    col_cache *cc;
    const int64_t *ids;
    unsigned char *fresh; /* per item: evaluate first; set to 2 when non-finite */
    const double *r;      /* NULL: no scores */
    double *score;        /* per item: a_e . r */
} batch_job;

static void batch_range(void *ctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    batch_job *job = ctx;
    col_cache *cc = job->cc;
    const int64_t m = cc->m;
    for (int64_t i = begin; i < end; ++i) {
        int64_t e = job->ids[i];
        double *a = cc->col[e];
        if (job->fresh[i]) {
            cc->prob->column(cc->prob->ctx, e, a);
            int finite = 1;
            for (int64_t k = 0; k < m; ++k)
                finite &= isfinite(a[k]) != 0;
            if (!finite) {
                job->fresh[i] = 2;
                continue;
            }
            cc->norm[e] = sqrt(sw_dot(a, a, m));
            cc->atb[e] = sw_dot(a, cc->prob->b, m);
        }
        if (job->r) job->score[i] = sw_dot(a, job->r, m);
    }
}

/* Drops least recently used unpinned columns until `need` more fit under the cap.
 * Which columns go affects only the evaluation count, never the result. */
static void cache_make_room(col_cache *cc, int64_t need) {
    while (cc->ncached + need > cc->cap) {
        int64_t victim = -1;
        for (int64_t e = 0; e < cc->nc; ++e)
            if (cc->col[e] && !cc->pinned[e] && (victim < 0 || cc->used[e] < cc->used[victim]))
                victim = e;
        if (victim < 0) return; /* everything is pinned: exceed the cap */
        free(cc->col[victim]);
        cc->col[victim] = NULL;
        cc->ncached--;
        /* Evict a quarter at a time so the O(nc) scan is amortised. */
        if (cc->ncached + need <= cc->cap - cc->cap / 4) break;
    }
}

/* Makes the columns of ids[0..k) available and, with r, scores[i] = a_i . r. */
sinew_result sw_cubature_cache_fetch(col_cache *cc, const int64_t *ids, int64_t k, const double *r,
                                     double *scores, sw_error *err) {
    unsigned char *fresh = calloc((size_t)(k ? k : 1), 1);
    if (!fresh) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cubature: out of memory");
    int64_t missing = 0;
    for (int64_t i = 0; i < k; ++i) {
        cc->pinned[ids[i]] |= 2;
        if (!cc->col[ids[i]]) missing++;
    }
    cache_make_room(cc, missing);
    sinew_result res = SINEW_OK;
    int ran = 0;
    for (int64_t i = 0; i < k; ++i) {
        int64_t e = ids[i];
        cc->used[e] = ++cc->tick;
        if (cc->col[e]) continue;
        cc->col[e] = malloc((size_t)cc->m * sizeof(double));
        if (!cc->col[e]) {
            res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                               "cubature: out of memory caching %lld columns of %lld rows",
                               (long long)cc->ncached, (long long)cc->m);
            break;
        }
        cc->ncached++;
        fresh[i] = 1;
    }
    if (res == SINEW_OK) {
        batch_job job = {cc, ids, fresh, r, scores};
        sw_pool_parallel_for(cc->pool, k, batch_range, &job);
        ran = 1;
        for (int64_t i = 0; i < k; ++i) {
            if (fresh[i]) cc->evaluated++;
            if (fresh[i] == 2 && res == SINEW_OK)
                res = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                   "cubature: column of candidate %lld is not finite",
                                   (long long)ids[i]);
        }
    }
    for (int64_t i = 0; i < k; ++i) {
        cc->pinned[ids[i]] &= 1;
        /* A half-made column must not be mistaken for a cached one later. */
        if (fresh[i] == 2 || (fresh[i] && !ran)) {
            free(cc->col[ids[i]]);
            cc->col[ids[i]] = NULL;
            cc->ncached--;
        }
    }
    free(fresh);
    return res;
}

void sw_cubature_cache_free(col_cache *cc) {
    if (cc->col)
        for (int64_t e = 0; e < cc->nc; ++e)
            free(cc->col[e]);
    free(cc->col);
    free(cc->norm);
    free(cc->atb);
    free(cc->used);
    free(cc->pinned);
    sw_pool_destroy(cc->pool);
}
