/* libFuzzer harness for the assimp import (precompute/import/scene_import.h; STYLE.md §9: a
 * fuzz harness for every loader), through sw_scene_import_memory with the hint "glb", or
 * "fbx" for an input that starts as an FBX file does (two_bones.fbx, make_fbx_seed.py;
 * fbx_assert.fbx, the file assimp aborted on).
 * tests/CMakeLists.txt builds it with clang when clang has libFuzzer and runs it for a few
 * seconds on tests/fuzz/corpus/scene_import (two_bones.glb: a hand-written 4-vertex,
 * 2-joint skin with a 2-key rotation clip, 1.8 KB; painted_two_primitives.glb:
 * test_scene_paint's skin of two primitives and a rigid prop with the _SINEW_STIFFNESS
 * attribute, FLOAT and normalized UNSIGNED_BYTE, 2.4 KB) as the test fuzz_scene_import. assimp
 * itself is Debian's uninstrumented build: ASan sees our reads, not assimp's. By hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/core -Iprecompute/io -Iprecompute/import \
 *     tests/fuzz/fuzz_scene_import.c precompute/import/scene_read.c \
 *     precompute/import/scene_import.c precompute/import/scene_clip.c \
 *     precompute/import/gltf_precheck.c precompute/import/assimp_trial.c \
 *     precompute/import/gltf_attribute.c precompute/io/sw_mesh.c runtime/core/sw_error.c \
 *     -lassimp -lcjson -lm -o build-fuzz-scene
 *   cp -r tests/fuzz/corpus/scene_import /tmp/scene-corpus && ./build-fuzz-scene /tmp/scene-corpus
 *
 * An accepted character is checked for the importer's promises (counts, indices in range,
 * finite positions and transforms, weight rows of at most 4 summing to 1, parents in
 * range, a painted stiffness finite in (0, 1e6]); a failure must leave its code, a message
 * naming "memory.glb" and a zeroed result. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_assimp.h"
#include "fuzz_check.h"
#include "scene_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(const sw_imported_character *c) {
    const sw_trimesh *m = &c->render;
    int32_t nb = c->skel.nbones;
    if (m->nverts <= 0 || m->ntris < 0 || nb <= 0 || c->weights.nverts != m->nverts ||
        c->weights.nbones != nb || c->skel.njoints != 2 * nb || c->nclips < 0)
        abort();
    for (size_t i = 0; i < 3 * (size_t)m->ntris; ++i)
        if (m->tris[i] < 0 || m->tris[i] >= m->nverts) abort();
    for (size_t i = 0; i < 3 * (size_t)m->nverts; ++i)
        if (!isfinite(m->X[i])) abort();
    for (int32_t v = 0; v < m->nverts; ++v) {
        double s = 0;
        int nz = 0;
        for (int32_t b = 0; b < nb; ++b) {
            double w = c->weights.w[(size_t)v * nb + b];
            if (!(w >= 0)) abort();
            s += w, nz += w > 0;
        }
        if (nz < 1 || nz > 4 || fabs(s - 1) > 1e-9) abort();
    }
    for (int32_t b = 0; b < nb; ++b)
        if (c->skel.parent[b] < -1 || c->skel.parent[b] >= b) abort();
    for (int32_t v = 0; c->render_stiffness && v < m->nverts; ++v)
        if (!(c->render_stiffness[v] > 0 && c->render_stiffness[v] <= 1e6)) abort();
    for (int32_t i = 0; i < c->nclips; ++i) {
        const sw_clip *k = &c->clips[i].clip;
        if (k->nbones != nb || k->nframes < 1 || !memchr(c->clips[i].name, 0, 64)) abort();
        for (size_t j = 0; j < 12 * (size_t)nb * k->nframes; ++j)
            if (!isfinite(k->T[j])) abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *copy = sw_fuzz_copy(data, size);
    if (!copy) return 0;
    sw_imported_character c;
    sw_error err;
    sw_error_clear(&err);
    const sw_import_options o = {.fps = 10};
    const char *hint = sw_fuzz_assimp_hint(data, size);
    sinew_result rc = sw_scene_import_memory(copy, size, hint, &o, &c, &err);
    char name[16];
    snprintf(name, sizeof name, "memory.%s", hint);
    if (rc == SINEW_OK)
        check(&c);
    else if (!sw_fuzz_zeroed(&c, sizeof c))
        abort();
    else
        sw_fuzz_check_error(rc, &err, name);
    sw_imported_character_free(&c);
    free(copy);
    return 0;
}
