/* The galerkin stage: reads rig, domains, poses, basis and the view with its springs;
 * writes the result's *_galerkin_error. Why the runtime misses more than the basis's
 * projection: The step finds the reduced energy's minimum; for the linearised model,
 * rest stiffness K in the skinned frames and the interface springs S at the blob's
 * stiffness k, that minimum for a reference displacement d is
 *   (blockdiag(U_d^T K_d U_d) + k S) q = (U_d^T K_d d_d)_d,
 * the reference projected in the energy norm, with the domains coupled at their
 * interfaces (thesis eqs. 2.11 and 4.20, linearised). Its error, measured as the
 * projection error is (each domain's copies against the snapshot, relative), shows how
 * much of the runtime's error the span and the springs already decide, before the
 * cubature, the contact and the nonlinearity (docs/notes/generalisation.md, The Galerkin
 * projection). */
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"

/* The un-skinned snapshots of n poses (T: 12 nb each, x: 3 nv each) into D (n x 3 nv). */
static int unskin_all(const sw_bake_state *s, const double *T, const double *x, int32_t n,
                      double *D) {
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    double *R = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->rig.nv * 3 * sizeof(double));
    for (int32_t j = 0; R && t && j < n; ++j)
        sw_bake_unskin(s, T + (size_t)j * 12 * s->rig.nb, x + (size_t)j * n3, R, t,
                       D + (size_t)j * n3);
    int ok = R && t;
    free(R);
    free(t);
    return ok;
}

sinew_result sw_bake_galerkin(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    int32_t Rt = s->basis.rank_total, nt = 0, P;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        nt += s->poses.train[i].npose;
    P = nt + s->poses.heldout.npose;
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    double *D = malloc((size_t)P * n3 * sizeof(double) + 1),
           *H = malloc((size_t)Rt * Rt * sizeof(double)),
           *Bq = calloc((size_t)Rt * P + 1, sizeof(double));
    double *Dd = NULL, *Ut = NULL, *G = NULL;
    double num[2] = {0, 0}, den[2] = {0, 0};
    int ok = D && H && Bq;
    for (int32_t i = 0, at = 0; ok && i < s->poses.ntrain_seq; at += s->poses.train[i].npose, ++i)
        ok = unskin_all(s, s->poses.train[i].T, s->poses.train[i].x, s->poses.train[i].npose,
                        D + (size_t)at * n3);
    ok = ok && unskin_all(s, s->poses.heldout.T, s->poses.heldout.x, s->poses.heldout.npose,
                          D + (size_t)nt * n3);
    for (int64_t i = 0; ok && i < (int64_t)Rt * Rt; ++i)
        H[i] = out->spring_k * s->reduce.spring_unit[i];
    /* per domain: U^T K U into H's diagonal block, U^T K d of every pose into Bq */
    for (int32_t dm = 0, off = 0; ok && dm < s->domains.nd; off += s->basis.rank[dm], ++dm) {
        int32_t base = s->domains.dom_vert_ptr[dm], n = s->domains.dom_vert_ptr[dm + 1] - base,
                r = s->basis.rank[dm];
        int64_t m = 3 * (int64_t)n;
        free(Dd);
        free(Ut);
        free(G);
        Dd = malloc((size_t)P * m * sizeof(double) + 1);
        Ut = malloc((size_t)r * m * sizeof(double) + 1);
        G = malloc((size_t)r * (r > P ? r : P) * sizeof(double) + 1);
        if (!(ok = Dd && Ut && G)) break;
        for (int32_t a = 0; a < P; ++a)
            for (int32_t j = 0; j < n; ++j)
                memcpy(Dd + (size_t)a * m + 3 * j,
                       D + (size_t)a * n3 + 3 * s->domains.dom_verts[base + j], 3 * sizeof(double));
        for (int32_t c = 0; c < r; ++c)
            for (int64_t i = 0; i < m; ++i)
                Ut[(size_t)c * m + i] = s->basis.U[dm][i * r + c];
        if (!(ok = sw_bake_strain_products(s, dm, Ut, r, NULL, 0, G))) break;
        double tr = 0;
        for (int32_t a = 0; a < r; ++a)
            tr += G[(size_t)a * r + a];
        for (int32_t a = 0; a < r; ++a) /* a floating domain's rigid modes cost no strain:
                                           a trace-relative 1e-10 keeps the block definite */
            for (int32_t c = 0; c < r; ++c)
                H[(size_t)(off + a) * Rt + off + c] +=
                    G[(size_t)a * r + c] + (a == c ? 1e-10 * tr / r : 0);
        if (!(ok = sw_bake_strain_products(s, dm, Ut, r, Dd, P, G))) break;
        memcpy(Bq + (size_t)off * P, G, (size_t)r * P * sizeof(double));
    }
    openblas_set_num_threads(1);
    if (ok && LAPACKE_dposv(LAPACK_ROW_MAJOR, 'L', Rt, P, H, Rt, Bq, P) != 0) {
        out->train_galerkin_error = out->heldout_galerkin_error = NAN; /* not definite */
        goto done;
    }
    /* the errors, as the projection's: each domain's copies against the snapshot */
    for (int32_t dm = 0, off = 0; ok && dm < s->domains.nd; off += s->basis.rank[dm], ++dm) {
        int32_t base = s->domains.dom_vert_ptr[dm], n = s->domains.dom_vert_ptr[dm + 1] - base,
                r = s->basis.rank[dm];
        const double *U = s->basis.U[dm];
        for (int32_t a = 0; a < P; ++a)
            for (int32_t j = 0; j < n; ++j)
                for (int i = 0; i < 3; ++i) {
                    double p = 0, dv = D[(size_t)a * n3 + 3 * s->domains.dom_verts[base + j] + i];
                    for (int32_t c = 0; c < r; ++c)
                        p += U[(size_t)(3 * j + i) * r + c] * Bq[(size_t)(off + c) * P + a];
                    num[a >= nt] += (dv - p) * (dv - p);
                    den[a >= nt] += dv * dv;
                }
    }
    out->train_galerkin_error = den[0] > 0 ? sqrt(num[0] / den[0]) : 0;
    out->heldout_galerkin_error = den[1] > 0 ? sqrt(num[1] / den[1]) : 0;
done:
    free(D);
    free(H);
    free(Bq);
    free(Dd);
    free(Ut);
    free(G);
    return ok ? SINEW_OK
              : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                             "out of memory for the Galerkin errors");
}
