/* libFuzzer harness for the libigl .tgf skeleton reader (sw_parse_tgf; STYLE.md §9: a
 * fuzz harness for every loader). tests/CMakeLists.txt builds it with clang when clang has
 * libFuzzer and runs it for a few seconds on tests/fuzz/corpus/tgf as the test fuzz_tgf;
 * tools/scripts/run-fuzz.sh runs it for longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_tgf.c \
 *     precompute/io/tgf_io.c precompute/io/text_reader.c precompute/io/sw_mesh.c \
 *     runtime/core/sw_error.c -lm -o build-fuzz-tgf
 *   cp -r tests/fuzz/corpus/tgf /tmp/tgf-corpus && ./build-fuzz-tgf /tmp/tgf-corpus
 *
 * A failure must name the text and leave the output zeroed. An accepted skeleton has
 * finite joints, in-range bones whose parent ends where they start, no parent cycle; with
 * at least one bone (and at most SW_MAX_BONES) it passes sw_skeleton_validate and forward
 * kinematics of the rest pose gives finite transforms. */
#include <math.h>

#include "fuzz_check.h"
#include "mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_skeleton(const sw_skeleton *s) {
    if (s->njoints < 1 || s->nbones < 0 || !s->joints) abort();
    for (int64_t i = 0; i < 3 * (int64_t)s->njoints; ++i)
        if (!isfinite(s->joints[i])) abort();
    for (int32_t b = 0; b < s->nbones; ++b) {
        int32_t h = s->bones[2 * b], t = s->bones[2 * b + 1], p = s->parent[b];
        if (h < 0 || h >= s->njoints || t < 0 || t >= s->njoints || h == t) abort();
        if (p < -1 || p >= s->nbones || (p >= 0 && s->bones[2 * p + 1] != h)) abort();
    }
    if (s->nbones < 1 || s->nbones > SW_MAX_BONES) return;
    sw_error err;
    if (sw_skeleton_validate(s, &err) != SINEW_OK) abort();
    double *local = calloc(9 * (size_t)s->nbones, sizeof(double));
    double *T = malloc(12 * (size_t)s->nbones * sizeof(double));
    if (local && T) {
        for (int32_t b = 0; b < s->nbones; ++b)
            local[9 * b] = local[9 * b + 4] = local[9 * b + 8] = 1.0;
        sw_forward_kinematics(s, local, NULL, T);
        for (int64_t i = 0; i < 12 * (int64_t)s->nbones; ++i)
            if (!isfinite(T[i])) abort();
    }
    free(local);
    free(T);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    sw_skeleton s;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_parse_tgf(copy, size, "fuzz.tgf", &s, &err);
    if (rc == SINEW_OK) {
        check_skeleton(&s);
    } else {
        sw_fuzz_check_error(rc, &err, "fuzz.tgf");
        if (!sw_fuzz_zeroed(&s, sizeof s)) abort();
    }
    sw_skeleton_free(&s);
    free(copy);
    return 0;
}
