/* How far the poses bend each joint (sw_bake_joint_reach: the measure of the sweeps'
 * extents) and which joints the held-out poses bend beyond training
 * (sw_bake_beyond_training: the bake's summary, JSON and report list them). A chain of
 * bones turned by known angles, measured back. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sw_test.h"

#include "bake.h"
#include "mat3.h"
#include "sw_mesh.h"

enum { NB = 5 };
static const double DEG = 0.017453292519943295;

/* A chain of NB bones along x: bone b from joint b to joint b + 1, each the parent of the
 * next. */
static void chain(sw_skeleton *sk, double joints[3 * (NB + 1)], int32_t bones[2 * NB],
                  int32_t parent[NB]) {
    for (int32_t j = 0; j <= NB; ++j) {
        joints[3 * j] = j;
        joints[3 * j + 1] = joints[3 * j + 2] = 0;
    }
    for (int32_t b = 0; b < NB; ++b) {
        bones[2 * b] = b;
        bones[2 * b + 1] = b + 1;
        parent[b] = b - 1;
    }
    *sk = (sw_skeleton){NB + 1, joints, NB, bones, parent};
}

/* The chain's pose with bone b turned by deg[b] degrees about axis[b] in its parent's
 * frame (the root too: a root's turn is rigid motion, not a bend). */
static void pose(const sw_skeleton *sk, const double *deg, const double (*axis)[3], double *T) {
    double local[9 * NB];
    for (int32_t b = 0; b < NB; ++b)
        sw_m3_axis_angle(axis[b], deg[b] * DEG, local + 9 * b);
    sw_forward_kinematics(sk, local, NULL, T);
}

TEST(joint_reach_is_each_bend_in_its_parents_frame) {
    double joints[3 * (NB + 1)];
    int32_t bones[2 * NB], parent[NB];
    sw_skeleton sk;
    chain(&sk, joints, bones, parent);
    static const double axis[NB][3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0.6, 0.8}, {0, 0, 1}};
    double T[2][12 * NB];
    /* bone 4's 1e-4 degrees: an arc cosine of the trace would read it 3e-5 off */
    static const double a0[NB] = {50, 30, 20, 10, 1e-4}, a1[NB] = {-70, 10, 25, 0, 0};
    pose(&sk, a0, axis, T[0]);
    pose(&sk, a1, axis, T[1]);
    double reach[NB] = {0}, ax[3 * NB] = {0};
    sw_bake_joint_reach(&sk, T[0], 2, reach, ax);
    /* the root's turn moves the whole chain rigidly: not measured */
    ENSURE(reach[0] == 0);
    static const double want[NB] = {0, 30, 25, 10, 1e-4};
    for (int32_t b = 1; b < NB; ++b) /* to rounding, however small the bend */
        ENSUREF(fabs(reach[b] / (want[b] * DEG) - 1) < 1e-9, "bone %d: %.12g degrees, want %g", b,
                reach[b] / DEG, want[b]);
    /* a half turn and the least turn short of it */
    static const double half[NB] = {0, 180, 180 - 1e-4, 0, 0};
    double Th[12 * NB], reach_h[NB] = {0};
    pose(&sk, half, axis, Th);
    sw_bake_joint_reach(&sk, Th, 1, reach_h, NULL);
    ENSURE_NEAR(reach_h[1] / DEG, 180, 1e-9);
    ENSURE_NEAR(reach_h[2] / DEG, 180 - 1e-4, 1e-9);
    /* the axis is the one at the largest bend, in the parent's frame */
    for (int i = 0; i < 3; ++i) {
        ENSURE_NEAR(ax[3 * 1 + i], axis[1][i], 1e-9);
        ENSURE_NEAR(ax[3 * 2 + i], axis[2][i], 1e-9);
        ENSURE_NEAR(ax[3 * 3 + i], axis[3][i], 1e-9);
    }
    /* raised, never lowered: a start above every pose's bend stays */
    double high[NB] = {0, 2, 2, 2, 2};
    sw_bake_joint_reach(&sk, T[0], 2, high, NULL);
    for (int32_t b = 1; b < NB; ++b)
        ENSURE(high[b] == 2);
}

TEST(beyond_training_lists_the_joints_held_out_poses_bend_further) {
    double joints[3 * (NB + 1)];
    int32_t bones[2 * NB], parent[NB];
    sw_skeleton sk;
    chain(&sk, joints, bones, parent);
    static const double axis[NB][3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};
    /* held-out bends against trained ones: bone 1 four times and 30 degrees more (listed
     * first), bone 2 twice and 40 degrees more (listed after: the order is the multiple of
     * the trained bend), bone 3 2 degrees more (within), bone 4 eight times but 3.5 degrees
     * more (within: a bend too small to matter) */
    static const double held[NB] = {90, 40, 80, 12, 4}, trained[NB] = {0, 10, 40, 10, 0.5};
    double T[12 * NB];
    pose(&sk, held, axis, T);
    sw_bake_result r;
    memset(&r, 0, sizeof r);
    double sweep[NB];
    for (int32_t b = 0; b < NB; ++b)
        sweep[b] = trained[b] * DEG;
    r.heldout_T = T;
    r.nheldout = 1;
    r.sweep_angle = sweep;
    sw_joint_reach out[NB];
    int32_t n = sw_bake_beyond_training(&r, &sk, out, NB);
    ENSUREF(n == 2, "%d joints beyond training, want 2", n);
    if (n == 2) {
        ENSURE(out[0].bone == 1 && out[1].bone == 2);
        ENSURE_NEAR(out[0].heldout_deg, 40, 1e-9);
        ENSURE_NEAR(out[0].train_deg, 10, 1e-9);
        ENSURE_NEAR(out[1].heldout_deg, 80, 1e-9);
        ENSURE_NEAR(out[1].train_deg, 40, 1e-9);
    }
    /* at most max listed, the count still all of them */
    memset(out, 0, sizeof out);
    ENSURE(sw_bake_beyond_training(&r, &sk, out, 1) == 2);
    ENSURE(out[0].bone == 1 && out[1].bone == 0 && out[1].heldout_deg == 0);
    /* trained as far as held out: nothing beyond */
    for (int32_t b = 0; b < NB; ++b)
        sweep[b] = held[b] * DEG;
    ENSURE(sw_bake_beyond_training(&r, &sk, out, NB) == 0);
    /* no held-out poses: nothing beyond */
    r.nheldout = 0;
    for (int32_t b = 0; b < NB; ++b)
        sweep[b] = 0;
    ENSURE(sw_bake_beyond_training(&r, &sk, out, NB) == 0);
}

SW_TEST_MAIN(CASE(joint_reach_is_each_bend_in_its_parents_frame),
             CASE(beyond_training_lists_the_joints_held_out_poses_bend_further))
