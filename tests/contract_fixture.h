/* The step contract's character (test_step_contract.c): a blob and a clip of float poses.
 * The static build bakes it in-process (bake_fixture.h); the build against libsinew.so
 * must link nothing of the runtime but the shared library (a static copy of a sinew_
 * function in the executable would take the calls meant for libsinew.so), so it reads
 * the same blob and clip from files that contract_fixture_write wrote, and uses the
 * public API alone. */
#ifndef SW_CONTRACT_FIXTURE_H
#define SW_CONTRACT_FIXTURE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinew/sinew.h"
#include "sw_test.h"

typedef struct {
    void *data; /* the blob's bytes (owned) */
    size_t size;
    sinew_blob *blob;
    float *poses; /* frames x nb x 12 (owned) */
    uint32_t nb, ns;
    int frames;
} contract_fixture;

/* The clip's file: "SWCLIP1\0", nb and frames as uint32, then the floats. */
static const char contract_clip_magic[8] = "SWCLIP1";

static inline int contract_path(char *out, size_t n, const char *dir, const char *name) {
    int k = snprintf(out, n, "%s/%s", dir, name);
    return k > 0 && (size_t)k < n;
}

/* Writes the blob bytes and the clip into dir (which must exist). 1 on success. */
static inline int contract_fixture_save(const char *dir, const void *blob, size_t size,
                                        const float *poses, uint32_t nb, int frames) {
    char path[4096];
    FILE *fp;
    int ok = contract_path(path, sizeof path, dir, "contract.blob") && (fp = fopen(path, "wb"));
    if (!ok) return 0;
    ok = fwrite(blob, 1, size, fp) == size;
    ok = (fclose(fp) == 0) && ok;
    if (!ok || !contract_path(path, sizeof path, dir, "contract.clip") || !(fp = fopen(path, "wb")))
        return 0;
    uint32_t head[2] = {nb, (uint32_t)frames};
    size_t nf = (size_t)12 * nb * (size_t)frames;
    ok = fwrite(contract_clip_magic, 1, 8, fp) == 8 && fwrite(head, sizeof head, 1, fp) == 1 &&
         fwrite(poses, sizeof(float), nf, fp) == nf;
    return (fclose(fp) == 0) && ok;
}

static inline void contract_fixture_free(contract_fixture *f) {
    sinew_blob_destroy(f->blob);
    free(f->data);
    free(f->poses);
    memset(f, 0, sizeof *f);
}

/* Loads the blob (copied: the fixture owns its bytes) and fills the counts. 1 on
 * success. */
static inline int contract_fixture_from_bytes(contract_fixture *f) {
    sinew_blob_def d = sinew_blob_def_default();
    d.data = f->data;
    d.data_size = f->size;
    if (sinew_blob_load(&d, &f->blob) != SINEW_OK) return 0;
    f->ns = sinew_blob_surface_vertex_count(f->blob);
    return sinew_blob_bone_count(f->blob) == f->nb && f->ns > 0 && f->frames > 0;
}

/* Reads what contract_fixture_save wrote into dir. 1 on success. */
static inline int contract_fixture_load(const char *dir, contract_fixture *f) {
    char path[4096];
    size_t n = 0;
    memset(f, 0, sizeof *f);
    if (!contract_path(path, sizeof path, dir, "contract.blob") ||
        !(f->data = sw_test_read_file(path, &f->size)))
        return 0;
    unsigned char *clip = NULL;
    int ok = contract_path(path, sizeof path, dir, "contract.clip") &&
             (clip = (unsigned char *)sw_test_read_file(path, &n)) && n >= 16 &&
             memcmp(clip, contract_clip_magic, 8) == 0;
    uint32_t head[2] = {0, 0};
    if (ok) memcpy(head, clip + 8, sizeof head);
    size_t nf = (size_t)12 * head[0] * head[1];
    ok = ok && head[0] > 0 && head[1] > 0 && n == 16 + nf * sizeof(float) &&
         (f->poses = malloc(nf * sizeof(float)));
    if (ok) {
        memcpy(f->poses, clip + 16, nf * sizeof(float));
        f->nb = head[0];
        f->frames = (int)head[1];
    }
    free(clip);
    if (!ok) {
        contract_fixture_free(f);
        return 0;
    }
    return contract_fixture_from_bytes(f);
}

#endif
