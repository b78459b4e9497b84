/* Per-thread counting of allocator, mapping and lock calls (see rt_interpose.h).
 *
 * Normal builds: this file defines malloc, free, mmap, pthread_mutex_lock, ... in the
 * executable that links it. An executable's definitions come first in the dynamic
 * linker's search order, so every PLT call in the process reaches them; each wrapper
 * bumps a thread-local counter when the calling thread is counting and forwards to the
 * next definition found with dlsym(RTLD_NEXT) (glibc, or a preloaded allocator).
 *
 * Sanitizer builds: the sanitizer runtime already defines these names and must keep
 * seeing the calls, so nothing is defined here; allocations are counted through the
 * sanitizer's malloc/free hooks and the other categories are reported unobservable.
 *
 * The functions are listed once, in the table of rt_interpose_fns.h: the names, the
 * categories, the wrappers and the self-check's list of our own definitions are made
 * from it here. */
#define _GNU_SOURCE /* dlvsym, RTLD_NEXT, mremap, memalign/pvalloc, SYS_futex */

#include "rt_interpose.h"

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SW_RT_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) ||                         \
    __has_feature(memory_sanitizer)
#define SW_RT_SANITIZER 1
#endif
#endif

/* dlvsym, the versioned condvar symbols and mremap's signature are glibc's; elsewhere
 * we only report "not observable". */
#if !defined(SW_RT_SANITIZER) && defined(__GLIBC__) && defined(__linux__)
#define SW_RT_WRAP 1
#endif

#if defined(__GLIBC__)
#include <malloc.h> /* memalign, pvalloc */
#endif
#if SW_RT_WRAP
#include <dlfcn.h>
#include <pthread.h>
#include <semaphore.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <threads.h>
#include <unistd.h>
#endif

/* initial-exec: the variables live in the executable's static TLS block, so touching
 * them never calls __tls_get_addr (which may allocate) from inside malloc. */
#define SW_RT_TLS __attribute__((tls_model("initial-exec")))

static _Thread_local int tl_on SW_RT_TLS;
static _Thread_local sw_rt_counts tl_counts SW_RT_TLS;

/* The symbol each counter stands for, and its category, from the table. */
#define SYMBOL_(ID, CAT, HOW, ret, name, ...) #name,
static const char *const fn_symbols[SW_RT_FN_COUNT] = {SW_RT_FNS(SYMBOL_)};
#undef SYMBOL_
#define CATEGORY_(ID, CAT, ...) SW_RT_CAT_##CAT,
static const unsigned char fn_categories[SW_RT_FN_COUNT] = {SW_RT_FNS(CATEGORY_)};
#undef CATEGORY_

_Static_assert(SW_RT_FN_COUNT <= 64, "observable_fns is a 64-bit mask");

static int fn_category(int f) {
    return fn_categories[f];
}

int sw_rt_fn_category(sw_rt_fn fn) {
    return (fn >= 0 && fn < SW_RT_FN_COUNT) ? fn_category(fn) : 0;
}

const char *sw_rt_fn_name(sw_rt_fn fn) {
    if (fn == SW_RT_SYSCALL_FUTEX) return "syscall(SYS_futex)"; /* counted for futex only */
    return (fn >= 0 && fn < SW_RT_FN_COUNT) ? fn_symbols[fn] : "?";
}

/* Set once by sw_rt_interpose_active (computing it calls dlsym, which may allocate). */
static atomic_int active_mask = -1;
/* Bit f set: function f is observed. Written by compute_active before active_mask. */
static _Atomic uint64_t observable_fns;

static void ensure_init(void);
static int compute_active(void);

int sw_rt_interpose_active(void) {
    int m = atomic_load_explicit(&active_mask, memory_order_acquire);
    if (m < 0) {
        ensure_init();
        m = compute_active();
        atomic_store_explicit(&active_mask, m, memory_order_release);
    }
    return m;
}

int sw_rt_fn_observable(sw_rt_fn fn) {
    if (fn < 0 || fn >= SW_RT_FN_COUNT) return 0;
    (void)sw_rt_interpose_active();
    return (int)((atomic_load(&observable_fns) >> fn) & 1u);
}

#if SW_RT_WRAP
/* ---------------------------------------------------------------- normal builds -- */

static inline void count(sw_rt_fn f) {
    if (tl_on) tl_counts.by_fn[f]++;
}

/* The real functions, indexed by sw_rt_fn, plus mmap64 (which shares mmap's counter). */
enum { R_MMAP64 = SW_RT_FN_COUNT, R_COUNT };

static const char *real_name(int i) {
    return i == R_MMAP64 ? "mmap64" : fn_symbols[i];
}

static void *_Atomic real_fns[R_COUNT];
static _Thread_local int tl_resolving SW_RT_TLS;

/* glibc on x86-64 keeps the pre-2.3.2 condvar ABI under the same names; a plain dlsym
 * may hand out either, and the old one corrupts a new-style pthread_cond_t. Ask for the
 * current version first (absent on newer ports, where the plain lookup is unambiguous). */
static int is_cond_fn(int i) {
    return i >= SW_RT_COND_WAIT && i <= SW_RT_COND_BROADCAST;
}

static void *resolve(int i) {
    /* dlsym may call calloc/malloc (dlerror buffer): those land back here and are
     * served from the bootstrap arena instead of recursing. */
    if (tl_resolving) return NULL;
    tl_resolving = 1;
    void *p = NULL;
    if (is_cond_fn(i)) p = dlvsym(RTLD_NEXT, real_name(i), "GLIBC_2.3.2");
    if (!p) p = dlsym(RTLD_NEXT, real_name(i));
    tl_resolving = 0;
    if (p) atomic_store_explicit(&real_fns[i], p, memory_order_release);
    return p;
}

static inline void *real_get(int i) {
    void *p = atomic_load_explicit(&real_fns[i], memory_order_acquire);
    return p ? p : resolve(i);
}

/* void* -> function pointer without the ISO C object/function pointer cast warning. */
#define REAL(var, idx)                                                                             \
    do {                                                                                           \
        void *p_ = real_get(idx);                                                                  \
        if (p_)                                                                                    \
            memcpy(&(var), &p_, sizeof(var));                                                      \
        else                                                                                       \
            (var) = NULL;                                                                          \
    } while (0)

static void ensure_init(void) {
    for (int i = 0; i < R_COUNT; ++i)
        (void)real_get(i);
}

/* Resolving everything before main: later calls never enter dlsym, and the first
 * counted section does not count the resolver's own allocations. */
__attribute__((constructor)) static void sw_rt_constructor(void) {
    ensure_init();
}

/* ---- bootstrap arena: serves allocations made while dlsym resolves malloc itself.
 * Never freed (free() ignores these pointers); a 16-byte header keeps the size for
 * realloc. */
#define BOOT_BYTES (64 * 1024)
static _Alignas(64) unsigned char boot_arena[BOOT_BYTES];
static atomic_size_t boot_used;

static int is_boot(const void *p) {
    const unsigned char *c = p;
    return c >= boot_arena && c < boot_arena + BOOT_BYTES;
}

static void *boot_alloc(size_t n, size_t align) {
    if (align < 16) align = 16;
    if (n > BOOT_BYTES || align > 4096 || (align & (align - 1))) {
        errno = ENOMEM;
        return NULL;
    }
    size_t need = n + 16 + align;
    size_t start = atomic_fetch_add(&boot_used, need);
    if (need > BOOT_BYTES || start > BOOT_BYTES - need) {
        errno = ENOMEM;
        return NULL;
    }
    uintptr_t base = (uintptr_t)(boot_arena + start) + 16;
    base = (base + align - 1) & ~(uintptr_t)(align - 1);
    memcpy((void *)(base - 16), &n, sizeof n);
    return (void *)base; /* static storage is zero: calloc needs nothing more */
}

static size_t boot_size(const void *p) {
    size_t n;
    memcpy(&n, (const unsigned char *)p - 16, sizeof n);
    return n;
}

static void *boot_calloc(size_t k, size_t n) {
    if (n && k > SIZE_MAX / n) {
        errno = ENOMEM;
        return NULL;
    }
    return boot_alloc(k * n, 16);
}

static int boot_posix_memalign(void **out, size_t a, size_t n) {
    *out = boot_alloc(n, a);
    return *out ? 0 : ENOMEM;
}

/* ---- the wrappers ---- */
typedef const struct timespec *ts_p; /* for the table's prototypes */

/* Counts the call as `counted`, forwards it to real function `real` or, while that is
 * unresolved, returns `fallback`. */
#define WRAP(ret, name, params, args, counted, real, fallback)                                     \
    ret name params {                                                                              \
        count(counted);                                                                            \
        ret(*f_) params;                                                                           \
        REAL(f_, real);                                                                            \
        return f_ ? f_ args : (fallback);                                                          \
    }
#define WRAP_FWD(ID, ret, name, params, args, fallback)                                            \
    WRAP(ret, name, params, args, SW_RT_##ID, SW_RT_##ID, fallback)
#define WRAP_HAND(...) /* written out below */
#define WRAPPER_(ID, CAT, HOW, ...) WRAP_##HOW(ID, __VA_ARGS__)
SW_RT_FNS(WRAPPER_)
#undef WRAPPER_

#if defined(__LP64__)
/* Same function as mmap on 64-bit glibc, but a separate symbol a caller may use. */
WRAP(void *, mmap64, (void *addr, size_t len, int prot, int flags, int fd, off64_t off),
     (addr, len, prot, flags, fd, off), SW_RT_MMAP, R_MMAP64, (errno = ENOMEM, MAP_FAILED))
#endif

void *realloc(void *p, size_t n) {
    count(SW_RT_REALLOC);
    void *(*f)(void *, size_t);
    REAL(f, SW_RT_REALLOC);
    if (p && is_boot(p)) { /* move out of the arena into real memory */
        void *(*m)(size_t);
        REAL(m, SW_RT_MALLOC);
        void *q = m ? m(n) : boot_alloc(n, 16);
        if (q) memcpy(q, p, boot_size(p) < n ? boot_size(p) : n);
        return q;
    }
    return f ? f(p, n) : boot_alloc(n, 16);
}

void free(void *p) {
    count(SW_RT_FREE);
    if (!p || is_boot(p)) return;
    void (*f)(void *);
    REAL(f, SW_RT_FREE);
    if (f) f(p); /* unreachable without f: p came from a resolved allocator */
}

void *mremap(void *old, size_t old_len, size_t new_len, int flags, ...) {
    count(SW_RT_MREMAP);
    void *new_addr = NULL;
    if (flags & MREMAP_FIXED) {
        va_list ap;
        va_start(ap, flags);
        new_addr = va_arg(ap, void *);
        va_end(ap);
    }
    void *(*f)(void *, size_t, size_t, int, ...);
    REAL(f, SW_RT_MREMAP);
    if (!f) {
        errno = ENOMEM;
        return MAP_FAILED;
    }
    return f(old, old_len, new_len, flags, new_addr);
}

/* syscall(SYS_futex, ...): a hand-rolled lock. The kernel takes at most six register
 * arguments; reading six from the va_list is what glibc's own syscall() does. */
long syscall(long number, ...) {
    va_list ap;
    va_start(ap, number);
    long a[6];
    for (int i = 0; i < 6; ++i)
        a[i] = va_arg(ap, long);
    va_end(ap);
    if (number == SYS_futex) count(SW_RT_SYSCALL_FUTEX);
    long (*f)(long, ...);
    REAL(f, SW_RT_SYSCALL_FUTEX);
    if (!f) {
        errno = ENOSYS;
        return -1;
    }
    return f(number, a[0], a[1], a[2], a[3], a[4], a[5]);
}

/* Our own definition of each name, to compare with what the dynamic linker resolves. */
#define OWN_(ID, CAT, HOW, ret, name, ...) (void (*)(void)) name,
#if defined(__LP64__)
#define OWN_MMAP64 (void (*)(void)) mmap64
#else
#define OWN_MMAP64 NULL
#endif
static void (*const own_fns[R_COUNT])(void) = {SW_RT_FNS(OWN_) OWN_MMAP64};
#undef OWN_

static void *own_fn(int i) {
    void *p = NULL;
    if (own_fns[i]) memcpy(&p, &own_fns[i], sizeof p);
    return p;
}

/* A category counts as observed when, for every name in it, the real function was
 * found and the process-wide lookup (what a shared library's PLT binds to) yields our
 * wrapper; for allocations also a live check through libc's strdup, whose malloc call
 * is a PLT call from inside libc.so. */
static int compute_active(void) {
    int mask = SW_RT_CAT_ALL | SW_RT_DETAIL;
    for (int i = 0; i < R_COUNT; ++i) {
        int cat = i == R_MMAP64 ? SW_RT_CAT_MAPS : fn_category(i);
        void *mine = own_fn(i);
        if (!mine) {
#if defined(__LP64__)
            mask &= ~cat;
#endif
            continue;
        }
        if (!real_get(i) || dlsym(RTLD_DEFAULT, real_name(i)) != mine) mask &= ~cat;
    }
    if (mask & SW_RT_CAT_ALLOCS) {
        /* volatile: GCC may otherwise delete an unused strdup/free pair. */
        char *(*volatile dup)(const char *) = strdup;
        void (*volatile release)(void *) = free;
        sw_rt_count_begin();
        char *s = dup("sinew");
        release(s);
        sw_rt_counts c = sw_rt_count_end();
        if (c.by_fn[SW_RT_MALLOC] < 1) mask &= ~SW_RT_CAT_ALLOCS;
        if (c.by_fn[SW_RT_FREE] < 1) mask &= ~SW_RT_CAT_FREES;
    }
    if (!(mask & SW_RT_CAT_ALLOCS) || !(mask & SW_RT_CAT_FREES)) mask &= ~SW_RT_DETAIL;
    for (int f = 0; f < SW_RT_FN_COUNT; ++f)
        if (mask & fn_category(f)) atomic_fetch_or(&observable_fns, (uint64_t)1 << f);
    return mask;
}

static void add_hook_counts(sw_rt_counts *c) {
    (void)c;
}

#elif defined(SW_RT_SANITIZER)
/* ------------------------------------------------------------- sanitizer builds -- */

/* From <sanitizer/allocator_interface.h>, which GCC does not ship; both the GCC and
 * the LLVM runtimes export it. Returns 0 when the hook table is full. */
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void *, size_t),
                                              void (*free_hook)(const volatile void *));

static _Thread_local uint64_t tl_hook_allocs SW_RT_TLS, tl_hook_frees SW_RT_TLS;
static atomic_int hooks_installed; /* 0 not tried, 1 installed, 2 failed */

static void on_malloc(const volatile void *p, size_t n) {
    (void)p;
    (void)n;
    if (tl_on) tl_hook_allocs++;
}

static void on_free(const volatile void *p) {
    (void)p;
    if (tl_on) tl_hook_frees++;
}

static void ensure_init(void) {
    int expected = 0;
    if (atomic_compare_exchange_strong(&hooks_installed, &expected, 3)) {
        int ok = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free) != 0;
        atomic_store(&hooks_installed, ok ? 1 : 2);
    }
}

__attribute__((constructor)) static void sw_rt_constructor(void) {
    ensure_init();
}

static void add_hook_counts(sw_rt_counts *c) {
    c->allocs += tl_hook_allocs;
    c->frees += tl_hook_frees;
}

/* Hooks see what the sanitizer allocator hands out: malloc/calloc as one allocation,
 * realloc as an allocation plus a free, free(NULL) not at all, and (GCC 12 TSan) the
 * aligned allocators not at all: each function is probed live. Mappings and lock calls
 * go to the sanitizer's own interceptors and cannot be seen from here. */
static int compute_active(void) {
    if (atomic_load(&hooks_installed) != 1) return 0;
    /* volatile pointers: GCC assumes a known allocator touches no global state and
     * would otherwise fold the counter reads or delete the allocation. */
    void *(*volatile v_malloc)(size_t) = malloc;
    void *(*volatile v_calloc)(size_t, size_t) = calloc;
    void *(*volatile v_realloc)(void *, size_t) = realloc;
    void *(*volatile v_aligned)(size_t, size_t) = aligned_alloc;
    int (*volatile v_posix)(void **, size_t, size_t) = posix_memalign;
    void (*volatile v_free)(void *) = free;
#if defined(__GLIBC__)
    void *(*volatile v_memalign)(size_t, size_t) = memalign;
    void *(*volatile v_valloc)(size_t) = valloc;
    void *(*volatile v_pvalloc)(size_t) = pvalloc;
#endif
    uint64_t seen = 0;
    for (int f = 0; f < SW_RT_FN_COUNT; ++f) {
        if (!(fn_category(f) & (SW_RT_CAT_ALLOCS | SW_RT_CAT_FREES))) continue;
        void *p = NULL, *q = NULL;
        sw_rt_count_begin();
        switch (f) {
        case SW_RT_MALLOC:
            p = v_malloc(24);
            break;
        case SW_RT_CALLOC:
            p = v_calloc(3, 8);
            break;
        case SW_RT_REALLOC:
            p = v_realloc(NULL, 24);
            break;
        case SW_RT_ALIGNED_ALLOC:
            p = v_aligned(64, 64);
            break;
        case SW_RT_POSIX_MEMALIGN:
            if (v_posix(&q, 64, 64) == 0) p = q;
            break;
#if defined(__GLIBC__)
        case SW_RT_MEMALIGN:
            p = v_memalign(64, 64);
            break;
        case SW_RT_VALLOC:
            p = v_valloc(64);
            break;
        case SW_RT_PVALLOC:
            p = v_pvalloc(64);
            break;
#endif
        default:
            break;
        }
        sw_rt_counts c = sw_rt_count_end();
        if (f == SW_RT_FREE) {
            p = v_malloc(24);
            sw_rt_count_begin();
            v_free(p);
            c = sw_rt_count_end();
            if (c.frees >= 1) seen |= (uint64_t)1 << f;
            continue;
        }
        if (p) v_free(p);
        if (c.allocs >= 1) seen |= (uint64_t)1 << f;
    }
    atomic_store(&observable_fns, seen);
    int mask = 0;
    if (seen & ((uint64_t)1 << SW_RT_MALLOC)) mask |= SW_RT_CAT_ALLOCS;
    if (seen & ((uint64_t)1 << SW_RT_FREE)) mask |= SW_RT_CAT_FREES;
    return mask;
}

#else
/* ------------------------------------------------------ unsupported platforms -- */
static void ensure_init(void) {}
static void add_hook_counts(sw_rt_counts *c) {
    (void)c;
}
static int compute_active(void) {
    return 0;
}
#endif

void sw_rt_count_begin(void) {
    ensure_init();
    tl_on = 0;
    memset(&tl_counts, 0, sizeof tl_counts);
#if !SW_RT_WRAP && defined(SW_RT_SANITIZER)
    tl_hook_allocs = tl_hook_frees = 0;
#endif
    /* A compiler barrier: GCC assumes malloc and free touch no global state and might
     * otherwise move the counter accesses across them when this is inlined. */
    atomic_signal_fence(memory_order_seq_cst);
    tl_on = 1;
    atomic_signal_fence(memory_order_seq_cst);
}

sw_rt_counts sw_rt_count_end(void) {
    atomic_signal_fence(memory_order_seq_cst);
    tl_on = 0;
    atomic_signal_fence(memory_order_seq_cst);
    sw_rt_counts c = tl_counts;
    c.allocs = c.frees = c.maps = c.locks = 0;
    for (int f = 0; f < SW_RT_FN_COUNT; ++f) {
        switch (fn_category(f)) {
        case SW_RT_CAT_ALLOCS:
            c.allocs += c.by_fn[f];
            break;
        case SW_RT_CAT_FREES:
            c.frees += c.by_fn[f];
            break;
        case SW_RT_CAT_MAPS:
            c.maps += c.by_fn[f];
            break;
        default:
            c.locks += c.by_fn[f];
            break;
        }
    }
    add_hook_counts(&c);
    return c;
}

const char *sw_rt_counts_describe(const sw_rt_counts *c, char *buf, size_t n) {
    if (!buf || n == 0) return buf;
    buf[0] = '\0';
    if (!c) return buf;
    static const struct {
        const char *label;
        int cat;
    } cats[] = {{"allocs", SW_RT_CAT_ALLOCS},
                {"frees", SW_RT_CAT_FREES},
                {"maps", SW_RT_CAT_MAPS},
                {"locks", SW_RT_CAT_LOCKS}};
    const uint64_t totals[4] = {c->allocs, c->frees, c->maps, c->locks};
    size_t used = 0;
    /* snprintf returns the untruncated length: clamp so later writes stay in bounds. */
#define PUT(...)                                                                                   \
    do {                                                                                           \
        if (used < n) {                                                                            \
            int k_ = snprintf(buf + used, n - used, __VA_ARGS__);                                  \
            if (k_ > 0) used += (size_t)k_;                                                        \
        }                                                                                          \
    } while (0)
    for (int k = 0; k < 4; ++k) {
        PUT("%s%s %" PRIu64, k ? ", " : "", cats[k].label, totals[k]);
        int any = 0;
        for (int f = 0; f < SW_RT_FN_COUNT; ++f) {
            if (fn_category(f) != cats[k].cat || !c->by_fn[f]) continue;
            PUT("%s%s %" PRIu64, any ? ", " : " (", sw_rt_fn_name((sw_rt_fn)f), c->by_fn[f]);
            any = 1;
        }
        if (any) PUT(")");
    }
#undef PUT
    return buf;
}

void sw_rt_counts_report(const sw_rt_counts *c, long *allocs, long *locks) {
    unsigned active = (unsigned)sw_rt_interpose_active();
    *allocs = active & SW_RT_CAT_ALLOCS
                  ? (long)(c->allocs + c->frees + (active & SW_RT_CAT_MAPS ? c->maps : 0))
                  : -1;
    *locks = active & SW_RT_CAT_LOCKS ? (long)c->locks : -1;
}
