/* Offline ray-cast images of triangle surfaces (DESIGN.md §7: sinew-render), built on
 * Embree 3. One primary ray per pixel (or s x s supersampling), Lambert shading with a
 * little ambient, a key light with a shadow ray and a weaker fill light, and an optional
 * checkered ground plane. Normals are turned toward the viewer, so inverted and
 * self-intersecting regions of a simulated surface still shade instead of going black.
 *
 * The scene (Embree device, BVH) is built and released inside each call: this is a bake
 * side tool, and rtcCommitScene allocates anyway (STYLE.md §6). */
#ifndef SW_RENDER_H
#define SW_RENDER_H

#include <stdint.h>

#include "sw_error.h"

/* Largest image width or height sw_render_surface accepts. */
#define SW_RENDER_MAX_DIM 16384

typedef struct sw_render_params {
    int32_t width, height;     /* pixels, 1..SW_RENDER_MAX_DIM */
    double eye[3];             /* camera position */
    double target[3];          /* point at the image centre */
    double up[3];              /* world up: camera roll and the ground plane's normal */
    double fov_y_deg;          /* vertical field of view, (0, 170) degrees */
    int32_t supersample;       /* s: s x s rays a pixel, 1..4 (1 = none) */
    double key_dir[3];         /* direction *toward* the key light; all zero = from the
                                  camera's upper left (see sw_render_surface) */
    double key, fill, ambient; /* light intensities (fill comes from the lower right) */
    int32_t shadows;           /* 1: shadow ray toward the key light */
    int32_t smooth;            /* 1: interpolate area-weighted vertex normals */
    int32_t ground;            /* 1: draw a checkered ground plane */
    double ground_level;       /* the plane is {x : dot(x, up_unit) = ground_level} */
    double ground_tile;        /* checker square size (> 0 when ground is on) */
    double ground_radius;      /* the checker fades into the background by this distance from
                                  the target (> 0 when ground is on) */
    float background[3];       /* output colour of pixels that hit nothing, [0,1] sRGB */
    int32_t threads;         /* rows are split over this many threads, 0..64 (0, 1: caller only) */
    double view_azimuth_deg; /* sw_render_frame_camera: turn from the front toward +side */
    double view_elevation_deg; /* sw_render_frame_camera: height above the horizon */
} sw_render_params;

/* Defaults for a w x h image: camera on +Z looking at the origin with +Y up, 35 degree
 * fov, 2x2 supersampling, key/fill/ambient 0.85/0.25/0.12, shadows and smooth normals
 * on, ground off, a pale blue-grey background, one thread, framing view 35 degrees
 * azimuth and 20 degrees elevation. */
sw_render_params sw_render_params_default(int32_t width, int32_t height);

/* Axis-aligned bounds of `nverts` points (3 doubles each). Returns NOT_FINITE naming
 * the first non-finite coordinate, DEGENERATE when nverts < 1. */
sinew_result sw_render_bbox(int32_t nverts, const double *X, double bmin[3], double bmax[3],
                            sw_error *err);

/* Frames the box [bmin, bmax] from a 3/4 view: the camera sits in front (+Z, relative to
 * p->up; +X when up is along Z), p->view_azimuth_deg toward the side (up x front, +X
 * for +Y up) and p->view_elevation_deg above the horizon (defaults 35 and 20; the
 * elevation must be within (-90, 90)), looking at the box, as near as lets the box's
 * corners fit the image at p->width x p->height with p->fov_y_deg (a 5% margin, never
 * inside the box's bounding sphere), their image centred. Also places the ground plane at
 * the box's lowest point along up, with tiles and fade radius scaled to the box
 * (p->ground itself is not changed). Errors: NOT_FINITE / INVALID_ARGUMENT for a bad box,
 * up, fov or size. */
sinew_result sw_render_frame_camera(sw_render_params *p, const double bmin[3], const double bmax[3],
                                    sw_error *err);

/* The same for the points themselves (npts positions X, the bounds of sw_render_bbox): a
 * character fills the image, where the corners of its box leave it small. */
sinew_result sw_render_frame_points(sw_render_params *p, int32_t npts, const double *X,
                                    sw_error *err);

/* Renders the surface (nverts positions X, ntris triangles `tris`, 0-based) into
 * `rgb_out` (width*height*3 bytes, row-major, top row first, sRGB). `tri_colors` is an
 * optional per-triangle linear RGB albedo in [0,1] (3 floats a triangle; NULL = a skin
 * tone). ntris may be 0 (background and ground only).
 * Errors: INVALID_ARGUMENT (NULL, sizes, index out of range, bad camera or light),
 * NOT_FINITE (a NaN/inf coordinate or colour, or one too large for float), and
 * OUT_OF_MEMORY / UNSUPPORTED for Embree failures (message carries Embree's). Every
 * Embree object is released on every path. Thread-safe for distinct outputs. */
sinew_result sw_render_surface(const sw_render_params *p, int32_t nverts, const double *X,
                               int32_t ntris, const int32_t *tris, const float *tri_colors,
                               uint8_t *rgb_out, sw_error *err);

#endif
