/* sinew — the stable C ABI an engine links against.
 *
 * Conventions (STYLE.md §1-§5):
 *  - Functions are sinew_<object>_<verb>; types are sinew_<snake_name>; macros SINEW_*.
 *  - Objects are opaque handles. A blob (baked character) is immutable once loaded and
 *    may be shared by any number of instances on any number of threads. An instance is
 *    owned by one thread at a time.
 *  - Every def struct starts with `struct_size` and is initialised by the inline
 *    sinew_*_def_default(). Zero in a field means "the default". The library reads
 *    only the bytes that the caller's struct_size covers, so adding fields at the end
 *    never breaks an old binary.
 *  - Every fallible call returns a sinew_result; output handles are written only on
 *    SINEW_OK.
 *  - Units: lengths in the character's own units, time in seconds, angles in radians.
 */
#ifndef SINEW_H
#define SINEW_H

#include "sinew_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A loaded, validated, immutable baked character (opaque). */
typedef struct sinew_blob sinew_blob;

/** One simulated character: pose, state and all its scratch memory (opaque). */
typedef struct sinew_instance sinew_instance;

/** How to load a blob: from a file path (mapped) or from a host-owned buffer. */
typedef struct sinew_blob_def {
    uint32_t struct_size;      /**< sizeof(sinew_blob_def), set by the default */
    const char *path;          /**< file to map, or NULL when `data` is given */
    const void *data;          /**< host buffer, 64-byte aligned, outliving the blob */
    size_t data_size;          /**< bytes in `data` */
    sinew_allocator allocator; /**< memory hooks; zero means the C library */
    sinew_logger logger;       /**< log hook; zero means silent */
} sinew_blob_def;

/** A sinew_blob_def with every field at its default. */
static inline sinew_blob_def sinew_blob_def_default(void) {
    sinew_blob_def d;
    d.struct_size = (uint32_t)sizeof(sinew_blob_def);
    d.path = NULL;
    d.data = NULL;
    d.data_size = 0;
    d.allocator.alloc = NULL;
    d.allocator.free = NULL;
    d.allocator.user = NULL;
    d.logger.log = NULL;
    d.logger.user = NULL;
    d.logger.max_level = SINEW_LOG_WARNING;
    return d;
}

/** Integration mode of an instance. */
typedef enum sinew_step_mode {
    SINEW_STEP_QUASISTATIC = 0, /**< equilibrium every frame: no inertia */
    SINEW_STEP_DYNAMIC = 1      /**< implicit dynamics: flesh lags, jiggles and settles */
} sinew_step_mode;

/** How to create an instance of a blob. All memory is reserved at creation. */
typedef struct sinew_instance_def {
    uint32_t struct_size;      /**< sizeof(sinew_instance_def), set by the default */
    sinew_step_mode mode;      /**< default quasistatic */
    uint32_t max_newton_iters; /**< per step; 0 means 5 */
    sinew_allocator allocator; /**< memory hooks; zero means the blob's */
    sinew_logger logger;       /**< log hook; zero means the blob's */
} sinew_instance_def;

/** A sinew_instance_def with every field at its default. */
static inline sinew_instance_def sinew_instance_def_default(void) {
    sinew_instance_def d;
    d.struct_size = (uint32_t)sizeof(sinew_instance_def);
    d.mode = SINEW_STEP_QUASISTATIC;
    d.max_newton_iters = 0;
    d.allocator.alloc = NULL;
    d.allocator.free = NULL;
    d.allocator.user = NULL;
    d.logger.log = NULL;
    d.logger.user = NULL;
    d.logger.max_level = SINEW_LOG_WARNING;
    return d;
}

#ifdef __cplusplus
}
#endif
#endif /* SINEW_H */
