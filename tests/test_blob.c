/* Blob writer, parser/validator and public load API (DESIGN.md §6): bit-exact round trips
 * through memory and files, the writer's validation, and hostile input: truncation at
 * every length, every byte flipped (with and without a recomputed checksum), forged
 * counts, indices and offsets (checksum fixed up so the semantic check must catch them),
 * versions, unknown sections, def struct sizes and NULL arguments. */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "blob_load.h"
#include "blob_write.h"
#include "sinew/sinew.h"
#include "sw_test.h"

#include "blob_synth.h"

static fixture g_fix; /* views point into it: never copied */

/* ---- tests ----------------------------------------------------------------------- */

TEST(checksum_is_fnv1a_64) {
    /* Published FNV-1a 64 test vectors. */
    ENSURE(sw_blob_checksum("", 0) == 0xcbf29ce484222325ull);
    ENSURE(sw_blob_checksum("a", 1) == 0xaf63dc4c8601ec8cull);
    ENSURE(sw_blob_checksum("foobar", 6) == 0x85944171f73967e8ull);
}

TEST(memory_round_trip_is_bit_exact) {
    fixture_init(&g_fix, 1);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    ENSURE((uintptr_t)blob % 64 == 0 && size % 64 == 0);
    const sinew_blob_header *h = hdr(blob);
    ENSURE(memcmp(h->magic, SINEW_BLOB_MAGIC, 8) == 0 && h->version == SINEW_BLOB_VERSION);
    ENSURE(h->file_size == size && h->section_count == SINEW_SECTION_COUNT_V1);
    for (uint32_t id = 1; id <= SINEW_SECTION_COUNT_V1; ++id) {
        const sinew_blob_section *e = entry(blob, id);
        ENSUREF(e && e->offset % 64 == 0, "section %u", id);
        /* padding after each section is zero */
        for (uint64_t b = e->offset + e->count * e->elem_size; b % 64 != 0; ++b)
            ENSUREF(blob[b] == 0, "padding byte %llu after section %u", (unsigned long long)b, id);
    }
    /* Each section holds the fixture's array (SURF_COPIES: the copies used), sized by the
     * fixture's own declarations, not by the table's count expressions: a wrong count in
     * the table would otherwise pass the writer, the loader and view_diff alike. */
#define HOLDS_FIXTURE(id, NAME, elem_size, type, field, ...)                                       \
    ENSUREF(entry(blob, id)->count *elem_size == (id == SINEW_SECTION_SURF_COPIES                  \
                                                      ? 2 * sizeof(int32_t) * g_fix.v.nsurf_copies \
                                                      : sizeof g_fix.field),                       \
            "section " #NAME ": %llu elements", (unsigned long long)entry(blob, id)->count);
    SINEW_BLOB_ARRAY_SECTIONS(HOLDS_FIXTURE)
#undef HOLDS_FIXTURE
    sw_blob_view v;
    char msg[512];
    ENSUREF(sw_blob_parse(blob, size, &v, msg, sizeof msg) == SINEW_OK, "%s", msg);
    const char *diff = view_diff(&g_fix.v, &v);
    ENSUREF(diff == NULL, "field %s differs", diff);
    ENSURE((const uint8_t *)v.rest > blob && (const uint8_t *)v.rest < blob + size); /* zero copy */

    /* Writing the parsed view again gives the same bytes. */
    size_t size2 = 0;
    void *again = NULL;
    sw_error err;
    ENSURE(sw_blob_write_memory(&v, &again, &size2, &err) == SINEW_OK);
    ENSURE(size2 == size && memcmp(again, blob, size) == 0);
    free(again);

    /* 8-byte aligned (not 64) data is accepted; 4-byte aligned is an argument error. */
    uint8_t *shifted = NULL;
    ENSURE(posix_memalign((void **)&shifted, 64, size + 8) == 0);
    memcpy(shifted + 8, blob, size);
    ENSURE(sw_blob_parse(shifted + 8, size, &v, msg, sizeof msg) == SINEW_OK);
    ENSURE(view_diff(&g_fix.v, &v) == NULL);
    memmove(shifted + 4, shifted + 8, size);
    ENSURE(sw_blob_parse(shifted + 4, size, &v, msg, sizeof msg) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(contains(msg, "aligned"));
    free(shifted);
    free(blob);
}

static int file_exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

TEST(file_and_buffer_loads_match) {
    fixture_init(&g_fix, 2);
    const char *path = SINEW_BINARY_DIR "/test_blob_roundtrip.blob";
    sw_error err;
    sw_error_clear(&err);
    ENSUREF(sw_blob_write(path, &g_fix.v, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(!file_exists(SINEW_BINARY_DIR "/test_blob_roundtrip.blob.tmp"));

    size_t size = 0;
    uint8_t *mem = write_fixture(&g_fix, &size);
    ENSURE(mem != NULL);
    FILE *fp = fopen(path, "rb");
    ENSURE(fp != NULL);
    uint8_t *disk = malloc(size + 1);
    size_t got = fread(disk, 1, size + 1, fp);
    fclose(fp);
    ENSUREF(got == size && memcmp(disk, mem, size) == 0, "file has %zu bytes, memory %zu", got,
            size);
    free(disk);

    sinew_blob_def def = sinew_blob_def_default();
    def.path = path;
    sinew_blob *from_file = NULL, *from_buf = NULL;
    ENSURE(sinew_blob_load(&def, &from_file) == SINEW_OK && from_file);
    def = sinew_blob_def_default();
    def.data = mem;
    def.data_size = size;
    ENSURE(sinew_blob_load(&def, &from_buf) == SINEW_OK && from_buf);
    const char *d1 = view_diff(&g_fix.v, sw_blob_get_view(from_file));
    const char *d2 = view_diff(&g_fix.v, sw_blob_get_view(from_buf));
    ENSUREF(!d1 && !d2, "file: %s, buffer: %s", d1 ? d1 : "-", d2 ? d2 : "-");
    ENSURE(sw_blob_get_view(from_buf)->rest ==
           (const double *)(const void *)(mem + entry(mem, SINEW_SECTION_REST)->offset));

    /* Queries. */
    ENSURE(sinew_blob_bone_count(from_file) == NB);
    ENSURE(sinew_blob_surface_vertex_count(from_file) == NSV);
    ENSURE(sinew_blob_surface_triangle_count(from_file) == NST);
    uint32_t tris[3 * NST + 1];
    tris[3 * NST] = 0xdeadbeefu;
    ENSURE(sinew_blob_surface_triangles(from_file, tris, 3 * NST - 1) == SINEW_ERROR_CAPACITY);
    ENSURE(sinew_blob_surface_triangles(from_file, tris, 3 * NST + 1) == SINEW_OK);
    for (int i = 0; i < 3 * NST; ++i)
        ENSURE(tris[i] == (uint32_t)g_fix.surf_tris[i]);
    ENSURE(tris[3 * NST] == 0xdeadbeefu);
    ENSURE(sinew_blob_surface_triangles(from_file, NULL, 100) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_surface_triangles(NULL, tris, 100) == SINEW_ERROR_INVALID_ARGUMENT);

    sinew_blob_destroy(from_file);
    sinew_blob_destroy(from_buf);
    free(mem);
    remove(path);
}

TEST(writer_rejects_invalid_views) {
    struct {
        const char *what, *section;
        sinew_result code;
    } cases[] = {
        {"weights", "SKIN_WEIGHT", SINEW_ERROR_CORRUPT},
        {"vert_count", "DOMAINS", SINEW_ERROR_CORRUPT},
        {"nan", "BASIS", SINEW_ERROR_NOT_FINITE},
        {"null", "CUB_DMINV", SINEW_ERROR_INVALID_ARGUMENT},
        {"nbasis", "BASIS", SINEW_ERROR_CORRUPT},
        {"copy", "SURF_COPIES", SINEW_ERROR_CORRUPT},
        {"cycle", "BONE_PARENT", SINEW_ERROR_CORRUPT},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        fixture_init(&g_fix, 3);
        switch (i) {
        case 0:
            g_fix.skin_weight[4 * 5] += 1e-3;
            break;
        case 1:
            g_fix.domains[1].vert_count = 7;
            break;
        case 2:
            g_fix.basis[77] = NAN;
            break;
        case 3:
            g_fix.v.cub_dminv = NULL;
            break;
        case 4:
            g_fix.v.nbasis = NBASIS - 1;
            break;
        case 5:
            g_fix.surf_copies[2 * 3] = ND;
            break;
        case 6:
            g_fix.bone_parent[0] = 3;
            break;
        }
        void *data = (void *)&g_fix; /* must be reset to NULL */
        size_t size = 123;
        sw_error err;
        sw_error_clear(&err);
        sinew_result r = sw_blob_write_memory(&g_fix.v, &data, &size, &err);
        ENSUREF(r == cases[i].code && err.code == r, "%s: got %d", cases[i].what, (int)r);
        ENSUREF(contains(err.msg, cases[i].section), "%s: message '%s'", cases[i].what, err.msg);
        ENSURE(data == NULL && size == 0);
        const char *path = SINEW_BINARY_DIR "/test_blob_invalid.blob";
        remove(path);
        ENSURE(sw_blob_write(path, &g_fix.v, &err) == cases[i].code);
        ENSURE(!file_exists(path));
    }
    sw_error err;
    void *data = NULL;
    size_t size = 0;
    ENSURE(sw_blob_write_memory(NULL, &data, &size, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    fixture_init(&g_fix, 3);
    ENSURE(sw_blob_write_memory(&g_fix.v, NULL, &size, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_blob_write(NULL, &g_fix.v, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_blob_validate_view(NULL, NULL, 0) == SINEW_ERROR_INVALID_ARGUMENT);
}

TEST(writer_file_errors_leave_nothing_behind) {
    fixture_init(&g_fix, 4);
    sw_error err;
    sw_error_clear(&err);
    const char *missing = SINEW_BINARY_DIR "/no_such_dir_blob/x.blob";
    ENSURE(sw_blob_write(missing, &g_fix.v, &err) == SINEW_ERROR_IO);
    ENSUREF(contains(err.msg, "no_such_dir_blob/x.blob.tmp"), "%s", err.msg);
    /* The target is a directory: the temporary file is written, the rename fails, and the
     * temporary file must be removed again. */
    const char *dir = SINEW_BINARY_DIR "/test_blob_dir_target";
    mkdir(dir, 0755);
    ENSURE(sw_blob_write(dir, &g_fix.v, &err) == SINEW_ERROR_IO);
    ENSUREF(contains(err.msg, "rename"), "%s", err.msg);
    ENSURE(!file_exists(SINEW_BINARY_DIR "/test_blob_dir_target.tmp"));
    rmdir(dir);
}

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
static void f_cub_index(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_CUB_TETS))[4 * 3 + 1] = 6;
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
static void f_dom_reserved(uint8_t *b) {
    dom(b, 0)->reserved = 7;
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
        {"domain reserved", f_dom_reserved, SINEW_ERROR_CORRUPT, "DOMAINS", "reserved"},
        {"huge section_count", f_table_huge, SINEW_ERROR_CORRUPT, "table", "1000"},
        {"newer version", f_version_new, SINEW_ERROR_VERSION, "header", "version 2"},
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

/* ---- the public API: defs, hooks, errors ----------------------------------------- */

typedef struct log_capture {
    int calls;
    sinew_log_level level;
    uint32_t id;
    char text[1024];
} log_capture;

static void capture_log(sinew_log_level level, uint32_t id, const char *message, void *user) {
    log_capture *c = user;
    c->calls++;
    c->level = level;
    c->id = id;
    snprintf(c->text, sizeof c->text, "%s", message);
}

typedef struct alloc_count {
    int allocs, frees, fail;
} alloc_count;

static void *count_alloc(size_t size, size_t align, void *user) {
    alloc_count *a = user;
    if (a->fail) return NULL;
    a->allocs++;
    void *p = NULL;
    return posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) == 0 ? p
                                                                                          : NULL;
}

static void count_free(void *p, void *user) {
    alloc_count *a = user;
    if (p) a->frees++;
    free(p);
}

TEST(load_uses_hooks_and_logs_errors) {
    fixture_init(&g_fix, 9);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    log_capture cap;
    memset(&cap, 0, sizeof cap);
    alloc_count ac = {0, 0, 0};
    sinew_blob_def def = sinew_blob_def_default();
    def.data = blob;
    def.data_size = size;
    def.allocator.alloc = count_alloc;
    def.allocator.free = count_free;
    def.allocator.user = &ac;
    def.logger.log = capture_log;
    def.logger.user = &cap;
    def.logger.max_level = SINEW_LOG_DEBUG;
    sinew_blob *h = NULL;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_OK && h);
    ENSURE(ac.allocs == 1 && ac.frees == 0);
    ENSUREF(cap.calls == 1 && cap.level == SINEW_LOG_INFO && cap.id == SINEW_MSG_BLOB_LOADED,
            "%d calls, last '%s'", cap.calls, cap.text);
    sinew_blob_destroy(h);
    ENSURE(ac.frees == 1);

    /* Allocator failure: an error, nothing leaked (the mapping is released too). */
    ac.fail = 1;
    h = (sinew_blob *)(void *)&cap;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_OUT_OF_MEMORY);
    ENSURE(h == (sinew_blob *)(void *)&cap); /* untouched on failure */
    ENSURE(cap.id == SINEW_MSG_BLOB_OUT_OF_MEMORY && cap.level == SINEW_LOG_ERROR);
    const char *path = SINEW_BINARY_DIR "/test_blob_hooks.blob";
    sw_error err;
    ENSURE(sw_blob_write(path, &g_fix.v, &err) == SINEW_OK);
    def.data = NULL;
    def.data_size = 0;
    def.path = path;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_OUT_OF_MEMORY);
    ac.fail = 0;

    /* A damaged blob: error logged with its stable id and a message naming the section. */
    uint8_t *bad = copy_exact(blob, size);
    f_cub_index(bad);
    fix_checksum(bad, size);
    def.path = NULL;
    def.data = bad;
    def.data_size = size;
    cap.calls = 0;
    def.logger.max_level = SINEW_LOG_ERROR; /* info would not be formatted */
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_CORRUPT);
    ENSUREF(cap.calls == 1 && cap.level == SINEW_LOG_ERROR && cap.id == SINEW_MSG_BLOB_INVALID &&
                contains(cap.text, "CUB_TETS"),
            "%d calls, id %u, '%s'", cap.calls, (unsigned)cap.id, cap.text);
    /* Loaded fine with max_level ERROR: the info message is not delivered. */
    def.data = blob;
    cap.calls = 0;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_OK);
    ENSURE(cap.calls == 0);
    sinew_blob_destroy(h);
    free(bad);

    /* Files: missing, a directory, too short, truncated, newer version. */
    def = sinew_blob_def_default();
    def.logger.log = capture_log;
    def.logger.user = &cap;
    def.path = SINEW_BINARY_DIR "/no_such_blob_file.blob";
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_IO);
    ENSURE(cap.id == SINEW_MSG_BLOB_IO && contains(cap.text, "no_such_blob_file"));
    def.path = SINEW_BINARY_DIR;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_IO);
    const size_t cuts[] = {0, 10, 64, size / 2, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; ++i) {
        FILE *fp = fopen(path, "wb");
        ENSURE(fp && fwrite(blob, 1, cuts[i], fp) == cuts[i]);
        fclose(fp);
        def.path = path;
        ENSUREF(sinew_blob_load(&def, &h) == SINEW_ERROR_CORRUPT, "file cut at %zu", cuts[i]);
        ENSURE(cap.id == SINEW_MSG_BLOB_INVALID && contains(cap.text, "header"));
    }
    uint8_t *newer = copy_exact(blob, size);
    hdr(newer)->version = SINEW_BLOB_VERSION + 1;
    FILE *fp = fopen(path, "wb");
    ENSURE(fp && fwrite(newer, 1, size, fp) == size);
    fclose(fp);
    free(newer);
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_VERSION);
    ENSURE(contains(cap.text, "version"));
    remove(path);
    free(blob);
}

TEST(load_argument_errors) {
    fixture_init(&g_fix, 10);
    size_t size = 0;
    uint8_t *blob = write_fixture(&g_fix, &size);
    ENSURE(blob != NULL);
    sinew_blob *h = NULL;
    sinew_blob_def def = sinew_blob_def_default();
    def.data = blob;
    def.data_size = size;
    ENSURE(sinew_blob_load(NULL, &h) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_load(&def, NULL) == SINEW_ERROR_INVALID_ARGUMENT);

    /* struct_size: smaller than the first fields is an error; covering only them works
     * (allocator and logger at their defaults, never read). */
    const uint32_t first = (uint32_t)(offsetof(sinew_blob_def, data_size) + sizeof(size_t));
    const uint32_t small[] = {0, 4, first - 1};
    for (size_t i = 0; i < sizeof small / sizeof small[0]; ++i) {
        def.struct_size = small[i];
        ENSUREF(sinew_blob_load(&def, &h) == SINEW_ERROR_INVALID_ARGUMENT, "struct_size %u",
                (unsigned)small[i]);
    }
    /* An old host's def: only the first fields exist. Garbage after them must be ignored. */
    unsigned char *old = malloc(first);
    def.struct_size = first;
    memcpy(old, &def, first);
    ENSURE(sinew_blob_load((const sinew_blob_def *)(void *)old, &h) == SINEW_OK);
    sinew_blob_destroy(h);
    free(old);
    /* A half-set allocator would be rejected, but struct_size does not cover it. */
    def.allocator.alloc = count_alloc;
    def.struct_size = (uint32_t)offsetof(sinew_blob_def, allocator);
    ENSURE(sinew_blob_load(&def, &h) == SINEW_OK);
    sinew_blob_destroy(h);
    def = sinew_blob_def_default();

    /* Exactly one source; both hooks or none; aligned data. */
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_INVALID_ARGUMENT);
    def.data = blob;
    def.data_size = size;
    def.path = "x.blob";
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_INVALID_ARGUMENT);
    def.path = NULL;
    def.allocator.alloc = count_alloc;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_INVALID_ARGUMENT);
    def.allocator.alloc = NULL;
    uint8_t *raw = malloc(size + 16);
    uint8_t *mis = raw + (8 - (uintptr_t)raw % 8) % 8 + 4; /* 4 mod 8 */
    memcpy(mis, blob, size);
    def.data = mis;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_INVALID_ARGUMENT);
    free(raw);
    def.data = blob;
    def.data_size = size - 64;
    ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_CORRUPT);

    /* NULL handles. */
    sinew_blob_destroy(NULL);
    ENSURE(sinew_blob_bone_count(NULL) == 0 && sinew_blob_surface_vertex_count(NULL) == 0);
    ENSURE(sinew_blob_surface_triangle_count(NULL) == 0 && sw_blob_get_view(NULL) == NULL);
    sw_blob_view v;
    char msg[64];
    ENSURE(sw_blob_parse(NULL, size, &v, msg, sizeof msg) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_blob_parse(blob, size, NULL, msg, sizeof msg) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_blob_parse(blob, size, &v, NULL, 0) == SINEW_OK); /* msg is optional */
    ENSURE(sw_blob_parse(blob, 10, &v, msg, sizeof msg) == SINEW_ERROR_CORRUPT);
    ENSURE(strlen(msg) < sizeof msg); /* truncated, terminated */
    free(blob);
}

SW_TEST_MAIN(CASE(checksum_is_fnv1a_64), CASE(memory_round_trip_is_bit_exact),
             CASE(file_and_buffer_loads_match), CASE(writer_rejects_invalid_views),
             CASE(writer_file_errors_leave_nothing_behind),
             CASE(truncation_at_every_length_is_an_error), CASE(every_flipped_byte_is_caught),
             CASE(forged_blobs_are_rejected_by_the_semantic_checks),
             CASE(unknown_extra_section_still_loads), CASE(load_uses_hooks_and_logs_errors),
             CASE(load_argument_errors))
