/* The pose-space equilibrium force (sinew_blob_format.h, TRAIN_FORCE; runtime
 * pose_space.h, sw_pose_space_force). The reduced model's quasistatic equilibrium at a
 * training pose is the Galerkin minimum of its potential, not the projection of the
 * reference's solution that the blob stores for it (train_q): the basis cannot hold the
 * reference's shape, and the energy it minimises trades the missing part differently from
 * the mass norm the error is measured in. The force b_t = -grad Phi_t(train_q_t), Phi_t
 * the quasistatic step's potential at pose t (cubature, springs, t's pose-space contact
 * pairs), makes the projection the equilibrium there; the runtime interpolates it between
 * the training poses as it does their contact pairs (thesis §3.2.3, after Pose Space
 * Deformation [83]).
 * It lowers the training error and leaves the held-out one (docs/notes/accuracy.md); the fade
 * by the locality share keeps it from raising the held-out error.
 *
 * The equilibrium stage reads the view with its springs chosen and the training poses;
 * writes the view's train_force, force_poses and model_train_error. */
#include <math.h>
#include <stdlib.h>

#include "bake_state.h"
#include "instance.h"

/* The training error of the blob without the force: the springs' choice measured it
 * when it chose (the blob is the one it measured), else one pass over the poses. */
static sinew_result model_error(const sinew_blob *blob, sw_bake_result *out, sw_error *err) {
    for (int32_t c = 0; c < out->nspring_tried; ++c)
        if (sw_bake_spring_mult(c) * out->spring_eh == out->spring_k) {
            out->model_train_error = out->spring_tried_err[c];
            return SINEW_OK;
        }
    sw_eval_result e;
    sinew_result r = sw_bake_train_error(blob, out, SINEW_SELF_CONTACT_POSE_SPACE, &e, NULL, err);
    if (r == SINEW_OK) out->model_train_error = e.failed > 0 ? 1.0 : e.correction_error;
    return r;
}

sinew_result sw_bake_equilibrium(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    out->force_poses = 0;
    out->model_train_error = -1;
    if (!s->p->pose_force) return SINEW_OK;
    sw_blob_view *view = &out->view;
    view->train_force = NULL; /* the potential below is the one without it */
    const int32_t R = view->rank_total, T = view->ntrain;
    double *F = sw_bake_own(out, calloc((size_t)R * T + 1, sizeof(double)));
    if (!F) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    void *mem = NULL;
    sinew_blob *blob = NULL;
    sinew_instance *inst = NULL;
    sinew_result r = sw_bake_result_blob(out, &mem, &blob, err);
    if (r == SINEW_OK) r = model_error(blob, out, err);
    if (r == SINEW_OK) {
        sinew_instance_def def = sinew_instance_def_default();
        def.self_contact = SINEW_SELF_CONTACT_POSE_SPACE; /* the pairs the runtime's force
                                                             applies with (instance.c) */
        if ((r = sinew_instance_create(blob, &def, &inst)) != SINEW_OK)
            r = sw_error_set(err, r, "equilibrium force: cannot create an instance: %s",
                             sinew_result_string(r));
    }
    /* the poses in the blob's order, each arrived at from the one before: a pose stored
       twice is found on the branch it was solved on (blob_view.h) */
    const float dt = 1.0f / 30;
    for (int32_t t = 0; r == SINEW_OK && t < T && t < out->ntrain; ++t) {
        if ((r = sw_instance_set_pose_d(inst, out->train_T + (size_t)12 * view->nbones * t)) !=
            SINEW_OK) {
            r = sw_error_set(err, r, "equilibrium force: training pose %d does not set", t);
            break;
        }
        sw_instance_step_prepare(inst, dt);
        if (sw_instance_nearest_pose(inst) != t) continue; /* its pairs are not in use: no force */
        double *b = F + (size_t)R * t;
        sw_instance_step_potential(inst, dt, view->train_q + (size_t)R * t, b, NULL, 0);
        int finite = 1;
        for (int32_t i = 0; i < R; ++i) {
            b[i] = -b[i];
            finite &= isfinite(b[i]) != 0;
        }
        if (!finite) { /* a blob holds finite forces only: none at this pose */
            for (int32_t i = 0; i < R; ++i)
                b[i] = 0;
            continue;
        }
        out->force_poses++;
    }
    sinew_instance_destroy(inst);
    sinew_blob_destroy(blob);
    free(mem);
    if (r == SINEW_OK) view->train_force = F;
    return r;
}
