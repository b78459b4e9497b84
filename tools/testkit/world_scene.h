/* A world file made live for the tools (sinew-fullsim, sinew-bench): the sinew_world
 * with its colliders, their keyframed motion applied frame by frame, and the motion of
 * the character the scene asks for (its clip, or its rest pose while the colliders move). */
#ifndef SW_WORLD_SCENE_H
#define SW_WORLD_SCENE_H

#include "sinew/sinew_world.h"
#include "sw_error.h"
#include "world_io.h"

typedef struct sw_world_scene {
    sw_world_file file;
    sinew_world *world;
    sinew_collider_id *ids; /* file.ncolliders */
} sw_world_scene;

/* Reads the world file and builds its world (colliders at frame 0). An error names the
 * file and the collider. */
sinew_result sw_world_scene_load(const char *path, sw_world_scene *out, sw_error *err);

/* Moves every collider to its keyframed transform at `frame` (no rebuild). */
sinew_result sw_world_scene_at(sw_world_scene *s, int frame, sw_error *err);

/* The frames the scene runs for a character at rest: the file's "frames", else the
 * last key frame + 10. */
int sw_world_scene_rest_frames(const sw_world_scene *s);

/* The character's pose at every frame of the scene (12 doubles per bone each, malloc'd,
 * *nframes set): its clip's frames when the file's "pose" is "clip" (at most `frames`
 * of them when frames > 0), else the rest pose (identity transforms) for `frames` frames
 * (0: sw_world_scene_rest_frames). NULL when out of memory or the clip is empty. */
double *sw_world_scene_poses(const sw_world_scene *s, const double *clip_T, int clip_frames,
                             int nbones, int frames, int *nframes);

void sw_world_scene_free(sw_world_scene *s);

#endif
