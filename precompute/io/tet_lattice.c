/* A tet mesh from a render surface: a lattice cut by the generalised winding number
 * (tet_lattice.h). */
#include "tet_lattice.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "vec3.h"
#include "winding.h"

/* A surface that encloses no volume is meshed as a shell of this share of its bounding
 * box's diagonal on each side. */
#define SW_LATTICE_SHELL 0.02

/* Lattices of more cubes than this are refused (memory: a byte and an index each). */
#define SW_LATTICE_MAX_CELLS 100000000LL

typedef struct {
    sw_winding_tree *tree;
    double origin[3], h;
    int32_t n[3];
    unsigned char *inside; /* n[0] n[1] n[2] cubes, x fastest */
} lattice;

static void classify_cells(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    lattice *L = vctx;
    for (int64_t c = begin; c < end; ++c) {
        int64_t i = c % L->n[0], j = (c / L->n[0]) % L->n[1], k = c / ((int64_t)L->n[0] * L->n[1]);
        double p[3] = {L->origin[0] + (i + 0.5) * L->h, L->origin[1] + (j + 0.5) * L->h,
                       L->origin[2] + (k + 0.5) * L->h};
        L->inside[c] = fabs(sw_winding_tree_eval(L->tree, p)) >= 0.5;
    }
}

/* Classifies the cubes of spacing h over the box [lo, hi]; returns the number inside,
 * or -1 when out of memory or the lattice is too large. */
static int64_t classify(lattice *L, const double lo[3], const double hi[3], double h,
                        sw_pool *pool) {
    int64_t total = 1;
    L->h = h;
    for (int a = 0; a < 3; ++a) {
        /* half a cube of margin each side: no cube centre on the surface's extremes */
        double ext = hi[a] - lo[a];
        L->n[a] = (int32_t)ceil(ext / h) + 1;
        L->origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * L->n[a] * h;
        total *= L->n[a];
        if (total > SW_LATTICE_MAX_CELLS) return -1;
    }
    free(L->inside);
    if (!(L->inside = malloc((size_t)total))) return -1;
    sw_pool_parallel_for(pool, total, classify_cells, L);
    int64_t k = 0;
    for (int64_t c = 0; c < total; ++c)
        k += L->inside[c];
    return k;
}

/* The six Freudenthal tets of a cube, corners numbered x + 2y + 4z: the paths from 0 to 7
 * along the three axes in each order, each ordered to be positively oriented (checked
 * on the unit cube; every cube of the lattice is a translate of it). */
static void freudenthal_tets(int32_t T[6][4]) {
    static const int perms[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4},
                                    {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
    for (int t = 0; t < 6; ++t) {
        T[t][0] = 0;
        T[t][1] = perms[t][0];
        T[t][2] = perms[t][0] + perms[t][1];
        T[t][3] = 7;
        double P[4][3];
        for (int k = 0; k < 4; ++k)
            for (int a = 0; a < 3; ++a)
                P[k][a] = (T[t][k] >> a) & 1;
        double e1[3], e2[3], e3[3];
        sw_v3_sub(P[1], P[0], e1);
        sw_v3_sub(P[2], P[0], e2);
        sw_v3_sub(P[3], P[0], e3);
        if (sw_v3_triple(e1, e2, e3) < 0) {
            int32_t s = T[t][1];
            T[t][1] = T[t][2];
            T[t][2] = s;
        }
    }
}

static int32_t find_root(int32_t *parent, int32_t x) {
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

/* Face-connected pieces among the inside cubes (cell_id: compact id or -1). */
static int32_t count_components(const lattice *L, const int32_t *cell_id, int32_t ncells) {
    int32_t *parent = malloc((size_t)ncells * sizeof(int32_t));
    if (!parent) return -1;
    for (int32_t i = 0; i < ncells; ++i)
        parent[i] = i;
    int64_t nx = L->n[0], ny = L->n[1], nz = L->n[2];
    for (int64_t k = 0; k < nz; ++k)
        for (int64_t j = 0; j < ny; ++j)
            for (int64_t i = 0; i < nx; ++i) {
                int64_t c = i + nx * (j + ny * k);
                if (cell_id[c] < 0) continue;
                int64_t nb[3] = {i + 1 < nx ? c + 1 : -1, j + 1 < ny ? c + nx : -1,
                                 k + 1 < nz ? c + nx * ny : -1};
                for (int a = 0; a < 3; ++a)
                    if (nb[a] >= 0 && cell_id[nb[a]] >= 0) {
                        int32_t ra = find_root(parent, cell_id[c]),
                                rb = find_root(parent, cell_id[nb[a]]);
                        if (ra != rb) parent[ra] = rb;
                    }
            }
    int32_t n = 0;
    for (int32_t i = 0; i < ncells; ++i)
        n += find_root(parent, i) == i;
    free(parent);
    return n;
}

static sinew_result validate(const sw_trimesh *s, int32_t target, sw_error *err) {
    sinew_result r = sw_trimesh_validate(s, "tet lattice", err);
    if (r != SINEW_OK) return r;
    if (target < 100 || target > 5000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tet lattice: %d tets requested, not in 100..5000000", target);
    return SINEW_OK;
}

/* The tets of the inside cubes over compacted lattice vertices. */
static sinew_result build_tets(const lattice *L, int64_t kept, sw_tetmesh *out, int32_t *components,
                               sw_error *err) {
    int64_t nx = L->n[0], ny = L->n[1], nz = L->n[2];
    int64_t vx = nx + 1, vy = ny + 1, nlat = vx * vy * (nz + 1), ncell = nx * ny * nz;
    int32_t freudenthal[6][4];
    freudenthal_tets(freudenthal);
    int32_t *vid = malloc((size_t)nlat * sizeof(int32_t));
    int32_t *cell_id = malloc((size_t)ncell * sizeof(int32_t));
    out->tets = malloc((size_t)kept * 24 * sizeof(int32_t));
    if (!vid || !cell_id || !out->tets) {
        free(vid);
        free(cell_id);
        sw_tetmesh_free(out);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tet lattice: out of memory");
    }
    for (int64_t i = 0; i < nlat; ++i)
        vid[i] = -1;
    int32_t nv = 0, nt = 0, nc = 0;
    for (int64_t c = 0; c < ncell; ++c) {
        cell_id[c] = L->inside[c] ? nc++ : -1;
        if (!L->inside[c]) continue;
        int64_t i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
        int32_t corner[8];
        for (int q = 0; q < 8; ++q) {
            int64_t g = (i + (q & 1)) + vx * ((j + ((q >> 1) & 1)) + vy * (k + ((q >> 2) & 1)));
            if (vid[g] < 0) vid[g] = nv++;
            corner[q] = vid[g];
        }
        for (int t = 0; t < 6; ++t, ++nt)
            for (int q = 0; q < 4; ++q)
                out->tets[4 * (size_t)nt + q] = corner[freudenthal[t][q]];
    }
    out->ntets = nt;
    out->nverts = nv;
    out->X = malloc((size_t)nv * 3 * sizeof(double));
    if (!out->X) {
        free(vid);
        free(cell_id);
        sw_tetmesh_free(out);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tet lattice: out of memory");
    }
    for (int64_t g = 0; g < nlat; ++g)
        if (vid[g] >= 0) {
            int64_t i = g % vx, j = (g / vx) % vy, k = g / (vx * vy);
            double *x = out->X + 3 * (size_t)vid[g];
            x[0] = L->origin[0] + i * L->h;
            x[1] = L->origin[1] + j * L->h;
            x[2] = L->origin[2] + k * L->h;
        }
    *components = count_components(L, cell_id, nc);
    free(vid);
    free(cell_id);
    if (*components < 0) {
        sw_tetmesh_free(out);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tet lattice: out of memory");
    }
    return SINEW_OK;
}

/* The cubes whose centre lies within r of the surface (a shell around a sheet), over the
 * box [lo, hi] (the surface's, grown by r) at spacing h: each triangle marks the cubes of
 * its own grown box. Returns the number kept, or -1 as classify. */
static int64_t classify_shell(lattice *L, const sw_trimesh *surf, const double lo[3],
                              const double hi[3], double h, double r) {
    int64_t total = 1;
    L->h = h;
    for (int a = 0; a < 3; ++a) {
        L->n[a] = (int32_t)ceil((hi[a] - lo[a]) / h) + 1;
        L->origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * L->n[a] * h;
        total *= L->n[a];
        if (total > SW_LATTICE_MAX_CELLS) return -1;
    }
    free(L->inside);
    if (!(L->inside = calloc((size_t)total, 1))) return -1;
    int64_t k = 0;
    for (int32_t t = 0; t < surf->ntris; ++t) {
        const double *A = surf->X + 3 * (size_t)surf->tris[3 * t],
                     *B = surf->X + 3 * (size_t)surf->tris[3 * t + 1],
                     *C = surf->X + 3 * (size_t)surf->tris[3 * t + 2];
        double e1[3], e2[3], nrm[3];
        sw_v3_sub(B, A, e1);
        sw_v3_sub(C, A, e2);
        sw_v3_cross(e1, e2, nrm);
        if (!(sw_v3_dot(nrm, nrm) > 0)) continue; /* no area: its edges are others' */
        int64_t c0[3], c1[3];
        for (int a = 0; a < 3; ++a) {
            double mn = fmin(A[a], fmin(B[a], C[a])) - r, mx = fmax(A[a], fmax(B[a], C[a])) + r;
            c0[a] = (int64_t)floor((mn - L->origin[a]) / h - 0.5);
            c1[a] = (int64_t)ceil((mx - L->origin[a]) / h - 0.5);
            c0[a] = c0[a] < 0 ? 0 : c0[a];
            c1[a] = c1[a] > L->n[a] - 1 ? L->n[a] - 1 : c1[a];
        }
        for (int64_t z = c0[2]; z <= c1[2]; ++z)
            for (int64_t y = c0[1]; y <= c1[1]; ++y)
                for (int64_t x = c0[0]; x <= c1[0]; ++x) {
                    int64_t c = x + L->n[0] * (y + (int64_t)L->n[1] * z);
                    if (L->inside[c]) continue;
                    double p[3] = {L->origin[0] + (x + 0.5) * h, L->origin[1] + (y + 0.5) * h,
                                   L->origin[2] + (z + 0.5) * h},
                           beta[3], q[3];
                    sw_closest_point_triangle(p, A, B, C, beta, q);
                    if (sw_v3_dist(p, q) <= r) L->inside[c] = 1, ++k;
                }
    }
    return k;
}

/* The spacing search: the count of tets falls with the spacing as its cube where the
 * shape is thick, in steps where it is thin (tubes a few cells across), where the cube
 * rule can jump back and forth over the target. So the spacings known to give too many
 * and too few bracket it, and a step that would leave the bracket halves it (in log h)
 * instead; the nearest count seen is kept. */
typedef struct lattice_search {
    double h_many, h_few;     /* the largest spacing giving too many, the smallest too few */
    double best_h, best_miss; /* the spacing of the nearest count, its |log(made/target)| */
} lattice_search;

static double next_spacing(lattice_search *ls, double h, double made, int32_t target) {
    const double miss = fabs(log(made / target));
    if (miss < ls->best_miss) ls->best_miss = miss, ls->best_h = h;
    if (made > target)
        ls->h_many = fmax(ls->h_many, h);
    else
        ls->h_few = fmin(ls->h_few, h);
    const double next = h * cbrt(made / target);
    if (ls->h_many > 0 && isfinite(ls->h_few) && !(next > ls->h_many && next < ls->h_few))
        return sqrt(ls->h_many * ls->h_few);
    return next;
}

sinew_result sw_tetmesh_from_surface(const sw_trimesh *surf, int32_t target_tets, sw_pool *pool,
                                     sw_tetmesh *out, sw_lattice_report *report, sw_error *err) {
    double t0 = sw_now_seconds();
    memset(out, 0, sizeof *out);
    sw_lattice_report rep;
    memset(&rep, 0, sizeof rep);
    sinew_result r = validate(surf, target_tets, err);
    if (r != SINEW_OK) return r;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t v = 0; v < surf->nverts; ++v)
        for (int a = 0; a < 3; ++a) {
            lo[a] = fmin(lo[a], surf->X[3 * (size_t)v + a]);
            hi[a] = fmax(hi[a], surf->X[3 * (size_t)v + a]);
        }
    double box = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]), area = 0;
    /* a sheet flat but for rounding (an exporter's axis turn leaves float noise across it)
       is a sheet: its box would ask for a spacing that no memory holds */
    double thinnest = fmin(hi[0] - lo[0], fmin(hi[1] - lo[1], hi[2] - lo[2]));
    if (thinnest <= 1e-6 * sw_v3_dist(lo, hi)) box = 0;
    for (int32_t t = 0; t < surf->ntris; ++t) {
        const int32_t *f = surf->tris + 3 * t;
        const double *A = surf->X + 3 * (size_t)f[0], *B = surf->X + 3 * (size_t)f[1],
                     *C = surf->X + 3 * (size_t)f[2];
        double e1[3], e2[3], nrm[3];
        sw_v3_sub(B, A, e1);
        sw_v3_sub(C, A, e2);
        sw_v3_cross(e1, e2, nrm);
        area += 0.5 * sw_v3_norm(nrm);
        rep.surface_volume += sw_v3_triple(A, B, C) / 6.0;
    }
    lattice L = {.tree = sw_winding_tree_create(surf)};
    if (!L.tree) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tet lattice: out of memory");
    /* first pass guessing half the box filled, then the spacing that gives the target
       for the filled volume it found (once more at a finer spacing while nothing is
       inside: a thin shape the coarse lattice missed) */
    double h = cbrt(6.0 * 0.5 * box / target_tets);
    int64_t kept = 0;
    lattice_search ls = {.h_many = 0, .h_few = INFINITY, .best_h = 0, .best_miss = INFINITY};
    for (int pass = 0, halvings = 0; box > 0 && pass < 8; ++pass) {
        kept = classify(&L, lo, hi, h, pool);
        if (kept < 0) break;
        double made = 6.0 * (double)kept;
        if (kept > 0 && fabs(made - target_tets) <= 0.2 * target_tets) break;
        if (kept == 0) {
            if (++halvings > 3) break; /* nothing at an eighth of the spacing: no volume */
            h *= 0.5;
            continue;
        }
        h = next_spacing(&ls, h, made, target_tets);
    }
    /* none within a fifth: the nearest seen, when it was not the last */
    if (kept > 0 && fabs(6.0 * (double)kept - target_tets) > 0.2 * target_tets && ls.best_h > 0 &&
        ls.best_h != L.h)
        kept = classify(&L, lo, hi, ls.best_h, pool);
    sw_winding_tree_destroy(L.tree);
    if (kept == 0 && area > 0) {
        /* no inside (a flat sheet, an open strip): a shell of half-thickness r around the
           surface, which bends as a plate of that thickness; at least two cubes through
           it */
        double rs = SW_LATTICE_SHELL * sw_v3_dist(lo, hi), glo[3], ghi[3];
        for (int a = 0; a < 3; ++a)
            glo[a] = lo[a] - rs, ghi[a] = hi[a] + rs;
        h = fmin(rs, cbrt(6.0 * area * 2 * rs / target_tets));
        for (int pass = 0; pass < 8; ++pass) {
            kept = classify_shell(&L, surf, glo, ghi, h, rs);
            if (kept <= 0) break;
            double made = 6.0 * (double)kept;
            if (fabs(made - target_tets) <= 0.2 * target_tets || (h >= rs && made > target_tets))
                break;
            h = fmin(rs, h * cbrt(made / target_tets));
        }
        rep.shell = 2 * rs;
    }
    if (kept < 0) {
        free(L.inside);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "tet lattice: a lattice of spacing %g is too large", h);
    }
    double made = 6.0 * (double)kept;
    /* a thin shape fills in steps (next_spacing): the nearest count within a factor of 2;
       a shell as thin as two cubes may hold more than asked of a small target */
    if (kept == 0 || (made > 2 * target_tets && !(rep.shell > 0)) || made < target_tets / 2.0) {
        free(L.inside);
        if (kept == 0)
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "tet lattice: the surface encloses no volume and has no area");
        return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                            "tet lattice: no spacing gives about %d tets (%.0f at the nearest)",
                            target_tets, made);
    }
    r = build_tets(&L, kept, out, &rep.components, err);
    rep.spacing = L.h;
    for (int a = 0; a < 3; ++a)
        rep.cells[a] = L.n[a];
    rep.cells_inside = (int32_t)kept;
    rep.volume = (double)kept * L.h * L.h * L.h;
    free(L.inside);
    rep.seconds = sw_now_seconds() - t0;
    if (report) *report = rep;
    return r;
}
