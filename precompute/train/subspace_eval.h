/* Accuracy of a baked subspace against the full-space reference (DESIGN.md §7):
 * the correction error  |x_sub - x_full|_M / |x_full - x_dqs|_M, the share of the
 * physics correction the subspace misses (0 exact, 1 no better than skinning), summed
 * over frames before the ratio (so frames with almost no correction do not dominate). */
#ifndef SW_SUBSPACE_EVAL_H
#define SW_SUBSPACE_EVAL_H

#include "sinew/sinew.h"
#include "sw_error.h"

/* Regions of the error the result names: the bones whose vertices miss the most. */
#define SW_EVAL_REGIONS 4

typedef struct sw_eval_result {
    double correction_error; /* the ratio above */
    double rel_l2;           /* |x_sub - x_full| / |x_full - rest| (thesis §4.5 style) */
    int32_t frames;
    int32_t failed; /* steps that did not return SINEW_OK */
    /* where the error is: the vertices split by their strongest skin bone, the
       SW_EVAL_REGIONS bones (nregions of them) whose vertices hold the largest share of
       the squared error |x_sub - x_full|_M^2 (region_err, largest first), with their
       share of the squared correction |x_full - x_dqs|_M^2 (region_corr). A region
       with a far larger share of the error than of the correction is where the subspace
       fails; a share of both near 1 is a region that holds all the physics (e.g. free
       flesh too loosely held by its bone) */
    int32_t nregions;
    int32_t region_bone[SW_EVAL_REGIONS];
    double region_err[SW_EVAL_REGIONS], region_corr[SW_EVAL_REGIONS];
    /* the seams the interface springs leave (sw_instance_copy_spread): the domains'
       copies of a vertex apart from their mean, |x_copy - x_mean|_M over the correction
       |x_full - x_dqs|_M (the correction error's denominator), and the largest
       |x_copy - x_mean| of any frame over the rest bounding-box diagonal */
    double seam, seam_max;
    /* every frame's correction is of rounding (|x_full - x_dqs|_M at most 1e-9 of the rest
       diagonal, the total mass's worth: frames at rest): a share of nothing, so
       correction_error and seam are 0, and a caller says the error is not defined */
    int no_correction;
    /* the same ratio on the output surface the host reads (each output vertex's weight 1,
       the reference and skinning carried onto it as the runtime carries its own state,
       sw_output_from_full): the one figure every level of detail has (sinew_lod) */
    double surface_error;
} sw_eval_result;

/* The sums behind the correction error, one frame at a time, for a caller that steps
 * its own instance (sinew-bench --dynamic: a dynamic instance with a pre-roll); the
 * formula is this one, sw_eval_correction adds its frames through it too. */
typedef struct sw_eval_acc {
    const double *mass, *rest; /* nverts vertex masses, the blob's rest positions */
    int32_t nverts;
    double num, den, l2n, l2d;
    double seam, seam_max, diag; /* sum of m |x_copy - x_mean|^2, largest gap, rest diagonal */
    double den_floor;            /* a frame's den at most this is rounding (sw_eval_result) */
    int32_t frames;
    double *xs, *cnt, *xd;    /* scratch: subspace, copy counts, DQS (3 nverts each) */
    const int32_t *skin_bone; /* the blob's 4 influences a vertex, strongest first */
    int32_t nbones;
    double *bone_num, *bone_den; /* num and den by the vertices' strongest bone */
    const void *view;            /* the blob's sw_blob_view */
    double snum, sden;           /* the output surface's num and den (surface_error) */
    double *sref, *sdqs;         /* scratch: the reference's and skinning's surfaces */
} sw_eval_acc;

sinew_result sw_eval_acc_init(sw_eval_acc *a, const sinew_blob *blob, const double *mass,
                              sw_error *err);
/* Adds the frame of the instance's last step (its pose and state) against x_full
 * (3 nverts). O(N): evaluation only. */
void sw_eval_acc_add(sw_eval_acc *a, const sinew_instance *inst, const double *x_full);
/* correction_error, rel_l2 and frames of the frames added so far (failed is 0). */
void sw_eval_acc_result(const sw_eval_acc *a, sw_eval_result *out);
void sw_eval_acc_free(sw_eval_acc *a);

/* Steps a fresh quasistatic instance of `blob` through npose poses (12 doubles per bone
 * each) in order with at most max_newton iterations a step, comparing every frame with
 * x_full (3 nverts per pose) under vertex masses `mass` (nverts). */
sinew_result sw_eval_correction(const sinew_blob *blob, const double *mass, const double *T,
                                const double *x_full, int32_t npose, uint32_t max_newton,
                                sw_eval_result *out, sw_error *err);

/* Called after each compared pose is added: `pose` its index on the path (0 .. npose),
 * `x_full` its reference, `inst` the instance that has just stepped it (a measurement
 * beside the error: sw_bake_reference_spread). */
typedef void (*sw_eval_frame_fn)(void *ctx, int32_t pose, const sinew_instance *inst,
                                 const double *x_full);

/* How sw_eval_correction_opts steps: the instance's mode, the step's dt, Newton's
 * iterations a step, `skip` leading poses stepped but not compared (a dynamic path's
 * lead-in: its held-out frames depend on the frames before them), the instance's
 * self-contact mode (0: pose-space, the default), novel contact and patch budget (0: the
 * defaults), and an optional per-pose callback
 * (NULL: none). */
typedef struct sw_eval_options {
    sinew_step_mode mode;
    float dt;
    uint32_t max_newton;
    int32_t skip;
    sinew_self_contact self_contact;
    uint32_t novel_contact;  /* sinew_instance_def.novel_contact (0: off) */
    uint32_t patch_vertices; /* sinew_instance_def.max_patch_vertices (0: no patches) */
    sinew_lod lod;           /* the level of detail every step runs (0: full) */
    sw_eval_frame_fn on_frame;
    void *frame_ctx;
} sw_eval_options;

/* As sw_eval_correction with options: steps through all npose poses and compares the
 * last npose - skip of them with x_full (3 nverts per compared pose). sw_eval_correction
 * is {quasistatic, 1/30 s, max_newton, 0}. */
sinew_result sw_eval_correction_opts(const sinew_blob *blob, const double *mass, const double *T,
                                     const double *x_full, int32_t npose, const sw_eval_options *o,
                                     sw_eval_result *out, sw_error *err);

/* As sw_eval_correction_opts, also writing each compared pose's own correction error
 * (the formula over that frame alone; 0 when the frame has no correction, NaN for a
 * failed step) to frame_error[0 .. npose - skip) when it is not NULL. */
sinew_result sw_eval_correction_frames(const sinew_blob *blob, const double *mass, const double *T,
                                       const double *x_full, int32_t npose,
                                       const sw_eval_options *o, double *frame_error,
                                       sw_eval_result *out, sw_error *err);
#endif
