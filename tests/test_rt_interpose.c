/* The allocation/lock call counter (tools/testkit/rt_interpose.h) that proves the frame step
 * allocation-free and lock-free (DESIGN.md §3): it must see each call made directly,
 * from our static libraries and from inside libc.so, must see nothing while off or on
 * other threads, and must count exactly zero for code that neither allocates nor
 * locks. Categories a build cannot observe (sanitizer builds: maps and locks) SKIP. */
#define _GNU_SOURCE /* memalign, valloc, mremap */

#include "rt_interpose.h"
#include "sw_error.h"
#include "sw_test.h"
#include "thread_pool.h"

#include <errno.h>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <threads.h>
#include <time.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SANITIZED 1
#endif
#endif

/* Stores here keep GCC from deleting allocation/free pairs it can prove unused. */
static void *volatile sink;

static const char *describe(const sw_rt_counts *c) {
    static char buf[1024];
    return sw_rt_counts_describe(c, buf, sizeof buf);
}

#define NEED(cats)                                                                                 \
    do {                                                                                           \
        if ((sw_rt_interpose_active() & (cats)) != (cats))                                         \
            SKIP("category not observable in this build (active mask %d)",                         \
                 sw_rt_interpose_active());                                                        \
    } while (0)

/* The allocation count of one allocating call: exact per function where the build
 * has per-function detail, otherwise (sanitizer hooks) as allocations seen; a function
 * the build cannot observe is reported and must count nothing. */
#define ENSURE_ONE_ALLOC(c, fn)                                                                    \
    do {                                                                                           \
        if (!sw_rt_fn_observable(fn)) {                                                            \
            fprintf(stderr, "  %s: not observable in this build\n", sw_rt_fn_name(fn));            \
            ENSUREF((c).allocs == 0, "%s", describe(&(c)));                                        \
        } else if (sw_rt_interpose_active() & SW_RT_DETAIL)                                        \
            ENSUREF((c).by_fn[fn] == 1 && (c).allocs == 1, "%s", describe(&(c)));                  \
        else                                                                                       \
            ENSUREF((c).allocs >= 1, "%s", describe(&(c)));                                        \
    } while (0)

TEST(active_categories_match_build) {
    int m = sw_rt_interpose_active();
    fprintf(stderr, "  active mask %d: allocs %d frees %d maps %d locks %d detail %d\n", m,
            !!(m & SW_RT_CAT_ALLOCS), !!(m & SW_RT_CAT_FREES), !!(m & SW_RT_CAT_MAPS),
            !!(m & SW_RT_CAT_LOCKS), !!(m & SW_RT_DETAIL));
#if defined(SANITIZED)
    /* Sanitizer hooks see allocations; mappings and locks belong to the runtime. */
    ENSURE((m & (SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES)) == (SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES));
    ENSURE(!(m & SW_RT_CAT_LOCKS) && !(m & SW_RT_CAT_MAPS));
#elif defined(__GLIBC__) && defined(__linux__)
    /* Everything must be observed in a normal build, or the zero-call tests prove nothing. */
    ENSURE(m == (SW_RT_CAT_ALL | SW_RT_DETAIL));
#endif
    ENSURE(sw_rt_interpose_active() == m); /* stable */
    int unseen = 0;
    for (int f = 0; f < SW_RT_FN_COUNT; ++f) {
        int cat = sw_rt_fn_category((sw_rt_fn)f);
        ENSURE(cat == SW_RT_CAT_ALLOCS || cat == SW_RT_CAT_FREES || cat == SW_RT_CAT_MAPS ||
               cat == SW_RT_CAT_LOCKS);
        if (sw_rt_fn_observable((sw_rt_fn)f))
            ENSURE(m & cat); /* never beyond its category */
        else if (m & SW_RT_DETAIL)
            ENSURE(!(m & cat)); /* normal build: all or none */
        if (!sw_rt_fn_observable((sw_rt_fn)f))
            fprintf(stderr, "%s %s",
                    unseen++ ? "" : "  not observable:", sw_rt_fn_name((sw_rt_fn)f));
    }
    if (unseen) fprintf(stderr, "\n");
    ENSURE(sw_rt_fn_observable(SW_RT_MALLOC) && sw_rt_fn_observable(SW_RT_FREE));
    ENSURE(!sw_rt_fn_observable(SW_RT_FN_COUNT) && sw_rt_fn_category(SW_RT_FN_COUNT) == 0);
}

TEST(counts_malloc_and_free) {
    NEED(SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES);
    sw_rt_count_begin();
    void *p = malloc(64);
    sink = p;
    free(p);
    sw_rt_counts c = sw_rt_count_end();
    ENSURE(p != NULL);
    ENSUREF(c.allocs == 1 && c.frees == 1 && c.maps == 0 && c.locks == 0, "%s", describe(&c));
    if (sw_rt_interpose_active() & SW_RT_DETAIL)
        ENSURE(c.by_fn[SW_RT_MALLOC] == 1 && c.by_fn[SW_RT_FREE] == 1);
    /* begin restarts from zero */
    sw_rt_count_begin();
    c = sw_rt_count_end();
    ENSUREF(c.allocs == 0 && c.frees == 0, "%s", describe(&c));
}

TEST(counts_each_allocator) {
    NEED(SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES);
    sw_rt_counts c;
    void *p = NULL;

    sw_rt_count_begin();
    p = calloc(10, 8);
    sink = p;
    c = sw_rt_count_end();
    ENSURE(p && ((unsigned char *)p)[79] == 0);
    ENSURE_ONE_ALLOC(c, SW_RT_CALLOC);

    sw_rt_count_begin();
    void *q = realloc(p, 1 << 16); /* grow: a new block under any allocator */
    sink = q;
    c = sw_rt_count_end();
    ENSURE(q != NULL);
    ENSURE_ONE_ALLOC(c, SW_RT_REALLOC);
    free(q);

    sw_rt_count_begin();
    int rc = posix_memalign(&p, 64, 256);
    sink = p;
    c = sw_rt_count_end();
    ENSURE(rc == 0 && ((uintptr_t)p & 63) == 0);
    ENSURE_ONE_ALLOC(c, SW_RT_POSIX_MEMALIGN);
    free(p);

    sw_rt_count_begin();
    p = aligned_alloc(128, 512);
    sink = p;
    c = sw_rt_count_end();
    ENSURE(p && ((uintptr_t)p & 127) == 0);
    ENSURE_ONE_ALLOC(c, SW_RT_ALIGNED_ALLOC);
    free(p);

    sw_rt_count_begin();
    p = memalign(32, 100);
    sink = p;
    c = sw_rt_count_end();
    ENSURE(p && ((uintptr_t)p & 31) == 0);
    ENSURE_ONE_ALLOC(c, SW_RT_MEMALIGN);
    free(p);

    sw_rt_count_begin();
    p = valloc(100);
    sink = p;
    c = sw_rt_count_end();
    ENSURE(p != NULL);
    ENSURE_ONE_ALLOC(c, SW_RT_VALLOC);
    free(p);

    /* free(NULL) is a call into the allocator too (the hooks cannot see it); called
     * through a volatile pointer because GCC drops a literal free(NULL). */
    if (sw_rt_interpose_active() & SW_RT_DETAIL) {
        void (*volatile release)(void *) = free;
        sw_rt_count_begin();
        release(NULL);
        c = sw_rt_count_end();
        ENSUREF(c.frees == 1 && c.allocs == 0, "%s", describe(&c));
    }
}

TEST(counts_maps) {
    NEED(SW_RT_CAT_MAPS);
    long page = sysconf(_SC_PAGESIZE);
    sw_rt_count_begin();
    void *p = mmap(NULL, (size_t)page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    void *q = p == MAP_FAILED ? p : mremap(p, (size_t)page, 4 * (size_t)page, MREMAP_MAYMOVE);
    int rc = q == MAP_FAILED ? -1 : munmap(q, 4 * (size_t)page);
    sw_rt_counts c = sw_rt_count_end();
    ENSURE(p != MAP_FAILED && q != MAP_FAILED && rc == 0);
    ENSUREF(c.maps == 3 && c.by_fn[SW_RT_MMAP] == 1 && c.by_fn[SW_RT_MREMAP] == 1 &&
                c.by_fn[SW_RT_MUNMAP] == 1 && c.allocs == 0 && c.locks == 0,
            "%s", describe(&c));
}

TEST(counts_each_lock_kind) {
    NEED(SW_RT_CAT_LOCKS);
    pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
    pthread_rwlock_t rw = PTHREAD_RWLOCK_INITIALIZER;
    pthread_cond_t cv = PTHREAD_COND_INITIALIZER;
    pthread_spinlock_t spin;
    pthread_barrier_t bar;
    sem_t sem;
    mtx_t cmu;
    cnd_t ccv;
    struct timespec past = {0, 0}; /* an absolute deadline long gone: no blocking */
    ENSURE(pthread_spin_init(&spin, PTHREAD_PROCESS_PRIVATE) == 0);
    ENSURE(pthread_barrier_init(&bar, NULL, 1) == 0);
    ENSURE(sem_init(&sem, 0, 0) == 0);
    ENSURE(mtx_init(&cmu, mtx_timed) == thrd_success && cnd_init(&ccv) == thrd_success);
    int futex_word = 0;

    sw_rt_count_begin();
    int ok = pthread_mutex_lock(&mu) == 0;
    ok &= pthread_cond_signal(&cv) == 0;
    ok &= pthread_cond_broadcast(&cv) == 0;
    ok &= pthread_cond_timedwait(&cv, &mu, &past) == ETIMEDOUT;
    ok &= pthread_mutex_unlock(&mu) == 0;
    ok &= pthread_mutex_trylock(&mu) == 0;
    ok &= pthread_mutex_unlock(&mu) == 0;
    ok &= pthread_mutex_timedlock(&mu, &past) == 0; /* free mutex: taken at once */
    ok &= pthread_mutex_unlock(&mu) == 0;
    ok &= pthread_rwlock_rdlock(&rw) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_rwlock_wrlock(&rw) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_rwlock_tryrdlock(&rw) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_rwlock_trywrlock(&rw) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_rwlock_timedrdlock(&rw, &past) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_rwlock_timedwrlock(&rw, &past) == 0;
    ok &= pthread_rwlock_unlock(&rw) == 0;
    ok &= pthread_spin_lock(&spin) == 0;
    ok &= pthread_spin_unlock(&spin) == 0;
    ok &= pthread_spin_trylock(&spin) == 0;
    ok &= pthread_spin_unlock(&spin) == 0;
    ok &= pthread_barrier_wait(&bar) == PTHREAD_BARRIER_SERIAL_THREAD;
    ok &= sem_post(&sem) == 0;
    ok &= sem_wait(&sem) == 0;
    ok &= sem_post(&sem) == 0;
    ok &= sem_trywait(&sem) == 0;
    ok &= sem_timedwait(&sem, &past) == -1 && errno == ETIMEDOUT;
    ok &= mtx_lock(&cmu) == thrd_success;
    ok &= cnd_signal(&ccv) == thrd_success;
    ok &= cnd_broadcast(&ccv) == thrd_success;
    ok &= cnd_timedwait(&ccv, &cmu, &past) == thrd_timedout;
    ok &= mtx_unlock(&cmu) == thrd_success;
    ok &= mtx_trylock(&cmu) == thrd_success;
    ok &= mtx_unlock(&cmu) == thrd_success;
    ok &= mtx_timedlock(&cmu, &past) == thrd_success;
    ok &= mtx_unlock(&cmu) == thrd_success;
    ok &= syscall(SYS_futex, &futex_word, 1 /* FUTEX_WAKE */, 1, NULL, NULL, 0) == 0;
    sw_rt_counts c = sw_rt_count_end();

    pthread_spin_destroy(&spin);
    pthread_barrier_destroy(&bar);
    sem_destroy(&sem);
    mtx_destroy(&cmu);
    cnd_destroy(&ccv);
    ENSURE(ok);
    /* clang-format off */
    static const struct {
        sw_rt_fn fn;
        uint64_t n;
    } want[] = {
        {SW_RT_MUTEX_LOCK, 1},      {SW_RT_MUTEX_TRYLOCK, 1},     {SW_RT_MUTEX_TIMEDLOCK, 1},
        {SW_RT_MUTEX_UNLOCK, 3},    {SW_RT_RWLOCK_RDLOCK, 1},     {SW_RT_RWLOCK_WRLOCK, 1},
        {SW_RT_RWLOCK_TRYRDLOCK, 1}, {SW_RT_RWLOCK_TRYWRLOCK, 1}, {SW_RT_RWLOCK_TIMEDRDLOCK, 1},
        {SW_RT_RWLOCK_TIMEDWRLOCK, 1}, {SW_RT_RWLOCK_UNLOCK, 6},  {SW_RT_COND_WAIT, 0},
        {SW_RT_COND_TIMEDWAIT, 1},  {SW_RT_COND_SIGNAL, 1},       {SW_RT_COND_BROADCAST, 1},
        {SW_RT_SPIN_LOCK, 1},       {SW_RT_SPIN_TRYLOCK, 1},      {SW_RT_SPIN_UNLOCK, 2},
        {SW_RT_BARRIER_WAIT, 1},    {SW_RT_SEM_WAIT, 1},          {SW_RT_SEM_TRYWAIT, 1},
        {SW_RT_SEM_TIMEDWAIT, 1},   {SW_RT_SEM_POST, 2},          {SW_RT_MTX_LOCK, 1},
        {SW_RT_MTX_TRYLOCK, 1},     {SW_RT_MTX_TIMEDLOCK, 1},     {SW_RT_MTX_UNLOCK, 3},
        {SW_RT_CND_WAIT, 0},        {SW_RT_CND_TIMEDWAIT, 1},     {SW_RT_CND_SIGNAL, 1},
        {SW_RT_CND_BROADCAST, 1},   {SW_RT_SYSCALL_FUTEX, 1},
    };
    /* clang-format on */
    uint64_t total = 0;
    for (size_t i = 0; i < sizeof want / sizeof want[0]; ++i) {
        ENSUREF(c.by_fn[want[i].fn] == want[i].n, "%s: %llu, want %llu (%s)",
                sw_rt_fn_name(want[i].fn), (unsigned long long)c.by_fn[want[i].fn],
                (unsigned long long)want[i].n, describe(&c));
        total += want[i].n;
    }
    ENSUREF(c.locks == total && c.allocs == 0 && c.frees == 0 && c.maps == 0, "%s", describe(&c));
    /* Every lock function of the table is exercised above. */
    for (int f = 0; f < SW_RT_FN_COUNT; ++f) {
        size_t i = 0;
        while (i < sizeof want / sizeof want[0] && want[i].fn != (sw_rt_fn)f)
            ++i;
        if (sw_rt_fn_category((sw_rt_fn)f) == SW_RT_CAT_LOCKS)
            ENSUREF(i < sizeof want / sizeof want[0], "%s not exercised", sw_rt_fn_name(f));
    }
}

/* A real blocking condvar wait, woken by another thread: the forwarded
 * pthread_cond_wait must be glibc's current ABI version, and only the waiter counts. */
typedef struct {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int ready;
    atomic_int waiting;
} wake_ctx;

static void *waker(void *p) {
    wake_ctx *w = p;
    while (!atomic_load(&w->waiting))
        sched_yield();
    pthread_mutex_lock(&w->mu);
    w->ready = 1;
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

TEST(counts_blocking_cond_wait_on_waiter_only) {
    NEED(SW_RT_CAT_LOCKS);
    wake_ctx w = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0, 0};
    pthread_t t;
    ENSURE(pthread_create(&t, NULL, waker, &w) == 0);
    sw_rt_count_begin();
    pthread_mutex_lock(&w.mu);
    atomic_store(&w.waiting, 1);
    while (!w.ready)
        pthread_cond_wait(&w.cv, &w.mu);
    pthread_mutex_unlock(&w.mu);
    sw_rt_counts c = sw_rt_count_end();
    pthread_join(t, NULL);
    /* The waker's lock/signal/unlock are on its own thread: not ours. */
    ENSUREF(c.by_fn[SW_RT_COND_WAIT] >= 1 && c.by_fn[SW_RT_MUTEX_LOCK] == 1 &&
                c.by_fn[SW_RT_MUTEX_UNLOCK] == 1 && c.by_fn[SW_RT_COND_SIGNAL] == 0 &&
                c.locks == 2 + c.by_fn[SW_RT_COND_WAIT],
            "%s", describe(&c));
}

/* Calls made inside our static libraries and inside libc.so are seen too. */
static void noop_range(void *ctx, int64_t b, int64_t e, int worker) {
    (void)worker;
    atomic_fetch_add((atomic_llong *)ctx, (long long)(e - b));
}

TEST(counts_calls_from_libraries) {
    NEED(SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES);
    int m = sw_rt_interpose_active();

    /* libsinew: the pool allocates and locks on creation and teardown. */
    sw_rt_count_begin();
    sw_pool *pool = sw_pool_create(3);
    sw_rt_counts c = sw_rt_count_end();
    ENSURE(pool != NULL && sw_pool_size(pool) == 3);
    /* calloc(pool) + calloc(threads) + malloc per worker argument (+ whatever
     * pthread_create allocates through the PLT). */
    ENSUREF(c.allocs >= 4, "%s", describe(&c));
    if (m & SW_RT_DETAIL)
        ENSUREF(c.by_fn[SW_RT_CALLOC] >= 2 && c.by_fn[SW_RT_MALLOC] >= 2, "%s", describe(&c));

    /* thread_pool.h promises parallel_for does not allocate (it does lock). */
    atomic_llong sum = 0;
    sw_rt_count_begin();
    sw_pool_parallel_for(pool, 1000, noop_range, &sum);
    c = sw_rt_count_end();
    ENSURE(atomic_load(&sum) == 1000);
    ENSUREF(c.allocs == 0 && c.frees == 0, "%s", describe(&c));
    if (m & SW_RT_CAT_LOCKS) ENSUREF(c.locks >= 4, "%s", describe(&c));

    sw_rt_count_begin();
    sw_pool_destroy(pool);
    c = sw_rt_count_end();
    ENSUREF(c.frees >= 2, "%s", describe(&c)); /* threads array and pool */
    if (m & SW_RT_CAT_LOCKS)
        ENSUREF(c.by_fn[SW_RT_MUTEX_LOCK] == 1 && c.by_fn[SW_RT_COND_BROADCAST] == 1 &&
                    c.by_fn[SW_RT_MUTEX_UNLOCK] == 1,
                "%s", describe(&c));

    /* libsinew_precompute's error setter formats into a fixed buffer: nothing at all. */
    sw_error err;
    sw_rt_count_begin();
    sinew_result r =
        sw_error_set(&err, SINEW_ERROR_INVALID_ARGUMENT, "bad item %d in %s", 17, "mesh.obj");
    c = sw_rt_count_end();
    ENSURE(r == SINEW_ERROR_INVALID_ARGUMENT && strcmp(err.msg, "bad item 17 in mesh.obj") == 0);
    ENSUREF(c.allocs == 0 && c.frees == 0 && c.maps == 0 && c.locks == 0, "%s", describe(&c));

    /* libc.so's strdup calls malloc through its own PLT. */
    char *(*volatile dup)(const char *) = strdup;
    sw_rt_count_begin();
    char *s = dup("sinew");
    c = sw_rt_count_end();
    ENSURE(s && strcmp(s, "sinew") == 0);
    free(s);
    ENSUREF(c.allocs == 1, "%s", describe(&c));
    if (m & SW_RT_DETAIL) ENSURE(c.by_fn[SW_RT_MALLOC] == 1);
}

/* Nothing is counted while off: the counters a second end() reads are unchanged. */
TEST(nothing_counted_when_off) {
    sw_rt_count_begin();
    sw_rt_counts before = sw_rt_count_end();
    pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
    for (int i = 0; i < 100; ++i) {
        sink = malloc(32);
        free(sink);
        pthread_mutex_lock(&mu);
        pthread_mutex_unlock(&mu);
    }
    sw_rt_counts after = sw_rt_count_end();
    ENSURE(memcmp(&before, &after, sizeof before) == 0);
    ENSUREF(after.allocs == 0 && after.frees == 0 && after.locks == 0, "%s", describe(&after));
}

/* Another thread allocates and locks while this one counts: none of it is ours, and
 * that thread's own counting sees exactly its own calls. */
typedef struct {
    atomic_int go, done;
    sw_rt_counts own;
} busy_ctx;

static void *busy(void *p) {
    busy_ctx *b = p;
    pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
    while (!atomic_load(&b->go))
        sched_yield();
    sw_rt_count_begin();
    for (int i = 0; i < 1000; ++i) {
        void *q = malloc((size_t)(16 + i));
        sink = q;
        free(q);
        pthread_mutex_lock(&mu);
        pthread_mutex_unlock(&mu);
    }
    b->own = sw_rt_count_end();
    atomic_store(&b->done, 1);
    return NULL;
}

TEST(other_threads_not_counted) {
    NEED(SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES);
    int m = sw_rt_interpose_active();
    busy_ctx *b = calloc(1, sizeof *b);
    ENSURE(b != NULL);
    pthread_t t;
    if (pthread_create(&t, NULL, busy, b) != 0) {
        free(b);
        ENSURE(0);
    }
    sw_rt_count_begin();
    atomic_store(&b->go, 1);
    while (!atomic_load(&b->done))
        sched_yield();
    sw_rt_counts mine = sw_rt_count_end();
    pthread_join(t, NULL);
    sw_rt_counts theirs = b->own;
    free(b);
    ENSUREF(mine.allocs == 0 && mine.frees == 0 && mine.maps == 0 && mine.locks == 0, "%s",
            describe(&mine));
    ENSUREF(theirs.allocs == 1000 && theirs.frees == 1000, "%s", describe(&theirs));
    if (m & SW_RT_CAT_LOCKS) ENSUREF(theirs.locks == 2000, "%s", describe(&theirs));
}

/* The shape of the real test of the step: thousands of calls of allocation-free,
 * lock-free code count exactly zero. */
__attribute__((noinline)) static double step_like(double *state, int n, double dt) {
    double e = 0.0;
    for (int i = 0; i < n; ++i) {
        state[i] += dt * (1.0 - state[i] * state[i]);
        e += state[i] * state[i];
    }
    return e;
}

TEST(pure_arithmetic_counts_zero) {
    NEED(SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES);
    double state[64];
    for (int i = 0; i < 64; ++i)
        state[i] = 0.01 * i;
    volatile double acc = 0.0;
    sw_rt_count_begin();
    for (int k = 0; k < 10000; ++k)
        acc += step_like(state, 64, 1e-3);
    sw_rt_counts c = sw_rt_count_end();
    ENSURE(acc > 0.0);
    ENSUREF(c.allocs == 0 && c.frees == 0 && c.maps == 0 && c.locks == 0, "%s", describe(&c));
    for (int f = 0; f < SW_RT_FN_COUNT; ++f)
        ENSURE(c.by_fn[f] == 0);
}

TEST(describe_formats_and_truncates) {
    sw_rt_counts c;
    memset(&c, 0, sizeof c);
    c.by_fn[SW_RT_MALLOC] = 2;
    c.by_fn[SW_RT_CALLOC] = 1;
    c.by_fn[SW_RT_FREE] = 3;
    c.by_fn[SW_RT_SEM_POST] = 4;
    c.allocs = 3;
    c.frees = 3;
    c.locks = 4;
    char buf[256];
    ENSURE(sw_rt_counts_describe(&c, buf, sizeof buf) == buf);
    ENSUREF(strcmp(buf, "allocs 3 (malloc 2, calloc 1), frees 3 (free 3), maps 0, locks 4 "
                        "(sem_post 4)") == 0,
            "got '%s'", buf);
    char small[12];
    memset(small, 'x', sizeof small);
    sw_rt_counts_describe(&c, small, sizeof small);
    ENSURE(strlen(small) == sizeof small - 1 && strncmp(small, "allocs 3 (m", 11) == 0);
    char one = 'x';
    sw_rt_counts_describe(&c, &one, 0); /* n == 0: nothing written */
    ENSURE(one == 'x');
    ENSURE(strcmp(sw_rt_fn_name(SW_RT_PVALLOC), "pvalloc") == 0);
    ENSURE(strcmp(sw_rt_fn_name(SW_RT_SYSCALL_FUTEX), "syscall(SYS_futex)") == 0);
    ENSURE(strcmp(sw_rt_fn_name(SW_RT_FN_COUNT), "?") == 0);
}

SW_TEST_MAIN(CASE(active_categories_match_build), CASE(counts_malloc_and_free),
             CASE(counts_each_allocator), CASE(counts_maps), CASE(counts_each_lock_kind),
             CASE(counts_blocking_cond_wait_on_waiter_only), CASE(counts_calls_from_libraries),
             CASE(nothing_counted_when_off), CASE(other_threads_not_counted),
             CASE(pure_arithmetic_counts_zero), CASE(describe_formats_and_truncates))
