/* The training poses' neighbourhood, derived from a blob's poses once when it loads
 * (sinew_blob_load) and shared read-only by all its instances: which stored poses are
 * one pose on several branches of the reference's path (twins), and how far each sample
 * lies from its nearest other one, whole pose and per pair of domains (the reach the
 * pose-space lookups fade a sample's tangential contact and equilibrium force over,
 * pose_space.h), and how far the training poses bend each joint (what the step calls
 * beyond training, sw_pose_space_beyond). They depend on the blob alone; computed per instance they
 * cost O(ntrain^2) at every creation (the robot's 290 poses: 8.5 ms of a 10 ms creation). */
#ifndef SW_BLOB_POSE_INDEX_H
#define SW_BLOB_POSE_INDEX_H

#include <stddef.h>
#include <stdint.h>

#include "blob_view.h"

typedef struct sw_pose_index {
    int32_t *twin_next; /* ntrain: the next training pose storing the same pose (a cycle
                           over its branches; itself when it has one) */
    double *reach;      /* ntrain: each pose's feature distance (its root) to the nearest
                           other pose (INFINITY when there is none) */
    double *pair_reach; /* npair_groups ntrain: per group and pose, the feature distance to
                           the group's nearest other distinct sample (INFINITY: none); NULL
                           without per-pair sections */
    double *joint_bend; /* nbones: each joint's largest bend (sw_pose_feature_bend) over the
                           training poses; 0 for a root (its turn is rigid motion) */
} sw_pose_index;

/* Bytes sw_pose_index_build needs for v (8-byte aligned parts). */
size_t sw_pose_index_bytes(const sw_blob_view *v);

/* Fills *ix in mem (sw_pose_index_bytes(v) bytes, 8-byte aligned). O(ntrain^2 (nbones +
 * 6 npair_groups)). */
void sw_pose_index_build(const sw_blob_view *v, void *mem, sw_pose_index *ix);

/* Per-pair samples whose features are closer than this share a feature (poses that
 * differ only elsewhere). */
#define SW_PAIR_SAME 1e-12

/* The Euclidean distance of two 6-coordinate pair features. */
double sw_pair_feature_distance(const double a[6], const double b[6]);

/* Links the training poses stored more than once into cycles (twin_next, ntrain). */
void sw_pose_index_link_twins(const sw_blob_view *v, int32_t *twin_next);

#endif
