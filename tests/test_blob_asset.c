/* The blob's optional asset description (sinew_blob_format.h, ids 52..56) through the
 * public ABI: bone names, parents and bind poses, the output map and the provenance of a
 * synthetic blob that has it; what a blob without it answers; and forged asset sections,
 * each refused by the loader with a message naming the section. The forging helpers and
 * the synthetic character are blob_synth.h's. */
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
static render_fixture g_render;
static asset_fixture g_asset;

/* The synthetic character with a render mesh and the asset description, written. */
static uint8_t *asset_blob(size_t *size) {
    fixture_init(&g_fix, 5);
    fixture_add_render(&g_fix, &g_render);
    fixture_add_asset(&g_fix, &g_asset);
    return write_fixture(&g_fix, size);
}

static sinew_blob *load(const uint8_t *b, size_t size) {
    sinew_blob_def d = sinew_blob_def_default();
    d.data = b;
    d.data_size = size;
    sinew_blob *blob = NULL;
    return sinew_blob_load(&d, &blob) == SINEW_OK ? blob : NULL;
}

TEST(the_skeleton_reads_back_by_name) {
    size_t size = 0;
    uint8_t *b = asset_blob(&size);
    ENSURE(b);
    sinew_blob *blob = load(b, size);
    ENSURE(blob);
    ENSURE(sinew_blob_bone_count(blob) == NB);
    ENSURE(strcmp(sinew_blob_bone_name(blob, 0), "Hips") == 0);
    ENSURE(strcmp(sinew_blob_bone_name(blob, 3), "bone 3") == 0);
    ENSURE(sinew_blob_bone_name(blob, NB) == NULL);
    ENSURE(sinew_blob_find_bone(blob, "bone 2") == 2 && sinew_blob_find_bone(blob, "Hips") == 0);
    ENSURE(sinew_blob_find_bone(blob, "hips") == -1 && sinew_blob_find_bone(blob, "") == -1);
    ENSURE(sinew_blob_find_bone(blob, NULL) == -1);
    for (uint32_t k = 0; k < NB; ++k) {
        int32_t parent = -7;
        double bind[12];
        ENSURE(sinew_blob_bone_parent(blob, k, &parent) == SINEW_OK);
        ENSURE(parent == g_fix.bone_parent[k]);
        ENSURE(sinew_blob_bone_bind(blob, k, bind) == SINEW_OK);
        ENSURE(memcmp(bind, g_asset.bone_bind + 12 * k, sizeof bind) == 0);
    }
    int32_t parent = 5;
    double bind[12];
    ENSURE(sinew_blob_bone_parent(blob, NB, &parent) == SINEW_ERROR_INVALID_ARGUMENT &&
           parent == 5);
    ENSURE(sinew_blob_bone_parent(blob, 0, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_bone_bind(blob, NB, bind) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_bone_bind(blob, 0, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_blob_destroy(blob);
    free(b);
}

TEST(the_output_map_and_provenance_read_back) {
    size_t size = 0;
    uint8_t *b = asset_blob(&size);
    ENSURE(b);
    sinew_blob *blob = load(b, size);
    ENSURE(blob);
    const uint32_t n = sinew_blob_surface_vertex_count(blob);
    ENSURE(n == NRV && sinew_blob_source_mesh_count(blob) == NSRC);
    int32_t pairs[2 * NOUT_MAX];
    memset(pairs, 0x55, sizeof pairs);
    ENSURE(sinew_blob_output_sources(blob, pairs, 2 * n - 1) == SINEW_ERROR_CAPACITY);
    ENSURE(pairs[0] == 0x55555555); /* nothing written */
    ENSURE(sinew_blob_output_sources(blob, NULL, 2 * n) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_output_sources(blob, pairs, 2 * n) == SINEW_OK);
    ENSURE(memcmp(pairs, g_asset.output_source, 2 * n * sizeof(int32_t)) == 0);
    ENSURE(pairs[0] == -1 && pairs[1] == -1 && pairs[2] == 1 && pairs[3] == 1);

    sinew_blob_provenance p;
    memset(&p, 0xaa, sizeof p);
    p.struct_size = sizeof p;
    ENSURE(sinew_blob_get_provenance(blob, &p) == SINEW_OK);
    ENSURE(p.struct_size == sizeof p && p.sinew_version == SINEW_VERSION);
    ENSURE(p.source_hash == 0x0123456789abcdefull && p.options_hash == 0xfedcba9876543210ull);
    /* the blob's own version: the synthetic one is dense and unpainted */
    ENSURE(p.format_version == SINEW_BLOB_VERSION_MIN && p.reserved == 0);
    /* an older host's smaller struct: only its bytes are written */
    memset(&p, 0xaa, sizeof p);
    p.struct_size = 16;
    ENSURE(sinew_blob_get_provenance(blob, &p) == SINEW_OK);
    ENSURE(p.struct_size == 16 && p.source_hash == 0x0123456789abcdefull);
    ENSURE(p.options_hash == 0xaaaaaaaaaaaaaaaaull);
    p.struct_size = 4;
    ENSURE(sinew_blob_get_provenance(blob, &p) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_blob_get_provenance(blob, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    /* the hash a host computes of its asset's bytes is the one the bake stores */
    ENSURE(sinew_hash_bytes("a", 1) == 0xaf63dc4c8601ec8cull);
    ENSURE(sinew_hash_bytes(NULL, 3) == 0);
    sinew_blob_destroy(blob);
    free(b);
}

/* A blob baked before the asset description loads and steps as before; what it lacks
 * says so instead of inventing names. */
TEST(a_blob_without_the_asset_description_says_so) {
    fixture_init(&g_fix, 5);
    size_t size = 0;
    uint8_t *b = write_fixture(&g_fix, &size);
    ENSURE(b && hdr(b)->section_count == SINEW_SECTION_COUNT_V1);
    sinew_blob *blob = load(b, size);
    ENSURE(blob);
    int32_t parent = -7, pairs[2 * NSV];
    double bind[12];
    sinew_blob_provenance p;
    p.struct_size = sizeof p;
    ENSURE(sinew_blob_bone_name(blob, 0) == NULL && sinew_blob_find_bone(blob, "bone 0") == -1);
    ENSURE(sinew_blob_bone_parent(blob, 1, &parent) == SINEW_OK && parent == g_fix.bone_parent[1]);
    ENSURE(sinew_blob_bone_bind(blob, 0, bind) == SINEW_ERROR_UNSUPPORTED);
    ENSURE(sinew_blob_source_mesh_count(blob) == 0);
    ENSURE(sinew_blob_output_sources(blob, pairs, 2 * NSV) == SINEW_ERROR_UNSUPPORTED);
    ENSURE(sinew_blob_get_provenance(blob, &p) == SINEW_ERROR_UNSUPPORTED);
    sinew_blob_destroy(blob);
    free(b);
}

/* ---- forged asset sections -------------------------------------------------------- */

typedef void (*forge_fn)(uint8_t *b);

static sinew_blob_asset_meta *asset_meta(uint8_t *b) {
    return section(b, SINEW_SECTION_ASSET_META);
}
static void f_name_unterminated(uint8_t *b) { /* "Hips\0" -> "HipsX": runs into bone 1 */
    ((char *)section(b, SINEW_SECTION_BONE_NAMES))[4] = 'X';
}
static void f_name_empty(uint8_t *b) {
    ((char *)section(b, SINEW_SECTION_BONE_NAMES))[0] = '\0';
}
static void f_name_last(uint8_t *b) { /* the last byte is no terminator */
    char *n = section(b, SINEW_SECTION_BONE_NAMES);
    n[asset_meta(b)->nname_bytes - 1] = 'z';
}
static void f_name_bytes(uint8_t *b) {
    asset_meta(b)->nname_bytes += 1;
}
static void f_name_bytes_small(uint8_t *b) {
    asset_meta(b)->nname_bytes = 1;
}
static void f_bind_nan(uint8_t *b) {
    double *m = section(b, SINEW_SECTION_BONE_BIND);
    m[13] = 0.0 / 0.0;
}
static void f_mesh_verts(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_SOURCE_MESH_VERTS))[1] = -4;
}
static void f_source_mesh(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_OUTPUT_SOURCE))[2] = NSRC;
}
static void f_source_vertex(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_OUTPUT_SOURCE))[3] = 4; /* mesh 1 has 4 */
}
static void f_source_half(uint8_t *b) { /* (-1, 0): a mesh of none, a vertex of one */
    ((int32_t *)section(b, SINEW_SECTION_OUTPUT_SOURCE))[1] = 0;
}
static void f_nout(uint8_t *b) {
    asset_meta(b)->noutput_verts = NSV;
    entry(b, SINEW_SECTION_OUTPUT_SOURCE)->count = 2 * NSV;
}
static void f_meta_reserved(uint8_t *b) {
    asset_meta(b)->reserved[7] = 3;
}
static void f_group_missing(uint8_t *b) {
    entry(b, SINEW_SECTION_BONE_BIND)->id = 999;
}
static void f_bind_count(uint8_t *b) {
    entry(b, SINEW_SECTION_BONE_BIND)->count -= 12;
}

TEST(forged_asset_sections_are_refused_by_name) {
    const struct {
        const char *name;
        forge_fn fn;
        sinew_result code;
        const char *needle, *needle2;
    } cases[] = {
        {"unterminated name", f_name_unterminated, SINEW_ERROR_CORRUPT, "BONE_NAMES", "bone 3"},
        {"empty name", f_name_empty, SINEW_ERROR_CORRUPT, "BONE_NAMES", "bone 0"},
        {"last name open", f_name_last, SINEW_ERROR_CORRUPT, "BONE_NAMES", "runs past"},
        {"name bytes +1", f_name_bytes, SINEW_ERROR_CORRUPT, "BONE_NAMES", "nname_bytes"},
        {"name bytes 1", f_name_bytes_small, SINEW_ERROR_CORRUPT, "ASSET_META", "nname_bytes"},
        {"bind NaN", f_bind_nan, SINEW_ERROR_NOT_FINITE, "BONE_BIND", "element 13"},
        {"mesh verts < 0", f_mesh_verts, SINEW_ERROR_CORRUPT, "SOURCE_MESH_VERTS", "mesh 1"},
        {"source mesh", f_source_mesh, SINEW_ERROR_CORRUPT, "OUTPUT_SOURCE", "output vertex 1"},
        {"source vertex", f_source_vertex, SINEW_ERROR_CORRUPT, "OUTPUT_SOURCE", "of mesh 1"},
        {"source half -1", f_source_half, SINEW_ERROR_CORRUPT, "OUTPUT_SOURCE", "output vertex 0"},
        {"output count", f_nout, SINEW_ERROR_CORRUPT, "ASSET_META", "noutput_verts"},
        {"meta reserved", f_meta_reserved, SINEW_ERROR_CORRUPT, "ASSET_META", "reserved"},
        {"group part missing", f_group_missing, SINEW_ERROR_CORRUPT, "BONE_BIND", "all or none"},
        {"bind count", f_bind_count, SINEW_ERROR_CORRUPT, "BONE_BIND", "12 nbones"},
    };
    size_t size = 0;
    uint8_t *good = asset_blob(&size);
    ENSURE(good);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        uint8_t *b = copy_exact(good, size);
        cases[i].fn(b);
        fprintf(stderr, "  %s:\n", cases[i].name);
        ENSUREF(parse_refuses(b, size, cases[i].code, cases[i].needle, cases[i].needle2), "%s",
                cases[i].name);
        free(b);
    }
    free(good);
}

/* Through the public loader a damaged asset section is SINEW_ERROR_CORRUPT, logged. */
static char g_logged[512];
static void keep_log(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    (void)level, (void)id, (void)user;
    snprintf(g_logged, sizeof g_logged, "%s", msg);
}

TEST(the_loader_logs_a_damaged_asset_section) {
    size_t size = 0;
    uint8_t *b = asset_blob(&size);
    ENSURE(b);
    f_source_vertex(b);
    fix_checksum(b, size);
    sinew_blob_def d = sinew_blob_def_default();
    d.data = b;
    d.data_size = size;
    d.logger.log = keep_log;
    sinew_blob *blob = NULL;
    ENSURE(sinew_blob_load(&d, &blob) == SINEW_ERROR_CORRUPT && blob == NULL);
    ENSUREF(strstr(g_logged, "OUTPUT_SOURCE") != NULL, "%s", g_logged);
    free(b);
}

SW_TEST_MAIN(CASE(the_skeleton_reads_back_by_name), CASE(the_output_map_and_provenance_read_back),
             CASE(a_blob_without_the_asset_description_says_so),
             CASE(forged_asset_sections_are_refused_by_name),
             CASE(the_loader_logs_a_damaged_asset_section))
