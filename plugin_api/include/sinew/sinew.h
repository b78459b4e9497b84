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

/** Stable log message ids of blob loading (sinew_logger). */
#define SINEW_MSG_BLOB_INVALID_ARGUMENT 0x0100u /**< error: bad def or arguments */
#define SINEW_MSG_BLOB_IO 0x0101u               /**< error: the file could not be mapped */
#define SINEW_MSG_BLOB_INVALID 0x0102u          /**< error: validation failed (names section) */
#define SINEW_MSG_BLOB_OUT_OF_MEMORY 0x0103u    /**< error: the allocator returned NULL */
#define SINEW_MSG_BLOB_LOADED 0x0104u           /**< info: loaded, with its counts */

/** Loads and validates a blob from def->path (mapped read-only) or from def->data /
 * def->data_size (used in place: at least 8-byte aligned, 64 recommended, and it must
 * outlive the blob). Every offset, count, index and value is checked first; a
 * truncated, damaged or hostile blob gives SINEW_ERROR_CORRUPT (or _VERSION,
 * _NOT_FINITE), logged with a message naming the section, never a crash. *out is written
 * only on SINEW_OK. Reads only the def fields its struct_size covers. Allocates one small
 * struct through def->allocator. Thread-safe (no shared state). */
SINEW_API sinew_result sinew_blob_load(const sinew_blob_def *def, sinew_blob **out);

/** Unmaps and frees a blob (NULL is allowed). No instance of it may still exist. */
SINEW_API void sinew_blob_destroy(sinew_blob *blob);

/** Number of skeleton bones the blob expects in a pose (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_bone_count(const sinew_blob *blob);

/** Number of output surface vertices (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_surface_vertex_count(const sinew_blob *blob);

/** Number of output surface triangles (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_surface_triangle_count(const sinew_blob *blob);

/** Copies the output surface's triangles, 3 vertex indices each, into `indices`, which
 * holds `capacity` uint32_t (at least 3 * sinew_blob_surface_triangle_count, else
 * SINEW_ERROR_CAPACITY and nothing written). Thread-safe. */
SINEW_API sinew_result sinew_blob_surface_triangles(const sinew_blob *blob, uint32_t *indices,
                                                    uint32_t capacity);

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

/** Status flags of a step (sinew_step_stats.status). */
#define SINEW_STEP_CONVERGED 1u /**< Newton reached its tolerance */
#define SINEW_STEP_GUARD 2u     /**< the energy guard stopped Newton early (best iterate kept) */
#define SINEW_STEP_TELEPORT 4u  /**< the pose jumped: no inertia taken from that jump */
#define SINEW_STEP_FAILED 8u    /**< non-finite state: the step was undone */
#define SINEW_STEP_POSE_SPACE                                                                      \
    16u /**< quasistatic: started from the pose-space blend of training solutions */

/** Figures of an instance's last step. */
typedef struct sinew_step_stats {
    uint32_t struct_size;       /**< set by the caller to sizeof(sinew_step_stats) */
    uint32_t newton_iterations; /**< Newton updates taken */
    uint32_t status;            /**< SINEW_STEP_* flags */
    uint32_t reserved;          /**< zero */
    double residual;            /**< |gradient| at exit relative to its value at entry */
    double energy;              /**< the step's potential at exit */
} sinew_step_stats;

/** Creates an instance of `blob` (which must outlive it), reserving all the memory it
 * will ever use through the def's allocator (or the blob's). The instance starts at
 * rest in the rest pose. Thread-safety: any thread; instances of one blob are
 * independent. */
SINEW_API sinew_result sinew_instance_create(const sinew_blob *blob, const sinew_instance_def *def,
                                             sinew_instance **out);

/** Releases an instance (NULL is allowed). */
SINEW_API void sinew_instance_destroy(sinew_instance *inst);

/** Back to rest: zero correction and velocity, rest pose, no pose history. */
SINEW_API sinew_result sinew_instance_reset(sinew_instance *inst);

/** Sets the pose for the next step: `bone_count` rigid transforms (12 floats each: the
 * 3x3 rotation row-major, then the translation) mapping the bind pose to world space.
 * A non-finite or non-rigid transform is rejected (NOT_FINITE / INVALID_ARGUMENT) and
 * the previous pose kept. Never allocates or locks. */
SINEW_API sinew_result sinew_instance_set_pose(sinew_instance *inst, const float *transforms,
                                               uint32_t bone_count);

/** Advances the instance by dt seconds (0 < dt <= 1) to the current pose: quasistatic
 * or dynamic per the instance def. Never allocates, locks or blocks; its cost depends
 * on the blob's cubature and surface sizes, not on the tet count. A non-finite result
 * is undone and reported as SINEW_ERROR_NOT_FINITE. */
SINEW_API sinew_result sinew_instance_step(sinew_instance *inst, float dt);

/** Copies the output surface of the last step into host buffers of `vertex_count`
 * (= sinew_blob_surface_vertex_count) xyz triples; either buffer may be NULL. */
SINEW_API sinew_result sinew_instance_read_surface(const sinew_instance *inst, float *positions,
                                                   float *normals, uint32_t vertex_count);

/** Figures of the last step; set out->struct_size first (fields it does not cover are
 * not written). */
SINEW_API sinew_result sinew_instance_get_stats(const sinew_instance *inst, sinew_step_stats *out);

#ifdef __cplusplus
}
#endif
#endif /* SINEW_H */
