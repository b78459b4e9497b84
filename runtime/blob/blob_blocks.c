/* The constant reduced matrices' domain blocks (sinew_blob_format.h, id 65): REDUCED_BLOCKS
 * present exactly in a blob of version 4 (layer 1, sw_blob_blocks_fill) and its offsets
 * packing MASS and SPRING_HESSIAN without gaps (layer 2, sw_blob_blocks_validate, shared
 * with the writer); entries and nonzero tests for the runtime. No allocation.
 *
 * The mass U^T M U is block diagonal and the springs couple only domains that share
 * vertices (thesis eqs. 4.17-4.20): dense, the two are most of a blob's bytes and mostly
 * zeros; the step already walks them by blocks (runtime/fem/reduced_map.c). */
#include "blob_check.h"

#define fail sw_blob_fail

sinew_result sw_blob_blocks_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                 const int found[], uint32_t version, sw_blob_view *v, char *msg,
                                 size_t ms) {
    v->reduced_blocks = NULL;
    v->nspring_hessian = (int64_t)s[found[SINEW_SECTION_SPRING_HESSIAN]].count;
    v->nmass = (int64_t)s[found[SINEW_SECTION_MASS]].count;
    const int present = found[SINEW_SECTION_REDUCED_BLOCKS] >= 0;
    /* the version says what MASS and SPRING_HESSIAN hold: the header is outside the
     * checksum, and a version-3 reader would take packed blocks for a dense matrix */
    if (present != (version >= 4))
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    present ? "blob section REDUCED_BLOCKS: present in a blob of format version "
                              "%u (it needs version 4)"
                            : "blob header: format version %u without REDUCED_BLOCKS (a blob "
                              "with dense reduced matrices is version 2 or 3)",
                    (unsigned)version);
    if (!present) return SINEW_OK;
    SW_BLOB_COUNT_LOCALS(v); /* ndomains */
    const sw_blob_count_expect expect[] = {SINEW_BLOB_BLOCKS_SECTIONS(SW_BLOB_EXPECT_ROW)};
    sinew_result r =
        sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0], "META", msg, ms);
    if (r != SINEW_OK) return r;
    SINEW_BLOB_BLOCKS_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

/* Matrix m's offsets: diagonal blocks stored, the stored ones back to back from 0 to the
 * section's end. */
static sinew_result check_packing(const sw_blob_view *v, int m, char *msg, size_t ms) {
    const int32_t nd = v->ndomains;
    const char *name = m == SW_BLOB_MASS ? "MASS" : "SPRING_HESSIAN";
    const int64_t n = m == SW_BLOB_MASS ? v->nmass : v->nspring_hessian;
    int64_t at = 0;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < nd; ++b) {
            int32_t off = v->reduced_blocks[((int64_t)m * nd + a) * nd + b];
            if (off < 0 && off != -1)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section REDUCED_BLOCKS: %s block (%d, %d) at %d (an offset "
                            "or -1)",
                            name, a, b, off);
            if (off < 0 && a == b)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section REDUCED_BLOCKS: %s diagonal block %d not stored", name,
                            a);
            if (off < 0) continue;
            if (off != at)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section REDUCED_BLOCKS: %s block (%d, %d) at %d, where the "
                            "blocks before it end at %lld",
                            name, a, b, off, (long long)at);
            at += (int64_t)v->domains[a].rank * v->domains[b].rank;
        }
    if (at != n)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section %s: holds %lld doubles, its stored blocks %lld", name,
                    (long long)n, (long long)at);
    return SINEW_OK;
}

sinew_result sw_blob_blocks_validate(const sw_blob_view *v, char *msg, size_t ms) {
    const int64_t dense = (int64_t)v->rank_total * v->rank_total;
    if (!v->reduced_blocks) {
        if (v->nmass != dense || v->nspring_hessian != dense)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: %lld elements, dense reduced matrices need "
                        "rank_total^2 = %lld",
                        v->nmass != dense ? "MASS" : "SPRING_HESSIAN",
                        (long long)(v->nmass != dense ? v->nmass : v->nspring_hessian),
                        (long long)dense);
        /* Lumped mass projected on the basis: its diagonal is sum_v m_v |U_v col i|^2 > 0. */
        return sw_blob_check_positive(SINEW_SECTION_MASS, v->mass, v->rank_total, v->rank_total + 1,
                                      msg, ms);
    }
    sinew_result r = check_packing(v, SW_BLOB_MASS, msg, ms);
    if (r == SINEW_OK) r = check_packing(v, SW_BLOB_SPRINGS, msg, ms);
    if (r != SINEW_OK) return r;
    /* the same, a domain's diagonal block at a time */
    for (int32_t a = 0; a < v->ndomains; ++a) {
        int64_t ld;
        const double *M = sw_blob_block(v, SW_BLOB_MASS, a, a, &ld);
        if ((r = sw_blob_check_positive(SINEW_SECTION_MASS, M, v->domains[a].rank, ld + 1, msg,
                                        ms)) != SINEW_OK)
            return r;
    }
    return SINEW_OK;
}

/* The domain whose rows of q hold i. */
static int32_t domain_of(const sw_blob_view *v, int32_t i) {
    int32_t d = 0;
    while (d + 1 < v->ndomains && v->domains[d + 1].q_offset <= i)
        ++d;
    return d;
}

double sw_blob_reduced_entry(const sw_blob_view *v, int m, int32_t i, int32_t j) {
    int32_t a = domain_of(v, i), b = domain_of(v, j);
    int64_t ld;
    const double *B = sw_blob_block(v, m, a, b, &ld);
    return B ? B[(int64_t)(i - v->domains[a].q_offset) * ld + (j - v->domains[b].q_offset)] : 0.0;
}

int sw_blob_block_nonzero(const sw_blob_view *v, int m, int32_t a, int32_t b) {
    int64_t ld;
    const double *B = sw_blob_block(v, m, a, b, &ld);
    for (int32_t r = 0; B && r < v->domains[a].rank; ++r)
        for (int32_t c = 0; c < v->domains[b].rank; ++c)
            if (B[(int64_t)r * ld + c] != 0.0) return 1;
    return 0;
}
