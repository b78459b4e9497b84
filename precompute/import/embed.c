/* Render-mesh embedding (embed.h): a uniform grid over the tets' boxes, the containing tet
 * of each render vertex from its cell, the least-extrapolating nearby tet by a ring search
 * outward for the vertices outside; the weld map by sorting the rest positions. */
#include "embed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bbox.h"
#include "bvh.h"
#include "clock.h"
#include "vec3.h"

/* A point counts as inside a tet when no barycentric is below -INSIDE_EPS (a vertex on a
 * shared face or edge, up to rounding). */
#define INSIDE_EPS 1e-12
/* The grid has about CELLS_PER_TET cells a tet, at most MAX_DIM a side. */
#define CELLS_PER_TET 1.0
#define MAX_DIM 512

typedef struct grid {
    double lo[3], h; /* origin and cell size */
    int32_t dim[3];
    int32_t *ptr;  /* cells + 1: cell c owns tets[ptr[c] .. ptr[c+1]) */
    int32_t *tets; /* tet ids, ascending within a cell */
} grid;

static void cell_of(const grid *g, const double p[3], int32_t c[3]) {
    for (int a = 0; a < 3; ++a) {
        double f = floor((p[a] - g->lo[a]) / g->h);
        c[a] = f < 0 ? 0 : f >= g->dim[a] ? g->dim[a] - 1 : (int32_t)f;
    }
}

static int64_t cell_index(const grid *g, const int32_t c[3]) {
    return ((int64_t)c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0];
}

static void tet_box(const sw_tetmesh *m, int32_t t, double lo[3], double hi[3]) {
    sw_bbox_empty(lo, hi);
    for (int k = 0; k < 4; ++k)
        sw_bbox_add(lo, hi, 1, m->X + 3 * (int64_t)m->tets[4 * (int64_t)t + k]);
}

/* Every tet listed in each cell its box overlaps: counted, then filled (CSR). */
static sinew_result grid_build(const sw_tetmesh *m, grid *g, sw_error *err) {
    double lo[3], hi[3], vol = 1;
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, m->nverts, m->X);
    double ext = sw_bbox_diagonal(lo, hi);
    for (int a = 0; a < 3; ++a)
        vol *= fmax(hi[a] - lo[a], 1e-9 * ext);
    g->h = cbrt(vol / (CELLS_PER_TET * m->ntets));
    for (int a = 0; a < 3; ++a) {
        g->lo[a] = lo[a];
        double n = ceil((hi[a] - lo[a]) / g->h);
        g->dim[a] = n < 1 ? 1 : n > MAX_DIM ? MAX_DIM : (int32_t)n;
    }
    /* a capped side: larger cells along it would be finer than needed elsewhere; keep
     * cells cubic by growing h so the largest side fits */
    for (int a = 0; a < 3; ++a)
        if (g->dim[a] == MAX_DIM) g->h = fmax(g->h, (hi[a] - lo[a]) / MAX_DIM * (1 + 1e-12));
    for (int a = 0; a < 3; ++a) {
        double n = ceil((hi[a] - lo[a]) / g->h);
        g->dim[a] = n < 1 ? 1 : (int32_t)n;
    }
    int64_t ncell = (int64_t)g->dim[0] * g->dim[1] * g->dim[2];
    g->ptr = calloc((size_t)ncell + 1, sizeof(int32_t));
    if (!g->ptr) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "embed: out of memory");
    int64_t total = 0;
    for (int pass = 0; pass < 2; ++pass) {
        for (int32_t t = 0; t < m->ntets; ++t) {
            double tlo[3], thi[3];
            int32_t c0[3], c1[3], c[3];
            tet_box(m, t, tlo, thi);
            cell_of(g, tlo, c0);
            cell_of(g, thi, c1);
            for (c[2] = c0[2]; c[2] <= c1[2]; ++c[2])
                for (c[1] = c0[1]; c[1] <= c1[1]; ++c[1])
                    for (c[0] = c0[0]; c[0] <= c1[0]; ++c[0]) {
                        int64_t i = cell_index(g, c);
                        if (pass == 0)
                            g->ptr[i + 1]++, total++;
                        else
                            g->tets[g->ptr[i]++] = t;
                    }
        }
        if (pass == 0) {
            if (total > INT32_MAX)
                return sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                                    "embed: %lld tet-cell overlaps, too many for the grid",
                                    (long long)total);
            for (int64_t i = 0; i < ncell; ++i)
                g->ptr[i + 1] += g->ptr[i];
            g->tets = malloc((size_t)(total > 0 ? total : 1) * sizeof(int32_t));
            if (!g->tets)
                return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "embed: out of memory");
        }
    }
    /* the fill advanced every ptr[i] to ptr[i+1]: shift back */
    for (int64_t i = ncell; i > 0; --i)
        g->ptr[i] = g->ptr[i - 1];
    g->ptr[0] = 0;
    return SINEW_OK;
}

/* Barycentrics of p in tet t: Cramer's rule on the edge matrix, then one step of
 * refinement on the residual p - sum b_k X_k, so that the sum reproduces p to rounding. */
static void tet_bary(const sw_tetmesh *m, int32_t t, const double p[3], double b[4]) {
    const double *X[4];
    for (int k = 0; k < 4; ++k)
        X[k] = m->X + 3 * (int64_t)m->tets[4 * (int64_t)t + k];
    double e1[3], e2[3], e3[3], d[3];
    sw_v3_sub(X[1], X[0], e1);
    sw_v3_sub(X[2], X[0], e2);
    sw_v3_sub(X[3], X[0], e3);
    double det = sw_v3_triple(e1, e2, e3);
    sw_v3_sub(p, X[0], d);
    for (int pass = 0; pass < 2; ++pass) {
        double y1 = sw_v3_triple(d, e2, e3) / det, y2 = sw_v3_triple(e1, d, e3) / det,
               y3 = sw_v3_triple(e1, e2, d) / det;
        if (pass == 0) {
            b[1] = y1, b[2] = y2, b[3] = y3;
        } else {
            b[1] += y1, b[2] += y2, b[3] += y3;
        }
        b[0] = 1.0 - b[1] - b[2] - b[3];
        for (int a = 0; a < 3; ++a) /* the residual, as the runtime sums it */
            d[a] = p[a] - (b[0] * X[0][a] + b[1] * X[1][a] + b[2] * X[2][a] + b[3] * X[3][a]);
    }
}

static double min4(const double b[4]) {
    return fmin(fmin(b[0], b[1]), fmin(b[2], b[3]));
}

/* Distance from p to tet t (0 inside): the nearest of its faces otherwise. */
static double tet_distance(const sw_tetmesh *m, int32_t t, const double p[3], const double b[4]) {
    if (min4(b) >= -INSIDE_EPS) return 0;
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    double best = INFINITY;
    for (int f = 0; f < 4; ++f) {
        const double *a = m->X + 3 * (int64_t)m->tets[4 * (int64_t)t + face[f][0]],
                     *bb = m->X + 3 * (int64_t)m->tets[4 * (int64_t)t + face[f][1]],
                     *c = m->X + 3 * (int64_t)m->tets[4 * (int64_t)t + face[f][2]];
        double beta[3], q[3];
        sw_closest_point_triangle(p, a, bb, c, beta, q);
        best = fmin(best, sw_v3_dist(p, q));
    }
    return best;
}

/* Distance from p to the box [lo, hi] (0 inside). */
static double box_distance(const double p[3], const double *lo, const double *hi) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
        double e = p[a] < lo[a] ? lo[a] - p[a] : p[a] > hi[a] ? p[a] - hi[a] : 0;
        d2 += e * e;
    }
    return sqrt(d2);
}

/* A tet within reach of the vertex: its distance, extrapolation score and barycentrics. */
typedef struct candidate {
    int32_t tet;
    double dist, score, b[4];
} candidate;

/* One render vertex's search over the grid's rings around it. Every tet within the reach
 * dmin + slack (dmin the nearest tet's distance so far, so the reach only shrinks) is a
 * candidate; the chosen one has the largest smallest barycentric among the candidates
 * still within the final reach: for a vertex inside, the tet it is deepest in; outside,
 * the one whose affine map extrapolates least; ties to the nearer, then the lower id, so
 * the result depends on nothing but the meshes. Boxes prune cells and tets before any
 * barycentric is computed. */
typedef struct search {
    const sw_tetmesh *m;
    const grid *g;
    const double *tbox;   /* 6 per tet: its box */
    int32_t *stamp, mark; /* stamp[t] == mark: tet t seen for this vertex */
    double slack;         /* how much farther than the nearest a tet may be */
    double dmin;          /* the nearest tet's distance so far */
    candidate *cand;
    int32_t ncand, cap;
    int oom;
} search;

static void consider(search *s, int32_t t, const double p[3]) {
    if (s->stamp[t] == s->mark) return;
    s->stamp[t] = s->mark;
    if (box_distance(p, s->tbox + 6 * (int64_t)t, s->tbox + 6 * (int64_t)t + 3) >
        s->dmin + s->slack)
        return;
    candidate c;
    c.tet = t;
    tet_bary(s->m, t, p, c.b);
    c.dist = tet_distance(s->m, t, p, c.b);
    c.score = -min4(c.b);
    s->dmin = fmin(s->dmin, c.dist);
    if (c.dist > s->dmin + s->slack) return;
    if (s->ncand == s->cap) {
        int32_t cap = s->cap ? 2 * s->cap : 256;
        candidate *grown = realloc(s->cand, (size_t)cap * sizeof *grown);
        if (!grown) {
            s->oom = 1;
            return;
        }
        s->cand = grown, s->cap = cap;
    }
    s->cand[s->ncand++] = c;
}

/* The tets of the cells at Chebyshev distance exactly r from cell c0 within reach. */
static void visit_ring(search *s, const int32_t c0[3], int32_t r, const double p[3]) {
    const grid *g = s->g;
    int32_t lo[3], hi[3], c[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = c0[a] - r < 0 ? 0 : c0[a] - r;
        hi[a] = c0[a] + r >= g->dim[a] ? g->dim[a] - 1 : c0[a] + r;
    }
    for (c[2] = lo[2]; c[2] <= hi[2]; ++c[2])
        for (c[1] = lo[1]; c[1] <= hi[1]; ++c[1])
            for (c[0] = lo[0]; c[0] <= hi[0]; ++c[0]) {
                int32_t ring = 0;
                double clo[3], chi[3];
                for (int a = 0; a < 3; ++a) {
                    int32_t da = c[a] > c0[a] ? c[a] - c0[a] : c0[a] - c[a];
                    ring = da > ring ? da : ring;
                    clo[a] = g->lo[a] + c[a] * g->h;
                    chi[a] = clo[a] + g->h;
                }
                if (ring != r || box_distance(p, clo, chi) > s->dmin + s->slack) continue;
                int64_t i = cell_index(g, c);
                for (int32_t k = g->ptr[i]; k < g->ptr[i + 1]; ++k)
                    consider(s, g->tets[k], p);
            }
}

/* A cell at ring r + 1 or beyond is at least r h from p (p lies in, or beyond the grid
 * from, its own clamped cell), so the rings stop once r h exceeds the reach; a vertex
 * inside a tet is done after its own cell, which lists every tet holding it. Returns the
 * chosen candidate, NULL when out of memory. */
static const candidate *embed_vertex(search *s, const double p[3]) {
    const grid *g = s->g;
    int32_t c0[3];
    cell_of(g, p, c0);
    int32_t rmax = g->dim[0];
    rmax = g->dim[1] > rmax ? g->dim[1] : rmax;
    rmax = g->dim[2] > rmax ? g->dim[2] : rmax;
    s->dmin = INFINITY;
    s->ncand = 0;
    s->mark++;
    for (int32_t r = 0; r <= rmax; ++r) {
        visit_ring(s, c0, r, p);
        if (s->dmin == 0 || r * g->h > s->dmin + s->slack) break;
    }
    if (s->oom) return NULL;
    const candidate *best = NULL;
    for (int32_t k = 0; k < s->ncand; ++k) {
        const candidate *c = &s->cand[k];
        if (c->dist > s->dmin + s->slack) continue;
        if (!best || c->score < best->score ||
            (c->score == best->score &&
             (c->dist < best->dist || (c->dist == best->dist && c->tet < best->tet))))
            best = c;
    }
    return best;
}

/* ---- weld ---------------------------------------------------------------------- */

typedef struct keyed {
    double x[3];
    int32_t i;
} keyed;

/* Position order (-0 and 0 are one position), then index. */
static int position_cmp(const keyed *a, const keyed *b) {
    for (int k = 0; k < 3; ++k)
        if (a->x[k] != b->x[k]) return a->x[k] < b->x[k] ? -1 : 1;
    return 0;
}

static int keyed_cmp(const void *pa, const void *pb) {
    const keyed *a = pa, *b = pb;
    int c = position_cmp(a, b);
    return c ? c : (a->i > b->i) - (a->i < b->i);
}

/* weld[i]: the lowest index among the render vertices at i's rest position. */
static sinew_result weld_map(const sw_trimesh *r, int32_t *weld, int32_t *nwelded, sw_error *err) {
    keyed *k = malloc((size_t)r->nverts * sizeof *k);
    if (!k) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "embed: out of memory");
    for (int32_t i = 0; i < r->nverts; ++i) {
        memcpy(k[i].x, r->X + 3 * (int64_t)i, sizeof k[i].x);
        k[i].i = i;
    }
    qsort(k, (size_t)r->nverts, sizeof *k, keyed_cmp);
    *nwelded = 0;
    for (int32_t j = 0, rep = 0; j < r->nverts; ++j) {
        if (j > 0 && position_cmp(&k[j], &k[j - 1]) != 0) rep = j;
        /* equal keys sort by index: the group's first is its lowest */
        weld[k[j].i] = k[rep].i;
        *nwelded += rep != j;
    }
    free(k);
    return SINEW_OK;
}

sinew_result sw_embed_render(const sw_tetmesh *mesh, const sw_trimesh *render, sw_embedding *out,
                             sw_error *err) {
    memset(out, 0, sizeof *out);
    double t0 = sw_now_seconds();
    sinew_result r = sw_trimesh_validate(render, "embed: the render mesh", err);
    if (r != SINEW_OK) return r;
    if (!mesh || mesh->ntets < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "embed: no tets to embed in");
    int32_t n = render->nverts;
    grid g;
    memset(&g, 0, sizeof g);
    search s;
    memset(&s, 0, sizeof s);
    out->nverts = n;
    out->tet = malloc((size_t)n * sizeof(int32_t));
    out->bary = malloc((size_t)n * 4 * sizeof(double));
    out->weld = malloc((size_t)n * sizeof(int32_t));
    s.stamp = calloc((size_t)mesh->ntets, sizeof(int32_t));
    double *tbox = malloc((size_t)mesh->ntets * 6 * sizeof(double));
    if (!out->tet || !out->bary || !out->weld || !s.stamp || !tbox) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "embed: out of memory");
        goto done;
    }
    if ((r = weld_map(render, out->weld, &out->nwelded, err)) != SINEW_OK ||
        (r = grid_build(mesh, &g, err)) != SINEW_OK)
        goto done;
    s.m = mesh;
    s.g = &g;
    s.tbox = tbox;
    s.slack = 0.25 * g.h;
    for (int32_t t = 0; t < mesh->ntets; ++t)
        tet_box(mesh, t, tbox + 6 * (int64_t)t, tbox + 6 * (int64_t)t + 3);
    out->worst = -1;
    for (int32_t i = 0; i < n; ++i) {
        int32_t w = out->weld[i];
        if (w != i) { /* a duplicate: its representative (a lower index) is done */
            out->tet[i] = out->tet[w];
            memcpy(out->bary + 4 * (int64_t)i, out->bary + 4 * (int64_t)w, 4 * sizeof(double));
            continue;
        }
        const double *p = render->X + 3 * (int64_t)i;
        const candidate *c = embed_vertex(&s, p);
        if (!c) {
            r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "embed: out of memory");
            goto done;
        }
        out->tet[i] = c->tet;
        memcpy(out->bary + 4 * (int64_t)i, c->b, sizeof c->b);
        double bmax = fmax(fmax(fabs(c->b[0]), fabs(c->b[1])), fmax(fabs(c->b[2]), fabs(c->b[3])));
        out->max_bary = fmax(out->max_bary, bmax);
        if (s.dmin > 0) {
            out->outside++;
            if (s.dmin > out->max_outside) out->max_outside = s.dmin, out->worst = i;
        }
        if (bmax > SW_EMBED_MAX_BARY) {
            r = sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                             "embed: render vertex %d (%g, %g, %g) lies %g outside the tets; "
                             "reaching it from tet %d takes barycentrics up to %g (at most %g): "
                             "the render mesh does not fit the simulation mesh",
                             i, p[0], p[1], p[2], s.dmin, c->tet, bmax, SW_EMBED_MAX_BARY);
            goto done;
        }
    }
    r = SINEW_OK;
done:
    free(g.ptr);
    free(g.tets);
    free(s.stamp);
    free(s.cand);
    free(tbox);
    if (r != SINEW_OK) sw_embedding_free(out);
    out->seconds = sw_now_seconds() - t0;
    return r;
}

void sw_embedding_free(sw_embedding *e) {
    if (!e) return;
    free(e->tet);
    free(e->bary);
    free(e->weld);
    memset(e, 0, sizeof *e);
}
