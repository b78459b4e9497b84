/* The report's contact sheet of held-out frames (bake_report.h): full-space reference,
 * runtime and plain skinning side by side, drawn by the Embree renderer (tools/render),
 * each surface coloured by its distance from the reference so that where the runtime
 * (or skinning) parts from the simulation shows at a glance. All three are drawn through
 * the blob's output surface: the render mesh placed by its embedding when the blob has
 * one (the artist's own mesh, runtime, reference and skinning alike), the simulation
 * mesh's boundary otherwise. */
#include "bake_report.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "instance.h"
#include "mesh_io.h"
#include "png_write.h"
#include "render.h"
#include "text5x7.h"

#define TILE_W 320
#define TILE_H 240
#define GAP 4
/* the sheet's margins for its labels (text5x7.h), so the one image reads on its own:
   column names above, frame numbers left, the colour legend below */
#define HEAD_H 28
#define LEFT_W 76
#define FOOT_H 52

const char *const sw_bake_report_sheet_keys[SW_SHEET_COLS] = {"reference", "sinew", "skinning"};

/* sRGB stops: a pale neutral where the surface sits on the reference, so the shading
 * still reads; yellow, orange, then red where it parts from it. */
const float sw_bake_report_ramp_stops[SW_BAKE_REPORT_RAMP_STOPS][3] = {
    {0.85f, 0.83f, 0.80f}, {0.98f, 0.86f, 0.25f}, {0.96f, 0.50f, 0.10f}, {0.78f, 0.06f, 0.10f}};

void sw_bake_report_tile_name(char *buf, size_t n, int32_t row, int col) {
    snprintf(buf, n, "heldout_%d_%s.png", row, sw_bake_report_sheet_keys[col]);
}

void sw_bake_report_ramp(double t, float srgb[3]) {
    t = isfinite(t) ? fmin(fmax(t, 0), 1) : 1;
    double u = t * (SW_BAKE_REPORT_RAMP_STOPS - 1);
    int k = u >= SW_BAKE_REPORT_RAMP_STOPS - 1 ? SW_BAKE_REPORT_RAMP_STOPS - 2 : (int)u;
    double w = u - k;
    for (int c = 0; c < 3; ++c)
        srgb[c] = (float)((1 - w) * sw_bake_report_ramp_stops[k][c] +
                          w * sw_bake_report_ramp_stops[k + 1][c]);
}

/* sRGB to linear (IEC 61966-2-1): the renderer shades linear albedo. */
static float linear(float c) {
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

void sw_bake_report_diff_colors(int32_t nv, const double *X, const double *ref, int32_t ntris,
                                const int32_t *tris, double scale, float *rgb) {
    (void)nv;
    for (int32_t t = 0; t < ntris; ++t) {
        double d = 0;
        for (int a = 0; a < 3; ++a) {
            const double *x = X + 3 * (size_t)tris[3 * t + a],
                         *y = ref + 3 * (size_t)tris[3 * t + a];
            d += sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                      (x[2] - y[2]) * (x[2] - y[2]));
        }
        float c[3];
        sw_bake_report_ramp(d / 3 / scale, c);
        for (int a = 0; a < 3; ++a)
            rgb[3 * (size_t)t + a] = linear(c[a]);
    }
}

/* The three surfaces (reference, runtime, skinning: SW_SHEET_*) of `rows` held-out poses,
 * 3 nverts doubles each, stepping a quasistatic instance along the held-out poses' path
 * (sw_bake_heldout_path) as sw_bake_errors does; each row's pose into pose. */
static sinew_result capture(const sw_bake_result *res, const sinew_blob *blob, int32_t nv,
                            int32_t rows, double *X, int32_t *pose, sw_error *err) {
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
        memcpy(out + SW_SHEET_REFERENCE * n3, res->heldout_x + (size_t)k * n3, n3 * sizeof(double));
        sw_instance_full_positions(inst, out + SW_SHEET_SINEW * n3, cnt);
        sw_instance_dqs_positions(inst, out + SW_SHEET_SKINNING * n3);
        pose[row++] = k;
    }
    free(T);
    free(cnt);
    sinew_instance_destroy(inst);
    return SINEW_OK;
}

/* Each tile's largest and mean vertex distance from its row's reference, the ramp's
 * scale (the largest distance of any tile: the colours compare across the sheet) and the
 * character's size. X: rows x SW_SHEET_COLS surfaces of nv vertices. */
static void measure(int32_t nv, const double *X, int32_t rows, sw_bake_report_sheet_info *info) {
    size_t n3 = 3 * (size_t)nv;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    info->scale = 0;
    for (int32_t row = 0; row < rows; ++row) {
        const double *ref = X + (size_t)row * SW_SHEET_COLS * n3 + SW_SHEET_REFERENCE * n3;
        for (int32_t v = 0; v < nv; ++v)
            for (int a = 0; a < 3; ++a) {
                lo[a] = fmin(lo[a], ref[3 * (size_t)v + a]);
                hi[a] = fmax(hi[a], ref[3 * (size_t)v + a]);
            }
        for (int col = 0; col < SW_SHEET_COLS; ++col) {
            const double *x = X + ((size_t)row * SW_SHEET_COLS + col) * n3;
            double mx = 0, sum = 0;
            for (size_t i = 0; i < n3; i += 3) {
                double d = sqrt((x[i] - ref[i]) * (x[i] - ref[i]) +
                                (x[i + 1] - ref[i + 1]) * (x[i + 1] - ref[i + 1]) +
                                (x[i + 2] - ref[i + 2]) * (x[i + 2] - ref[i + 2]));
                mx = fmax(mx, d);
                sum += d;
            }
            info->max_dist[row][col] = mx;
            info->mean_dist[row][col] = nv > 0 ? sum / nv : 0;
            info->scale = fmax(info->scale, mx);
        }
    }
    info->size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    /* a sheet with no difference at all (never from a bake) still has a ramp to draw */
    if (!(info->scale > 0)) info->scale = info->size > 0 ? 1e-3 * info->size : 1;
}

/* Renders tile (row, col), coloured by its distance from the row's reference, into the
 * sheet and into its own PNG in dir. */
static sinew_result draw_tile(const sw_render_params *p, int32_t nv, const double *X,
                              const double *ref, double scale, const sw_surface *s, float *colors,
                              uint8_t *tile, uint8_t *sheet, int W, int row, int col,
                              const char *dir, sw_error *err) {
    sw_bake_report_diff_colors(nv, X, ref, s->ntris, s->tris, scale, colors);
    sinew_result r = sw_render_surface(p, nv, X, s->ntris, s->tris, colors, tile, err);
    if (r != SINEW_OK) return r;
    int x0 = LEFT_W + col * (TILE_W + GAP), y0 = HEAD_H + row * (TILE_H + GAP);
    for (int y = 0; y < TILE_H; ++y)
        memcpy(sheet + 3 * ((size_t)(y0 + y) * W + x0), tile + 3 * (size_t)y * TILE_W, 3 * TILE_W);
    char name[64], path[4200];
    sw_bake_report_tile_name(name, sizeof name, row, col);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return sw_write_png(path, TILE_W, TILE_H, tile, err);
}

/* The sheet's labels: the columns' names, each row's frame (or random pose), and the
 * colour legend with its scale in length units and as a share of the character's size. */
static void draw_labels(uint8_t *sheet, int W, int H, const sw_bake_result *res,
                        const sw_bake_report_sheet_info *info) {
    static const uint8_t ink[3] = {40, 40, 40};
    static const char *const head[SW_SHEET_COLS] = {"REFERENCE", "SINEW", "SKINNING"};
    char text[96];
    for (int c = 0; c < SW_SHEET_COLS; ++c)
        sw_draw_text(sheet, W, H,
                     LEFT_W + c * (TILE_W + GAP) + (TILE_W - sw_text_width(head[c], 2)) / 2, 7, 2,
                     head[c], ink);
    for (int32_t row = 0; row < info->rows; ++row) {
        int32_t k = info->pose[row];
        int y = HEAD_H + row * (TILE_H + GAP) + TILE_H / 2 - 16;
        sw_draw_text(sheet, W, H, 8, y, 2, res->heldout_clip[k] < 0 ? "POSE" : "FRAME", ink);
        snprintf(text, sizeof text, "%d", res->heldout_clip[k] < 0 ? k : res->heldout_frame[k]);
        sw_draw_text(sheet, W, H, 8, y + 20, 2, text, ink);
    }
    int y0 = H - FOOT_H + 8, x0 = LEFT_W, bar = 3 * TILE_W + 2 * GAP;
    sw_draw_text(sheet, W, H, x0, y0, 1,
                 "DISTANCE FROM THE REFERENCE, IN LENGTH UNITS (SHARE OF "
                 "THE CHARACTER'S SIZE)",
                 ink);
    for (int x = 0; x < bar; ++x) {
        float c[3];
        sw_bake_report_ramp((double)x / (bar - 1), c);
        for (int y = y0 + 11; y < y0 + 23; ++y)
            for (int a = 0; a < 3; ++a)
                sheet[3 * ((size_t)y * W + x0 + x) + a] = (uint8_t)(255 * c[a] + 0.5f);
    }
    for (int t = 0; t <= 4; ++t) {
        double d = info->scale * t / 4;
        snprintf(text, sizeof text, "%s%.3g (%.2g%%)", t == 4 ? ">=" : "", d,
                 info->size > 0 ? 100 * d / info->size : 0);
        int w = sw_text_width(text, 1), x = x0 + bar * t / 4 - (t == 0 ? 0 : t == 4 ? w : w / 2);
        sw_draw_text(sheet, W, H, x, y0 + 28, 1, text, ink);
    }
}

/* The surfaces X (3 * rows tiles of the simulation mesh's nv vertices) carried onto the
 * blob's render mesh through its embedding, in place; *nv and the surface follow. */
static sinew_result to_render_mesh(const sw_blob_view *v, int32_t rows, double **X, int32_t *nv,
                                   sw_surface *surf, sw_error *err) {
    double *Y = malloc(sizeof(double) * 9 * (size_t)v->nrender_verts * (size_t)rows);
    int32_t *tris = malloc(sizeof(int32_t) * 3 * (size_t)v->nrender_tris);
    if (!Y || !tris) {
        free(Y);
        free(tris);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
    }
    for (int32_t t = 0; t < 3 * rows; ++t)
        sw_output_from_full(v, *X + (size_t)t * 3 * *nv, Y + (size_t)t * 3 * v->nrender_verts);
    free(*X);
    *X = Y;
    *nv = v->nrender_verts;
    sw_surface_free(surf);
    surf->ntris = v->nrender_tris;
    surf->tris = tris;
    memcpy(surf->tris, v->render_tris, sizeof(int32_t) * 3 * (size_t)surf->ntris);
    return SINEW_OK;
}

sinew_result sw_bake_report_sheet(const char *dir, const sw_character *ch,
                                  const sw_bake_result *res, const sinew_blob *blob, int32_t frames,
                                  sw_bake_report_sheet_info *info, sw_error *err) {
    if (frames > SW_BAKE_REPORT_SHEET_ROWS) frames = SW_BAKE_REPORT_SHEET_ROWS;
    int32_t nv = ch->mesh.nverts, rows = frames < res->nheldout ? frames : res->nheldout;
    if (rows < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "contact sheet: no held-out pose");
    memset(info, 0, sizeof *info);
    info->rows = rows;
    sw_surface surf = {0};
    sinew_result r = sw_tetmesh_surface(&ch->mesh, &surf, err);
    if (r != SINEW_OK) return r;
    int W = LEFT_W + 3 * TILE_W + 2 * GAP, H = HEAD_H + rows * TILE_H + (rows - 1) * GAP + FOOT_H;
    double *X = malloc(sizeof(double) * 9 * (size_t)nv * (size_t)rows);
    uint8_t *tile = malloc(3 * (size_t)TILE_W * TILE_H), *sheet = malloc(3 * (size_t)W * H);
    float *colors = NULL;
    if (!X || !tile || !sheet) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
        goto done;
    }
    memset(sheet, 255, 3 * (size_t)W * H); /* white margins and gutters */
    if ((r = capture(res, blob, nv, rows, X, info->pose, err)) != SINEW_OK) goto done;
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (v->nrender_verts > 0 && (r = to_render_mesh(v, rows, &X, &nv, &surf, err)) != SINEW_OK)
        goto done;
    measure(nv, X, rows, info);
    if (!(colors = malloc(sizeof(float) * 3 * ((size_t)surf.ntris + 1)))) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "contact sheet: out of memory");
        goto done;
    }
    /* one camera for every tile, fitted to all of them */
    sw_render_params p = sw_render_params_default(TILE_W, TILE_H);
    p.ground = 1;
    if ((r = sw_render_frame_points(&p, 3 * nv * rows, X, err)) != SINEW_OK) goto done;
    size_t n3 = 3 * (size_t)nv;
    for (int32_t row = 0; row < rows && r == SINEW_OK; ++row)
        for (int col = 0; col < SW_SHEET_COLS && r == SINEW_OK; ++col)
            r = draw_tile(&p, nv, X + ((size_t)row * SW_SHEET_COLS + col) * n3,
                          X + ((size_t)row * SW_SHEET_COLS + SW_SHEET_REFERENCE) * n3, info->scale,
                          &surf, colors, tile, sheet, W, row, col, dir, err);
    if (r == SINEW_OK) draw_labels(sheet, W, H, res, info);
    char path[4200];
    snprintf(path, sizeof path, "%s/heldout_sheet.png", dir);
    if (r == SINEW_OK) r = sw_write_png(path, W, H, sheet, err);
done:
    sw_surface_free(&surf);
    free(X);
    free(colors);
    free(tile);
    free(sheet);
    return r;
}
