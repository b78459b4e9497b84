/* Dual-quaternion skinning (Kavan, Collins, Zara, O'Sullivan 2008, "Geometric skinning
 * with approximate dual quaternion blending"): DLB = normalised weighted sum of the
 * bones' unit dual quaternions. Used by the bake and the per-frame step, so nothing
 * here allocates, locks or branches on anything but the data. */
#include "dqs.h"

#include <math.h>
#include <string.h>

/* Shepperd (1978): of the four equivalent formulas for a quaternion from a rotation
 * matrix, use the one whose square root has the largest argument (the largest of
 * trace, R00, R11, R22), so the division is never by a tiny number and 180-degree
 * rotations (trace = -1, w = 0) are exact. */
static void quat_from_matrix(const double *R, double q[4]) {
    double tr = R[0] + R[4] + R[8];
    if (tr >= R[0] && tr >= R[4] && tr >= R[8]) {
        double s = 2.0 * sqrt(fmax(1.0 + tr, 0.0)); /* s = 4w */
        q[0] = 0.25 * s;
        q[1] = (R[7] - R[5]) / s;
        q[2] = (R[2] - R[6]) / s;
        q[3] = (R[3] - R[1]) / s;
    } else if (R[0] >= R[4] && R[0] >= R[8]) {
        double s = 2.0 * sqrt(fmax(1.0 + R[0] - R[4] - R[8], 0.0)); /* s = 4x */
        q[0] = (R[7] - R[5]) / s;
        q[1] = 0.25 * s;
        q[2] = (R[1] + R[3]) / s;
        q[3] = (R[2] + R[6]) / s;
    } else if (R[4] >= R[8]) {
        double s = 2.0 * sqrt(fmax(1.0 - R[0] + R[4] - R[8], 0.0)); /* s = 4y */
        q[0] = (R[2] - R[6]) / s;
        q[1] = (R[1] + R[3]) / s;
        q[2] = 0.25 * s;
        q[3] = (R[5] + R[7]) / s;
    } else {
        double s = 2.0 * sqrt(fmax(1.0 - R[0] - R[4] + R[8], 0.0)); /* s = 4z */
        q[0] = (R[3] - R[1]) / s;
        q[1] = (R[2] + R[6]) / s;
        q[2] = (R[5] + R[7]) / s;
        q[3] = 0.25 * s;
    }
    /* A rotation matrix with round-off gives a quaternion off unit length by the same
     * order; renormalising keeps the dual quaternion on the unit manifold. */
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i)
        q[i] /= n;
}

void sw_dq_from_transform(const double T[12], sw_dualquat *dq) {
    const double *t = T + 9;
    double *r = dq->r;
    quat_from_matrix(T, r);
    /* d = 0.5 (0, t) r: the product of a pure quaternion with r. */
    dq->d[0] = -0.5 * (t[0] * r[1] + t[1] * r[2] + t[2] * r[3]);
    dq->d[1] = 0.5 * (r[0] * t[0] + t[1] * r[3] - t[2] * r[2]);
    dq->d[2] = 0.5 * (r[0] * t[1] + t[2] * r[1] - t[0] * r[3]);
    dq->d[3] = 0.5 * (r[0] * t[2] + t[0] * r[2] - t[1] * r[1]);
}

void sw_quat_to_matrix(const double q[4], double R[9]) {
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1.0 - 2.0 * (y * y + z * z);
    R[1] = 2.0 * (x * y - w * z);
    R[2] = 2.0 * (x * z + w * y);
    R[3] = 2.0 * (x * y + w * z);
    R[4] = 1.0 - 2.0 * (x * x + z * z);
    R[5] = 2.0 * (y * z - w * x);
    R[6] = 2.0 * (x * z - w * y);
    R[7] = 2.0 * (y * z + w * x);
    R[8] = 1.0 - 2.0 * (x * x + y * y);
}

void sw_dqs_blend(const sw_dualquat *bones, const int32_t *ids, const double *weights, int k,
                  double R[9], double t[3]) {
    double br[4] = {0, 0, 0, 0}, bd[4] = {0, 0, 0, 0};
    const double *pivot = 0;
    for (int i = 0; i < k; ++i) {
        double w = weights[i];
        if (!(w > 0)) continue; /* zero (and negative or NaN) weights do not count */
        const sw_dualquat *q = bones + ids[i];
        if (!pivot) pivot = q->r;
        /* Antipodality: q and -q are the same transform; summing them would cancel, so
         * every influence joins the hemisphere of the first one (Kavan et al. 2008 §4). */
        double dot =
            q->r[0] * pivot[0] + q->r[1] * pivot[1] + q->r[2] * pivot[2] + q->r[3] * pivot[3];
        if (dot < 0) w = -w;
        for (int j = 0; j < 4; ++j) {
            br[j] += w * q->r[j];
            bd[j] += w * q->d[j];
        }
    }
    double n2 = br[0] * br[0] + br[1] * br[1] + br[2] * br[2] + br[3] * br[3];
    if (!(n2 > 0)) { /* no influence: the identity (flipping makes |br| >= w_first > 0) */
        for (int i = 0; i < 9; ++i)
            R[i] = (i % 4 == 0) ? 1.0 : 0.0;
        t[0] = t[1] = t[2] = 0;
        return;
    }
    double inv = 1.0 / sqrt(n2);
    for (int j = 0; j < 4; ++j) {
        br[j] *= inv;
        bd[j] *= inv;
    }
    sw_quat_to_matrix(br, R);
    /* t = 2 vec(d conj(r)) = 2 (r_w d_v - d_w r_v + r_v x d_v). The part of d along r
     * (non-zero after blending) only contributes to the scalar part, which is dropped:
     * this is the projection of the blend onto the rigid transforms (Kavan §3.4). */
    t[0] = 2.0 * (br[0] * bd[1] - bd[0] * br[1] + br[2] * bd[3] - br[3] * bd[2]);
    t[1] = 2.0 * (br[0] * bd[2] - bd[0] * br[2] + br[3] * bd[1] - br[1] * bd[3]);
    t[2] = 2.0 * (br[0] * bd[3] - bd[0] * br[3] + br[1] * bd[2] - br[2] * bd[1]);
}

void sw_dqs_skin(int32_t n, const double *X, const sw_dualquat *bones, const int32_t *ids,
                 const double *weights, int k, double *x) {
    for (int32_t v = 0; v < n; ++v) {
        double R[9], t[3];
        const double *p = X + 3 * (int64_t)v;
        sw_dqs_blend(bones, ids + (int64_t)v * k, weights + (int64_t)v * k, k, R, t);
        double y0 = R[0] * p[0] + R[1] * p[1] + R[2] * p[2] + t[0];
        double y1 = R[3] * p[0] + R[4] * p[1] + R[5] * p[2] + t[1];
        double y2 = R[6] * p[0] + R[7] * p[1] + R[8] * p[2] + t[2];
        x[3 * (int64_t)v] = y0;
        x[3 * (int64_t)v + 1] = y1;
        x[3 * (int64_t)v + 2] = y2;
    }
}

/* The first root: the frame every root is measured in. */
static int32_t first_root(const int32_t *parent, int32_t nbones) {
    int32_t root = 0;
    while (root < nbones - 1 && parent[root] >= 0)
        ++root;
    return root;
}

/* L (3x3) = R_p^T R_b, p bone b's parent or (another root) the first root `root`; the
 * identity for the first root. */
static void joint_rotation(const double *T, const int32_t *parent, int32_t root, int32_t b,
                           double L[9]) {
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double *Rb = T + 12 * b;
    if (b == root) {
        memcpy(L, I, sizeof I);
        return;
    }
    const double *Rp = T + 12 * (parent[b] >= 0 ? parent[b] : root);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            L[3 * i + j] = Rp[i] * Rb[j] + Rp[3 + i] * Rb[3 + j] + Rp[6 + i] * Rb[6 + j];
}

void sw_pose_feature(const double *T, const int32_t *parent, int32_t nbones, double *feature) {
    const int32_t root = first_root(parent, nbones);
    for (int32_t b = 0; b < nbones; ++b) {
        double L[12] = {0};
        joint_rotation(T, parent, root, b, L);
        sw_dualquat dq;
        sw_dq_from_transform(L, &dq);
        /* unit: a snapped pose's rotations (sw_pose_snap) are orthonormal to 1e-8 only */
        double n =
            sqrt(dq.r[0] * dq.r[0] + dq.r[1] * dq.r[1] + dq.r[2] * dq.r[2] + dq.r[3] * dq.r[3]);
        double s = (dq.r[0] < 0 ? -1.0 : 1.0) / (n > 0 ? n : 1);
        for (int k = 0; k < 4; ++k)
            feature[4 * b + k] = s * dq.r[k];
    }
}

void sw_pose_rotation_feature(const double *T, const int32_t *parent, int32_t nbones,
                              double *feature) {
    const int32_t root = first_root(parent, nbones);
    for (int32_t b = 0; b < nbones; ++b) {
        double *L = feature + 9 * b;
        joint_rotation(T, parent, root, b, L);
        L[0] -= 1, L[4] -= 1, L[8] -= 1;
    }
    feature[9 * nbones] = 1;
}

double sw_pose_feature_bend(const double q[4]) {
    /* 2 atan2(|v|, |w|), not 2 acos(w): exact to rounding near 0 */
    double v = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    return 2.0 * atan2(v, fabs(q[0]));
}

void sw_relative_transform(const double Ta[12], const double Tb[12], double z[12]) {
    const double *Ra = Ta, *ta = Ta + 9, *Rb = Tb, *tb = Tb + 9;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            z[3 * i + j] = Ra[i] * Rb[j] + Ra[3 + i] * Rb[3 + j] + Ra[6 + i] * Rb[6 + j];
        z[9 + i] =
            Ra[i] * (tb[0] - ta[0]) + Ra[3 + i] * (tb[1] - ta[1]) + Ra[6 + i] * (tb[2] - ta[2]);
    }
}

double sw_pose_distance(const double *fa, const double *fb, int32_t nbones) {
    double d = 0;
    for (int32_t b = 0; b < nbones; ++b) {
        double c = fa[4 * b] * fb[4 * b] + fa[4 * b + 1] * fb[4 * b + 1] +
                   fa[4 * b + 2] * fb[4 * b + 2] + fa[4 * b + 3] * fb[4 * b + 3];
        d += 1.0 - c * c;
    }
    return d;
}

double sw_pose_grid(double size) {
    double g = 0x1p-24, want = size * 0x1p-24;
    if (!(size > 0) || !(size < 1e300)) return g;
    while (g > want)
        g *= 0.5;
    while (2 * g <= want)
        g *= 2;
    return g;
}

void sw_pose_snap(const double F[12], const double *T, int32_t nb, double grid, double *L) {
    double R[9], t[3]; /* F's own: F may be T_0, overwritten first */
    memcpy(R, F, sizeof R);
    memcpy(t, F + 9, sizeof t);
    for (int32_t b = 0; b < nb; ++b) {
        const double *Tb = T + 12 * (int64_t)b;
        double *Lb = L + 12 * (int64_t)b;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                Lb[3 * i + j] =
                    sw_snap(R[i] * Tb[j] + R[3 + i] * Tb[3 + j] + R[6 + i] * Tb[6 + j], 0x1p-24);
            Lb[9 + i] = sw_snap(R[i] * (Tb[9] - t[0]) + R[3 + i] * (Tb[10] - t[1]) +
                                    R[6 + i] * (Tb[11] - t[2]),
                                grid);
        }
    }
}
