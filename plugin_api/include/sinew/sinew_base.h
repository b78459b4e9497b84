/* sinew — physics-based skinning middleware. Base header: export macro, version,
 * result codes, allocator and log hooks. Plain C99; usable from C++.
 *
 * Thread-safety: every function in this header is pure or reads only constant data,
 * and may be called from any thread at any time. */
#ifndef SINEW_BASE_H
#define SINEW_BASE_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(SINEW_BUILDING_SHARED)
#define SINEW_API __declspec(dllexport)
#elif defined(SINEW_USING_SHARED)
#define SINEW_API __declspec(dllimport)
#else
#define SINEW_API
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define SINEW_API __attribute__((visibility("default")))
#else
#define SINEW_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Version of the headers being compiled against. The ABI changes only with the major. */
#define SINEW_VERSION_MAJOR 0
#define SINEW_VERSION_MINOR 1
#define SINEW_VERSION_PATCH 0
/** Packed version: major << 16 | minor << 8 | patch. */
#define SINEW_VERSION                                                                              \
    ((uint32_t)((SINEW_VERSION_MAJOR << 16) | (SINEW_VERSION_MINOR << 8) | SINEW_VERSION_PATCH))

/** Packed version (major << 16 | minor << 8 | patch) of the library loaded at run time. */
SINEW_API uint32_t sinew_version(void);

/** Human-readable run-time version, e.g. "0.1.0". Static storage; never free it. */
SINEW_API const char *sinew_version_string(void);

/** Non-zero when a host compiled against header version `header_version` (pass
 * SINEW_VERSION) can use the loaded library: same major, library minor >= header minor. */
SINEW_API int sinew_version_compatible(uint32_t header_version);

/** Result of every fallible call. Zero is success; values are stable across versions. */
typedef enum sinew_result {
    SINEW_OK = 0,
    SINEW_ERROR_INVALID_ARGUMENT = 1, /**< a NULL, out-of-range or absurd argument */
    SINEW_ERROR_OUT_OF_MEMORY = 2,    /**< the allocator returned NULL */
    SINEW_ERROR_IO = 3,               /**< a file could not be opened, read or written */
    SINEW_ERROR_PARSE = 4,            /**< malformed text input (message names file and line) */
    SINEW_ERROR_DEGENERATE = 5,       /**< zero-volume element, empty mesh, degenerate geometry */
    SINEW_ERROR_NOT_FINITE = 6,       /**< a NaN or infinity in input or state */
    SINEW_ERROR_CORRUPT = 7,          /**< a binary input failed validation (blob, checksum) */
    SINEW_ERROR_VERSION = 8,          /**< a blob or struct of an unsupported version */
    SINEW_ERROR_CAPACITY = 9,         /**< a reserved budget is too small; raise it */
    SINEW_ERROR_NOT_CONVERGED = 10,   /**< a solver stopped before its tolerance */
    SINEW_ERROR_UNSUPPORTED = 11,     /**< a feature this build or file does not have */
    SINEW_RESULT_COUNT_ = 12
} sinew_result;

/** Short English description of a result code. Static storage; never NULL, also for
 * unknown values. */
SINEW_API const char *sinew_result_string(sinew_result result);

/** Host memory hooks. `alloc` returns memory aligned to `alignment` (a power of two,
 * at least sizeof(void*)) or NULL; `free` releases it (NULL is allowed). All-NULL
 * functions mean the C library's aligned allocation. Called only outside the step. */
typedef struct sinew_allocator {
    void *(*alloc)(size_t size, size_t alignment, void *user);
    void (*free)(void *ptr, void *user);
    void *user;
} sinew_allocator;

/** Severity of a log message; SINEW_LOG_NONE as a logger's max_level passes none. */
typedef enum sinew_log_level {
    SINEW_LOG_NONE = -1,
    SINEW_LOG_ERROR = 0,
    SINEW_LOG_WARNING = 1,
    SINEW_LOG_INFO = 2,
    SINEW_LOG_DEBUG = 3
} sinew_log_level;

/** Host log hook. `message_id` is stable across versions (see SINEW_MSG_*); `message`
 * is valid only during the call. May be called from any thread that calls into sinew.
 * Without a hook (log NULL) errors and warnings within max_level are printed to stderr,
 * one line each ("sinew: error: ..."), by one write(2): no allocation, no lock. */
typedef struct sinew_logger {
    void (*log)(sinew_log_level level, uint32_t message_id, const char *message, void *user);
    void *user;
    sinew_log_level max_level; /**< messages above this level are not formatted at all */
} sinew_logger;

/** The C library's allocation (all hooks NULL). */
static inline sinew_allocator sinew_allocator_default(void) {
    sinew_allocator a;
    a.alloc = NULL;
    a.free = NULL;
    a.user = NULL;
    return a;
}

/** The default logger: no hook, so errors and warnings are printed to stderr. */
static inline sinew_logger sinew_logger_default(void) {
    sinew_logger l;
    l.log = NULL;
    l.user = NULL;
    l.max_level = SINEW_LOG_WARNING;
    return l;
}

/** A logger that passes nothing (max_level SINEW_LOG_NONE): the silence of before. */
static inline sinew_logger sinew_logger_silent(void) {
    sinew_logger l = sinew_logger_default();
    l.max_level = SINEW_LOG_NONE;
    return l;
}

#ifdef __cplusplus
}
#endif
#endif /* SINEW_BASE_H */
