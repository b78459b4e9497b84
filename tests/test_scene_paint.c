/* The painted stiffness multiplier of a glTF (the _SINEW_STIFFNESS vertex attribute, read by
 * precompute/import/gltf_attribute.c beside assimp) on the render vertices, from a GLB
 * built here: a skinned mesh of two primitives (the second painted, FLOAT) and a painted
 * rigid prop (normalized UNSIGNED_BYTE) that comes first in the file but last in assimp's
 * meshes; the same as a .gltf with a data: URI, as a .gltf with a .bin beside it and
 * from a file; and the errors: a count,
 * type or view that does not fit, a value that is not finite or not > 0, a sparse
 * accessor, an index out of range. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_attribute.h"
#include "scene_import.h"
#include "sw_test.h"

/* The BIN chunk: accessor k's bytes in view k. */
typedef struct bin {
    unsigned char b[1024];
    size_t n, off[16], len[16];
    int nview;
} bin;

static void put_view(bin *B, const void *p, size_t n) {
    B->off[B->nview] = B->n, B->len[B->nview++] = n;
    memcpy(B->b + B->n, p, n);
    B->n += (n + 3) / 4 * 4;
}

#define NPAINT 4
static const float paint1[NPAINT] = {0.25f, 0.5f, 1.0f, 2.0f}; /* primitive 1's values */
static const unsigned char paint_prop[3] = {51, 255, 102};     /* 0.2, 1, 0.4 */

/* The buffer: views 0-10 (the accessors of the same number). `stiff` replaces paint1. */
static void make_bin(bin *B, const float *stiff) {
    memset(B, 0, sizeof *B);
    const float p0[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint16_t j0[12] = {0};
    const float w0[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const float p1[12] = {0, 1, 0, 1, 1, 0, 0, 2, 0, 1, 2, 0};
    const uint16_t j1[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const float w1[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const float pp[9] = {0, 0, 0, 0.1f, 0, 0, 0, 0, 0.1f};
    float ibm[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,
                     1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
    const uint16_t idx1[6] = {0, 1, 2, 2, 1, 3};
    put_view(B, p0, sizeof p0);
    put_view(B, j0, sizeof j0);
    put_view(B, w0, sizeof w0);
    put_view(B, p1, sizeof p1);
    put_view(B, j1, sizeof j1);
    put_view(B, w1, sizeof w1);
    put_view(B, stiff, sizeof(float) * NPAINT);
    put_view(B, pp, sizeof pp);
    put_view(B, paint_prop, sizeof paint_prop);
    put_view(B, ibm, sizeof ibm);
    put_view(B, idx1, sizeof idx1);
}

/* The stiffness accessor (6) as it is unless a test swaps it. */
#define STIFF_ACCESSOR "{\"bufferView\":6,\"componentType\":5126,\"count\":4,\"type\":\"SCALAR\"}"

/* The JSON over B; `buffer` is the buffers array's one element (NULL: the GLB's BIN chunk). */
static char *make_json(const bin *B, const char *buffer) {
    char glb[64], views[1024] = "";
    snprintf(glb, sizeof glb, "{\"byteLength\":%zu}", B->n);
    if (!buffer) buffer = glb;
    for (int v = 0; v < B->nview; ++v) {
        size_t k = strlen(views);
        snprintf(views + k, sizeof views - k,
                 "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", v ? "," : "", B->off[v],
                 B->len[v]);
    }
    char *j = malloc(8192 + strlen(buffer));
    if (!j) return NULL;
    sprintf(
        j,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
        "\"nodes\":[{\"name\":\"body\",\"mesh\":1,\"skin\":0},{\"name\":\"root\","
        "\"children\":[2]},{\"name\":\"tip\",\"translation\":[0,1,0],\"children\":[3]},"
        "{\"name\":\"hat\",\"mesh\":0,\"translation\":[0,0.5,0]}],"
        "\"meshes\":[{\"name\":\"prop\",\"primitives\":[{\"attributes\":{\"POSITION\":7,"
        "\"_SINEW_STIFFNESS\":8}}]},{\"name\":\"body\",\"primitives\":[{\"attributes\":{"
        "\"POSITION\":0,\"JOINTS_0\":1,\"WEIGHTS_0\":2}},{\"attributes\":{\"POSITION\":3,"
        "\"JOINTS_0\":4,\"WEIGHTS_0\":5,\"_SINEW_STIFFNESS\":6},\"indices\":10}]}],"
        "\"skins\":[{\"inverseBindMatrices\":9,\"joints\":[1,2]}],\"accessors\":["
        "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[1,1,0]},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"VEC4\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
        "{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
        "\"min\":[0,1,0],\"max\":[1,2,0]},"
        "{\"bufferView\":4,\"componentType\":5123,\"count\":4,\"type\":\"VEC4\"},"
        "{\"bufferView\":5,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}," STIFF_ACCESSOR
        ",{\"bufferView\":7,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[0.1,0,0.1]},"
        "{\"bufferView\":8,\"componentType\":5121,\"normalized\":true,\"count\":3,"
        "\"type\":\"SCALAR\"},"
        "{\"bufferView\":9,\"componentType\":5126,\"count\":2,\"type\":\"MAT4\"},"
        "{\"bufferView\":10,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
        "\"bufferViews\":[%s],\"buffers\":[%s]}",
        views, buffer);
    return j;
}

/* `j` with its first `from` replaced by `to` (a new string; NULL when `from` is absent). */
static char *swap(const char *j, const char *from, const char *to) {
    const char *at = strstr(j, from);
    if (!at) return NULL;
    char *o = malloc(strlen(j) + strlen(to) + 1);
    if (!o) return NULL;
    size_t k = (size_t)(at - j);
    memcpy(o, j, k);
    strcpy(o + k, to);
    strcat(o, at + strlen(from));
    return o;
}

static void put32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16),
    p[3] = (unsigned char)(v >> 24);
}

/* A GLB of `json` (space-padded) and B's bytes. */
static unsigned char *make_glb(const char *json, const bin *B, size_t *len) {
    size_t jl = (strlen(json) + 3) / 4 * 4, bl = (B->n + 3) / 4 * 4;
    *len = 12 + 8 + jl + 8 + bl;
    unsigned char *g = calloc(*len, 1);
    if (!g) return NULL;
    memcpy(g, "glTF", 4);
    put32(g + 4, 2), put32(g + 8, (uint32_t)*len);
    put32(g + 12, (uint32_t)jl), put32(g + 16, 0x4E4F534Au);
    memset(g + 20, ' ', jl);
    memcpy(g + 20, json, strlen(json));
    put32(g + 20 + jl, (uint32_t)bl), put32(g + 24 + jl, 0x004E4942u);
    memcpy(g + 28 + jl, B->b, B->n);
    return g;
}

/* The base GLB with `from` swapped for `to` in the JSON (both NULL: as built) and the
 * stiffness values `stiff`, imported from memory. */
static sinew_result import_variant(const char *from, const char *to, const float *stiff,
                                   sw_imported_character *c, sw_error *e) {
    bin B;
    make_bin(&B, stiff ? stiff : paint1);
    char *j = make_json(&B, NULL);
    char *j2 = j && from ? swap(j, from, to) : j;
    size_t len = 0;
    unsigned char *g = j2 ? make_glb(j2, &B, &len) : NULL;
    sw_error_clear(e);
    sinew_result rc =
        g ? sw_scene_import_memory(g, len, "glb", NULL, c, e) : SINEW_ERROR_OUT_OF_MEMORY;
    if (j2 != j) free(j2);
    free(j);
    free(g);
    return rc;
}

/* Render vertices 0-2: primitive 0 (unpainted, 1); 3-6: primitive 1's paint1; 7-9: the
 * prop (a rigid prop joins after the skinned meshes) 51/255, 1, 102/255. */
static int painted_right(const sw_imported_character *c) {
    const double want[10] = {1, 1, 1, 0.25, 0.5, 1, 2, 51 / 255.0, 1, 102 / 255.0};
    if (c->render.nverts != 10 || !c->render_stiffness || c->nskinned != 2 || c->nrigid != 1) {
        fprintf(stderr, "  %d vertices, %d skinned, %d rigid, stiffness %s\n", c->render.nverts,
                c->nskinned, c->nrigid, c->render_stiffness ? "read" : "NULL");
        return 0;
    }
    for (int i = 0; i < 10; ++i)
        if (fabs(c->render_stiffness[i] - want[i]) > 1e-7) {
            fprintf(stderr, "  vertex %d: %g, want %g\n", i, c->render_stiffness[i], want[i]);
            return 0;
        }
    return 1;
}

TEST(glb_paint_lands_on_the_render_vertices) {
    sw_imported_character c;
    sw_error e;
    sinew_result rc = import_variant(NULL, NULL, NULL, &c, &e);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    int ok = painted_right(&c);
    /* the prop's mesh is the file's first: assimp loads it last (gltf_attribute.c) */
    ok = ok && c.render_source[0] == 0 && c.render_source[3] == 1 && c.render_source[7] == 2;
    sw_imported_character_free(&c);
    ENSURE(ok);
}

/* A node only names its skin in assimp 5.2.5: the skin's joints are read after the scene's
 * roots. With "lamp" (a mesh outside the skeleton, not rendered) a root between the body
 * and the joints, the aiMeshes are body, body, lamp, prop (prop before lamp were the
 * skin read with its node). */
TEST(skins_are_read_after_the_scene) {
    bin B;
    make_bin(&B, paint1);
    char *j = make_json(&B, NULL);
    char *j2 =
        j ? swap(j, "\"scenes\":[{\"nodes\":[0,1]}]", "\"scenes\":[{\"nodes\":[0,4,1]}]") : NULL;
    char *j3 = j2 ? swap(j2, "\"translation\":[0,0.5,0]}]",
                         "\"translation\":[0,0.5,0]},{\"name\":\"lamp\",\"mesh\":2}]")
                  : NULL;
    char *j4 = j3 ? swap(j3, "\"indices\":10}]}]",
                         "\"indices\":10}]},{\"primitives\":[{\"attributes\":{"
                         "\"POSITION\":0}}]}]")
                  : NULL;
    size_t len = 0;
    unsigned char *g = j4 ? make_glb(j4, &B, &len) : NULL;
    free(j), free(j2), free(j3), free(j4);
    ENSURE(g);
    sw_imported_character c;
    sw_error e;
    sw_error_clear(&e);
    sinew_result rc = sw_scene_import_memory(g, len, "glb", NULL, &c, &e);
    free(g);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    int ok =
        painted_right(&c) && c.nsource_meshes == 4 && c.nignored == 1 && c.render_source[7] == 3;
    sw_imported_character_free(&c);
    ENSURE(ok);
}

TEST(nothing_painted_is_null) {
    sw_imported_character c;
    sw_error e;
    bin B;
    make_bin(&B, paint1);
    char *j = make_json(&B, NULL);
    char *j2 = j ? swap(j, ",\"_SINEW_STIFFNESS\":6", "") : NULL;
    char *j3 = j2 ? swap(j2, ",\"_SINEW_STIFFNESS\":8", "") : NULL;
    size_t len = 0;
    unsigned char *g = j3 ? make_glb(j3, &B, &len) : NULL;
    sinew_result rc = g ? sw_scene_import_memory(g, len, "glb", NULL, &c, &e) : SINEW_ERROR_IO;
    free(j), free(j2), free(j3), free(g);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    int ok = c.render.nverts == 10 && c.render_stiffness == NULL;
    sw_imported_character_free(&c);
    ENSURE(ok);
}

static void b64(const unsigned char *p, size_t n, char *o) {
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t k = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) |
                     (i + 2 < n ? p[i + 2] : 0);
        o[k++] = t[v >> 18], o[k++] = t[v >> 12 & 63];
        o[k++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        o[k++] = i + 2 < n ? t[v & 63] : '=';
    }
    o[k] = 0;
}

/* The same scene as a .gltf whose buffer is a base64 data: URI, from memory; and the GLB
 * from a file (sw_scene_import reads the file's bytes once more for the attribute). */
TEST(gltf_data_uri_and_glb_file) {
    bin B;
    make_bin(&B, paint1);
    char buffer[2048];
    int k = snprintf(buffer, sizeof buffer,
                     "{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,", B.n);
    b64(B.b, B.n, buffer + k);
    strcat(buffer, "\"}");
    char *j = make_json(&B, buffer);
    ENSURE(j);
    sw_imported_character c;
    sw_error e;
    sw_error_clear(&e);
    sinew_result rc = sw_scene_import_memory(j, strlen(j), "gltf", NULL, &c, &e);
    free(j);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    int ok = painted_right(&c);
    sw_imported_character_free(&c);
    ENSURE(ok);

    char *jb = make_json(&B, NULL);
    size_t len = 0;
    unsigned char *g = jb ? make_glb(jb, &B, &len) : NULL;
    free(jb);
    ENSURE(g);
    const char *path = SINEW_BINARY_DIR "/tests/test_scene_paint.glb";
    FILE *f = fopen(path, "wb");
    int wrote = f && fwrite(g, 1, len, f) == len;
    if (f) fclose(f);
    free(g);
    ENSURE(wrote);
    rc = sw_scene_import(path, NULL, &c, &e);
    remove(path);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    ok = painted_right(&c);
    sw_imported_character_free(&c);
    ENSURE(ok);
}

/* The .gltf of a separate .bin (Blender's "glTF Separate"), from a path: the .bin is read
 * beside it; missing, it is an error. */
TEST(gltf_with_a_bin_file_beside_it) {
    bin B;
    make_bin(&B, paint1);
    char buffer[128];
    snprintf(buffer, sizeof buffer, "{\"byteLength\":%zu,\"uri\":\"paint_buffer.bin\"}", B.n);
    char *j = make_json(&B, buffer);
    ENSURE(j);
    const char *gltf = SINEW_BINARY_DIR "/tests/test_scene_paint.gltf";
    const char *bin_path = SINEW_BINARY_DIR "/tests/paint_buffer.bin";
    FILE *f = fopen(gltf, "wb"), *g = fopen(bin_path, "wb");
    int wrote = f && g && fwrite(j, 1, strlen(j), f) == strlen(j) && fwrite(B.b, 1, B.n, g) == B.n;
    if (f) fclose(f);
    if (g) fclose(g);
    free(j);
    ENSURE(wrote);
    sw_imported_character c;
    sw_error e;
    sw_error_clear(&e);
    sinew_result rc = sw_scene_import(gltf, NULL, &c, &e);
    int ok = rc == SINEW_OK && painted_right(&c);
    if (rc) fprintf(stderr, "  %s\n", e.msg);
    sw_imported_character_free(&c);
    remove(bin_path);
    rc = sw_scene_import(gltf, NULL, &c, &e); /* assimp itself needs the .bin */
    ok = ok && rc != SINEW_OK && c.render.nverts == 0;
    remove(gltf);
    ENSURE(ok);
}

/* An error `want` naming `what`, and no character. */
static int fails_with(sinew_result rc, sinew_result want, const sw_imported_character *c,
                      const sw_error *e, const char *what) {
    int ok =
        rc == want && strstr(e->msg, what) && c->render.nverts == 0 && c->render_stiffness == NULL;
    fprintf(stderr, "  %s -> %d %s\n", what, (int)rc, e->msg);
    return ok;
}

#define STIFF_WITH(...) "{\"bufferView\":6,\"componentType\":5126," __VA_ARGS__ "}"

TEST(bad_attributes_are_errors) {
    sw_imported_character c;
    sw_error e;
    sinew_result rc;
    rc =
        import_variant(STIFF_ACCESSOR, STIFF_WITH("\"count\":3,\"type\":\"SCALAR\""), NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "count must be 4"));
    rc = import_variant(STIFF_ACCESSOR, STIFF_WITH("\"count\":4,\"type\":\"VEC2\""), NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "must be SCALAR FLOAT"));
    rc = import_variant(STIFF_ACCESSOR,
                        "{\"bufferView\":6,\"componentType\":5125,\"count\":4,\"type\":\"SCALAR\"}",
                        NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "must be SCALAR FLOAT"));
    rc = import_variant(STIFF_ACCESSOR,
                        STIFF_WITH("\"count\":4,\"type\":\"SCALAR\",\"byteOffset\":4"), NULL, &c,
                        &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "overrun its view"));
    rc = import_variant(STIFF_ACCESSOR,
                        STIFF_WITH("\"count\":4,\"type\":\"SCALAR\",\"sparse\":{\"count\":1}"),
                        NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_UNSUPPORTED, &c, &e, "sparse"));
    /* view 6 moved past the buffer's end: its bytes are not there */
    char from[64], to[64];
    bin B;
    make_bin(&B, paint1);
    snprintf(from, sizeof from, "\"byteOffset\":%zu,\"byteLength\":16}", B.off[6]);
    snprintf(to, sizeof to, "\"byteOffset\":%zu,\"byteLength\":16}", B.n);
    rc = import_variant(from, to, NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "overruns buffer"));
    /* a bufferView index out of range: the precheck names it before assimp runs */
    rc = import_variant(STIFF_ACCESSOR, "{\"bufferView\":60,\"componentType\":5126,\"count\":4}",
                        NULL, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_PARSE, &c, &e, "accessor 6"));
}

TEST(values_must_be_finite_and_positive) {
    sw_imported_character c;
    sw_error e;
    float v[NPAINT];
    memcpy(v, paint1, sizeof v);
    v[2] = NAN;
    sinew_result rc = import_variant(NULL, NULL, v, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_INVALID_ARGUMENT, &c, &e, "mesh 1 primitive 1 vertex 2"));
    v[2] = INFINITY;
    rc = import_variant(NULL, NULL, v, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_INVALID_ARGUMENT, &c, &e, "mesh 1 primitive 1 vertex 2"));
    v[2] = 1, v[0] = 0;
    rc = import_variant(NULL, NULL, v, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_INVALID_ARGUMENT, &c, &e, "mesh 1 primitive 1 vertex 0"));
    v[0] = -0.5f;
    rc = import_variant(NULL, NULL, v, &c, &e);
    ENSURE(fails_with(rc, SINEW_ERROR_INVALID_ARGUMENT, &c, &e, "vertex 0"));
}

/* The reader on its own: counts that are not assimp's, an accessor index out of range. */
TEST(reader_checks_against_assimps_meshes) {
    bin B;
    make_bin(&B, paint1);
    char *j = make_json(&B, NULL);
    size_t len = 0;
    unsigned char *g = j ? make_glb(j, &B, &len) : NULL;
    ENSURE(g);
    double *out = NULL;
    sw_error e;
    const int32_t right[3] = {3, 4, 3}, wrong[3] = {3, 3, 4}, few[2] = {3, 4};
    sinew_result rc = sw_gltf_float_attribute(g, len, 1, NULL, "_SINEW_STIFFNESS", "t.glb", 3,
                                              right, NULL, &out, &e);
    int ok = rc == SINEW_OK && out && out[3] == 0.25 && out[6] == 2 && out[2] == 1;
    free(out);
    rc = sw_gltf_float_attribute(g, len, 1, NULL, "_SINEW_STIFFNESS", "t.glb", 3, wrong, NULL, &out,
                                 &e);
    ok = ok && rc == SINEW_ERROR_UNSUPPORTED && !out && strstr(e.msg, "does not match");
    rc = sw_gltf_float_attribute(g, len, 1, NULL, "_SINEW_STIFFNESS", "t.glb", 2, few, NULL, &out,
                                 &e);
    ok = ok && rc == SINEW_ERROR_UNSUPPORTED && !out && strstr(e.msg, "3 glTF primitives");
    rc = sw_gltf_float_attribute(g, len, 1, NULL, "_OTHER", "t.glb", 3, right, NULL, &out, &e);
    ok = ok && rc == SINEW_OK && !out;
    free(g);
    char *j2 = j ? swap(j, "\"_SINEW_STIFFNESS\":6", "\"_SINEW_STIFFNESS\":99") : NULL;
    g = j2 ? make_glb(j2, &B, &len) : NULL;
    rc = g ? sw_gltf_float_attribute(g, len, 1, NULL, "_SINEW_STIFFNESS", "t.glb", 3, right, NULL,
                                     &out, &e)
           : SINEW_OK;
    ok = ok && rc == SINEW_ERROR_PARSE && !out && strstr(e.msg, "not an accessor");
    free(g), free(j), free(j2);
    ENSURE(ok);
}

SW_TEST_MAIN(CASE(glb_paint_lands_on_the_render_vertices), CASE(skins_are_read_after_the_scene),
             CASE(nothing_painted_is_null), CASE(gltf_data_uri_and_glb_file),
             CASE(gltf_with_a_bin_file_beside_it), CASE(bad_attributes_are_errors),
             CASE(values_must_be_finite_and_positive), CASE(reader_checks_against_assimps_meshes))
