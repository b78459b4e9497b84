/* sinew-bench --novel: self-contact nobody trained (sinew_instance_def.novel_contact) on
 * the clip the reference solved, in three configurations of the runtime: pose-space
 * pairs alone (the default), with the novel contact applied through the subspace, and
 * with it seeding condensation patches (a budget of a tenth of the vertices). For each:
 * the correction error over the clip (sw_eval_correction_frames), the deepest
 * self-penetration of its positions (every tet vertex, mapped, by the reference's own
 * detector, selfcontact.h) and the step's cost; and the reference's deepest
 * self-penetration over the same frames. */
#ifndef SW_NOVEL_BENCH_H
#define SW_NOVEL_BENCH_H

#include <stdio.h>

#include "bake.h"

#define SW_NOVEL_CONFIGS 3

typedef struct sw_novel_bench {
    int frames;
    double pen_self_full;                    /* the reference's deepest self-penetration */
    double pen_self[SW_NOVEL_CONFIGS];       /* the runtime's, per configuration */
    double err[SW_NOVEL_CONFIGS];            /* correction error over the clip */
    double step_ms[SW_NOVEL_CONFIGS];        /* mean step (sw_step_ms) */
    double novel_ms[SW_NOVEL_CONFIGS];       /* mean novel detection */
    double novel_contacts[SW_NOVEL_CONFIGS]; /* mean a step */
    double patch_max[SW_NOVEL_CONFIGS];      /* most patch vertices in a step */
    double cluster_pairs[SW_NOVEL_CONFIGS];  /* mean cluster pairs the broad phase passed */
    double tests[SW_NOVEL_CONFIGS];          /* mean self-contact tests a step */
    double size;                             /* rest diagonal */
    long failed;
} sw_novel_bench;

/* Runs the three configurations over the first kf frames of T (12 nbones each) against
 * full_x (3 nverts each) on the character's tet mesh. */
sinew_result sw_novel_bench_run(const sinew_blob *blob, const sw_character *ch, const double *T,
                                const double *full_x, int kf, sw_novel_bench *out, sw_error *err);

void sw_novel_bench_print(const sw_novel_bench *b, FILE *f, int json);

#endif
