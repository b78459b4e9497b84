/* libFuzzer harness for the Wavefront OBJ reader (sw_parse_obj; STYLE.md §9: a fuzz
 * harness for every loader). tests/CMakeLists.txt builds it with clang when clang has
 * libFuzzer and runs it for a few seconds on tests/fuzz/corpus/obj as the test fuzz_obj;
 * tools/scripts/run-fuzz.sh runs it for longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_obj.c \
 *     precompute/io/obj_io.c precompute/io/text_reader.c precompute/io/sw_mesh.c \
 *     runtime/core/sw_error.c -lm -o build-fuzz-obj
 *   cp -r tests/fuzz/corpus/obj /tmp/obj-corpus && ./build-fuzz-obj /tmp/obj-corpus
 *
 * A failure must name the text and leave the output zeroed. An accepted surface has at
 * least one vertex and one triangle, finite coordinates and in-range corners. */
#include <math.h>

#include "fuzz_check.h"
#include "mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    sw_trimesh m;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_parse_obj(copy, size, "fuzz.obj", &m, &err);
    if (rc == SINEW_OK) {
        if (m.nverts < 1 || m.ntris < 1 || !m.X || !m.tris) abort();
        for (int64_t i = 0; i < 3 * (int64_t)m.nverts; ++i)
            if (!isfinite(m.X[i])) abort();
        for (int64_t i = 0; i < 3 * (int64_t)m.ntris; ++i)
            if (m.tris[i] < 0 || m.tris[i] >= m.nverts) abort();
    } else {
        sw_fuzz_check_error(rc, &err, "fuzz.obj");
        if (!sw_fuzz_zeroed(&m, sizeof m)) abort();
    }
    sw_trimesh_free(&m);
    free(copy);
    return 0;
}
