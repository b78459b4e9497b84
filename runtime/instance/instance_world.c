/* An instance and the collision world (sinew_world.h): attaching one, and the forces
 * the flesh exerted on each collider in the last step (two-way coupling). */
#include <math.h>

#include "collision.h"
#include "instance_internal.h"
#include "recording.h"
#include "log.h"

SINEW_API sinew_result sinew_instance_set_world(sinew_instance *inst, const sinew_world *world) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    if (world && inst->scale != 1) { /* the world's queries are in its own units (pose.c) */
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_POSE,
               "sinew_instance_set_world: the actor is scaled %.6g; a collision world with a "
               "scaled actor is not simulated yet",
               inst->scale);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    inst->wc.world = world;
    /* the world's contact reads the surface copies (instance.c's active vertices) */
    inst->red.skin_surface =
        world != NULL || inst->v->nrender_verts == 0 || inst->novel_on || inst->coll_on;
    sw_world_contacts_clear(&inst->wc);
    inst->wc.boxes_valid = 0; /* the next step's broad phase starts from every cluster */
    sw_rec_world(inst);
    return SINEW_OK;
}

SINEW_API sinew_result sinew_instance_ignore_collider(sinew_instance *inst, sinew_collider_id id) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    if (id && inst->wc.world && sw_world_slot_of(inst->wc.world, id) < 0) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
               "sinew_instance_ignore_collider: id 0x%08x is not a live collider of the world",
               (unsigned)id);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    inst->wc.ignore = id;
    sw_rec_ignore(inst);
    return SINEW_OK;
}

/* The candidates of collider `id` hold the flesh's force on it: minus each copy's
 * contact force, applied at the copy's contact point (its frozen surface point). */
SINEW_API sinew_result sinew_instance_collider_force(const sinew_instance *inst,
                                                     sinew_collider_id id, float force[3],
                                                     float torque[3]) {
    if (!inst || !force || !torque) return SINEW_ERROR_INVALID_ARGUMENT;
    const sw_world_contacts *wc = &inst->wc;
    if (!wc->world || sw_world_slot_of(wc->world, id) < 0) return SINEW_ERROR_INVALID_ARGUMENT;
    double R[9], o[3], F[3] = {0, 0, 0}, M[3] = {0, 0, 0};
    sw_collider_transform(sw_world_slot(wc->world, (uint32_t)sw_world_slot_of(wc->world, id)), R,
                          o);
    for (int32_t j = 0; j < wc->ncand; ++j) {
        const sw_world_cand *cd = &wc->cand[j];
        if (cd->id != id) continue;
        double f[3], a[3], r[3]; /* in the world, from the step's frame */
        sw_instance_from_step(inst, cd->f, 1, f);
        sw_instance_from_step(inst, cd->law.a, 0, a);
        for (int k = 0; k < 3; ++k) {
            f[k] = -f[k];
            F[k] += f[k];
            r[k] = a[k] - o[k];
        }
        M[0] += r[1] * f[2] - r[2] * f[1];
        M[1] += r[2] * f[0] - r[0] * f[2];
        M[2] += r[0] * f[1] - r[1] * f[0];
    }
    for (int k = 0; k < 3; ++k) {
        force[k] = (float)F[k];
        torque[k] = (float)M[k];
    }
    return SINEW_OK;
}
