#include "world_scene.h"

#include <stdlib.h>
#include <string.h>

sinew_result sw_world_scene_load(const char *path, sw_world_scene *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    sinew_result r = sw_world_file_read(path, &out->file, err);
    if (r != SINEW_OK) return r;
    sinew_world_def wd = sinew_world_def_default();
    wd.max_colliders = out->file.ncolliders > 0 ? (uint32_t)out->file.ncolliders : 1;
    out->ids = calloc((size_t)wd.max_colliders, sizeof *out->ids);
    if (!out->ids) {
        sw_world_scene_free(out);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    if ((r = sinew_world_create(&wd, &out->world)) != SINEW_OK) {
        sw_world_scene_free(out);
        return sw_error_set(err, r, "%s: cannot create the world", path);
    }
    for (int32_t i = 0; i < out->file.ncolliders; ++i) {
        const sw_world_collider_spec *c = &out->file.colliders[i];
        if ((r = sinew_world_add_collider(out->world, &c->def, &out->ids[i])) != SINEW_OK) {
            sw_error_set(err, r, "%s: collider \"%s\" (#%d): rejected by the world: %s", path,
                         c->name, (int)i, sinew_result_string(r));
            sw_world_scene_free(out);
            return r;
        }
    }
    return SINEW_OK;
}

sinew_result sw_world_scene_at(sw_world_scene *s, int frame, sw_error *err) {
    for (int32_t i = 0; i < s->file.ncolliders; ++i) {
        sinew_transform t;
        sw_world_collider_at(&s->file.colliders[i], frame, &t);
        sinew_result r = sinew_world_set_collider_transform(s->world, s->ids[i], &t);
        if (r != SINEW_OK)
            return sw_error_set(err, r, "%s: collider \"%s\" (#%d): bad transform at frame %d",
                                s->file.path, s->file.colliders[i].name, (int)i, frame);
    }
    return SINEW_OK;
}

int sw_world_scene_rest_frames(const sw_world_scene *s) {
    return s->file.frames > 0 ? s->file.frames : sw_world_file_last_key_frame(&s->file) + 10;
}

double *sw_world_scene_poses(const sw_world_scene *s, const double *clip_T, int clip_frames,
                             int nbones, int frames, int *nframes) {
    size_t per = (size_t)12 * nbones;
    int n = s->file.rest_pose ? (frames > 0 ? frames : sw_world_scene_rest_frames(s))
                              : (frames > 0 && frames < clip_frames ? frames : clip_frames);
    *nframes = 0;
    if (n <= 0) return NULL;
    double *T = malloc((size_t)n * per * sizeof(double));
    if (!T) return NULL;
    for (int f = 0; f < n; ++f) {
        double *Tf = T + (size_t)f * per;
        if (!s->file.rest_pose) {
            memcpy(Tf, clip_T + (size_t)f * per, per * sizeof(double));
            continue;
        }
        memset(Tf, 0, per * sizeof(double));
        for (int b = 0; b < nbones; ++b)
            Tf[12 * b] = Tf[12 * b + 4] = Tf[12 * b + 8] = 1;
    }
    *nframes = n;
    return T;
}

void sw_world_scene_free(sw_world_scene *s) {
    sinew_world_destroy(s->world);
    free(s->ids);
    sw_world_file_free(&s->file);
    memset(s, 0, sizeof *s);
}
