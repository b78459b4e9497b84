/* Pose-space self-contact per pair of domains (thesis §3.2.3, DESIGN.md §4.4 and §8): the
 * contact of a knuckle depends on its two neighbouring bones, not on the whole skeleton,
 * so each group (domain a's vertices against domain b's triangles) looks up its own two
 * nearest training samples by its own 6-coordinate feature (the uncentred PCA of b's
 * surface in a's frame, blob_view.h), and applies their cubature pairs: poses the bake
 * never saw together still find a close sample for every pair. A group of a domain
 * against itself has no relative motion to tell poses apart and takes the whole pose's
 * nearest samples (pose_space.c). */
#include <math.h>
#include <string.h>

#include "blob_pose_index.h"
#include "dqs.h"
#include "pose_space.h"

void sw_pair_space_feature(const sw_blob_view *v, int32_t g, const double *T, double c[6]) {
    const int32_t a = v->domains[v->pair_domains[2 * g]].bone,
                  b = v->domains[v->pair_domains[2 * g + 1]].bone;
    double z[12];
    sw_relative_transform(T + 12 * a, T + 12 * b, z);
    const double *M = v->pair_map + 72 * (int64_t)g;
    for (int k = 0; k < 6; ++k) {
        double acc = 0;
        for (int j = 0; j < 12; ++j)
            acc += M[12 * k + j] * z[j];
        c[k] = acc;
    }
}

/* Appends the pairs of weight > 0 of training pose t in group g, each at w times its
 * cubature weight, while the budget lasts. */
static void gather_group(sw_pose_space *ps, const sw_blob_view *v, int32_t g, int32_t t, double w,
                         double tan) {
    const int64_t i = (int64_t)t * v->npair_groups + g;
    for (int32_t c = v->pair_ptr[i]; c < v->pair_ptr[i + 1]; ++c)
        if (v->pair_weight[c] > 0) sw_pose_space_add_pair(ps, c, w * v->pair_weight[c], tan);
}

void sw_pair_space_gather(sw_pose_space *ps, const sw_blob_view *v, const double *T) {
    ps->npairs = ps->dropped = ps->novel = 0;
    if (ps->novel_mask) memset(ps->novel_mask, 0, (size_t)v->ndomains * (size_t)v->ndomains);
    if (ps->nearest < 0) return;
    const int32_t nt = v->ntrain;
    for (int32_t g = 0; g < v->npair_groups; ++g) {
        if (v->pair_domains[2 * g] == v->pair_domains[2 * g + 1]) { /* the whole pose's */
            gather_group(ps, v, g, ps->nearest, 1 - ps->blend, ps->tangent[0]);
            if (ps->blend > 0) gather_group(ps, v, g, ps->second, ps->blend, ps->tangent[1]);
            continue;
        }
        double c[6], d0 = INFINITY, d1 = INFINITY;
        int32_t n0 = -1, n1 = -1;
        sw_pair_space_feature(v, g, T, c);
        const double *F = v->pair_feature + 6 * (int64_t)g * nt;
        /* Samples within SW_PAIR_SAME of each other share a feature (poses that differ only
           elsewhere) but not their pairs: of those the first stored is taken, whatever the
           rounding of the feature, which changes with the character's heading. */
        for (int32_t t = 0; t < nt; ++t) {
            double d = sw_pair_feature_distance(c, F + 6 * (int64_t)t);
            if (d < d0 - SW_PAIR_SAME) {
                d1 = d0, n1 = n0;
                d0 = d, n0 = t;
            } else if (d - d0 > SW_PAIR_SAME && d < d1 - SW_PAIR_SAME) {
                d1 = d, n1 = t;
            }
        }
        const double size =
            sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3] + c[4] * c[4] + c[5] * c[5]);
        /* no sample near: exhaustive detection instead. None comparable at all (a hostile
           blob's feature basis can make every distance NaN): nothing to gather either. */
        if (n0 < 0 || !(d0 <= SW_PAIR_NOVEL * size)) {
            ps->novel++;
            if (ps->novel_mask)
                ps->novel_mask[v->pair_domains[2 * g] * v->ndomains + v->pair_domains[2 * g + 1]] =
                    1;
            if (ps->novel_mask || n0 < 0) continue;
        }
        double blend = 0;
        if (n1 >= 0 && d0 >= 1e-3 * size && d1 <= 4 * d0) blend = d0 / (d0 + d1);
        n0 = sw_pose_space_branch(ps, v, n0);
        gather_group(ps, v, g, n0, 1 - blend,
                     sw_pose_space_tangent_share(d0, ps->pair_reach[g * (int64_t)nt + n0]));
        if (blend > 0) {
            n1 = sw_pose_space_branch(ps, v, n1);
            gather_group(ps, v, g, n1, blend,
                         sw_pose_space_tangent_share(d1, ps->pair_reach[g * (int64_t)nt + n1]));
        }
    }
}

int32_t sw_pair_space_default_max_pairs(const sw_blob_view *v) {
    int64_t total = 0;
    for (int32_t g = 0; g < v->npair_groups; ++g) {
        int32_t a = 0, b = 0; /* the fullest and second fullest samples */
        for (int32_t t = 0; t < v->ntrain; ++t) {
            const int64_t i = (int64_t)t * v->npair_groups + g;
            int32_t n = 0;
            for (int32_t c = v->pair_ptr[i]; c < v->pair_ptr[i + 1]; ++c)
                n += v->pair_weight[c] > 0;
            if (n > a)
                b = a, a = n;
            else if (n > b)
                b = n;
        }
        total += a + b;
    }
    return (int32_t)(total < v->ncontacts ? total : v->ncontacts);
}
