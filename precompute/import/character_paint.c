/* Painted material carried onto the simulation tets (character_paint.h). A multiplier
 * scales E, so mu and lambda alike: the painted flesh keeps the character's Poisson ratio
 * and its energy is the multiplier times the unpainted one, which is what lets the bake's
 * cubature and the runtime weigh each tet by a number (thesis eq. 2.7 summed per tet). */
#include "character_paint.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_view.h" /* SW_STIFFNESS_MIN, _MAX: the range a blob may hold */
#include "mesh_io.h"
#include "rig.h"

static sinew_result check_range(const double *a, int32_t n, const char *what, sw_error *err) {
    for (int32_t i = 0; i < n; ++i)
        if (!(a[i] >= SW_STIFFNESS_MIN && a[i] <= SW_STIFFNESS_MAX))
            return sw_error_set(
                err, isfinite(a[i]) ? SINEW_ERROR_INVALID_ARGUMENT : SINEW_ERROR_NOT_FINITE,
                "painted stiffness: %s %d's multiplier %g is outside [%g, %g]", what, i, a[i],
                SW_STIFFNESS_MIN, SW_STIFFNESS_MAX);
    return SINEW_OK;
}

sinew_result sw_character_paint(sw_character *c, const double *vert_stiffness, sw_error *err) {
    const int from_render = c->render_stiffness != NULL && c->render.nverts > 0;
    if (!from_render && !vert_stiffness) return SINEW_OK; /* uniform */
    sinew_result r = from_render
                         ? check_range(c->render_stiffness, c->render.nverts, "render vertex", err)
                         : check_range(vert_stiffness, c->mesh.nverts, "vertex", err);
    if (r) return r;
    const int32_t nv = c->mesh.nverts, nt = c->mesh.ntets;
    double *sv = malloc((size_t)(nv > 0 ? nv : 1) * sizeof(double)),
           *st = malloc((size_t)(nt > 0 ? nt : 1) * sizeof(double));
    if (!sv || !st) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "painted stiffness: out of memory");
        goto fail;
    }
    if (!from_render)
        memcpy(sv, vert_stiffness, (size_t)nv * sizeof(double));
    else if ((r = sw_surface_interpolate(&c->mesh, &c->render, 1, c->render_stiffness, sv, err)))
        goto fail;
    for (int32_t t = 0; t < nt; ++t) {
        const int32_t *q = c->mesh.tets + 4 * (int64_t)t;
        st[t] = 0.25 * (sv[q[0]] + sv[q[1]] + sv[q[2]] + sv[q[3]]);
    }
    /* a convex combination of multipliers in range is in range; this guards the code */
    if ((r = check_range(st, nt, "tet", err))) goto fail;
    free(sv);
    free(c->tet_stiffness);
    c->tet_stiffness = st;
    return SINEW_OK;
fail:
    free(sv);
    free(st);
    return r;
}

sinew_result sw_character_read_stiffness(const char *path, sw_character *c, sw_error *err) {
    int32_t rows = 0, cols = 0;
    double *a = NULL;
    sinew_result r = sw_read_dmat(path, &rows, &cols, &a, err);
    if (r) return r;
    const int render = c->render.nverts > 0;
    const int32_t want = render ? c->render.nverts : c->mesh.nverts;
    if (cols != 1 || rows != want) {
        free(a);
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: %d x %d stiffness multipliers, expected %d x 1 (one per %s)", path,
                            rows, cols, want, render ? "render vertex" : "simulation vertex");
    }
    if (render) {
        free(c->render_stiffness);
        c->render_stiffness = a;
        return sw_character_paint(c, NULL, err);
    }
    r = sw_character_paint(c, a, err);
    free(a);
    return r;
}

void sw_character_paint_summary(const sw_character *c, char *buf, size_t n) {
    if (n) buf[0] = 0;
    if (!c->tet_stiffness || !n) return;
    int32_t painted = 0;
    double lo = INFINITY, hi = -INFINITY, soft_vol = 0, vol = 0;
    for (int32_t t = 0; t < c->mesh.ntets; ++t) {
        const int32_t *q = c->mesh.tets + 4 * (int64_t)t;
        const double s = c->tet_stiffness[t],
                     v = fabs(sw_tet_signed_volume(
                         c->mesh.X + 3 * (int64_t)q[0], c->mesh.X + 3 * (int64_t)q[1],
                         c->mesh.X + 3 * (int64_t)q[2], c->mesh.X + 3 * (int64_t)q[3]));
        painted += s != 1.0;
        lo = fmin(lo, s);
        hi = fmax(hi, s);
        vol += v;
        if (s < 1.0) soft_vol += v;
    }
    snprintf(buf, n, "%d of %d tets painted, multipliers %.3g to %.3g, %.1f%% of the volume softer",
             painted, c->mesh.ntets, lo, hi, vol > 0 ? 100.0 * soft_vol / vol : 0.0);
}
