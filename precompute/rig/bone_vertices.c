/* Which vertices each bone drives rigidly ("inside the bone"). The reference simulator
 * prescribes these from the bone transforms; every other vertex is free flesh.
 *
 * A bone's flesh radius is estimated as the distance from its segment to the nearest
 * surface vertex that the bone dominates (by skin weight) beside the segment, or the
 * median distance to those it dominates when none is beside it (flesh_radii). Interior vertices
 * dominated by the bone and closer to the segment than SW_BONE_RADIUS_FRACTION of that radius are
 * driven by it. Each bone then gets at least four non-coplanar driven vertices (adding
 * the nearest free interior vertices), so a bone's rigid motion is always fully pinned
 * down and no domain is left floating. Surface vertices are never driven: they carry the
 * secondary motion we are simulating. Everything is ordered by (distance, index), so the
 * result is deterministic. */
#include "rig.h"

#include "mesh_io.h"
#include "vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SW_BONE_RADIUS_FRACTION 0.4
#define SW_BONE_MIN_DRIVEN 4
#define SW_BONE_REACH 2.0

static double bone_distance(const sw_tetmesh *m, const sw_skeleton *s, int32_t v, int32_t b) {
    return sw_point_segment_distance(m->X + 3 * v, s->joints + 3 * s->bones[2 * b],
                                     s->joints + 3 * s->bones[2 * b + 1]);
}

/* Affine rank of the listed vertices (-1 none, 0 point, 1 line, 2 plane, 3 space), found
 * greedily: the point farthest from the first, then the largest triangle, then the
 * largest tet, each compared with the set's extent (1e-3 relative). */
static int affine_rank(const sw_tetmesh *m, const int32_t *ids, int32_t n) {
    if (n < 2) return n - 1; /* empty: -1 */
    const double *a = m->X + 3 * ids[0];
    double e1[3] = {0, 0, 0}, L2 = 0, A2 = 0, nrm[3] = {0, 0, 0}, vol = 0;
    for (int32_t i = 1; i < n; ++i) {
        double d[3];
        sw_v3_sub(m->X + 3 * ids[i], a, d);
        if (sw_v3_dot(d, d) > L2) {
            L2 = sw_v3_dot(d, d);
            memcpy(e1, d, sizeof d);
        }
    }
    if (!(L2 > 0)) return 0;
    for (int32_t i = 1; i < n; ++i) {
        double d[3], c[3];
        sw_v3_sub(m->X + 3 * ids[i], a, d);
        sw_v3_cross(e1, d, c);
        if (sw_v3_dot(c, c) > A2) {
            A2 = sw_v3_dot(c, c);
            memcpy(nrm, c, sizeof c);
        }
    }
    if (!(A2 > 1e-6 * L2 * L2)) return 1; /* all within 1e-3 L of a line */
    for (int32_t i = 1; i < n; ++i) {
        double d[3];
        sw_v3_sub(m->X + 3 * ids[i], a, d);
        vol = fmax(vol, fabs(sw_v3_dot(nrm, d)));
    }
    return vol > 1e-3 * sqrt(L2) * sqrt(A2) ? 3 : 2; /* a point 1e-3 L off the plane */
}

typedef struct cand {
    int tier; /* lower tiers are taken first */
    double d;
    int32_t v;
} cand;

static int cand_cmp(const void *pa, const void *pb) {
    const cand *a = pa, *b = pb;
    if (a->tier != b->tier) return a->tier < b->tier ? -1 : 1;
    if (a->d != b->d) return a->d < b->d ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

/* Last resort for bone b when the shared pass left it short: free interior vertices
 * within its reach first, then the nearest free vertices of any kind, surface included.
 * A coarse mesh can have no interior vertex anywhere near a thin limb (the elephant's
 * legs); driving the limb's own skin is then better than driving flesh far away or
 * leaving the limb undriven. A candidate is only taken when it raises the set's
 * affine rank, so a flat set gains one vertex off its plane rather than every nearer
 * vertex in that plane (rank 3 implies at least SW_BONE_MIN_DRIVEN = 4 vertices). */
static sinew_result top_up(const sw_tetmesh *m, const sw_skeleton *s, const unsigned char *surf,
                           double reach, int32_t *bov, int32_t b, int32_t *ids, cand *c,
                           sw_error *err) {
    int32_t n = 0, nc = 0;
    for (int32_t v = 0; v < m->nverts; ++v)
        if (bov[v] == b) ids[n++] = v;
    int rank = affine_rank(m, ids, n);
    if (n >= SW_BONE_MIN_DRIVEN && rank == 3) return SINEW_OK;
    for (int32_t v = 0; v < m->nverts; ++v) {
        if (bov[v] != -1) continue;
        double d = bone_distance(m, s, v, b);
        c[nc++] = (cand){!surf[v] && d <= reach ? 0 : 1, d, v};
    }
    qsort(c, (size_t)nc, sizeof *c, cand_cmp);
    for (int32_t k = 0; k < nc; ++k) {
        ids[n] = c[k].v;
        int r = affine_rank(m, ids, n + 1);
        if (r <= rank) continue;
        bov[c[k].v] = b;
        rank = r;
        if (++n >= SW_BONE_MIN_DRIVEN && rank == 3) return SINEW_OK;
    }
    return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                        "bone %d: only %d free vertices can be driven by it and they do not span "
                        "3-D (the mesh has too few vertices for %d bones)",
                        b, n, s->nbones);
}

/* Whether bone b already has enough driven vertices; fills ids with them. */
static int satisfied(const sw_tetmesh *m, const int32_t *bov, int32_t b, int32_t *ids, int32_t *n,
                     int *rank) {
    *n = 0;
    for (int32_t v = 0; v < m->nverts; ++v)
        if (bov[v] == b) ids[(*n)++] = v;
    *rank = affine_rank(m, ids, *n);
    return *n >= SW_BONE_MIN_DRIVEN && *rank == 3;
}

typedef struct pair {
    double d;
    int32_t v, b;
} pair;

static int pair_cmp(const void *pa, const void *pb) {
    const pair *a = pa, *b = pb;
    if (a->d != b->d) return a->d < b->d ? -1 : 1;
    if (a->b != b->b) return a->b < b->b ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

/* One shared pass over (vertex, bone) pairs of the bones still short of vertices,
 * nearest pair first: on a coarse mesh with few interior vertices this hands each free
 * vertex to the closest bone that needs it instead of to whichever bone asks first.
 * Candidates are each needy bone's SW_BONE_TOPUP_CANDIDATES nearest free interior
 * vertices within its reach; bones still short afterwards fall back to top_up. */
#define SW_BONE_TOPUP_CANDIDATES 32
static sinew_result shared_top_up(const sw_tetmesh *m, const sw_skeleton *s,
                                  const unsigned char *surf, const unsigned char *drives,
                                  const double *reach, int32_t *bov, int32_t *ids, cand *c,
                                  sw_error *err) {
    int32_t n, nneedy = 0, np = 0;
    int rank;
    for (int32_t b = 0; b < s->nbones; ++b)
        nneedy += drives[b] && !satisfied(m, bov, b, ids, &n, &rank);
    if (nneedy == 0) return SINEW_OK;
    pair *p = malloc(sizeof(pair) * (size_t)nneedy * SW_BONE_TOPUP_CANDIDATES);
    if (!p) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "bone vertices: out of memory");
    for (int32_t b = 0; b < s->nbones; ++b) {
        if (!drives[b] || satisfied(m, bov, b, ids, &n, &rank)) continue;
        int32_t nc = 0;
        for (int32_t v = 0; v < m->nverts; ++v)
            if (!surf[v] && bov[v] == -1) {
                double d = bone_distance(m, s, v, b);
                if (d <= reach[b]) c[nc++] = (cand){0, d, v};
            }
        qsort(c, (size_t)nc, sizeof *c, cand_cmp);
        for (int32_t k = 0; k < nc && k < SW_BONE_TOPUP_CANDIDATES; ++k)
            p[np++] = (pair){c[k].d, c[k].v, b};
    }
    qsort(p, (size_t)np, sizeof *p, pair_cmp);
    for (int32_t k = 0; k < np; ++k) {
        if (bov[p[k].v] != -1 || satisfied(m, bov, p[k].b, ids, &n, &rank)) continue;
        ids[n] = p[k].v;
        if (affine_rank(m, ids, n + 1) <= rank) continue;
        bov[p[k].v] = p[k].b;
    }
    free(p);
    return SINEW_OK;
}

static int double_cmp(const void *pa, const void *pb) {
    double a = *(const double *)pa, b = *(const double *)pb;
    return a < b ? -1 : a > b;
}

/* Flesh radius of each bone: the distance from its segment to the nearest surface
 * vertex it dominates, counting only vertices beside the segment (projecting strictly
 * inside it), since joints at the tips of limbs sit at or beyond the skin. A bone with
 * no dominated surface vertex beside its segment takes the median distance to the
 * surface vertices it dominates instead: its segment runs along an edge of its flesh or
 * outside it (a head whose bone sits at the neck), and the nearest of them is skin next
 * to the joint. From that nearest skin, the robot's box head got one driven tet: free
 * flesh pinned at one point, and most of the robot's correction error was there. Falls
 * back to any surface vertex. dist: scratch of nverts doubles. */
static void flesh_radii(const sw_tetmesh *m, const sw_skeleton *s, const unsigned char *surf,
                        const int32_t *dom, double *radius, double *dist) {
    for (int32_t b = 0; b < s->nbones; ++b) {
        const double *h = s->joints + 3 * s->bones[2 * b], *t = s->joints + 3 * s->bones[2 * b + 1];
        double ax[3], L2, beside = INFINITY, any = INFINITY;
        int32_t nown = 0;
        sw_v3_sub(t, h, ax);
        L2 = sw_v3_dot(ax, ax);
        for (int32_t v = 0; v < m->nverts; ++v) {
            if (!surf[v]) continue;
            double d = bone_distance(m, s, v, b), hv[3];
            any = fmin(any, d);
            if (dom[v] != b) continue;
            dist[nown++] = d;
            sw_v3_sub(m->X + 3 * v, h, hv);
            double u = sw_v3_dot(hv, ax);
            if (u > 0 && u < L2) beside = fmin(beside, d);
        }
        if (isfinite(beside) || nown == 0) {
            radius[b] = isfinite(beside) ? beside : any;
            continue;
        }
        qsort(dist, (size_t)nown, sizeof(double), double_cmp); /* (distance order: deterministic) */
        radius[b] = dist[nown / 2];
    }
}

static sinew_result check_inputs(const sw_tetmesh *m, const sw_skeleton *s, const sw_weights *w,
                                 const int32_t *bov, sw_error *err) {
    if (!m || !s || !w || !bov || !w->w)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "bone vertices: NULL argument");
    sinew_result rc = sw_tetmesh_validate(m, 0.0, err);
    if (rc) return rc;
    if ((rc = sw_skeleton_validate(s, err))) return rc;
    if (w->nverts != m->nverts || w->nbones != s->nbones)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "bone vertices: weights are %d x %d but the mesh has %d vertices and "
                            "the skeleton %d bones",
                            w->nverts, w->nbones, m->nverts, s->nbones);
    return SINEW_OK;
}

sinew_result sw_select_bone_vertices(const sw_tetmesh *m, const sw_skeleton *s, const sw_weights *w,
                                     int32_t *bone_of_vertex, sw_error *err) {
    return sw_select_bone_vertices_of(m, s, w, NULL, bone_of_vertex, err);
}

sinew_result sw_select_bone_vertices_of(const sw_tetmesh *m, const sw_skeleton *s,
                                        const sw_weights *w, const unsigned char *drives_in,
                                        int32_t *bone_of_vertex, sw_error *err) {
    sinew_result rc = check_inputs(m, s, w, bone_of_vertex, err);
    if (rc) return rc;
    sw_surface surface = {0};
    if ((rc = sw_tetmesh_surface(m, &surface, err))) return rc;
    int32_t n = m->nverts;
    unsigned char *surf = calloc((size_t)n, 1);
    int32_t *dom = malloc(sizeof(int32_t) * (size_t)n);
    int32_t *ids = malloc(sizeof(int32_t) * (size_t)n);
    cand *c = malloc(sizeof(cand) * (size_t)n);
    double *radius = malloc(sizeof(double) * (size_t)s->nbones);
    double *dist = malloc(sizeof(double) * (size_t)n);
    unsigned char *drives = malloc((size_t)s->nbones);
    if (!surf || !dom || !ids || !c || !radius || !dist || !drives) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "bone vertices: out of memory");
        goto done;
    }
    for (int32_t k = 0; k < surface.nverts; ++k)
        surf[surface.verts[k]] = 1;
    /* a vertex no tet uses is never driven: mark it taken (bov -2) until the end */
    for (int32_t v = 0; v < n; ++v)
        ids[v] = 0;
    for (int32_t k = 0; k < 4 * m->ntets; ++k)
        ids[m->tets[k]] = 1;
    for (int32_t v = 0; v < n; ++v) { /* dominant bone; ties go to the lower index */
        const double *row = w->w + (size_t)v * w->nbones;
        dom[v] = 0;
        for (int32_t b = 1; b < w->nbones; ++b)
            if (row[b] > row[dom[v]]) dom[v] = b;
    }
    for (int32_t b = 0; b < s->nbones; ++b)
        drives[b] = !drives_in || drives_in[b];
    flesh_radii(m, s, surf, dom, radius, dist);
    for (int32_t v = 0; v < n; ++v) {
        bone_of_vertex[v] = ids[v] ? -1 : -2;
        if (ids[v] && !surf[v] && drives[dom[v]] &&
            bone_distance(m, s, v, dom[v]) <= SW_BONE_RADIUS_FRACTION * radius[dom[v]])
            bone_of_vertex[v] = dom[v];
    }
    /* a bone reaches interior vertices up to SW_BONE_REACH flesh radii from it */
    for (int32_t b = 0; b < s->nbones; ++b)
        radius[b] *= SW_BONE_REACH;
    rc = shared_top_up(m, s, surf, drives, radius, bone_of_vertex, ids, c, err);
    for (int32_t b = 0; b < s->nbones && !rc; ++b)
        if (drives[b]) rc = top_up(m, s, surf, radius[b], bone_of_vertex, b, ids, c, err);
    for (int32_t v = 0; v < n; ++v)
        if (rc || bone_of_vertex[v] < 0) bone_of_vertex[v] = -1;
done:
    sw_surface_free(&surface);
    free(surf);
    free(dom);
    free(ids);
    free(c);
    free(radius);
    free(dist);
    free(drives);
    return rc;
}

/* Union-find root of v with path halving. */
static int32_t find_root(int32_t *up, int32_t v) {
    while (up[v] != v)
        v = up[v] = up[up[v]];
    return v;
}

/* Bone b's summed weight over tet t and the distance of its centroid from b. */
static int32_t tet_bone_and_distance(const sw_tetmesh *m, const sw_skeleton *s, const sw_weights *w,
                                     int32_t t, double *dist) {
    const int32_t *tv = m->tets + 4 * (size_t)t;
    int32_t best = 0;
    double best_w = -1, c[3] = {0, 0, 0};
    for (int32_t b = 0; b < s->nbones; ++b) {
        double sum = 0;
        for (int k = 0; k < 4; ++k)
            sum += w->w[(size_t)tv[k] * s->nbones + b];
        if (sum > best_w) best_w = sum, best = b;
    }
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 3; ++i)
            c[i] += 0.25 * m->X[3 * (size_t)tv[k] + i];
    *dist = sw_point_segment_distance(c, s->joints + 3 * s->bones[2 * best],
                                      s->joints + 3 * s->bones[2 * best + 1]);
    return best;
}

sinew_result sw_anchor_free_components(const sw_tetmesh *m, const sw_skeleton *s,
                                       const sw_weights *w, int32_t *bov, int32_t *anchored,
                                       sw_error *err) {
    if (anchored) *anchored = 0;
    sinew_result rc = check_inputs(m, s, w, bov, err);
    if (rc) return rc;
    int32_t n = m->nverts;
    int32_t *up = malloc(sizeof(int32_t) * (size_t)n);
    unsigned char *held = calloc((size_t)n, 1);
    int32_t *best_tet = malloc(sizeof(int32_t) * (size_t)n);
    double *best_d = malloc(sizeof(double) * (size_t)n);
    if (!up || !held || !best_tet || !best_d) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "anchoring components: out of memory");
        goto done;
    }
    for (int32_t v = 0; v < n; ++v)
        up[v] = v, best_tet[v] = -1, best_d[v] = INFINITY;
    for (int32_t t = 0; t < m->ntets; ++t)
        for (int k = 1; k < 4; ++k) {
            int32_t a = find_root(up, m->tets[4 * (size_t)t]),
                    b = find_root(up, m->tets[4 * (size_t)t + k]);
            if (a != b) up[a < b ? b : a] = a < b ? a : b; /* the lower id is the root */
        }
    for (int32_t v = 0; v < n; ++v)
        if (bov[v] >= 0) held[find_root(up, v)] = 1;
    /* per free component: the tet nearest its dominant bone (ties: the lower tet id) */
    for (int32_t t = 0; t < m->ntets; ++t) {
        int32_t r = find_root(up, m->tets[4 * (size_t)t]);
        if (held[r]) continue;
        double d;
        tet_bone_and_distance(m, s, w, t, &d);
        if (d < best_d[r]) best_d[r] = d, best_tet[r] = t;
    }
    for (int32_t r = 0; r < n; ++r) {
        if (best_tet[r] < 0) continue;
        double d;
        int32_t b = tet_bone_and_distance(m, s, w, best_tet[r], &d);
        for (int k = 0; k < 4; ++k)
            bov[m->tets[4 * (size_t)best_tet[r] + k]] = b;
        if (anchored) ++*anchored;
    }
done:
    free(up);
    free(held);
    free(best_tet);
    free(best_d);
    return rc;
}
