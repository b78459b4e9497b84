#include "pose_space.h"

#include <math.h>
#include <string.h>

#include "dqs.h"

/* The tangential share of a training pose's pairs at feature distance s (its root) from
 * it: the pairs' contact points and normals are the reference's at that pose, frozen
 * where it detected them (selfcontact.h). Along the normal they stay a sound law at other
 * poses; the tangential spring alpha |d_t|^2 pulls p towards a contact point the
 * reference would have found elsewhere, and (eq. 3.12's Heaviside) it jumps into the
 * energy wherever a pair starts to collide with |d_t| > 0, which the energy guard
 * cannot descend through. With the whole term off everywhere (alpha 0) the held-out
 * errors fall but the training errors rise: at its own pose the term is the reference's.
 * So it fades from 1 there to 0 at the nearest other sample, where that sample's pairs
 * take over (figures: docs/notes/runtime-constants.md). */
double sw_pose_space_tangent_share(double s, double reach) {
    return s >= reach ? 0.0 : 1.0 - s / reach; /* reach INFINITY: 1 */
}

void sw_pose_space_reset(sw_pose_space *ps, int32_t nbones) {
    ps->nearest = ps->second = -1;
    ps->blend = 0;
    ps->d_nearest = ps->d_last = INFINITY;
    ps->tangent[0] = ps->tangent[1] = 0;
    ps->looked_up = 0; /* no motion yet: a pose on two branches takes the first stored */
    memset(ps->motion, 0, 4 * (size_t)nbones * sizeof(double));
    ps->npairs = ps->dropped = ps->novel = 0;
}

/* Training pose t is stored on the branch cycle of u (the same pose: the bake stores a
 * pose once per branch of the reference's path, twin_next). */
static int same_pose(const sw_pose_space *ps, int32_t t, int32_t u) {
    if (u < 0) return 0;
    int32_t w = u;
    do {
        if (w == t) return 1;
        w = ps->twin_next[w];
    } while (w != u);
    return 0;
}

/* Of the branches stored for training pose `rep`, the one the instance is on. The
 * bake solved the training poses in the order it stored them, each from the one before
 * (a path, blob_view.h), so a stored pose's arrival direction is its feature minus
 * its predecessor's: on the way into a bend or on the way out. The branch whose
 * arrival is most aligned with the instance's own last motion wins (the first stored
 * on a tie, e.g. before the pose ever moved): a fold that buckled while the joint
 * bent stays buckled while it unbends. */
int32_t sw_pose_space_branch(const sw_pose_space *ps, const sw_blob_view *v, int32_t rep) {
    size_t f = (size_t)4 * v->nbones;
    int32_t best = rep, t = rep;
    double best_s = -INFINITY;
    do { /* rep's branches, from rep round its cycle */
        double s = 0, n = 0;
        for (size_t i = 0; t > 0 && i < f; ++i) {
            double a = v->train_pose[f * t + i] - v->train_pose[f * (t - 1) + i];
            s += a * ps->motion[i];
            n += a * a;
        }
        s = n > 0 ? s / sqrt(n) : 0;
        if (s > best_s || (s == best_s && t < best)) best_s = s, best = t;
        t = ps->twin_next[t];
    } while (t != rep);
    return best;
}

/* The two training poses nearest to the current pose (feature distance) and the
 * pose-space blend weight of the second (DESIGN.md §8: one sample when the nearest is
 * within 1e-3 or the second is more than 4 times as far, else a blend by distance).
 * A pose stored on several branches counts once; the instance's motion picks the
 * branch (sw_pose_space_branch). Sets ps->nearest (-1 without training poses), ps->second and
 * ps->blend. */
void sw_pose_space_lookup(sw_pose_space *ps, const sw_blob_view *v, const double *T) {
    int32_t n0 = -1, n1 = -1;
    ps->nearest = ps->second = -1;
    ps->blend = 0;
    ps->d_nearest = ps->d_last = INFINITY;
    ps->tangent[0] = ps->tangent[1] = 0;
    if (v->ntrain < 1) return;
    sw_pose_feature(T, v->bone_parent, v->nbones, ps->feature);
    double d0 = INFINITY, d1 = INFINITY;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        double d =
            sw_pose_distance(ps->feature, v->train_pose + (size_t)4 * v->nbones * t, v->nbones);
        if ((d == d0 && same_pose(ps, t, n0)) || (d == d1 && same_pose(ps, t, n1))) continue;
        if (d < d0) {
            d1 = d0, n1 = n0;
            d0 = d, n0 = t;
        } else if (d < d1) {
            d1 = d, n1 = t;
        }
    }
    if (n0 < 0) return; /* no distance comparable (NaN: only a hostile blob's poses) */
    ps->d_nearest = d0;
    if (ps->looked_up) ps->d_last = sw_pose_distance(ps->feature, ps->feature_last, v->nbones);
    /* the feature distance is sum (1 - cos^2(theta_b / 2)): its root is linear in the
       angles for small ones */
    double s0 = sqrt(fmax(d0, 0)), s1 = sqrt(fmax(d1, 0)); /* (rounding: d0 ~ -1e-17 at a sample) */
    if (n1 >= 0 && s0 >= 1e-3 && s1 <= 4 * s0) ps->blend = s0 / (s0 + s1);
    ps->tangent[0] = sw_pose_space_tangent_share(s0, ps->reach[n0]);
    ps->tangent[1] = n1 >= 0 ? sw_pose_space_tangent_share(s1, ps->reach[n1]) : 0;
    /* the last motion: kept while the pose holds still, so a pause does not switch branch */
    size_t f = (size_t)4 * v->nbones;
    double moved = 0;
    for (size_t i = 0; i < f; ++i)
        moved += fabs(ps->feature[i] - ps->feature_last[i]);
    if (moved > 1e-9 && ps->looked_up)
        for (size_t i = 0; i < f; ++i)
            ps->motion[i] = ps->feature[i] - ps->feature_last[i];
    memcpy(ps->feature_last, ps->feature, f * sizeof(double));
    ps->looked_up = 1;
    ps->nearest = sw_pose_space_branch(ps, v, n0);
    ps->second = ps->blend > 0 ? sw_pose_space_branch(ps, v, n1) : n1;
}

static const double RAD_PER_DEG = 0.017453292519943295;

int sw_joint_beyond_training(double bend, double trained) {
    return bend > SW_BEYOND_RATIO * trained && bend - trained > SW_BEYOND_DEG * RAD_PER_DEG;
}

int32_t sw_pose_space_beyond(const sw_pose_space *ps, const sw_blob_view *v, int32_t *bone,
                             double *excess) {
    int32_t n = 0;
    *bone = -1;
    *excess = 0;
    if (v->ntrain < 1 || !ps->joint_bend) return 0;
    for (int32_t b = 0; b < v->nbones; ++b) {
        if (v->bone_parent[b] < 0) continue;
        double bend = sw_pose_feature_bend(ps->feature + 4 * b), trained = ps->joint_bend[b];
        if (!sw_joint_beyond_training(bend, trained)) continue;
        ++n;
        double deg = (bend - trained) / RAD_PER_DEG;
        if (deg > *excess) *excess = deg, *bone = b;
    }
    return n;
}

void sw_pose_space_add_pair(sw_pose_space *ps, int32_t c, double w, double tan) {
    if (ps->npairs == ps->max_pairs) {
        ps->dropped++;
        return;
    }
    ps->pair_w[ps->npairs] = w;
    ps->pair_tan[ps->npairs] = tan;
    ps->pairs[ps->npairs++] = c;
}

void sw_pose_space_gather_pairs(sw_pose_space *ps, const sw_blob_view *v) {
    ps->npairs = ps->dropped = ps->novel = 0;
    if (ps->nearest < 0) return;
    for (int32_t c = v->contact_ptr[ps->nearest]; c < v->contact_ptr[ps->nearest + 1]; ++c)
        sw_pose_space_add_pair(ps, c, 1 - ps->blend, ps->tangent[0]);
    if (ps->blend > 0)
        for (int32_t c = v->contact_ptr[ps->second]; c < v->contact_ptr[ps->second + 1]; ++c)
            sw_pose_space_add_pair(ps, c, ps->blend, ps->tangent[1]);
}

int32_t sw_pose_space_default_max_pairs(const sw_blob_view *v) {
    int32_t a = 0, b = 0; /* the largest and second largest counts */
    for (int32_t t = 0; t < v->ntrain; ++t) {
        int32_t n = v->contact_ptr[t + 1] - v->contact_ptr[t];
        if (n > a)
            b = a, a = n;
        else if (n > b)
            b = n;
    }
    return a + b;
}

double sw_pose_space_force(const sw_pose_space *ps, int32_t R, const double *q, double *g) {
    if (!ps->force || ps->nearest < 0) return 0;
    const double w0 = (1 - ps->blend) * ps->tangent[0];
    const double w1 = ps->blend > 0 ? ps->blend * ps->tangent[1] : 0;
    const double *b0 = ps->force + (size_t)R * ps->nearest;
    const double *b1 = w1 > 0 ? ps->force + (size_t)R * ps->second : b0;
    double phi = 0;
    for (int32_t i = 0; i < R; ++i) {
        const double b = w0 * b0[i] + w1 * b1[i];
        phi += b * q[i];
        if (g) g[i] += b;
    }
    return phi;
}

void sw_pose_space_blend(const sw_pose_space *ps, const double *rows, int32_t m, double *out) {
    if (ps->nearest < 0) {
        memset(out, 0, (size_t)m * sizeof(double));
        return;
    }
    const double *r0 = rows + (size_t)m * ps->nearest;
    const double *r1 = rows + (size_t)m * (ps->blend == 0 ? ps->nearest : ps->second);
    const double b = ps->blend;
    for (int32_t j = 0; j < m; ++j)
        out[j] = b == 0 ? r0[j] : (1 - b) * r0[j] + b * r1[j];
}

void sw_pose_space_take(sw_mem_plan *p, const sw_blob_view *v, int32_t max_pairs, int with_mask,
                        sw_pose_space *ps) {
    const uint64_t nb = (uint64_t)v->nbones, nd = (uint64_t)v->ndomains;
    SW_PLAN_TAKE(p, ps->feature, 4 * nb);
    SW_PLAN_TAKE(p, ps->feature_last, 4 * nb);
    SW_PLAN_TAKE(p, ps->motion, 4 * nb);
    SW_PLAN_TAKE(p, ps->pairs, (uint64_t)max_pairs);
    SW_PLAN_TAKE(p, ps->pair_w, (uint64_t)max_pairs);
    SW_PLAN_TAKE(p, ps->pair_tan, (uint64_t)max_pairs);
    ps->novel_mask = NULL;
    if (with_mask) SW_PLAN_TAKE(p, ps->novel_mask, nd * nd);
}
