/* Where the character is must not matter (DESIGN.md §3): two instances of one blob play
 * one clip, the second carried by a motion of the whole pose, and the second's surface is
 * compared with the first's carried by the same motion. What can carry it:
 *   SW_MOVE_RIGID    one rigid motion G (rotation about any axis, a translation) applied
 *                    to every bone transform, constant over the clip
 *   SW_MOVE_TURNING  G changing every frame (turning about one axis and walking away)
 *   SW_MOVE_ACTOR    G and a uniform scale as the actor's transform
 *                    (sinew_instance_set_actor), the bones in the actor's frame: the
 *                    output surface, in the actor's frame, must be the first's itself
 *   SW_MOVE_SCALE    a uniform scale s on every bone (s R_b, s t_b): s times the first's
 * The error is the largest distance of an output vertex from where it should be, over
 * every frame, as a share of the character's size (its rest bounding-box diagonal). Used
 * by sinew-invariance and test_rigid_invariance; every instance steps through the public
 * API, the poses handed in as floats (as a host would) or doubles (sw_instance_set_pose_d).
 */
#ifndef SW_INVARIANCE_H
#define SW_INVARIANCE_H

#include <stdint.h>

#include "sinew/sinew.h"
#include "sinew/sinew_world.h"

typedef enum sw_move_kind {
    SW_MOVE_RIGID,
    SW_MOVE_TURNING,
    SW_MOVE_ACTOR,
    SW_MOVE_SCALE
} sw_move_kind;

typedef struct sw_move {
    sw_move_kind kind;
    double axis[3];   /* rotation axis (normalised on use) */
    double angle;     /* radians: G's turn; TURNING: its turn a frame */
    double shift[3];  /* G's translation; TURNING: its translation a frame */
    double scale;     /* SCALE and ACTOR: the uniform scale s (0: 1) */
    int float_poses;  /* hand the poses in as floats (sinew_instance_set_pose) */
    int float_output; /* read the surface as floats (sinew_instance_read_surface) */
} sw_move;

typedef struct sw_invariance_run {
    sinew_step_mode mode;
    sinew_self_contact self_contact; /* 0: the blob's default */
    const sinew_world *world;        /* the first instance's world (NULL: none) */
    const sinew_world *world_moved;  /* the second's: the same colliders carried by G */
    float dt;                        /* the step (0: 1/30 s) */
    uint32_t max_patch_vertices;     /* condensation's budget (0: off) */
    uint32_t novel_contact;          /* sinew_instance_def.novel_contact (0: off) */
    /* 1: the second instance keeps no scratch (shared_workspace) and steps in two
       workspaces taken in turn (sinew_instance_step_in), as a crowd's does */
    uint32_t workspaces;
} sw_invariance_run;

typedef struct sw_invariance_result {
    double err; /* largest |x_moved - G x| over the frames, / size */
    int32_t worst_frame;
    double size;             /* the rest bounding-box diagonal */
    int32_t failed;          /* steps that did not return SINEW_OK (either instance) */
    int64_t world_contacts;  /* the first instance's, summed over the frames */
    int64_t self_contacts;   /* the same of its self-contact pairs */
    int64_t novel_contacts;  /* the same of its novel contacts (novel_contact on) */
    int64_t novel_moved;     /* the second instance's novel contacts, summed */
    uint32_t patch_vertices; /* its largest condensation patch */
    int32_t unconverged;     /* its steps that ended short of the solve's tolerance */
} sw_invariance_result;

/* The rigid part of a move at frame f as a transform (12: R row-major, t). */
void sw_move_transform(const sw_move *m, int32_t f, double G[12]);

/* Carries collider def c by the rigid transform G (12): its placement, or a plane's normal
 * and offset (a plane has no placement). Float placements round at 1e-7 of their
 * distance from the origin. */
void sw_move_collider(const double G[12], sinew_collider_def *c);

/* The placement (position, unit quaternion w x y z) of collider def c carried by G, in
 * doubles: what sinew_world_set_collider_transform_d takes, so the moved world is the
 * same world to rounding. 0 for a plane (no placement). */
int sw_move_placement(const double G[12], const sinew_collider_def *c, double pos[3],
                      double rot[4]);

/* Plays frames of `clip` (12 doubles a bone a frame, nb bones) in two instances of blob,
 * the second carried by m, and measures *out. */
sinew_result sw_invariance_measure(const sinew_blob *blob, const double *clip, int32_t nb,
                                   int32_t frames, const sw_invariance_run *run, const sw_move *m,
                                   sw_invariance_result *out);

#endif
