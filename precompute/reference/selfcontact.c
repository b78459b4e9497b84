/* Full-space self-contact: detection (thesis §3.3.1 "Collision Resolution",
 * DESIGN.md §8) and the assembly of the penalty of eqs. 3.4-3.6 (the law itself is the
 * runtime's contact/penalty.h). */
#include "selfcontact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "sorted.h"
#include "penalty.h"
#include "vec3.h"

struct sw_selfcontact {
    sw_self_mesh m; /* over the arrays below */
    double *X;      /* 3*nverts rest positions (copy) */
    int32_t *tets;  /* 4*ntets (copy) */
    int32_t *tris;  /* 3*ntris (copy) */
    int32_t *surf;  /* nsurf surface vertex ids, ascending (copy) */
    int32_t max_contacts;
    sw_contact *list;                 /* nsurf: per-range slices during detect, then the list */
    int32_t *range_count, *range_end; /* nsurf, indexed by the first item of a range */
    int32_t count, dropped;
    double max_depth;
};

/* The penalty section below still calls dot3 by that name. */
static inline double dot3(const double *a, const double *b) {
    return sw_v3_dot(a, b);
}

void sw_selfcontact_destroy(sw_selfcontact *sc) {
    if (!sc) return;
    free(sc->X);
    free(sc->tets);
    free(sc->tris);
    free(sc->surf);
    free(sc->m.ring);
    free(sc->m.tri_area);
    free(sc->m.tri_edge);
    sw_bvh_free(&sc->m.tri_bvh);
    sw_bvh_free(&sc->m.tet_bvh);
    free(sc->list);
    free(sc->range_count);
    free(sc->range_end);
    free(sc);
}

static sinew_result validate(const sw_tetmesh *m, const sw_surface *s, double factor,
                             int32_t max_contacts, sw_error *err) {
    if (!m || !s)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_selfcontact_create: mesh or surface is NULL");
    if (m->nverts < 4 || m->ntets < 1 || !m->X || !m->tets)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                            "sw_selfcontact_create: empty tet mesh (%d vertices, %d tets)",
                            (int)m->nverts, (int)m->ntets);
    if (s->ntris < 1 || s->nverts < 3 || !s->tris || !s->verts)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                            "sw_selfcontact_create: empty surface (%d triangles, %d vertices)",
                            (int)s->ntris, (int)s->nverts);
    if (!isfinite(factor) || factor < 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_selfcontact_create: neighbour_factor %g must be finite and >= 0",
                            factor);
    if (max_contacts < 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_selfcontact_create: max_contacts %d is negative",
                            (int)max_contacts);
    for (int32_t i = 0; i < 3 * m->nverts; ++i)
        if (!isfinite(m->X[i]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "sw_selfcontact_create: rest position of vertex %d is not finite",
                                (int)(i / 3));
    for (int32_t i = 0; i < 4 * m->ntets; ++i)
        if (m->tets[i] < 0 || m->tets[i] >= m->nverts)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "sw_selfcontact_create: tet %d vertex %d out of range [0, %d)",
                                (int)(i / 4), (int)m->tets[i], (int)m->nverts);
    for (int32_t i = 0; i < s->nverts; ++i) {
        if (s->verts[i] < 0 || s->verts[i] >= m->nverts)
            return sw_error_set(
                err, SINEW_ERROR_INVALID_ARGUMENT,
                "sw_selfcontact_create: surface vertex %d (id %d) out of range [0, %d)", (int)i,
                (int)s->verts[i], (int)m->nverts);
        if (i > 0 && s->verts[i] <= s->verts[i - 1])
            return sw_error_set(
                err, SINEW_ERROR_INVALID_ARGUMENT,
                "sw_selfcontact_create: surface vertex ids not strictly ascending at %d", (int)i);
    }
    for (int32_t t = 0; t < s->ntris; ++t) {
        const int32_t *v = s->tris + 3 * (size_t)t;
        for (int k = 0; k < 3; ++k)
            if (sw_sorted_index(s->verts, s->nverts, v[k]) < 0)
                return sw_error_set(
                    err, SINEW_ERROR_INVALID_ARGUMENT,
                    "sw_selfcontact_create: surface triangle %d vertex %d is not in the "
                    "surface vertex list",
                    (int)t, (int)v[k]);
        double e1[3], e2[3], nrm[3];
        sw_v3_sub(m->X + 3 * (size_t)v[1], m->X + 3 * (size_t)v[0], e1);
        sw_v3_sub(m->X + 3 * (size_t)v[2], m->X + 3 * (size_t)v[0], e2);
        sw_v3_cross(e1, e2, nrm);
        if (!(sw_v3_dot(nrm, nrm) > 0))
            return sw_error_set(
                err, SINEW_ERROR_DEGENERATE,
                "sw_selfcontact_create: surface triangle %d (%d %d %d) has zero rest area", (int)t,
                (int)v[0], (int)v[1], (int)v[2]);
    }
    return SINEW_OK;
}

sinew_result sw_selfcontact_create(const sw_tetmesh *mesh, const sw_surface *surf,
                                   double neighbour_factor, int32_t max_contacts,
                                   sw_selfcontact **out, sw_error *err) {
    if (!out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_selfcontact_create: out is NULL");
    *out = NULL;
    sinew_result r = validate(mesh, surf, neighbour_factor, max_contacts, err);
    if (r != SINEW_OK) return r;
    sw_selfcontact *sc = calloc(1, sizeof *sc);
    if (!sc)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "sw_selfcontact_create: out of memory");
    sw_self_mesh *m = &sc->m;
    m->nverts = mesh->nverts;
    m->ntets = mesh->ntets;
    m->ntris = surf->ntris;
    m->nsurf = surf->nverts;
    m->neighbour_factor = neighbour_factor;
    sc->max_contacts = max_contacts;
    size_t nv = (size_t)m->nverts, nt = (size_t)m->ntets, nf = (size_t)m->ntris,
           ns = (size_t)m->nsurf;
    sc->X = malloc(3 * nv * sizeof(double));
    sc->tets = malloc(4 * nt * sizeof(int32_t));
    sc->tris = malloc(3 * nf * sizeof(int32_t));
    sc->surf = malloc(ns * sizeof(int32_t));
    m->ring = calloc(ns, sizeof(double));
    m->tri_area = malloc(nf * sizeof(double));
    m->tri_edge = malloc(nf * sizeof(double));
    sc->list = malloc(ns * sizeof(sw_contact));
    sc->range_count = calloc(ns, sizeof(int32_t));
    sc->range_end = calloc(ns, sizeof(int32_t));
    /* build-time boxes: triangles, then (reused) tets */
    double *box = malloc(6 * (nf > nt ? nf : nt) * sizeof(double));
    if (!sc->X || !sc->tets || !sc->tris || !sc->surf || !m->ring || !m->tri_area || !m->tri_edge ||
        !sc->list || !sc->range_count || !sc->range_end || !box) {
        free(box);
        sw_selfcontact_destroy(sc);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "sw_selfcontact_create: out of memory");
    }
    memcpy(sc->X, mesh->X, 3 * nv * sizeof(double));
    memcpy(sc->tets, mesh->tets, 4 * nt * sizeof(int32_t));
    memcpy(sc->tris, surf->tris, 3 * nf * sizeof(int32_t));
    memcpy(sc->surf, surf->verts, ns * sizeof(int32_t));
    m->X = sc->X;
    m->tets = sc->tets;
    m->tris = sc->tris;
    m->surf = sc->surf;
    sw_self_mesh_measures(m);

    sw_bvh_element_boxes(sc->tris, 3, sc->X, 0, m->ntris, box);
    r = sw_bvh_build(m->ntris, box, &m->tri_bvh, err);
    if (r == SINEW_OK) {
        sw_bvh_element_boxes(sc->tets, 4, sc->X, 0, m->ntets, box);
        r = sw_bvh_build(m->ntets, box, &m->tet_bvh, err);
    }
    free(box);
    if (r != SINEW_OK) {
        sw_selfcontact_destroy(sc);
        return r;
    }
    *out = sc;
    return SINEW_OK;
}

typedef struct {
    sw_selfcontact *sc;
    const double *x;
} detect_ctx;

static void boxes_range(void *ctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    detect_ctx *d = ctx;
    sw_bvh_refit_elements(&d->sc->m.tet_bvh, d->sc->tets, 4, d->x, (int32_t)begin, (int32_t)end);
}

/* One range of surface vertices writes its contacts compactly from list[begin]: the
 * range owns slots [begin, end) since each vertex yields at most one contact. */
static void detect_range(void *ctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    detect_ctx *d = ctx;
    sw_selfcontact *sc = d->sc;
    int32_t n = 0;
    for (int64_t i = begin; i < end; ++i)
        n += sw_self_detect_vertex(&sc->m, d->x, (int32_t)i, &sc->list[begin + n], NULL);
    sc->range_count[begin] = n;
    sc->range_end[begin] = (int32_t)end;
}

/* Deepest first, ties by vertex id: the order that decides who is kept. */
static int deeper(const sw_contact *a, const sw_contact *b) {
    return a->depth > b->depth || (a->depth == b->depth && a->p < b->p);
}
static int lower_vertex(const sw_contact *a, const sw_contact *b) {
    return a->p < b->p;
}

/* In-place heap sort (qsort may allocate; detect must not). */
static void sift(sw_contact *a, int32_t n, int32_t i,
                 int (*before)(const sw_contact *, const sw_contact *)) {
    for (;;) {
        int32_t l = 2 * i + 1, r = l + 1, m = i;
        if (l < n && before(&a[m], &a[l])) m = l;
        if (r < n && before(&a[m], &a[r])) m = r;
        if (m == i) return;
        sw_contact t = a[i];
        a[i] = a[m];
        a[m] = t;
        i = m;
    }
}
static void heap_sort(sw_contact *a, int32_t n,
                      int (*before)(const sw_contact *, const sw_contact *)) {
    for (int32_t i = n / 2 - 1; i >= 0; --i)
        sift(a, n, i, before);
    for (int32_t e = n - 1; e > 0; --e) {
        sw_contact t = a[0];
        a[0] = a[e];
        a[e] = t;
        sift(a, e, 0, before);
    }
}

int32_t sw_selfcontact_detect(sw_selfcontact *sc, const double *x, sw_pool *pool) {
    if (!sc) return 0;
    sc->count = 0;
    sc->dropped = 0;
    sc->max_depth = 0;
    if (!x) return 0;
    detect_ctx d = {sc, x};
    sw_pool_parallel_for(pool, sc->m.ntets, boxes_range, &d);
    sw_bvh_refit_nodes(&sc->m.tet_bvh);
    sw_pool_parallel_for(pool, sc->m.nsurf, detect_range, &d);
    /* Concatenate the ranges in order; the result is the list in surface vertex
     * order whatever the partition (hence the thread count) was. */
    int32_t n = 0;
    for (int32_t pos = 0; pos < sc->m.nsurf; pos = sc->range_end[pos]) {
        int32_t c = sc->range_count[pos];
        if (c > 0 && n != pos)
            memmove(sc->list + n, sc->list + pos, (size_t)c * sizeof(sw_contact));
        n += c;
    }
    int32_t cap = sc->max_contacts > 0 ? sc->max_contacts : sc->m.nsurf;
    if (n > cap) {
        /* Over budget: keep the deepest (ties by vertex id), back in vertex order. */
        heap_sort(sc->list, n, deeper);
        sc->dropped = n - cap;
        n = cap;
        heap_sort(sc->list, n, lower_vertex);
    }
    sc->count = n;
    for (int32_t i = 0; i < n; ++i)
        if (sc->list[i].depth > sc->max_depth) sc->max_depth = sc->list[i].depth;
    return n;
}

const sw_contact *sw_selfcontact_list(const sw_selfcontact *sc, int32_t *count) {
    if (count) *count = sc ? sc->count : 0;
    return sc ? sc->list : NULL;
}

double sw_selfcontact_max_depth(const sw_selfcontact *sc) {
    return sc ? sc->max_depth : 0;
}

/* ---- penalty (eqs. 3.4-3.6) ------------------------------------------------------
 * The law (N, N d, the energy) is penalty.h's, shared with the runtime's step. With n
 * and beta frozen, d = J x where J = [-I, beta_0 I, beta_1 I, beta_2 I] acts on
 * (x_p, x_t0, x_t1, x_t2); each contact is a quadratic 1/2 k J^T N J. Written over four
 * slots (vertex, coefficient) so a vertex appearing twice is still exact. */

void sw_contact_slots(const sw_contact *c, int32_t v[4], double a[4]) {
    v[0] = c->p, a[0] = -1;
    for (int k = 0; k < 3; ++k)
        v[k + 1] = c->tri[k], a[k + 1] = c->beta[k];
}

static void contact_d(const sw_contact *c, const double *x, double d[3]) {
    int32_t v[4];
    double a[4];
    sw_contact_slots(c, v, a);
    d[0] = d[1] = d[2] = 0;
    for (int s = 0; s < 4; ++s)
        for (int j = 0; j < 3; ++j)
            d[j] += a[s] * x[3 * (size_t)v[s] + j];
}

double sw_contact_gap(const sw_contact *c, const double *x) {
    double d[3];
    contact_d(c, x, d);
    return sw_penalty_gap(c->n, d);
}

double sw_contact_energy(const sw_contact *c, int32_t n, const double *x, double kc, double alpha) {
    double e = 0;
    for (int32_t i = 0; i < n; ++i) {
        double d[3], Nd[3];
        contact_d(&c[i], x, d);
        sw_penalty_apply_N(c[i].n, alpha, d, Nd);
        /* 0.5 (kc ka) rather than (0.5 kc) ka: the same, scaling by 0.5 is exact */
        e += sw_penalty_energy(kc * c[i].ka, d, Nd);
    }
    return e;
}

void sw_contact_add_forces(const sw_contact *c, int32_t n, const double *x, double kc, double alpha,
                           double *f) {
    for (int32_t i = 0; i < n; ++i) {
        int32_t v[4];
        double a[4], d[3], Nd[3];
        sw_contact_slots(&c[i], v, a);
        contact_d(&c[i], x, d);
        sw_penalty_apply_N(c[i].n, alpha, d, Nd);
        double k = kc * c[i].ka;
        /* eq. 3.4 (a = -1 gives f_p = k N d) and eq. 3.6 (f_i = -beta_i k N d). */
        for (int s = 0; s < 4; ++s)
            for (int j = 0; j < 3; ++j)
                f[3 * (size_t)v[s] + j] -= a[s] * k * Nd[j];
    }
}

void sw_contact_add_diag(const sw_contact *c, int32_t n, double kc, double alpha, double *diag) {
    for (int32_t i = 0; i < n; ++i) {
        int32_t v[4];
        double a[4];
        sw_contact_slots(&c[i], v, a);
        double k = kc * c[i].ka;
        double N[9];
        sw_penalty_N(c[i].n, alpha, N);
        for (int s = 0; s < 4; ++s) {
            int seen = 0;
            for (int u = 0; u < s; ++u)
                seen |= v[u] == v[s];
            if (seen) continue;
            double coef = 0; /* total coefficient of this vertex in J */
            for (int u = s; u < 4; ++u)
                if (v[u] == v[s]) coef += a[u];
            double *D = diag + 9 * (size_t)v[s];
            for (int m = 0; m < 9; ++m)
                D[m] += k * coef * coef * N[m];
        }
    }
}

void sw_contact_apply_hessian(const sw_contact *c, int32_t n, double kc, double alpha,
                              const double *v, double *y) {
    for (int32_t i = 0; i < n; ++i) {
        double Jv[3], NJv[3];
        contact_d(&c[i], v, Jv);
        sw_penalty_apply_N(c[i].n, alpha, Jv, NJv);
        int32_t vs[4];
        double a[4];
        sw_contact_slots(&c[i], vs, a);
        double k = kc * c[i].ka;
        for (int s = 0; s < 4; ++s)
            for (int j = 0; j < 3; ++j)
                y[3 * (size_t)vs[s] + j] += a[s] * k * NJv[j];
    }
}
