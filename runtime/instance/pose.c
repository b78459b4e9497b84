/* The pose a host sets for the next step and where the actor stands: bone transforms in
 * the actor's frame, each a rotation times one uniform scale shared by every bone, and
 * the actor's transform to the world (a rotation times a uniform scale, a translation,
 * in doubles). Both are checked before any is taken, and composed into the simulation
 * frame (instance_internal.h): the world divided by the whole scale, so that the flesh
 * is the physics of the rest-size character at any scale (DESIGN.md §3), with the
 * bones' rigid transforms there in double precision. The step itself works in bone 0's
 * frame with the pose snapped to a grid there (sw_instance_frame): a turned or moved
 * character gives it the same bits, and 10^5 units from the origin is the origin's
 * shape. Never allocates or locks. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "instance.h"
#include "instance_internal.h"
#include "recording.h"
#include "log.h"

/* A scale outside this range is refused: the flesh of a character 10^-6 or 10^6 times
 * its baked size is not a game's. */
#define SW_SCALE_MIN 1e-6
#define SW_SCALE_MAX 1e6
/* How far a bone's scale may differ from the pose's, and its rotation part from a
 * rotation (float transforms from an engine round at 1e-7). */
#define SW_SCALE_TOL 1e-3

/* The uniform scale of M (3x3 row-major): the cube root of its determinant, 0 when it is
 * not a proper (positive determinant) rotation times a scale within SW_SCALE_TOL. */
static double uniform_scale(const double *M) {
    double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                 M[2] * (M[3] * M[7] - M[4] * M[6]);
    if (!(det > 0)) return 0;
    double s = cbrt(det);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = (M[i] * M[j] + M[3 + i] * M[3 + j] + M[6 + i] * M[6 + j]) / (s * s);
            if (!(fabs(d - (i == j)) <= SW_SCALE_TOL)) return 0;
        }
    return s;
}

static sinew_result refuse(const sinew_instance *in, sinew_result r, const char *what) {
    sw_log(&in->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_POSE, "%s", what);
    return r;
}

/* x_sim of the host's bone b: rotation R_A R_b, translation (s_A R_A t_b + t_A) / s,
 * with R_b = M_b / pose_scale (the host's y = M_b X + t_b in the actor's frame, the
 * world's s_A R_A y + t_A). */
static void compose_bone(const sinew_instance *in, int32_t b, double *T) {
    const double *M = in->pose_host + 12 * b, *A = in->actor;
    const double sb = in->pose_scale, sa = in->actor_scale, s = in->scale;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] =
                (A[3 * i] * M[j] + A[3 * i + 1] * M[3 + j] + A[3 * i + 2] * M[6 + j]) / sb;
        T[9 + i] =
            (sa * (A[3 * i] * M[9] + A[3 * i + 1] * M[10] + A[3 * i + 2] * M[11]) + A[9 + i]) / s;
    }
}

/* pose.T_cur from the host's bones and the actor, and the step's frame from it. */
static void compose(sinew_instance *in) {
    in->scale = in->actor_scale * in->pose_scale;
    for (int32_t b = 0; b < in->v->nbones; ++b)
        compose_bone(in, b, in->pose.T_cur + 12 * b);
    sw_instance_frame(in);
}

void sw_instance_frame(sinew_instance *in) {
    const int32_t nb = in->v->nbones;
    sw_pose_history *P = &in->pose, *L = &in->loc;
    L->history = P->history;
    L->h_prev = P->h_prev;
    L->declared_jump = P->declared_jump;
    memcpy(in->frame, P->T_cur, sizeof in->frame); /* bone 0 */
    sw_pose_snap(in->frame, P->T_cur, nb, in->grid, L->T_cur);
    sw_pose_snap(in->frame, P->T_prev, nb, in->grid, L->T_prev);
    sw_pose_snap(in->frame, P->T_prev2, nb, in->grid, L->T_prev2);
    for (int32_t b = 0; b < nb; ++b)
        sw_dq_from_transform(L->T_cur + 12 * b, &in->bone_dq[b]);
}

void sw_instance_to_step(const sinew_instance *in, const double x[3], int direction, double y[3]) {
    const double *F = in->frame;
    double d[3];
    for (int k = 0; k < 3; ++k)
        d[k] = x[k] - (direction ? 0 : F[9 + k]);
    for (int i = 0; i < 3; ++i)
        y[i] = F[i] * d[0] + F[3 + i] * d[1] + F[6 + i] * d[2];
}

void sw_instance_from_step(const sinew_instance *in, const double x[3], int direction,
                           double y[3]) {
    const double *F = in->frame;
    for (int i = 0; i < 3; ++i)
        y[i] = F[3 * i] * x[0] + F[3 * i + 1] * x[1] + F[3 * i + 2] * x[2] +
               (direction ? 0 : F[9 + i]);
}

void sw_instance_actor_identity(sinew_instance *in) {
    memset(in->actor, 0, sizeof in->actor);
    in->actor[0] = in->actor[4] = in->actor[8] = 1;
    in->actor_scale = in->pose_scale = in->scale = 1;
}

void sw_instance_rest_pose(sinew_instance *in) {
    for (int32_t b = 0; b < in->v->nbones; ++b) {
        double *M = in->pose_host + 12 * b;
        memset(M, 0, 12 * sizeof(double));
        M[0] = M[4] = M[8] = 1;
    }
    in->pose_scale = 1;
    compose(in);
}

void sw_instance_to_actor(const sinew_instance *in, const double x[3], int direction, double y[3]) {
    const double *A = in->actor;
    double d[3];
    for (int k = 0; k < 3; ++k) /* the world's point, less the actor's origin */
        d[k] = direction ? x[k] : in->scale * x[k] - A[9 + k];
    for (int i = 0; i < 3; ++i) { /* R_A^T d / s_A */
        double r = A[i] * d[0] + A[3 + i] * d[1] + A[6 + i] * d[2];
        y[i] = direction ? r : r / in->actor_scale;
    }
}

/* Accepts the pose (all bones finite, rotations times one scale) or leaves everything as
 * it was, logging which bone was refused and why. */
static sinew_result set_pose(sinew_instance *inst, const double *Td, const float *Tf) {
    int32_t nb = inst->v->nbones;
    double s0 = 0;
    char why[320];
    for (int32_t b = 0; b < nb; ++b) {
        double T[12];
        for (int i = 0; i < 12; ++i)
            if (!isfinite(T[i] = Td ? Td[12 * b + i] : (double)Tf[12 * b + i]))
                return SINEW_ERROR_NOT_FINITE;
        double s = uniform_scale(T);
        if (s == 0) {
            snprintf(why, sizeof why,
                     "sinew_instance_set_pose: bone %d is not a rotation times a uniform scale "
                     "(sheared, mirrored or degenerate)",
                     (int)b);
            return refuse(inst, SINEW_ERROR_INVALID_ARGUMENT, why);
        }
        if (b == 0) s0 = s;
        if (!(fabs(s / s0 - 1) <= SW_SCALE_TOL) || !(s0 * inst->actor_scale >= SW_SCALE_MIN) ||
            !(s0 * inst->actor_scale <= SW_SCALE_MAX)) {
            snprintf(why, sizeof why,
                     "sinew_instance_set_pose: bone %d is scaled %.6g where bone 0 is %.6g: "
                     "one uniform scale for the whole pose is simulated (squash and stretch "
                     "of single bones is not), within [%g, %g] with the actor's",
                     (int)b, s, s0, SW_SCALE_MIN, SW_SCALE_MAX);
            return refuse(inst, SINEW_ERROR_INVALID_ARGUMENT, why);
        }
    }
    /* a rotation's own rounding (float transforms: det 1 +- 1e-7) is no scale: the step
       then works in the world's own units, as the collision world does */
    if (fabs(s0 - 1) <= 1e-6) s0 = 1;
    if (inst->wc.world && s0 * inst->actor_scale != 1)
        return refuse(inst, SINEW_ERROR_INVALID_ARGUMENT,
                      "sinew_instance_set_pose: a scaled pose with a collision world is not "
                      "simulated yet (scale the world's colliders with the character instead)");
    for (int32_t i = 0; i < 12 * nb; ++i)
        inst->pose_host[i] = Td ? Td[i] : (double)Tf[i];
    inst->pose_scale = s0;
    compose(inst);
    return SINEW_OK;
}

sinew_result sw_instance_set_pose_d(sinew_instance *inst, const double *T) {
    if (!inst || !T) return SINEW_ERROR_INVALID_ARGUMENT;
    return set_pose(inst, T, NULL);
}

SINEW_API sinew_result sinew_instance_set_pose(sinew_instance *inst, const float *transforms,
                                               uint32_t bone_count) {
    if (!inst || !transforms || bone_count != (uint32_t)inst->v->nbones)
        return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_result r = set_pose(inst, NULL, transforms);
    if (r == SINEW_OK) {
        inst->touched = 1;
        sw_rec_pose(inst, transforms);
    }
    return r;
}

SINEW_API sinew_result sinew_instance_set_actor(sinew_instance *inst, const double transform[12]) {
    if (!inst || !transform) return SINEW_ERROR_INVALID_ARGUMENT;
    for (int i = 0; i < 12; ++i)
        if (!isfinite(transform[i])) return SINEW_ERROR_NOT_FINITE;
    double s = uniform_scale(transform);
    if (fabs(s - 1) <= 1e-6) s = 1; /* as set_pose */
    if (s != 0 && inst->wc.world && s * inst->pose_scale != 1)
        return refuse(inst, SINEW_ERROR_INVALID_ARGUMENT,
                      "sinew_instance_set_actor: a scaled actor with a collision world is not "
                      "simulated yet");
    if (s == 0 || !(s * inst->pose_scale >= SW_SCALE_MIN) ||
        !(s * inst->pose_scale <= SW_SCALE_MAX))
        return refuse(inst, SINEW_ERROR_INVALID_ARGUMENT,
                      "sinew_instance_set_actor: not a rotation times a uniform scale within "
                      "[1e-6, 1e6] (with the pose's)");
    for (int i = 0; i < 9; ++i)
        inst->actor[i] = transform[i] / s;
    for (int i = 9; i < 12; ++i)
        inst->actor[i] = transform[i];
    inst->actor_scale = s;
    compose(inst);
    inst->touched = 1;
    sw_rec_actor(inst, transform);
    return SINEW_OK;
}

SINEW_API sinew_result sinew_instance_mark_teleport(sinew_instance *inst) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    inst->pose.declared_jump = 1;
    inst->touched = 1;
    sw_rec_mark(inst, SW_REC_TELEPORT);
    return SINEW_OK;
}
