/* Levels of detail (sinew_lod): the pose-space level's step, which solves nothing (each
 * output vertex skinned on its own and displaced by the blob's LOD modes, their weights
 * linear in the pose's joint rotations), and the fade that carries a change of level
 * while the surface moves (SINEW_LOD_BLEND_FRAMES steps at the fastest). The other two
 * levels are the step itself (step.c), the reduced one with its world, patches and novel
 * contact left out and one Newton update. Never allocates or locks. */
#include <math.h>
#include <string.h>

#include "clock.h"
#include "dqs.h"
#include "instance.h"
#include "instance_internal.h"
#include "log.h"
#include "recording.h"

/* The screen fractions from which sinew_lod_for_screen_size picks the full and the reduced
 * level: a character a quarter of the screen high shows its flesh's detail, one under a
 * twelfth its silhouette. */
#define SW_LOD_SCREEN_FULL 0.25f
#define SW_LOD_SCREEN_REDUCED 0.08f

SINEW_API uint32_t sinew_blob_lod_count(const sinew_blob *blob) {
    if (!blob) return 0;
    return sw_blob_get_view(blob)->lod_rank > 0 ? 3u : 2u;
}

SINEW_API sinew_lod sinew_lod_for_screen_size(const sinew_blob *blob, float screen_fraction) {
    if (!(screen_fraction < SW_LOD_SCREEN_FULL) || screen_fraction != screen_fraction)
        return SINEW_LOD_FULL;
    if (screen_fraction >= SW_LOD_SCREEN_REDUCED || sinew_blob_lod_count(blob) < 3)
        return SINEW_LOD_REDUCED;
    return SINEW_LOD_POSE_SPACE;
}

SINEW_API sinew_result sinew_instance_set_lod(sinew_instance *inst, sinew_lod level) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    if ((uint32_t)level >= sinew_blob_lod_count(inst->blob)) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_LOD,
               "sinew_instance_set_lod: level %u, but the blob holds %u levels (the pose-space "
               "level needs a blob sinew-bake wrote with it)",
               (unsigned)level, (unsigned)sinew_blob_lod_count(inst->blob));
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    if (level == inst->lod) return SINEW_OK; /* (a host may say it every frame) */
    inst->lod = level;
    if (!inst->stepped) inst->lod_last = level; /* no surface shown yet: nothing to blend */
    inst->touched = 1;
    sw_rec_lod(inst);
    return SINEW_OK;
}

/* The largest coefficient of a mode the level takes (a blob's map, finite but absurd,
 * can give more): with modes of entries in [-1, 1] no displacement leaves float range. */
#define SW_LOD_COEF_MAX 1e30

/* disp (n3 floats) = sum_j c_j B_j, B's modes n3 floats each: one pass a mode along
 * contiguous memory, which the compiler vectorises (a dot product a vertex would not). */
static void displacements(const float *restrict B, const float *c, int32_t m, int64_t n3,
                          float *restrict disp) {
    for (int64_t k = 0; k < n3; ++k)
        disp[k] = 0;
    for (int32_t j = 0; j < m; ++j) {
        const float *restrict Bj = B + (size_t)j * n3;
        const float cj = c[j];
        for (int64_t k = 0; k < n3; ++k)
            disp[k] += cj * Bj[k];
    }
}

int sw_lod_pose_surface(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    const int32_t m = v->lod_rank, n = v->nlod_verts, nf = SW_POSE_ROTATION_FEATURES(v->nbones);
    double *f = in->lod_feat;
    float c[SINEW_BLOB_LOD_MAX_RANK];
    sw_pose_rotation_feature(in->pose.T_cur, v->bone_parent, v->nbones, f);
    int bounded = 1;
    for (int32_t j = 0; j < m; ++j) { /* c = W f */
        const double *W = v->lod_map + (size_t)j * nf;
        double a = 0;
        for (int32_t i = 0; i < nf; ++i)
            a += W[i] * f[i];
        bounded &= fabs(a) <= SW_LOD_COEF_MAX;
        c[j] = bounded ? (float)a : 0;
    }
    if (!bounded) memset(c, 0, sizeof c); /* plain skinning: no overflow reaches the host */
    displacements(v->lod_basis, c, m, 3 * (int64_t)n, in->lod_disp);
    for (int32_t b = 0; b < v->nbones; ++b)
        sw_dq_from_transform(in->pose.T_cur + 12 * b, &in->lod_dq[b]);
    for (int32_t s = 0; s < n; ++s) {
        double R[9], t[3], y[3];
        sw_dqs_blend(in->lod_dq, v->lod_bone + 4 * s, v->lod_weight + 4 * s, 4, R, t);
        for (int i = 0; i < 3; ++i)
            y[i] = v->lod_rest[3 * s + i] + in->lod_disp[3 * s + i];
        double *x = in->surf_x + 3 * s;
        for (int i = 0; i < 3; ++i)
            x[i] = R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + t[i];
    }
    sw_instance_surface_normals(in);
    return bounded;
}

sinew_result sw_lod_pose_step(sinew_instance *in, float dt, sinew_step_stats *st) {
    const sw_blob_view *v = in->v;
    double t0 = sw_now_seconds();
    in->solver.pred_valid = 0; /* (the frame is the pose's: set_pose took it) */
    sinew_result r = SINEW_OK;
    if (!sw_lod_pose_surface(in)) {
        st->status |= SINEW_STEP_FAILED;
        r = SINEW_ERROR_NOT_FINITE;
    }
    sw_pose_history_advance(&in->pose, v->nbones, dt); /* the last step's frame and boxes
                                                          are renewed on leaving */
    st->status |= SINEW_STEP_POSE_SPACE;
    in->coll_src = SW_COLL_SKINNED;
    st->ms_output = 1e3 * (sw_now_seconds() - t0);
    return r;
}

void sw_lod_leave_pose_space(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    sw_solver *s = &in->solver;
    sw_instance_frame(in);
    sw_pose_space_lookup(&in->ps, v, in->loc.T_cur);
    sw_pose_space_blend(&in->ps, v->train_q, in->red.R, s->q);
    memset(s->qdot, 0, (size_t)in->red.R * sizeof(double));
    s->pred_valid = 0;
    if (in->cond.z.max_verts > 0) sw_cond_forget(&in->cond);
    in->ps.in_patch = NULL;
    in->sc.in_patch = NULL;
    in->pose.history = 0; /* the broad phases' boxes are of surfaces it did not solve */
}

/* How fast a change of level fades: each step by at most this share of the largest move
 * the new level's surface makes in it, and by 1 / SINEW_LOD_BLEND_FRAMES at most; a
 * character standing still keeps what it showed. */
#define SW_LOD_FADE_SHARE 0.5

/* The surface plus lod_w times lod_off (bone 0's frame), and its normals again. */
static void apply_offset(sinew_instance *in) {
    for (int32_t i = 0; i < sw_blob_output_verts(in->v); ++i) {
        double d[3];
        sw_instance_from_step(in, in->lod_off + 3 * i, 1, d);
        for (int k = 0; k < 3; ++k)
            in->surf_x[3 * i + k] += in->lod_w * d[k];
    }
    sw_instance_surface_normals(in);
}

/* A step during a fade: lod_w falls with the largest move of the new level's surface
 * since the last step (lod_tmp holds that surface), then the surface shows the rest. */
static void fade(sinew_instance *in) {
    const int64_t n3 = 3 * (int64_t)sw_blob_output_verts(in->v);
    double move = 0;
    for (int64_t i = 0; i < n3; i += 3) {
        const double *a = in->surf_x + i, *b = in->lod_tmp + i;
        double d = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]);
        move = d > move ? d : move;
    }
    memcpy(in->lod_tmp, in->surf_x, (size_t)n3 * sizeof(double));
    double dw = 1.0 / SINEW_LOD_BLEND_FRAMES, reach = SW_LOD_FADE_SHARE * sqrt(move);
    if (reach < dw * in->lod_off_max) dw = reach / in->lod_off_max;
    in->lod_w = in->lod_w > dw ? in->lod_w - dw : 0;
    if (in->lod_w > 0) apply_offset(in);
}

/* The surface the old level `from` gives at this pose, into surf_x, when the new level's
 * step ran: the pose-space level's own, or the subspace surface at the last step's
 * solution (s->qn) for a solving level. */
static void old_surface(sinew_instance *in, sinew_lod from) {
    if (from == SINEW_LOD_POSE_SPACE) {
        sw_lod_pose_surface(in);
        return;
    }
    sw_solver *s = &in->solver;
    double *q = s->q;
    s->q = s->qn;
    sw_instance_write_surface(in);
    s->q = q;
}

/* lod_off = the displayed surface `shown` less surf_x, in bone 0's frame; lod_off_max its
 * largest. */
static void set_offset(sinew_instance *in, const double *shown) {
    double big = 0;
    for (int64_t i = 0; i < 3 * (int64_t)sw_blob_output_verts(in->v); i += 3) {
        double d[3] = {shown[i] - in->surf_x[i], shown[i + 1] - in->surf_x[i + 1],
                       shown[i + 2] - in->surf_x[i + 2]};
        sw_instance_to_step(in, d, 1, in->lod_off + i);
        double n = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        big = n > big ? n : big;
    }
    in->lod_off_max = sqrt(big);
}

void sw_lod_finish(sinew_instance *in, sinew_lod from, sinew_lod to, sinew_lod ran) {
    const size_t bytes = 3 * (size_t)sw_blob_output_verts(in->v) * sizeof(double);
    double *tmp = in->lod_tmp;
    if (from == to) {
        if (in->lod_w > 0) fade(in);
        return;
    }
    if (ran == from) { /* the old level's step: what it shows, then the new level's surface */
        if (in->lod_w > 0) apply_offset(in);
        memcpy(tmp, in->surf_x, bytes);
        sw_lod_pose_surface(in); /* (only a change to the pose-space level runs so) */
        set_offset(in, tmp);
    } else { /* the new level's step: what the old one would show at this pose */
        memcpy(tmp, in->surf_x, bytes);
        old_surface(in, from);
        if (in->lod_w > 0) apply_offset(in); /* the old change's fade, still showing */
        for (size_t i = 0; i < bytes / sizeof(double); ++i) { /* shown - new */
            double shown = in->surf_x[i];
            in->surf_x[i] = tmp[i];
            tmp[i] = shown;
        }
        set_offset(in, tmp);
        if (from != SINEW_LOD_POSE_SPACE) sw_instance_write_surface(in); /* its boxes again */
    }
    memcpy(tmp, in->surf_x, bytes); /* the new level's surface, which the fade follows */
    in->lod_w = 1;
    apply_offset(in);
}
