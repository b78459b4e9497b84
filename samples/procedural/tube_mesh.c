/* Tube mesher: a block-structured hexahedral "O-grid", split into tets.
 *
 * Why not one structured n x n grid mapped onto the disc: every smooth square-to-disc
 * map opens the square's 90-degree corners to 180 degrees on the circle, so the
 * Jacobian there has rank 1 and the corner cells flatten as the grid is refined (the
 * elliptical grid mapping gave a 4.9-degree minimum dihedral at 2M tets, and rounded
 * caps built the same way 0.3 degrees). The O-grid keeps every cell's shape bounded at
 * any resolution:
 *  - the cross-section is a k x k core square of half-size ALPHA*R plus a ring of
 *    4k x l cells whose radial lines run from the core's boundary to the circle;
 *  - core and ring are extruded along x in M layers;
 *  - a rounded end extends the core half a core-width into the cap (a half cube around
 *    the sphere's centre) and closes it with an end block of l shells; ring and end
 *    block vertices are projected from the sphere's centre, which is the "cubed sphere"
 *    layout of the hemisphere.
 * Every hex is cut into 2 triangular prisms by its cross-section diagonal, and every
 * prism into 3 tets whose quad-face diagonals pass through the face's lowest global
 * vertex id (Dompierre et al. 1999, "How to subdivide pyramids, prisms and hexahedra
 * into tetrahedra"): a face's diagonal depends only on the face, so the tets are
 * conforming, and a prism always admits this split. Cross-section diagonals use the
 * same lowest-id rule, applied to layer-local ids, so they agree with the end blocks. */
#include "tube_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ALPHA 0.5 /* core half-size over radius: ring cells stay near square */

sinew_result sw_tube_validate(const sw_tube_profile *p, sw_error *err) {
    if (!p) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "tube profile is NULL");
    if (!isfinite(p->length) || !isfinite(p->r0) || !isfinite(p->r1))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "tube profile has a non-finite value");
    if (!(p->length > 0) || !(p->r0 > 0) || !(p->r1 > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tube length %g and radii %g, %g must be positive", p->length, p->r0,
                            p->r1);
    double caps = (p->cap_start ? p->r0 : 0.0) + (p->cap_end ? p->r1 : 0.0);
    if (!(caps < 0.99 * p->length))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tube caps (%g long) leave no body in length %g", caps, p->length);
    return SINEW_OK;
}

/* The body spans [x0, x1]; caps fill the rest. */
static void body_span(const sw_tube_profile *p, double *x0, double *x1) {
    *x0 = p->cap_start ? p->r0 : 0.0;
    *x1 = p->length - (p->cap_end ? p->r1 : 0.0);
}

double sw_tube_body_radius(const sw_tube_profile *p, double x) {
    double x0, x1;
    body_span(p, &x0, &x1);
    double t = (x - x0) / (x1 - x0);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return p->r0 + (p->r1 - p->r0) * t;
}

double sw_tube_radius(const sw_tube_profile *p, double x) {
    double x0, x1;
    body_span(p, &x0, &x1);
    if (x < 0 || x > p->length) return 0.0;
    double d = x < x0 ? x0 - x : (x > x1 ? x - x1 : 0.0); /* depth into a cap */
    double r = sw_tube_body_radius(p, x);
    return d > 0 ? sqrt(fmax(r * r - d * d, 0.0)) : r;
}

double sw_tube_volume(const sw_tube_profile *p) {
    double x0, x1;
    body_span(p, &x0, &x1);
    const double pi = 3.14159265358979323846;
    double v = pi * (x1 - x0) * (p->r0 * p->r0 + p->r0 * p->r1 + p->r1 * p->r1) / 3.0;
    if (p->cap_start) v += 2.0 / 3.0 * pi * p->r0 * p->r0 * p->r0;
    if (p->cap_end) v += 2.0 / 3.0 * pi * p->r1 * p->r1 * p->r1;
    return v;
}

/* The grid: k core cells a side, l ring shells, M layers over the core's extent
 * [xs, xe]; numbering: layer-major (layer q holds nv2 = (k+1)^2 + 4kl vertices, the
 * core grid first, then the ring shell by shell), then the end blocks' own vertices. */
typedef struct grid {
    const sw_tube_profile *p;
    int32_t k, l, M, nv2;
    int32_t mc0, mc1; /* layers in the start / end cap zone */
    double xs, xe;
    int32_t cap_base[2]; /* first own vertex of the start / end block, or -1 */
} grid;

static double layer_x(const grid *g, int32_t q);

static int32_t core2d(const grid *g, int32_t i, int32_t j) {
    return j * (g->k + 1) + i;
}

/* Core boundary vertex number t (counter-clockwise from (0,0)) as (i, j). */
static void perim(const grid *g, int32_t t, int32_t *i, int32_t *j) {
    const int32_t k = g->k, side = t / k, o = t % k;
    const int32_t I[4] = {o, k, k - o, 0}, J[4] = {0, o, k, k - o};
    *i = I[side];
    *j = J[side];
}

static int32_t perim_index(const grid *g, int32_t i, int32_t j) {
    int32_t k = g->k;
    if (j == 0 && i < k) return i;
    if (i == k && j < k) return k + j;
    if (j == k && i > 0) return 3 * k - i;
    return 4 * k - j;
}

/* Layer-local id of ring vertex (t, s); s = 0 is the core's boundary. */
static int32_t ring2d(const grid *g, int32_t t, int32_t s) {
    t %= 4 * g->k;
    if (s == 0) {
        int32_t i, j;
        perim(g, t, &i, &j);
        return core2d(g, i, j);
    }
    return (g->k + 1) * (g->k + 1) + (s - 1) * 4 * g->k + t;
}

/* Global id of core point (i, j) on shell s of end block e (0 start, 1 end). */
static int32_t cap_vertex(const grid *g, int e, int32_t i, int32_t j, int32_t s) {
    int32_t layer = e ? g->M : 0, k = g->k;
    if (s == 0) return layer * g->nv2 + core2d(g, i, j);
    if (i == 0 || j == 0 || i == k || j == k)
        return layer * g->nv2 + ring2d(g, perim_index(g, i, j), s);
    return g->cap_base[e] + (s - 1) * (k - 1) * (k - 1) + (j - 1) * (k - 1) + (i - 1);
}

/* Core point (i, j) on the layer at x. */
static void core_point(const grid *g, int32_t i, int32_t j, double x, double *c) {
    double a = ALPHA * sw_tube_body_radius(g->p, x);
    c[0] = x;
    c[1] = a * (-1.0 + 2.0 * i / g->k);
    c[2] = a * (-1.0 + 2.0 * j / g->k);
}

/* Surface point a core point c maps to: radially out from the axis in the body, from
 * the sphere's centre in a cap. */
static void surface_point(const grid *g, const double *c, double *P) {
    double x0, x1;
    body_span(g->p, &x0, &x1);
    double ctr[3] = {c[0], 0, 0}, r;
    if (g->p->cap_start && c[0] < x0)
        ctr[0] = x0, r = g->p->r0;
    else if (g->p->cap_end && c[0] > x1)
        ctr[0] = x1, r = g->p->r1;
    else
        r = sw_tube_body_radius(g->p, c[0]);
    double d[3] = {c[0] - ctr[0], c[1], c[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int a = 0; a < 3; ++a)
        P[a] = ctr[a] + r * d[a] / len;
}

static void place(const grid *g, const double *c, int32_t s, double *X) {
    double P[3];
    surface_point(g, c, P);
    double f = (double)s / g->l;
    for (int a = 0; a < 3; ++a)
        X[a] = c[a] + f * (P[a] - c[a]);
}

static void place_vertices(const grid *g, double *X, unsigned char *surf) {
    const int32_t k = g->k, l = g->l;
    for (int32_t q = 0; q <= g->M; ++q) {
        double x = layer_x(g, q), c[3];
        int flat = (q == 0 && !g->p->cap_start) || (q == g->M && !g->p->cap_end);
        for (int32_t j = 0; j <= k; ++j)
            for (int32_t i = 0; i <= k; ++i) {
                int32_t id = q * g->nv2 + core2d(g, i, j);
                core_point(g, i, j, x, c);
                memcpy(X + 3 * id, c, sizeof c);
                if (surf) surf[id] = (unsigned char)flat;
            }
        for (int32_t s = 1; s <= l; ++s)
            for (int32_t t = 0; t < 4 * k; ++t) {
                int32_t i, j, id = q * g->nv2 + ring2d(g, t, s);
                perim(g, t, &i, &j);
                core_point(g, i, j, x, c);
                place(g, c, s, X + 3 * id);
                if (surf) surf[id] = (unsigned char)(flat || s == l);
            }
    }
    for (int e = 0; e < 2; ++e) {
        if (g->cap_base[e] < 0) continue;
        double x = e ? g->xe : g->xs, c[3];
        for (int32_t s = 1; s <= l; ++s)
            for (int32_t j = 1; j < k; ++j)
                for (int32_t i = 1; i < k; ++i) {
                    int32_t id = cap_vertex(g, e, i, j, s);
                    core_point(g, i, j, x, c);
                    place(g, c, s, X + 3 * id);
                    if (surf) surf[id] = (unsigned char)(s == l);
                }
    }
}

/* Splits the prism (v[0..2] bottom, v[3..5] top above them) into 3 tets (Dompierre et
 * al.): rotate the lowest id to v[0]; the face opposite it takes the diagonal through
 * its lower id. */
static void split_prism(const int32_t *v, int32_t *out) {
    static const int sym[6][6] = {{0, 1, 2, 3, 4, 5}, {1, 2, 0, 4, 5, 3}, {2, 0, 1, 5, 3, 4},
                                  {3, 5, 4, 0, 2, 1}, {4, 3, 5, 1, 0, 2}, {5, 4, 3, 2, 1, 0}};
    int lo = 0;
    for (int a = 1; a < 6; ++a)
        if (v[a] < v[lo]) lo = a;
    int32_t w[6];
    for (int a = 0; a < 6; ++a)
        w[a] = v[sym[lo][a]];
    int d15 = (w[1] < w[5] ? w[1] : w[5]) < (w[2] < w[4] ? w[2] : w[4]);
    const int32_t t1[12] = {w[0], w[1], w[2], w[5], w[0], w[1], w[5], w[4], w[0], w[4], w[5], w[3]};
    const int32_t t2[12] = {w[0], w[1], w[2], w[4], w[0], w[4], w[2], w[5], w[0], w[4], w[5], w[3]};
    memcpy(out, d15 ? t1 : t2, sizeof t1);
}

/* Emits the 6 tets of the hex whose bottom quad is b[0..3] (cyclic) and top quad
 * u[0..3] (above b), cutting both quads along the diagonal through the quad's lowest
 * local id (lid). */
static int32_t emit_hex(const int32_t *b, const int32_t *u, const int32_t *lid, int32_t *out) {
    int lo = 0;
    for (int a = 1; a < 4; ++a)
        if (lid[a] < lid[lo]) lo = a;
    int a0 = lo, a1 = (lo + 1) % 4, a2 = (lo + 2) % 4, a3 = (lo + 3) % 4;
    const int32_t p1[6] = {b[a0], b[a1], b[a2], u[a0], u[a1], u[a2]};
    const int32_t p2[6] = {b[a0], b[a2], b[a3], u[a0], u[a2], u[a3]};
    split_prism(p1, out);
    split_prism(p2, out + 12);
    return 6;
}

/* Cross-section quad number c: core cells first, then ring cells. Writes its 4 corners
 * as (i, j, s) triples where s >= 0 means a ring vertex (t = i) and s < 0 a core one. */
static void section_quad(const grid *g, int32_t c, int32_t corner[4][3]) {
    const int32_t k = g->k;
    if (c < k * k) {
        int32_t i = c % k, j = c / k;
        const int32_t di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
        for (int a = 0; a < 4; ++a)
            corner[a][0] = i + di[a], corner[a][1] = j + dj[a], corner[a][2] = -1;
    } else {
        c -= k * k;
        int32_t t = c % (4 * k), s = c / (4 * k);
        const int32_t dt[4] = {0, 1, 1, 0}, ds[4] = {0, 0, 1, 1};
        for (int a = 0; a < 4; ++a)
            corner[a][0] = t + dt[a], corner[a][1] = 0, corner[a][2] = s + ds[a];
    }
}

static int32_t local_id(const grid *g, const int32_t *corner) {
    return corner[2] < 0 ? core2d(g, corner[0], corner[1]) : ring2d(g, corner[0], corner[2]);
}

static int64_t emit_all(const grid *g, int32_t *tets) {
    const int32_t k = g->k, nq = k * k + 4 * k * g->l;
    int64_t t = 0;
    for (int32_t q = 0; q < g->M; ++q)
        for (int32_t c = 0; c < nq; ++c) {
            int32_t corner[4][3], lid[4], b[4], u[4];
            section_quad(g, c, corner);
            for (int a = 0; a < 4; ++a) {
                lid[a] = local_id(g, corner[a]);
                b[a] = q * g->nv2 + lid[a];
                u[a] = b[a] + g->nv2;
            }
            t += emit_hex(b, u, lid, tets + 4 * t);
        }
    for (int e = 0; e < 2; ++e) {
        if (g->cap_base[e] < 0) continue;
        for (int32_t s = 0; s < g->l; ++s)
            for (int32_t c = 0; c < k * k; ++c) {
                int32_t corner[4][3], lid[4], b[4], u[4];
                section_quad(g, c, corner);
                for (int a = 0; a < 4; ++a) {
                    lid[a] = core2d(g, corner[a][0], corner[a][1]);
                    b[a] = cap_vertex(g, e, corner[a][0], corner[a][1], s);
                    u[a] = cap_vertex(g, e, corner[a][0], corner[a][1], s + 1);
                }
                t += emit_hex(b, u, lid, tets + 4 * t);
            }
    }
    return t;
}

/* Resolution: core cells of side 2*ALPHA*R/k and layers about as thick, but at least 12
 * boundary edges around the circle (fewer make a poor circle) and at least one layer
 * per cap zone and in the body. */
static void choose_grid(const sw_tube_profile *p, int32_t target, grid *g) {
    double x0, x1;
    body_span(p, &x0, &x1);
    g->p = p;
    g->xs = p->cap_start ? x0 - ALPHA * p->r0 : 0.0;
    g->xe = p->cap_end ? x1 + ALPHA * p->r1 : p->length;
    double rbar = 0.5 * (p->r0 + p->r1), span = g->xe - g->xs;
    int ncaps = (p->cap_start != 0) + (p->cap_end != 0);
    /* tets ~ 6 (k^2 + 4 k l) M with l ~ 0.4 k, M ~ span k / (2 ALPHA rbar) */
    int32_t k = (int32_t)lround(cbrt(target * 2.0 * ALPHA * rbar / (6.0 * 2.6 * span)));
    if (k < 3) k = 3;
    int32_t l = (int32_t)(0.4 * k);
    if (l < 1) l = 1;
    double per_layer = 6.0 * (k * k + 4.0 * k * l);
    double layers = (target - ncaps * 6.0 * k * k * l) / per_layer, h = span / fmax(layers, 1.0);
    /* Cap zones get layers as thick as the body's, so the half cube's cells stay cubic. */
    g->mc0 = p->cap_start ? (int32_t)fmax(1.0, (double)lround(ALPHA * p->r0 / h)) : 0;
    g->mc1 = p->cap_end ? (int32_t)fmax(1.0, (double)lround(ALPHA * p->r1 / h)) : 0;
    int32_t mb = (int32_t)lround(layers) - g->mc0 - g->mc1;
    if (mb < 1) mb = 1;
    g->k = k, g->l = l, g->M = g->mc0 + mb + g->mc1;
    g->nv2 = (k + 1) * (k + 1) + 4 * k * l;
}

/* x of layer q: uniform within each cap zone and within the body. */
static double layer_x(const grid *g, int32_t q) {
    double x0 = g->p->cap_start ? g->p->r0 : g->xs;
    double x1 = g->p->cap_end ? g->p->length - g->p->r1 : g->xe;
    int32_t mb = g->M - g->mc0 - g->mc1;
    if (q <= g->mc0 && g->mc0 > 0) return g->xs + (x0 - g->xs) * q / g->mc0;
    if (q <= g->mc0 + mb) return x0 + (x1 - x0) * (q - g->mc0) / mb;
    return x1 + (g->xe - x1) * (q - g->mc0 - mb) / g->mc1;
}

sinew_result sw_tube_mesh(const sw_tube_profile *p, int32_t target_tets, sw_tetmesh *out,
                          unsigned char **on_surface, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "tube mesh output is NULL");
    memset(out, 0, sizeof *out);
    if (on_surface) *on_surface = NULL;
    sinew_result r = sw_tube_validate(p, err);
    if (r != SINEW_OK) return r;
    if (target_tets < 1000 || target_tets > 2000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tube target of %d tets is outside [1000, 2000000]", target_tets);
    grid g;
    choose_grid(p, target_tets, &g);
    const int64_t k = g.k, l = g.l, ncap = (k - 1) * (k - 1) * l;
    int64_t nverts = (int64_t)g.nv2 * (g.M + 1), ntets = 6 * (k * k + 4 * k * l) * g.M;
    g.cap_base[0] = g.cap_base[1] = -1;
    for (int e = 0; e < 2; ++e)
        if (e ? p->cap_end : p->cap_start) {
            g.cap_base[e] = (int32_t)(nverts < INT32_MAX ? nverts : 0);
            nverts += ncap;
            ntets += 6 * k * k * l;
        }
    if (ntets > INT32_MAX / 4 || nverts > INT32_MAX / 3)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tube grid (k %d, l %d, %d layers) is too large for length %g", g.k,
                            g.l, g.M, p->length);
    double *X = malloc(sizeof(double) * 3 * (size_t)nverts);
    int32_t *tets = malloc(sizeof(int32_t) * 4 * (size_t)ntets);
    unsigned char *surf = on_surface ? malloc((size_t)nverts) : NULL;
    if (!X || !tets || (on_surface && !surf)) {
        free(X);
        free(tets);
        free(surf);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "out of memory meshing a tube of %lld tets", (long long)ntets);
    }
    place_vertices(&g, X, surf);
    emit_all(&g, tets);
    for (int64_t t = 0; t < ntets; ++t) { /* orient: the prism split ignores handedness */
        int32_t *q = tets + 4 * t;
        double vol = sw_tet_signed_volume(X + 3 * q[0], X + 3 * q[1], X + 3 * q[2], X + 3 * q[3]);
        if (vol < 0) {
            int32_t tmp = q[2];
            q[2] = q[3];
            q[3] = tmp;
        } else if (!(vol > 0)) {
            free(X);
            free(tets);
            free(surf);
            return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tube tet %lld is flat", (long long)t);
        }
    }
    out->nverts = (int32_t)nverts;
    out->ntets = (int32_t)ntets;
    out->X = X;
    out->tets = tets;
    if (on_surface) *on_surface = surf;
    return SINEW_OK;
}
