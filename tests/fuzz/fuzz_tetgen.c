/* libFuzzer harness for the TetGen .node/.ele reader (sw_parse_tetgen; STYLE.md §9: a
 * fuzz harness for every loader). tests/CMakeLists.txt builds it with clang when clang has
 * libFuzzer and runs it for a few seconds on tests/fuzz/corpus/tetgen as the test
 * fuzz_tetgen; tools/scripts/run-fuzz.sh runs it for longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_tetgen.c \
 *     precompute/io/tetgen_io.c precompute/io/medit_io.c precompute/io/text_reader.c \
 *     precompute/io/sw_mesh.c runtime/core/sw_error.c -lm -o build-fuzz-tetgen
 *   cp -r tests/fuzz/corpus/tetgen /tmp/tetgen-corpus && ./build-fuzz-tetgen /tmp/tetgen-corpus
 *
 * One input holds both files: the .node text, a line "=====", then the .ele text (no
 * such line: all of it is the .node and the .ele is empty). Each part is copied into a
 * buffer of exactly its size. A failure must name one of the two texts and leave the
 * output zeroed; an accepted mesh must pass sw_tetmesh_validate with finite volumes. */
#include <math.h>

#include "fuzz_check.h"
#include "mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define SEP "\n=====\n"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    size_t node_len = size, ele_at = size;
    const size_t k = sizeof SEP - 1;
    for (size_t i = 0; i + k <= size; ++i)
        if (memcmp(data + i, SEP, k) == 0) {
            node_len = i + 1; /* the .node keeps its last newline */
            ele_at = i + k;
            break;
        }
    char *node = sw_fuzz_copy(data, node_len);
    char *ele = sw_fuzz_copy(data + ele_at, size - ele_at);
    if (node && ele) {
        sw_tetmesh m;
        sw_error err;
        sw_error_clear(&err);
        sinew_result rc =
            sw_parse_tetgen(node, node_len, "fuzz.node", ele, size - ele_at, "fuzz.ele", &m, &err);
        if (rc == SINEW_OK) {
            if (sw_tetmesh_validate(&m, 0.0, &err) != SINEW_OK) abort();
            for (int32_t t = 0; t < m.ntets; ++t) {
                const int32_t *q = m.tets + 4 * (size_t)t;
                double v = sw_tet_signed_volume(m.X + 3 * (size_t)q[0], m.X + 3 * (size_t)q[1],
                                                m.X + 3 * (size_t)q[2], m.X + 3 * (size_t)q[3]);
                if (!isfinite(v)) abort();
            }
        } else {
            if (strncmp(err.msg, "fuzz.node", 9) == 0)
                sw_fuzz_check_error(rc, &err, "fuzz.node");
            else
                sw_fuzz_check_error(rc, &err, "fuzz.ele");
            if (!sw_fuzz_zeroed(&m, sizeof m)) abort();
        }
        sw_tetmesh_free(&m);
    }
    free(node);
    free(ele);
    return 0;
}
