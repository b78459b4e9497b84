/* The optional per-pair self-contact of a blob (sinew_blob_format.h, ids 45..50): its
 * sections' presence and counts (layer 1, sw_blob_pair_fill) and its indices and values
 * (layer 2, sw_blob_pair_validate, shared with the writer), in the manner of blob_cond.c.
 * One pass over each array, no allocation. */
#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_pair_meta) == 32, "PAIR_META is 32 bytes");

/* npair_groups in [1, ndomains^2] and npair_groups ntrain within SW_BLOB_MAX_COUNT (PAIR_PTR
 * is int32-indexed). */
static sinew_result check_counts(const sw_blob_view *v, char *msg, size_t ms) {
    const int64_t most = (int64_t)v->ndomains * v->ndomains;
    if (v->npair_groups < 1 || v->npair_groups > most)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section PAIR_META: npair_groups = %d outside [1, ndomains^2 = %lld]",
                    v->npair_groups, (long long)most);
    if ((int64_t)v->npair_groups * v->ntrain > SW_BLOB_MAX_COUNT)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section PAIR_META: npair_groups %d x ntrain %d is over %d",
                    v->npair_groups, v->ntrain, SW_BLOB_MAX_COUNT);
    return SINEW_OK;
}

sinew_result sw_blob_pair_fill(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                               sw_blob_view *v, char *msg, size_t ms) {
    sinew_blob_pair_meta m;
    int present;
    sinew_result r =
        sw_blob_group_meta(bytes, s, found, SINEW_SECTION_PAIR_FIRST, SINEW_SECTION_PAIR_LAST,
                           "the per-pair self-contact's", &m, sizeof m,
                           sizeof m.reserved / sizeof m.reserved[0], &present, msg, ms);
    if (r != SINEW_OK || !present) return r; /* none: the view's fields stay 0 / NULL */
#define FROM_META(name) v->name = m.name;
    SINEW_BLOB_PAIR_COUNTS(FROM_META)
#undef FROM_META
    if ((r = check_counts(v, msg, ms)) != SINEW_OK) return r;
    SW_BLOB_COUNT_LOCALS(v); /* ntrain, ncontacts */
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_PAIR_COUNTS);
    const sw_blob_count_expect expect[] = {SINEW_BLOB_PAIR_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
    if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0],
                                  "PAIR_META and META", msg, ms)) != SINEW_OK)
        return r;
    SINEW_BLOB_PAIR_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

/* PAIR_PTR runs through CONTACT_PTR's ranges without decreasing (pose t's groups split
 * [contact_ptr[t], contact_ptr[t+1])), and every contact of group g has its vertex in
 * domain a_g and its triangle's first corner in b_g. */
static sinew_result check_ptr(const sw_blob_view *v, char *msg, size_t ms) {
    const int32_t G = v->npair_groups, *ptr = v->pair_ptr;
    for (int32_t t = 0; t <= v->ntrain; ++t)
        if (ptr[(int64_t)t * G] != v->contact_ptr[t])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section PAIR_PTR: pose %d starts at contact %d, CONTACT_PTR says %d",
                        t, ptr[(int64_t)t * G], v->contact_ptr[t]);
    for (int64_t i = 0; i < (int64_t)G * v->ntrain; ++i) {
        if (ptr[i + 1] < ptr[i])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section PAIR_PTR: entry %lld (%d) below entry %lld (%d)",
                        (long long)i + 1, ptr[i + 1], (long long)i, ptr[i]);
        const int32_t g = (int32_t)(i % G), a = v->pair_domains[2 * g],
                      b = v->pair_domains[2 * g + 1];
        for (int32_t c = ptr[i]; c < ptr[i + 1]; ++c)
            if (v->contact_verts[8 * (int64_t)c] != a || v->contact_verts[8 * (int64_t)c + 2] != b)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section PAIR_PTR: contact %d (vertex in domain %d, triangle in "
                            "domain %d) listed in group %d of domains %d, %d",
                            c, v->contact_verts[8 * (int64_t)c],
                            v->contact_verts[8 * (int64_t)c + 2], g, a, b);
    }
    return SINEW_OK;
}

sinew_result sw_blob_pair_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->npair_groups == 0) return SINEW_OK;
    sinew_result r = check_counts(v, msg, ms);
    if (r != SINEW_OK) return r;
    const sw_blob_array_ref arrays[] = {SINEW_BLOB_PAIR_ARRAY_SECTIONS(SW_BLOB_ARRAY_REF_ROW)};
    const int64_t G = v->npair_groups;
    if ((r = sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms)) ||
        (r = sw_blob_check_indices(SINEW_SECTION_PAIR_DOMAINS, "group", 2, v->pair_domains,
                                   v->npair_groups, "domain", v->ndomains, msg, ms)) ||
        (r = sw_blob_check_finite(SINEW_SECTION_PAIR_MAP, v->pair_map, 72 * G, msg, ms)) ||
        (r = sw_blob_check_finite(SINEW_SECTION_PAIR_FEATURE, v->pair_feature, 6 * G * v->ntrain,
                                  msg, ms)) ||
        (r = sw_blob_check_finite(SINEW_SECTION_PAIR_WEIGHT, v->pair_weight, v->ncontacts, msg,
                                  ms)))
        return r;
    for (int32_t c = 0; c < v->ncontacts; ++c)
        if (v->pair_weight[c] < 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section PAIR_WEIGHT: contact %d has weight %g, must be >= 0", c,
                        v->pair_weight[c]);
    for (int32_t g = 1; g < v->npair_groups; ++g) {
        const int32_t *p = v->pair_domains + 2 * (int64_t)g;
        if (p[0] < p[-2] || (p[0] == p[-2] && p[1] <= p[-1]))
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section PAIR_DOMAINS: group %d (%d, %d) after (%d, %d): groups "
                        "must ascend",
                        g, p[0], p[1], p[-2], p[-1]);
    }
    return check_ptr(v, msg, ms);
}
