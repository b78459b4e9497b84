/* Hostile blobs against the parser/validator (DESIGN.md §6): truncation at every length,
 * every byte flipped (with and without a recomputed checksum), forged counts, indices and
 * offsets (checksum fixed up so the semantic check must catch them), versions and header
 * fields, and unknown sections (skipped, yet kept inside the file and off the others).
 * Round trips, the writer and the public load API are in test_blob.c; the synthetic
 * character and the forging helpers in blob_synth.h. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "blob_write.h"
#include "sinew/sinew.h"
#include "sw_test.h"

#include "blob_synth.h"

static fixture g_fix; /* views point into it: never copied */

/* ---- truncation and flipped bytes ------------------------------------------------ */

/* Parses `blob` (size bytes) copied into an exact-size buffer; when accepted, walks it. */
static sinew_result parse_copy(const uint8_t *blob, size_t size, char *msg, size_t ms,
                               int *walked) {
    uint8_t *copy = copy_exact(blob, size);
    sw_blob_view v;
    sinew_result r = sw_blob_parse(copy, size, &v, msg, ms);
    *walked = 1;
    if (r == SINEW_OK) {
        double acc = 0.0;
        char msg2[512];
        *walked = walk_view(&v, copy, size, &acc) &&
                  sw_blob_validate_view(&v, msg2, sizeof msg2) == SINEW_OK;
    }
    free(copy);
    return r;
}

TEST(truncation_at_every_length_is_an_error) {
    fixture_init(&g_fix, 5);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    uint64_t last_end = 0;
    for (uint32_t id = 1; id <= SINEW_SECTION_COUNT_V1; ++id) {
        const sinew_blob_section *e = entry(blob, id);
        if (e->offset + e->count * e->elem_size > last_end)
            last_end = e->offset + e->count * e->elem_size;
    }
    char msg[512];
    int walked;
    for (size_t cut = 0; cut < size; ++cut) {
        /* Plain cut: the header's file_size no longer matches. */
        sinew_result r = parse_copy(blob, cut, msg, sizeof msg, &walked);
        ENSUREF(r == SINEW_ERROR_CORRUPT, "cut at %zu: %d", cut, (int)r);
        if (cut < 64) continue;
        /* Hostile cut: header and checksum say the file really is that long. */
        uint8_t *forged = copy_exact(blob, cut);
        hdr(forged)->file_size = cut;
        fix_checksum(forged, cut);
        r = parse_copy(forged, cut, msg, sizeof msg, &walked);
        free(forged);
        if (cut < last_end)
            ENSUREF(r == SINEW_ERROR_CORRUPT, "hostile cut at %zu: %d", cut, (int)r);
        else
            ENSUREF(r == SINEW_OK && walked, "cut in trailing padding at %zu: %s", cut, msg);
    }
    free(blob);
}

TEST(every_flipped_byte_is_caught) {
    fixture_init(&g_fix, 6);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    uint8_t *work = copy_exact(blob, size);
    char msg[512];
    int accepted_hostile = 0, rejected_hostile = 0;
    for (size_t i = 0; i < size; ++i) {
        for (int m = 0; m < 2; ++m) {
            const uint8_t mask = m == 0 ? 0xFFu : (uint8_t)(1u << (i % 8));
            memcpy(work, blob, size);
            work[i] ^= mask;
            sw_blob_view v;
            sinew_result r = sw_blob_parse(work, size, &v, msg, sizeof msg);
            ENSUREF(r != SINEW_OK, "flip 0x%02x at byte %zu accepted", mask, i);
            if (i >= 64)
                ENSUREF(r == SINEW_ERROR_CORRUPT && contains(msg, "checksum"), "flip at %zu: %d %s",
                        i, (int)r, msg);
            /* Hostile: the checksum agrees with the damage. */
            fix_checksum(work, size);
            if (i >= offsetof(sinew_blob_header, checksum) &&
                i < offsetof(sinew_blob_header, checksum) + 8)
                continue; /* the fix-up undid this flip */
            int walked = 1;
            r = parse_copy(work, size, msg, sizeof msg, &walked);
            ENSUREF(walked, "hostile flip at %zu accepted with a bad view", i);
            if (r == SINEW_OK)
                accepted_hostile++;
            else {
                rejected_hostile++;
                ENSUREF(msg[0] != '\0', "flip at %zu: error %d without a message", i, (int)r);
            }
        }
    }
    /* Both outcomes must occur: flips in the low bytes of doubles stay valid, flips in
     * counts and indices do not. */
    ENSURE(accepted_hostile > 0 && rejected_hostile > 0);
    fprintf(stderr, "  %zu bytes: hostile flips accepted %d, rejected %d\n", size, accepted_hostile,
            rejected_hostile);
    free(work);
    free(blob);
}

/* ---- forged blobs ------------------------------------------------------------------ */

typedef void (*forge_fn)(uint8_t *blob);

static void f_meta_huge(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->nverts = 1 << 30;
}
static void f_meta_nverts(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->nverts += 1;
}
static void f_meta_negative(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->ncub = -3;
}
static void f_meta_domains(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->ndomains = NB + 1;
}
static void f_meta_mu(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->mu = INFINITY;
}
static void f_meta_mu_neg(uint8_t *b) {
    ((sinew_blob_meta *)section(b, 1))->mu = -1.0;
}
static sw_blob_domain *dom(uint8_t *b, int d) {
    return (sw_blob_domain *)section(b, SINEW_SECTION_DOMAINS) + d;
}
static void f_dom_vert_count(uint8_t *b) {
    dom(b, 1)->vert_count = 1000;
}
static void f_dom_rank(uint8_t *b) {
    dom(b, 2)->rank = -1;
}
static void f_dom_bone(uint8_t *b) {
    dom(b, 0)->bone = NB;
}
static void f_dom_basis(uint8_t *b) {
    dom(b, 1)->basis_offset += 1;
}
static void f_dom_inertia(uint8_t *b) {
    dom(b, 2)->inertia_offset = 0;
}
static void f_dom_qoff(uint8_t *b) {
    dom(b, 1)->q_offset = 0;
}
static void f_dom_cub(uint8_t *b) {
    dom(b, 2)->cub_count = 0;
}
static void f_cub_neg(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_CUB_TETS))[0] = -1;
}
static void f_copy_domain(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SURF_COPIES))[2] = ND;
}
static void f_copy_local(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SURF_COPIES))[1] = 6;
}
static void f_copy_ptr(uint8_t *b) { /* surface vertex 1 gets no copy */
    int32_t *p = section(b, SINEW_SECTION_SURF_COPY_PTR);
    p[2] = p[1];
}
static void f_copy_ptr_dec(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SURF_COPY_PTR))[2] = 0;
}
static void f_copy_ptr_last(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SURF_COPY_PTR))[NSV] += 1;
}
static void f_tri(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SURF_TRIS))[3 * NST - 1] = NSV;
}
static void f_cycle(uint8_t *b) {
    int32_t *p = section(b, SINEW_SECTION_BONE_PARENT);
    p[1] = 2, p[2] = 1; /* 1 -> 2 -> 1 */
}
static void f_self_parent(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_BONE_PARENT))[3] = 3;
}
static void f_parent_range(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_BONE_PARENT))[2] = -2;
}
static void f_skin_bone(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SKIN_BONE))[4 * 7] = NB;
}
static void f_skin_sum(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_SKIN_WEIGHT))[4 * 7] *= 0.5;
}
static void f_skin_neg(uint8_t *b) {
    double *w = section(b, SINEW_SECTION_SKIN_WEIGHT);
    w[4 * 2 + 3] = -0.25, w[4 * 2 + 0] += 0.25; /* still sums to 1 */
}
static void f_dverts(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_DOMAIN_VERTS))[16] = NV;
}
static void f_cub_weight(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_CUB_WEIGHT))[5] = 0.0;
}
static void f_cub_vol(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_CUB_VOL))[7] = -1.0;
}
static void f_mass(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_MASS))[4 * RT + 4] = 0.0;
}
static void f_basis_nan(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_BASIS))[149] = NAN;
}
static void f_inertia_inf(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_INERTIA_U))[3] = -INFINITY;
}
static void f_dominv_nan(uint8_t *b) {
    ((double *)section(b, SINEW_SECTION_CUB_DMINV))[0] = NAN;
}
static void f_overlap(uint8_t *b) {
    entry(b, SINEW_SECTION_REST)->offset = entry(b, SINEW_SECTION_SKIN_BONE)->offset;
}
static void f_misaligned(uint8_t *b) {
    entry(b, SINEW_SECTION_CUB_VOL)->offset += 8;
}
static void f_elem_size(uint8_t *b) {
    entry(b, SINEW_SECTION_INERTIA_X)->elem_size = 4;
}
static void f_count_huge(uint8_t *b) {
    entry(b, SINEW_SECTION_BASIS)->count = 1ull << 61;
}
static void f_count_small(uint8_t *b) {
    entry(b, SINEW_SECTION_BASIS)->count -= 1;
}
static void f_count_mass(uint8_t *b) {
    entry(b, SINEW_SECTION_MASS)->count -= 1;
}
static void f_copies_odd(uint8_t *b) {
    entry(b, SINEW_SECTION_SURF_COPIES)->count -= 1;
}
static void f_in_table(uint8_t *b) {
    entry(b, SINEW_SECTION_META)->offset = 64;
}
static void f_past_end(uint8_t *b) {
    entry(b, SINEW_SECTION_CUB_TETS)->offset = hdr(b)->file_size + 64;
}
static void f_duplicate(uint8_t *b) {
    entry(b, SINEW_SECTION_SKIN_BONE)->id = SINEW_SECTION_REST;
}
static void f_missing(uint8_t *b) {
    entry(b, SINEW_SECTION_SURF_TRIS)->id = 999;
}
static void f_entry_reserved(uint8_t *b) {
    entry(b, SINEW_SECTION_DOMAINS)->reserved = 1;
}
static void f_dom_inertia_count(uint8_t *b) {
    dom(b, 0)->inertia_count = dom(b, 0)->rank + 1;
}
static void f_table_huge(uint8_t *b) {
    hdr(b)->section_count = 1000;
}
static void f_version_new(uint8_t *b) {
    hdr(b)->version = SINEW_BLOB_VERSION + 1;
}
static void f_version_old(uint8_t *b) {
    hdr(b)->version = 0;
}
static void f_magic(uint8_t *b) {
    b[3] = 'x';
}
static void f_endian(uint8_t *b) {
    hdr(b)->endian_tag = 0x04030201u;
}
static void f_header_size(uint8_t *b) {
    hdr(b)->header_size = 128;
}
static void f_file_size(uint8_t *b) {
    hdr(b)->file_size -= 64;
}
static void f_hdr_reserved(uint8_t *b) {
    hdr(b)->reserved[15] = 1;
}

TEST(forged_blobs_are_rejected_by_the_semantic_checks) {
    const struct {
        const char *name;
        forge_fn fn;
        sinew_result code;
        const char *needle, *needle2;
    } cases[] = {
        {"meta huge nverts", f_meta_huge, SINEW_ERROR_CORRUPT, "META", "nverts"},
        {"meta nverts +1", f_meta_nverts, SINEW_ERROR_CORRUPT, "REST", "3 nverts"},
        {"meta negative ncub", f_meta_negative, SINEW_ERROR_CORRUPT, "META", "ncub"},
        {"meta ndomains > nbones", f_meta_domains, SINEW_ERROR_CORRUPT, "META", "ndomains"},
        {"meta mu inf", f_meta_mu, SINEW_ERROR_NOT_FINITE, "META", "mu"},
        {"meta mu < 0", f_meta_mu_neg, SINEW_ERROR_CORRUPT, "META", "mu"},
        {"domain vert_count", f_dom_vert_count, SINEW_ERROR_CORRUPT, "DOMAINS", "domain 1"},
        {"domain rank -1", f_dom_rank, SINEW_ERROR_CORRUPT, "DOMAINS", "rank"},
        {"domain bone", f_dom_bone, SINEW_ERROR_CORRUPT, "DOMAINS", "bone"},
        {"domain basis_offset", f_dom_basis, SINEW_ERROR_CORRUPT, "DOMAINS", "basis_offset"},
        {"domain inertia_offset", f_dom_inertia, SINEW_ERROR_CORRUPT, "DOMAINS", "inertia"},
        {"domain q_offset", f_dom_qoff, SINEW_ERROR_CORRUPT, "DOMAINS", "q_offset"},
        {"domain cub_count 0", f_dom_cub, SINEW_ERROR_CORRUPT, "DOMAINS", "cub_count"},
        {"cub local index", f_cub_index, SINEW_ERROR_CORRUPT, "CUB_TETS", "tet 3"},
        {"cub negative index", f_cub_neg, SINEW_ERROR_CORRUPT, "CUB_TETS", "tet 0"},
        {"surf copy domain", f_copy_domain, SINEW_ERROR_CORRUPT, "SURF_COPIES", "domain 3"},
        {"surf copy local", f_copy_local, SINEW_ERROR_CORRUPT, "SURF_COPIES", "copy 0"},
        {"surf vertex without copy", f_copy_ptr, SINEW_ERROR_CORRUPT, "SURF_COPY_PTR",
         "vertex 1 has 0"},
        {"surf copy ptr decreasing", f_copy_ptr_dec, SINEW_ERROR_CORRUPT, "SURF_COPY_PTR",
         "vertex 1"},
        {"surf copy ptr last", f_copy_ptr_last, SINEW_ERROR_CORRUPT, "SURF_COPY_PTR", "last"},
        {"surf tri index", f_tri, SINEW_ERROR_CORRUPT, "SURF_TRIS", "triangle 5"},
        {"bone cycle", f_cycle, SINEW_ERROR_CORRUPT, "BONE_PARENT", "cycle"},
        {"bone self parent", f_self_parent, SINEW_ERROR_CORRUPT, "BONE_PARENT", "cycle"},
        {"bone parent -2", f_parent_range, SINEW_ERROR_CORRUPT, "BONE_PARENT", "bone 2"},
        {"skin bone", f_skin_bone, SINEW_ERROR_CORRUPT, "SKIN_BONE", "vertex 7"},
        {"skin sum", f_skin_sum, SINEW_ERROR_CORRUPT, "SKIN_WEIGHT", "vertex 7"},
        {"skin negative", f_skin_neg, SINEW_ERROR_CORRUPT, "SKIN_WEIGHT", "vertex 2"},
        {"domain vert id", f_dverts, SINEW_ERROR_CORRUPT, "DOMAIN_VERTS", "domain 2"},
        {"cub weight 0", f_cub_weight, SINEW_ERROR_CORRUPT, "CUB_WEIGHT", "5"},
        {"cub vol < 0", f_cub_vol, SINEW_ERROR_CORRUPT, "CUB_VOL", "7"},
        {"mass diagonal 0", f_mass, SINEW_ERROR_CORRUPT, "MASS", "4"},
        {"basis nan", f_basis_nan, SINEW_ERROR_NOT_FINITE, "BASIS", "149"},
        {"inertia_u -inf", f_inertia_inf, SINEW_ERROR_NOT_FINITE, "INERTIA_U", "3"},
        {"dminv nan", f_dominv_nan, SINEW_ERROR_NOT_FINITE, "CUB_DMINV", "0"},
        {"overlapping offsets", f_overlap, SINEW_ERROR_CORRUPT, "REST",
         "overlaps section SKIN_BONE"},
        {"misaligned offset", f_misaligned, SINEW_ERROR_CORRUPT, "CUB_VOL", "multiple of 64"},
        {"wrong elem_size", f_elem_size, SINEW_ERROR_CORRUPT, "INERTIA_X", "elem_size"},
        {"huge count", f_count_huge, SINEW_ERROR_CORRUPT, "BASIS", "past the end"},
        {"basis count short", f_count_small, SINEW_ERROR_CORRUPT, "BASIS", "149"},
        {"mass count short", f_count_mass, SINEW_ERROR_CORRUPT, "MASS", "rank_total"},
        {"odd copies count", f_copies_odd, SINEW_ERROR_CORRUPT, "SURF_COPIES", "even"},
        {"offset inside table", f_in_table, SINEW_ERROR_CORRUPT, "META", "table"},
        {"offset past end", f_past_end, SINEW_ERROR_CORRUPT, "CUB_TETS", "outside"},
        {"duplicate id", f_duplicate, SINEW_ERROR_CORRUPT, "REST", "twice"},
        {"missing section", f_missing, SINEW_ERROR_CORRUPT, "SURF_TRIS", "missing"},
        {"table entry reserved", f_entry_reserved, SINEW_ERROR_CORRUPT, "DOMAINS", "reserved"},
        {"domain inertia count", f_dom_inertia_count, SINEW_ERROR_CORRUPT, "DOMAINS",
         "inertia_count"},
        {"huge section_count", f_table_huge, SINEW_ERROR_CORRUPT, "table", "1000"},
        {"newer version", f_version_new, SINEW_ERROR_VERSION, "header", "versions 2 to 4"},
        {"older version", f_version_old, SINEW_ERROR_VERSION, "header", "version 0"},
        {"magic", f_magic, SINEW_ERROR_CORRUPT, "header", "magic"},
        {"endian", f_endian, SINEW_ERROR_CORRUPT, "header", "endian"},
        {"header_size", f_header_size, SINEW_ERROR_CORRUPT, "header", "header_size"},
        {"file_size", f_file_size, SINEW_ERROR_CORRUPT, "header", "file_size"},
        {"header reserved", f_hdr_reserved, SINEW_ERROR_CORRUPT, "header", "reserved"},
    };
    fixture_init(&g_fix, 7);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        uint8_t *b = copy_exact(blob, size);
        cases[i].fn(b);
        fix_checksum(b, size);
        char msg[512];
        sw_blob_view v;
        memset(&v, 0xAB, sizeof v);
        sinew_result r = sw_blob_parse(b, size, &v, msg, sizeof msg);
        const unsigned char *raw = (const unsigned char *)&v;
        int untouched = 1;
        for (size_t k = 0; k < sizeof v; ++k)
            untouched &= raw[k] == 0xAB;
        free(b);
        ENSUREF(r == cases[i].code, "%s: got %d (%s), expected %d", cases[i].name, (int)r, msg,
                (int)cases[i].code);
        ENSUREF(contains(msg, cases[i].needle) && contains(msg, cases[i].needle2),
                "%s: message '%s' should name '%s' and '%s'", cases[i].name, msg, cases[i].needle,
                cases[i].needle2);
        ENSUREF(untouched, "%s: the view was written on failure", cases[i].name);
    }
    free(blob);
}

TEST(unknown_extra_section_still_loads) {
    fixture_init(&g_fix, 8);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    /* Insert one table entry: shift every section by 64 bytes to make room (offsets stay
     * 64-aligned) and append the new section's data at the end. */
    const uint32_t n = hdr(blob)->section_count;
    const size_t shift = 64, big = size + shift + 128;
    uint8_t *b = NULL;
    ENSURE(posix_memalign((void **)&b, 64, big) == 0);
    memset(b, 0, big);
    const size_t table_end = 64 + (size_t)n * 32;
    uint64_t first = UINT64_MAX;
    for (uint32_t id = 1; id <= SINEW_SECTION_COUNT_V1; ++id)
        if (entry(blob, id)->offset < first) first = entry(blob, id)->offset;
    ENSURE(first >= table_end && 64 + (size_t)(n + 1) * 32 <= first + shift);
    memcpy(b, blob, table_end);
    memcpy(b + first + shift, blob + first, size - first);
    for (uint32_t i = 0; i < n; ++i)
        ((sinew_blob_section *)(void *)(b + 64))[i].offset += shift;
    size += shift;
    sinew_blob_section *t = (sinew_blob_section *)(void *)(b + 64);
    t[n].id = 4242;
    t[n].elem_size = 24; /* an element size no v1 section has */
    t[n].offset = size;
    t[n].count = 5;
    t[n].reserved = 99; /* unknown sections are skipped entirely */
    memset(b + size, 0x5A, 120);
    hdr(b)->section_count = n + 1;
    hdr(b)->file_size = big;
    fix_checksum(b, big);
    char msg[512];
    sw_blob_view v;
    ENSUREF(sw_blob_parse(b, big, &v, msg, sizeof msg) == SINEW_OK, "%s", msg);
    ENSURE(view_diff(&g_fix.v, &v) == NULL);
    /* The public loader accepts it too. */
    sinew_blob_def def = sinew_blob_def_default();
    def.data = b;
    def.data_size = big;
    sinew_blob *blob_h = NULL;
    ENSURE(sinew_blob_load(&def, &blob_h) == SINEW_OK);
    sinew_blob_destroy(blob_h);
    /* ...but an unknown section must still stay inside the file and off the others. */
    t[n].offset = entry(b, SINEW_SECTION_MASS)->offset;
    fix_checksum(b, big);
    ENSURE(sw_blob_parse(b, big, &v, msg, sizeof msg) == SINEW_ERROR_CORRUPT);
    ENSUREF(contains(msg, "unknown id 4242") && contains(msg, "MASS"), "%s", msg);
    t[n].offset = size;
    t[n].count = 6; /* 144 bytes > 128 available */
    fix_checksum(b, big);
    ENSURE(sw_blob_parse(b, big, &v, msg, sizeof msg) == SINEW_ERROR_CORRUPT);
    ENSUREF(contains(msg, "unknown id 4242") && contains(msg, "past the end"), "%s", msg);
    free(b);
    free(blob);
}

SW_TEST_MAIN(CASE(truncation_at_every_length_is_an_error), CASE(every_flipped_byte_is_caught),
             CASE(forged_blobs_are_rejected_by_the_semantic_checks),
             CASE(unknown_extra_section_still_loads))
