// The public header as an engine written in C++11 sees it (DESIGN.md §3): it compiles
// with -std=c++11 -pedantic -Werror, the functions have C linkage and resolve against
// the shared library, the defs are plain standard-layout structs, and their layout is
// byte for byte what the C compiler produced (compared with abi_layout_c.c).
#include <sinew/sinew.h>
#include <sinew/sinew.h> // include guards
#include <sinew/sinew_world.h>
#include <sinew/sinew_blob_format.h>

#include <cstdio>
#include <cstring>
#include <type_traits>

#include "abi_layout.h"

#if __cplusplus != 201103L
#error "compiled with a different C++ standard than the target asked for (-std=c++11)"
#endif

// Host-side structs must be copyable with memcpy and zero-initialisable like in C.
static_assert(std::is_standard_layout<sinew_blob_def>::value, "blob def layout");
static_assert(std::is_trivial<sinew_blob_def>::value, "blob def trivial");
static_assert(std::is_standard_layout<sinew_instance_def>::value, "instance def layout");
static_assert(std::is_trivial<sinew_instance_def>::value, "instance def trivial");
static_assert(std::is_trivial<sinew_allocator>::value, "allocator trivial");
static_assert(std::is_trivial<sinew_logger>::value, "logger trivial");
static_assert(offsetof(sinew_blob_def, struct_size) == 0, "struct_size first");
static_assert(offsetof(sinew_instance_def, struct_size) == 0, "struct_size first");
static_assert(SINEW_OK == 0 && SINEW_ERROR_UNSUPPORTED == 11, "stable result codes");
static_assert(SINEW_SECTION_META == 1 && SINEW_SECTION_COUNT_V1 == 26, "stable section ids");
#define SW_ABI_CXX_ELEM_SIZE(id, NAME, elem_size, type, ...)                                       \
    static_assert(sizeof(type) == elem_size, #NAME " element size");
SINEW_BLOB_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_RENDER_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_COND_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_FORCE_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_ASSET_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_STIFFNESS_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_LOD_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
SINEW_BLOB_BLOCKS_SECTIONS(SW_ABI_CXX_ELEM_SIZE)
static_assert(SINEW_SECTION_COND_FIRST == 35 && SINEW_SECTION_PAIR_FIRST == 45 &&
                  SINEW_SECTION_TRAIN_FORCE == 51 && SINEW_SECTION_ASSET_FIRST == 52 &&
                  SINEW_SECTION_CUB_STIFFNESS == 57 && SINEW_SECTION_LOD_FIRST == 59 &&
                  SINEW_SECTION_REDUCED_BLOCKS == 65 && SINEW_SECTION_ID_MAX == 65,
              "optional section ids");
static_assert(std::is_same<decltype(SINEW_VERSION), uint32_t>::value, "version is u32");

// The exact signatures a C++ host binds to.
static_assert(std::is_same<decltype(&sinew_version), uint32_t (*)()>::value, "sig");
static_assert(std::is_same<decltype(&sinew_version_string), const char *(*)()>::value, "sig");
static_assert(std::is_same<decltype(&sinew_version_compatible), int (*)(uint32_t)>::value, "sig");
static_assert(std::is_same<decltype(&sinew_result_string), const char *(*)(sinew_result)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_blob_def_default), sinew_blob_def (*)()>::value, "sig");
static_assert(std::is_same<decltype(&sinew_instance_def_default), sinew_instance_def (*)()>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_blob_bone_name),
                           const char *(*)(const sinew_blob *, uint32_t)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_blob_find_bone),
                           int32_t (*)(const sinew_blob *, const char *)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_blob_output_sources),
                           sinew_result (*)(const sinew_blob *, int32_t *, uint32_t)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_blob_get_provenance),
                           sinew_result (*)(const sinew_blob *, sinew_blob_provenance *)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_world_set_mesh_vertices),
                           sinew_result (*)(sinew_world *, sinew_collider_id, const float *,
                                            uint32_t)>::value,
              "sig");
static_assert(std::is_same<decltype(&sinew_instance_ignore_collider),
                           sinew_result (*)(sinew_instance *, sinew_collider_id)>::value,
              "sig");

namespace {

int failures = 0;

void check(bool ok, const char *what, int line) {
    if (!ok) {
        std::fprintf(stderr, "  header_cxx.cpp:%d: check failed: %s\n", line, what);
        ++failures;
    }
}
#define CHECK(cond) check((cond), #cond, __LINE__)

#define SW_ABI_CXX_VALUE(expr) static_cast<size_t>(expr),
#define SW_ABI_CXX_NAME(expr) #expr,

void layout_matches_c() {
    static const size_t cxx[] = {SW_ABI_LAYOUT(SW_ABI_CXX_VALUE)};
    static const char *const names[] = {SW_ABI_LAYOUT(SW_ABI_CXX_NAME)};
    const size_t n = sizeof cxx / sizeof cxx[0];
    CHECK(sw_abi_layout_count_c() == n);
    for (size_t i = 0; i < n && i < sw_abi_layout_count_c(); ++i) {
        if (cxx[i] != sw_abi_layout_value_c(i)) {
            std::fprintf(stderr, "  %s: C++ %zu, C %zu\n", names[i], cxx[i],
                         sw_abi_layout_value_c(i));
            ++failures;
        }
    }
}

void version_and_results() {
    CHECK(sinew_version() == SINEW_VERSION);
    CHECK(sinew_version_compatible(SINEW_VERSION) != 0);
    CHECK(sinew_version_compatible(SINEW_VERSION + (1u << 16)) == 0);
    const char *v = sinew_version_string();
    CHECK(v != nullptr && std::strchr(v, '.') != nullptr);
    for (int r = 0; r < static_cast<int>(SINEW_RESULT_COUNT_); ++r) {
        const char *s = sinew_result_string(static_cast<sinew_result>(r));
        CHECK(s != nullptr && s[0] != '\0');
        for (int q = 0; q < r && s; ++q)
            CHECK(std::strcmp(s, sinew_result_string(static_cast<sinew_result>(q))) != 0);
    }
    CHECK(std::strcmp(sinew_result_string(SINEW_OK), "ok") == 0);
    CHECK(sinew_result_string(SINEW_RESULT_COUNT_) != nullptr);
}

struct host_log {
    int calls;
};

void defaults_and_hooks() {
    sinew_blob_def b = sinew_blob_def_default();
    sinew_instance_def d = sinew_instance_def_default();
    CHECK(b.struct_size == sizeof b && b.path == nullptr && b.data_size == 0);
    CHECK(b.logger.max_level == SINEW_LOG_WARNING && b.allocator.alloc == nullptr);
    CHECK(d.struct_size == sizeof d && d.mode == SINEW_STEP_QUASISTATIC);
    CHECK(d.max_newton_iters == 0 && d.logger.log == nullptr);
    // Captureless lambdas convert to the C hook types.
    host_log log = {0};
    d.logger.log = [](sinew_log_level, uint32_t, const char *, void *user) {
        static_cast<host_log *>(user)->calls++;
    };
    d.logger.user = &log;
    d.allocator.alloc = [](size_t, size_t, void *) -> void * { return nullptr; };
    d.allocator.free = [](void *, void *) {};
    d.logger.log(SINEW_LOG_ERROR, 7u, "x", d.logger.user);
    CHECK(log.calls == 1);
    CHECK(d.allocator.alloc(8, 8, nullptr) == nullptr);
    d.allocator.free(nullptr, nullptr);
    sinew_blob *blob = nullptr;
    sinew_instance *instance = nullptr;
    CHECK(blob == nullptr && instance == nullptr);
}

} // namespace

int main() {
    layout_matches_c();
    version_and_results();
    defaults_and_hooks();
    std::printf("header_cxx: %s\n", failures ? "FAILED" : "ok");
    return failures ? 1 : 0;
}
