/* libFuzzer harness for the viewer's world-file reader (samples/viewer/world.c, STYLE.md
 * §9: a fuzz harness for every loader). The viewer reads world files as a host does, with
 * cJSON and the public sinew_world.h, not through the bake's reader (fuzz_world_io), so
 * its own JSON, hull and OBJ reading is fuzzed here. tests/CMakeLists.txt builds it with
 * clang and the runtime's sources and runs it for a few seconds on
 * tests/fuzz/corpus/view_world as the test fuzz_view_world.
 *
 * An input is a world file, optionally followed by a NUL byte and the text of an OBJ that
 * the world may name as "m.obj" (the seeds: samples/worlds, the mesh collider's file
 * renamed so). Both are written to a folder of the process's own, as a user's files would
 * be. A world that loads is moved through its keys; every collider must stay finite where
 * it is placed and drawn. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "world.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], world_path[96], obj_path[96];

static int write_file(const char *path, const uint8_t *p, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(p, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

static void check_placed(const vw_world *w) {
    for (int i = 0; i < w->ncol; ++i) {
        const vw_collider *c = &w->col[i];
        for (int k = 0; k < 3; ++k)
            if (!isfinite(c->now.position[k])) abort();
        float n = 0;
        for (int k = 0; k < 4; ++k)
            n += c->now.rotation[k] * c->now.rotation[k];
        if (!(n > 0.5f && n < 2.0f)) abort(); /* a rotation (keys are normalised-lerped) */
        for (int32_t v = 0; v < 3 * c->nverts; ++v)
            if (!isfinite(c->pos[v])) abort();
        for (int32_t t = 0; t < 3 * c->ntris; ++t)
            if (c->tris[t] >= (uint32_t)c->nverts) abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/fuzz_view_world.%ld", (long)getpid());
        snprintf(world_path, sizeof world_path, "%s/w.json", dir);
        snprintf(obj_path, sizeof obj_path, "%s/m.obj", dir);
        char cmd[96];
        snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
        if (system(cmd) != 0) abort();
    }
    const uint8_t *nul = memchr(data, 0, size);
    size_t nworld = nul ? (size_t)(nul - data) : size;
    unlink(obj_path);
    if (!write_file(world_path, data, nworld)) abort();
    if (nul && !write_file(obj_path, nul + 1, size - nworld - 1)) abort();
    vw_world w;
    char err[256];
    err[0] = 0;
    if (!vw_world_load(world_path, &w, err, sizeof err)) {
        if (!err[0] || w.world || w.ncol) abort(); /* a message, and nothing left behind */
        return 0;
    }
    const double times[4] = {0.0, 0.51, 0.5 * w.period_s, w.period_s + 2.0};
    for (int k = 0; k < 4; ++k) {
        vw_world_move(&w, times[k]);
        check_placed(&w);
    }
    vw_world_free(&w);
    return 0;
}
