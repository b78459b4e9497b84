/* libFuzzer harness for the libigl .dmat reader, ASCII and binary (sw_parse_dmat), and the
 * skin-weight reader built on it (sw_parse_weights; STYLE.md §9: a fuzz harness for every
 * loader). tests/CMakeLists.txt builds it with clang when clang has libFuzzer and runs it
 * for a few seconds on tests/fuzz/corpus/dmat as the test fuzz_dmat; tools/scripts/run-fuzz.sh
 * runs it for longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_dmat.c \
 *     precompute/io/dmat_io.c precompute/io/text_reader.c precompute/io/sw_mesh.c \
 *     runtime/core/sw_error.c -lm -o build-fuzz-dmat
 *   cp -r tests/fuzz/corpus/dmat /tmp/dmat-corpus && ./build-fuzz-dmat /tmp/dmat-corpus
 *
 * A failure must name the text and leave the outputs zeroed. An accepted matrix has
 * finite values (data NULL exactly when it is empty). The same text is then read as the
 * weights of that many vertices and bones: accepted rows are >= 0 and sum to 1. */
#include <math.h>

#include "fuzz_check.h"
#include "mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_weights(const char *copy, size_t size, int32_t rows, int32_t cols) {
    sw_weights w;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_parse_weights(copy, size, "fuzz.dmat", rows, cols, &w, &err);
    if (rc != SINEW_OK) {
        sw_fuzz_check_error(rc, &err, "fuzz.dmat");
        if (!sw_fuzz_zeroed(&w, sizeof w)) abort();
        return;
    }
    if (w.nverts != rows || w.nbones != cols) abort();
    for (int32_t v = 0; v < rows; ++v) {
        double sum = 0.0;
        for (int32_t b = 0; b < cols; ++b) {
            double x = w.w[(size_t)v * cols + b];
            if (!(x >= 0.0) || !(x <= 1.0)) abort();
            sum += x;
        }
        if (!(fabs(sum - 1.0) < 1e-9)) abort();
    }
    sw_weights_free(&w);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    int32_t rows, cols;
    double *d;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_parse_dmat(copy, size, "fuzz.dmat", &rows, &cols, &d, &err);
    if (rc == SINEW_OK) {
        if (rows < 0 || cols < 0 || (int64_t)rows * cols > INT32_MAX) abort();
        if ((rows * cols == 0) != (d == NULL)) abort();
        for (int64_t i = 0; i < (int64_t)rows * cols; ++i)
            if (!isfinite(d[i])) abort();
        free(d);
        check_weights(copy, size, rows, cols);
    } else {
        sw_fuzz_check_error(rc, &err, "fuzz.dmat");
        if (rows || cols || d) abort();
    }
    free(copy);
    return 0;
}
