/* State shared by the cubature trainer's files: cubature_train.c (the entry, set-up and
 * result), cubature_cache.c (the column cache), cubature_support.c (the support and its
 * NNLS re-solve), cubature_greedy.c and cubature_nnhtp.c (the selectors). The loop they
 * make up is described in cubature_train.c. */
#ifndef SW_CUBATURE_INTERNAL_H
#define SW_CUBATURE_INTERNAL_H

#include <stdint.h>

#include "cubature_train.h"
#include "thread_pool.h"

#define NNHTP_CANDIDATE_FACTOR 5 /* NN-HTP: ~5 s random candidates (thesis, DESIGN §8) */

static inline uint64_t rng_next(uint64_t *s) { /* splitmix64 */
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static inline double rng_unit(uint64_t *s) {
    return ((double)(rng_next(s) >> 11) + 0.5) * 0x1.0p-53;
}

/* Uniform in [0, n) without modulo bias. */
static inline int64_t rng_below(uint64_t *s, int64_t n) {
    uint64_t un = (uint64_t)n, lim = UINT64_MAX - UINT64_MAX % un;
    uint64_t v;
    do
        v = rng_next(s);
    while (v >= lim);
    return (int64_t)(v % un);
}

/* ---- the column cache (cubature_cache.c) ---------------------------------------- */

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

/* Fetches (evaluating what is missing) and optionally scores columns (cubature_cache.c). */
sinew_result sw_cubature_cache_fetch(col_cache *cc, const int64_t *ids, int64_t k, const double *r,
                                     double *scores, sw_error *err);
void sw_cubature_cache_free(col_cache *cc);

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

typedef struct keyed {
    double key;
    int64_t i;
} keyed;

static inline int sw_cubature_by_key_desc(const void *pa, const void *pb) {
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

/* Re-solves the weights (NNLS, eq. 2.14) on a new support (cubature_support.c). */
sinew_result sw_cubature_solve_on(trainer *t, const int64_t *list, int64_t k, const double *x0,
                                  sw_error *err);
/* Up to K distinct random candidates outside the support (cubature_support.c). */
int64_t sw_cubature_sample(trainer *t, int64_t K, int64_t *out);

/* The selectors: Algorithms 1 and 2 (cubature_greedy.c; sets *stuck when no candidate
 * can help) and Algorithm 3 (cubature_nnhtp.c). */
sinew_result sw_cubature_run_greedy(trainer *t, select_buf *sb, int *stuck, sw_error *err);
sinew_result sw_cubature_run_nnhtp(trainer *t, select_buf *sb, sw_error *err);

#endif
