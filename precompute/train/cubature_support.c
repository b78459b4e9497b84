/* The cubature trainer's support: the NNLS re-solve on a new support (eq. 2.14) with
 * its Gram matrix kept across iterations, and the random candidate sampler. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cubature_internal.h"

#define NNLS_TOL 1e-10
#define PRUNE_REL 1e-12

typedef struct gram_job {
    trainer *t;
    const int64_t *list;
    int64_t k;
    double *G;
} gram_job;

/* Columns j of the new Gram matrix: entries between two old support members are
 * copied, the rest are fresh dot products (each owned by one j: no races). */
static void gram_range(void *ctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    gram_job *job = ctx;
    trainer *t = job->t;
    const int64_t k = job->k;
    for (int64_t j = begin; j < end; ++j) {
        int64_t ej = job->list[j], pj = t->pos[ej];
        const double *aj = t->cc.col[ej];
        for (int64_t i = 0; i <= j; ++i) {
            int64_t ei = job->list[i], pi = t->pos[ei];
            double g =
                (pi >= 0 && pj >= 0) ? t->G[pj * t->s + pi] : sw_dot(t->cc.col[ei], aj, t->m);
            job->G[j * k + i] = job->G[i * k + j] = g;
        }
    }
}

static void set_support_pins(trainer *t, int on) {
    for (int64_t i = 0; i < t->s; ++i) {
        t->pos[t->ids[i]] = on ? i : -1;
        if (on)
            t->cc.pinned[t->ids[i]] |= 1;
        else
            t->cc.pinned[t->ids[i]] &= 2;
    }
}

/* The weights for a new support `list` (k <= max_points, all cached): NNLS (eq. 2.14)
 * warm-started from x0, zero weights dropped, residual and best set updated. */
sinew_result sw_cubature_solve_on(trainer *t, const int64_t *list, int64_t k, const double *x0,
                                  sw_error *err) {
    const int64_t m = t->m;
    double *x = malloc((size_t)(k ? k : 1) * sizeof(double));
    double *G = NULL, *aux = NULL;
    if (!x) goto oom;
    /* Usually all cached already; the best set (restore_best) may have been evicted. */
    sinew_result res = sw_cubature_cache_fetch(&t->cc, list, k, NULL, NULL, err);
    if (res != SINEW_OK) goto done;
    if (k > 0 && t->par.nnls == SW_NNLS_FAST) {
        G = malloc((size_t)(k * k) * sizeof(double));
        aux = malloc((size_t)k * sizeof(double));
        if (!G || !aux) goto oom;
        gram_job job = {t, list, k, G};
        sw_pool_parallel_for(t->cc.pool, k, gram_range, &job);
        for (int64_t i = 0; i < k; ++i)
            aux[i] = t->cc.atb[list[i]];
        res = sw_nnls_normal(G, aux, t->bnorm * t->bnorm, k, NNLS_TOL, 0, x0, x, NULL, err);
    } else if (k > 0) {
        aux = malloc((size_t)(m * k) * sizeof(double));
        if (!aux) goto oom;
        for (int64_t i = 0; i < k; ++i)
            memcpy(aux + i * m, t->cc.col[list[i]], (size_t)m * sizeof(double));
        res = sw_nnls(SW_NNLS_LAWSON_HANSON, aux, m, k, t->b, NNLS_TOL, 0, x, NULL, err);
    }
    /* An NNLS that stopped at its iteration limit still returns feasible weights. */
    if (res == SINEW_ERROR_NOT_CONVERGED) res = SINEW_OK;
    if (res != SINEW_OK) goto done;

    /* Prune zero weights; the kept Gram block is compacted in place of the old one. */
    set_support_pins(t, 0);
    /* Also drop weights whose whole contribution w_e |a_e| is rounding noise of an
     * exact zero (a degenerate active set can leave 1e-15 there). */
    for (int64_t i = 0; i < k; ++i)
        if (x[i] * t->cc.norm[list[i]] <= PRUNE_REL * t->bnorm) x[i] = 0;
    int64_t s = 0;
    for (int64_t i = 0; i < k; ++i) {
        if (!(x[i] > 0)) continue;
        if (G) {
            int64_t sj = 0;
            for (int64_t j = 0; j < k; ++j)
                if (x[j] > 0) G[s * k + sj++] = G[i * k + j];
        }
        t->ids[s] = list[i];
        t->w[s] = x[i];
        s++;
    }
    t->s = s;
    if (G) {
        /* Rows were packed to the front of each column (stride k); restride to s. */
        for (int64_t c = 0; c < s; ++c)
            memmove(G + c * s, G + c * k, (size_t)s * sizeof(double));
        free(t->G);
        t->G = G;
        G = NULL;
    }
    set_support_pins(t, 1);

    double *r = t->r;
    memcpy(r, t->b, (size_t)m * sizeof(double));
    for (int64_t i = 0; i < s; ++i) {
        const double *a = t->cc.col[t->ids[i]];
        for (int64_t q = 0; q < m; ++q)
            r[q] -= t->w[i] * a[q];
    }
    t->rel = sqrt(sw_dot(r, r, m)) / t->bnorm;
    /* Best: once some set meets tol, the smallest such set; before, the lowest error. */
    const double tol = t->par.tol;
    int better = t->rel <= tol ? (t->best_rel > tol || s < t->best_n ||
                                  (s == t->best_n && t->rel < t->best_rel))
                               : (t->best_rel > tol && t->rel < t->best_rel);
    if (s > t->par.max_points) better = 0; /* a merged set (nnhtp_merge_step) */
    t->current_is_best = better;
    if (better) {
        t->best_rel = t->rel;
        t->best_n = s;
        memcpy(t->best_ids, t->ids, (size_t)s * sizeof(int64_t));
        memcpy(t->best_w, t->w, (size_t)s * sizeof(double));
    }
    goto done;
oom:
    res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cubature: out of memory (support %lld)",
                       (long long)k);
done:
    free(x);
    free(G);
    free(aux);
    return res;
}

/* Up to K distinct random candidates outside the support (a partial Fisher-Yates
 * shuffle over a persistent permutation: each pick is uniform over the rest). */
int64_t sw_cubature_sample(trainer *t, int64_t K, int64_t *out) {
    int64_t remaining = t->nc - t->s, got = 0;
    if (K > remaining) K = remaining;
    for (int64_t i = 0; got < K && i < t->nc; ++i) {
        int64_t j = i + rng_below(&t->rng, t->nc - i);
        int64_t e = t->perm[j];
        t->perm[j] = t->perm[i];
        t->perm[i] = e;
        if (t->pos[e] < 0) out[got++] = e;
    }
    return got;
}
