/* Novel self-contact (novel_contact.h): the clusters' broad phase, the layers' narrow
 * phase with the reference's rule, the deepest contact of each vertex. */
#include "novel_contact.h"

#include <math.h>
#include <string.h>

#include "sorted.h"

static int32_t max_valence(const sw_blob_view *v) {
    int32_t m = 0;
    for (int32_t gv = 0; gv < v->nverts; ++gv)
        m = v->vert_tet_ptr[gv + 1] - v->vert_tet_ptr[gv] > m
                ? v->vert_tet_ptr[gv + 1] - v->vert_tet_ptr[gv]
                : m;
    return m;
}

void sw_novel_take(sw_mem_plan *p, const sw_blob_view *v, int32_t ncl, sw_novel *nv) {
    memset(nv, 0, sizeof *nv);
    uint64_t layers = 0, nv3 = (uint64_t)v->nverts;
    for (int32_t i = 0; i < v->nsurf_copies; ++i) {
        int32_t gv = sw_blob_surf_copy_vertex(v, i);
        layers += (uint64_t)(v->vert_tet_ptr[gv + 1] - v->vert_tet_ptr[gv]);
    }
    nv->max_layer = SW_WORLD_CLUSTER * max_valence(v);
#define TAKE(ptr, count) SW_PLAN_TAKE(p, ptr, count)
    TAKE(nv->cl_dom, (uint64_t)ncl);
    TAKE(nv->cl_now, 6 * (uint64_t)ncl);
    TAKE(nv->order, (uint64_t)ncl);
    TAKE(nv->layer_ptr, (uint64_t)ncl + 1);
    TAKE(nv->layer_tets, layers);
    TAKE(nv->layer_box, 6 * layers);
    TAKE(nv->cl_boxed, (uint64_t)ncl);
    TAKE(nv->cand, (uint64_t)nv->max_layer);
    TAKE(nv->held, nv3);
    TAKE(nv->best, nv3);
    TAKE(nv->best_i, nv3);
    TAKE(nv->hits, (uint64_t)SW_NOVEL_MAX_CONTACTS);
    TAKE(nv->cl_rest, 6 * (uint64_t)ncl);
    TAKE(nv->cl_grow, (uint64_t)ncl);
#undef TAKE
}

static void box_empty(double b[6]) {
    for (int k = 0; k < 3; ++k) {
        b[k] = INFINITY;
        b[3 + k] = -INFINITY;
    }
}

static void box_add(double b[6], const double x[3]) {
    for (int k = 0; k < 3; ++k) {
        b[k] = fmin(b[k], x[k]);
        b[3 + k] = fmax(b[3 + k], x[k]);
    }
}

static void box_grow(double b[6], double r) {
    for (int k = 0; k < 3; ++k) {
        b[k] -= r;
        b[3 + k] += r;
    }
}

static int box_meets(const double a[6], const double b[6]) {
    for (int k = 0; k < 3; ++k)
        if (a[k] > b[3 + k] || b[k] > a[3 + k]) return 0;
    return 1;
}

static int box_holds(const double b[6], const double x[3]) {
    return x[0] >= b[0] && x[1] >= b[1] && x[2] >= b[2] && x[0] <= b[3] && x[1] <= b[4] &&
           x[2] <= b[5];
}

/* Each cluster's rest box grown by the reach of the reference's neighbour rule (the
 * longest rest edge of the boundary times its factor): two clusters whose grown boxes
 * meet are one stretch of skin across a joint. */
static void rest_boxes(sw_novel *nv, const sw_blob_view *v, const sw_world_contacts *wc,
                       const sw_self_contacts *sc) {
    double edge = 0;
    for (int32_t t = 0; t < sc->m.ntris; ++t)
        edge = fmax(edge, sc->m.tri_edge[t]);
    for (int32_t c = 0; c < wc->ncl; ++c) {
        double *b = nv->cl_rest + 6 * c;
        box_empty(b);
        for (int32_t i = wc->cl_begin[c]; i < wc->cl_begin[c + 1]; ++i)
            box_add(b, v->rest + 3 * (int64_t)sw_blob_surf_copy_vertex(v, wc->cl_copy[i]));
        box_grow(b, 0.5 * SW_SELF_NEIGHBOUR_FACTOR * edge);
    }
}

void sw_novel_build(sw_novel *nv, const sw_blob_view *v, const sw_world_contacts *wc,
                    sw_self_contacts *sc) {
    nv->ncl = wc->ncl;
    int32_t n = 0, mark = 0;
    for (int32_t c = 0; c < wc->ncl; ++c) {
        nv->order[c] = c;
        nv->cl_dom[c] = v->surf_copies[2 * wc->cl_copy[wc->cl_begin[c]]];
        nv->layer_ptr[c] = n;
        ++mark; /* each tet listed once a layer (the re-test's tet stamps, free here) */
        for (int32_t i = wc->cl_begin[c]; i < wc->cl_begin[c + 1]; ++i) {
            int32_t gv = sw_blob_surf_copy_vertex(v, wc->cl_copy[i]);
            for (int32_t e = v->vert_tet_ptr[gv]; e < v->vert_tet_ptr[gv + 1]; ++e) {
                int32_t t = v->vert_tets[e];
                if (sc->tstamp[t] == mark) continue;
                sc->tstamp[t] = mark;
                nv->layer_tets[n++] = t;
            }
        }
    }
    memset(sc->tstamp, 0, (size_t)v->ntets * sizeof *sc->tstamp);
    rest_boxes(nv, v, wc, sc);
    nv->layer_ptr[wc->ncl] = n;
    memset(nv->best, 0, (size_t)v->nverts * sizeof *nv->best);
    memset(nv->held, 0, (size_t)v->nverts * sizeof *nv->held);
    memset(nv->cl_boxed, 0, (size_t)wc->ncl * sizeof *nv->cl_boxed);
    nv->stamp = 0;
}

/* A fresh stamp for held[] and best[] (both cleared on wrap-around). */
static void next_stamp(sw_novel *nv, int32_t nverts) {
    if (nv->stamp == INT32_MAX) {
        memset(nv->best, 0, (size_t)nverts * sizeof *nv->best);
        memset(nv->held, 0, (size_t)nverts * sizeof *nv->held);
        memset(nv->cl_boxed, 0, (size_t)nv->ncl * sizeof *nv->cl_boxed);
        nv->stamp = 0;
    }
    nv->stamp++;
}

/* x (the step's frame) in bone 0's frame this step, nv->frame: R^T (x - t). Every box
 * of the detection is taken there. A rigid motion of the whole pose carries bone 0 too,
 * so it leaves these boxes, the sweep's order and every box test as they were (to
 * rounding); boxes on the step's axes change shape with the heading, and with them
 * which copies near the edge of another cluster's layer are tested at all. */
static void to_frame(const double F[12], const double x[3], double y[3]) {
    const double d[3] = {x[0] - F[9], x[1] - F[10], x[2] - F[11]};
    for (int r = 0; r < 3; ++r)
        y[r] = F[r] * d[0] + F[3 + r] * d[1] + F[6 + r] * d[2];
}

/* Where rigid motion D (12: R row-major, t) takes x, in bone 0's frame. */
static void carry_to_frame(const double F[12], const double *D, const double x[3], double y[3]) {
    double z[3];
    for (int r = 0; r < 3; ++r)
        z[r] = D[9 + r] + D[3 * r] * x[0] + D[3 * r + 1] * x[1] + D[3 * r + 2] * x[2];
    to_frame(F, z, y);
}

/* Cluster c's box in bone 0's frame: its copies' last output positions carried by its
 * dominant bone's motion, grown by how far the other bones move them apart from that
 * (about their centroid: a ball, which no axis choice changes); returns that growth. */
static double carried_box(const sw_novel *nv, const sw_world_contacts *wc, const sw_blob_view *v,
                          int32_t c, double b[6]) {
    const double *D0 = wc->bone_motion + 12 * wc->cl_bone0[c];
    double ctr[3] = {0, 0, 0}, rho2 = 0;
    const int32_t i0 = wc->cl_begin[c], i1 = wc->cl_begin[c + 1];
    box_empty(b);
    for (int32_t i = i0; i < i1; ++i) {
        const double *xl = wc->copy_x + 3 * (int64_t)wc->cl_copy[i];
        double y[3];
        carry_to_frame(nv->frame, D0, xl, y);
        box_add(b, y);
        for (int k = 0; k < 3; ++k)
            ctr[k] += xl[k];
    }
    for (int k = 0; k < 3; ++k)
        ctr[k] /= (double)(i1 - i0);
    for (int32_t i = i0; i < i1; ++i) {
        const double *xl = wc->copy_x + 3 * (int64_t)wc->cl_copy[i];
        double d2 = 0;
        for (int k = 0; k < 3; ++k)
            d2 += (xl[k] - ctr[k]) * (xl[k] - ctr[k]);
        rho2 = fmax(rho2, d2);
    }
    const double g = sw_world_cluster_spread(wc, v, c, ctr, sqrt(rho2));
    box_grow(b, g);
    return g;
}

/* This step's box of every cluster in bone 0's frame: the last output's carried by the
 * bones' motion, or, without one, the copies at q. */
static void cluster_boxes(sw_novel *nv, sw_self_contacts *sc, sw_world_contacts *wc,
                          const sw_reduced *red, const double *q, const double *T,
                          const double *T_last) {
    const sw_blob_view *v = red->v;
    int use_boxes = wc->boxes_valid && T_last;
    if (use_boxes) sw_world_clusters_motion(wc, v->nbones, T, T_last);
    for (int32_t c = 0; c < nv->ncl; ++c) {
        double *b = nv->cl_now + 6 * c;
        if (use_boxes) {
            nv->cl_grow[c] = carried_box(nv, wc, v, c, b);
            continue;
        }
        nv->cl_grow[c] = -1; /* no last output: the copies are mapped */
        box_empty(b);
        for (int32_t i = wc->cl_begin[c]; i < wc->cl_begin[c + 1]; ++i) {
            double y[3];
            to_frame(nv->frame,
                     sw_self_contacts_map(sc, q, sw_blob_surf_copy_vertex(v, wc->cl_copy[i])), y);
            box_add(b, y);
        }
        box_grow(b, wc->radius);
    }
    /* insertion sort by the low x (of bone 0's frame): the order of the last step is
     * almost this one's */
    for (int32_t a = 1; a < nv->ncl; ++a)
        for (int32_t j = a;
             j > 0 && nv->cl_now[6 * nv->order[j - 1]] > nv->cl_now[6 * nv->order[j]]; --j) {
            int32_t t = nv->order[j];
            nv->order[j] = nv->order[j - 1];
            nv->order[j - 1] = t;
        }
}

/* The hit of vertex gv: kept when it is the vertex's first or deeper than its last. */
static void keep_hit(sw_novel *nv, int32_t gv, const sw_self_hit *hit) {
    if (nv->best[gv] == nv->stamp) {
        sw_self_hit *h = &nv->hits[nv->best_i[gv]];
        if (hit->rest_depth > h->rest_depth ||
            (hit->rest_depth == h->rest_depth && hit->tet < h->tet))
            *h = *hit;
        return;
    }
    if (nv->nhits == SW_NOVEL_MAX_CONTACTS) {
        nv->dropped++;
        return;
    }
    nv->best[gv] = nv->stamp;
    nv->best_i[gv] = nv->nhits;
    nv->hits[nv->nhits++] = *hit;
}

/* The copies of cluster a inside cluster b's box against b's layer. */
static void narrow(sw_novel *nv, sw_self_contacts *sc, const sw_world_contacts *wc,
                   const sw_reduced *red, const double *q, int32_t a, int32_t b) {
    const sw_blob_view *v = red->v;
    const sw_self_mesh *m = &sc->m;
    const double *bb = nv->cl_now + 6 * b;
    int32_t lb = nv->layer_ptr[b], ln = nv->layer_ptr[b + 1] - lb;
    const double *boxes = nv->layer_box + 6 * (int64_t)lb;
    const double g = nv->cl_grow[a], *D0 = wc->bone_motion + 12 * wc->cl_bone0[a];
    for (int32_t i = wc->cl_begin[a]; i < wc->cl_begin[a + 1]; ++i) {
        int32_t gv = sw_blob_surf_copy_vertex(v, wc->cl_copy[i]);
        if (nv->held[gv] == nv->stamp) continue;
        if (g >= 0) { /* where its last output and the bones' motion put it, before mapping */
            double y[3];
            carry_to_frame(nv->frame, D0, wc->copy_x + 3 * (int64_t)wc->cl_copy[i], y);
            int out = 0;
            for (int r = 0; r < 3 && !out; ++r)
                out = y[r] < bb[r] - g || y[r] > bb[3 + r] + g;
            if (out) continue;
        }
        double x[3];
        to_frame(nv->frame, sw_self_contacts_map(sc, q, gv), x);
        if (!box_holds(bb, x)) continue;
        if (nv->cl_boxed[b] != nv->stamp) { /* the layer's tet boxes, once a step */
            for (int32_t k = 0; k < ln; ++k) {
                double *tb = nv->layer_box + 6 * (int64_t)(lb + k), y[3];
                box_empty(tb);
                for (int c = 0; c < 4; ++c) {
                    to_frame(nv->frame,
                             sw_self_contacts_map(sc, q,
                                                  v->tets[4 * (int64_t)nv->layer_tets[lb + k] + c]),
                             y);
                    box_add(tb, y);
                }
            }
            nv->cl_boxed[b] = nv->stamp;
        }
        int32_t n = 0;
        for (int32_t k = 0; k < ln; ++k)
            if (box_holds(boxes + 6 * k, x)) nv->cand[n++] = nv->layer_tets[lb + k];
        if (n == 0) continue;
        nv->tests += n;
        int32_t si = sw_sorted_index(m->surf, m->nsurf, gv);
        sw_self_hit hit;
        if (si >= 0 && sw_self_detect_among(m, sc->x, si, nv->cand, n, &hit))
            keep_hit(nv, gv, &hit);
    }
}

int32_t sw_novel_detect(sw_novel *nv, sw_self_contacts *sc, sw_world_contacts *wc,
                        const sw_reduced *red, const double *q, const sw_pose_space *ps,
                        const double *T, const double *T_last, int near) {
    const sw_blob_view *v = red->v;
    sw_self_contacts_clear(sc);
    sw_self_contacts_begin(sc, red);
    next_stamp(nv, v->nverts);
    nv->nhits = nv->dropped = nv->cluster_pairs = 0;
    nv->tests = 0;
    memcpy(nv->frame, T, sizeof nv->frame);  /* bone 0's pose: the boxes' frame */
    for (int32_t i = 0; i < ps->npairs; ++i) /* the vertices the trained pairs hold */
        nv->held[red->act_vert[red->contact_act[4 * (int64_t)ps->pairs[i]]]] = nv->stamp;
    cluster_boxes(nv, sc, wc, red, q, T, T_last);
    for (int32_t a = 0; a < nv->ncl; ++a) {
        int32_t i = nv->order[a];
        const double *bi = nv->cl_now + 6 * i;
        for (int32_t k = a + 1; k < nv->ncl; ++k) {
            int32_t j = nv->order[k];
            const double *bj = nv->cl_now + 6 * j;
            if (bj[0] > bi[3]) break; /* sorted by the low x: none after meets i */
            if (nv->cl_dom[i] == nv->cl_dom[j] || !box_meets(bi, bj) ||
                (!near && box_meets(nv->cl_rest + 6 * i, nv->cl_rest + 6 * j)))
                continue;
            nv->cluster_pairs++;
            narrow(nv, sc, wc, red, q, i, j);
            narrow(nv, sc, wc, red, q, j, i);
        }
    }
    for (int32_t h = 0; h < nv->nhits; ++h) {
        const int32_t *tv = sw_self_hit_triangle(&sc->m, &nv->hits[h]);
        for (int k = 0; k < 3; ++k)
            sw_self_contacts_map(sc, q, tv[k]);
        sw_contact c;
        sw_self_detect_finish(&sc->m, sc->x, &nv->hits[h], &c);
        sw_self_contacts_add(sc, &c, 1, 1);
    }
    sc->tests = nv->tests;
    return sc->npairs;
}
