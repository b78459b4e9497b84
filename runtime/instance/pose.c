/* The pose a host sets for the next step: rigid bone transforms, checked before any is
 * taken. Never allocates or locks. */
#include <math.h>

#include "instance.h"
#include "instance_internal.h"

/* A bone transform must be finite (else NOT_FINITE) with a proper orthonormal rotation
 * part (else INVALID_ARGUMENT). */
static sinew_result check_transform(const double *T) {
    for (int i = 0; i < 12; ++i)
        if (!isfinite(T[i])) return SINEW_ERROR_NOT_FINITE;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = T[i] * T[j] + T[3 + i] * T[3 + j] + T[6 + i] * T[6 + j];
            if (fabs(d - (i == j)) > 1e-3) return SINEW_ERROR_INVALID_ARGUMENT;
        }
    double det = T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                 T[2] * (T[3] * T[7] - T[4] * T[6]);
    return det > 0 ? SINEW_OK : SINEW_ERROR_INVALID_ARGUMENT;
}

/* Accepts the pose (all bones valid) or leaves everything as it was. */
static sinew_result set_pose(sinew_instance *inst, const double *Td, const float *Tf) {
    int32_t nb = inst->v->nbones;
    for (int32_t b = 0; b < nb; ++b) {
        double T[12];
        for (int i = 0; i < 12; ++i)
            T[i] = Td ? Td[12 * b + i] : (double)Tf[12 * b + i];
        sinew_result r = check_transform(T);
        if (r != SINEW_OK) return r;
    }
    for (int32_t i = 0; i < 12 * nb; ++i)
        inst->pose.T_cur[i] = Td ? Td[i] : (double)Tf[i];
    for (int32_t b = 0; b < nb; ++b)
        sw_dq_from_transform(inst->pose.T_cur + 12 * b, &inst->bone_dq[b]);
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
    return set_pose(inst, NULL, transforms);
}

SINEW_API sinew_result sinew_instance_mark_teleport(sinew_instance *inst) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    inst->pose.declared_jump = 1;
    return SINEW_OK;
}
