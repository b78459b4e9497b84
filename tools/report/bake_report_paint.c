/* The report's picture of the painted material (bake_report.h): the simulation mesh at
 * rest, its boundary coloured by each vertex's multiplier of E (the mean of its tets'),
 * softest at the ramp's hot end, so an artist sees where the painting landed on the tets
 * the physics runs on, not only where it was painted on the render mesh. */
#include "bake_report.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "png_write.h"
#include "render.h"
#include "text5x7.h"

#define PAINT_W 480
#define PAINT_H 360

/* Each vertex's multiplier (the mean of its tets') into s (nverts). */
static void vertex_stiffness(const sw_character *ch, double *s, double *n) {
    memset(s, 0, sizeof(double) * (size_t)ch->mesh.nverts);
    memset(n, 0, sizeof(double) * (size_t)ch->mesh.nverts);
    for (int32_t t = 0; t < ch->mesh.ntets; ++t)
        for (int k = 0; k < 4; ++k) {
            s[ch->mesh.tets[4 * (int64_t)t + k]] += ch->tet_stiffness[t];
            n[ch->mesh.tets[4 * (int64_t)t + k]] += 1;
        }
    for (int32_t v = 0; v < ch->mesh.nverts; ++v)
        s[v] = n[v] > 0 ? s[v] / n[v] : 1.0;
}

sinew_result sw_bake_report_paint(const char *dir, const sw_character *ch, sw_error *err) {
    if (!ch->tet_stiffness) return SINEW_OK;
    sw_surface surf = {0};
    sinew_result r = sw_tetmesh_surface(&ch->mesh, &surf, err);
    if (r != SINEW_OK) return r;
    const int32_t nv = ch->mesh.nverts;
    double *s = malloc(sizeof(double) * (size_t)nv), *n = malloc(sizeof(double) * (size_t)nv);
    float *colors = malloc(sizeof(float) * 3 * ((size_t)surf.ntris + 1));
    uint8_t *rgb = malloc(3 * (size_t)PAINT_W * PAINT_H);
    if (!s || !n || !colors || !rgb) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "painted material picture: out of memory");
        goto done;
    }
    vertex_stiffness(ch, s, n);
    double lo = INFINITY, hi = -INFINITY;
    for (int32_t t = 0; t < ch->mesh.ntets; ++t) {
        lo = fmin(lo, ch->tet_stiffness[t]);
        hi = fmax(hi, ch->tet_stiffness[t]);
    }
    const double span = hi > lo ? log(hi / lo) : 1.0;
    for (int32_t f = 0; f < surf.ntris; ++f) {
        const int32_t *q = surf.tris + 3 * (int64_t)f;
        const double m = (s[q[0]] + s[q[1]] + s[q[2]]) / 3;
        sw_bake_report_ramp(hi > lo ? log(hi / m) / span : 0.0, colors + 3 * (int64_t)f);
    }
    sw_render_params p = sw_render_params_default(PAINT_W, PAINT_H);
    p.ground = 1;
    if ((r = sw_render_frame_points(&p, nv, ch->mesh.X, err)) != SINEW_OK ||
        (r = sw_render_surface(&p, nv, ch->mesh.X, surf.ntris, surf.tris, colors, rgb, err)) !=
            SINEW_OK)
        goto done;
    char text[96], path[4200];
    static const uint8_t ink[3] = {40, 40, 40};
    snprintf(text, sizeof text, "STIFFNESS x %.3g (HOT) TO x %.3g", lo, hi);
    sw_draw_text(rgb, PAINT_W, PAINT_H, 8, 8, 1, text, ink);
    snprintf(path, sizeof path, "%s/%s", dir, SW_BAKE_REPORT_PAINT_NAME);
    r = sw_write_png(path, PAINT_W, PAINT_H, rgb, err);
done:
    sw_surface_free(&surf);
    free(s);
    free(n);
    free(colors);
    free(rgb);
    return r;
}
