/* The optional pose-space equilibrium force of a blob (sinew_blob_format.h, id 51): one
 * section whose count META fixes (layer 1, sw_blob_force_fill) and whose values must be
 * finite (layer 2, sw_blob_force_validate, shared with the writer). No allocation. */
#include "blob_check.h"

sinew_result sw_blob_force_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], sw_blob_view *v, char *msg, size_t ms) {
    v->train_force = NULL;
    if (found[SINEW_SECTION_TRAIN_FORCE] < 0) return SINEW_OK; /* none */
    SW_BLOB_COUNT_LOCALS(v);                                   /* ntrain, rank_total */
    const sw_blob_count_expect expect[] = {SINEW_BLOB_FORCE_SECTIONS(SW_BLOB_EXPECT_ROW)};
    sinew_result r =
        sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0], "META", msg, ms);
    if (r != SINEW_OK) return r;
    SINEW_BLOB_FORCE_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

sinew_result sw_blob_force_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (!v->train_force) return SINEW_OK;
    return sw_blob_check_finite(SINEW_SECTION_TRAIN_FORCE, v->train_force,
                                (int64_t)v->ntrain * v->rank_total, msg, ms);
}
