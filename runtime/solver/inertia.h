/* The skeleton's motion as the flesh feels it (DESIGN.md §4.7): each domain rides its
 * bone, and in the bone's frame the bone's motion appears as inertial forces (frame
 * acceleration, angular acceleration, centrifugal, Coriolis) whose projections onto the
 * basis were precomputed (Kim & James 2011), so they cost O(r^2) a step. */
#ifndef SW_INERTIA_H
#define SW_INERTIA_H

#include "blob_view.h"
#include "solver.h"

/* The last three poses (12 doubles per bone each), how many of them are real, and the
 * time between T_prev2 and T_prev (the step before this one may have had another dt). */
typedef struct sw_pose_history {
    double *T_cur, *T_prev, *T_prev2;
    int history;   /* frames of history before T_cur available (0..2) */
    double h_prev; /* seconds from T_prev2 to T_prev (valid when history == 2) */
    /* The host declared T_cur discontinuous with T_prev (sinew_instance_mark_teleport):
     * the next step treats it as a jump whatever sw_pose_jump says, then clears this. */
    int declared_jump;
} sw_pose_history;

/* Inertial forces s->fin of every domain riding its bone, explicit at q_n and qdot_n
 * over a step of h seconds (zero without pose history). The bone's velocities are the
 * backward differences over their own intervals, v = (T_cur - T_prev) / h and
 * v_prev = (T_prev - T_prev2) / h_prev, and its acceleration over this step is
 * (v - v_prev) / h (the velocity change the step must carry; with h_prev == h it is the
 * usual (T_cur - 2 T_prev + T_prev2) / h^2, computed by that formula). */
void sw_inertial_forces(const sw_blob_view *v, const sw_pose_history *ph, sw_solver *s, double h);

/* Why a pose change is a jump (a teleport), SW_JUMP_* bits, 0 when it is motion. */
#define SW_JUMP_ANGLE 1u    /* a bone turned by more than 120 degrees */
#define SW_JUMP_DISTANCE 2u /* a point a bone carries moved more than half the size */
#define SW_JUMP_SPEED                                                                              \
    4u /* implied angular speed > SW_JUMP_MAX_SPIN or point speed                                  \
          > SW_JUMP_MAX_SPIN * size */
/* The fastest joint rotation a character makes, rad/s: human joints peak near 140 rad/s
 * (a finger snap, 7,800 deg/s; a pitcher's shoulder, 7,000 deg/s); a bone implied to
 * spin faster than this between two steps jumped. */
#define SW_JUMP_MAX_SPIN 200.0

/* The pose jump between T_prev and T_cur over h seconds (SW_JUMP_* bits, 0 for motion).
 * Each bone b carries the rest points within the ball (ball[4b..4b+2] centre, ball[4b+3]
 * radius) of the vertices it skins; their largest displacement is at most
 * d_b = |(R_cur - R_prev) c + t_cur - t_prev| + |R_cur - R_prev|_2 r. A jump: any bone
 * turned by more than 120 degrees, or d_b > size / 2, or its implied angular speed
 * theta_b / h > SW_JUMP_MAX_SPIN, or d_b / h > SW_JUMP_MAX_SPIN * size. O(bones). */
unsigned sw_pose_jump(const sw_blob_view *v, const sw_pose_history *ph, const double *ball,
                      double size, double h);

/* Shifts the history by one step of h seconds: T_prev2 = T_prev, T_prev = T_cur. */
void sw_pose_history_advance(sw_pose_history *ph, int32_t nbones, double h);

#endif
