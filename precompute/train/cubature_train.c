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
 * Files: this one (params, set-up, the result), cubature_cache.c (the column cache),
 * cubature_support.c (the NNLS re-solve on a support, the candidate sampler),
 * cubature_greedy.c (Algorithms 1-2), cubature_nnhtp.c (Algorithm 3); state in
 * cubature_internal.h.
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

#include "cubature_internal.h"
#include "sw_mesh.h"

/* Column cache budget (sw_cubature_train); m = r T = 3000 rows keeps ~11k columns. */
#define DEFAULT_CACHE_BYTES ((size_t)256 << 20)
#define AUTO_CANDIDATES 1000  /* greedy / importance: random subset per iteration */
#define AUTO_PER_ITERATION 10 /* importance: points added per iteration */

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
    sw_cubature_cache_free(&t->cc);
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
        res = sw_cubature_run_nnhtp(&t, &sb, err);
    } else {
        res = sw_cubature_run_greedy(&t, &sb, &stuck, err);
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
