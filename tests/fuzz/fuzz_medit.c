/* libFuzzer harness for the Medit .mesh reader (sw_parse_medit; STYLE.md §9: a fuzz
 * harness for every loader). tests/CMakeLists.txt builds it with clang when clang has
 * libFuzzer and runs it for a few seconds on tests/fuzz/corpus/medit as the test
 * fuzz_medit; tools/scripts/run-fuzz.sh runs it for longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iruntime/math -Iprecompute/io \
 *     tests/fuzz/fuzz_medit.c precompute/io/medit_io.c precompute/io/mesh_surface.c \
 *     precompute/io/mesh_quality.c precompute/io/text_reader.c precompute/io/sw_mesh.c \
 *     runtime/core/sw_error.c -lm -o build-fuzz-medit
 *   cp -r tests/fuzz/corpus/medit /tmp/medit-corpus && ./build-fuzz-medit /tmp/medit-corpus
 *
 * A failure must name the text and leave the output zeroed. An accepted mesh must pass
 * sw_tetmesh_validate with finite positive volumes, and is handed to the surface
 * extraction and the quality report (what the bake does next). */
#include <math.h>

#include "fuzz_check.h"
#include "mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_mesh(const sw_tetmesh *m) {
    sw_error err;
    if (sw_tetmesh_validate(m, 0.0, &err) != SINEW_OK) abort();
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *q = m->tets + 4 * (size_t)t;
        double v = sw_tet_signed_volume(m->X + 3 * (size_t)q[0], m->X + 3 * (size_t)q[1],
                                        m->X + 3 * (size_t)q[2], m->X + 3 * (size_t)q[3]);
        if (!isfinite(v) || !(v > 0)) abort();
    }
    sw_surface s;
    if (sw_tetmesh_surface(m, &s, &err) == SINEW_OK) {
        for (int32_t i = 0; i < 3 * s.ntris; ++i)
            if (s.tris[i] < 0 || s.tris[i] >= m->nverts) abort();
        sw_surface_free(&s);
    }
    sw_quality q;
    sw_tetmesh_quality(m, 0.0, &q);
    if (q.ntets != m->ntets) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    sw_tetmesh m;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_parse_medit(copy, size, "fuzz.mesh", &m, &err);
    if (rc == SINEW_OK) {
        check_mesh(&m);
    } else {
        sw_fuzz_check_error(rc, &err, "fuzz.mesh");
        if (!sw_fuzz_zeroed(&m, sizeof m)) abort();
    }
    sw_tetmesh_free(&m);
    free(copy);
    return 0;
}
