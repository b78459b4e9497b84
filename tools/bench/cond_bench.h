/* sinew-bench --world: the condensed runtime (subspace condensation, issue 12) on the
 * world scene, measured against the reference's frames of the same run. */
#ifndef SW_COND_BENCH_H
#define SW_COND_BENCH_H

#include "sinew/sinew.h"
#include "sw_error.h"
#include "world_scene.h"

#define SW_COND_MAX_RHO 8

typedef struct sw_cond_bench_params {
    double rho[SW_COND_MAX_RHO]; /* patch radii in units of the rest diagonal */
    int nrho;                    /* 0: the default radius alone */
    uint32_t budget;             /* max_patch_vertices (0: a quarter of the vertices) */
    const char *out_dir;         /* NULL, or where the first radius's frames go as OBJ files
                                    (DIR/condensed/frame_NNNN.obj), patch vertices coloured */
} sw_cond_bench_params;

typedef struct sw_cond_bench {
    double rho;             /* the radius used (rest-diagonal units) */
    uint32_t budget;        /* the budget used */
    double err_world_cond;  /* correction error over the reference's contact frames */
    double speedup_mean;    /* mean over frames of reference ms / condensed ms */
    double speedup_worst;   /* the lowest per-frame ratio */
    double patch_frac_mean; /* share of the vertices in full space, mean over frames */
    double patch_frac_max;
    double ms_median, ms_max, p100_over_p50; /* condensed frame times */
    int truncated_frames;                    /* frames the budget cut */
    double pop_max; /* largest surface jump at a patch's activation or release over the
                       reference's largest jump at that frame */
    uint32_t pcg_iters_max;
    /* over the frames with a patch: mean condensed step time and patch size (the step's
       cost at a patch size, compared across mesh resolutions) */
    double patch_ms_mean, patch_verts_mean, patch_tets_mean;
    int failed;
} sw_cond_bench;

/* Steps a condensed instance of blob with patch radius rho (0: the default) and budget
 * cp->budget over the scene's nf frames (poses T), compares each frame with the
 * reference's x_full (its frame times ref_ms, contact frames touch, masses mass for the
 * error's weights). */
sinew_result sw_cond_bench_run(const sinew_blob *blob, sw_world_scene *ws, const double *T, int nf,
                               const double *x_full, const double *ref_ms,
                               const unsigned char *touch, const double *mass,
                               const sw_cond_bench_params *cp, double rho, sw_cond_bench *out,
                               sw_error *err);

#endif
