#include "pose_contact.h"

#include <stddef.h>

#include "penalty.h"

/* Pair c of set at q: its four slots' domains D and positions x (the vertex, then the
 * triangle's corners) and the gap d = sum b_i x_ti - x_p; map carries set's transforms. */
static void pair_gap(const sw_reduced *map, const sw_pair_set *set, int32_t c, const double *q,
                     const sw_blob_domain *D[4], double x[4][3], double d[3]) {
    const int32_t *cv = set->verts + 8 * (int64_t)c, *ca = set->act + 4 * (int64_t)c;
    const double *cd = set->data + 7 * (int64_t)c;
    const double coef[4] = {-1.0, cd[0], cd[1], cd[2]};
    d[0] = d[1] = d[2] = 0;
    for (int m = 0; m < 4; ++m) {
        D[m] = &map->v->domains[cv[2 * m]];
        sw_reduced_position(map, D[m], cv[2 * m + 1], ca[m], q + D[m]->q_offset, x[m], NULL);
        for (int i = 0; i < 3; ++i)
            d[i] += coef[m] * x[m][i];
    }
}

/* Self-contact pairs (blob_view.h, thesis eqs. 3.4-3.6 and §3.2.3): the nearest
 * training poses' pairs or the exhaustive mode's, each the reference's penalty
 * E = 1/2 k ka d^T N d with d = sum b_i x_ti - x_p, N = (1 - alpha) n n^T + alpha I and
 * n = R_p n_rest (alpha:
 * SW_CONTACT_ALPHA times the pose's tangential share, pose_space.c), applied
 * while the pair collides (the Heaviside of eq. 3.12: p behind the triangle along n).
 * Per pair the slots of one domain are summed into G_d = sum coef_m J_m (3 x r_d), so
 * the gradient is k ka G_d^T N d and the Hessian blocks k ka G_a^T N G_b, which may
 * couple two domains. Added after the cubature so it lands on the full (mirrored)
 * matrix. */
static double contact_pairs(sw_reduced *red, const sw_pair_set *set, const int32_t *pairs,
                            const unsigned char *skip, int32_t npairs, const double *weight,
                            const double *tangent, const double *q, int want_grad, int want_hess) {
    const sw_blob_view *v = red->v;
    double E = 0;
    int32_t rm = red->rmax;
    sw_reduced map = *red; /* the same map with the set's skinning transforms */
    map.act_R = (double *)set->act_R;
    map.act_t = (double *)set->act_t;
    for (int32_t p = 0; p < npairs; ++p) {
        if (skip && skip[p]) continue; /* a condensation patch's (condense.h) */
        const int32_t c = pairs ? pairs[p] : p;
        const int32_t *cv = set->verts + 8 * (int64_t)c, *ca = set->act + 4 * (int64_t)c;
        const double *cd = set->data + 7 * (int64_t)c;
        const double coef[4] = {-1.0, cd[0], cd[1], cd[2]};
        const sw_blob_domain *D[4];
        double x[4][3], d[3];
        pair_gap(&map, set, c, q, D, x, d);
        const double *Rp = set->act_R + 9 * (int64_t)ca[0];
        double n[3];
        for (int i = 0; i < 3; ++i)
            n[i] = Rp[3 * i] * cd[3] + Rp[3 * i + 1] * cd[4] + Rp[3 * i + 2] * cd[5];
        if (!(sw_penalty_gap(n, d) > 0)) continue;
        const double al = (tangent ? tangent[p] : 1) * SW_CONTACT_ALPHA;
        double kk = (weight ? weight[p] : 1) * v->contact_k * cd[6], Nd[3];
        sw_penalty_apply_N(n, al, d, Nd);
        E += sw_penalty_energy(kk, d, Nd);
        if (!want_grad) continue;
        /* the Jacobians of a pair in contact only (most pairs of a pose are apart) */
        for (int m = 0; m < 4; ++m)
            sw_reduced_jacobian(&map, D[m], cv[2 * m + 1], ca[m], red->Jc + 3 * m * rm);
        /* G per distinct domain (slot `lead[m]` holds the sum of its domain's slots) */
        int lead[4], nlead = 0, leads[4];
        for (int m = 0; m < 4; ++m) {
            int32_t r = D[m]->rank;
            double *Jm = red->Jc + 3 * m * rm;
            lead[m] = m;
            for (int l = 0; l < nlead; ++l)
                if (D[leads[l]] == D[m]) lead[m] = leads[l];
            if (lead[m] == m) {
                leads[nlead++] = m;
                for (int32_t j = 0; j < 3 * r; ++j)
                    Jm[j] *= coef[m];
            } else {
                double *Jl = red->Jc + 3 * lead[m] * rm;
                for (int32_t j = 0; j < 3 * r; ++j)
                    Jl[j] += coef[m] * Jm[j];
            }
        }
        for (int l = 0; l < nlead; ++l) {
            const sw_blob_domain *Dl = D[leads[l]];
            int32_t r = Dl->rank;
            const double *G = red->Jc + 3 * leads[l] * rm;
            double *P = red->hc + 3 * l * rm; /* N G */
            for (int32_t j = 0; j < r; ++j) {
                double col[3] = {G[j], G[r + j], G[2 * r + j]}, Ncol[3];
                sw_penalty_apply_N(n, al, col, Ncol);
                for (int i = 0; i < 3; ++i)
                    P[i * r + j] = Ncol[i];
                red->g[Dl->q_offset + j] +=
                    kk * (G[j] * Nd[0] + G[r + j] * Nd[1] + G[2 * r + j] * Nd[2]);
            }
        }
        if (!want_hess) continue;
        for (int a = 0; a < nlead; ++a)
            for (int b = 0; b < nlead; ++b) {
                const sw_blob_domain *Da = D[leads[a]], *Db = D[leads[b]];
                int32_t ra = Da->rank, rb = Db->rank;
                const double *Ga = red->Jc + 3 * leads[a] * rm, *Pb = red->hc + 3 * b * rm;
                sw_reduced_mark(red, Da, Db);
                for (int32_t i = 0; i < ra; ++i) {
                    double *Hi = red->H + (int64_t)(Da->q_offset + i) * red->R + Db->q_offset;
                    double g0 = kk * Ga[i], g1 = kk * Ga[ra + i], g2 = kk * Ga[2 * ra + i];
                    for (int32_t j = 0; j < rb; ++j)
                        Hi[j] += g0 * Pb[j] + g1 * Pb[rb + j] + g2 * Pb[2 * rb + j];
                }
            }
    }
    return E;
}

void sw_contact_pair_point(const sw_reduced *red, const sw_pair_set *set, int32_t c,
                           const double *q, double x[3], double n[3]) {
    sw_reduced map = *red; /* the same map with the set's skinning transforms */
    map.act_R = (double *)set->act_R;
    map.act_t = (double *)set->act_t;
    const sw_blob_domain *D[4];
    double xs[4][3], d[3];
    pair_gap(&map, set, c, q, D, xs, d);
    const double *cd = set->data + 7 * (int64_t)c;
    const double *Rp = set->act_R + 9 * (int64_t)set->act[4 * (int64_t)c];
    for (int i = 0; i < 3; ++i) {
        x[i] = xs[0][i];
        n[i] = Rp[3 * i] * cd[3] + Rp[3 * i + 1] * cd[4] + Rp[3 * i + 2] * cd[5];
    }
}

sw_pair_set sw_pose_pair_set(const sw_reduced *red) {
    const sw_blob_view *v = red->v;
    sw_pair_set set = {v->contact_verts, v->contact_data, red->contact_act, red->act_R, red->act_t};
    return set;
}

double sw_contact_pairs_eval(sw_reduced *red, const sw_pair_set *set, const int32_t *ids,
                             const unsigned char *skip, int32_t n, const double *weight,
                             const double *tangent, const double *q, int want_grad, int want_hess) {
    return contact_pairs(red, set, ids, skip, n, weight, tangent, q, want_grad, want_hess);
}

/* The pairs the pose space gathered, each at its weight: the pose-space blend (DESIGN.md
 * §8, thesis §3.2.3: the two schemes' forces interpolated) times its cubature weight. */
double sw_pose_contact_eval(sw_reduced *red, const sw_pose_space *ps, const double *q,
                            int want_grad, int want_hess) {
    if (ps->npairs == 0) return 0;
    sw_pair_set set = sw_pose_pair_set(red);
    return contact_pairs(red, &set, ps->pairs, ps->in_patch, ps->npairs, ps->pair_w, ps->pair_tan,
                         q, want_grad, want_hess);
}

/* Whether the pair's vertex lies farther from its contact point on the triangle than
 * SW_PAIR_APART times the triangle's longest edge over 1 - share (x, d from pair_gap). */
static int pair_apart(double x[4][3], const double d[3], double share) {
    double e2 = 0;
    for (int a = 1; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
            double l[3] = {x[a][0] - x[b][0], x[a][1] - x[b][1], x[a][2] - x[b][2]};
            double l2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            if (l2 > e2) e2 = l2;
        }
    double f = 1 - share;
    return (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * f * f > SW_PAIR_APART * SW_PAIR_APART * e2;
}

int32_t sw_pose_contacts_drop_apart(sw_pose_space *ps, const sw_reduced *red, const double *q) {
    sw_pair_set set = sw_pose_pair_set(red);
    int32_t kept = 0;
    for (int32_t i = 0; i < ps->npairs; ++i) {
        const sw_blob_domain *D[4];
        double x[4][3], d[3];
        pair_gap(red, &set, ps->pairs[i], q, D, x, d);
        if (pair_apart(x, d, ps->pair_tan[i])) continue;
        ps->pairs[kept] = ps->pairs[i];
        ps->pair_w[kept] = ps->pair_w[i];
        ps->pair_tan[kept++] = ps->pair_tan[i];
    }
    int32_t apart = ps->npairs - kept;
    ps->npairs = kept;
    return apart;
}
