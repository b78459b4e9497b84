/* A bake's figures (bake_eval.h): its blob stepped along the training and held-out poses
 * and measured against the full-space reference (sw_eval_correction_frames). */
#include "bake_eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "blob_write.h"

sinew_result sw_bake_errors(const sinew_blob *blob, const sw_bake_result *res,
                            sinew_self_contact sc, sw_eval_result *train, sw_eval_result *heldout,
                            sw_error *err) {
    return sw_bake_errors_frames(blob, res, sc, train, heldout, NULL, NULL, err);
}

double *sw_bake_heldout_path(const sw_bake_result *res, int32_t nbones, int32_t *pre, int32_t *n) {
    *pre = res->heldout_after > 0 && res->heldout_after <= res->ntrain ? res->heldout_after : 0;
    *n = *pre + res->nheldout;
    size_t pt = (size_t)12 * nbones * sizeof(double);
    double *T = malloc((size_t)*n * pt + 1);
    if (T) {
        memcpy(T, res->train_T, (size_t)*pre * pt);
        memcpy((char *)T + (size_t)*pre * pt, res->heldout_T, (size_t)res->nheldout * pt);
    }
    return T;
}

sinew_result sw_bake_train_error(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact sc, sw_eval_result *train, double *train_frames,
                                 sw_error *err) {
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = sc};
    return sw_eval_correction_frames(blob, res->mass, res->train_T, res->train_x, res->ntrain, &o,
                                     train_frames, train, err);
}

/* The held-out path stepped with options o (its skip and frames filled here). */
static sinew_result heldout_path(const sinew_blob *blob, const sw_bake_result *res,
                                 sw_eval_options *o, sw_eval_result *heldout,
                                 double *heldout_frames, sw_error *err) {
    memset(heldout, 0, sizeof *heldout);
    int32_t pre, n;
    double *T = sw_bake_heldout_path(res, sw_blob_get_view(blob)->nbones, &pre, &n);
    if (!T) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    o->skip = pre;
    sinew_result r = sw_eval_correction_frames(blob, res->mass, T, res->heldout_x, n, o,
                                               heldout_frames, heldout, err);
    free(T);
    return r;
}

sinew_result sw_bake_heldout_error(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_frame_fn on_frame, void *ctx,
                                   sw_eval_result *heldout, double *heldout_frames, sw_error *err) {
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = sc,
                         .on_frame = on_frame,
                         .frame_ctx = ctx};
    return heldout_path(blob, res, &o, heldout, heldout_frames, err);
}

sinew_result sw_bake_heldout_level_error(const sinew_blob *blob, const sw_bake_result *res,
                                         sinew_lod lod, sw_eval_result *heldout, sw_error *err) {
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = SINEW_SELF_CONTACT_POSE_SPACE,
                         .lod = lod};
    return heldout_path(blob, res, &o, heldout, NULL, err);
}

sinew_result sw_bake_errors_frames(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_result *train,
                                   sw_eval_result *heldout, double *train_frames,
                                   double *heldout_frames, sw_error *err) {
    memset(train, 0, sizeof *train);
    memset(heldout, 0, sizeof *heldout);
    sinew_result r = sw_bake_train_error(blob, res, sc, train, train_frames, err);
    if (r != SINEW_OK) return r;
    return sw_bake_heldout_error(blob, res, sc, NULL, NULL, heldout, heldout_frames, err);
}

const char *const sw_self_contact_names[SW_BAKE_MODES + 1] = {"pose-space", "exhaustive",
                                                              "pose-pairs", NULL};
const char *const sw_self_contact_keys[SW_BAKE_MODES] = {"pose_space", "exhaustive", "pose_pairs"};

sinew_result sw_bake_mode_errors(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact measured, double measured_err,
                                 double err_mode[SW_BAKE_MODES], sw_error *err) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    for (int k = 0; k < SW_BAKE_MODES; ++k) {
        const sinew_self_contact mode = (sinew_self_contact)k;
        err_mode[k] = NAN;
        if (mode == measured) {
            err_mode[k] = measured_err;
            continue;
        }
        if (mode == SINEW_SELF_CONTACT_POSE_PAIRS && (!v || v->npair_groups == 0))
            continue; /* no per-pair sections: the mode is not available */
        sw_eval_result h;
        sinew_result r = sw_bake_heldout_error(blob, res, mode, NULL, NULL, &h, NULL, err);
        if (r != SINEW_OK) return r;
        if (h.failed == 0 && h.frames > 0) err_mode[k] = h.correction_error;
    }
    return SINEW_OK;
}

sinew_result sw_bake_result_blob(const sw_bake_result *res, void **mem, sinew_blob **blob,
                                 sw_error *err) {
    size_t size = 0;
    *blob = NULL;
    *mem = NULL;
    sinew_result r = sw_blob_write_memory(&res->view, mem, &size, err);
    if (r != SINEW_OK) return r;
    sinew_blob_def d = sinew_blob_def_default();
    d.data = *mem;
    d.data_size = size;
    if ((r = sinew_blob_load(&d, blob)) != SINEW_OK)
        return sw_error_set(err, r, "the bake's blob does not load");
    return SINEW_OK;
}
