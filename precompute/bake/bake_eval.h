/* A bake's figures: its blob measured on its training and held-out poses against the
 * full-space reference (bake_eval.c), and how well that reference is defined
 * (bake_spread.c). The stages that tune the blob (bake_springs.c, bake_equilibrium.c)
 * measure with these too. */
#ifndef SW_BAKE_EVAL_H
#define SW_BAKE_EVAL_H

#include "bake_params.h"

/* The one definition of a bake's training and held-out error (sinew-bake and
 * sinew-bench report these): sw_eval_correction of `blob` over res's training poses (the
 * clip's training frames, then the return path when baked, then every joint sweep, in
 * that order, one quasistatic instance stepped through them all) and, separately, over
 * its held-out poses, the instance in self-contact mode `sc` (the pose-space mode is the
 * bake's figure) and otherwise as an engine creates it: SW_BAKE_EVAL_NEWTON is the
 * instance's default Newton cap (0: DESIGN.md's 5 a frame), so the bake reports what the
 * shipped step does, not what a step run to convergence would (the two differ little:
 * docs/notes). */
#define SW_BAKE_EVAL_NEWTON 0
sinew_result sw_bake_errors(const sinew_blob *blob, const sw_bake_result *res,
                            sinew_self_contact sc, sw_eval_result *train, sw_eval_result *heldout,
                            sw_error *err);

/* The self-contact modes an instance can take (sinew_instance_def.self_contact), indexed
 * by sinew_self_contact's value: their names (the tools' flags; NULL after the last, for
 * sw_tool_choice) and JSON keys. */
#define SW_BAKE_MODES 3
extern const char *const sw_self_contact_names[SW_BAKE_MODES + 1];
extern const char *const sw_self_contact_keys[SW_BAKE_MODES];

/* The held-out error of `blob` in each self-contact mode, measured as sw_bake_errors
 * measures it, into err_mode (indexed by the mode's value): `measured_err` for the mode `measured`
 * (already measured), NaN for the pose-pairs mode of a blob without per-pair sections and for a
 * mode whose steps failed. Which mode suits the character's motion: on clips like its training
 * clips the pose-space mode, on combinations of joints no training pose holds the
 * detecting modes (docs/notes/generalisation.md "The Fox's Run is beyond its training"). */
sinew_result sw_bake_mode_errors(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact measured, double measured_err,
                                 double err_mode[SW_BAKE_MODES], sw_error *err);

/* The held-out half of sw_bake_errors_frames, on_frame (NULL: none) called with ctx after
 * each held-out pose is measured (sw_eval_options; `pose` counts the path's leading
 * training poses too: sw_bake_heldout_path). */
sinew_result sw_bake_heldout_error(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_frame_fn on_frame, void *ctx,
                                   sw_eval_result *heldout, double *heldout_frames, sw_error *err);

/* The held-out error of `blob` at level of detail `lod` (pose-space self-contact), its
 * surface_error the figure the levels share (bake_lod.c). */
sinew_result sw_bake_heldout_level_error(const sinew_blob *blob, const sw_bake_result *res,
                                         sinew_lod lod, sw_eval_result *heldout, sw_error *err);

/* How well the held-out references are defined (bake_spread.c; sinew-bake
 * --reference-spread): at every `every`-th held-out pose (every - 1, 2 every - 1, ...)
 * that the blob steps along the held-out path in self-contact mode sc, three full-space
 * solves with the reference's parameters at that pose, started from plain skinning, from
 * the reference and from the runtime's state. Each is measured as the correction error
 * measures the runtime (|x - x_ref|_M over |x_ref - x_dqs|_M, summed over the poses before
 * the ratio): `from_skin` is how far a reference that had not walked the path lands from
 * the bake's, `from_reference` how far a fresh solve moves the reference itself (its own
 * precision: the contact set starts afresh, Newton's tolerance is relative to its start),
 * `polished` how far the full-space equilibrium nearest the runtime's state is from the
 * reference (0: the runtime is off the one equilibrium; near `runtime`: it sits by
 * another), `polish_move` how far that solve moved the runtime's state; per pose the same
 * shares of that pose alone. */
typedef struct sw_bake_spread_pose {
    int32_t heldout;                                     /* the held-out pose's index */
    double runtime, from_skin, from_reference, polished; /* its own shares */
    double correction; /* |x_ref - x_dqs|_M: the shares' denominator (near 0: rounding) */
} sw_bake_spread_pose;
typedef struct sw_bake_spread {
    int32_t poses;         /* held-out poses measured */
    double runtime;        /* the runtime's correction error at those poses */
    double from_skin;      /* the full-space solve from plain skinning, against the reference */
    double from_reference; /* the solve from the reference, against it */
    double polished;       /* the full-space solve from the runtime's state, against it */
    double polish_move;    /* that solve against the runtime's state */
    int32_t unconverged;   /* solves that ended unconverged (kept, as the reference keeps them) */
    int32_t failed;        /* poses left out: a step or a solve that did not stay finite */
    sw_bake_spread_pose *per_pose; /* `poses` of them, in order (sw_bake_spread_free) */
} sw_bake_spread;
sinew_result sw_bake_reference_spread(const sw_character *ch, const sw_bake_params *p,
                                      const sinew_blob *blob, const sw_bake_result *res,
                                      sinew_self_contact sc, int32_t every, sw_bake_spread *out,
                                      sw_error *err);
void sw_bake_spread_free(sw_bake_spread *s);

/* The training half of sw_bake_errors_frames (train_frames: res->ntrain doubles or NULL). */
sinew_result sw_bake_train_error(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact sc, sw_eval_result *train, double *train_frames,
                                 sw_error *err);

/* The result's view written and loaded as a blob (its bytes in *mem, the caller's to
 * free after sinew_blob_destroy). */
sinew_result sw_bake_result_blob(const sw_bake_result *res, void **mem, sinew_blob **blob,
                                 sw_error *err);

/* The held-out poses on the path the reference solved them on (malloc'd, 12 nbones
 * each): the first *pre = res->heldout_after training poses, then the held-out ones,
 * *n in all. sw_bake_errors, the error gap and the report's contact sheet step one
 * instance along it and measure the poses after the first *pre. NULL: out of memory. */
double *sw_bake_heldout_path(const sw_bake_result *res, int32_t nbones, int32_t *pre, int32_t *n);

/* sw_bake_errors, also writing every pose's own correction error (res->ntrain and
 * res->nheldout doubles; sw_eval_correction_frames) when the arrays are not NULL. */
sinew_result sw_bake_errors_frames(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_result *train,
                                   sw_eval_result *heldout, double *train_frames,
                                   double *heldout_frames, sw_error *err);
#endif
