/* libFuzzer harness for the complementary-dynamics bone animation reader
 * (sw_parse_cd_anim; STYLE.md §9: a fuzz harness for every loader). tests/CMakeLists.txt
 * builds it with clang when clang has libFuzzer and runs it for a few seconds on
 * tests/fuzz/corpus/cd_anim as the test fuzz_cd_anim; tools/scripts/run-fuzz.sh runs it for
 * longer. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_cd_anim.c \
 *     precompute/io/cd_anim_io.c precompute/io/sw_mesh.c runtime/core/sw_error.c \
 *     -lm -o build-fuzz-cd-anim
 *   cp -r tests/fuzz/corpus/cd_anim /tmp/anim-corpus && ./build-fuzz-cd-anim /tmp/anim-corpus
 *
 * The reader needs a skeleton: every input is read against three fixed ones (1 bone; a
 * 2-bone chain; 3 bones under two roots, which takes the multi-root path), so the file's
 * bone count picks the one that matches and the corpus holds plain animation files. A
 * failure must name the text and leave the clip zeroed; an accepted clip holds finite
 * rigid transforms (rotation parts orthonormal). */
#include <math.h>

#include "clip_io.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static double joints[] = {0, 0, 0, 0, 1, 0, 0, 2, 0, 1, 0, 0, 1, 1, 0};
static int32_t bones1[] = {0, 1}, parent1[] = {-1};
static int32_t bones2[] = {0, 1, 1, 2}, parent2[] = {-1, 0};
static int32_t bones3[] = {0, 1, 1, 2, 3, 4}, parent3[] = {-1, 0, -1};

static void check_clip(const sw_clip *c, int32_t nbones) {
    if (c->nbones != nbones || c->nframes < 1 || !c->T || !(c->fps == 30.0)) abort();
    for (int64_t k = 0; k < (int64_t)c->nframes * nbones; ++k) {
        const double *T = c->T + 12 * k;
        for (int i = 0; i < 12; ++i)
            if (!isfinite(T[i])) abort();
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double dot =
                    T[3 * i] * T[3 * j] + T[3 * i + 1] * T[3 * j + 1] + T[3 * i + 2] * T[3 * j + 2];
                if (!(fabs(dot - (i == j)) < 1e-6)) abort();
            }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const sw_skeleton skels[3] = {{2, joints, 1, bones1, parent1},
                                  {3, joints, 2, bones2, parent2},
                                  {5, joints, 3, bones3, parent3}};
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    for (int k = 0; k < 3; ++k) {
        sw_clip c;
        sw_error err;
        sw_error_clear(&err);
        sinew_result rc = sw_parse_cd_anim(copy, size, "fuzz.txt", &skels[k], 30.0, &c, &err);
        if (rc == SINEW_OK) {
            check_clip(&c, skels[k].nbones);
        } else {
            sw_fuzz_check_error(rc, &err, "fuzz.txt");
            if (!sw_fuzz_zeroed(&c, sizeof c)) abort();
        }
        sw_clip_free(&c);
    }
    free(copy);
    return 0;
}
