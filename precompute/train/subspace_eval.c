/* Correction error of a blob against full-space solutions (subspace_eval.h). */
#include "subspace_eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "instance.h"

sinew_result sw_eval_correction(const sinew_blob *blob, const double *mass, const double *T,
                                const double *x_full, int32_t npose, uint32_t max_newton,
                                sw_eval_result *out, sw_error *err) {
    sw_eval_options o = {SINEW_STEP_QUASISTATIC, 1.0f / 30, max_newton, 0};
    return sw_eval_correction_opts(blob, mass, T, x_full, npose, &o, out, err);
}

sinew_result sw_eval_correction_opts(const sinew_blob *blob, const double *mass, const double *T,
                                     const double *x_full, int32_t npose, const sw_eval_options *o,
                                     sw_eval_result *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || !mass || !o || (!T && npose) || (!x_full && npose > o->skip) || npose < 0 ||
        o->skip < 0 || !(o->dt > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "bad evaluation arguments");
    sinew_instance_def def = sinew_instance_def_default();
    def.mode = o->mode;
    def.max_newton_iters = o->max_newton;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    if (r != SINEW_OK)
        return sw_error_set(err, r, "cannot create an instance: %s", sinew_result_string(r));
    int32_t n = v->nverts;
    double *xs = malloc((size_t)n * 3 * sizeof(double)), *cnt = malloc((size_t)n * sizeof(double));
    double *xd = malloc((size_t)n * 3 * sizeof(double));
    if (!xs || !cnt || !xd) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    double num = 0, den = 0, l2n = 0, l2d = 0;
    for (int32_t f = 0; f < npose; ++f) {
        const double *Tf = T + (size_t)f * 12 * v->nbones;
        if (sw_instance_set_pose_d(inst, Tf) != SINEW_OK ||
            sinew_instance_step(inst, o->dt) != SINEW_OK) {
            out->failed++;
            continue;
        }
        if (f < o->skip) continue;
        const double *xf = x_full + (size_t)(f - o->skip) * 3 * n;
        sw_instance_full_positions(inst, xs, cnt);
        sw_instance_dqs_positions(inst, xd);
        for (int32_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) {
                double a = xs[3 * i + k] - xf[3 * i + k], b = xf[3 * i + k] - xd[3 * i + k];
                double c = xf[3 * i + k] - v->rest[3 * i + k];
                num += mass[i] * a * a;
                den += mass[i] * b * b;
                l2n += a * a;
                l2d += c * c;
            }
        out->frames++;
    }
    out->correction_error = den > 0 ? sqrt(num / den) : 0;
    out->rel_l2 = l2d > 0 ? sqrt(l2n / l2d) : 0;
    r = SINEW_OK;
done:
    free(xs);
    free(cnt);
    free(xd);

    sinew_instance_destroy(inst);
    return r;
}
