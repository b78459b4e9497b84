/* The public header as an engine written in strict ISO C sees it (DESIGN.md §3).
 * Built three times by tests/abi.cmake: C99 and C11 against the shared library, C99
 * against the static one, always with -pedantic -Werror. It touches every public
 * declaration: the signatures are pinned by typed function pointers (a changed
 * signature stops the build), the stable enum values and struct layout rules by
 * compile-time asserts, and the functions and inline defaults are called. */

/* The target's C_STANDARD must beat the project's global C17 (abi.cmake passes the
 * expected value), and extensions must be off, or this test would prove nothing. */
#if !defined(__STDC_VERSION__) || !defined(SW_ABI_EXPECT_STDC) ||                                  \
    __STDC_VERSION__ != SW_ABI_EXPECT_STDC
#error "compiled with a different C standard than the target asked for"
#endif
#ifndef __STRICT_ANSI__
#error "compiled with GNU extensions; the ABI test needs strict ISO C (C_EXTENSIONS OFF)"
#endif
#if defined(_POSIX_C_SOURCE) || defined(_GNU_SOURCE) || defined(_DEFAULT_SOURCE)
#error "a feature-test macro leaked in; the header must compile on ISO C alone"
#endif

#include <sinew/sinew_base.h>
#include <sinew/sinew.h>
#include <sinew/sinew.h> /* include guards: a second inclusion must be harmless */
#include <sinew/sinew_types.h>
#include <sinew/sinew_world.h>
#include <sinew/sinew_blob_format.h>

#include "sw_test.h"

#if __STDC_VERSION__ >= 201112L
#define SW_ABI_ASSERT(cond, tag) _Static_assert(cond, #tag)
#else
#define SW_ABI_ASSERT(cond, tag) typedef char sw_abi_assert_##tag[(cond) ? 1 : -1]
#endif

/* Result codes are stable across versions: a renumbering breaks every old host. */
SW_ABI_ASSERT(SINEW_OK == 0, ok);
SW_ABI_ASSERT(SINEW_ERROR_INVALID_ARGUMENT == 1, invalid_argument);
SW_ABI_ASSERT(SINEW_ERROR_OUT_OF_MEMORY == 2, out_of_memory);
SW_ABI_ASSERT(SINEW_ERROR_IO == 3, io);
SW_ABI_ASSERT(SINEW_ERROR_PARSE == 4, parse);
SW_ABI_ASSERT(SINEW_ERROR_DEGENERATE == 5, degenerate);
SW_ABI_ASSERT(SINEW_ERROR_NOT_FINITE == 6, not_finite);
SW_ABI_ASSERT(SINEW_ERROR_CORRUPT == 7, corrupt);
SW_ABI_ASSERT(SINEW_ERROR_VERSION == 8, version);
SW_ABI_ASSERT(SINEW_ERROR_CAPACITY == 9, capacity);
SW_ABI_ASSERT(SINEW_ERROR_NOT_CONVERGED == 10, not_converged);
SW_ABI_ASSERT(SINEW_ERROR_UNSUPPORTED == 11, unsupported);
SW_ABI_ASSERT(SINEW_RESULT_COUNT_ >= 12, result_count);
SW_ABI_ASSERT(SINEW_LOG_NONE == -1, log_none);
SW_ABI_ASSERT(SINEW_LOG_ERROR == 0 && SINEW_LOG_WARNING == 1, log_levels_low);
SW_ABI_ASSERT(SINEW_LOG_INFO == 2 && SINEW_LOG_DEBUG == 3, log_levels_high);
SW_ABI_ASSERT(SINEW_STEP_QUASISTATIC == 0 && SINEW_STEP_DYNAMIC == 1, step_modes);

/* The packed version is usable in #if and in constant expressions. */
SW_ABI_ASSERT(SINEW_VERSION ==
                  ((SINEW_VERSION_MAJOR << 16) | (SINEW_VERSION_MINOR << 8) | SINEW_VERSION_PATCH),
              packed_version);
SW_ABI_ASSERT(sizeof(SINEW_VERSION) == sizeof(uint32_t), version_is_u32);

/* Extensible defs: struct_size comes first, so the library can read it before it knows
 * which version of the struct it was handed. */
SW_ABI_ASSERT(offsetof(sinew_blob_def, struct_size) == 0, blob_def_size_first);
SW_ABI_ASSERT(offsetof(sinew_instance_def, struct_size) == 0, instance_def_size_first);

/* The blob format's section table expands in strict C: stable ids, and element types of
 * the format's element sizes. */
SW_ABI_ASSERT(SINEW_SECTION_META == 1 && SINEW_SECTION_CONTACT_DATA == 26, section_ids);
SW_ABI_ASSERT(SINEW_SECTION_COUNT_V1 == 26, section_count_v1);
#define SW_ABI_ELEM_SIZE(id, NAME, elem_size, type, ...)                                           \
    SW_ABI_ASSERT(sizeof(type) == elem_size, elem_size_##NAME);
SINEW_BLOB_SECTIONS(SW_ABI_ELEM_SIZE)
/* The optional groups: the render mesh's and the condensation tet mesh's ids, in order. */
SW_ABI_ASSERT(SINEW_SECTION_RENDER_FIRST == 27 && SINEW_SECTION_RENDER_LAST == 34, render_ids);
SW_ABI_ASSERT(SINEW_SECTION_COND_FIRST == 35 && SINEW_SECTION_COND_LAST == 44, cond_ids);
SW_ABI_ASSERT(SINEW_SECTION_PAIR_FIRST == 45 && SINEW_SECTION_PAIR_LAST == 50, pair_ids);
SW_ABI_ASSERT(SINEW_SECTION_TRAIN_FORCE == 51, force_id);
SW_ABI_ASSERT(SINEW_SECTION_ASSET_FIRST == 52 && SINEW_SECTION_ASSET_LAST == 56, asset_ids);
SW_ABI_ASSERT(SINEW_SECTION_CUB_STIFFNESS == 57 && SINEW_SECTION_TET_STIFFNESS == 58,
              stiffness_ids);
SW_ABI_ASSERT(SINEW_SECTION_LOD_FIRST == 59 && SINEW_SECTION_LOD_LAST == 64, lod_ids);
SW_ABI_ASSERT(SINEW_SECTION_REDUCED_BLOCKS == 65 &&
                  SINEW_SECTION_ID_MAX == SINEW_SECTION_REDUCED_BLOCKS,
              blocks_id);
SINEW_BLOB_RENDER_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_COND_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_FORCE_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_ASSET_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_LOD_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_STIFFNESS_SECTIONS(SW_ABI_ELEM_SIZE)
SINEW_BLOB_BLOCKS_SECTIONS(SW_ABI_ELEM_SIZE)
SW_ABI_ASSERT(offsetof(sinew_blob_provenance, struct_size) == 0, provenance_size_first);

/* Every public function, with the exact signature a host binary was built against. */
typedef uint32_t (*sw_abi_version_fn)(void);
typedef const char *(*sw_abi_version_string_fn)(void);
typedef int (*sw_abi_version_compatible_fn)(uint32_t);
typedef const char *(*sw_abi_result_string_fn)(sinew_result);
typedef sinew_blob_def (*sw_abi_blob_def_default_fn)(void);
typedef sinew_instance_def (*sw_abi_instance_def_default_fn)(void);
typedef const char *(*sw_abi_bone_name_fn)(const sinew_blob *, uint32_t);
typedef int32_t (*sw_abi_find_bone_fn)(const sinew_blob *, const char *);
typedef sinew_result (*sw_abi_bone_parent_fn)(const sinew_blob *, uint32_t, int32_t *);
typedef sinew_result (*sw_abi_bone_bind_fn)(const sinew_blob *, uint32_t, double *);
typedef uint32_t (*sw_abi_source_mesh_count_fn)(const sinew_blob *);
typedef sinew_result (*sw_abi_output_sources_fn)(const sinew_blob *, int32_t *, uint32_t);
typedef sinew_result (*sw_abi_get_provenance_fn)(const sinew_blob *, sinew_blob_provenance *);
typedef uint64_t (*sw_abi_hash_bytes_fn)(const void *, size_t);
typedef sinew_result (*sw_abi_debug_draw_fn)(const sinew_instance *, const sinew_debug_draw *);
typedef sinew_result (*sw_abi_recorder_open_fn)(const sinew_recorder_def *, sinew_recorder **);
typedef sinew_result (*sw_abi_recorder_fn)(sinew_recorder *);
typedef sinew_result (*sw_abi_set_recorder_fn)(sinew_instance *, sinew_recorder *);
typedef sinew_result (*sw_abi_set_mesh_vertices_fn)(sinew_world *, sinew_collider_id, const float *,
                                                    uint32_t);
typedef sinew_result (*sw_abi_ignore_collider_fn)(sinew_instance *, sinew_collider_id);

static int sw_abi_log_calls;

static void *sw_abi_alloc(size_t size, size_t alignment, void *user) {
    (void)size;
    (void)alignment;
    (void)user;
    return NULL;
}

static void sw_abi_free(void *ptr, void *user) {
    (void)ptr;
    (void)user;
}

static void sw_abi_log(sinew_log_level level, uint32_t message_id, const char *message,
                       void *user) {
    (void)level;
    (void)message_id;
    (void)message;
    (void)user;
    sw_abi_log_calls++;
}

TEST(functions_have_the_pinned_signatures) {
    sw_abi_version_fn version = &sinew_version;
    sw_abi_version_string_fn version_string = &sinew_version_string;
    sw_abi_version_compatible_fn compatible = &sinew_version_compatible;
    sw_abi_result_string_fn result_string = &sinew_result_string;
    sw_abi_blob_def_default_fn blob_default = &sinew_blob_def_default;
    sw_abi_instance_def_default_fn instance_default = &sinew_instance_def_default;
    ENSURE(version && version_string && compatible && result_string);
    ENSURE(blob_default && instance_default);
    {
        sw_abi_bone_name_fn bone_name = &sinew_blob_bone_name;
        sw_abi_find_bone_fn find_bone = &sinew_blob_find_bone;
        sw_abi_bone_parent_fn bone_parent = &sinew_blob_bone_parent;
        sw_abi_bone_bind_fn bone_bind = &sinew_blob_bone_bind;
        sw_abi_source_mesh_count_fn mesh_count = &sinew_blob_source_mesh_count;
        sw_abi_output_sources_fn sources = &sinew_blob_output_sources;
        sw_abi_get_provenance_fn provenance = &sinew_blob_get_provenance;
        sw_abi_hash_bytes_fn hash = &sinew_hash_bytes;
        sinew_blob_provenance p;
        int32_t parent = 7;
        p.struct_size = (uint32_t)sizeof p;
        /* NULL blobs are refused, never dereferenced */
        ENSURE(bone_name(NULL, 0) == NULL && find_bone(NULL, "x") == -1);
        ENSURE(bone_parent(NULL, 0, &parent) == SINEW_ERROR_INVALID_ARGUMENT && parent == 7);
        ENSURE(bone_bind(NULL, 0, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(mesh_count(NULL) == 0 && sources(NULL, NULL, 0) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(provenance(NULL, &p) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(hash("", 0) == 0xcbf29ce484222325ull); /* FNV-1a 64's offset basis */
    }
    {
        sw_abi_debug_draw_fn draw = &sinew_instance_debug_draw;
        sw_abi_recorder_open_fn open_rec = &sinew_recorder_open;
        sw_abi_recorder_fn flush = &sinew_recorder_flush, close_rec = &sinew_recorder_close;
        sw_abi_set_recorder_fn set_rec = &sinew_instance_set_recorder;
        sinew_recorder_def rd = sinew_recorder_def_default();
        sinew_recorder *rec = NULL;
        ENSURE(draw(NULL, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(open_rec(&rd, &rec) == SINEW_ERROR_INVALID_ARGUMENT && rec == NULL); /* no path */
        ENSURE(flush(NULL) == SINEW_ERROR_INVALID_ARGUMENT && close_rec(NULL) == SINEW_OK);
        ENSURE(set_rec(NULL, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(rd.struct_size == sizeof(sinew_recorder_def));
    }
    {
        sw_abi_set_mesh_vertices_fn set_vertices = &sinew_world_set_mesh_vertices;
        sw_abi_ignore_collider_fn ignore = &sinew_instance_ignore_collider;
        ENSURE(set_vertices(NULL, 1, NULL, 3) == SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(ignore(NULL, 0) == SINEW_ERROR_INVALID_ARGUMENT);
    }
    /* Calls through the pointers reach the same code as direct calls. */
    ENSURE(version() == sinew_version());
    ENSURE(version_string() == sinew_version_string());
    ENSURE(compatible(SINEW_VERSION) == sinew_version_compatible(SINEW_VERSION));
    ENSURE(result_string(SINEW_ERROR_IO) == sinew_result_string(SINEW_ERROR_IO));
    ENSURE(blob_default().struct_size == sizeof(sinew_blob_def));
    ENSURE(instance_default().struct_size == sizeof(sinew_instance_def));
}

TEST(library_matches_header_version) {
    char expect[32];
    ENSUREF(sinew_version() == SINEW_VERSION, "library %lx, header %lx",
            (unsigned long)sinew_version(), (unsigned long)SINEW_VERSION);
    ENSURE(sinew_version_compatible(SINEW_VERSION) != 0);
    ENSURE(sinew_version_compatible(SINEW_VERSION + (1u << 16)) == 0); /* newer major */
    ENSURE(sinew_version_compatible(SINEW_VERSION + (1u << 8)) == 0);  /* newer minor */
    sprintf(expect, "%d.%d.%d", SINEW_VERSION_MAJOR, SINEW_VERSION_MINOR, SINEW_VERSION_PATCH);
    ENSURE(sinew_version_string() != NULL);
    ENSUREF(strcmp(sinew_version_string(), expect) == 0, "'%s' vs '%s'", sinew_version_string(),
            expect);
}

TEST(every_result_has_a_string) {
    int r;
    for (r = 0; r < (int)SINEW_RESULT_COUNT_; ++r) {
        const char *s = sinew_result_string((sinew_result)r);
        ENSUREF(s != NULL && s[0] != '\0', "result %d", r);
    }
    /* Unknown values from a newer library or a bad cast still get a string. */
    ENSURE(sinew_result_string(SINEW_RESULT_COUNT_) != NULL);
    ENSURE(sinew_result_string((sinew_result)-1) != NULL);
    ENSURE(sinew_result_string((sinew_result)1000000) != NULL);
}

TEST(inline_defaults_fill_every_field) {
    sinew_blob_def b = sinew_blob_def_default();
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(b.struct_size == sizeof b);
    ENSURE(b.path == NULL && b.data == NULL && b.data_size == 0);
    ENSURE(b.allocator.alloc == NULL && b.allocator.free == NULL && b.allocator.user == NULL);
    ENSURE(b.logger.log == NULL && b.logger.user == NULL);
    ENSURE(b.logger.max_level == SINEW_LOG_WARNING);
    ENSURE(d.struct_size == sizeof d);
    ENSURE(d.mode == SINEW_STEP_QUASISTATIC && d.max_newton_iters == 0);
    ENSURE(d.allocator.alloc == NULL && d.allocator.free == NULL && d.allocator.user == NULL);
    ENSURE(d.logger.log == NULL && d.logger.user == NULL);
    ENSURE(d.logger.max_level == SINEW_LOG_WARNING);
    ENSURE(sinew_logger_silent().log == NULL && sinew_logger_silent().max_level == SINEW_LOG_NONE);
}

TEST(host_hooks_and_handles_fit_the_types) {
    sinew_blob_def b = sinew_blob_def_default();
    sinew_instance_def d = sinew_instance_def_default();
    sinew_blob *blob = NULL;         /* opaque: only pointers exist on the host side */
    sinew_instance *instance = NULL; /* likewise */
    sinew_result result = SINEW_OK;
    sinew_log_level level = SINEW_LOG_DEBUG;
    sinew_step_mode mode = SINEW_STEP_DYNAMIC;
    b.allocator.alloc = sw_abi_alloc;
    b.allocator.free = sw_abi_free;
    b.allocator.user = &b;
    b.logger.log = sw_abi_log;
    b.logger.user = &b;
    b.logger.max_level = level;
    d.mode = mode;
    d.allocator = b.allocator;
    d.logger = b.logger;
    ENSURE(blob == NULL && instance == NULL && result == SINEW_OK);
    ENSURE(d.allocator.alloc(16, 16, d.allocator.user) == NULL);
    d.allocator.free(NULL, d.allocator.user);
    d.logger.log(SINEW_LOG_INFO, 1u, "hello", d.logger.user);
    ENSURE(sw_abi_log_calls == 1);
    ENSURE(d.mode == SINEW_STEP_DYNAMIC && d.logger.max_level == SINEW_LOG_DEBUG);
}

SW_TEST_MAIN(CASE(functions_have_the_pinned_signatures), CASE(library_matches_header_version),
             CASE(every_result_has_a_string), CASE(inline_defaults_fill_every_field),
             CASE(host_hooks_and_handles_fit_the_types))
