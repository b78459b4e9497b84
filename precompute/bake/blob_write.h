/* The blob writer (DESIGN.md §6): lays a baked character (an sw_blob_view filled from the
 * bake's arrays) out in the format of sinew/sinew_blob_format.h. The view is validated
 * first with the loader's own validator (runtime/blob/blob_load.h), so a bake bug is reported
 * here, with the message a runtime would give, instead of producing a file no runtime
 * accepts. Sections are written in id order, each at a multiple of 64 bytes with zero
 * padding, and the file is padded to a multiple of 64. Thread-safe (no shared state). */
#ifndef SW_BLOB_WRITE_H
#define SW_BLOB_WRITE_H

#include <stddef.h>

#include "blob_view.h"
#include "sw_error.h"

/* Serialises `view` into a new 64-byte aligned buffer (*data, *size bytes); the caller
 * releases it with free(). On error *data is NULL and err says why:
 * SINEW_ERROR_CORRUPT / _NOT_FINITE / _INVALID_ARGUMENT for an invalid view (the
 * message names the section and element), SINEW_ERROR_OUT_OF_MEMORY. */
sinew_result sw_blob_write_memory(const sw_blob_view *view, void **data, size_t *size,
                                  sw_error *err);

/* Serialises `view` into the file `path` atomically: writes path.tmp, fsyncs it,
 * renames it over `path` (then fsyncs the folder, best effort). On any failure the
 * temporary file is removed and `path` is untouched. SINEW_ERROR_IO names the file and
 * the system's reason; other codes as sw_blob_write_memory. */
sinew_result sw_blob_write(const char *path, const sw_blob_view *view, sw_error *err);

/* A dense R x R matrix A (row-major) by the domains' blocks, as a version-4 blob stores
 * MASS and SPRING_HESSIAN (sinew_blob_format.h): writes each block's offset into
 * blocks[nd^2] (-1 for an off-diagonal block of zeros; diagonal blocks always stored) and,
 * when packed is not NULL, the stored blocks into packed. Returns the doubles stored. */
int64_t sw_blob_pack_blocks(const sw_blob_domain *doms, int32_t nd, int32_t R, const double *A,
                            int32_t *blocks, double *packed);

/* Whether `path` can be written as sw_blob_write writes it, before the work that makes
 * it: not a folder, and its path.tmp can be created in its folder (created and removed
 * again; a path.tmp already there is opened, not removed). SINEW_ERROR_IO names the file
 * and the system's reason. */
sinew_result sw_write_file_check(const char *path, sw_error *err);

/* Writes size bytes to `path` atomically, as sw_blob_write does (path.tmp, fsync,
 * rename, the folder fsynced). */
sinew_result sw_write_file_atomic(const char *path, const uint8_t *data, size_t size,
                                  sw_error *err);

#endif
