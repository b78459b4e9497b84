/* Blob parsing and validation (DESIGN.md §6): turns bytes laid out as described in
 * sinew/sinew_blob_format.h into a zero-copy sw_blob_view, after checking every offset,
 * count, index and value, so that no runtime code ever has to range-check the blob.
 *
 * The same view validator runs in the writer (precompute/bake/blob_write.c) before a byte is
 * written, so a bake bug is reported at bake time, with the same message a loader would
 * give, instead of producing a file that no runtime accepts.
 *
 * Limits beyond the format header (they keep every index product of the runtime inside
 * int32 and bound the work of the validator on hostile input):
 *   - at most SW_BLOB_MAX_SECTIONS table entries;
 *   - nverts, ndomain_verts, ncub, nsurf_verts, nsurf_tris <= SW_BLOB_MAX_COUNT,
 *     nbones <= SW_BLOB_MAX_BONES, ndomains <= nbones, rank 1..SW_BLOB_MAX_RANK per
 *     domain, rank_total <= SW_BLOB_MAX_RANK_TOTAL, surface copies <= SW_BLOB_MAX_COPIES;
 *   - the optional render mesh: its counts <= SW_BLOB_MAX_COUNT, |barycentric| <=
 *     SW_BLOB_MAX_BARY (blob_render.c);
 *   - the optional condensation tet mesh: ntets <= SW_BLOB_MAX_COUNT (blob_cond.c);
 *   - the optional per-pair self-contact: npair_groups ntrain <= SW_BLOB_MAX_COUNT
 *     (blob_pair.c);
 *   - domain d's ranges are the prefix sums of the previous domains' sizes in domain
 *     order (vertex copies, q, cubature, basis, inertia_u), every domain has at least
 *     one vertex copy and one cubature tet, every surface vertex at least one copy.
 * All thread-safe: pure functions of their arguments. */
#ifndef SW_BLOB_LOAD_H
#define SW_BLOB_LOAD_H

#include <stddef.h>
#include <stdint.h>

#include "blob_active.h"
#include "blob_clusters.h"
#include "blob_collision.h"
#include "blob_pose_index.h"
#include "blob_view.h"
#include "sinew/sinew.h"

#define SW_BLOB_MAX_SECTIONS 96
#define SW_BLOB_MAX_COUNT 50000000
#define SW_BLOB_MAX_BONES 65536
#define SW_BLOB_MAX_RANK 1024
/* rank_total^2 < 2^31: the runtime indexes the dense R x R matrices with int32. */
#define SW_BLOB_MAX_RANK_TOTAL 32768
/* 2 * copies < 2^31 (surf_copies holds int32 pairs). */
#define SW_BLOB_MAX_COPIES 200000000
/* Tolerance on the sum of a vertex's skin weights (and of a render vertex's barycentrics). */
#define SW_BLOB_WEIGHT_SUM_TOL 1e-6
/* The largest |barycentric| of a render vertex: one outside the tets extrapolates its tet,
 * and a larger coefficient would amplify the tet's every motion (the bake keeps well
 * below it, precompute/import/embed.h). */
#define SW_BLOB_MAX_BARY 64.0

/* A loaded blob: the validated view plus where its bytes live. The view's pointers
 * point into `data`. */
struct sinew_blob {
    sw_blob_view view;
    const void *data;          /* the blob's bytes (mapping or host buffer) */
    size_t size;               /* bytes at `data` */
    void *map;                 /* mmap base when loaded from a path, else NULL */
    size_t map_size;           /* bytes mapped at `map` */
    sinew_allocator allocator; /* frees this struct */
    sinew_logger logger;
    sw_pose_index poses;          /* the training poses' neighbourhood, in this struct's block */
    sw_active_map act;            /* the subspace map's tables (blob_active.h), in the same block */
    sw_surface_clusters clusters; /* the output surface's clusters (blob_clusters.h), same */
    sw_coll_surface coll;         /* the collision surface (blob_collision.h), its own block */
};

/* FNV-1a 64 of n bytes (the blob checksum covers bytes [64, file_size)). */
uint64_t sw_blob_checksum(const void *data, size_t n);

/* Name of a section id ("META", "REST", ...), "unknown" for other ids. Static storage. */
const char *sw_blob_section_name(uint32_t id);

/* Validates bytes [data, data + size) as a version-1 blob and, only when everything is
 * valid, fills *view with pointers into `data` (zero copy: `data` must outlive the
 * view). `data` must be at least 8-byte aligned (64 recommended). Never reads outside
 * [data, data + size). On failure writes a message naming the section and the offending
 * element into msg (msg may be NULL) and returns:
 *   SINEW_ERROR_INVALID_ARGUMENT  data or view NULL, data misaligned
 *   SINEW_ERROR_VERSION           a format version other than SINEW_BLOB_VERSION
 *   SINEW_ERROR_NOT_FINITE        a NaN or infinity in any double
 *   SINEW_ERROR_CORRUPT           everything else: structure, checksum, counts, indices */
sinew_result sw_blob_parse(const void *data, size_t size, sw_blob_view *view, char *msg,
                           size_t msg_size);

/* Checks the counts, domain records, indices and values of a view (everything but the
 * byte structure), exactly as sw_blob_parse does after reading the section table; used
 * by the writer on the bake's view. Every array pointer must be non-NULL and hold the
 * number of elements the format header gives for its section. Same codes as above. */
sinew_result sw_blob_validate_view(const sw_blob_view *view, char *msg, size_t msg_size);

/* The validated view of a loaded blob (for the runtime's instance code). NULL for NULL. */
const sw_blob_view *sw_blob_get_view(const sinew_blob *blob);

#endif
