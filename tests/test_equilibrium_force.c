/* The pose-space equilibrium force (bake_equilibrium.c, pose_space.h): at every training
 * pose the step's potential is stationary at the stored projected solution, and the
 * quasistatic step returns it (without the force it does not); between poses the force is
 * the blend of the two nearest samples' forces times their locality shares, nothing where
 * the shares are 0; a bake without it writes no force and measures no model error. */
#include <math.h>

#include "bake_fixture.h"
#include "instance.h"
#include "pose_space.h"
#include "sw_test.h"

static double norm(const double *x, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += x[i] * x[i];
    return sqrt(s);
}

static double dist(const double *a, const double *b, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s);
}

static int bake(bake_fixture *f, int pose_force) {
    sw_bake_params p = bake_fixture_params(1, 2); /* return path: a fold with contact pairs */
    p.pose_force = pose_force;
    return bake_fixture_make_params(f, "finger", 2000, 12, &p);
}

/* The largest |q - train_q[t]| over the largest |train_q[t]|, the training poses each stepped
 * (quasistatic) after the one before; *stationary the largest |grad| / |b_t| at train_q[t]
 * of the step's potential (with the force: 0 up to rounding). */
static double training_poses_gap(const bake_fixture *f, double *stationary) {
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    const int32_t R = v->rank_total;
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, NULL, &inst) != SINEW_OK) return INFINITY;
    double *g = malloc(sizeof(double) * (size_t)R), worst = 0, qmax = 0;
    *stationary = 0;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        const double *T = f->res.train_T + (size_t)12 * v->nbones * t,
                     *qt = v->train_q + (size_t)R * t;
        sw_instance_set_pose_d(inst, T);
        sw_instance_step_prepare(inst, 1.0f / 30);
        if (sw_instance_nearest_pose(inst) != t) worst = INFINITY;
        sw_instance_step_potential(inst, 1.0f / 30, qt, g, NULL, 0);
        if (v->train_force) {
            const double bn = norm(v->train_force + (size_t)R * t, R);
            *stationary = fmax(*stationary, norm(g, R) / (bn > 0 ? bn : 1));
        }
        sw_instance_set_pose_d(inst, T);
        if (sinew_instance_step(inst, 1.0f / 30) != SINEW_OK) worst = INFINITY;
        worst = fmax(worst, dist(sw_instance_q(inst), qt, R));
        qmax = fmax(qmax, norm(qt, R));
    }
    free(g);
    sinew_instance_destroy(inst);
    return qmax > 0 ? worst / qmax : worst;
}

TEST(the_training_poses_are_the_step_s_equilibria) {
    bake_fixture a, b;
    ENSURE(bake(&a, 1));
    ENSURE(bake(&b, 0));
    const sw_blob_view *v = sw_blob_get_view(a.blob);
    ENSURE(v->train_force && a.res.force_poses == v->ntrain && v->ncontacts > 0);
    ENSURE(!sw_blob_get_view(b.blob)->train_force && b.res.force_poses == 0 &&
           b.res.model_train_error == -1);
    double st_with, st_without;
    const double with = training_poses_gap(&a, &st_with);
    const double without = training_poses_gap(&b, &st_without);
    fprintf(stderr,
            "  max |q - q_t| / max |q_t| at the training poses: %.3g with the force, %.3g without; "
            "|grad| / |b_t| at q_t %.3g\n",
            with, without, st_with);
    ENSURE(st_with < 1e-8);
    ENSURE(with < 1e-9 && without > 1e-3);
    /* the same model: the force-free blob's training error is the one the force hid */
    sw_eval_result e;
    sw_error err;
    ENSURE(sw_bake_train_error(b.blob, &b.res, SINEW_SELF_CONTACT_POSE_SPACE, &e, NULL, &err) ==
           SINEW_OK);
    ENSUREF(fabs(e.correction_error - a.res.model_train_error) < 1e-12,
            "training error without the force %.6f, recorded %.6f", e.correction_error,
            a.res.model_train_error);
    bake_fixture_free(&a);
    bake_fixture_free(&b);
}

/* sw_pose_space_force on a pose space set by hand: R = 3, two samples. */
TEST(the_force_blends_the_nearest_samples_and_fades_with_their_shares) {
    double force[9] = {1, 2, 3, -4, 5, 6, 1, 2, 3}; /* samples 0 and 2 alike */
    const double q[3] = {0.5, -1, 2};
    sw_pose_space ps;
    memset(&ps, 0, sizeof ps);
    ps.force = force;
    ps.nearest = 0;
    ps.second = 1;
    ps.blend = 0.25;
    ps.tangent[0] = 1;
    ps.tangent[1] = 0.5;
    double g[3] = {10, 10, 10};
    double phi = sw_pose_space_force(&ps, 3, q, g);
    double want[3];
    for (int i = 0; i < 3; ++i) {
        want[i] = 0.75 * force[i] + 0.25 * 0.5 * force[3 + i];
        ENSURE(fabs(g[i] - 10 - want[i]) < 1e-15);
    }
    ENSURE(fabs(phi - (want[0] * q[0] + want[1] * q[1] + want[2] * q[2])) < 1e-14);
    /* two samples alike, full shares: the one sample's force */
    ps.second = 2;
    ps.tangent[1] = 1;
    ENSURE(fabs(sw_pose_space_force(&ps, 3, q, NULL) - (1 * 0.5 - 2 + 3 * 2)) < 1e-14);
    /* no share left (far from both samples), no pose, no force: nothing */
    ps.tangent[0] = ps.tangent[1] = 0;
    memset(g, 0, sizeof g);
    ENSURE(sw_pose_space_force(&ps, 3, q, g) == 0 && g[0] == 0 && g[1] == 0 && g[2] == 0);
    ps.tangent[0] = 1;
    ps.nearest = -1;
    ENSURE(sw_pose_space_force(&ps, 3, q, g) == 0 && g[0] == 0);
    ps.nearest = 0;
    ps.force = NULL;
    ENSURE(sw_pose_space_force(&ps, 3, q, g) == 0 && g[0] == 0);
}

SW_TEST_MAIN(CASE(the_training_poses_are_the_step_s_equilibria),
             CASE(the_force_blends_the_nearest_samples_and_fades_with_their_shares))
