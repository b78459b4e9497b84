/* A world file (samples/worlds/, schema "sinew_world": 1) read by the host: its colliders
 * added to a sinew world, moved along their keys every step, and drawn. */
#ifndef SW_VIEWER_WORLD_H
#define SW_VIEWER_WORLD_H

#include <sinew/sinew_world.h>

#define VW_WORLD_MAX_KEYS 64
#define VW_WORLD_MAX_COLLIDERS 32
#define VW_WORLD_MAX_HULL 100 /* points: the viewer draws a hull by brute force */

typedef struct vw_key {
    double frame;
    float position[3], rotation[4];
} vw_key;

typedef struct vw_collider {
    sinew_collider_def def;
    sinew_collider_id id;
    vw_key keys[VW_WORLD_MAX_KEYS];
    int nkeys;
    sinew_transform now; /* where it is */
    int held;            /* dragged by the mouse or a script: at `hold`, off its keys */
    float hold[3];
    float *shape; /* a hull's points or a mesh's vertices, as the world file gives them */
    uint32_t *shape_tris;
    float *local;     /* the drawn mesh in the collider's frame: 3 nverts */
    float *pos, *nrm; /* placed */
    uint32_t *tris;
    int32_t nverts, ntris;
} vw_collider;

typedef struct vw_world {
    sinew_world *world;
    vw_collider col[VW_WORLD_MAX_COLLIDERS];
    int ncol;
    double period_s; /* the keys' span, looped */
    int rest_pose;   /* "pose": "rest": the character holds its rest pose */
} vw_world;

/* Reads FILE and builds the sinew world; 0 and a message on bad input. */
int vw_world_load(const char *path, vw_world *w, char *err, size_t errlen);
/* Places every collider at time t (seconds; 30 key frames a second, looped); a held one
 * stays where it is held. */
void vw_world_move(vw_world *w, double t);
/* Holds collider i at position p (its rotation kept) from now on. */
void vw_world_hold(vw_world *w, int i, const float p[3]);
/* The collider's position now. */
void vw_world_position(const vw_world *w, int i, float p[3]);
void vw_world_free(vw_world *w);

#endif
