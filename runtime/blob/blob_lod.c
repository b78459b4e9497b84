/* The optional pose-space level of detail of a blob (sinew_blob_format.h, ids 59..64): its
 * sections' presence and counts (layer 1, sw_blob_lod_fill) and values (layer 2,
 * sw_blob_lod_validate, shared with the writer), in the manner of blob_asset.c. One pass
 * over each array, no allocation. */
#include <math.h>

#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_lod_meta) == 32, "LOD_META is 32 bytes");

sinew_result sw_blob_lod_fill(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                              sw_blob_view *v, char *msg, size_t ms) {
    v->nlod_verts = v->lod_rank = 0;
    v->lod_rest = v->lod_weight = v->lod_map = NULL;
    v->lod_bone = NULL;
    v->lod_basis = NULL;
    sinew_blob_lod_meta m;
    int present;
    sinew_result r = sw_blob_group_meta(
        bytes, s, found, SINEW_SECTION_LOD_FIRST, SINEW_SECTION_LOD_LAST, "the pose-space level's",
        &m, sizeof m, sizeof m.reserved / sizeof m.reserved[0], &present, msg, ms);
    if (r != SINEW_OK || !present) return r;
    if (m.nlod_verts != sw_blob_output_verts(v))
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section LOD_META: nlod_verts = %d, not the output surface's %d",
                    m.nlod_verts, sw_blob_output_verts(v));
    if (m.lod_rank < 1 || m.lod_rank > SINEW_BLOB_LOD_MAX_RANK)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section LOD_META: lod_rank = %d outside [1, %d]", m.lod_rank,
                    SINEW_BLOB_LOD_MAX_RANK);
    v->nlod_verts = m.nlod_verts;
    v->lod_rank = m.lod_rank;
    SW_BLOB_COUNT_LOCALS(v); /* nbones */
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_LOD_COUNTS);
    const sw_blob_count_expect expect[] = {SINEW_BLOB_LOD_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
    if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0],
                                  "LOD_META and META", msg, ms)) != SINEW_OK)
        return r;
    SINEW_BLOB_LOD_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

sinew_result sw_blob_lod_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->lod_rank == 0) return SINEW_OK;
    if (v->nlod_verts != sw_blob_output_verts(v) || v->lod_rank < 0 ||
        v->lod_rank > SINEW_BLOB_LOD_MAX_RANK || !v->lod_rest || !v->lod_bone || !v->lod_weight ||
        !v->lod_basis || !v->lod_map)
        return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT,
                    "pose-space level: %d vertices (the output has %d), rank %d, or an array "
                    "missing",
                    v->nlod_verts, sw_blob_output_verts(v), v->lod_rank);
    const int64_t n = v->nlod_verts;
    sinew_result r;
    if ((r = sw_blob_check_finite(SINEW_SECTION_LOD_REST, v->lod_rest, 3 * n, msg, ms)) ||
        (r = sw_blob_check_finite(SINEW_SECTION_LOD_MAP, v->lod_map,
                                  (int64_t)v->lod_rank * (9 * (int64_t)v->nbones + 1), msg, ms)) ||
        (r = sw_blob_check_influences(SINEW_SECTION_LOD_BONE, SINEW_SECTION_LOD_WEIGHT, v->lod_bone,
                                      v->lod_weight, v->nlod_verts, v->nbones, msg, ms)))
        return r;
    for (int64_t i = 0; i < 3 * n * v->lod_rank; ++i)
        if (!(fabsf(v->lod_basis[i]) <= 1.0f))
            return fail(msg, ms,
                        isnan(v->lod_basis[i]) ? SINEW_ERROR_NOT_FINITE : SINEW_ERROR_CORRUPT,
                        "blob section LOD_BASIS: entry %lld = %g outside [-1, 1] (the modes are "
                        "orthonormal)",
                        (long long)i, (double)v->lod_basis[i]);
    return SINEW_OK;
}
