/* libFuzzer harness for the world-file reader (STYLE.md §9: a fuzz harness for every
 * loader). tests/CMakeLists.txt builds it with clang when clang has libFuzzer and runs it
 * for a few seconds on tests/fuzz/corpus/world (the sample worlds and the schema's
 * example) as the test fuzz_world_io. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io tests/fuzz/fuzz_world_io.c \
 *     precompute/io/world_io.c precompute/io/world_motion.c precompute/io/obj_io.c \
 *     precompute/io/text_reader.c precompute/io/sw_mesh.c runtime/core/sw_error.c \
 *     -lcjson -lm -o build-fuzz-world
 *   cp -r tests/fuzz/corpus/world /tmp/world-corpus && ./build-fuzz-world /tmp/world-corpus
 *
 * The input is copied into a buffer of exactly its size (no NUL after it), so that ASan
 * reports any read past the text. There is no folder (base_dir NULL): mesh colliders are
 * rejected and no file is opened. An accepted world is checked for the reader's promises
 * and every collider's motion is evaluated. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "world_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(const sw_world_file *w) {
    if (w->ncolliders < 0 || w->ncolliders > SW_WORLD_MAX_COLLIDERS) abort();
    for (int32_t i = 0; i < w->ncolliders; ++i) {
        const sw_world_collider_spec *c = &w->colliders[i];
        if (!memchr(c->name, 0, sizeof c->name) || !c->name[0]) abort();
        if (c->def.shape == SINEW_SHAPE_MESH) abort(); /* no folder: no meshes */
        if (c->def.shape == SINEW_SHAPE_HULL &&
            (c->def.points != c->points || c->def.point_count < 4 ||
             c->def.point_count > SW_WORLD_MAX_HULL_POINTS))
            abort();
        for (uint32_t k = 0; k < 3 * c->def.point_count; ++k)
            if (!isfinite(c->points[k])) abort();
        if (c->nkeys < 0 || c->nkeys > SW_WORLD_MAX_KEYS) abort();
        for (int32_t k = 1; k < c->nkeys; ++k)
            if (c->keys[k].frame <= c->keys[k - 1].frame) abort();
        double last = c->nkeys ? c->keys[c->nkeys - 1].frame : 0;
        const double frames[4] = {-1.0, 0.5, 0.5 * last + 0.25, last + 1.0};
        for (int f = 0; f < 4; ++f) {
            sinew_transform t;
            sw_world_collider_at(c, frames[f], &t);
            double n = 0;
            for (int k = 0; k < 4; ++k)
                n += (double)t.rotation[k] * t.rotation[k];
            if (!(fabs(n - 1.0) < 1e-4)) abort();
            for (int k = 0; k < 3; ++k)
                if (!isfinite(t.position[k])) abort();
        }
    }
    (void)sw_world_file_last_key_frame(w);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = malloc(size ? size : 1);
    if (!copy) return 0;
    memcpy(copy, data, size);
    sw_world_file w;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_world_file_parse(copy, size, NULL, "fuzz.json", &w, &err);
    if (rc == SINEW_OK) {
        check(&w);
    } else if (err.code != rc || strncmp(err.msg, "fuzz.json: ", 11) != 0 || w.colliders) {
        abort(); /* every failure leaves a message naming the file and a zeroed output */
    }
    sw_world_file_free(&w);
    free(copy);
    return 0;
}
