/* A small pthread pool for hosts without a job system, and for the bake.
 * parallel_for splits [0, n) into fixed contiguous chunks that depend only on n and
 * the worker count, so a reduction that sums per-chunk partials in chunk order is
 * deterministic for a given thread count. Not used inside the per-frame step (which
 * must not lock); creation allocates, parallel_for does not. */
#ifndef SW_THREAD_POOL_H
#define SW_THREAD_POOL_H

#include <stdint.h>

typedef struct sw_pool sw_pool;

/* Called for the half-open range [begin, end) by worker `worker` (0..nworkers-1). */
typedef void (*sw_range_fn)(void *ctx, int64_t begin, int64_t end, int worker);

/* nthreads <= 0 means the number of online cores. A pool of 1 runs everything on the
 * caller's thread. Returns NULL when out of memory or threads cannot be started. */
sw_pool *sw_pool_create(int nthreads);
void sw_pool_destroy(sw_pool *pool);

/* Number of workers (the caller counts as worker 0). pool == NULL means 1. */
int sw_pool_size(const sw_pool *pool);

/* Runs fn over [0, n) in sw_pool_size() contiguous chunks, one per worker, and waits.
 * pool == NULL runs fn(ctx, 0, n, 0) on the caller. Not reentrant: fn must not call
 * parallel_for on the same pool. */
void sw_pool_parallel_for(sw_pool *pool, int64_t n, sw_range_fn fn, void *ctx);

/* The chunk [begin, end) worker w gets for n items with `workers` workers. */
void sw_pool_chunk(int64_t n, int workers, int w, int64_t *begin, int64_t *end);

#endif
