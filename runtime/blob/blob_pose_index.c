#include "blob_pose_index.h"

#include <math.h>

#include "dqs.h"

/* twin_next: links the training poses stored more than once (one per branch of the
 * reference's path: on its return path a fold that buckled on the way in may stay
 * buckled on the way out) into cycles in stored order. Each pose joins the cycle of the
 * first earlier pose u within 1e-14 of it, just before u (the cycle's end: u is its first
 * on any honest blob, where twins are equal poses). "Within 1e-14" is not transitive on a
 * hostile blob, and walking a chain that is not a cycle (sw_pose_space_branch,
 * same_pose) would never end; built this way every pose is on exactly one cycle whatever
 * the poses are. */
void sw_pose_index_link_twins(const sw_blob_view *v, int32_t *twin_next) {
    size_t f = (size_t)4 * v->nbones;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        twin_next[t] = t;
        for (int32_t u = 0; u < t; ++u) {
            if (!(sw_pose_distance(v->train_pose + f * t, v->train_pose + f * u, v->nbones) <=
                  1e-14))
                continue;
            int32_t last = u; /* the cycle's last pose: the one before its first */
            while (twin_next[last] != u)
                last = twin_next[last];
            twin_next[t] = u;
            twin_next[last] = t;
            break;
        }
    }
}

static void pose_reach(const sw_blob_view *v, double *reach) {
    size_t f = (size_t)4 * v->nbones;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        double best = INFINITY;
        for (int32_t u = 0; u < v->ntrain; ++u) {
            double d = sw_pose_distance(v->train_pose + f * t, v->train_pose + f * u, v->nbones);
            if (d > 1e-14 && d < best) best = d; /* (twins: link_twins' threshold) */
        }
        reach[t] = sqrt(best);
    }
}

double sw_pair_feature_distance(const double a[6], const double b[6]) {
    double d = 0;
    for (int k = 0; k < 6; ++k)
        d += (a[k] - b[k]) * (a[k] - b[k]);
    return sqrt(d);
}

static void pair_reach(const sw_blob_view *v, double *reach) {
    const int32_t T = v->ntrain;
    for (int32_t g = 0; g < v->npair_groups; ++g)
        for (int32_t t = 0; t < T; ++t) {
            const double *ft = v->pair_feature + 6 * ((int64_t)g * T + t);
            double best = INFINITY;
            for (int32_t u = 0; u < T; ++u) {
                double d = sw_pair_feature_distance(ft, v->pair_feature + 6 * ((int64_t)g * T + u));
                if (d > SW_PAIR_SAME && d < best) best = d;
            }
            reach[(int64_t)g * T + t] = best;
        }
}

static void joint_bend(const sw_blob_view *v, double *bend) {
    for (int32_t b = 0; b < v->nbones; ++b) {
        bend[b] = 0;
        if (v->bone_parent[b] < 0) continue;
        for (int32_t t = 0; t < v->ntrain; ++t)
            bend[b] = fmax(bend[b],
                           sw_pose_feature_bend(v->train_pose + 4 * ((size_t)v->nbones * t + b)));
    }
}

/* Parts in mem: reach (ntrain doubles), pair_reach (npair_groups ntrain doubles),
 * joint_bend (nbones doubles), then twin_next (ntrain int32): the doubles first keep every
 * part 8-byte aligned. */
size_t sw_pose_index_bytes(const sw_blob_view *v) {
    const size_t T = (size_t)v->ntrain, G = (size_t)v->npair_groups, B = (size_t)v->nbones;
    return sizeof(double) * (T + G * T + B) + sizeof(int32_t) * T;
}

void sw_pose_index_build(const sw_blob_view *v, void *mem, sw_pose_index *ix) {
    const size_t T = (size_t)v->ntrain, G = (size_t)v->npair_groups, B = (size_t)v->nbones;
    double *d = mem;
    ix->reach = d;
    ix->pair_reach = G > 0 ? d + T : NULL;
    ix->joint_bend = d + T + G * T;
    ix->twin_next = (int32_t *)(void *)(d + T + G * T + B);
    sw_pose_index_link_twins(v, ix->twin_next);
    pose_reach(v, ix->reach);
    if (ix->pair_reach) pair_reach(v, ix->pair_reach);
    joint_bend(v, ix->joint_bend);
}
