/* The report's contact sheet of held-out frames (bake_report.h): runtime, full-space
 * reference and plain skinning side by side, drawn by the Embree renderer
 * (tools/render). All three are drawn through the blob's output surface: the render
 * mesh placed by its embedding when the blob has one (the artist's own mesh, runtime,
 * reference and skinning alike), the simulation mesh's boundary otherwise. */
#include "bake_report.h"

#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "instance.h"
#include "mesh_io.h"
#include "png_write.h"
#include "render.h"

#define TILE_W 320
#define TILE_H 240
#define GAP 4

/* The three surfaces (runtime, reference, skinning) of `rows` held-out poses, 3 nverts
 * doubles each, stepping a quasistatic instance along the held-out poses' path
 * (sw_bake_heldout_path) as sw_bake_errors does. */
static sinew_result capture(const sw_bake_result *res, const sinew_blob *blob, int32_t nv,
                            int32_t rows, double *X, sw_error *err) {
    sinew_instance_def def = sinew_instance_def_default();
    def.mode = SINEW_STEP_QUASISTATIC;
    def.max_newton_iters = SW_BAKE_EVAL_NEWTON;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    if (r != SINEW_OK) return sw_error_set(err, r, "contact sheet: cannot create an instance");
    double *cnt = malloc(sizeof(double) * (size_t)nv);
    if (!cnt) {
        sinew_instance_destroy(inst);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
    }
    const sw_blob_view *v = sw_blob_get_view(blob);
    size_t n3 = 3 * (size_t)nv;
    int32_t pre, n; /* the held-out poses on the reference's path */
    double *T = sw_bake_heldout_path(res, v->nbones, &pre, &n);
    if (!T) {
        free(cnt);
        sinew_instance_destroy(inst);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
    }
    for (int32_t k = -pre, row = 0; k < res->nheldout && row < rows; ++k) {
        sw_instance_set_pose_d(inst, T + (size_t)(k + pre) * 12 * v->nbones);
        sinew_instance_step(inst, 1.0f / 30);
        if (k < 0) continue;
        int32_t want = rows == 1 ? 0 : (int32_t)((int64_t)row * (res->nheldout - 1) / (rows - 1));
        if (k != want) continue;
        double *out = X + (size_t)row * 3 * n3;
        sw_instance_full_positions(inst, out, cnt);
        memcpy(out + n3, res->heldout_x + (size_t)k * n3, n3 * sizeof(double));
        sw_instance_dqs_positions(inst, out + 2 * n3);
        row++;
    }
    free(T);
    free(cnt);
    sinew_instance_destroy(inst);
    return SINEW_OK;
}

/* Renders tile (row, col) into the sheet. */
static sinew_result draw_tile(const sw_render_params *p, int32_t nv, const double *X,
                              const sw_surface *s, uint8_t *tile, uint8_t *sheet, int W, int row,
                              int col, sw_error *err) {
    sinew_result r = sw_render_surface(p, nv, X, s->ntris, s->tris, NULL, tile, err);
    if (r != SINEW_OK) return r;
    int x0 = col * (TILE_W + GAP), y0 = row * (TILE_H + GAP);
    for (int y = 0; y < TILE_H; ++y)
        memcpy(sheet + 3 * ((size_t)(y0 + y) * W + x0), tile + 3 * (size_t)y * TILE_W, 3 * TILE_W);
    return SINEW_OK;
}

sinew_result sw_bake_report_sheet(const char *png_path, const sw_character *ch,
                                  const sw_bake_result *res, const sinew_blob *blob, int32_t frames,
                                  sw_error *err) {
    int32_t nv = ch->mesh.nverts, rows = frames < res->nheldout ? frames : res->nheldout;
    if (rows < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "contact sheet: no held-out pose");
    sw_surface surf = {0};
    sinew_result r = sw_tetmesh_surface(&ch->mesh, &surf, err);
    if (r != SINEW_OK) return r;
    int W = 3 * TILE_W + 2 * GAP, H = rows * TILE_H + (rows - 1) * GAP;
    double *X = malloc(sizeof(double) * 9 * (size_t)nv * (size_t)rows);
    uint8_t *tile = malloc(3 * (size_t)TILE_W * TILE_H), *sheet = malloc(3 * (size_t)W * H);
    if (!X || !tile || !sheet) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
        goto done;
    }
    memset(sheet, 64, 3 * (size_t)W * H); /* dark grey gutters */
    if ((r = capture(res, blob, nv, rows, X, err)) != SINEW_OK) goto done;
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (v->nrender_verts > 0) { /* every tile through the embedding, in place */
        double *Y = malloc(sizeof(double) * 9 * (size_t)v->nrender_verts * (size_t)rows);
        if (!Y) {
            r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
            goto done;
        }
        for (int32_t t = 0; t < 3 * rows; ++t)
            sw_output_from_full(v, X + (size_t)t * 3 * nv, Y + (size_t)t * 3 * v->nrender_verts);
        free(X);
        X = Y;
        nv = v->nrender_verts;
        sw_surface_free(&surf);
        surf.ntris = v->nrender_tris;
        surf.tris = malloc(sizeof(int32_t) * 3 * (size_t)surf.ntris);
        if (!surf.tris) {
            r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
            goto done;
        }
        memcpy(surf.tris, v->render_tris, sizeof(int32_t) * 3 * (size_t)surf.ntris);
    }
    /* one camera for every tile, fitted to all of them */
    sw_render_params p = sw_render_params_default(TILE_W, TILE_H);
    p.ground = 1;
    if ((r = sw_render_frame_points(&p, 3 * nv * rows, X, err)) != SINEW_OK) goto done;
    for (int32_t row = 0; row < rows && r == SINEW_OK; ++row)
        for (int col = 0; col < 3 && r == SINEW_OK; ++col)
            r = draw_tile(&p, nv, X + ((size_t)row * 3 + col) * 3 * nv, &surf, tile, sheet, W, row,
                          col, err);
    if (r == SINEW_OK) r = sw_write_png(png_path, W, H, sheet, err);
done:
    sw_surface_free(&surf);
    free(X);
    free(tile);
    free(sheet);
    return r;
}
