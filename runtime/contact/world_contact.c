#include "world_contact.h"

#include <math.h>
#include <string.h>

#include "collision.h"
#include "dqs.h"
#include "vec3.h"

/* ---- creation ------------------------------------------------------------------- */

void sw_world_contacts_build(sw_world_contacts *wc, const sw_blob_view *v,
                             const sw_surface_clusters *cl) {
    wc->ncl = cl->ncl;
    wc->cl_begin = cl->cl_begin;
    wc->cl_copy = cl->cl_copy;
    wc->cl_bones = cl->cl_bones;
    wc->cl_bone0 = cl->cl_bone0;
    wc->copy_area = cl->copy_area;
    wc->dom_umax = cl->dom_umax;
    for (int32_t i = 0; i < v->nsurf_copies; ++i)
        wc->copy_first[i] = -1;
    wc->boxes_valid = 0;
    wc->ncand = 0;
}

/* ---- detection ------------------------------------------------------------------- */

/* Each bone's rigid motion since the last output, D = T1 T0^-1 (12 doubles: R row-major,
 * t), once per detection into wc->bone_motion. */
void sw_world_clusters_motion(sw_world_contacts *wc, int32_t nbones, const double *T,
                              const double *T0) {
    for (int32_t b = 0; b < nbones; ++b) {
        const double *A = T0 + 12 * b, *B = T + 12 * b;
        double *D = wc->bone_motion + 12 * b;
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) {
                double acc = 0;
                for (int j = 0; j < 3; ++j)
                    acc += B[3 * r + j] * A[3 * k + j]; /* R1 R0^T */
                D[3 * r + k] = acc;
            }
        for (int r = 0; r < 3; ++r) { /* t = t1 - dR t0 */
            double acc = B[9 + r];
            for (int k = 0; k < 3; ++k)
                acc -= D[3 * r + k] * A[9 + k];
            D[9 + r] = acc;
        }
    }
}

static int boxes_overlap(const double a[6], const double b[6]) {
    for (int k = 0; k < 3; ++k)
        if (a[k] > b[3 + k] || b[k] > a[3 + k]) return 0;
    return 1;
}

/* The position of surface copy i at q. */
static void copy_position(const sw_reduced *red, int32_t i, const double *q, double x[3],
                          double *J) {
    const sw_blob_view *v = red->v;
    const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
    sw_reduced_position(red, D, v->surf_copies[2 * i + 1], red->copy_act[i], q + D->q_offset, x, J);
}

/* x of the step's frame in the world (wc->frame). */
static void to_world(const sw_world_contacts *wc, const double x[3], double y[3]) {
    const double *F = wc->frame;
    for (int i = 0; i < 3; ++i)
        y[i] = F ? F[3 * i] * x[0] + F[3 * i + 1] * x[1] + F[3 * i + 2] * x[2] + F[9 + i] : x[i];
}

/* A collider's answer (in the world) in the step's frame, snapped: the same world moved
 * with the character answers within rounding, which the grid takes to the same value. */
static void hit_to_step(const sw_world_contacts *wc, sw_collider_hit *hit) {
    const double *F = wc->frame;
    if (!F) return;
    double d[3], n[3];
    for (int k = 0; k < 3; ++k) {
        d[k] = hit->point[k] - F[9 + k];
        n[k] = hit->normal[k];
    }
    for (int i = 0; i < 3; ++i) {
        hit->point[i] = sw_snap(F[i] * d[0] + F[3 + i] * d[1] + F[6 + i] * d[2], wc->grid);
        hit->normal[i] = sw_snap(F[i] * n[0] + F[3 + i] * n[1] + F[6 + i] * n[2], 0x1p-24);
    }
    hit->phi = sw_snap(hit->phi, wc->grid);
}

/* The world box of a box of the step's frame. */
static void box_to_world(const sw_world_contacts *wc, const double b[6], double w[6]) {
    const double *F = wc->frame;
    if (!F) {
        memcpy(w, b, 6 * sizeof(double));
        return;
    }
    double c[3], h[3], cw[3];
    for (int k = 0; k < 3; ++k) {
        c[k] = 0.5 * (b[k] + b[3 + k]);
        h[k] = 0.5 * (b[3 + k] - b[k]);
    }
    to_world(wc, c, cw);
    for (int i = 0; i < 3; ++i) {
        double r = fabs(F[3 * i]) * h[0] + fabs(F[3 * i + 1]) * h[1] + fabs(F[3 * i + 2]) * h[2];
        w[i] = cw[i] - r;
        w[3 + i] = cw[i] + r;
    }
}

static int is_candidate(const sw_world_contacts *wc, int32_t copy, int32_t slot) {
    for (int32_t j = wc->copy_first[copy]; j >= 0; j = wc->cand[j].next)
        if (wc->cand[j].slot == slot) return 1;
    return 0;
}

void sw_world_contacts_clear(sw_world_contacts *wc) {
    for (int32_t j = 0; j < wc->ncand; ++j)
        wc->copy_first[wc->cand[j].copy] = -1;
    wc->ncand = 0;
}

/* Queries copy i at xw (the world's) against world slot s; a hit within the radius (or,
 * with penetrating_only, inside) becomes a candidate unless it is one already. */
static void try_candidate(sw_world_contacts *wc, int32_t i, const double xw[3], uint32_t s,
                          double blob_k, int penetrating_only) {
    const sw_collider *c = sw_world_slot(wc->world, s);
    sw_collider_hit hit;
    if (penetrating_only && is_candidate(wc, i, (int32_t)s)) return;
    wc->queries++;
    if (!sw_collider_query(c, xw, wc->radius, &hit)) return;
    hit_to_step(wc, &hit);
    if (penetrating_only && !(hit.phi < 0)) return;
    if (wc->ncand >= wc->max_cand) {
        wc->dropped++;
        return;
    }
    sw_world_cand *cd = &wc->cand[wc->ncand++];
    double ks = sw_collider_stiffness(c);
    cd->law.k = (ks > 0 ? ks : blob_k) * wc->copy_area[i];
    for (int k = 0; k < 3; ++k) {
        cd->law.a[k] = hit.point[k];
        cd->law.n[k] = hit.normal[k];
    }
    /* lagged friction: the cap is mu times the normal force at detection */
    cd->law.cap = sw_collider_friction(c) * cd->law.k * fmax(0.0, -hit.phi);
    cd->copy = i;
    cd->slot = (int32_t)s;
    cd->id = sw_collider_id_of(wc->world, s);
    cd->active = 0;
    cd->patch = -1;
    cd->f[0] = cd->f[1] = cd->f[2] = 0;
    cd->next = wc->copy_first[i];
    wc->copy_first[i] = wc->ncand - 1;
}

/* The world box of slot s grown by the detection radius; 0 for an empty slot and for the
 * collider the instance ignores (every query of the world passes here first). */
static int collider_box(const sw_world_contacts *wc, uint32_t s, double box[6]) {
    const sw_collider *c = sw_world_slot(wc->world, s);
    if (!c || (wc->ignore && sw_collider_id_of(wc->world, s) == wc->ignore)) return 0;
    sw_collider_bounds(c, wc->radius, box, box + 3);
    return 1;
}

/* How far a point of the box (centre c, half-diagonal rho) moved by bone motion B lands
 * from where motion A takes it: |B(c) - A(c)| + ||R_B - R_A||_2 rho, the norm
 * sqrt(3 - tr(R_B R_A^T)) (2 sin of half the angle between them). */
static double motion_apart(const double *A, const double *B, const double c[3], double rho) {
    double d2 = 0, tr = 0;
    for (int r = 0; r < 3; ++r) {
        double y = B[9 + r] - A[9 + r];
        for (int k = 0; k < 3; ++k) {
            y += (B[3 * r + k] - A[3 * r + k]) * c[k];
            tr += B[3 * r + k] * A[3 * r + k];
        }
        d2 += y * y;
    }
    return sqrt(d2) + sqrt(fmax(0.0, 3 - tr)) * rho;
}

/* The broad-phase box of cluster c: its box at the last output carried by the motion of
 * its dominant bone since (T_last -> T), grown by how far the other bones that skin it
 * move its points apart from that, and by the detection radius. Carried, not grown by
 * the whole motion: a character running or turning moves every box far in a step, while
 * its bones move little relative to each other. */
double sw_world_cluster_spread(const sw_world_contacts *wc, const sw_blob_view *v, int32_t c,
                               const double ctr[3], double rho) {
    const double *D0 = wc->bone_motion + 12 * wc->cl_bone0[c];
    double grow = 0;
    for (int32_t bone = 0; bone < v->nbones; ++bone)
        if (wc->cl_bones[c] >> (bone < 64 ? bone : 63) & 1)
            grow = sw_max(grow, motion_apart(D0, wc->bone_motion + 12 * bone, ctr, rho));
    /* a dual-quaternion blend of bone motions lands a point about no further from the
     * dominant bone's than the furthest of them; 1.25 x leaves room for the blend and the
     * correction's change */
    return 1.25 * grow + wc->radius;
}

double sw_world_cluster_box(const sw_world_contacts *wc, const sw_blob_view *v, int32_t c,
                            double box[6]) {
    const double *b = wc->cl_box + 6 * c, *D0 = wc->bone_motion + 12 * wc->cl_bone0[c];
    double ctr[3], half[3], rho = 0;
    for (int k = 0; k < 3; ++k) {
        ctr[k] = 0.5 * (b[k] + b[3 + k]);
        half[k] = 0.5 * (b[3 + k] - b[k]);
        rho += half[k] * half[k];
    }
    rho = sqrt(rho);
    const double grow = sw_world_cluster_spread(wc, v, c, ctr, rho);
    for (int r = 0; r < 3; ++r) { /* the box of the carried box */
        double cr = D0[9 + r], hr = 0;
        for (int k = 0; k < 3; ++k) {
            cr += D0[3 * r + k] * ctr[k];
            hr += fabs(D0[3 * r + k]) * half[k];
        }
        box[r] = cr - hr - grow;
        box[3 + r] = cr + hr + grow;
    }
    return grow;
}

/* Narrow phase of cluster c at q against every collider whose box meets `box` (NULL:
 * all), the cluster's positions computed once (or, with copy_x, read from there). */
static void narrow_cluster(sw_world_contacts *wc, const sw_reduced *red, const double *q, int32_t c,
                           const double *box, const double *copy_x, int penetrating_only) {
    double x[SW_WORLD_CLUSTER][3], bw[6];
    int32_t b = wc->cl_begin[c], n = wc->cl_begin[c + 1] - b, have = 0;
    uint32_t ns = sw_world_slot_count(wc->world);
    if (box) box_to_world(wc, box, bw);
    for (uint32_t s = 0; s < ns; ++s) {
        double cb[6];
        if (!collider_box(wc, s, cb) || (box && !boxes_overlap(bw, cb))) continue;
        for (int32_t j = 0; j < n && !have; ++j) { /* in the world */
            double y[3];
            if (copy_x)
                memcpy(y, copy_x + 3 * wc->cl_copy[b + j], sizeof y);
            else
                copy_position(red, wc->cl_copy[b + j], q, y, NULL);
            to_world(wc, y, x[j]);
        }
        have = 1;
        for (int32_t j = 0; j < n; ++j)
            if (sw_box_contains(cb, cb + 3, x[j]))
                try_candidate(wc, wc->cl_copy[b + j], x[j], s, red->v->contact_k, penetrating_only);
    }
    if (have && !penetrating_only) wc->cl_pass[wc->npass++] = c;
}

int32_t sw_world_contacts_detect(sw_world_contacts *wc, const sw_reduced *red, const double *q,
                                 const double *T, const double *T_last) {
    sw_world_contacts_clear(wc);
    wc->dropped = wc->npass = 0;
    wc->queries = 0;
    if (!wc->world) return 0;
    memcpy(wc->q_detect, q, (size_t)red->R * sizeof(double));
    int use_boxes = wc->boxes_valid && T_last;
    if (use_boxes) sw_world_clusters_motion(wc, red->v->nbones, T, T_last);
    for (int32_t c = 0; c < wc->ncl; ++c) {
        double box[6];
        if (use_boxes) sw_world_cluster_box(wc, red->v, c, box);
        narrow_cluster(wc, red, q, c, use_boxes ? box : NULL, NULL, 0);
    }
    return wc->ncand;
}

int32_t sw_world_contacts_add_missed(sw_world_contacts *wc, const sw_reduced *red,
                                     const double *q) {
    if (!wc->world) return 0;
    const sw_blob_view *v = red->v;
    int32_t before = wc->ncand;
    /* A copy that was no candidate was at least the detection radius from every
     * collider; the skinning is fixed within the step, so it moved by at most
     * umax_d |q_d - q_detect_d| (the Frobenius bound of its basis rows). A domain that
     * moved less than the radius cannot have entered a collider: its clusters are
     * skipped. Those that did are in clusters the detection passed (their grown boxes
     * hold where the copies can reach). */
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *D = &v->domains[d];
        double m2 = 0;
        for (int32_t j = 0; j < D->rank; ++j) {
            double e = q[D->q_offset + j] - wc->q_detect[D->q_offset + j];
            m2 += e * e;
        }
        wc->dom_moved[d] = wc->dom_umax[d] * sqrt(m2) >= wc->radius;
    }
    for (int32_t p = 0; p < wc->npass; ++p) {
        int32_t c = wc->cl_pass[p];
        if (wc->dom_moved[v->surf_copies[2 * wc->cl_copy[wc->cl_begin[c]]]])
            narrow_cluster(wc, red, q, c, NULL, wc->copy_x, 1);
    }
    return wc->ncand - before;
}

/* Candidate j's law taken again at x (the world's): the collider's normal at x's closest point, the
 * friction cap from the normal force there, and the anchor (the friction's stick point)
 * either that closest point or, with keep_anchor, the old anchor projected onto the new
 * plane. A collider no longer within four detection radii leaves the law without
 * stiffness (with keep_anchor, as it was).
 *
 * keep_anchor is the in-solve refresh of a patch (SW_WC_AT_REPLANE): a law taken at the
 * patch's start state, deep inside a collider the subspace went through, has a cap from
 * that depth that holds the flesh where the reference's slides, while keeping the stick
 * point keeps a resting contact's friction history (a new anchor each refresh makes a
 * resting finger's patch miss sixty times more of the reference's correction). */
static void refresh_candidate(sw_world_contacts *wc, int32_t j, const double x[3],
                              int keep_anchor) {
    sw_world_cand *cd = &wc->cand[j];
    const sw_collider *c = sw_world_slot(wc->world, (uint32_t)cd->slot);
    sw_collider_hit hit;
    wc->queries++;
    if (!c || !sw_collider_query(c, x, 4 * wc->radius, &hit)) {
        if (keep_anchor) return;
        cd->law.k = 0;
        cd->law.cap = 0;
        return;
    }
    hit_to_step(wc, &hit);
    double e = 0; /* the old anchor's height over the new plane */
    for (int k = 0; k < 3; ++k)
        e += (cd->law.a[k] - hit.point[k]) * hit.normal[k];
    for (int k = 0; k < 3; ++k) {
        cd->law.a[k] = keep_anchor ? cd->law.a[k] - e * hit.normal[k] : hit.point[k];
        cd->law.n[k] = hit.normal[k];
    }
    cd->law.cap = sw_collider_friction(c) * cd->law.k * fmax(0.0, -hit.phi);
}

int32_t sw_world_contacts_at(sw_world_contacts *wc, int32_t i, const double xs[3], double blob_k,
                             sw_wc_at_mode mode) {
    int32_t before = wc->ncand;
    double x[3]; /* in the world */
    to_world(wc, xs, x);
    for (int32_t j = wc->copy_first[i]; mode != SW_WC_AT_MISSED && j >= 0; j = wc->cand[j].next)
        refresh_candidate(wc, j, x, mode == SW_WC_AT_REPLANE);
    int penetrating_only = mode == SW_WC_AT_MISSED;
    uint32_t ns = sw_world_slot_count(wc->world);
    for (uint32_t s = 0; s < ns; ++s) {
        double cb[6];
        if (collider_box(wc, s, cb) && sw_box_contains(cb, cb + 3, x) &&
            !is_candidate(wc, i, (int32_t)s))
            try_candidate(wc, i, x, s, blob_k, penetrating_only);
    }
    return wc->ncand - before;
}

/* ---- energy, gradient, Hessian --------------------------------------------------- */

double sw_world_contact_eval(sw_reduced *red, const sw_world_contacts *wc, const double *q,
                             int want_grad, int want_hess) {
    const sw_blob_view *v = red->v;
    double E = 0;
    for (int32_t j = 0; j < wc->ncand; ++j) {
        const sw_world_cand *cd = &wc->cand[j];
        if (cd->patch >= 0) continue;
        const sw_blob_domain *D = &v->domains[v->surf_copies[2 * cd->copy]];
        int32_t r = D->rank;
        double x[3], f[3], H3[9];
        double *J = red->Jc;
        copy_position(red, cd->copy, q, x, want_grad ? J : NULL);
        E += sw_world_penalty(&cd->law, x, f, want_hess ? H3 : NULL);
        if (!want_grad) continue;
        double *g = red->g + D->q_offset;
        for (int32_t a = 0; a < r; ++a)
            g[a] -= J[a] * f[0] + J[r + a] * f[1] + J[2 * r + a] * f[2];
        if (!want_hess || (H3[0] == 0 && H3[4] == 0 && H3[8] == 0)) continue;
        double *HJ = red->hc; /* H3 J: 3 x r */
        for (int i = 0; i < 3; ++i)
            for (int32_t a = 0; a < r; ++a)
                HJ[i * r + a] =
                    H3[3 * i] * J[a] + H3[3 * i + 1] * J[r + a] + H3[3 * i + 2] * J[2 * r + a];
        for (int32_t a = 0; a < r; ++a) {
            double *Ha = red->H + (int64_t)(D->q_offset + a) * red->R + D->q_offset;
            double j0 = J[a], j1 = J[r + a], j2 = J[2 * r + a];
            for (int32_t b = 0; b < r; ++b)
                Ha[b] += j0 * HJ[b] + j1 * HJ[r + b] + j2 * HJ[2 * r + b];
        }
    }
    return E;
}

void sw_world_contacts_finish(sw_world_contacts *wc, sw_reduced *red, const double *q) {
    for (int32_t j = 0; j < wc->ncand; ++j) {
        sw_world_cand *cd = &wc->cand[j];
        double x[3];
        if (cd->patch >= 0)
            memcpy(x, wc->patch_x + 3 * (int64_t)cd->patch, sizeof x);
        else
            copy_position(red, cd->copy, q, x, NULL);
        (void)sw_world_penalty(&cd->law, x, cd->f, NULL);
        double d[3] = {cd->law.a[0] - x[0], cd->law.a[1] - x[1], cd->law.a[2] - x[2]};
        cd->active = sw_penalty_gap(cd->law.n, d) > 0;
    }
}

void sw_world_contacts_update_boxes(sw_world_contacts *wc) {
    for (int32_t c = 0; c < wc->ncl; ++c) {
        double *b = wc->cl_box + 6 * c;
        for (int k = 0; k < 3; ++k) {
            b[k] = INFINITY;
            b[3 + k] = -INFINITY;
        }
        for (int32_t j = wc->cl_begin[c]; j < wc->cl_begin[c + 1]; ++j) {
            const double *x = wc->copy_x + 3 * wc->cl_copy[j];
            for (int k = 0; k < 3; ++k) {
                b[k] = sw_min(b[k], x[k]);
                b[3 + k] = sw_max(b[3 + k], x[k]);
            }
        }
    }
    wc->boxes_valid = 1;
}

void sw_world_contacts_take(sw_mem_plan *p, const sw_blob_view *v, int32_t ncl, int32_t max_world,
                            sw_world_contacts *wc) {
    const uint64_t nc = (uint64_t)v->nsurf_copies, nb = (uint64_t)v->nbones;
    SW_PLAN_TAKE(p, wc->cand, (uint64_t)max_world);
    SW_PLAN_TAKE(p, wc->cl_box, 6 * (uint64_t)ncl);
    SW_PLAN_TAKE(p, wc->cl_pass, (uint64_t)ncl);
    SW_PLAN_TAKE(p, wc->copy_first, nc);
    SW_PLAN_TAKE(p, wc->dom_moved, (uint64_t)v->ndomains);
    SW_PLAN_TAKE(p, wc->q_detect, (uint64_t)v->rank_total);
    SW_PLAN_TAKE(p, wc->bone_motion, 12 * nb);
    SW_PLAN_TAKE(p, wc->copy_x, 3 * nc);
}
