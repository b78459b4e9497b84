/* The helpers the bake's stages share (bake_state.h): the state's memory, its progress
 * and the skinning transforms every stage that un-skins takes. */
#include "bake_state.h"

#include <stdlib.h>
#include <string.h>

#include "bbox.h"
#include "clock.h"
#include "dqs.h"

double sw_bake_pose_grid(const sw_bake_state *s) {
    double lo[3], hi[3]; /* the runtime's size: the rest bounding box's diagonal */
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, s->rig.nv, s->rig.ch.mesh.X);
    return sw_pose_grid(sw_bbox_diagonal(lo, hi));
}

void sw_bake_pose_snapped(const sw_bake_state *s, const double *T, double *L) {
    sw_pose_snap(T, T, s->rig.nb, sw_bake_pose_grid(s), L);
}

void sw_bake_skin_transforms(const sw_bake_state *s, const double *T, double *R, double *t) {
    sw_dualquat dq[SW_MAX_BONES];
    for (int32_t b = 0; b < s->rig.nb; ++b)
        sw_dq_from_transform(T + 12 * b, &dq[b]);
    for (int32_t v = 0; v < s->rig.nv; ++v)
        sw_dqs_blend(dq, s->rig.skin_bone + 4 * v, s->rig.skin_weight + 4 * v, 4, R + 9 * v,
                     t + 3 * v);
}

void sw_bake_progress_begin(sw_bake_state *s, const char *stage, int64_t total) {
    pthread_mutex_lock(&s->progress_lock);
    s->progress_stage = stage;
    s->progress_total = total;
    s->progress_done = 0;
    s->progress_t0 = sw_now_seconds();
    pthread_mutex_unlock(&s->progress_lock);
}

void sw_bake_progress(sw_bake_state *s, int64_t units) {
    if (!s->p->on_progress) return;
    pthread_mutex_lock(&s->progress_lock); /* the bake's workers, never the frame */
    s->progress_done += units;
    s->p->on_progress(s->p->progress_user, s->progress_stage, s->progress_done, s->progress_total,
                      sw_now_seconds() - s->progress_t0);
    pthread_mutex_unlock(&s->progress_lock);
}

void sw_bake_state_free(sw_bake_state *s) {
    pthread_mutex_destroy(&s->progress_lock);
    free(s->rig.weights);
    free(s->poses.sweep_axis);
    free(s->poses.sweep_angle);
    free(s->rig.skin_bone);
    free(s->rig.skin_weight);
    free(s->rig.mass);
    free(s->domains.tet_domain);
    free(s->domains.domain_bone);
    free(s->domains.dom_vert_ptr);
    free(s->domains.dom_verts);
    free(s->domains.dom_tet_ptr);
    free(s->domains.dom_tets);
    free(s->domains.copy_mass);
    free(s->reduce.spring_unit);
    free(s->reduce.spring_unit_packed);
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i) {
        free(s->poses.train[i].T);
        free(s->poses.train[i].x);
        free(s->poses.train[i].contact_ptr);
        free(s->poses.train[i].contacts);
        free(s->poses.train[i].clip);
        free(s->poses.train[i].frame);
    }
    free(s->poses.train);
    free(s->poses.heldout.T);
    free(s->poses.heldout.x);
    free(s->poses.heldout.contact_ptr);
    free(s->poses.heldout.contacts);
    free(s->poses.heldout.clip);
    free(s->poses.heldout.frame);
    for (int32_t d = 0; d < s->domains.nd; ++d) {
        if (s->basis.U) free(s->basis.U[d]);
        if (s->cubature.local) free(s->cubature.local[d]);
        if (s->cubature.w) free(s->cubature.w[d]);
    }
    free(s->basis.U);
    free(s->basis.rank);
    free(s->basis.rank_dynamic);
    free(s->basis.rank_trained);
    free(s->basis.train_q);
    free(s->basis.train_pose);
    free(s->contacts.contact_ptr);
    free(s->contacts.contact_verts);
    free(s->contacts.contact_data);
    free(s->cubature.n);
    free(s->cubature.local);
    free(s->cubature.w);
    sw_embedding_free(&s->embed);
    sw_pool_destroy(s->pool);
}

sw_fullsim_params sw_bake_sim_params(const sw_bake_params *p) {
    sw_fullsim_params fp = sw_fullsim_params_default();
    if (p->reference) sw_fullsim_params_take_solver(&fp, p->reference);
    fp.self_contact = p->self_contact;
    return fp;
}
