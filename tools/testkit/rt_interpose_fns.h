/* The functions the interposer counts (rt_interpose.h), one row each: the only list.
 * rt_interpose.h makes the sw_rt_fn counters of it; rt_interpose.c makes the names, the
 * categories, the wrappers, the real-function lookups and the self-check of it.
 *
 *   X(ID, CAT, HOW, ret, name, params, args, fallback)
 *
 * ID        the counter SW_RT_<ID> (and the row's place in sw_rt_counts.by_fn)
 * CAT       its category SW_RT_CAT_<CAT>: ALLOCS, FREES, MAPS or LOCKS
 * HOW       FWD: the wrapper counts the call, forwards it to the real function and, while
 *           that is not resolved, returns `fallback` instead; HAND: the wrapper does more
 *           and is written out in rt_interpose.c (fallback empty)
 * ret name params   the prototype the wrapper defines (ts_p: const struct timespec *)
 * args      the parameters, as the forwarding call passes them
 *
 * Allocations made while dlsym resolves malloc itself are served from a bootstrap arena
 * (boot_*). A lock function can only be unresolved while dlsym is resolving on this
 * thread, and dlsym takes the dynamic linker's internal locks, not these: fail loudly.
 * Semaphores, mmap and munmap report failure through errno. C11 <threads.h> calls the
 * pthread internals directly in glibc, so it needs wrappers of its own. syscall is
 * counted only for SYS_futex (a hand-rolled lock). */
#ifndef SW_RT_INTERPOSE_FNS_H
#define SW_RT_INTERPOSE_FNS_H

/* clang-format off */
#define SW_RT_FNS(X)                                                                               \
    X(MALLOC,             ALLOCS, FWD,  void *, malloc,                                            \
      (size_t n), (n), boot_alloc(n, 16))                                                          \
    X(CALLOC,             ALLOCS, FWD,  void *, calloc,                                            \
      (size_t k, size_t n), (k, n), boot_calloc(k, n))                                             \
    X(REALLOC,            ALLOCS, HAND, void *, realloc,                                           \
      (void *p, size_t n), (p, n), )                                                               \
    X(ALIGNED_ALLOC,      ALLOCS, FWD,  void *, aligned_alloc,                                     \
      (size_t a, size_t n), (a, n), boot_alloc(n, a))                                              \
    X(POSIX_MEMALIGN,     ALLOCS, FWD,  int,    posix_memalign,                                    \
      (void **out, size_t a, size_t n), (out, a, n), boot_posix_memalign(out, a, n))               \
    X(MEMALIGN,           ALLOCS, FWD,  void *, memalign,                                          \
      (size_t a, size_t n), (a, n), boot_alloc(n, a))                                              \
    X(VALLOC,             ALLOCS, FWD,  void *, valloc,                                            \
      (size_t n), (n), boot_alloc(n, 4096))                                                        \
    X(PVALLOC,            ALLOCS, FWD,  void *, pvalloc,                                           \
      (size_t n), (n), boot_alloc(n, 4096))                                                        \
    X(FREE,               FREES,  HAND, void,   free,                                              \
      (void *p), (p), )                                                                            \
    X(MMAP,               MAPS,   FWD,  void *, mmap,                                              \
      (void *addr, size_t len, int prot, int flags, int fd, off_t off),                            \
      (addr, len, prot, flags, fd, off), (errno = ENOMEM, MAP_FAILED))                             \
    X(MREMAP,             MAPS,   HAND, void *, mremap,                                            \
      (void *old, size_t old_len, size_t new_len, int flags, ...),                                 \
      (old, old_len, new_len, flags), )                                                            \
    X(MUNMAP,             MAPS,   FWD,  int,    munmap,                                            \
      (void *addr, size_t len), (addr, len), (errno = ENOSYS, -1))                                 \
    X(MUTEX_LOCK,         LOCKS,  FWD,  int,    pthread_mutex_lock,                                \
      (pthread_mutex_t *m), (m), ENOSYS)                                                           \
    X(MUTEX_TRYLOCK,      LOCKS,  FWD,  int,    pthread_mutex_trylock,                             \
      (pthread_mutex_t *m), (m), ENOSYS)                                                           \
    X(MUTEX_TIMEDLOCK,    LOCKS,  FWD,  int,    pthread_mutex_timedlock,                           \
      (pthread_mutex_t *restrict m, ts_p restrict t), (m, t), ENOSYS)                              \
    X(MUTEX_UNLOCK,       LOCKS,  FWD,  int,    pthread_mutex_unlock,                              \
      (pthread_mutex_t *m), (m), ENOSYS)                                                           \
    X(RWLOCK_RDLOCK,      LOCKS,  FWD,  int,    pthread_rwlock_rdlock,                             \
      (pthread_rwlock_t *l), (l), ENOSYS)                                                          \
    X(RWLOCK_WRLOCK,      LOCKS,  FWD,  int,    pthread_rwlock_wrlock,                             \
      (pthread_rwlock_t *l), (l), ENOSYS)                                                          \
    X(RWLOCK_TRYRDLOCK,   LOCKS,  FWD,  int,    pthread_rwlock_tryrdlock,                          \
      (pthread_rwlock_t *l), (l), ENOSYS)                                                          \
    X(RWLOCK_TRYWRLOCK,   LOCKS,  FWD,  int,    pthread_rwlock_trywrlock,                          \
      (pthread_rwlock_t *l), (l), ENOSYS)                                                          \
    X(RWLOCK_TIMEDRDLOCK, LOCKS,  FWD,  int,    pthread_rwlock_timedrdlock,                        \
      (pthread_rwlock_t *restrict l, ts_p restrict t), (l, t), ENOSYS)                             \
    X(RWLOCK_TIMEDWRLOCK, LOCKS,  FWD,  int,    pthread_rwlock_timedwrlock,                        \
      (pthread_rwlock_t *restrict l, ts_p restrict t), (l, t), ENOSYS)                             \
    X(RWLOCK_UNLOCK,      LOCKS,  FWD,  int,    pthread_rwlock_unlock,                             \
      (pthread_rwlock_t *l), (l), ENOSYS)                                                          \
    X(COND_WAIT,          LOCKS,  FWD,  int,    pthread_cond_wait,                                 \
      (pthread_cond_t *restrict c, pthread_mutex_t *restrict m), (c, m), ENOSYS)                   \
    X(COND_TIMEDWAIT,     LOCKS,  FWD,  int,    pthread_cond_timedwait,                            \
      (pthread_cond_t *restrict c, pthread_mutex_t *restrict m, ts_p restrict t),                  \
      (c, m, t), ENOSYS)                                                                           \
    X(COND_SIGNAL,        LOCKS,  FWD,  int,    pthread_cond_signal,                               \
      (pthread_cond_t *c), (c), ENOSYS)                                                            \
    X(COND_BROADCAST,     LOCKS,  FWD,  int,    pthread_cond_broadcast,                            \
      (pthread_cond_t *c), (c), ENOSYS)                                                            \
    X(SPIN_LOCK,          LOCKS,  FWD,  int,    pthread_spin_lock,                                 \
      (pthread_spinlock_t *s), (s), ENOSYS)                                                        \
    X(SPIN_TRYLOCK,       LOCKS,  FWD,  int,    pthread_spin_trylock,                              \
      (pthread_spinlock_t *s), (s), ENOSYS)                                                        \
    X(SPIN_UNLOCK,        LOCKS,  FWD,  int,    pthread_spin_unlock,                               \
      (pthread_spinlock_t *s), (s), ENOSYS)                                                        \
    X(BARRIER_WAIT,       LOCKS,  FWD,  int,    pthread_barrier_wait,                              \
      (pthread_barrier_t *b), (b), ENOSYS)                                                         \
    X(SEM_WAIT,           LOCKS,  FWD,  int,    sem_wait,                                          \
      (sem_t *s), (s), (errno = ENOSYS, -1))                                                       \
    X(SEM_TRYWAIT,        LOCKS,  FWD,  int,    sem_trywait,                                       \
      (sem_t *s), (s), (errno = ENOSYS, -1))                                                       \
    X(SEM_TIMEDWAIT,      LOCKS,  FWD,  int,    sem_timedwait,                                     \
      (sem_t *restrict s, ts_p restrict t), (s, t), (errno = ENOSYS, -1))                          \
    X(SEM_POST,           LOCKS,  FWD,  int,    sem_post,                                          \
      (sem_t *s), (s), (errno = ENOSYS, -1))                                                       \
    X(MTX_LOCK,           LOCKS,  FWD,  int,    mtx_lock,                                          \
      (mtx_t *m), (m), thrd_error)                                                                 \
    X(MTX_TRYLOCK,        LOCKS,  FWD,  int,    mtx_trylock,                                       \
      (mtx_t *m), (m), thrd_error)                                                                 \
    X(MTX_TIMEDLOCK,      LOCKS,  FWD,  int,    mtx_timedlock,                                     \
      (mtx_t *restrict m, ts_p restrict t), (m, t), thrd_error)                                    \
    X(MTX_UNLOCK,         LOCKS,  FWD,  int,    mtx_unlock,                                        \
      (mtx_t *m), (m), thrd_error)                                                                 \
    X(CND_WAIT,           LOCKS,  FWD,  int,    cnd_wait,                                          \
      (cnd_t *c, mtx_t *m), (c, m), thrd_error)                                                    \
    X(CND_TIMEDWAIT,      LOCKS,  FWD,  int,    cnd_timedwait,                                     \
      (cnd_t *restrict c, mtx_t *restrict m, ts_p restrict t), (c, m, t), thrd_error)              \
    X(CND_SIGNAL,         LOCKS,  FWD,  int,    cnd_signal,                                        \
      (cnd_t *c), (c), thrd_error)                                                                 \
    X(CND_BROADCAST,      LOCKS,  FWD,  int,    cnd_broadcast,                                     \
      (cnd_t *c), (c), thrd_error)                                                                 \
    X(SYSCALL_FUTEX,      LOCKS,  HAND, long,   syscall,                                           \
      (long number, ...), (number), )
/* clang-format on */

#endif
