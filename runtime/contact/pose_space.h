/* The pose space of the step (thesis §3.2.3, DESIGN.md §8): the training poses nearest
 * to the current pose by their pose feature, the blend weight between the two nearest,
 * the branch a pose stored twice is on, and the pose-space contact pairs those poses
 * bring into this step (under the instance's budget). */
#ifndef SW_POSE_SPACE_H
#define SW_POSE_SPACE_H

#include <stdint.h>

#include "blob_view.h"
#include "mem_plan.h"

typedef struct sw_pose_space {
    double *feature;      /* 4 nbones: the current pose's feature */
    double *feature_last; /* 4 nbones: the pose feature of the last lookup */
    double *motion;       /* 4 nbones: the last change of pose between two lookups */
    /* the blob's pose index (blob_pose_index.h): twins, each pose's reach, and each
       joint's largest bend in training (nbones; sw_pose_space_beyond) */
    const int32_t *twin_next;
    const double *reach;
    const double *joint_bend;
    int looked_up;   /* feature_last holds a pose */
    int32_t nearest; /* training pose nearest to the current pose, or -1 */
    int32_t second;  /* the second nearest, or -1 */
    double blend;    /* pose-space weight of `second` (0: `nearest` alone) */
    /* feature distances of the current pose to `nearest` and to the last lookup's pose
       (INFINITY without one) */
    double d_nearest, d_last;
    /* the share of the contact law's tangential term (SW_CONTACT_ALPHA) that the pairs of
       `nearest` [0] and of `second` [1] carry: 1 at their own training pose, falling
       linearly to 0 at the distance of its nearest other pose (sw_pose_space_lookup) */
    double tangent[2];
    /* the contact pairs in use, pairs[0, npairs): the nearest pose's, then the second's
       (when blended), or in per-pair mode (sw_pair_space_gather) each group's nearest
       sample's, then its second's, group after group; per pair, its weight (pose-space
       blend times cubature weight) and its share of the tangential term */
    int32_t *pairs;    /* max_pairs contact ids */
    double *pair_w;    /* max_pairs */
    double *pair_tan;  /* max_pairs */
    int32_t max_pairs; /* the budget: at most this many pairs a step */
    int32_t npairs;
    int32_t dropped; /* pairs the budget left out this step */
    /* per-pair mode (the blob's pair groups, pair_space.c): the pose index's per-group
       reach (blob_pose_index.h); NULL in whole-pose mode */
    const double *pair_reach;
    int32_t novel; /* groups whose nearest sample was farther than SW_PAIR_NOVEL this step */
    /* ndomains^2: 1 for the pairs of domains (a, b) novel this step, whose contact the
       exhaustive detection finds instead (NULL: no fallback, the nearest sample's pairs
       stay in use) */
    unsigned char *novel_mask;
    /* per pairs[] entry: 1 when a condensation patch evaluates the pair with its full-space
       positions instead (condense.h); NULL: none does */
    const unsigned char *in_patch;
    /* the blob's pose-space equilibrium forces (sw_blob_view.train_force) when the step
       applies them (sw_pose_space_force), else NULL */
    const double *force;
} sw_pose_space;

/* Lays out the pose features and the pair budget, and the novel-pair mask of a step that
 * detects (with_mask). */
void sw_pose_space_take(sw_mem_plan *p, const sw_blob_view *v, int32_t max_pairs, int with_mask,
                        sw_pose_space *ps);

/* Forgets the pose history: no motion, no nearest pose. */
void sw_pose_space_reset(sw_pose_space *ps, int32_t nbones);

/* Finds the two nearest training poses of the pose T (12 per bone) and the blend
 * weight, and updates the pose motion. Sets nearest (-1 without training poses), second,
 * blend and tangent. O(ntrain nbones). */
void sw_pose_space_lookup(sw_pose_space *ps, const sw_blob_view *v, const double *T);

/* The blend of the training poses the last lookup found, (1 - blend) on the nearest and
 * blend on the second, of `rows` (m per training pose: the reduced solutions, say) into
 * out (m); zeros when the blob has no training pose. */
void sw_pose_space_blend(const sw_pose_space *ps, const double *rows, int32_t m, double *out);

/* A joint is bent beyond training when its bend (radians) exceeds the largest a training
 * pose gives it (trained) by more than SW_BEYOND_RATIO times and SW_BEYOND_DEG degrees:
 * there the subspace extrapolates (docs/notes/generalisation.md "The Fox's Run is beyond
 * its training"). The one rule of the bake's
 * held-out list (sw_bake_beyond_training) and the step's stat. */
#define SW_BEYOND_RATIO 1.25
#define SW_BEYOND_DEG 5.0
int sw_joint_beyond_training(double bend, double trained);

/* After sw_pose_space_lookup: how many joints the current pose bends beyond training
 * (0 without training poses), the one furthest beyond (*bone, -1: none) and by how many
 * degrees (*excess, 0: none). O(nbones). */
int32_t sw_pose_space_beyond(const sw_pose_space *ps, const sw_blob_view *v, int32_t *bone,
                             double *excess);

/* Collects the contact pairs of the poses the lookup found into ps->pairs, the nearest
 * pose's first, at most max_pairs; sets npairs and dropped. */
void sw_pose_space_gather_pairs(sw_pose_space *ps, const sw_blob_view *v);

/* Appends contact c to the pairs in use at weight w and tangential share tan, or counts
 * it in ps->dropped when the budget is spent (both modes' gathering). */
void sw_pose_space_add_pair(sw_pose_space *ps, int32_t c, double w, double tan);

/* The share of the tangential term the pairs of a training sample carry at feature
 * distance s from it, reach its distance to its nearest other sample (pose_space.c). */
double sw_pose_space_tangent_share(double s, double reach);

/* The pose-space equilibrium force's potential b . q, b = sum over the two nearest poses k
 * of (pose-space weight) (locality share, `tangent`) b_k, whose gradient b it adds to g
 * (R; NULL: none). The reduced model's own equilibrium at a training pose misses the
 * reference's (the Galerkin minimum is not the projection); b_t, stored by the bake,
 * is the force that closes that gap at pose t, and between poses it is interpolated as
 * the thesis interpolates its per-pose contact cubatures (§3.2.3, after Pose Space
 * Deformation [83]); it fades with the share as a pose leaves its samples. 0 without
 * ps->force or a nearest pose. O(R). */
double sw_pose_space_force(const sw_pose_space *ps, int32_t R, const double *q, double *g);

/* The default pair budget: the pairs of the two training poses that hold the most. */
int32_t sw_pose_space_default_max_pairs(const sw_blob_view *v);

/* Of the branches stored for training pose t (twin_next), the one the instance's last
 * motion is on (t itself when it has one). */
int32_t sw_pose_space_branch(const sw_pose_space *ps, const sw_blob_view *v, int32_t t);

/* Per-pair mode (pair_space.c): a group whose nearest sample is farther than this
 * (relative feature distance, DESIGN.md §8) is novel contact. */
#define SW_PAIR_NOVEL 0.5

/* Group g's feature of the bone transforms T (12 per bone): pair_map times the relative
 * transform [vec(R); t] of its second domain's bone in its first's frame. */
void sw_pair_space_feature(const sw_blob_view *v, int32_t g, const double *T, double c[6]);

/* Per-pair mode: every group's two nearest samples by its own feature of the pose T (a
 * domain against itself: the whole pose's, after sw_pose_space_lookup), blended by
 * distance (DESIGN.md §8), and their pairs of weight > 0 into ps->pairs with pair_w
 * (blend times cubature weight) and pair_tan, at most max_pairs; sets npairs, dropped
 * and novel. A group with no sample within SW_PAIR_NOVEL is novel: with novel_mask it is
 * marked there and brings no pairs (the exhaustive detection's take its place). O(npair_groups
 * ntrain + pairs). */
void sw_pair_space_gather(sw_pose_space *ps, const sw_blob_view *v, const double *T);

/* The per-pair mode's budget: per group, its two fullest samples' pairs of weight > 0. */
int32_t sw_pair_space_default_max_pairs(const sw_blob_view *v);

#endif
