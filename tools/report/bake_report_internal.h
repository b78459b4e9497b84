/* The bake report's parts (bake_report.h), shared by its files: bake_report.c gathers the
 * figures and writes the JSON, bake_report_verdict.c judges the bake, bake_report_html.c
 * writes the page with bake_report_plots.c's SVG plots. */
#ifndef SW_BAKE_REPORT_INTERNAL_H
#define SW_BAKE_REPORT_INTERNAL_H

#include <cjson/cJSON.h>
#include <stdio.h>

#include "bake_report.h"

#define SHEET_NAME "heldout_sheet.png"
#define REPORT_BEYOND 32 /* joints listed beyond training, at most */
#define VERDICT_JOINTS 3 /* joints named in the verdict's sentence, at most */

/* One clip's frames in the report: the poses of `split` labelled `label`. */
typedef struct report_clip {
    char name[80];
    int heldout;
    int32_t n;
    int32_t *frame;
    double *error;
    int32_t *beyond; /* per frame: joints bent beyond training (sw_bake_pose_beyond) */
    int32_t nbeyond; /* frames with any */
} report_clip;

typedef enum { VERDICT_NOT_MEASURED = -1, VERDICT_MISS = 0, VERDICT_PASS = 1 } verdict_status;

/* The verdict: the held-out error against the target, in plain words, and on a miss what
 * motion to add. */
typedef struct report_verdict {
    verdict_status status;
    double target;
    int target_given; /* 1: the caller's target; 0: SW_BAKE_REPORT_TARGET */
    char headline[320];
    char advice[1600]; /* "" when there is nothing to add */
    /* on a miss, the joints to train further: the joints bent beyond training (the
       report's beyond list) when there are any, else the bones whose flesh holds the most
       held-out error */
    int add_beyond; /* 1: add_bone lists joints beyond training; 0: bones with the error */
    int32_t nadd;
    int32_t add_bone[REPORT_BEYOND];
    double add_share[REPORT_BEYOND]; /* the error's share of a bone (add_beyond 0) */
} report_verdict;

typedef struct report {
    report_clip *clips;
    int32_t nclips;
    int32_t sweep_poses;
    double sweep_mean;
    sw_joint_reach beyond[REPORT_BEYOND]; /* sw_bake_beyond_training's, largest first */
    int32_t nbeyond, nbeyond_all;
    int sheet; /* the contact sheet was rendered (sheet_info holds its figures) */
    sw_bake_report_sheet_info sheet_info;
    report_verdict verdict;
} report;

#define REPORT_MAX_STAGES 32 /* room for the bake's stages */

/* The bake's stages as the report shows them: their names and seconds into names and
 * seconds (room for REPORT_MAX_STAGES); returns how many (bake_report.c). */
int32_t report_stage_times(const sw_bake_result *res, const char **names, double *seconds);

/* Whether the held-out poses are random combined poses (no clip to hold out). */
int report_heldout_random(const sw_bake_result *res);

/* A bone's name in the file, or "bone N" when the file names none. */
void report_bone_name(const sw_character *ch, int32_t bone, char *buf, size_t n);

/* The verdict of the bake (bake_report_verdict.c), as JSON and as the page's first part. */
void report_verdict_make(const sw_bake_report_input *in, report *r);
cJSON *report_verdict_json(const sw_bake_report_input *in, const report *r);
void html_verdict(FILE *f, const sw_bake_report_input *in, const report *r);

/* The page (bake_report_html.c); 0 when it cannot be written. */
int report_write_html(const char *path, const sw_bake_report_input *in, const report *r);

/* s with &, <, >, " escaped for HTML text and attributes (bake_report_plots.c). */
void html_text(FILE *f, const char *s);

/* A plot's frame: its title, what its axes measure (with units) and a dashed target line
 * at y = target (NaN: none). */
typedef struct plot_axes {
    const char *title, *xname, *yname;
    double ymax, target;
    const char *target_label;
} plot_axes;

/* A line plot of y over x (n points; NaN points skipped), y from 0 to ax->ymax; a red tick
 * under every point whose mark is nonzero (NULL: none). */
void svg_line(FILE *f, const plot_axes *ax, const int32_t *x, const double *y, const int32_t *mark,
              int32_t n, const char *colour);

/* A bar chart of v[0..n) labelled by labels (NULL: by index), each bar's value above it. */
void svg_bars(FILE *f, const plot_axes *ax, const double *v, int32_t n, const char *const *labels,
              const char *colour);

/* A horizontal bar chart: one row a bar, its label left of it and its value (with unit)
 * right of it; suits long labels (stage names) that would overlap under vertical bars. */
void svg_hbars(FILE *f, const char *title, const double *v, int32_t n, const char *const *labels,
               const char *const *tips, const char *unit, const char *colour);

/* The contact sheet's colour legend: the ramp from 0 to scale (length units), ticks also as
 * a share of size. */
void html_ramp_legend(FILE *f, double scale, double size);

#endif
