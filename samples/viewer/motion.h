/* What a character plays, as an engine's animation system would drive it: a clip, a
 * cross-fade into a second clip (local transforms blended, rotations by slerp), and root
 * motion (the root bone's ground translation and heading taken out of the pose and given
 * to the actor, which also walks and turns on its own for a clip animated in place). */
#ifndef SW_VIEWER_MOTION_H
#define SW_VIEWER_MOTION_H

#include "viewer.h"

typedef struct vw_motion {
    int clip, fade_clip;       /* fade_clip -1: no cross-fade */
    double fade_at, fade_time; /* seconds of the simulation clock */
    int32_t root_bone;         /* -1: no root motion */
    double root_bind[3];       /* the root bone's bind position */
    double walk, turn;         /* the actor's own motion: units a second along +z, rad/s */
} vw_motion;

/* A rigid motion of the ground plane: a heading (radians about +y, 0 facing +z) and a
 * position (x, z). */
typedef struct vw_planar {
    double x, z, yaw;
} vw_planar;

/* The pose at clip time t (the clip's own phase added by the caller) and simulation time
 * clock (which drives the fade), root motion taken out when there is a root bone. */
int vw_motion_pose(const vw_asset *a, const vw_motion *m, double t, double clock, float *out);
/* Moves the actor from clip time t0 to t1 (clock1: the simulation time at t1): the root
 * motion the pose gave up between them, then the actor's own walk and turn. */
void vw_motion_advance(const vw_asset *a, const vw_motion *m, double t0, double t1, double clock1,
                       vw_planar *actor);
/* The actor's transform for sinew_instance_set_actor (12 doubles, row-major 3x3 then the
 * translation), and a point or direction (w 0) through it. */
void vw_planar_matrix(const vw_planar *p, double out[12]);
void vw_planar_apply(const vw_planar *p, float *v, int w);

#endif
