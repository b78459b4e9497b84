/* Per-vertex data of an artist's render mesh carried onto the simulation mesh: each
 * simulation vertex takes the data at its closest point on the render surface, interpolated
 * barycentrically over that triangle. Skin weights so follow the artist's intent (joint
 * blends, props bound to one joint) where heat diffusion over the generated tets would only
 * guess it: a convex combination of rows that sum to 1, their rows do too, and the bake
 * keeps each row's 4 largest. Painted material goes the same way (character_paint.c). */
#include "rig.h"

#include "bbox.h"
#include "bvh.h"
#include "vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Triangles of positive area: the closest-point walk needs a proper triangle, and a
 * zero-area one (common in game meshes: welded seams, collapsed LODs) only repeats the
 * weights of its edges' neighbours. */
static int32_t proper_triangles(const sw_trimesh *s, int32_t *keep) {
    int32_t n = 0;
    for (int32_t t = 0; t < s->ntris; ++t) {
        const int32_t *v = s->tris + 3 * (size_t)t;
        double e1[3], e2[3], c[3];
        sw_v3_sub(s->X + 3 * (size_t)v[1], s->X + 3 * (size_t)v[0], e1);
        sw_v3_sub(s->X + 3 * (size_t)v[2], s->X + 3 * (size_t)v[0], e2);
        sw_v3_cross(e1, e2, c);
        double L = fmax(sw_v3_dot(e1, e1), sw_v3_dot(e2, e2));
        if (sw_v3_dot(c, c) > 1e-20 * L * L) keep[n++] = t;
    }
    return n;
}

static sinew_result check_transfer_inputs(const sw_tetmesh *m, const sw_trimesh *surf,
                                          const sw_weights *sw, sw_error *err) {
    if (!m || !surf || !sw || !sw->w || !surf->X || !surf->tris)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "weight transfer: NULL argument");
    if (sw->nverts != surf->nverts || sw->nbones < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "weight transfer: %d weight rows for %d render vertices", sw->nverts,
                            surf->nverts);
    for (int32_t k = 0; k < 3 * surf->ntris; ++k)
        if (surf->tris[k] < 0 || surf->tris[k] >= surf->nverts)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "weight transfer: triangle %d has vertex %d of %d", k / 3,
                                surf->tris[k], surf->nverts);
    for (int32_t k = 0; k < 3 * m->nverts; ++k)
        if (!isfinite(m->X[k]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "weight transfer: vertex %d is not finite", k / 3);
    return SINEW_OK;
}

sinew_result sw_surface_interpolate(const sw_tetmesh *m, const sw_trimesh *surf, int32_t ncols,
                                    const double *vals, double *out, sw_error *err) {
    int32_t *keep = malloc(sizeof(int32_t) * (size_t)(surf->ntris > 0 ? surf->ntris : 1));
    int32_t *tris = malloc(sizeof(int32_t) * 3 * (size_t)(surf->ntris > 0 ? surf->ntris : 1));
    double *boxes = malloc(sizeof(double) * 6 * (size_t)(surf->ntris > 0 ? surf->ntris : 1));
    sw_bvh bvh = {0};
    sinew_result rc = SINEW_OK;
    if (!keep || !tris || !boxes) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "surface transfer: out of memory");
        goto done;
    }
    int32_t nt = proper_triangles(surf, keep);
    if (nt == 0) {
        rc = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                          "surface transfer: the render surface has no triangle of positive area");
        goto done;
    }
    for (int32_t t = 0; t < nt; ++t)
        memcpy(tris + 3 * (size_t)t, surf->tris + 3 * (size_t)keep[t], 3 * sizeof(int32_t));
    sw_bvh_element_boxes(tris, 3, surf->X, 0, nt, boxes);
    if ((rc = sw_bvh_build(nt, boxes, &bvh, err))) goto done;
    /* every point is within the diagonal of the union of both boxes */
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, m->nverts, m->X);
    sw_bbox_add(lo, hi, surf->nverts, surf->X);
    double reach = 2.0 * sw_bbox_diagonal(lo, hi) + 1.0;
    for (int32_t v = 0; v < m->nverts; ++v) {
        sw_bvh_closest c;
        if (!sw_bvh_closest_triangle(&bvh, surf->X, tris, m->X + 3 * (size_t)v, reach, &c)) {
            rc = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                              "surface transfer: no render triangle near vertex %d", v);
            goto done;
        }
        double *row = out + (size_t)v * ncols;
        for (int32_t b = 0; b < ncols; ++b)
            row[b] = 0;
        for (int k = 0; k < 3; ++k) {
            const double *src = vals + (size_t)tris[3 * (size_t)c.tri + k] * ncols;
            for (int32_t b = 0; b < ncols; ++b)
                row[b] += c.beta[k] * src[b];
        }
    }
done:
    sw_bvh_free(&bvh);
    free(keep);
    free(tris);
    free(boxes);
    return rc;
}

sinew_result sw_weights_from_surface(const sw_tetmesh *m, const sw_trimesh *surf,
                                     const sw_weights *surf_w, sw_weights *out, sw_error *err) {
    if (!out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "weight transfer: out is NULL");
    memset(out, 0, sizeof *out);
    sinew_result rc = check_transfer_inputs(m, surf, surf_w, err);
    if (rc) return rc;
    int32_t nb = surf_w->nbones;
    double *w = calloc((size_t)m->nverts * (size_t)nb, sizeof(double));
    if (!w) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "weight transfer: out of memory");
    if ((rc = sw_surface_interpolate(m, surf, nb, surf_w->w, w, err))) goto done;
    for (int32_t v = 0; v < m->nverts; ++v) {
        double *row = w + (size_t)v * nb, sum = 0;
        for (int32_t b = 0; b < nb; ++b)
            sum += row[b] = row[b] > 0 ? row[b] : 0; /* barycentric round-off */
        if (!(sum > 0)) {
            rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                              "weight transfer: the render weights near vertex %d sum to %g", v,
                              sum);
            goto done;
        }
        for (int32_t b = 0; b < nb; ++b)
            row[b] /= sum;
    }
    out->nverts = m->nverts;
    out->nbones = nb;
    out->w = w;
    w = NULL;
done:
    free(w);
    return rc;
}
