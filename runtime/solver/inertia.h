/* The skeleton's motion as the flesh feels it (DESIGN.md §4.7): each domain rides its
 * bone, and in the bone's frame the bone's motion appears as inertial forces (frame
 * acceleration, angular acceleration, centrifugal, Coriolis) whose projections onto the
 * basis were precomputed (Kim & James 2011), so they cost O(r^2) a step. */
#ifndef SW_INERTIA_H
#define SW_INERTIA_H

#include "blob_view.h"
#include "solver.h"

/* The last three poses (12 doubles per bone each) and how many of them are real. */
typedef struct sw_pose_history {
    double *T_cur, *T_prev, *T_prev2;
    int history; /* frames of history before T_cur available (0..2) */
} sw_pose_history;

/* Inertial forces s->fin of every domain riding its bone, explicit at q_n and qdot_n
 * over a step of h seconds (zero without pose history). */
void sw_inertial_forces(const sw_blob_view *v, const sw_pose_history *ph, sw_solver *s, double h);

/* A pose jump no animation makes in one frame (a teleport): a bone moved by more than
 * half the character's size (rest bounding-box diagonal) or turned by more than 90
 * degrees since the last step. */
int sw_pose_teleported(const sw_blob_view *v, const sw_pose_history *ph, double size);

/* Shifts the history by one step: T_prev2 = T_prev, T_prev = T_cur. */
void sw_pose_history_advance(sw_pose_history *ph, int32_t nbones);

#endif
