/* Correction error of a blob against full-space solutions (subspace_eval.h). */
#include "subspace_eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "instance.h"

sinew_result sw_eval_acc_init(sw_eval_acc *a, const sinew_blob *blob, const double *mass,
                              sw_error *err) {
    memset(a, 0, sizeof *a);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || !mass)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "bad evaluation arguments");
    a->mass = mass;
    a->rest = v->rest;
    a->nverts = v->nverts;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < v->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], v->rest[3 * i + k]);
            hi[k] = fmax(hi[k], v->rest[3 * i + k]);
        }
    a->diag = v->nverts > 0
                  ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                         (hi[2] - lo[2]) * (hi[2] - lo[2]))
                  : 0;
    double total_mass = 0;
    for (int32_t i = 0; i < v->nverts; ++i)
        total_mass += mass[i];
    a->den_floor = total_mass * (1e-9 * a->diag) * (1e-9 * a->diag);
    size_t n3 = (size_t)v->nverts * 3 * sizeof(double);
    a->xs = malloc(n3);
    a->xd = malloc(n3);
    a->cnt = malloc((size_t)v->nverts * sizeof(double));
    a->skin_bone = v->skin_bone;
    a->nbones = v->nbones;
    a->bone_num = calloc((size_t)v->nbones, sizeof(double));
    a->bone_den = calloc((size_t)v->nbones, sizeof(double));
    a->view = v;
    size_t s3 = (size_t)sw_blob_output_verts(v) * 3 * sizeof(double);
    a->sref = malloc(s3);
    a->sdqs = malloc(s3);
    if (!a->xs || !a->xd || !a->cnt || !a->bone_num || !a->bone_den || !a->sref || !a->sdqs) {
        sw_eval_acc_free(a);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    return SINEW_OK;
}

void sw_eval_acc_add(sw_eval_acc *a, const sinew_instance *inst, const double *xf) {
    sw_instance_full_positions(inst, a->xs, a->cnt);
    sw_instance_dqs_positions(inst, a->xd);
    double gap = sw_instance_copy_spread(inst, a->xs, a->cnt); /* cnt: scratch again */
    if (gap > a->seam_max) a->seam_max = gap;
    for (int32_t i = 0; i < a->nverts; ++i) {
        a->seam += a->mass[i] * a->cnt[i];
        double vn = 0, vd = 0;
        for (int k = 0; k < 3; ++k) {
            double e = a->xs[3 * i + k] - xf[3 * i + k], b = xf[3 * i + k] - a->xd[3 * i + k];
            double c = xf[3 * i + k] - a->rest[3 * i + k];
            vn += a->mass[i] * e * e;
            vd += a->mass[i] * b * b;
            a->l2n += e * e;
            a->l2d += c * c;
        }
        a->num += vn;
        a->den += vd;
        a->bone_num[a->skin_bone[4 * (int64_t)i]] += vn;
        a->bone_den[a->skin_bone[4 * (int64_t)i]] += vd;
    }
    const sw_blob_view *v = a->view;
    sw_output_from_full(v, xf, a->sref);
    sw_output_from_full(v, a->xd, a->sdqs);
    const double *y = sw_instance_surface(inst);
    for (int64_t i = 0; i < 3 * (int64_t)sw_blob_output_verts(v); ++i) {
        a->snum += (y[i] - a->sref[i]) * (y[i] - a->sref[i]);
        a->sden += (a->sref[i] - a->sdqs[i]) * (a->sref[i] - a->sdqs[i]);
    }
    a->frames++;
}

void sw_eval_acc_result(const sw_eval_acc *a, sw_eval_result *out) {
    memset(out, 0, sizeof *out);
    /* frames at rest: the reference and skinning agree to rounding, and a share of that
       is noise (the bare hand's rest frame read 423484) */
    int none = !(a->den > a->den_floor * (a->frames > 0 ? a->frames : 1));
    out->no_correction = none && a->frames > 0;
    out->correction_error = none ? 0 : sqrt(a->num / a->den);
    out->surface_error = none || !(a->sden > 0) ? 0 : sqrt(a->snum / a->sden);
    out->rel_l2 = a->l2d > 0 ? sqrt(a->l2n / a->l2d) : 0;
    out->frames = a->frames;
    out->seam = none ? 0 : sqrt(a->seam / a->den);
    out->seam_max = a->diag > 0 ? a->seam_max / a->diag : 0;
    for (int32_t b = 0; b < a->nbones && a->num > 0; ++b) { /* the largest shares, in order */
        if (!(a->bone_num[b] > 0)) continue;
        int k = out->nregions < SW_EVAL_REGIONS ? out->nregions++ : SW_EVAL_REGIONS;
        while (k > 0 && a->bone_num[b] > a->bone_num[out->region_bone[k - 1]]) {
            if (k < SW_EVAL_REGIONS) out->region_bone[k] = out->region_bone[k - 1];
            --k;
        }
        if (k < SW_EVAL_REGIONS) out->region_bone[k] = b;
    }
    for (int32_t r = 0; r < out->nregions; ++r) {
        out->region_err[r] = a->bone_num[out->region_bone[r]] / a->num;
        out->region_corr[r] = a->den > 0 ? a->bone_den[out->region_bone[r]] / a->den : 0;
    }
}

void sw_eval_acc_free(sw_eval_acc *a) {
    free(a->xs);
    free(a->cnt);
    free(a->xd);
    free(a->bone_num);
    free(a->bone_den);
    free(a->sref);
    free(a->sdqs);
    a->xs = a->cnt = a->xd = a->bone_num = a->bone_den = a->sref = a->sdqs = NULL;
}

sinew_result sw_eval_correction(const sinew_blob *blob, const double *mass, const double *T,
                                const double *x_full, int32_t npose, uint32_t max_newton,
                                sw_eval_result *out, sw_error *err) {
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = max_newton,
                         .self_contact = SINEW_SELF_CONTACT_POSE_SPACE};
    return sw_eval_correction_opts(blob, mass, T, x_full, npose, &o, out, err);
}

sinew_result sw_eval_correction_opts(const sinew_blob *blob, const double *mass, const double *T,
                                     const double *x_full, int32_t npose, const sw_eval_options *o,
                                     sw_eval_result *out, sw_error *err) {
    return sw_eval_correction_frames(blob, mass, T, x_full, npose, o, NULL, out, err);
}

sinew_result sw_eval_correction_frames(const sinew_blob *blob, const double *mass, const double *T,
                                       const double *x_full, int32_t npose,
                                       const sw_eval_options *o, double *frame_error,
                                       sw_eval_result *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || !mass || !o || (!T && npose) || (!x_full && npose > o->skip) || npose < 0 ||
        o->skip < 0 || !(o->dt > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "bad evaluation arguments");
    sinew_instance_def def = sinew_instance_def_default();
    def.mode = o->mode;
    def.max_newton_iters = o->max_newton;
    def.self_contact = o->self_contact;
    def.novel_contact = o->novel_contact;
    def.max_patch_vertices = o->patch_vertices;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    if (r == SINEW_OK && o->lod != SINEW_LOD_FULL) r = sinew_instance_set_lod(inst, o->lod);
    if (r != SINEW_OK) {
        sinew_instance_destroy(inst);
        return sw_error_set(err, r, "cannot create an instance: %s", sinew_result_string(r));
    }
    sw_eval_acc acc;
    if ((r = sw_eval_acc_init(&acc, blob, mass, err)) != SINEW_OK) {
        sinew_instance_destroy(inst);
        return r;
    }
    int32_t n = v->nverts, failed = 0;
    for (int32_t f = 0; f < npose; ++f) {
        const double *Tf = T + (size_t)f * 12 * v->nbones;
        double *fe = frame_error && f >= o->skip ? frame_error + (f - o->skip) : NULL;
        if (sw_instance_set_pose_d(inst, Tf) != SINEW_OK ||
            sinew_instance_step(inst, o->dt) != SINEW_OK) {
            failed++;
            if (fe) *fe = NAN;
            continue;
        }
        if (f < o->skip) continue;
        double num = acc.num, den = acc.den;
        sw_eval_acc_add(&acc, inst, x_full + (size_t)(f - o->skip) * 3 * n);
        /* the frame's own share, by the same formula; a frame with no correction to miss
           (the rest pose, its correction of rounding) counts 0 */
        if (fe) *fe = acc.den - den > acc.den_floor ? sqrt((acc.num - num) / (acc.den - den)) : 0.0;
        if (o->on_frame) o->on_frame(o->frame_ctx, f, inst, x_full + (size_t)(f - o->skip) * 3 * n);
    }
    sw_eval_acc_result(&acc, out);
    out->failed = failed;
    sw_eval_acc_free(&acc);
    sinew_instance_destroy(inst);
    return SINEW_OK;
}
