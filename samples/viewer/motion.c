/* Cross-fades and root motion on the host's side: sinew sees only the resulting bone
 * transforms and the actor's placement (sinew_instance_set_actor). */
#include "motion.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The fade's weight of the second clip at simulation time clock. */
static double fade_weight(const vw_motion *m, double clock) {
    if (m->fade_clip < 0 || clock < m->fade_at) return 0;
    return m->fade_time > 0 ? fmin(1.0, (clock - m->fade_at) / m->fade_time) : 1;
}

static void blend_locals(vw_trs *a, const vw_trs *b, int32_t n, double w) {
    for (int32_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k)
            a[i].t[k] += w * (b[i].t[k] - a[i].t[k]), a[i].s[k] += w * (b[i].s[k] - a[i].s[k]);
        double q[4];
        vw_quat_slerp(a[i].q, b[i].q, w, q);
        memcpy(a[i].q, q, sizeof q);
    }
}

/* The second clip starts at its beginning when the fade starts. */
static int blended_pose(const vw_asset *a, const vw_motion *m, double t, double clock, float *out) {
    const double w = fade_weight(m, clock);
    if (w <= 0) return a->pose(a, m->clip, t, out);
    const double tb = t - m->fade_at;
    if (w >= 1 || !a->sample) return a->pose(a, m->fade_clip, tb, out);
    vw_trs *la = malloc(sizeof *la * 2 * (size_t)a->nnodes), *lb = la + a->nnodes;
    int ok = la && a->sample(a, m->clip, t, la) && a->sample(a, m->fade_clip, tb, lb);
    if (ok) blend_locals(la, lb, a->nnodes, w);
    ok = ok && a->compose(a, la, out);
    free(la);
    return ok;
}

/* The root frame of a pose: where the root bone stands on the ground and which way it
 * heads, relative to its bind pose (identity at bind). */
static vw_planar root_frame(const vw_motion *m, const float *pose) {
    const float *T = pose + 12 * m->root_bone;
    const double *b = m->root_bind;
    double p[3];
    for (int r = 0; r < 3; ++r)
        p[r] = T[3 * r] * b[0] + T[3 * r + 1] * b[1] + T[3 * r + 2] * b[2] + T[9 + r];
    /* the heading of the bone's z axis as the pose turns it (+z: glTF's forward) */
    vw_planar f = {0, 0, atan2(T[2], T[8])};
    const double c = cos(f.yaw), s = sin(f.yaw);
    /* F(x) = RotY(yaw) (x - g_bind) + g */
    f.x = p[0] - (c * b[0] + s * b[2]);
    f.z = p[2] - (-s * b[0] + c * b[2]);
    return f;
}

static vw_planar compose(vw_planar a, vw_planar b) {
    const double c = cos(a.yaw), s = sin(a.yaw);
    return (vw_planar){a.x + c * b.x + s * b.z, a.z - s * b.x + c * b.z, a.yaw + b.yaw};
}

static vw_planar inverse(vw_planar a) {
    const double c = cos(a.yaw), s = sin(a.yaw);
    return (vw_planar){-(c * a.x - s * a.z), -(s * a.x + c * a.z), -a.yaw};
}

/* Pose transforms T become F^-1 T: the root stays over its bind position, facing its
 * bind heading. */
static void remove_root(const vw_planar *f, float *pose, int32_t nbones) {
    const vw_planar g = inverse(*f);
    for (int32_t b = 0; b < nbones; ++b) {
        float *T = pose + 12 * b;
        for (int c = 0; c < 3; ++c) { /* the rotation's columns turn, the translation moves */
            float v[3] = {T[c], T[3 + c], T[6 + c]};
            vw_planar_apply(&g, v, 0);
            T[c] = v[0], T[3 + c] = v[1], T[6 + c] = v[2];
        }
        vw_planar_apply(&g, T + 9, 1);
    }
}

int vw_motion_pose(const vw_asset *a, const vw_motion *m, double t, double clock, float *out) {
    if (!blended_pose(a, m, t, clock, out)) return 0;
    if (m->root_bone >= 0) {
        const vw_planar f = root_frame(m, out);
        remove_root(&f, out, a->nbones);
    }
    return 1;
}

/* One clip's root frame at clip time t. */
static int clip_frame(const vw_asset *a, const vw_motion *m, int clip, double t, float *scratch,
                      vw_planar *f) {
    if (!a->pose(a, clip, t, scratch)) return 0;
    *f = root_frame(m, scratch);
    return 1;
}

/* The root's motion in one clip from t0 to t1 in the frame of t0; across the loop's end it
 * continues from the last frame rather than jumping back to the first. */
static vw_planar clip_delta(const vw_asset *a, const vw_motion *m, int clip, double t0, double t1,
                            float *scratch) {
    const double d = a->clip_duration[clip];
    vw_planar f0, f1, e, s, none = {0, 0, 0};
    if (!(d > 0) || !clip_frame(a, m, clip, t0, scratch, &f0) ||
        !clip_frame(a, m, clip, t1, scratch, &f1))
        return none;
    if (floor(t0 / d) == floor(t1 / d)) return compose(inverse(f0), f1);
    if (!clip_frame(a, m, clip, d * (1 - 1e-9), scratch, &e) ||
        !clip_frame(a, m, clip, 0, scratch, &s))
        return none;
    return compose(compose(inverse(f0), e), compose(inverse(s), f1));
}

void vw_motion_advance(const vw_asset *a, const vw_motion *m, double t0, double t1, double clock1,
                       vw_planar *actor) {
    const double dt = t1 - t0;
    vw_planar d = {0, 0, 0};
    float *scratch = m->root_bone >= 0 ? malloc(sizeof(float) * 12 * (size_t)a->nbones) : NULL;
    if (scratch) {
        const double w = fade_weight(m, clock1);
        if (w < 1) d = clip_delta(a, m, m->clip, t0, t1, scratch);
        if (w > 0) { /* deltas blend as the poses do */
            const vw_planar e =
                clip_delta(a, m, m->fade_clip, t0 - m->fade_at, t1 - m->fade_at, scratch);
            d.x += w * (e.x - d.x), d.z += w * (e.z - d.z), d.yaw += w * (e.yaw - d.yaw);
        }
    }
    free(scratch);
    *actor = compose(*actor, d);
    *actor = compose(*actor, (vw_planar){0, m->walk * dt, m->turn * dt});
}

void vw_planar_matrix(const vw_planar *p, double out[12]) {
    const double c = cos(p->yaw), s = sin(p->yaw);
    const double M[12] = {c, 0, s, 0, 1, 0, -s, 0, c, p->x, 0, p->z};
    memcpy(out, M, sizeof M);
}

void vw_planar_apply(const vw_planar *p, float *v, int w) {
    const double c = cos(p->yaw), s = sin(p->yaw), x = v[0], z = v[2];
    v[0] = (float)(c * x + s * z + (w ? p->x : 0));
    v[2] = (float)(-s * x + c * z + (w ? p->z : 0));
}
