/* Blob writer, parser/validator and public load API (DESIGN.md §6): bit-exact round trips
 * through memory and files, the writer's validation and its file errors, and the load
 * API's hooks, log messages, def struct sizes and NULL arguments. Hostile input
 * (truncation at every length, every byte flipped, forged counts, indices, offsets and
 * versions, unknown sections) is in test_blob_hostile.c; the synthetic character and the
 * forging helpers in blob_synth.h. */
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
    ENSURE(memcmp(h->magic, SINEW_BLOB_MAGIC, 8) == 0 && h->version == SINEW_BLOB_VERSION_MIN);
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
    int allocs, frees, fail, fail_at; /* fail: every allocation; fail_at: the one numbered so */
} alloc_count;

static void *count_alloc(size_t size, size_t align, void *user) {
    alloc_count *a = user;
    if (a->fail || (a->fail_at > 0 && a->allocs + 1 == a->fail_at)) return NULL;
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
    alloc_count ac = {0, 0, 0, 0};
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
    /* the blob and its collision surface are kept; the surface's scratch went back */
    ENSUREF(ac.allocs - ac.frees == 2, "%d allocations, %d freed", ac.allocs, ac.frees);
    ENSUREF(cap.calls == 1 && cap.level == SINEW_LOG_INFO && cap.id == SINEW_MSG_BLOB_LOADED,
            "%d calls, last '%s'", cap.calls, cap.text);
    sinew_blob_destroy(h);
    ENSURE(ac.frees == ac.allocs);
    /* each allocation of the load failing in turn: an error, nothing leaked */
    const int all = ac.allocs;
    for (int n = 1; n <= all; ++n) {
        alloc_count one = {0, 0, 0, n};
        def.allocator.user = &one;
        ENSURE(sinew_blob_load(&def, &h) == SINEW_ERROR_OUT_OF_MEMORY);
        ENSUREF(one.frees == one.allocs, "allocation %d failing: %d kept", n,
                one.allocs - one.frees);
    }
    def.allocator.user = &ac;

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

/* Version 4 stores the mass and the springs by domain blocks (sinew_blob_format.h, id 65):
 * the same character written dense (version 2) and by blocks reads back the same entries
 * everywhere, zeros where a block is left out; the blocks' table is checked. */
TEST(reduced_matrices_by_blocks_read_as_the_dense_ones) {
    static fixture dense, packed;
    static blocks_fixture k;
    fixture_init(&packed, 5);
    fixture_add_blocks(&packed, &k); /* zeroes a springs block of packed's dense arrays */
    fixture_init(&dense, 5);
    memcpy(dense.spring_hessian, packed.spring_hessian, sizeof dense.spring_hessian);
    size_t nd_bytes = 0, np_bytes = 0;
    sw_blob_view vd, vp;
    uint8_t *bd = write_parsed(&dense, &nd_bytes, &vd), *bp = write_parsed(&packed, &np_bytes, &vp);
    ENSURE(bd && bp);
    ENSURE(hdr(bd)->version == SINEW_BLOB_VERSION_MIN && hdr(bp)->version == 4);
    ENSURE(!vd.reduced_blocks && vp.reduced_blocks && entry(bp, SINEW_SECTION_REDUCED_BLOCKS));
    ENSURE(vp.nmass < vd.nmass && vp.nspring_hessian < vd.nspring_hessian);
    for (int m = SW_BLOB_MASS; m <= SW_BLOB_SPRINGS; ++m)
        for (int32_t i = 0; i < RT; ++i)
            for (int32_t j = 0; j < RT; ++j) {
                double a = sw_blob_reduced_entry(&vd, m, i, j),
                       b = sw_blob_reduced_entry(&vp, m, i, j);
                ENSUREF(memcmp(&a, &b, sizeof a) == 0, "matrix %d (%d, %d): %g and %g", m, i, j, a,
                        b);
            }
    ENSURE(!sw_blob_block_nonzero(&vp, SW_BLOB_SPRINGS, 0, ND - 1) &&
           !sw_blob_block_nonzero(&vd, SW_BLOB_SPRINGS, 0, ND - 1));
    ENSURE(sw_blob_block_nonzero(&vp, SW_BLOB_SPRINGS, 0, 1) &&
           sw_blob_block_nonzero(&vd, SW_BLOB_SPRINGS, 0, 1));
    int64_t ld;
    ENSURE(!sw_blob_block(&vp, SW_BLOB_SPRINGS, 0, ND - 1, &ld) &&
           sw_blob_block(&vd, SW_BLOB_SPRINGS, 0, ND - 1, &ld));
    /* the table, forged: each refused with what is wrong */
    int32_t *blk;
    uint8_t *f = copy_exact(bp, np_bytes);
    hdr(f)->version = 2; /* outside the checksum */
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "REDUCED_BLOCKS", "version 4"));
    memcpy(f, bp, np_bytes);
    hdr(f)->version = 4;
    blk = section(f, SINEW_SECTION_REDUCED_BLOCKS);
    blk[0] = -1; /* the mass's first diagonal block */
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "MASS diagonal block 0", "not stored"));
    memcpy(f, bp, np_bytes);
    blk = section(f, SINEW_SECTION_REDUCED_BLOCKS);
    blk[1] = 0; /* the mass's block (0, 1), left out, said to be where block (0, 0) is */
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "MASS block (0, 1) at 0", "end at"));
    memcpy(f, bp, np_bytes);
    blk = section(f, SINEW_SECTION_REDUCED_BLOCKS);
    blk[ND * ND + ND - 1] = -7;
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "SPRING_HESSIAN block (0, 2)",
                         "offset or -1"));
    memcpy(f, bp, np_bytes);
    entry(f, SINEW_SECTION_SPRING_HESSIAN)->count -= 1;
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "SPRING_HESSIAN", "stored blocks"));
    memcpy(f, bp, np_bytes);
    ((double *)section(f, SINEW_SECTION_MASS))[0] = 0.0; /* a diagonal entry */
    ENSURE(parse_refuses(f, np_bytes, SINEW_ERROR_CORRUPT, "MASS", "diagonal entry 0"));
    free(f);
    /* a dense blob must stay dense: a version-2 header on dense matrices of another size */
    f = copy_exact(bd, nd_bytes);
    hdr(f)->version = 4;
    ENSURE(parse_refuses(f, nd_bytes, SINEW_ERROR_CORRUPT, "version 4", "without REDUCED_BLOCKS"));
    memcpy(f, bd, nd_bytes);
    entry(f, SINEW_SECTION_MASS)->count -= 1;
    ENSURE(parse_refuses(f, nd_bytes, SINEW_ERROR_CORRUPT, "MASS", "rank_total^2"));
    free(f);
    fprintf(stderr, "    dense %zu bytes, by blocks %zu\n", nd_bytes, np_bytes);
    free(bd);
    free(bp);
}

SW_TEST_MAIN(CASE(checksum_is_fnv1a_64), CASE(memory_round_trip_is_bit_exact),
             CASE(file_and_buffer_loads_match), CASE(writer_rejects_invalid_views),
             CASE(writer_file_errors_leave_nothing_behind), CASE(load_uses_hooks_and_logs_errors),
             CASE(load_argument_errors), CASE(reduced_matrices_by_blocks_read_as_the_dense_ones))
