/* Helpers of the collision tests: a seeded generator, random rigid transforms as the
 * public float quaternions, the world <-> collider maps done by hand, and reference
 * geometry written independently of runtime/collision (a triangle's closest point by
 * plane projection and edge segments, the solid angle of a triangle for winding
 * numbers). Static functions: each test includes what it uses. */
#ifndef SW_COLLISION_REF_H
#define SW_COLLISION_REF_H

#include <math.h>
#include <stdint.h>

#include "collision.h"
#include "sinew/sinew_world.h"

static uint64_t ref_rng = 0x9E3779B97F4A7C15ull;

static inline double urand(void) { /* uniform in [0, 1) (xorshift64*) */
    ref_rng ^= ref_rng >> 12;
    ref_rng ^= ref_rng << 25;
    ref_rng ^= ref_rng >> 27;
    return (double)((ref_rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

static inline double srand1(void) { /* uniform in [-1, 1) */
    return 2.0 * urand() - 1.0;
}

/* A random rigid transform (uniform-ish rotation, position in [-5, 5]^3). */
static inline sinew_transform random_transform(void) {
    sinew_transform t;
    double q[4], n;
    do {
        n = 0;
        for (int i = 0; i < 4; ++i) {
            q[i] = srand1();
            n += q[i] * q[i];
        }
    } while (n < 0.01 || n > 1);
    for (int i = 0; i < 4; ++i)
        t.rotation[i] = (float)(q[i] / sqrt(n));
    for (int i = 0; i < 3; ++i)
        t.position[i] = (float)(5 * srand1());
    return t;
}

/* R (row-major) of the public transform, computed here from its quaternion. */
static inline void ref_rotation(const sinew_transform *t, double R[9]) {
    double w = t->rotation[0], x = t->rotation[1], y = t->rotation[2], z = t->rotation[3];
    double n = sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    double M[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                   2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int i = 0; i < 9; ++i)
        R[i] = M[i];
}

/* x = R y + t. */
static inline void to_world(const sinew_transform *tf, const double y[3], double x[3]) {
    double R[9];
    ref_rotation(tf, R);
    for (int i = 0; i < 3; ++i)
        x[i] = R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + tf->position[i];
}

/* y = R^T (x - t) (translate = 1) or R^T x (a direction, translate = 0). */
static inline void to_local(const sinew_transform *tf, const double x[3], int translate,
                            double y[3]) {
    double R[9], d[3];
    ref_rotation(tf, R);
    for (int i = 0; i < 3; ++i)
        d[i] = x[i] - (translate ? tf->position[i] : 0.0);
    for (int i = 0; i < 3; ++i)
        y[i] = R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2];
}

static inline double ref_dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double ref_dist(const double a[3], const double b[3]) {
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(ref_dot(d, d));
}

/* Closest point of segment ab to p. */
static inline void ref_segment(const double p[3], const double a[3], const double b[3],
                               double c[3]) {
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
           ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double s = ref_dot(ab, ab) > 0 ? ref_dot(ap, ab) / ref_dot(ab, ab) : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    for (int i = 0; i < 3; ++i)
        c[i] = a[i] + s * ab[i];
}

/* Distance of p to triangle abc: the plane projection when its barycentric coordinates
 * are all >= 0, else the nearest of the three edges. */
static inline double ref_triangle_dist(const double p[3], const double *a, const double *b,
                                       const double *c) {
    double e0[3], e1[3], n[3], ap[3];
    for (int i = 0; i < 3; ++i)
        e0[i] = b[i] - a[i], e1[i] = c[i] - a[i], ap[i] = p[i] - a[i];
    n[0] = e0[1] * e1[2] - e0[2] * e1[1];
    n[1] = e0[2] * e1[0] - e0[0] * e1[2];
    n[2] = e0[0] * e1[1] - e0[1] * e1[0];
    double nn = ref_dot(n, n), h = ref_dot(ap, n) / nn, q[3];
    for (int i = 0; i < 3; ++i)
        q[i] = p[i] - h * n[i];
    const double *v[3] = {a, b, c};
    int in = 1;
    for (int k = 0; k < 3; ++k) { /* the sign of each sub-triangle's area */
        const double *u = v[k], *w = v[(k + 1) % 3];
        double x[3] = {w[0] - u[0], w[1] - u[1], w[2] - u[2]},
               y[3] = {q[0] - u[0], q[1] - u[1], q[2] - u[2]};
        double cr[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                        x[0] * y[1] - x[1] * y[0]};
        if (ref_dot(cr, n) < 0) in = 0;
    }
    if (in) return ref_dist(p, q);
    double best = HUGE_VAL, cs[3];
    for (int k = 0; k < 3; ++k) {
        ref_segment(p, v[k], v[(k + 1) % 3], cs);
        best = fmin(best, ref_dist(p, cs));
    }
    return best;
}

/* Solid angle of triangle abc seen from p (Van Oosterom and Strackee 1983). */
static inline double ref_solid_angle(const double p[3], const double *a, const double *b,
                                     const double *c) {
    double x[3], y[3], z[3];
    for (int i = 0; i < 3; ++i)
        x[i] = a[i] - p[i], y[i] = b[i] - p[i], z[i] = c[i] - p[i];
    double lx = sqrt(ref_dot(x, x)), ly = sqrt(ref_dot(y, y)), lz = sqrt(ref_dot(z, z));
    double cr[3] = {y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2],
                    y[0] * z[1] - y[1] * z[0]};
    double num = ref_dot(x, cr);
    double den = lx * ly * lz + ref_dot(x, y) * lz + ref_dot(y, z) * lx + ref_dot(z, x) * ly;
    return 2.0 * atan2(num, den);
}

#endif
