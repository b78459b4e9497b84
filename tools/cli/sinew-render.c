/* sinew-render: ray-traced pictures of surfaces (DESIGN.md §7), so a person can look at
 * what the simulator or the runtime produced.
 *
 *   sinew-render --obj FILE [--obj FILE ...] --out IMAGE.png [--width W] [--height H]
 *   sinew-render --frames DIR [--grid N] --out IMAGE.png [...]
 *
 * One OBJ gives one picture; several give a contact sheet (one tile each, left to
 * right, top to bottom) all seen by the same camera, which frames the union of their
 * bounding boxes, so motion between tiles is real motion. --frames takes the
 * frame_NNNN.obj files that `sinew-fullsim --out DIR` writes and picks at most N x N
 * evenly spaced ones (first and last included). */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "tool_common.h"
#include "mesh_io.h"
#include "png_write.h"
#include "render.h"

#define GAP 4 /* pixels between tiles of a contact sheet */

typedef struct {
    const char **objs;
    int nobjs;
    const char *frames_dir, *out;
    int width, height, grid, supersample, threads, ground, quiet;
    int azimuth, elevation;
} options;

#define TEXT_(x) #x
#define TEXT(x) TEXT_(x)

/* --obj FILE, any number of times */
static int take_obj(const char *tool, const char *flag, const char *v, void *target) {
    (void)tool, (void)flag;
    options *o = target;
    o->objs[o->nobjs++] = v;
    return 1;
}

/* Parses argv into *o; 0 for a usable command line, else the exit status 2 (the message
 * is out). */
static int parse_args(int argc, char **argv, options *o) {
    memset(o, 0, sizeof *o);
    o->grid = 4;
    o->supersample = 2;
    o->ground = 1;
    o->azimuth = 35;
    o->elevation = 20;
    long nproc = sysconf(_SC_NPROCESSORS_ONLN);
    o->threads = nproc > 0 ? (nproc > 64 ? 64 : (int)nproc) : 1;
    o->objs = calloc((size_t)argc, sizeof *o->objs);
    if (!o->objs) {
        fprintf(stderr, "sinew-render: out of memory\n");
        return 2;
    }
    int grid_given = 0;
    const sw_flag flags[] = {
        {SW_CALL("--obj", take_obj, o, "FILE",
                 "a Wavefront OBJ surface; several make a contact sheet (vertex\n"
                 "colours, v x y z r g b, colour its triangles: sinew-bench\n"
                 "--world --out marks the full-space patch so)")},
        {SW_STR("--frames", &o->frames_dir, "DIR",
                "every DIR/frame_NNNN.obj (as written by sinew-fullsim --out)")},
        {SW_INT("--grid", &o->grid, 1, 64, "N",
                "with --frames: at most N x N evenly spaced frames, 1..64\n(default 4)"),
         .given = &grid_given},
        {SW_STR("--out", &o->out, "FILE", "the PNG to write (written to FILE.tmp, then renamed)")},
        {SW_INT("--width", &o->width, 1, SW_PNG_MAX_DIM, "W",
                "image width in pixels, 1.." TEXT(SW_PNG_MAX_DIM) " (default 640, contact\n"
                                                                  "sheet 1280)")},
        {SW_INT("--height", &o->height, 1, SW_PNG_MAX_DIM, "H",
                "image height in pixels, 1.." TEXT(SW_PNG_MAX_DIM) " (default 480, contact\n"
                                                                   "sheet 960)")},
        {SW_INT("--supersample", &o->supersample, 1, 4, "S",
                "S x S rays a pixel, 1..4 (default 2)")},
        {SW_INT("--azimuth", &o->azimuth, -360, 360, "DEG",
                "camera turned from the front (+Z, Y up) toward +X, -360..360\n(default 35)")},
        {SW_INT("--elevation", &o->elevation, -89, 89, "DEG",
                "camera height above the horizon, -89..89 (default 20)")},
        {SW_INT("--threads", &o->threads, 1, 64, "T",
                "render threads, 1..64 (default: all cores)")},
        {SW_SET("--no-ground", &o->ground, 0, "no checkered ground plane")},
        {SW_SET("--quiet", &o->quiet, 1, "no summary line on stderr")},
    };
    const sw_flag_group groups[] = {{NULL, flags, SW_FLAGS_N(flags)}};
    const sw_tool_cli cli = {
        "sinew-render",
        "sinew-render --obj FILE [--obj FILE ...] --out IMAGE.png [options]\n"
        "       sinew-render --frames DIR --out IMAGE.png [--grid N] [options]\n",
        groups,
        1,
        "exit status: 0 written, 1 failed, 2 bad arguments\n",
        NULL,
        0};
    if (sw_flags_parse(&cli, argc, argv)) return 2;
    if (!o->out || (o->nobjs == 0) == (o->frames_dir == NULL)) {
        fprintf(stderr, "sinew-render: need --out and either --obj (one or more) or --frames\n");
        return 2;
    }
    if (grid_given && !o->frames_dir) {
        fprintf(stderr, "sinew-render: --grid does not apply to --obj (it thins --frames)\n");
        return 2;
    }
    for (int k = 0; k < o->nobjs; ++k)
        if (!sw_tool_format("sinew-render", "--obj", o->objs[k], "obj", ".obj (Wavefront)"))
            return 2;
    return sw_tool_format("sinew-render", "--out", o->out, "png", ".png") ? 0 : 2;
}

/* ---- --frames: frame_NNNN.obj files, sorted by number, evenly thinned --------------- */

typedef struct {
    long number;
    char *path;
} frame_file;

static int cmp_frame(const void *a, const void *b) {
    long x = ((const frame_file *)a)->number, y = ((const frame_file *)b)->number;
    return (x > y) - (x < y);
}

/* Returns the frame number of "frame_<digits>.obj", or -1. */
static long frame_number(const char *name) {
    if (strncmp(name, "frame_", 6)) return -1;
    const char *d = name + 6, *e = d;
    while (*e >= '0' && *e <= '9')
        ++e;
    if (e == d || e - d > 9 || strcmp(e, ".obj")) return -1;
    return strtol(d, NULL, 10);
}

static void free_frames(frame_file *f, int n) {
    for (int i = 0; i < n; ++i)
        free(f[i].path);
    free(f);
}

static int list_frames(const char *dir, frame_file **out, int *count) {
    *out = NULL;
    *count = 0;
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "sinew-render: %s: cannot open directory (%s)\n", dir, strerror(errno));
        return 0;
    }
    frame_file *f = NULL;
    int n = 0, cap = 0, ok = 1;
    struct dirent *e;
    while (ok && (e = readdir(d))) {
        long num = frame_number(e->d_name);
        if (num < 0) continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            frame_file *g = realloc(f, (size_t)cap * sizeof *g);
            if (!g) {
                ok = 0;
                break;
            }
            f = g;
        }
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        f[n].path = malloc(len);
        if (!f[n].path) {
            ok = 0;
            break;
        }
        snprintf(f[n].path, len, "%s/%s", dir, e->d_name);
        f[n++].number = num;
    }
    closedir(d);
    if (!ok) {
        fprintf(stderr, "sinew-render: out of memory listing %s\n", dir);
        free_frames(f, n);
        return 0;
    }
    if (n == 0) {
        fprintf(stderr, "sinew-render: %s: no frame_NNNN.obj files\n", dir);
        free(f);
        return 0;
    }
    qsort(f, (size_t)n, sizeof *f, cmp_frame);
    *out = f;
    *count = n;
    return 1;
}

/* ---- rendering ------------------------------------------------------------------------ */

/* A thin bar along a tile's bottom edge showing where the tile lies in the sequence. */
static void progress_bar(uint8_t *tile, int w, int h, double frac) {
    int filled = (int)lrint(frac * (w - 1)) + 1;
    for (int y = h - 3; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            uint8_t *px = tile + 3 * ((size_t)y * w + x);
            uint8_t v = x < filled ? 60 : 200;
            px[0] = x < filled ? 200 : v;
            px[1] = px[2] = v;
        }
}

/* Each triangle's colour, the mean of its corners' vertex colours, or NULL (the
 * renderer's skin tone) for a file without colours. */
static float *triangle_colors(const sw_trimesh *m, const double *C) {
    float *tc = C ? malloc(sizeof(float) * 3 * (size_t)(m->ntris ? m->ntris : 1)) : NULL;
    for (int32_t t = 0; tc && t < m->ntris; ++t)
        for (int k = 0; k < 3; ++k)
            tc[3 * t + k] = (float)((C[3 * m->tris[3 * t] + k] + C[3 * m->tris[3 * t + 1] + k] +
                                     C[3 * m->tris[3 * t + 2] + k]) /
                                    3);
    return tc;
}

static int render_all(const options *o, const char **paths, int n) {
    sw_trimesh *m = calloc((size_t)n, sizeof *m);
    float **tc = calloc((size_t)n, sizeof *tc);
    uint8_t *tile = NULL, *sheet = NULL;
    int ok = m != NULL && tc != NULL;
    sw_error err;
    sw_error_clear(&err);
    double bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    long long total_tris = 0;
    for (int i = 0; ok && i < n; ++i) {
        double lo[3], hi[3];
        double *C = NULL; /* vertex colours (sinew-bench --world --out: the patch) */
        if (sw_read_obj_colors(paths[i], &m[i], &C, &err) ||
            sw_render_bbox(m[i].nverts, m[i].X, lo, hi, &err)) {
            fprintf(stderr, "sinew-render: %s\n", err.msg);
            ok = 0;
            break;
        }
        tc[i] = triangle_colors(&m[i], C);
        free(C);
        total_tris += m[i].ntris;
        for (int k = 0; k < 3; ++k) {
            if (lo[k] < bmin[k]) bmin[k] = lo[k];
            if (hi[k] > bmax[k]) bmax[k] = hi[k];
        }
    }
    int cols = (int)ceil(sqrt((double)n)), rows = (n + cols - 1) / cols;
    int W = o->width ? o->width : (n > 1 ? 1280 : 640);
    int H = o->height ? o->height : (n > 1 ? 960 : 480);
    int gap = n > 1 ? GAP : 0;
    int tw = (W - gap * (cols + 1)) / cols, th = (H - gap * (rows + 1)) / rows;
    if (ok && (tw < 8 || th < 8)) {
        fprintf(stderr, "sinew-render: %d x %d is too small for %d x %d tiles\n", W, H, cols, rows);
        ok = 0;
    }
    sw_render_params p = sw_render_params_default(tw, th);
    p.supersample = o->supersample;
    p.threads = o->threads;
    p.ground = o->ground;
    p.view_azimuth_deg = o->azimuth;
    p.view_elevation_deg = o->elevation;
    /* one camera for every tile, fitted to the points of all of them */
    long long npts = 0;
    for (int i = 0; ok && i < n; ++i)
        npts += m[i].nverts;
    double *pts = ok && npts <= INT32_MAX ? malloc(sizeof(double) * 3 * (size_t)npts) : NULL;
    if (pts) {
        size_t at = 0;
        for (int i = 0; i < n; ++i) {
            memcpy(pts + at, m[i].X, sizeof(double) * 3 * (size_t)m[i].nverts);
            at += 3 * (size_t)m[i].nverts;
        }
    }
    if (ok && (pts ? sw_render_frame_points(&p, (int32_t)npts, pts, &err)
                   : sw_render_frame_camera(&p, bmin, bmax, &err))) { /* too many: their box */
        fprintf(stderr, "sinew-render: %s\n", err.msg);
        ok = 0;
    }
    free(pts);
    if (ok) {
        tile = malloc((size_t)tw * th * 3);
        sheet = malloc((size_t)W * H * 3);
        if (!tile || !sheet) {
            fprintf(stderr, "sinew-render: out of memory for a %d x %d image\n", W, H);
            ok = 0;
        }
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (ok) memset(sheet, 64, (size_t)W * H * 3); /* dark grey gutters */
    for (int i = 0; ok && i < n; ++i) {
        if (sw_render_surface(&p, m[i].nverts, m[i].X, m[i].ntris, m[i].tris, tc[i], tile, &err)) {
            fprintf(stderr, "sinew-render: %s: %s\n", paths[i], err.msg);
            ok = 0;
            break;
        }
        if (n > 1) progress_bar(tile, tw, th, (double)i / (double)(n - 1));
        int x0 = gap + (i % cols) * (tw + gap), y0 = gap + (i / cols) * (th + gap);
        for (int y = 0; y < th; ++y)
            memcpy(sheet + 3 * ((size_t)(y0 + y) * W + x0), tile + 3 * (size_t)y * tw,
                   3 * (size_t)tw);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (ok && sw_write_png(o->out, W, H, sheet, &err)) {
        fprintf(stderr, "sinew-render: %s\n", err.msg);
        ok = 0;
    }
    if (ok && !o->quiet) {
        double ms =
            1e3 * (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_nsec - t0.tv_nsec);
        fprintf(stderr,
                "sinew-render: wrote %s (%d x %d, %d tile%s of %d x %d, %lld triangles, "
                "%.1f ms rendering on %d thread%s)\n",
                o->out, W, H, n, n == 1 ? "" : "s", tw, th, total_tris, ms, o->threads,
                o->threads == 1 ? "" : "s");
    }
    for (int i = 0; m && i < n; ++i)
        sw_trimesh_free(&m[i]);
    for (int i = 0; tc && i < n; ++i)
        free(tc[i]);
    free(m);
    free(tc);
    free(tile);
    free(sheet);
    return ok;
}

int main(int argc, char **argv) {
    options o;
    if (parse_args(argc, argv, &o)) {
        free(o.objs);
        return 2;
    }
    int ok;
    if (o.frames_dir) {
        frame_file *f;
        int nf;
        ok = list_frames(o.frames_dir, &f, &nf);
        if (ok) {
            /* k evenly spaced picks from nf frames, first and last included. */
            int k = nf < o.grid * o.grid ? nf : o.grid * o.grid;
            const char **pick = malloc((size_t)k * sizeof *pick);
            if (!pick) {
                fprintf(stderr, "sinew-render: out of memory\n");
                ok = 0;
            } else {
                for (int i = 0; i < k; ++i)
                    pick[i] = f[k == 1 ? 0 : (int)lrint((double)i * (nf - 1) / (k - 1))].path;
                ok = render_all(&o, pick, k);
                free(pick);
            }
            free_frames(f, nf);
        }
    } else {
        ok = render_all(&o, o.objs, o.nobjs);
    }
    free(o.objs);
    return ok ? 0 : 1;
}
