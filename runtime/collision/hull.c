/* Convex hulls: the convex hull of a point set, checked at add time (enough points,
 * finite, not coplanar relative to the hull's size) and queried with libccd's Minkowski
 * Portal Refinement, the query point taken as a ball of the query radius. MPR
 * (ccdMPRPenetration) keeps its simplex on the stack; GJK+EPA reallocs its polytope on
 * every overlapping call (STYLE.md §6), so it is never used.
 *
 * Accuracy: every MPR depth is the distance to a supporting plane of the Minkowski
 * difference where one ray leaves it, never less than the true depth. Inside, the point
 * itself is the second object (flat faces): the ray from the point mean, along the
 * principal axes and along the best normal give the nearest face, measured exact to
 * 1e-15. Outside within the radius, the ball-swept hull has round edges and corners and
 * the normal iteration converges slowly there: measured up to 2e-2 (boxes) and 0.15
 * (a regular tetrahedron) of a 0.3 radius, always too deep rather than too shallow
 * (tests/test_collision_hull.c); since the point itself is known to be outside, such a
 * distance is clamped at 0, so an outside point is never reported inside. Open item: a
 * better outside iteration.
 */
#include <ccd/ccd.h>
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "collision_internal.h"
#include "svd3.h"

/* Support evaluations one MPR call may make. libccd 2.1's portal refinement loops until
 * its tolerance test passes, with no iteration cap: measured here, a point near a hull's
 * edge made it spin forever (tests/test_collision_contract.c hung in ccdMPRPenetration).
 * Past this budget both support functions answer with the Minkowski difference's point
 * farthest *against* the direction, which fails libccd's "can encapsulate the origin"
 * test and passes its tolerance test, so either loop ends (the call then reports no
 * intersection for that ray). Normal calls take 10-60 evaluations. */
#define SW_MPR_SUPPORT_BUDGET 2000

/* The hull with the interior point MPR casts its ray from (libccd's first object), and
 * the support evaluations of the current MPR call. */
typedef struct hull_obj {
    const sw_hull *h;
    double c[3];
    int calls;
} hull_obj;

/* The query point as a ball (libccd's second object); it shares the hull's budget. */
typedef struct ball {
    double c[3], r;
    const hull_obj *o;
} ball;

static void hull_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out) {
    hull_obj *o = (hull_obj *)(uintptr_t)obj; /* libccd passes our own object back */
    const sw_hull *h = o->h;
    double sign = ++o->calls > SW_MPR_SUPPORT_BUDGET ? -1.0 : 1.0;
    const double *d = dir->v, *p = h->points;
    uint32_t best = 0;
    double bd = -HUGE_VAL;
    for (uint32_t i = 0; i < h->count; ++i) {
        double s = sign * (d[0] * p[3 * i] + d[1] * p[3 * i + 1] + d[2] * p[3 * i + 2]);
        if (s > bd) bd = s, best = i;
    }
    memcpy(out->v, p + 3 * best, 3 * sizeof(double));
}

static void hull_center(const void *obj, ccd_vec3_t *out) {
    memcpy(out->v, ((const hull_obj *)obj)->c, 3 * sizeof(double));
}

static void ball_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out) {
    const ball *b = obj;
    double n = sqrt(dir->v[0] * dir->v[0] + dir->v[1] * dir->v[1] + dir->v[2] * dir->v[2]);
    double s = n > 0 ? b->r / n : 0.0;
    if (b->o->calls > SW_MPR_SUPPORT_BUDGET) s = -s; /* see SW_MPR_SUPPORT_BUDGET */
    for (int i = 0; i < 3; ++i)
        out->v[i] = b->c[i] + s * dir->v[i];
}

static void ball_center(const void *obj, ccd_vec3_t *out) {
    memcpy(out->v, ((const ball *)obj)->c, 3 * sizeof(double));
}

/* One MPR penetration: 1 with the depth and the unit direction (moving the ball, libccd's
 * second object, by depth along it separates them: the hull's outward normal), 0 when
 * they do not intersect or libccd gave no usable direction. */
static int mpr(hull_obj *o, const ball *b, const ccd_t *ccd, double *depth, double n[3]) {
    ccd_real_t d = 0;
    ccd_vec3_t dir, pos;
    o->calls = 0;
    if (ccdMPRPenetration(o, b, ccd, &d, &dir, &pos) != 0 || o->calls > SW_MPR_SUPPORT_BUDGET)
        return 0;
    for (int i = 0; i < 3; ++i)
        n[i] = dir.v[i];
    if (!(sw_v3_normalize(n) > 0) || !sw_v3_isfinite(n) || !isfinite(d)) return 0;
    *depth = d;
    return 1;
}

/* The ray from the ball's centre y along u (a centre half the radius behind y): its
 * result replaces the best when shallower. Every MPR depth is the distance to a
 * supporting plane of the Minkowski difference, never less than the true depth, so the
 * shallowest is the best. */
static int try_ray(hull_obj *o, const ball *b, const ccd_t *ccd, const double u[3], double *best,
                   double n[3]) {
    double d, m[3];
    /* The centre must lie in the Minkowski difference: behind y by less than the true
     * depth, which is at most the best depth so far (a quarter of it, then). */
    double back = 0.25 * *best;
    for (int i = 0; i < 3; ++i)
        o->c[i] = b->c[i] - back * u[i];
    if (!mpr(o, b, ccd, &d, m) || !(d < *best)) return 0;
    *best = d;
    memcpy(n, m, sizeof m);
    return 1;
}

/* The shallowest supporting plane found from the ray of the point mean (already in
 * depth, n), then along each principal axis (towards y's side), then along the best
 * normal so far until no shallower plane appears (on the round parts of a ball-swept hull
 * this converges to the true normal). */
static void search(hull_obj *o, const ball *b, const ccd_t *ccd, double *depth, double n[3]) {
    const sw_hull *hl = o->h;
    double yc[3];
    sw_v3_sub(b->c, hl->center, yc);
    for (int k = 0; k < 3; ++k) {
        const double *a = hl->axes + 3 * k;
        double s = sw_v3_dot(yc, a) < 0 ? -1.0 : 1.0, u[3] = {s * a[0], s * a[1], s * a[2]};
        try_ray(o, b, ccd, u, depth, n);
    }
    for (int it = 0; it < 12; ++it) {
        double u[3] = {n[0], n[1], n[2]};
        if (!try_ray(o, b, ccd, u, depth, n)) break;
    }
}

/* Inside the hull (the point itself intersects it), the depth of the point: the
 * Minkowski difference is the hull's own polytope, flat faces, exact planes. Outside,
 * the ball of the query radius: depth = r - phi, over the round edges and corners of
 * the ball-swept hull. */
int sw_hull_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    const sw_hull *hl = &c->hull;
    hull_obj o = {hl, {hl->center[0], hl->center[1], hl->center[2]}, 0};
    ball b = {{y[0], y[1], y[2]}, 0.0, &o};
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = hull_support;
    ccd.support2 = ball_support;
    ccd.center1 = hull_center;
    ccd.center2 = ball_center;
    ccd.max_iterations = 200;
    ccd.mpr_tolerance = hl->tolerance + 1e-9 * radius;
    double depth, n[3];
    int inside = mpr(&o, &b, &ccd, &depth, n);
    if (!inside) {
        b.r = radius;
        memcpy(o.c, hl->center, sizeof o.c);
        if (!mpr(&o, &b, &ccd, &depth, n)) return 0; /* farther than the radius */
    }
    search(&o, &b, &ccd, &depth, n);
    /* Outside, the ball's depth can be overestimated near edges and corners (see the
     * head comment); the point itself is known to be outside, so it is never reported
     * inside: the distance may read short, never negative (a contact then engages at
     * most that much early, and never pushes a vertex that does not touch the hull). */
    double phi = b.r - depth;
    if (!inside && phi < 0) phi = 0;
    h->phi = phi;
    for (int i = 0; i < 3; ++i) {
        h->point[i] = y[i] - phi * n[i];
        h->normal[i] = n[i];
    }
    return 1;
}

/* Index of the point farthest from the line (a, u) (u unit, or zero: from a), and its
 * distance. */
static uint32_t farthest_from_line(const double *p, uint32_t n, const double a[3],
                                   const double u[3], double *dist) {
    uint32_t best = 0;
    double bd = -1;
    for (uint32_t i = 0; i < n; ++i) {
        double d[3], x[3];
        sw_v3_sub(p + 3 * i, a, d);
        sw_v3_cross(d, u, x);
        double s = sw_v3_dot(u, u) > 0 ? sw_v3_norm(x) : sw_v3_norm(d);
        if (s > bd) bd = s, best = i;
    }
    *dist = bd;
    return best;
}

/* Not all points in one plane, measured against the points' box diagonal `diag`: the
 * farthest-point simplex (a, b farthest from a, c farthest from ab, d farthest from abc)
 * must have height above 1e-6 diag at each step. */
static const char *flatness(const double *p, uint32_t n, double diag) {
    static const double none[3] = {0, 0, 0};
    double da, dl, u[3], v[3], e1[3], e2[3];
    uint32_t b = farthest_from_line(p, n, p, none, &da);
    if (!(da > 1e-6 * diag)) return "all points coincide";
    sw_v3_sub(p + 3 * b, p, u);
    sw_v3_normalize(u);
    uint32_t c = farthest_from_line(p, n, p, u, &dl);
    if (!(dl > 1e-6 * diag)) return "all points are collinear";
    sw_v3_sub(p + 3 * b, p, e1);
    sw_v3_sub(p + 3 * c, p, e2);
    sw_v3_cross(e1, e2, v);
    sw_v3_normalize(v);
    double hmax = 0;
    for (uint32_t i = 0; i < n; ++i) {
        double d[3];
        sw_v3_sub(p + 3 * i, p, d);
        hmax = fmax(hmax, fabs(sw_v3_dot(d, v)));
    }
    return hmax > 1e-6 * diag ? NULL : "all points are coplanar";
}

/* The eigenvectors of the points' covariance (any orthonormal frame when isotropic). */
static void principal_axes(sw_hull *h) {
    double C[9] = {0}, U[9], s[3], V[9];
    for (uint32_t i = 0; i < h->count; ++i) {
        double d[3];
        sw_v3_sub(h->points + 3 * i, h->center, d);
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k)
                C[3 * r + k] += d[r] * d[k];
    }
    sw_svd3(C, U, s, V);
    for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 3; ++r)
            h->axes[3 * k + r] = V[3 * r + k];
}

/* Count, finiteness and magnitude of the def's points; the box in c->lo, c->hi. */
static sinew_result check_points(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    if (!d->points || d->point_count < 4 || d->point_count > SW_HULL_MAX_POINTS)
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "sinew_world_add_collider: a hull needs 4 to %u points (got %u%s)",
                             SW_HULL_MAX_POINTS, (unsigned)d->point_count,
                             d->points ? "" : ", points NULL");
    for (int k = 0; k < 3; ++k)
        c->lo[k] = HUGE_VAL, c->hi[k] = -HUGE_VAL;
    for (uint32_t i = 0; i < 3 * d->point_count; ++i) {
        double x = d->points[i];
        if (!isfinite(x))
            return sw_world_fail(w, SINEW_ERROR_NOT_FINITE,
                                 "sinew_world_add_collider: hull point %u is not finite",
                                 (unsigned)(i / 3));
        if (!(fabs(x) <= SW_COLLIDER_MAX_SIZE))
            return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                                 "sinew_world_add_collider: hull point %u is beyond 1e15",
                                 (unsigned)(i / 3));
        c->lo[i % 3] = fmin(c->lo[i % 3], x);
        c->hi[i % 3] = fmax(c->hi[i % 3], x);
    }
    return SINEW_OK;
}

sinew_result sw_hull_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    sinew_result r = check_points(w, d, c);
    if (r != SINEW_OK) return r;
    uint32_t n = d->point_count;
    sw_hull *h = &c->hull;
    h->points = sw_alloc(&w->allocator, sizeof(double) * 3 * n, SW_ALLOC_ALIGN);
    if (!h->points)
        return sw_world_fail(w, SINEW_ERROR_OUT_OF_MEMORY,
                             "sinew_world_add_collider: no memory for %u hull points", (unsigned)n);
    h->count = n;
    for (uint32_t i = 0; i < 3 * n; ++i) {
        h->points[i] = d->points[i];
        h->center[i % 3] += d->points[i];
    }
    for (int k = 0; k < 3; ++k)
        h->center[k] /= n;
    double ext[3];
    sw_v3_sub(c->hi, c->lo, ext);
    double diag = sw_v3_norm(ext);
    const char *flat = flatness(h->points, n, diag);
    if (flat) {
        sw_hull_release(w, c);
        return sw_world_fail(w, SINEW_ERROR_DEGENERATE,
                             "sinew_world_add_collider: degenerate hull of %u points: %s",
                             (unsigned)n, flat);
    }
    h->tolerance = 1e-9 * diag;
    principal_axes(h);
    return SINEW_OK;
}

void sw_hull_release(sinew_world *w, sw_collider *c) {
    sw_free(&w->allocator, c->hull.points);
    memset(&c->hull, 0, sizeof c->hull);
}
