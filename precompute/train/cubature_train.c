/* Cubature training (see cubature_train.h; thesis §2.2.3, Algorithms 1-3).
 *
 * All three selectors share one loop body: evaluate some random candidate columns
 * (cached, optionally in parallel), score them against the residual r = b - A_C w,
 * choose a new support, re-solve the weights by NNLS on it (eq. 2.14) and drop the
 * zero weights. For FNNLS the Gram matrix A_C^T A_C is kept across iterations and
 * only the entries of new columns are computed; the NNLS is warm-started from the
 * previous weights.
 *
 * NN-HTP grows its support bound s (8, 16, 32, ...) until tol is met, then bisects
 * the bound down; when the gradient step cannot swap any entry (coherent columns) it
 * falls back to a merged-set NNLS step (nnhtp_merge_step).
 *
 * Determinism: every random choice comes from one splitmix64 stream seeded by
 * params.seed and happens on the calling thread; threads only evaluate columns and
 * per-column dot products into fixed slots, so the result does not depend on the
 * thread count (nor on cache evictions: a column evaluates to the same values). */
#include "cubature_train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sw_mesh.h"

#include "thread_pool.h"

/* Column cache budget (sw_cubature_train); m = r T = 3000 rows keeps ~11k columns. */
#define DEFAULT_CACHE_BYTES ((size_t)256 << 20)
#define AUTO_CANDIDATES 1000     /* greedy / importance: random subset per iteration */
#define AUTO_PER_ITERATION 10    /* importance: points added per iteration */
#define NNHTP_CANDIDATE_FACTOR 5 /* NN-HTP: ~5 s random candidates (thesis, DESIGN §8) */
#define NNHTP_FIRST_SIZE 8       /* first support bound s; grown by NNHTP_GROWTH */
#define NNHTP_GROWTH 2.0
#define NNHTP_STALL 4 /* iterations without 0.1% progress end a stage */
#define NNHTP_STAGE_ITERATIONS 40
#define NNHTP_REFINE 16 /* bisect the bound down to ~1/16 of the size */
#define NNLS_TOL 1e-10
#define PRUNE_REL 1e-12

static uint64_t rng_next(uint64_t *s) { /* splitmix64 */
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double rng_unit(uint64_t *s) {
    return ((double)(rng_next(s) >> 11) + 0.5) * 0x1.0p-53;
}

/* Uniform in [0, n) without modulo bias. */
static int64_t rng_below(uint64_t *s, int64_t n) {
    uint64_t un = (uint64_t)n, lim = UINT64_MAX - UINT64_MAX % un;
    uint64_t v;
    do
        v = rng_next(s);
    while (v >= lim);
    return (int64_t)(v % un);
}

/* ---- the column cache ---------------------------------------------------------- */

typedef struct col_cache {
    const sw_cubature_problem *prob;
    int64_t m, nc;
    double **col;          /* nc: cached column or NULL */
    double *norm, *atb;    /* nc: |a_e| and a_e . b, valid once evaluated */
    uint64_t *used;        /* nc: last-use tick (LRU eviction) */
    unsigned char *pinned; /* nc: in the support or in the current batch */
    int64_t ncached, cap;
    uint64_t tick;
    int64_t evaluated;
    sw_pool *pool;
} col_cache;

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
static sinew_result cache_fetch(col_cache *cc, const int64_t *ids, int64_t k, const double *r,
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

static void cache_free(col_cache *cc) {
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

/* ---- the trainer state: current support, weights, Gram matrix, residual -------- */

typedef struct trainer {
    col_cache cc;
    sw_cubature_params par; /* defaults resolved */
    int64_t m, nc;
    const double *b;
    double bnorm;
    int64_t s;     /* support size */
    int64_t *ids;  /* support (max_points) */
    double *w;     /* weights (max_points) */
    double *G;     /* s x s Gram matrix of the support (FNNLS only) */
    double *r;     /* m: b - A_C w */
    double rel;    /* |r| / |b| */
    int64_t *pos;  /* nc: position in the support or -1 */
    int64_t *perm; /* nc: permutation consumed by the sampler */
    uint64_t rng;
    int64_t best_n;
    int64_t *best_ids;
    double *best_w, best_rel;
    int current_is_best;
    int iterations;
} trainer;

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
static sinew_result solve_on(trainer *t, const int64_t *list, int64_t k, const double *x0,
                             sw_error *err) {
    const int64_t m = t->m;
    double *x = malloc((size_t)(k ? k : 1) * sizeof(double));
    double *G = NULL, *aux = NULL;
    if (!x) goto oom;
    /* Usually all cached already; the best set (restore_best) may have been evicted. */
    sinew_result res = cache_fetch(&t->cc, list, k, NULL, NULL, err);
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
static int64_t sample_candidates(trainer *t, int64_t K, int64_t *out) {
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

typedef struct keyed {
    double key;
    int64_t i;
} keyed;

static int by_key_desc(const void *pa, const void *pb) {
    const keyed *a = pa, *b = pb;
    if (a->key != b->key) return a->key > b->key ? -1 : 1;
    return (a->i > b->i) - (a->i < b->i); /* ties: sample order (deterministic) */
}

/* Scratch shared by the selectors, sized for the largest batch and support. */
typedef struct select_buf {
    int64_t *batch, *list;
    double *score, *x0;
    keyed *keys;
} select_buf;

/* The support followed by `extra` new ids: the NNLS warm start keeps the old weights. */
static sinew_result grow_support(trainer *t, select_buf *sb, const int64_t *extra, int64_t nextra,
                                 sw_error *err) {
    memcpy(sb->list, t->ids, (size_t)t->s * sizeof(int64_t));
    memcpy(sb->x0, t->w, (size_t)t->s * sizeof(double));
    for (int64_t i = 0; i < nextra; ++i) {
        sb->list[t->s + i] = extra[i];
        sb->x0[t->s + i] = 0;
    }
    return solve_on(t, sb->list, t->s + nextra, sb->x0, err);
}

/* Algorithm 1 (An et al. 2008) and Algorithm 2 (Kim & Delaney 2013): add the best
 * correlated candidate of a random subset, or sample `per_iteration` of them with
 * probability proportional to a_e . r (eq. 2.15). Only the positive part counts:
 * under w >= 0 a column pointing away from the residual gets weight zero and would
 * be pruned right after the NNLS. Sets *stuck when no candidate can help. */
static sinew_result run_additive(trainer *t, select_buf *sb, int *stuck, sw_error *err) {
    const int importance = t->par.selector == SW_CUBATURE_IMPORTANCE;
    const int64_t max_points = t->par.max_points;
    int64_t max_iter = 4 * max_points + 100, misses = 0;
    while (t->rel > t->par.tol && t->s < max_points && t->iterations < max_iter) {
        int64_t K = sample_candidates(t, t->par.candidates, sb->batch);
        if (K == 0) break;
        sinew_result res = cache_fetch(&t->cc, sb->batch, K, t->r, sb->score, err);
        if (res != SINEW_OK) return res;
        int64_t npos = 0;
        for (int64_t i = 0; i < K; ++i) {
            double sc = sb->score[i], nrm = t->cc.norm[sb->batch[i]];
            if (!(sc > 0 && nrm > 0)) continue;
            /* Greedy: cosine with r (Algorithm 1, line 5). Importance: Efraimidis-
             * Spirakis keys log(u)/p pick without replacement with probability ~ p. */
            double key = importance ? log(rng_unit(&t->rng)) / sc : sc / nrm;
            sb->keys[npos++] = (keyed){key, i};
        }
        if (npos == 0) {
            /* No candidate correlates with r: with all of them examined, the NNLS
             * over every candidate is optimal already and nothing can improve it. */
            if (K == t->nc - t->s || ++misses > 20) {
                *stuck = 1;
                break;
            }
            continue;
        }
        misses = 0;
        int64_t nadd = importance ? t->par.per_iteration : 1;
        if (nadd > max_points - t->s) nadd = max_points - t->s;
        if (nadd > npos) nadd = npos;
        qsort(sb->keys, (size_t)npos, sizeof(keyed), by_key_desc);
        int64_t add[1];
        int64_t *extra = nadd == 1 ? add : sb->batch + K; /* room: see train() */
        for (int64_t i = 0; i < nadd; ++i)
            extra[i] = sb->batch[sb->keys[i].i];
        /* The chosen columns are still cached: nothing evicts before solve_on. */
        res = grow_support(t, sb, extra, nadd, err);
        if (res != SINEW_OK) return res;
        t->iterations++;
    }
    return SINEW_OK;
}

/* Restores the best set found so far as the current support (NN-HTP is not
 * monotone; every stage starts from the best, not the last, iterate). */
static sinew_result restore_best(trainer *t, select_buf *sb, sw_error *err) {
    if (t->current_is_best) return SINEW_OK;
    memcpy(sb->list, t->best_ids, (size_t)t->best_n * sizeof(int64_t));
    memcpy(sb->x0, t->best_w, (size_t)t->best_n * sizeof(double));
    return solve_on(t, sb->list, t->best_n, sb->x0, err);
}

/* The gradient step left the support unchanged: in a coherent dictionary (all
 * columns alike, e.g. all positive) HTP's step mu h is then too short to swap any
 * entry, however poor the support. Escape as subspace pursuit / CoSaMP do: NNLS on
 * the merged set S (support + new entries, list[0..nS)), keep the sb_s largest
 * contributions w_e |a_e|, re-solve. Sets *done when the support still repeats. */
static sinew_result nnhtp_merge_step(trainer *t, select_buf *sb, int64_t sb_s, int64_t nS,
                                     int *done, sw_error *err) {
    const int64_t s_old = t->s;
    int64_t *old = sb->batch; /* the sample is consumed: reuse as scratch */
    memcpy(old, t->ids, (size_t)s_old * sizeof(int64_t));
    int64_t *nl = sb->list + nS;
    double *nx = sb->x0 + nS;
    memcpy(nl, sb->list, (size_t)nS * sizeof(int64_t));
    for (int64_t i = 0; i < nS; ++i)
        nx[i] = i < s_old ? t->w[i] : 0;
    sinew_result res = solve_on(t, nl, nS, nx, err);
    if (res != SINEW_OK) return res;
    if (t->s > sb_s) {
        int64_t k = 0;
        for (int64_t i = 0; i < t->s; ++i)
            sb->keys[k++] = (keyed){t->w[i] * t->cc.norm[t->ids[i]], i};
        qsort(sb->keys, (size_t)k, sizeof(keyed), by_key_desc);
        for (int64_t i = 0; i < sb_s; ++i) {
            nl[i] = t->ids[sb->keys[i].i];
            nx[i] = t->w[sb->keys[i].i];
        }
        res = solve_on(t, nl, sb_s, nx, err);
        if (res != SINEW_OK) return res;
    }
    int same = t->s == s_old;
    for (int64_t i = 0; same && i < s_old; ++i)
        same = t->pos[old[i]] >= 0;
    *done = same;
    t->iterations++;
    return SINEW_OK;
}

/* One NN-HTP iteration (Algorithm 3, eqs. 2.17-2.19) with support bound sb_s and a
 * lazy gradient on K random outside candidates. With h = A^T r = -grad g / 2, the
 * step w + mu h (mu from eq. 2.19, where the factor 2 cancels) is thresholded to its
 * sb_s largest positive entries. Sets *done when the support would not change (2:
 * when no outside candidate correlates with r at all). */
static sinew_result nnhtp_step(trainer *t, select_buf *sb, int64_t sb_s, int *done, sw_error *err) {
    const int64_t m = t->m, s = t->s;
    int64_t K = t->par.candidates > 0 ? t->par.candidates : NNHTP_CANDIDATE_FACTOR * sb_s;
    K = sample_candidates(t, K, sb->batch);
    sinew_result res = cache_fetch(&t->cc, sb->batch, K, t->r, sb->score, err);
    if (res != SINEW_OK) return res;
    /* eq. 2.18: the support plus the sb_s outside entries of largest -grad. */
    int64_t npos = 0;
    for (int64_t i = 0; i < K; ++i)
        if (sb->score[i] > 0) sb->keys[npos++] = (keyed){sb->score[i], i};
    if (npos == 0) { /* 2: every outside candidate was examined */
        *done = K == t->nc - t->s ? 2 : 1;
        return SINEW_OK;
    }
    qsort(sb->keys, (size_t)npos, sizeof(keyed), by_key_desc);
    if (npos > sb_s) npos = sb_s;
    int64_t nS = s + npos;
    double *h = sb->x0; /* h on S: support first, then the new entries */
    for (int64_t i = 0; i < s; ++i) {
        sb->list[i] = t->ids[i];
        h[i] = sw_dot(t->cc.col[t->ids[i]], t->r, m);
    }
    for (int64_t i = 0; i < npos; ++i) {
        sb->list[s + i] = sb->batch[sb->keys[i].i];
        h[s + i] = sb->keys[i].key;
    }
    /* eq. 2.19: mu = |h_S|^2 / |A h_S|^2. */
    double hh = 0, *Ah = sb->score + K; /* room: see train() */
    memset(Ah, 0, (size_t)m * sizeof(double));
    for (int64_t i = 0; i < nS; ++i) {
        const double *a = t->cc.col[sb->list[i]];
        hh += h[i] * h[i];
        for (int64_t q = 0; q < m; ++q)
            Ah[q] += h[i] * a[q];
    }
    double AhAh = sw_dot(Ah, Ah, m);
    double mu = AhAh > 0 ? hh / AhAh : 0;
    /* eq. 2.17: H_s^+ keeps the sb_s largest positive entries of w + mu h. */
    int64_t nv = 0;
    for (int64_t i = 0; i < nS; ++i) {
        double v = (i < s ? t->w[i] : 0) + mu * h[i];
        if (v > 0) sb->keys[nv++] = (keyed){v, i};
    }
    qsort(sb->keys, (size_t)nv, sizeof(keyed), by_key_desc);
    if (nv > sb_s) nv = sb_s;
    /* Algorithm 3 line 9: stop when the support repeats. */
    int64_t kept_old = 0;
    for (int64_t i = 0; i < nv; ++i)
        kept_old += sb->keys[i].i < s;
    int64_t *nl = sb->list + nS;
    double *nx = sb->x0 + nS;
    if (kept_old == s && nv == s) return nnhtp_merge_step(t, sb, sb_s, nS, done, err);
    /* Gather list/x0 in selection order into the tail scratch, then solve. */
    for (int64_t i = 0; i < nv; ++i) {
        nl[i] = sb->list[sb->keys[i].i];
        double wi = sb->keys[i].i < s ? t->w[sb->keys[i].i] : 0;
        nx[i] = wi + mu * h[sb->keys[i].i];
    }
    res = solve_on(t, nl, nv, nx, err);
    if (res == SINEW_OK) t->iterations++;
    return res;
}

/* One NN-HTP stage with support bound `bound`, from the best set so far; ends when a
 * set of at most `bound` points meets tol (*ok = 1), the support repeats, the error
 * stalls, or after NNHTP_STAGE_ITERATIONS. */
static sinew_result nnhtp_stage(trainer *t, select_buf *sb, int64_t bound, int *ok, sw_error *err) {
    sinew_result res = restore_best(t, sb, err);
    if (res != SINEW_OK) return res;
    double stage_best = INFINITY;
    int stall = 0;
    *ok = 0;
    for (int it = 0; it < NNHTP_STAGE_ITERATIONS; ++it) {
        if (t->s <= bound && t->rel <= t->par.tol) {
            *ok = 1;
            return SINEW_OK;
        }
        int done = 0;
        res = nnhtp_step(t, sb, bound, &done, err);
        if (res != SINEW_OK) return res;
        if (done == 2) break;
        /* Algorithm 3 stops when the support repeats. With a lazy gradient that only
         * means this sample held nothing better: count it as a stalled iteration. */
        if (!done && t->rel < stage_best * (1 - 1e-3)) {
            stage_best = t->rel;
            stall = 0;
        } else if (++stall >= NNHTP_STALL) {
            break;
        }
    }
    *ok = t->s <= bound && t->rel <= t->par.tol;
    return SINEW_OK;
}

/* NN-HTP with a growing support bound: s = 8, 16, 32, ... (capped by max_points)
 * until a stage meets tol; then bisection on the bound between the last failing and
 * the succeeding size, since doubling can overshoot the needed size by up to 2x. */
static sinew_result run_nnhtp(trainer *t, select_buf *sb, sw_error *err) {
    const int64_t max_points = t->par.max_points;
    int64_t lo = 0, bound = max_points < NNHTP_FIRST_SIZE ? max_points : NNHTP_FIRST_SIZE;
    int ok = 0;
    for (;;) {
        sinew_result res = nnhtp_stage(t, sb, bound, &ok, err);
        if (res != SINEW_OK) return res;
        if (ok || t->best_rel <= t->par.tol) break;
        if (bound >= max_points) return restore_best(t, sb, err);
        lo = bound;
        int64_t next = (int64_t)ceil((double)bound * NNHTP_GROWTH);
        bound = next > max_points ? max_points : next;
    }
    for (int64_t hi = t->best_n; hi - lo > 1 + hi / NNHTP_REFINE;) {
        int64_t mid = lo + (hi - lo) / 2;
        sinew_result res = nnhtp_stage(t, sb, mid, &ok, err);
        if (res != SINEW_OK) return res;
        if (ok)
            hi = t->best_n;
        else
            lo = mid;
    }
    return restore_best(t, sb, err);
}

sw_cubature_params sw_cubature_params_default(void) {
    sw_cubature_params p;
    memset(&p, 0, sizeof p);
    p.selector = SW_CUBATURE_NNHTP;
    p.tol = 0.05;
    p.max_points = 1000;
    p.seed = 1;
    p.nnls = SW_NNLS_FAST;
    p.threads = 1;
    return p;
}

void sw_cubature_result_free(sw_cubature_result *r) {
    if (!r) return;
    free(r->ids);
    free(r->weights);
    memset(r, 0, sizeof *r);
}

static sinew_result check_input(const sw_cubature_problem *prob, const sw_cubature_params *par,
                                sw_cubature_result *out, sw_error *err) {
    if (!prob || !par || !out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "cubature: NULL argument");
    if (prob->m < 1 || prob->ncandidates < 1 || prob->ncandidates > INT64_MAX / 16)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "cubature: bad problem size m = %lld, candidates = %lld",
                            (long long)prob->m, (long long)prob->ncandidates);
    if (!prob->b || !prob->column)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "cubature: problem has no %s",
                            prob->b ? "column callback" : "b");
    for (int64_t i = 0; i < prob->m; ++i)
        if (!isfinite(prob->b[i]))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "cubature: b[%lld] = %g is not finite", (long long)i, prob->b[i]);
    if (!(par->tol > 0) || !isfinite(par->tol))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "cubature: tolerance %g (must be > 0)", par->tol);
    if ((unsigned)par->selector > SW_CUBATURE_NNHTP)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "cubature: unknown selector %d",
                            (int)par->selector);
    if ((unsigned)par->nnls > SW_NNLS_FAST)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "cubature: unknown NNLS method %d",
                            (int)par->nnls);
    if (par->max_points < 0 || par->candidates < 0 || par->per_iteration < 0 || par->threads < 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "cubature: negative max_points (%d), candidates (%d), per_iteration "
                            "(%d) or threads (%d)",
                            (int)par->max_points, (int)par->candidates, (int)par->per_iteration,
                            par->threads);
    return SINEW_OK;
}

static void trainer_free(trainer *t, select_buf *sb) {
    cache_free(&t->cc);
    free(t->ids);
    free(t->w);
    free(t->G);
    free(t->r);
    free(t->pos);
    free(t->perm);
    free(t->best_ids);
    free(t->best_w);
    free(sb->batch);
    free(sb->list);
    free(sb->score);
    free(sb->x0);
    free(sb->keys);
}

/* Allocates everything; the column cache holds at most cache_bytes of columns (but
 * always the support and one batch). Returns 0 when out of memory. */
static int trainer_init(trainer *t, select_buf *sb, const sw_cubature_problem *prob,
                        uint64_t cache_bytes) {
    const int64_t m = prob->m, nc = prob->ncandidates, mp = t->par.max_points;
    t->m = m;
    t->nc = nc;
    t->b = prob->b;
    t->rng = t->par.seed;
    int64_t kmax = t->par.candidates;
    if (t->par.selector == SW_CUBATURE_NNHTP && NNHTP_CANDIDATE_FACTOR * mp > kmax)
        kmax = NNHTP_CANDIDATE_FACTOR * mp;
    if (kmax > nc) kmax = nc;
    col_cache *cc = &t->cc;
    cc->prob = prob;
    cc->m = m;
    cc->nc = nc;
    int64_t budget = (int64_t)(cache_bytes / ((uint64_t)m * sizeof(double)));
    cc->cap = budget > kmax + mp + 16 ? budget : kmax + mp + 16;
    cc->col = calloc((size_t)nc, sizeof(double *));
    cc->norm = calloc((size_t)nc, sizeof(double));
    cc->atb = calloc((size_t)nc, sizeof(double));
    cc->used = calloc((size_t)nc, sizeof(uint64_t));
    cc->pinned = calloc((size_t)nc, 1);
    if (t->par.threads > 1) cc->pool = sw_pool_create(t->par.threads); /* NULL: serial */
    t->ids = malloc((size_t)(2 * mp + 1) * sizeof(int64_t));           /* merged sets: 2 mp */
    t->w = malloc((size_t)(2 * mp + 1) * sizeof(double));
    t->r = malloc((size_t)m * sizeof(double));
    t->pos = malloc((size_t)nc * sizeof(int64_t));
    t->perm = malloc((size_t)nc * sizeof(int64_t));
    t->best_ids = malloc((size_t)(mp + 1) * sizeof(int64_t));
    t->best_w = malloc((size_t)(mp + 1) * sizeof(double));
    /* Scratch: a batch plus added points (importance), a batch of scores plus A h
     * (NN-HTP), lists of up to 4 max_points (S, then S again or the new set). */
    sb->batch = malloc((size_t)(kmax + mp + 1) * sizeof(int64_t));
    sb->score = malloc((size_t)(kmax + m + 1) * sizeof(double));
    sb->list = malloc((size_t)(4 * mp + 1) * sizeof(int64_t));
    sb->x0 = malloc((size_t)(4 * mp + 1) * sizeof(double));
    sb->keys = malloc((size_t)(kmax + 2 * mp + 1) * sizeof(keyed));
    if (!cc->col || !cc->norm || !cc->atb || !cc->used || !cc->pinned || !t->ids || !t->w ||
        !t->r || !t->pos || !t->perm || !t->best_ids || !t->best_w || !sb->batch || !sb->score ||
        !sb->list || !sb->x0 || !sb->keys)
        return 0;
    for (int64_t e = 0; e < nc; ++e) {
        t->pos[e] = -1;
        t->perm[e] = e;
    }
    memcpy(t->r, t->b, (size_t)m * sizeof(double));
    t->rel = t->best_rel = 1;
    t->current_is_best = 1;
    return 1;
}

static int by_id(const void *pa, const void *pb) {
    const keyed *a = pa, *b = pb;
    return (a->i > b->i) - (a->i < b->i);
}

/* The best set, ascending by id. */
static sinew_result fill_result(trainer *t, sw_cubature_result *out, sw_error *err) {
    int64_t n = t->best_n;
    out->n = (int32_t)n;
    out->ids = malloc((size_t)(n ? n : 1) * sizeof(int64_t));
    out->weights = malloc((size_t)(n ? n : 1) * sizeof(double));
    keyed *order = malloc((size_t)(n ? n : 1) * sizeof(keyed));
    if (!out->ids || !out->weights || !order) {
        free(order);
        sw_cubature_result_free(out);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cubature: out of memory");
    }
    for (int64_t i = 0; i < n; ++i)
        order[i] = (keyed){t->best_w[i], t->best_ids[i]};
    qsort(order, (size_t)n, sizeof(keyed), by_id);
    for (int64_t i = 0; i < n; ++i) {
        out->ids[i] = order[i].i;
        out->weights[i] = order[i].key;
    }
    free(order);
    out->rel_error = t->best_rel;
    out->iterations = t->iterations;
    out->columns_evaluated = t->cc.evaluated;
    return SINEW_OK;
}

sinew_result sw_cubature_train_cache(const sw_cubature_problem *prob,
                                     const sw_cubature_params *params, uint64_t cache_bytes,
                                     sw_cubature_result *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    sinew_result res = check_input(prob, params, out, err);
    if (res != SINEW_OK) return res;
    double t0 = sw_now_seconds();
    trainer t;
    select_buf sb;
    memset(&t, 0, sizeof t);
    memset(&sb, 0, sizeof sb);
    t.par = *params;
    if (t.par.max_points == 0) t.par.max_points = 1000;
    if (t.par.max_points > prob->ncandidates) t.par.max_points = (int32_t)prob->ncandidates;
    if (t.par.candidates == 0 && t.par.selector != SW_CUBATURE_NNHTP)
        t.par.candidates = AUTO_CANDIDATES;
    if (t.par.per_iteration == 0) t.par.per_iteration = AUTO_PER_ITERATION;
    if (t.par.candidates > prob->ncandidates) t.par.candidates = (int32_t)prob->ncandidates;
    if (cache_bytes == 0) cache_bytes = DEFAULT_CACHE_BYTES;
    if (!trainer_init(&t, &sb, prob, cache_bytes)) {
        trainer_free(&t, &sb);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "cubature: out of memory (%lld candidates, %lld rows)",
                            (long long)prob->ncandidates, (long long)prob->m);
    }
    t.bnorm = sqrt(sw_dot(prob->b, prob->b, prob->m));
    int stuck = 0;
    if (t.bnorm == 0) {
        t.rel = t.best_rel = 0; /* the empty cubature is exact */
    } else if (t.par.selector == SW_CUBATURE_NNHTP) {
        res = run_nnhtp(&t, &sb, err);
    } else {
        res = run_additive(&t, &sb, &stuck, err);
    }
    if (res == SINEW_OK) res = fill_result(&t, out, err);
    if (res == SINEW_OK && t.best_rel > t.par.tol)
        res = sw_error_set(err, SINEW_ERROR_NOT_CONVERGED,
                           "cubature: relative error %.4g above tolerance %.4g with %d points "
                           "(max_points %d%s)",
                           t.best_rel, t.par.tol, (int)t.best_n, (int)t.par.max_points,
                           stuck ? "; no remaining candidate correlates with the residual" : "");
    out->seconds = sw_now_seconds() - t0;
    trainer_free(&t, &sb);
    return res;
}

sinew_result sw_cubature_train(const sw_cubature_problem *prob, const sw_cubature_params *params,
                               sw_cubature_result *out, sw_error *err) {
    return sw_cubature_train_cache(prob, params, 0, out, err);
}
