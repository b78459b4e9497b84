/* Axis-aligned bounding boxes of point sets: the size of a character (the rest
 * bounding-box diagonal) that teleports and distance clamps are measured against. */
#ifndef SW_BBOX_H
#define SW_BBOX_H

#include <math.h>
#include <stdint.h>

#include "vec3.h"

/* lo, hi = the empty box (every point added grows it). */
static inline void sw_bbox_empty(double lo[3], double hi[3]) {
    for (int i = 0; i < 3; ++i) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
    }
}

/* Grows the box by the n points X (3 each). */
static inline void sw_bbox_add(double lo[3], double hi[3], int32_t n, const double *X) {
    for (int32_t v = 0; v < n; ++v)
        for (int i = 0; i < 3; ++i) {
            lo[i] = fmin(lo[i], X[3 * v + i]);
            hi[i] = fmax(hi[i], X[3 * v + i]);
        }
}

/* The box's diagonal |hi - lo|. */
static inline double sw_bbox_diagonal(const double lo[3], const double hi[3]) {
    return sw_v3_dist(hi, lo);
}

#endif
