/* Motion beyond the bake's training (SINEW_STEP_BEYOND_TRAINING): the blob's pose index
 * holds each joint's largest bend over the training poses, and the step counts the joints
 * the pose bends more than SW_BEYOND_RATIO times and SW_BEYOND_DEG degrees beyond it,
 * naming the one furthest beyond. Checked on the folding finger against the bake's own
 * measure of the training poses (sw_bake_joint_reach, from the rotation matrices, not
 * the pose feature's quaternions), on its clip (never beyond: it trained on it) and on
 * poses bending one joint by known multiples of its trained bend. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake_fixture.h"
#include "instance.h"
#include "mat3.h"
#include "pose_space.h"
#include "sw_mesh.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;
static const double DEG = 0.017453292519943295;

/* The folding finger at 2,000 tets with a 12-frame clip. */
static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

/* One quasistatic step at pose T; its stats. */
static sinew_step_stats step_at(sinew_instance *inst, const double *T) {
    sinew_step_stats st = {.struct_size = sizeof st};
    if (sw_instance_set_pose_d(inst, T) != SINEW_OK ||
        sinew_instance_step(inst, 1.0f / 30) != SINEW_OK)
        st.status = SINEW_STEP_FAILED;
    sinew_instance_get_stats(inst, &st);
    return st;
}

TEST(the_rule_needs_both_the_multiple_and_the_degrees) {
    /* 1.25 times and 5 degrees beyond: both, strictly */
    ENSURE(sw_joint_beyond_training(40.1 * DEG, 32 * DEG));  /* 1.253x, 8.1 degrees */
    ENSURE(!sw_joint_beyond_training(39.9 * DEG, 32 * DEG)); /* 1.247x */
    ENSURE(!sw_joint_beyond_training(4.9 * DEG, 0));         /* never bent: 4.9 degrees */
    ENSURE(sw_joint_beyond_training(5.1 * DEG, 0));
    ENSURE(!sw_joint_beyond_training(24.9 * DEG, 20 * DEG)); /* 1.245x, 4.9 degrees */
    ENSURE(!sw_joint_beyond_training(NAN, 0));
}

TEST(the_index_holds_each_joints_largest_training_bend) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    if (!f) return;
    int32_t nb = f->ch.skel.nbones;
    double *want = calloc((size_t)nb, sizeof(double));
    ENSURE(want);
    if (!want) return;
    sw_bake_joint_reach(&f->ch.skel, f->res.train_T, f->res.ntrain, want, NULL);
    const double *have = f->blob->poses.joint_bend;
    int bent = 0;
    for (int32_t b = 0; b < nb; ++b) {
        /* the index is of the poses as the step sees them, snapped to 2^-24 (sw_pose_snap):
           1e-7 rad from the clip's own */
        ENSUREF(fabs(have[b] - want[b]) < 1e-7, "bone %d: %.12g rad, the bake measures %.12g", b,
                have[b], want[b]);
        bent += want[b] > 10 * DEG;
    }
    ENSURE(bent >= 2);    /* the finger's two joints fold */
    ENSURE(have[0] == 0); /* the root's turn is rigid motion, not a bend */
    free(want);
}

TEST(the_clip_it_trained_on_is_never_beyond) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    if (!f) return;
    sinew_instance *inst = NULL;
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    if (!inst) return;
    int32_t nb = f->ch.skel.nbones;
    for (int32_t k = 0; k < f->ch.clip.nframes; ++k) {
        sinew_step_stats st = step_at(inst, f->ch.clip.T + (size_t)k * 12 * nb);
        ENSUREF(!(st.status & SINEW_STEP_BEYOND_TRAINING) && st.joints_beyond_training == 0 &&
                    st.beyond_training_bone == -1 && st.beyond_training_deg == 0,
                "frame %d: status %u, %u joints beyond", k, st.status, st.joints_beyond_training);
    }
    sinew_instance_destroy(inst);
}

TEST(a_joint_bent_past_its_training_is_counted_and_named) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    if (!f) return;
    const sw_skeleton *sk = &f->ch.skel;
    int32_t nb = sk->nbones, j = -1;
    for (int32_t b = 0; b < nb; ++b) /* the joint bent least far in training, but bent */
        if (sk->parent[b] >= 0 && f->res.sweep_angle[b] > 5 * DEG &&
            (j < 0 || f->res.sweep_angle[b] < f->res.sweep_angle[j]))
            j = b;
    ENSURE(j >= 0);
    if (j < 0) return;
    double trained = f->blob->poses.joint_bend[j];
    double *local = malloc((size_t)nb * 9 * sizeof(double)),
           *T = malloc((size_t)nb * 12 * sizeof(double));
    sinew_instance *inst = NULL;
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(local && T && sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    /* joint j alone turned about its sweep axis to m times its trained bend (a half turn
     * at most); 1.2 is within the rule, the others beyond it */
    static const double mult[] = {0.5, 1.2, 1.4, 2.0};
    for (size_t k = 0; inst && k < sizeof mult / sizeof mult[0]; ++k) {
        double bend = fmin(mult[k] * trained, 3.0);
        for (int32_t b = 0; b < nb; ++b)
            sw_m3_axis_angle(f->res.sweep_axis + 3 * b, b == j ? bend : 0, local + 9 * b);
        sw_forward_kinematics(sk, local, NULL, T);
        sinew_step_stats st = step_at(inst, T);
        ENSURE(!(st.status & SINEW_STEP_FAILED));
        int beyond = sw_joint_beyond_training(bend, trained);
        ENSURE(beyond == (mult[k] > 1.25));
        ENSUREF(st.joints_beyond_training == (uint32_t)beyond &&
                    !!(st.status & SINEW_STEP_BEYOND_TRAINING) == beyond,
                "%.1fx: %u joints beyond, status %u", mult[k], st.joints_beyond_training,
                st.status);
        ENSURE(st.beyond_training_bone == (beyond ? j : -1));
        ENSUREF(fabs(st.beyond_training_deg - (beyond ? (bend - trained) / DEG : 0)) < 1e-5,
                "%.1fx: %.9f degrees beyond, want %.9f", mult[k], st.beyond_training_deg,
                beyond ? (bend - trained) / DEG : 0);
    }
    sinew_instance_destroy(inst);
    free(local);
    free(T);
}

SW_TEST_MAIN(CASE(the_rule_needs_both_the_multiple_and_the_degrees),
             CASE(the_index_holds_each_joints_largest_training_bend),
             CASE(the_clip_it_trained_on_is_never_beyond),
             CASE(a_joint_bent_past_its_training_is_counted_and_named))
