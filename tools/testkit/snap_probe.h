/* Pose abuse for the step's bounds (sinew_types.h, status flags): one-step rotation snaps
 * of a bone, translation jumps, and how far the output strays from the skinned surface
 * relative to the bound the instance promises. Shared by tests/test_snap.c and
 * sinew-soak. Header-only; evaluation is O(N) (tools and tests, never a step). */
#ifndef SW_SNAP_PROBE_H
#define SW_SNAP_PROBE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "instance.h"
#include "mat3.h"

/* y = T x for a transform T (12: R row-major, t). */
static inline void snap_apply(const double *T, const double x[3], double y[3]) {
    for (int i = 0; i < 3; ++i)
        y[i] = T[3 * i] * x[0] + T[3 * i + 1] * x[1] + T[3 * i + 2] * x[2] + T[9 + i];
}

/* 1 when bone b is `root` or one of its descendants. */
static inline int snap_in_subtree(const sw_blob_view *v, int32_t b, int32_t root) {
    for (int guard = 0; b >= 0 && guard <= v->nbones; ++guard, b = v->bone_parent[b])
        if (b == root) return 1;
    return 0;
}

/* The pose T (12 per bone) with bone `bone` and its descendants turned by `angle` about
 * the bone's world joint (head), around an axis across the bone (a bend), into out. */
static inline void snap_rotate(const sw_blob_view *v, const double *T, int32_t bone, double angle,
                               double *out) {
    const double *J = v->bone_joints + 6 * bone;
    double head[3], tail[3], d[3], ax[3];
    snap_apply(T + 12 * bone, J, head);
    snap_apply(T + 12 * bone, J + 3, tail);
    for (int i = 0; i < 3; ++i)
        d[i] = tail[i] - head[i];
    int m = fabs(d[0]) <= fabs(d[1]) && fabs(d[0]) <= fabs(d[2]) ? 0
            : fabs(d[1]) <= fabs(d[2])                           ? 1
                                                                 : 2;
    double e[3] = {0, 0, 0};
    e[m] = 1;
    ax[0] = d[1] * e[2] - d[2] * e[1];
    ax[1] = d[2] * e[0] - d[0] * e[2];
    ax[2] = d[0] * e[1] - d[1] * e[0];
    double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    for (int i = 0; i < 3; ++i)
        ax[i] = n > 0 ? ax[i] / n : (i == 2);
    double Q[9];
    sw_m3_axis_angle(ax, angle, Q);
    memcpy(out, T, 12 * (size_t)v->nbones * sizeof(double));
    for (int32_t b = 0; b < v->nbones; ++b) {
        if (!snap_in_subtree(v, b, bone)) continue;
        const double *A = T + 12 * b;
        double *B = out + 12 * b;
        for (int i = 0; i < 3; ++i) /* x -> Q (A x - head) + head */
            for (int j = 0; j < 3; ++j)
                B[3 * i + j] = Q[3 * i] * A[j] + Q[3 * i + 1] * A[3 + j] + Q[3 * i + 2] * A[6 + j];
        for (int i = 0; i < 3; ++i)
            B[9 + i] = Q[3 * i] * (A[9] - head[0]) + Q[3 * i + 1] * (A[10] - head[1]) +
                       Q[3 * i + 2] * (A[11] - head[2]) + head[i];
    }
}

/* The pose of a chain of local rotations L (9 per bone, relative to the parent, about the
 * bone's rest head; the rest pose is identity) into T (12 per bone). Parents must come
 * before their children (the blob's order). */
static inline void snap_pose_from_local(const sw_blob_view *v, const double *L, double *T) {
    for (int32_t b = 0; b < v->nbones; ++b) {
        int32_t p = v->bone_parent[b];
        const double *h = v->bone_joints + 6 * b, *Lb = L + 9 * b;
        double *Tb = T + 12 * b, P[3];
        if (p >= 0 && p < b) {
            const double *Tp = T + 12 * p;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    Tb[3 * i + j] =
                        Tp[3 * i] * Lb[j] + Tp[3 * i + 1] * Lb[3 + j] + Tp[3 * i + 2] * Lb[6 + j];
            snap_apply(Tp, h, P);
        } else {
            memcpy(Tb, Lb, 9 * sizeof(double));
            memcpy(P, h, sizeof P);
        }
        for (int i = 0; i < 3; ++i) /* the head stays where the parent carries it */
            Tb[9 + i] = P[i] - (Tb[3 * i] * h[0] + Tb[3 * i + 1] * h[1] + Tb[3 * i + 2] * h[2]);
    }
}

/* The largest distance of an output vertex from its skinned position after the last
 * step; -1 when an output value is not finite. skin: scratch, 3 per surface vertex. */
static inline double snap_deviation(const sinew_instance *inst, const sw_blob_view *v,
                                    double *skin) {
    const double *x = sw_instance_surface(inst);
    sw_instance_skinned_surface(inst, skin);
    double m = 0;
    for (int32_t s = 0; s < sw_blob_output_verts(v); ++s) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
            if (!isfinite(x[3 * s + k])) return -1;
            d2 += (x[3 * s + k] - skin[3 * s + k]) * (x[3 * s + k] - skin[3 * s + k]);
        }
        m = fmax(m, sqrt(d2));
    }
    return m;
}

/* One snap experiment's figures. */
typedef struct {
    double max_ratio;     /* largest deviation / bound over the snap and the steps after */
    double max_size;      /* the same deviation / the character's size */
    uint32_t snap_status; /* the snap step's SINEW_STEP_* flags */
    int limited_steps;    /* steps after the snap flagged LIMITED */
    int nonfinite;        /* steps with a non-finite output or an error */
} snap_result;

/* From the settled pose T0 (held for `settle` steps at dt after 1/30 s steps of the
 * same pose), one step to T1 at dt, then `hold` steps of T1 at dt: the deviation relative
 * to the instance's bound and the flags. With `declare` the host declares the snap a cut
 * (sinew_instance_mark_teleport). T0, T1: 12 per bone. skin: 3 per surface vertex. */
static inline snap_result snap_run(sinew_instance *inst, const sw_blob_view *v, const double *T0,
                                   const double *T1, float dt, int settle, int hold, int declare,
                                   double *skin) {
    snap_result r = {0, 0, 0, 0, 0};
    double bound = sw_instance_displacement_bound(inst), size = 0;
    {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int32_t i = 0; i < v->nverts; ++i)
            for (int k = 0; k < 3; ++k) {
                lo[k] = fmin(lo[k], v->rest[3 * i + k]);
                hi[k] = fmax(hi[k], v->rest[3 * i + k]);
            }
        for (int k = 0; k < 3; ++k)
            size += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        size = sqrt(size);
    }
    sinew_instance_reset(inst);
    sinew_step_stats st = {.struct_size = sizeof st};
    for (int s = 0; s < 30 + settle + 1 + hold; ++s) {
        const double *T = s <= 30 + settle - 1 ? T0 : T1;
        float h = s < 30 ? 1.0f / 30 : dt;
        if (declare && s == 30 + settle && sinew_instance_mark_teleport(inst) != SINEW_OK)
            r.nonfinite++;
        if (sw_instance_set_pose_d(inst, T) != SINEW_OK ||
            sinew_instance_step(inst, h) != SINEW_OK) {
            r.nonfinite++;
            continue;
        }
        sinew_instance_get_stats(inst, &st);
        if (s < 30 + settle) continue;
        if (s == 30 + settle)
            r.snap_status = st.status;
        else if (st.status & SINEW_STEP_LIMITED)
            r.limited_steps++;
        double d = snap_deviation(inst, v, skin);
        if (d < 0) {
            r.nonfinite++;
            continue;
        }
        r.max_ratio = fmax(r.max_ratio, d / bound);
        r.max_size = fmax(r.max_size, d / size);
    }
    return r;
}

#endif
