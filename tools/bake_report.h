/* The bake report (issue 14, sinew-bake --report DIR): one self-contained HTML page a
 * technical artist opens (inline SVG plots: the correction error of every clip frame,
 * training and held-out; the basis rank and energy and the cubature size of every
 * domain; the stage times) and the same figures as JSON (libcjson), plus contact sheets
 * of held-out frames (runtime, full-space reference and plain skinning side by side)
 * as PNG files the page shows.
 *
 *   DIR/report.html   the page (references heldout_sheet.png when it was rendered)
 *   DIR/report.json   {"sinew_bake_report": 1, ...}: the figures (schema in bake_report.c)
 *   DIR/heldout_sheet.png  the contact sheet */
#ifndef SW_BAKE_REPORT_H
#define SW_BAKE_REPORT_H

#include "bake.h"
#include "bake_adaptive.h"
#include "sinew/sinew.h"
#include "sw_mesh.h"

#define SW_BAKE_REPORT_VERSION 1

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
    int contact_sheet; /* render DIR/heldout_sheet.png (Embree; a few seconds) */
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
} sw_bake_report_input;

/* Creates DIR (and its parents) and writes the report there. Errors: IO (cannot create
 * or write), OUT_OF_MEMORY, and the renderer's for the contact sheet. */
sinew_result sw_bake_report_write(const char *dir, const sw_bake_report_input *in, sw_error *err);

/* The contact sheet of up to `frames` held-out poses of res, one row each: the runtime
 * (a quasistatic instance of blob stepped through the held-out poses), the full-space
 * reference and plain dual-quaternion skinning, the simulation mesh's boundary each
 * (bake_report_sheet.c). */
sinew_result sw_bake_report_sheet(const char *png_path, const sw_character *ch,
                                  const sw_bake_result *res, const sinew_blob *blob, int32_t frames,
                                  sw_error *err);

#endif
