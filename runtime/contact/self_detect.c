/* Self-contact detection (self_detect.h): the tet a surface vertex entered, its rest
 * projection and the contact of eqs. 3.4-3.5. */
#include "self_detect.h"

#include <math.h>
#include <string.h>

#include "sorted.h"
#include "vec3.h"

void sw_self_mesh_measures(sw_self_mesh *m) {
    for (int32_t i = 0; i < m->nsurf; ++i)
        m->ring[i] = 0;
    for (int32_t t = 0; t < m->ntris; ++t) {
        const int32_t *v = m->tris + 3 * (size_t)t;
        const double *a = m->X + 3 * (size_t)v[0], *b = m->X + 3 * (size_t)v[1],
                     *c = m->X + 3 * (size_t)v[2];
        double e[3][3], nrm[3];
        sw_v3_sub(b, a, e[0]);
        sw_v3_sub(c, b, e[1]);
        sw_v3_sub(a, c, e[2]);
        sw_v3_cross(e[0], e[2], nrm);
        double area = 0.5 * sw_v3_norm(nrm), longest = 0;
        for (int k = 0; k < 3; ++k) {
            double l = sw_v3_norm(e[k]);
            if (l > longest) longest = l;
        }
        m->tri_area[t] = area;
        m->tri_edge[t] = longest;
        for (int k = 0; k < 3; ++k)
            m->ring[sw_sorted_index(m->surf, m->nsurf, v[k])] += area;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < m->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            if (m->X[3 * (size_t)i + k] < lo[k]) lo[k] = m->X[3 * (size_t)i + k];
            if (m->X[3 * (size_t)i + k] > hi[k]) hi[k] = m->X[3 * (size_t)i + k];
        }
    /* Every rest point lies in the bounding box, so this radius always finds the
     * closest surface triangle, yet it is finite (STYLE.md §6). */
    m->rest_diag = 1.01 * sw_v3_dist(hi, lo) + 1e-300;
}

typedef struct {
    const sw_self_mesh *sc;
    const double *x;
    int32_t p;        /* the surface vertex */
    const double *xp; /* its deformed position */
    /* best candidate so far: deepest rest point, ties to the lowest tet id */
    int32_t tet;
    double rest_depth;
    sw_bvh_closest hit;
} vertex_query;

/* Barycentrics of p in the deformed tet t; 0 when the tet is flat. */
static int tet_barycentrics(const double *x, const int32_t *v, const double *p, double b[4]) {
    const double *x0 = x + 3 * (size_t)v[0], *x1 = x + 3 * (size_t)v[1], *x2 = x + 3 * (size_t)v[2],
                 *x3 = x + 3 * (size_t)v[3];
    double e1[3], e2[3], e3[3], q0[3], q1[3], q2[3], q3[3];
    sw_v3_sub(x1, x0, e1);
    sw_v3_sub(x2, x0, e2);
    sw_v3_sub(x3, x0, e3);
    double vol = sw_v3_triple(e1, e2, e3);
    if (!(vol != 0) || !isfinite(vol)) return 0;
    sw_v3_sub(x0, p, q0);
    sw_v3_sub(x1, p, q1);
    sw_v3_sub(x2, p, q2);
    sw_v3_sub(x3, p, q3);
    /* Each weight is the signed volume of the tet with its vertex replaced by p. */
    b[0] = sw_v3_triple(q1, q2, q3) / vol;
    b[1] = -sw_v3_triple(q0, q2, q3) / vol;
    b[2] = sw_v3_triple(q0, q1, q3) / vol;
    b[3] = -sw_v3_triple(q0, q1, q2) / vol;
    return 1;
}

static int visit_tet(void *ctx, int32_t t) {
    vertex_query *q = ctx;
    const sw_self_mesh *sc = q->sc;
    const int32_t *v = sc->tets + 4 * (size_t)t;
    /* Tets incident to p always contain it; they are its own flesh, not a contact. */
    if (v[0] == q->p || v[1] == q->p || v[2] == q->p || v[3] == q->p) return 0;
    double b[4];
    if (!tet_barycentrics(q->x, v, q->xp, b)) return 0;
    for (int k = 0; k < 4; ++k)
        if (!(b[k] >= -SW_SELF_BARY_TOL)) return 0;
    /* §3.3.1: the penetrating vertex's rest position, by barycentric interpolation in
     * the rest pose of the tet it entered, then its closest rest-surface point. */
    double Xr[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c)
            Xr[c] += b[k] * sc->X[3 * (size_t)v[k] + c];
    sw_bvh_closest hit;
    if (!sw_bvh_closest_triangle(&sc->tri_bvh, sc->X, sc->tris, Xr, sc->rest_diag, &hit)) return 0;
    const int32_t *tv = sc->tris + 3 * (size_t)hit.tri;
    if (tv[0] == q->p || tv[1] == q->p || tv[2] == q->p) return 0;
    double edge = sc->tri_edge[hit.tri];
    if (hit.dist <= SW_SELF_TOUCH_TOL * edge) return 0;
    /* Neighbour rule (DESIGN.md §8): a triangle close to p in rest space is p's own
     * neighbourhood folding, not a contact. */
    double beta[3], Q[3];
    const double *Xp = sc->X + 3 * (size_t)q->p;
    sw_closest_point_triangle(Xp, sc->X + 3 * (size_t)tv[0], sc->X + 3 * (size_t)tv[1],
                              sc->X + 3 * (size_t)tv[2], beta, Q);
    double dQ[3];
    sw_v3_sub(Q, Xp, dQ);
    if (sw_v3_norm(dQ) < sc->neighbour_factor * edge) return 0;
    if (q->tet < 0 || hit.dist > q->rest_depth || (hit.dist == q->rest_depth && t < q->tet)) {
        q->tet = t;
        q->rest_depth = hit.dist;
        q->hit = hit;
    }
    return 0;
}

/* Fills c from the chosen triangle: v_s, d, n, depth, ka (eqs. 3.4-3.5). */
static void make_contact(const sw_self_mesh *sc, const double *x, int32_t si, const vertex_query *q,
                         sw_contact *c) {
    const int32_t *tv = sc->tris + 3 * (size_t)q->hit.tri;
    memset(c, 0, sizeof *c);
    c->p = q->p;
    double vs[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        c->tri[k] = tv[k];
        c->beta[k] = q->hit.beta[k];
        for (int j = 0; j < 3; ++j)
            vs[j] += c->beta[k] * x[3 * (size_t)tv[k] + j];
    }
    c->ka = 0.25 * (sc->ring[si] + sc->tri_area[q->hit.tri]);
    double d[3];
    sw_v3_sub(vs, q->xp, d);
    double len = sw_v3_norm(d);
    c->depth = len;
    if (len > 0 && isfinite(len)) {
        for (int j = 0; j < 3; ++j)
            c->n[j] = d[j] / len;
        return;
    }
    /* v_s == v_p: the direction is undefined; the triangle's outward normal is where
     * v_s - v_p points for any nearby penetration (deformed, else rest). */
    double e1[3], e2[3], nrm[3];
    for (int pass = 0; pass < 2; ++pass) {
        const double *P = pass == 0 ? x : sc->X;
        sw_v3_sub(P + 3 * (size_t)tv[1], P + 3 * (size_t)tv[0], e1);
        sw_v3_sub(P + 3 * (size_t)tv[2], P + 3 * (size_t)tv[0], e2);
        sw_v3_cross(e1, e2, nrm);
        double l = sw_v3_norm(nrm);
        if (l > 0 && isfinite(l)) {
            for (int j = 0; j < 3; ++j)
                c->n[j] = nrm[j] / l;
            return;
        }
    }
}

static void query_init(vertex_query *q, const sw_self_mesh *m, const double *x, int32_t si) {
    q->sc = m;
    q->x = x;
    q->p = m->surf[si];
    q->xp = x + 3 * (size_t)q->p;
    q->tet = -1;
    q->rest_depth = 0;
}

int sw_self_detect_vertex(const sw_self_mesh *m, const double *x, int32_t si, sw_contact *c,
                          int32_t *tested) {
    vertex_query q;
    query_init(&q, m, x, si);
    int32_t visits = sw_bvh_query_point(&m->tet_bvh, q.xp, visit_tet, &q);
    if (tested) *tested = visits;
    if (q.tet < 0) return 0;
    make_contact(m, x, si, &q, c);
    return 1;
}

int sw_self_detect_among(const sw_self_mesh *m, const double *x, int32_t si, const int32_t *tets,
                         int32_t n, sw_self_hit *hit) {
    vertex_query q;
    query_init(&q, m, x, si);
    for (int32_t i = 0; i < n; ++i)
        visit_tet(&q, tets[i]);
    hit->si = si;
    hit->tet = q.tet;
    hit->rest_depth = q.rest_depth;
    hit->hit = q.hit;
    return q.tet >= 0;
}

const int32_t *sw_self_hit_triangle(const sw_self_mesh *m, const sw_self_hit *hit) {
    return m->tris + 3 * (size_t)hit->hit.tri;
}

void sw_self_detect_finish(const sw_self_mesh *m, const double *x, const sw_self_hit *hit,
                           sw_contact *c) {
    vertex_query q;
    query_init(&q, m, x, hit->si);
    q.tet = hit->tet;
    q.rest_depth = hit->rest_depth;
    q.hit = hit->hit;
    make_contact(m, x, hit->si, &q, c);
}
