/* Small static-inline 3-vector helpers, 3-vectors as double[3]: the one copy the runtime,
 * the bake and the tools use. Each is written in one operation order (and the build sets
 * -ffp-contract=off), so code that calls it computes bitwise what it computed inline. */
#ifndef SW_VEC3_H
#define SW_VEC3_H

#include <math.h>

/* a . b, summed left to right. */
static inline double sw_v3_dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* c = a x b; c may alias a or b. */
static inline void sw_v3_cross(const double a[3], const double b[3], double c[3]) {
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    c[0] = x;
    c[1] = y;
    c[2] = z;
}

/* c = a - b; c may alias a or b. */
static inline void sw_v3_sub(const double a[3], const double b[3], double c[3]) {
    c[0] = a[0] - b[0];
    c[1] = a[1] - b[1];
    c[2] = a[2] - b[2];
}

/* |a|. */
static inline double sw_v3_norm(const double a[3]) {
    return sqrt(sw_v3_dot(a, a));
}

/* |a - b|. */
static inline double sw_v3_dist(const double a[3], const double b[3]) {
    double d[3];
    sw_v3_sub(a, b, d);
    return sw_v3_norm(d);
}

/* a . (b x c): six times the signed volume of the tet spanned by a, b and c. */
static inline double sw_v3_triple(const double a[3], const double b[3], const double c[3]) {
    double t[3];
    sw_v3_cross(b, c, t);
    return sw_v3_dot(a, t);
}

/* Divides a by its length in place and returns that length; a of length 0 (or NaN) is
 * left as it is. */
static inline double sw_v3_normalize(double a[3]) {
    double n = sw_v3_norm(a);
    if (n > 0) {
        a[0] /= n;
        a[1] /= n;
        a[2] /= n;
    }
    return n;
}

/* The smaller and the larger of two finite numbers, as one minsd/maxsd: without
 * -ffast-math the compiler cannot inline fmin/fmax (their NaN and signed-zero rules) and
 * calls libm, which showed as 5% of the world detection's profile. For finite operands
 * they equal fmin/fmax except that of -0.0 and +0.0 they return b. */
static inline double sw_min(double a, double b) {
    return a < b ? a : b;
}
static inline double sw_max(double a, double b) {
    return a > b ? a : b;
}

/* Whether all three components are finite. */
static inline int sw_v3_isfinite(const double a[3]) {
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

#endif
