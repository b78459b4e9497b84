#include "cubature.h"

#include <stddef.h>

#include "blob_load.h"
#include "fem_corot.h"

double sw_cubature_eval(sw_reduced *m, const double *q, int want_grad, int want_hess) {
    const sw_blob_view *v = m->v;
    double E = 0;
    uint32_t project = want_hess == SW_CUB_HESSIAN_EXACT ? 0u : SW_COROT_PROJECT_PSD;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank, o = D->q_offset;
        const double *qd = q + o;
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c) {
            double x[12], f[12], wm[9], gm[108], h[SW_BLOB_MAX_RANK];
            for (int j = 0; j < 4; ++j)
                sw_reduced_position(m, D, v->cub_tets[4 * c + j], m->cub_act[4 * c + j], qd,
                                    x + 3 * j, want_grad ? m->Je + 3 * j * r : NULL);
            double w = v->cub_weight[c];
            E += w * sw_corot_eval_modes(x, v->cub_dminv + 9 * c, v->cub_vol[c], v->mu, v->lambda,
                                         want_grad ? f : NULL, want_hess ? wm : NULL, gm,
                                         m->svd_V + 9 * (int64_t)c, project);
            if (!want_grad) continue;
            for (int32_t j = 0; j < r; ++j) {
                double acc = 0;
                for (int row = 0; row < 12; ++row)
                    acc += m->Je[row * r + j] * f[row];
                m->g[o + j] -= w * acc;
            }
            if (!want_hess) continue;
            /* eq. 2.12 through the element's modes: J^T K J = sum_k w_k (J^T g_k)(J^T g_k)^T */
            for (int k = 0; k < 9; ++k) {
                if (wm[k] == 0.0) continue;
                const double *gk = gm + 12 * k;
                for (int32_t j = 0; j < r; ++j) {
                    double acc = 0;
                    for (int row = 0; row < 12; ++row)
                        acc += m->Je[row * r + j] * gk[row];
                    h[j] = acc;
                }
                double wk = w * wm[k];
                for (int32_t i = 0; i < r; ++i) {
                    double *Hi = m->H + (int64_t)(o + i) * m->R + o, hi = wk * h[i];
                    for (int32_t j = i; j < r; ++j)
                        Hi[j] += hi * h[j];
                }
            }
        }
    }
    /* the domain blocks were filled in their upper triangle: mirror */
    if (want_hess)
        for (int32_t k = 0; k < v->ndomains; ++k) {
            const sw_blob_domain *D = &v->domains[k];
            int32_t o = D->q_offset;
            for (int32_t i = 0; i < D->rank; ++i)
                for (int32_t j = i + 1; j < D->rank; ++j)
                    m->H[(int64_t)(o + j) * m->R + o + i] = m->H[(int64_t)(o + i) * m->R + o + j];
        }
    return E;
}
