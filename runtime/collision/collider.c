/* One collider as the step reads it (collision.h): its properties, its world-space box,
 * and the query, which maps the point into the collider's frame, asks the shape there,
 * and maps the answer back: moving a collider never rebuilds anything. */
#include <math.h>
#include <string.h>

#include "collision_internal.h"

double sw_collider_stiffness(const sw_collider *c) {
    return c->stiffness;
}

double sw_collider_friction(const sw_collider *c) {
    return c->friction;
}

void sw_collider_transform(const sw_collider *c, double R[9], double t[3]) {
    for (int i = 0; i < 9; ++i)
        R[i] = c->R[i];
    for (int i = 0; i < 3; ++i)
        t[i] = c->t[i];
}

void sw_collider_source(const sw_collider *c, sinew_collider_def *d) {
    *d = c->src;
}

void sw_collider_placement(const sw_collider *c, double position[3], double rotation[4]) {
    for (int i = 0; i < 3; ++i)
        position[i] = c->src_pos[i];
    for (int i = 0; i < 4; ++i)
        rotation[i] = c->src_rot[i];
}

uint32_t sw_collider_vertex_moves(const sw_collider *c) {
    return c->shape == SINEW_SHAPE_MESH ? c->mesh.moves : 0;
}

const double *sw_collider_points(const sw_collider *c, uint32_t *count) {
    *count = c->shape == SINEW_SHAPE_HULL   ? c->hull.count
             : c->shape == SINEW_SHAPE_MESH ? c->mesh.nverts
                                            : 0;
    return c->shape == SINEW_SHAPE_HULL   ? c->hull.points
           : c->shape == SINEW_SHAPE_MESH ? c->mesh.X
                                          : NULL;
}

const uint32_t *sw_collider_triangles(const sw_collider *c, uint32_t *count) {
    *count = c->shape == SINEW_SHAPE_MESH ? c->mesh.ntris : 0;
    return c->shape == SINEW_SHAPE_MESH ? c->mesh.tris : NULL;
}

/* The plane's square around `around`: its closest point there, two unit axes across. */
static void plane_square(const sw_collider *c, const double around[3], double extent,
                         double corners[8][3]) {
    double n[3], p0[3], u[3], v[3], d = 0;
    for (int i = 0; i < 3; ++i) {
        n[i] = c->R[3 * i] * c->u.plane.n[0] + c->R[3 * i + 1] * c->u.plane.n[1] +
               c->R[3 * i + 2] * c->u.plane.n[2];
        p0[i] = n[i] * c->u.plane.offset + c->t[i]; /* R (n offset) + t */
    }
    for (int i = 0; i < 3; ++i)
        d += n[i] * (around[i] - p0[i]);
    int k = fabs(n[0]) < 0.6 ? 0 : 1; /* an axis not along n */
    double a[3] = {k == 0, k == 1, 0};
    sw_v3_cross(n, a, u);
    double un = sw_v3_norm(u);
    for (int i = 0; i < 3; ++i)
        u[i] /= un;
    sw_v3_cross(n, u, v);
    for (int j = 0; j < 4; ++j) {
        double su = (j == 0 || j == 3) ? -extent : extent, sv = j < 2 ? -extent : extent;
        for (int i = 0; i < 3; ++i)
            corners[j][i] = around[i] - d * n[i] + su * u[i] + sv * v[i];
    }
}

int sw_collider_outline(const sw_collider *c, const double around[3], double extent,
                        double corners[8][3]) {
    if (c->shape == SINEW_SHAPE_PLANE) {
        plane_square(c, around, extent, corners);
        return 4;
    }
    for (int j = 0; j < 8; ++j) {
        double y[3] = {(j & 1) ? c->hi[0] : c->lo[0], (j & 2) ? c->hi[1] : c->lo[1],
                       (j & 4) ? c->hi[2] : c->lo[2]};
        for (int i = 0; i < 3; ++i)
            corners[j][i] =
                c->R[3 * i] * y[0] + c->R[3 * i + 1] * y[1] + c->R[3 * i + 2] * y[2] + c->t[i];
    }
    return 8;
}

/* The plane's world box: unbounded, except on the axis its world normal lies along
 * (within 1e-12 in each other component), where the solid ends at the plane. */
static void plane_box(const sw_collider *c, double lo[3], double hi[3]) {
    const double *nl = c->u.plane.n, *R = c->R;
    double n[3];
    for (int i = 0; i < 3; ++i) {
        n[i] = R[3 * i] * nl[0] + R[3 * i + 1] * nl[1] + R[3 * i + 2] * nl[2];
        lo[i] = -HUGE_VAL;
        hi[i] = HUGE_VAL;
    }
    double off = c->u.plane.offset + sw_v3_dot(n, c->t);
    for (int k = 0; k < 3; ++k) {
        if (!(fabs(n[(k + 1) % 3]) <= 1e-12 && fabs(n[(k + 2) % 3]) <= 1e-12)) continue;
        if (n[k] > 0)
            hi[k] = off / n[k];
        else
            lo[k] = off / n[k];
    }
}

void sw_collider_place(sw_collider *c, const double R[9], const double t[3]) {
    memcpy(c->R, R, sizeof c->R);
    memcpy(c->t, t, sizeof c->t);
    double *lo = c->box, *hi = c->box + 3;
    if (c->shape == SINEW_SHAPE_PLANE) {
        plane_box(c, lo, hi);
        return;
    }
    /* The local box's centre moves with R, its half extents grow to |R| e. */
    double m[3], e[3];
    for (int i = 0; i < 3; ++i) {
        m[i] = 0.5 * (c->lo[i] + c->hi[i]);
        e[i] = 0.5 * (c->hi[i] - c->lo[i]);
    }
    for (int i = 0; i < 3; ++i) {
        const double *r = c->R + 3 * i;
        double cw = r[0] * m[0] + r[1] * m[1] + r[2] * m[2] + c->t[i];
        double ew = fabs(r[0]) * e[0] + fabs(r[1]) * e[1] + fabs(r[2]) * e[2];
        lo[i] = cw - ew;
        hi[i] = cw + ew;
    }
}

void sw_collider_bounds(const sw_collider *c, double margin, double lo[3], double hi[3]) {
    for (int i = 0; i < 3; ++i) {
        lo[i] = c->box[i] - margin;
        hi[i] = c->box[3 + i] + margin;
    }
}

int sw_shape_query_local(const sw_collider *c, const double y[3], double radius,
                         sw_collider_hit *hit) {
    switch (c->shape) {
    case SINEW_SHAPE_PLANE:
        return sw_plane_query(c, y, radius, hit);
    case SINEW_SHAPE_SPHERE:
        return sw_sphere_query(c, y, radius, hit);
    case SINEW_SHAPE_CAPSULE:
        return sw_capsule_query(c, y, radius, hit);
    case SINEW_SHAPE_BOX:
        return sw_box_query(c, y, radius, hit);
    case SINEW_SHAPE_HULL:
        return sw_hull_query(c, y, radius, hit);
    case SINEW_SHAPE_MESH:
        return sw_mesh_query(c, y, radius, hit);
    }
    return 0;
}

/* y = R^T (x - t); the hit's point back as R p + t and its normal as R n. A radius that
 * is not positive and finite, or a point that is not finite, finds nothing. */
int sw_collider_query(const sw_collider *c, const double x[3], double radius,
                      sw_collider_hit *hit) {
    if (!(radius > 0) || !isfinite(radius) || !sw_v3_isfinite(x)) return 0;
    const double *R = c->R;
    double d[3], y[3];
    sw_v3_sub(x, c->t, d);
    for (int i = 0; i < 3; ++i)
        y[i] = R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2];
    sw_collider_hit h;
    if (!sw_shape_query_local(c, y, radius, &h)) return 0;
    hit->phi = h.phi;
    for (int i = 0; i < 3; ++i) {
        const double *r = R + 3 * i;
        hit->point[i] = r[0] * h.point[0] + r[1] * h.point[1] + r[2] * h.point[2] + c->t[i];
        hit->normal[i] = r[0] * h.normal[0] + r[1] * h.normal[1] + r[2] * h.normal[2];
    }
    return 1;
}

double sw_world_max_penetration(const sinew_world *w, int32_t n, const double *x,
                                const double *mask, const unsigned char *known, int32_t *inside) {
    double pen = 0;
    if (inside) *inside = 0;
    for (uint32_t s = 0; w && s < sw_world_slot_count(w); ++s) {
        const sw_collider *c = sw_world_slot(w, s);
        double lo[3], hi[3];
        if (!c) continue;
        sw_collider_bounds(c, 0, lo, hi);
        for (int32_t i = 0; i < n; ++i) {
            sw_collider_hit hit;
            if ((mask && !(mask[i] > 0)) || !sw_box_contains(lo, hi, x + 3 * i) ||
                !sw_collider_query(c, x + 3 * i, 1e-9, &hit) || !(hit.phi < 0))
                continue;
            pen = fmax(pen, -hit.phi);
            if (inside && !(known && known[i])) ++*inside;
        }
    }
    return pen;
}
