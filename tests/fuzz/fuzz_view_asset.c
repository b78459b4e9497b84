/* libFuzzer harness for the viewer's import of a character file (samples/viewer/asset.c,
 * STYLE.md §9: a fuzz harness for every loader): assimp reads the file, then the viewer
 * maps it onto a blob by bone names and the blob's output map, and builds its clips. The
 * bake's own import is fuzz_scene_import; this is the host's, as an engine would write it.
 * tests/CMakeLists.txt builds it with clang and the runtime's sources and runs it for a few
 * seconds on tests/fuzz/corpus/view_asset as the test fuzz_view_asset.
 *
 * The blob is tests/blob_synth.h's synthetic character with its asset description, every
 * output vertex given a source (the fixture leaves the first without one). The seeds
 * (2.7 KB each, written by make_view_asset_seed.py): four_bones.glb, a file that blob maps
 * onto (its four joints carry the fixture's bone names and bind poses, its rigid prop and
 * skinned mesh are the fixture's two source meshes); no_inverse_bind.glb and
 * infinite_vertex.glb, what this harness found (assimp crashed on the first inside the
 * viewer; the second was accepted), refused now. The FBX seeds (make_fbx_seed.py, Blender's
 * exporter): four_bones.fbx, the same character, which the blob maps onto too (the FBX
 * unit, the mesh node's placement and the weld); two_bones.fbx, a character that is not
 * the blob's; fbx_assert.fbx, a file assimp aborts on (assimp_trial.h). An input is
 * written to a folder of the process's own as a user's file would be, named .fbx or .glb
 * by its first bytes. A refused file must leave a message and
 * nothing behind; an accepted one must keep the importer's promises (indices in range,
 * finite rest positions, weights summing to 1), and its clips are posed and skinned. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SINEW_SOURCE_DIR "." /* (blob_synth.h's seed files: unused here) */
#include "blob_synth.h"
#include "fuzz_assimp.h"
#include "viewer.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int sw_test_failed_, sw_test_skipped_; /* (blob_synth.h's checks, unused here) */

static sinew_blob *blob;
static char dir[64], path[96], path_fbx[96];

static void setup(void) {
    static fixture f;
    static asset_fixture a;
    fixture_init(&f, 11);
    fixture_add_asset(&f, &a);
    a.output_source[0] = 0, a.output_source[1] = 0;
    size_t n = 0;
    uint8_t *bytes = write_fixture(&f, &n);
    sinew_blob_def d = sinew_blob_def_default();
    d.data = bytes, d.data_size = n;
    if (!bytes || sinew_blob_load(&d, &blob) != SINEW_OK) abort();
    snprintf(dir, sizeof dir, "/tmp/fuzz_view_asset.%ld", (long)getpid());
    snprintf(path, sizeof path, "%s/a.glb", dir);
    snprintf(path_fbx, sizeof path_fbx, "%s/a.fbx", dir);
    char cmd[96];
    snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
    if (system(cmd) != 0) abort();
}

static void check_mapped(const vw_asset *a) {
    if (a->nbones != (int32_t)sinew_blob_bone_count(blob)) abort();
    if (a->nverts != (int32_t)sinew_blob_surface_vertex_count(blob)) abort();
    for (int32_t v = 0; v < a->nverts; ++v) {
        float sum = 0;
        for (int k = 0; k < 4; ++k) {
            if (a->wbone[4 * v + k] < 0 || a->wbone[4 * v + k] >= a->nbones) abort();
            if (!(a->wgt[4 * v + k] >= 0)) abort();
            sum += a->wgt[4 * v + k];
        }
        if (!(fabsf(sum - 1) < 1e-4f)) abort();
        for (int k = 0; k < 3; ++k)
            if (!isfinite(a->rest[3 * v + k])) abort();
        if (a->weld[v] < 0 || a->weld[v] > v) abort();
    }
    for (int32_t t = 0; t < 3 * a->ntris; ++t)
        if (a->tris[t] >= (uint32_t)a->nverts) abort();
}

/* Every clip posed at a few times and skinned both ways: what the viewer draws. */
static void play(const vw_asset *a) {
    float T[12 * VW_MAX_BONES], pos[3 * 64], nrm[3 * 64];
    if (a->nverts > 64) abort();
    for (int c = 0; c < a->nclips; ++c) {
        const double d = a->clip_duration[c], times[4] = {0.0, 0.37, d, 2.5 * d + 0.1};
        for (int k = 0; k < 4; ++k)
            if (a->pose(a, c, times[k], T)) {
                vw_skin(a, T, k & 1, pos, nrm);
                vw_normals(pos, a->nverts, a->tris, a->ntris, a->weld, nrm);
            }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (!blob) setup();
    const char *file = !strcmp(sw_fuzz_assimp_hint(data, size), "fbx") ? path_fbx : path;
    FILE *f = fopen(file, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) abort();
    vw_asset a;
    char err[512];
    err[0] = 0;
    if (!vw_asset_import(file, blob, &a, err, sizeof err)) {
        if (!err[0] || a.impl || a.rest || a.nverts) abort(); /* a message, nothing behind */
        return 0;
    }
    check_mapped(&a);
    play(&a);
    vw_asset_free(&a);
    return 0;
}
