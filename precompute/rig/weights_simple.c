/* Inverse-distance skin weights, for assets that ship none (the bake computes the
 * heat-diffusion weights of DESIGN.md §8; these only need to be plausible and smooth). */
#include "rig.h"
#include "vec3.h"

#include "bbox.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double sw_rig_diagonal(const sw_tetmesh *m, const sw_skeleton *s) {
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, m->nverts, m->X);
    sw_bbox_add(lo, hi, s->njoints, s->joints);
    return sw_bbox_diagonal(lo, hi);
}

sinew_result sw_weights_inverse_distance(const sw_tetmesh *m, const sw_skeleton *s, sw_weights *out,
                                         sw_error *err) {
    if (!out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "inverse-distance weights: out is NULL");
    memset(out, 0, sizeof *out);
    if (!m || !s)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "inverse-distance weights: NULL input");
    if (m->nverts < 1 || !m->X)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                            "inverse-distance weights: mesh has no vertices");
    sinew_result rc = sw_skeleton_validate(s, err);
    if (rc) return rc;
    for (int32_t v = 0; v < 3 * m->nverts; ++v)
        if (!isfinite(m->X[v]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "inverse-distance weights: vertex %d is not finite", v / 3);
    double *w = malloc(sizeof(double) * (size_t)m->nverts * (size_t)s->nbones);
    if (!w)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "inverse-distance weights: out of memory");
    /* A vertex on a segment would divide by zero: distances are clamped to a tiny
     * fraction of the model size, which makes that bone's weight ~1. */
    double eps = 1e-9 * sw_rig_diagonal(m, s);
    if (!(eps > 0)) eps = 1e-300;
    for (int32_t v = 0; v < m->nverts; ++v) {
        double *row = w + (size_t)v * s->nbones, dmin = INFINITY, sum = 0;
        for (int32_t b = 0; b < s->nbones; ++b) {
            row[b] = fmax(sw_point_segment_distance(m->X + 3 * v, s->joints + 3 * s->bones[2 * b],
                                                    s->joints + 3 * s->bones[2 * b + 1]),
                          eps);
            dmin = fmin(dmin, row[b]);
        }
        /* w ~ 1/d^4, computed as (dmin/d)^4 so nothing over- or underflows at any scale. */
        for (int32_t b = 0; b < s->nbones; ++b) {
            double r = dmin / row[b];
            row[b] = (r * r) * (r * r);
            sum += row[b];
        }
        for (int32_t b = 0; b < s->nbones; ++b)
            row[b] /= sum;
    }
    out->nverts = m->nverts;
    out->nbones = s->nbones;
    out->w = w;
    return SINEW_OK;
}
