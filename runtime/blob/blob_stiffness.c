/* The optional painted material of a blob (sinew_blob_format.h, ids 57, 58): its sections'
 * presence and counts (layer 1, sw_blob_stiffness_fill) and values (layer 2,
 * sw_blob_stiffness_validate, shared with the writer). No allocation. */
#include <math.h>

#include "blob_check.h"

#define fail sw_blob_fail

sinew_result sw_blob_stiffness_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                    const int found[], uint32_t version, sw_blob_view *v, char *msg,
                                    size_t ms) {
    v->cub_stiffness = v->tet_stiffness = NULL;
    const int cub = found[SINEW_SECTION_CUB_STIFFNESS] >= 0,
              tet = found[SINEW_SECTION_TET_STIFFNESS] >= 0;
    if (!cub && !tet) {
        if (version != 3) return SINEW_OK; /* none: uniform material */
        /* the version says what the sections must hold: the header is outside the checksum */
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: format version %u without painted material (CUB_STIFFNESS "
                    "missing; an unpainted blob is version 2 or 4)",
                    (unsigned)version);
    }
    if (version < 3)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section %s: painted material in a blob of format version %u (it "
                    "needs version 3)",
                    cub ? "CUB_STIFFNESS" : "TET_STIFFNESS", (unsigned)version);
    if (!cub || tet != (v->ntets > 0))
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section TET_STIFFNESS: %s, with%s CUB_STIFFNESS and %d condensation "
                    "tets (it is present exactly when both are)",
                    tet ? "present" : "missing", cub ? "" : "out", v->ntets);
    SW_BLOB_COUNT_LOCALS(v); /* ncub */
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_COND_COUNTS);
    const sw_blob_count_expect expect[] = {SINEW_BLOB_STIFFNESS_SECTIONS(SW_BLOB_EXPECT_ROW)};
    sinew_result r = sw_blob_check_counts(s, found, expect, (size_t)(tet ? 2 : 1),
                                          "META and COND_META", msg, ms);
    if (r != SINEW_OK) return r;
    v->cub_stiffness =
        (const double *)(const void *)(bytes + s[found[SINEW_SECTION_CUB_STIFFNESS]].offset);
    if (tet)
        v->tet_stiffness =
            (const double *)(const void *)(bytes + s[found[SINEW_SECTION_TET_STIFFNESS]].offset);
    return SINEW_OK;
}

static sinew_result check_range(uint32_t id, const char *name, const double *a, int64_t n,
                                char *msg, size_t ms) {
    for (int64_t i = 0; i < n; ++i)
        if (!(a[i] >= SW_STIFFNESS_MIN && a[i] <= SW_STIFFNESS_MAX))
            return fail(msg, ms, isfinite(a[i]) ? SINEW_ERROR_CORRUPT : SINEW_ERROR_NOT_FINITE,
                        "blob section %s (id %u): tet %lld's multiplier %g is outside [%g, %g]",
                        name, (unsigned)id, (long long)i, a[i], SW_STIFFNESS_MIN, SW_STIFFNESS_MAX);
    return SINEW_OK;
}

sinew_result sw_blob_stiffness_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (!v->cub_stiffness) {
        if (v->tet_stiffness)
            return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT,
                        "painted material: TET_STIFFNESS without CUB_STIFFNESS");
        return SINEW_OK;
    }
    if ((v->ntets > 0) != (v->tet_stiffness != NULL))
        return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT,
                    "painted material: TET_STIFFNESS %s with %d condensation tets",
                    v->tet_stiffness ? "given" : "missing", v->ntets);
    sinew_result r = check_range(SINEW_SECTION_CUB_STIFFNESS, "CUB_STIFFNESS", v->cub_stiffness,
                                 v->ncub, msg, ms);
    if (r != SINEW_OK || !v->tet_stiffness) return r;
    if ((r = check_range(SINEW_SECTION_TET_STIFFNESS, "TET_STIFFNESS", v->tet_stiffness, v->ntets,
                         msg, ms)))
        return r;
    /* the cubature tets' indices were checked with the condensation mesh */
    for (int32_t c = 0; c < v->ncub; ++c)
        if (v->cub_stiffness[c] != v->tet_stiffness[v->cub_tet_id[c]])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section CUB_STIFFNESS: cubature tet %d's multiplier %g is not its "
                        "tet %d's %g (TET_STIFFNESS)",
                        c, v->cub_stiffness[c], v->cub_tet_id[c],
                        v->tet_stiffness[v->cub_tet_id[c]]);
    return SINEW_OK;
}
