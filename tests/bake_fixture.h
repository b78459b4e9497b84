/* A small character baked in-process and loaded as a blob, for runtime tests. */
#ifndef SW_BAKE_FIXTURE_H
#define SW_BAKE_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "blob_load.h"
#include "blob_write.h"
#include "mat3.h"
#include "samples.h"

typedef struct {
    sw_character ch;
    sw_bake_result res;
    void *data;
    size_t size;
    sinew_blob *blob;
} bake_fixture;

/* Bakes the character f->ch with bake parameters p, writes and loads the blob. 1 on
 * success. sw_bake bakes a character's only clip split by heldout_fraction, as it always
 * has: the fixtures' and the golden tests' blobs are the split's, bit for bit (the blob
 * sinew-bake ships from such a clip is baked again on the whole clip,
 * sw_bake_ships_whole_clip; --ship-split is this one). */
static inline int bake_fixture_bake(bake_fixture *f, const sw_bake_params *p) {
    sw_error err;
    if (sw_bake(&f->ch, p, &f->res, &err) != SINEW_OK) {
        fprintf(stderr, "bake failed: %s\n", err.msg);
        return 0;
    }
    if (sw_blob_write_memory(&f->res.view, &f->data, &f->size, &err) != SINEW_OK) return 0;
    sinew_blob_def d = sinew_blob_def_default();
    d.data = f->data;
    d.data_size = f->size;
    return sinew_blob_load(&d, &f->blob) == SINEW_OK;
}

/* Bakes `sample` at about `tets` tets with a clip of `frames` frames and bake parameters
 * p (bake_fixture_bake). 1 on success. */
static inline int bake_fixture_make_params(bake_fixture *f, const char *sample, int tets,
                                           int frames, const sw_bake_params *p) {
    sw_error err;
    memset(f, 0, sizeof *f);
    if (sw_sample_make(sample, tets, frames, &f->ch, &err) != SINEW_OK) return 0;
    return bake_fixture_bake(f, p);
}

/* The fixture's quick bake parameters: 3 samples a joint sweep, 8 clip frames, `threads`
 * bake threads, the clip's return path when return_path is set. */
static inline sw_bake_params bake_fixture_params(int return_path, int threads) {
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3;
    p.max_train_frames = 8;
    p.threads = threads;
    p.return_path = return_path;
    return p;
}

/* bake_fixture_make_params with bake_fixture_params(return_path, threads). */
static inline int bake_fixture_make_threads(bake_fixture *f, const char *sample, int tets,
                                            int frames, int return_path, int threads) {
    sw_bake_params p = bake_fixture_params(return_path, threads);
    return bake_fixture_make_params(f, sample, tets, frames, &p);
}

/* bake_fixture_make_threads on 2 threads. */
static inline int bake_fixture_make(bake_fixture *f, const char *sample, int tets, int frames,
                                    int return_path) {
    return bake_fixture_make_threads(f, sample, tets, frames, return_path, 2);
}

static inline void bake_fixture_free(bake_fixture *f) {
    sinew_blob_destroy(f->blob);
    free(f->data);
    sw_bake_result_free(&f->res);
    sw_character_free(&f->ch);
    memset(f, 0, sizeof *f);
}

/* Pose f of the fixture's clip as float transforms (12 per bone) into out. */
static inline void bake_fixture_pose(const bake_fixture *f, int frame, float *out) {
    const double *T = f->ch.clip.T + (size_t)(frame % f->ch.clip.nframes) * 12 * f->ch.skel.nbones;
    for (int i = 0; i < 12 * f->ch.skel.nbones; ++i)
        out[i] = (float)T[i];
}
/* The 3-bone finger at about `tets` tets without its clip, and a joint range of `nframes`
 * frames written to range_T (12 * 3 doubles a frame) in which bone b turns deg[3 f + b]
 * degrees about z at frame f. 1 on success (the caller frees the character), 0 with the
 * character freed. */
static inline int finger_range_fixture(sw_character *c, int tets, int nframes, const double *deg,
                                       double *range_T) {
    sw_error err;
    if (sw_sample_make("finger", tets, 8, c, &err) != SINEW_OK) return 0;
    c->clip.nframes = 0;
    if (c->skel.nbones != 3) {
        sw_character_free(c);
        return 0;
    }
    static const double z[3] = {0, 0, 1};
    double local[9 * 3];
    for (int f = 0; f < nframes; ++f) {
        for (int32_t b = 0; b < 3; ++b)
            sw_m3_axis_angle(z, deg[3 * f + b] * 0.017453292519943295, local + 9 * b);
        sw_forward_kinematics(&c->skel, local, NULL, range_T + (size_t)f * 12 * 3);
    }
    return 1;
}

#endif
