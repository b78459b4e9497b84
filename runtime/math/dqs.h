/* Dual-quaternion skinning (Kavan et al. 2008), shared by the bake and the step.
 * Quaternions are (w, x, y, z). A bone's dual quaternion is built from its rigid
 * transform (12 doubles, R row-major then t, rest -> world). Blending flips every
 * influence onto the hemisphere of the first (heaviest) one before summing, so that
 * antipodal quaternions q and -q (the same rotation) never cancel. The blended dual
 * quaternion is normalised and converted to a rotation R (a proper rotation matrix)
 * and a translation t: the skinned point is R p + t. No allocation. */
#ifndef SW_DQS_H
#define SW_DQS_H

#include <math.h>
#include <stdint.h>

typedef struct sw_dualquat {
    double r[4]; /* rotation part, unit */
    double d[4]; /* dual part: 0.5 * (0, t) * r */
} sw_dualquat;

/* Dual quaternion of a rigid transform T (12). R must be a rotation (det +1). */
void sw_dq_from_transform(const double T[12], sw_dualquat *dq);

/* Unit quaternion (w, x, y, z) to a row-major rotation matrix. */
void sw_quat_to_matrix(const double q[4], double R[9]);

/* Blends k influences (bone ids into `bones`, weights >= 0; zero weights are
 * skipped) into the skinning rotation R (9, row-major) and translation t (3). When
 * the weights sum to zero the identity is returned. */
void sw_dqs_blend(const sw_dualquat *bones, const int32_t *ids, const double *weights, int k,
                  double R[9], double t[3]);

/* Skins n points: x = R_v X + t_v with each point's k influences (ids, weights:
 * k per point). */
void sw_dqs_skin(int32_t n, const double *X, const sw_dualquat *bones, const int32_t *ids,
                 const double *weights, int k, double *x);
/* Pose feature of bone transforms T (12 per bone): each bone's rotation relative to its
 * parent's as a unit quaternion (w, x, y, z), w >= 0; a root's relative to the first
 * root's, which is the identity: turning the whole pose (a character facing another way)
 * is rigid motion, not a pose (DESIGN.md §3). Writes 4 * nbones doubles. Invariant to
 * the character's placement and heading. */
void sw_pose_feature(const double *T, const int32_t *parent, int32_t nbones, double *feature);

/* The pose's joint rotations as the pose-space level's regressors (SMPL's pose feature):
 * each bone's rotation in its parent's frame (a root's in the first root's, as
 * sw_pose_feature) less the identity, 9 entries row-major a bone, then a 1. Writes
 * SW_POSE_ROTATION_FEATURES(nbones) doubles; invariant to placement and heading. */
#define SW_POSE_ROTATION_FEATURES(nbones) (9 * (nbones) + 1)
void sw_pose_rotation_feature(const double *T, const int32_t *parent, int32_t nbones,
                              double *feature);

/* The angle (radians, [0, pi]) of the rotation a pose feature's unit quaternion q holds:
 * how far the bone is bent from its rest in its parent's frame. */
double sw_pose_feature_bend(const double q[4]);

/* z = [vec(R); t] (R row-major) of Tb in Ta's frame, Ta^-1 Tb, for rigid transforms Ta, Tb
 * (12 each): the per-pair contact feature's input (bake_pairs.c, pair_space.c). */
void sw_relative_transform(const double Ta[12], const double Tb[12], double z[12]);

/* x on the grid of spacing g (a power of two), to nearest. */
static inline double sw_snap(double x, double g) {
    return nearbyint(x / g) * g;
}

/* The grid a pose's translations are snapped to for a character of rest diagonal size:
 * the power of two nearest below size 2^-24 (2^-24 for a size that is not positive). */
double sw_pose_grid(double size);

/* L_b = F^-1 T_b for each of nb bones (rigid transforms, R row-major and t), each
 * rotation entry snapped to 2^-24 and each translation to grid (sw_pose_grid): the pose as
 * the step sees it with F its bone 0 (runtime pose.c), and as the bake measures its
 * training poses' features with, so that a training pose given again is the stored one
 * bit for bit. The same bones carried by any rigid motion give F^-1 T within rounding
 * (1e-16 of the distances involved), which the grid takes to the same value except
 * within that rounding of a grid midpoint; 2^-24 of the size is an engine's float pose's
 * resolution, so nothing a host sends is lost. F may be T itself (L_0 is then the
 * identity). */
void sw_pose_snap(const double F[12], const double *T, int32_t nb, double grid, double *L);

/* Squared distance between two pose features: sum over bones of 1 - <q_a, q_b>^2
 * (0 for the same rotations, sign of each quaternion irrelevant). */
double sw_pose_distance(const double *fa, const double *fb, int32_t nbones);
#endif
