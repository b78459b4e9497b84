/* The closed-form colliders: plane, sphere, capsule (along local y) and box. Each query
 * is the exact signed distance, closest surface point and outward unit normal, inside
 * and outside; where the normal is not unique (a sphere's centre, a capsule's axis, a
 * box's medial planes, edges and corners) one valid choice is made by a fixed rule, so a
 * normal is never NaN and the answer is deterministic. */
#include <math.h>
#include <string.h>

#include "collision_internal.h"

/* Writes the hit (phi, point, normal) and tells whether it counts (inside or within r). */
static int report(double phi, const double p[3], const double n[3], double radius,
                  sw_collider_hit *h) {
    if (phi > radius) return 0;
    h->phi = phi;
    memcpy(h->point, p, sizeof h->point);
    memcpy(h->normal, n, sizeof h->normal);
    return 1;
}

/* n . y = offset with unit n: the half-space behind it is solid. */
int sw_plane_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    const double *n = c->u.plane.n;
    double phi = sw_v3_dot(n, y) - c->u.plane.offset;
    double p[3] = {y[0] - phi * n[0], y[1] - phi * n[1], y[2] - phi * n[2]};
    return report(phi, p, n, radius, h);
}

/* A ball of radius r around q: the sphere and both capsule parts. At q itself every
 * direction is a closest one; `fallback` (unit, perpendicular to the capsule's axis) is
 * taken. */
static int ball_query(const double q[3], double r, const double y[3], const double fallback[3],
                      double radius, sw_collider_hit *h) {
    double n[3];
    sw_v3_sub(y, q, n);
    /* farther than r + radius (with a margin for rounding): no hit, no square root */
    double reach = r + radius;
    if (sw_v3_dot(n, n) > reach * reach * (1 + 1e-9)) return 0;
    double d = sw_v3_normalize(n);
    /* d == 0, or so small that its square underflowed: no direction to trust. */
    if (!(d > 0) || !sw_v3_isfinite(n) || fabs(sw_v3_norm(n) - 1.0) > 1e-6)
        memcpy(n, fallback, sizeof n);
    double p[3] = {q[0] + r * n[0], q[1] + r * n[1], q[2] + r * n[2]};
    return report(d - r, p, n, radius, h);
}

int sw_sphere_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    static const double zero[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    return ball_query(zero, c->u.radius, y, up, radius, h);
}

/* The ball around the closest point of the axis segment y in [-hh, hh]. */
int sw_capsule_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    static const double side[3] = {1, 0, 0}; /* perpendicular to the axis */
    double hh = c->u.capsule.half_height;
    double q[3] = {0, sw_min(sw_max(y[1], -hh), hh), 0};
    return ball_query(q, c->u.capsule.radius, y, side, radius, h);
}

/* Inside (or on) the box: the nearest face, the lowest axis on a tie. */
static int box_inside(const double *e, const double y[3], double radius, sw_collider_hit *h) {
    int k = 0;
    double best = fabs(y[0]) - e[0];
    for (int i = 1; i < 3; ++i) {
        double q = fabs(y[i]) - e[i];
        if (q > best) best = q, k = i;
    }
    double s = y[k] < 0 ? -1.0 : 1.0; /* the centre plane y_k = 0 goes to the + face */
    double p[3] = {y[0], y[1], y[2]}, n[3] = {0, 0, 0};
    p[k] = s * e[k];
    n[k] = s;
    return report(best, p, n, radius, h);
}

/* |y_i| <= e_i. Outside, the closest point is the clamp and the normal the direction to
 * it; inside, the nearest face. */
int sw_box_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    const double *e = c->u.half;
    double p[3], n[3];
    int outside = 0, k = 0;
    double qmax = -HUGE_VAL;
    for (int i = 0; i < 3; ++i) {
        p[i] = sw_min(sw_max(y[i], -e[i]), e[i]);
        double q = fabs(y[i]) - e[i];
        if (q > 0) outside = 1;
        if (q > qmax) qmax = q, k = i;
    }
    if (!outside) return box_inside(e, y, radius, h);
    if (qmax > radius) return 0; /* the distance is at least the largest axis excess */
    sw_v3_sub(y, p, n);
    double d = sw_v3_normalize(n);
    if (!(d > 0) || fabs(sw_v3_norm(n) - 1.0) > 1e-6) { /* underflow: the farthest axis */
        n[0] = n[1] = n[2] = 0;
        n[k] = y[k] < 0 ? -1.0 : 1.0;
        d = qmax;
    }
    return report(d, p, n, radius, h);
}

/* NOT_FINITE for NaN or infinity, INVALID_ARGUMENT outside (0, 1e15]; logs `what`. */
static sinew_result check_size(sinew_world *w, double s, const char *what) {
    if (!isfinite(s))
        return sw_world_fail(w, SINEW_ERROR_NOT_FINITE, "sinew_world_add_collider: %s is %g", what,
                             s);
    if (!sw_size_ok(s))
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "sinew_world_add_collider: %s is %g, not in (0, 1e15]", what, s);
    return SINEW_OK;
}

/* The plane's box: unbounded along the plane; when its normal is a coordinate axis the
 * solid's box is bounded on that axis's outer side by the plane itself (and unbounded on
 * the solid side), else unbounded everywhere. */
static sinew_result build_plane(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    double n[3] = {d->normal[0], d->normal[1], d->normal[2]}, off = d->offset;
    if (!sw_v3_isfinite(n) || !isfinite(off))
        return sw_world_fail(
            w, SINEW_ERROR_NOT_FINITE,
            "sinew_world_add_collider: the plane's normal or offset is not finite");
    double len = sw_v3_normalize(n);
    if (!(len > 1e-30) || !(fabs(off) / len <= SW_COLLIDER_MAX_SIZE))
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "sinew_world_add_collider: the plane's normal is zero or its offset "
                             "above 1e15");
    memcpy(c->u.plane.n, n, sizeof n);
    c->u.plane.offset = off / len;
    for (int i = 0; i < 3; ++i) {
        c->lo[i] = -HUGE_VAL;
        c->hi[i] = HUGE_VAL;
        if (fabs(n[i]) == 1.0) { /* axis-aligned: the other components are zero */
            if (n[i] > 0)
                c->hi[i] = c->u.plane.offset;
            else
                c->lo[i] = -c->u.plane.offset;
        }
    }
    return SINEW_OK;
}

sinew_result sw_shapes_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    sinew_result r = SINEW_OK;
    switch (d->shape) {
    case SINEW_SHAPE_PLANE:
        return build_plane(w, d, c);
    case SINEW_SHAPE_SPHERE:
        if ((r = check_size(w, d->radius, "the sphere's radius")) != SINEW_OK) return r;
        c->u.radius = d->radius;
        for (int i = 0; i < 3; ++i)
            c->lo[i] = -(c->hi[i] = d->radius);
        return SINEW_OK;
    case SINEW_SHAPE_CAPSULE:
        if ((r = check_size(w, d->radius, "the capsule's radius")) != SINEW_OK) return r;
        /* half_height 0 is a sphere: allowed, so check it as a size of its own. */
        if (d->half_height != 0 &&
            (r = check_size(w, d->half_height, "the capsule's half_height")) != SINEW_OK)
            return r;
        c->u.capsule.radius = d->radius;
        c->u.capsule.half_height = d->half_height;
        for (int i = 0; i < 3; ++i)
            c->lo[i] = -(c->hi[i] = d->radius + (i == 1 ? d->half_height : 0.0));
        return SINEW_OK;
    case SINEW_SHAPE_BOX:
        for (int i = 0; i < 3; ++i) {
            if ((r = check_size(w, d->half_extents[i], "a box half extent")) != SINEW_OK) return r;
            c->u.half[i] = d->half_extents[i];
            c->lo[i] = -(c->hi[i] = d->half_extents[i]);
        }
        return SINEW_OK;
    default:
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "sinew_world_add_collider: shape %d is not a closed-form shape",
                             (int)d->shape);
    }
}
