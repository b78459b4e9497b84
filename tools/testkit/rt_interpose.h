/* Counts allocator, mapping and lock calls made by one thread, to prove that the frame
 * step is allocation-free and lock-free (DESIGN.md §3: "A test proves it by interposing
 * the allocator and the pthread lock functions during thousands of steps").
 *
 * Link the static library sinew_rt_interpose into an executable that calls
 * sw_rt_count_begin(). In a normal build the library then *defines* malloc, free,
 * pthread_mutex_lock, mmap, ... in the executable; the dynamic linker binds every
 * call through a PLT (from our static libraries, from libsinew.so, from libc's own
 * strdup) to those definitions first, they count and forward to the next definition
 * (dlsym(RTLD_NEXT)). Calls glibc makes to its own internals (its malloc mapping memory,
 * a condvar taking its internal lock) are not PLT calls and are not seen: we count what
 * code calls, not what glibc does underneath.
 *
 * Under AddressSanitizer or ThreadSanitizer the sanitizer runtime already owns those
 * symbols, so nothing is defined: allocations and frees are counted through the
 * sanitizer's malloc/free hooks, mappings and locks are not observable (see
 * sw_rt_interpose_active()). */
#ifndef SW_RT_INTERPOSE_H
#define SW_RT_INTERPOSE_H

#include <stddef.h>
#include <stdint.h>

#include "rt_interpose_fns.h"

/* One counter per interposed function (the per-function detail of sw_rt_counts), in the
 * order of the table in rt_interpose_fns.h: SW_RT_MALLOC, ..., SW_RT_SYSCALL_FUTEX. */
#define SW_RT_FN_ENUM_(ID, ...) SW_RT_##ID,
typedef enum sw_rt_fn { SW_RT_FNS(SW_RT_FN_ENUM_) SW_RT_FN_COUNT } sw_rt_fn;
#undef SW_RT_FN_ENUM_

/* Category bits of sw_rt_interpose_active(). */
enum {
    SW_RT_CAT_ALLOCS = 1, /* malloc, calloc, realloc, aligned allocs */
    SW_RT_CAT_FREES = 2,  /* free */
    SW_RT_CAT_MAPS = 4,   /* mmap, mremap, munmap */
    SW_RT_CAT_LOCKS = 8,  /* pthread mutex/rwlock/cond/spin/barrier, semaphores, C11 mtx/cnd,
                             futex syscalls */
    SW_RT_CAT_ALL = 15,
    /* Not a category: by_fn also splits allocs and frees per function (normal builds). */
    SW_RT_DETAIL = 16
};

typedef struct sw_rt_counts {
    uint64_t allocs; /* sum of the allocation entries of by_fn (or sanitizer malloc hooks) */
    uint64_t frees;  /* free calls (or sanitizer free hooks) */
    uint64_t maps;   /* mmap + mremap + munmap */
    uint64_t locks;  /* sum of the lock entries of by_fn */
    /* Per-function detail. All zero for allocs/frees in sanitizer builds, where the
     * hooks do not say which function allocated. */
    uint64_t by_fn[SW_RT_FN_COUNT];
} sw_rt_counts;

/* Zeroes the calling thread's counters and starts counting its calls. Other threads
 * are never counted (each thread has its own flag and counters). Does not allocate
 * or lock. Calling it again restarts from zero. */
void sw_rt_count_begin(void);

/* Stops counting on the calling thread and returns what was counted since begin. */
sw_rt_counts sw_rt_count_end(void);

/* Which SW_RT_CAT_* categories (plus SW_RT_DETAIL) are really observed in this build
 * and process: a
 * category bit is set only when the counting wrappers (or sanitizer hooks) are in
 * place, the real functions were found, and the dynamic linker resolves the symbol
 * names to our wrappers (so shared libraries' calls are counted too). Tests assert
 * "zero calls" only for the categories set here and SKIP the rest. The first call runs
 * a self-check that counts: make it outside a counted section. */
int sw_rt_interpose_active(void);

/* What a benchmark reports of counts c: *allocs the allocation, free and (when observed)
 * mapping calls, *locks the lock calls, each -1 when this build cannot observe its
 * category (sw_rt_interpose_active). */
void sw_rt_counts_report(const sw_rt_counts *c, long *allocs, long *locks);

/* Whether calls of this one function are counted in this build (its category is
 * active and, in sanitizer builds, a live probe saw the hook fire for it: GCC 12's
 * ThreadSanitizer runs no hook for aligned_alloc, posix_memalign, memalign, valloc or
 * pvalloc). Computed with sw_rt_interpose_active(); same caveat. */
int sw_rt_fn_observable(sw_rt_fn fn);

/* Name of an interposed function ("malloc", "pthread_mutex_lock", ...). */
const char *sw_rt_fn_name(sw_rt_fn fn);

/* The SW_RT_CAT_* category of an interposed function (0 for one out of range). */
int sw_rt_fn_category(sw_rt_fn fn);

/* Writes e.g. "allocs 2 (malloc 1, calloc 1), frees 2 (free 2), maps 0, locks 0" into
 * buf (truncated to n bytes, always terminated when n > 0) and returns buf. */
const char *sw_rt_counts_describe(const sw_rt_counts *c, char *buf, size_t n);

#endif
