/* The bake report (sinew-bake --report DIR): one self-contained HTML page a technical
 * artist opens, its verdict first (the held-out error against a target, and what motion
 * to add when it misses), then inline SVG plots (the correction error of every clip
 * frame, training and held-out; the basis rank and energy and the cubature size of every
 * domain; the stage times), and the same figures as JSON (libcjson), plus a contact sheet
 * of held-out frames (full-space reference, runtime and plain skinning side by side, each
 * surface coloured by its distance from the reference) as PNG files the page shows.
 *
 *   DIR/report.html   the page (shows the tiles below when they were rendered)
 *   DIR/report.json   {"sinew_bake_report": 1, ...}: the figures (schema in bake_report.c)
 *   DIR/heldout_sheet.png  the contact sheet in one image, labelled (columns named, frames
 *                     numbered, the colour legend)
 *   DIR/heldout_<row>_<column>.png  its tiles, one a frame and column, which the page
 *                     lays out under named columns and numbered frames */
#ifndef SW_BAKE_REPORT_H
#define SW_BAKE_REPORT_H

#include <stddef.h>

#include "blob_parts.h"
#include "bake.h"
#include "bake_adaptive.h"
#include "sinew/sinew.h"
#include "sw_mesh.h"

#define SW_BAKE_REPORT_VERSION 1

/* The held-out error the verdict measures against when none is given: sinew's acceptance
 * limit for a character's held-out clip (the runtime misses at most a fifth of the
 * physics correction on motion it never trained on). */
#define SW_BAKE_REPORT_TARGET 0.2

/* Everything the report shows; the pointers are borrowed. */
typedef struct sw_bake_report_input {
    const char *source;        /* the character's file or scene name */
    const sw_character *ch;    /* the baked character */
    const sw_bake_result *res; /* the bake (poses, labels, stage times, basis energy) */
    const sinew_blob *blob;    /* the blob it made (domains, ranks, cubature) */
    /* names of the clips the pose labels index (sw_bake_result.train_clip): with clips
       of their own, their names; NULL: the character's one clip */
    const char (*train_names)[64];
    int32_t ntrain_names;
    const char (*heldout_names)[64];
    int32_t nheldout_names;
    const double *train_frames;   /* res->ntrain per-pose correction errors */
    const double *heldout_frames; /* res->nheldout */
    double err_train, err_heldout;
    int32_t failed_steps;
    double bake_seconds, eval_seconds;
    int contact_sheet; /* render DIR/heldout_sheet.png and its tiles (Embree; a few seconds) */
    /* the adaptive loop's rounds (sinew-bake --adaptive; NULL or 0 rounds: none) */
    const sw_adaptive_report *adaptive;
    /* where the error is (sw_eval_result's regions) on the training and the held-out poses;
       NULL: not shown */
    const sw_eval_result *eval_train, *eval_heldout;
    /* what made the simulation mesh ("lattice", "tetgen"; NULL: the character's own tet
       mesh); the report shows it beside the mesh's quality (sw_tetmesh_quality) */
    const char *mesher;
    /* the held-out error in each self-contact mode (sw_bake_mode_errors, SW_BAKE_MODES, NaN:
       not measured); NULL: not shown */
    const double *mode_err_heldout;
    /* how well the held-out references are defined (sw_bake_reference_spread, sinew-bake
       --reference-spread); NULL: not measured */
    const sw_bake_spread *spread;
    /* the names of the reference's linear solver and element Hessians (fullsim.h's
       sw_linear_solver_name, sw_hessian_mode_name): the figures are measured against its
       solutions; NULL: not shown */
    const char *ref_solver, *ref_hessian;
    /* the held-out error the verdict measures against, in (0, 1); 0: SW_BAKE_REPORT_TARGET */
    double target;
    /* the written blob's bytes by part and its instances' (blob_parts.h); NULL: not shown */
    const sw_blob_memory *memory;
} sw_bake_report_input;

/* Creates DIR (and its parents) and writes the report there. Errors: IO (cannot create
 * or write), OUT_OF_MEMORY, and the renderer's for the contact sheet. */
sinew_result sw_bake_report_write(const char *dir, const sw_bake_report_input *in, sw_error *err);

/* The contact sheet's columns, left to right, and their keys in the tiles' file names. */
enum { SW_SHEET_REFERENCE, SW_SHEET_SINEW, SW_SHEET_SKINNING, SW_SHEET_COLS };
extern const char *const sw_bake_report_sheet_keys[SW_SHEET_COLS];

#define SW_BAKE_REPORT_SHEET_ROWS 4 /* held-out frames on the sheet, at most */

/* What the contact sheet shows, for the page's labels and legend. Distances are in the
 * character's length units. */
typedef struct sw_bake_report_sheet_info {
    int32_t rows;
    int32_t pose[SW_BAKE_REPORT_SHEET_ROWS]; /* the held-out pose (index) of each row */
    double scale; /* the colour ramp's top: a vertex this far from the reference, or further */
    double size;  /* the character's size: the largest side of the reference frames' box */
    /* per row and column: the largest and the mean vertex distance from the reference */
    double max_dist[SW_BAKE_REPORT_SHEET_ROWS][SW_SHEET_COLS];
    double mean_dist[SW_BAKE_REPORT_SHEET_ROWS][SW_SHEET_COLS];
} sw_bake_report_sheet_info;

/* The tile of (row, col) as a file name in the report's folder. */
void sw_bake_report_tile_name(char *buf, size_t n, int32_t row, int col);

/* The contact sheet of up to `frames` (at most SW_BAKE_REPORT_SHEET_ROWS) held-out poses
 * of res, one row each: the full-space reference, the runtime (a quasistatic instance of
 * blob stepped through the held-out poses) and plain dual-quaternion skinning, each
 * coloured by its vertices' distance from the reference (sw_bake_report_ramp), written as
 * DIR/heldout_sheet.png and one PNG a tile (bake_report_sheet.c). */
sinew_result sw_bake_report_sheet(const char *dir, const sw_character *ch,
                                  const sw_bake_result *res, const sinew_blob *blob, int32_t frames,
                                  sw_bake_report_sheet_info *info, sw_error *err);

/* The colour ramp of the distance from the reference, t = distance / scale clamped to
 * [0, 1]: pale grey (0), yellow, orange, red (1), as sRGB in [0, 1], evenly spaced. The
 * page's legend draws the same stops (sw_bake_report_ramp_stops). */
#define SW_BAKE_REPORT_RAMP_STOPS 4
extern const float sw_bake_report_ramp_stops[SW_BAKE_REPORT_RAMP_STOPS][3];
void sw_bake_report_ramp(double t, float srgb[3]);

/* Per-triangle linear RGB albedo (3 floats a triangle, for sw_render_surface) of the
 * surface X against the reference surface ref (nv vertices each): the ramp at each
 * triangle's mean vertex distance over scale (> 0). */
void sw_bake_report_diff_colors(int32_t nv, const double *X, const double *ref, int32_t ntris,
                                const int32_t *tris, double scale, float *rgb);

/* The painted material's picture (bake_report_paint.c): the simulation mesh at rest
 * coloured by each vertex's stiffness multiplier, written as dir/SW_BAKE_REPORT_PAINT_NAME;
 * nothing when ch is unpainted. */
#define SW_BAKE_REPORT_PAINT_NAME "painted_stiffness.png"
sinew_result sw_bake_report_paint(const char *dir, const sw_character *ch, sw_error *err);

#endif
