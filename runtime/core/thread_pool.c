/* Fork-join pthread pool: one generation counter, workers wake on a condition
 * variable, the caller runs chunk 0 itself and waits for the others. */
#include "thread_pool.h"

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

struct sw_pool {
    int nworkers; /* including the caller */
    pthread_t *threads;
    pthread_mutex_t mu;
    pthread_cond_t wake, done;
    uint64_t generation;
    int pending;
    int quit;
    sw_range_fn fn;
    void *ctx;
    int64_t n;
};

typedef struct {
    sw_pool *pool;
    int index;
} worker_arg;

void sw_pool_chunk(int64_t n, int workers, int w, int64_t *begin, int64_t *end) {
    int64_t base = n / workers, rem = n % workers;
    *begin = w * base + (w < rem ? w : rem);
    *end = *begin + base + (w < rem ? 1 : 0);
}

static void *worker_main(void *p) {
    worker_arg *a = p;
    sw_pool *pool = a->pool;
    int index = a->index;
    free(a);
    uint64_t seen = 0;
    pthread_mutex_lock(&pool->mu);
    for (;;) {
        while (!pool->quit && pool->generation == seen)
            pthread_cond_wait(&pool->wake, &pool->mu);
        if (pool->quit) break;
        seen = pool->generation;
        sw_range_fn fn = pool->fn;
        void *ctx = pool->ctx;
        int64_t n = pool->n, b, e;
        pthread_mutex_unlock(&pool->mu);
        sw_pool_chunk(n, pool->nworkers, index, &b, &e);
        if (e > b) fn(ctx, b, e, index);
        pthread_mutex_lock(&pool->mu);
        if (--pool->pending == 0) pthread_cond_signal(&pool->done);
    }
    pthread_mutex_unlock(&pool->mu);
    return NULL;
}

sw_pool *sw_pool_create(int nthreads) {
    if (nthreads <= 0) {
        long c = sysconf(_SC_NPROCESSORS_ONLN);
        nthreads = c > 0 ? (int)c : 1;
    }
    if (nthreads > 256) nthreads = 256;
    sw_pool *pool = calloc(1, sizeof *pool);
    if (!pool) return NULL;
    pool->nworkers = nthreads;
    if (nthreads == 1) return pool;
    pool->threads = calloc((size_t)nthreads - 1, sizeof(pthread_t));
    if (!pool->threads) {
        free(pool);
        return NULL;
    }
    pthread_mutex_init(&pool->mu, NULL);
    pthread_cond_init(&pool->wake, NULL);
    pthread_cond_init(&pool->done, NULL);
    for (int i = 1; i < nthreads; ++i) {
        worker_arg *a = malloc(sizeof *a);
        if (a) {
            a->pool = pool;
            a->index = i;
        }
        if (!a || pthread_create(&pool->threads[i - 1], NULL, worker_main, a) != 0) {
            free(a);
            pool->nworkers = i; /* keep the workers that did start */
            break;
        }
    }
    return pool;
}

void sw_pool_destroy(sw_pool *pool) {
    if (!pool) return;
    if (pool->threads) {
        pthread_mutex_lock(&pool->mu);
        pool->quit = 1;
        pthread_cond_broadcast(&pool->wake);
        pthread_mutex_unlock(&pool->mu);
        for (int i = 1; i < pool->nworkers; ++i)
            pthread_join(pool->threads[i - 1], NULL);
        pthread_mutex_destroy(&pool->mu);
        pthread_cond_destroy(&pool->wake);
        pthread_cond_destroy(&pool->done);
        free(pool->threads);
    }
    free(pool);
}

int sw_pool_size(const sw_pool *pool) {
    return pool ? pool->nworkers : 1;
}

void sw_pool_parallel_for(sw_pool *pool, int64_t n, sw_range_fn fn, void *ctx) {
    if (n <= 0) return;
    if (!pool || pool->nworkers == 1) {
        fn(ctx, 0, n, 0);
        return;
    }
    pthread_mutex_lock(&pool->mu);
    pool->fn = fn;
    pool->ctx = ctx;
    pool->n = n;
    pool->pending = pool->nworkers - 1;
    pool->generation++;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->mu);
    int64_t b, e;
    sw_pool_chunk(n, pool->nworkers, 0, &b, &e);
    if (e > b) fn(ctx, b, e, 0);
    pthread_mutex_lock(&pool->mu);
    while (pool->pending > 0)
        pthread_cond_wait(&pool->done, &pool->mu);
    pthread_mutex_unlock(&pool->mu);
}
