/* Helpers of the stages after domains and basis, below them (bake_state.h): a domain's
 * tets at rest, a pose's un-skinned displacements and the snapshots' products in the
 * rest strain energy. */
#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"

void sw_bake_domain_tets(const sw_bake_state *s, int32_t dm, int32_t *local_of, int32_t *tet_local,
                         double *dminv, double *evol) {
    int32_t base = s->domains.dom_vert_ptr[dm], t0 = s->domains.dom_tet_ptr[dm],
            ntd = s->domains.dom_tet_ptr[dm + 1] - t0;
    for (int32_t k = base; k < s->domains.dom_vert_ptr[dm + 1]; ++k)
        local_of[s->domains.dom_verts[k]] = k - base;
    for (int32_t i = 0; i < ntd; ++i) {
        const int32_t *tet = s->rig.ch.mesh.tets + 4 * (int64_t)s->domains.dom_tets[t0 + i];
        double Xe[12];
        for (int k = 0; k < 4; ++k) {
            tet_local[4 * i + k] = local_of[tet[k]];
            memcpy(Xe + 3 * k, s->rig.ch.mesh.X + 3 * (int64_t)tet[k], 24);
        }
        if (!sw_tet_rest(Xe, dminv + 9 * i, evol + i)) { /* a degenerate tet weighs nothing */
            memset(dminv + 9 * i, 0, 9 * sizeof(double));
            evol[i] = 0;
        }
        /* the energy is linear in (mu, lambda): its painted multiplier scales its volume */
        evol[i] *= sw_character_stiffness(&s->rig.ch, s->domains.dom_tets[t0 + i]);
    }
}

void sw_bake_unskin(const sw_bake_state *s, const double *T, const double *x, double *R, double *t,
                    double *d) {
    sw_bake_skin_transforms(s, T, R, t);
    for (int32_t v = 0; v < s->rig.nv; ++v) {
        const double *Rv = R + 9 * v, *xv = x + 3 * v, *tv = t + 3 * v,
                     *X = s->rig.ch.mesh.X + 3 * v;
        double w[3] = {xv[0] - tv[0], xv[1] - tv[1], xv[2] - tv[2]};
        for (int i = 0; i < 3; ++i)
            d[3 * v + i] = Rv[i] * w[0] + Rv[3 + i] * w[1] + Rv[6 + i] * w[2] - X[i];
        if (s->rig.ch.bone_of_vertex[v] >= 0) d[3 * v] = d[3 * v + 1] = d[3 * v + 2] = 0;
    }
}

/* Tets a pass of strain_gram takes: each adds 7 columns to the T-row strain matrix. */
#define STRAIN_CHUNK 128
#define SQRT1_2 0.70710678118654752440

/* The 7 strain numbers of tet c (corners loc, shape gradients Dg) for each of the n rows
 * of D (m entries each) into S (row a at S + a * cols + 7 c): the strain e = sym(grad d)
 * gives 2 Psi = 2 mu dev(e):dev(e) + (2 mu / 3 + lambda) tr(e)^2, and the numbers'
 * squares sum to vol 2 Psi (dev = sqrt(2 mu vol), bulk = sqrt((2 mu / 3 + lambda) vol)). */
static void strain_numbers(const double *D, int32_t n, int64_t m, const int32_t loc[4],
                           const double Dg[12], double dev, double bulk, double *S, int64_t cols,
                           int32_t c) {
    for (int32_t a = 0; a < n; ++a) {
        double g[9] = {0}; /* grad d = sum over corners d_k Dg_k^T */
        for (int k = 0; k < 4; ++k) {
            const double *dk = D + (size_t)a * m + 3 * loc[k];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    g[3 * i + j] += dk[i] * Dg[3 * k + j];
        }
        double tr = g[0] + g[4] + g[8], *e = S + (size_t)a * cols + 7 * c;
        e[0] = dev * (g[0] - tr / 3);
        e[1] = dev * (g[4] - tr / 3);
        e[2] = dev * (g[8] - tr / 3);
        e[3] = dev * SQRT1_2 * (g[1] + g[3]); /* 2 e01^2 = ((g01 + g10) / sqrt 2)^2 */
        e[4] = dev * SQRT1_2 * (g[2] + g[6]);
        e[5] = dev * SQRT1_2 * (g[5] + g[7]);
        e[6] = bulk * tr;
    }
}

/* The products accumulate chunk by chunk of tets, in order (the bake is the same on any
 * thread count). */
int sw_bake_strain_products(const sw_bake_state *s, int32_t dm, const double *A, int32_t na,
                            const double *B, int32_t nb, double *G) {
    int64_t m = 3 * (int64_t)(s->domains.dom_vert_ptr[dm + 1] - s->domains.dom_vert_ptr[dm]);
    int sym = B == NULL;
    if (sym) nb = na;
    double mu, lambda;
    sw_lame(s->rig.ch.youngs, s->rig.ch.poisson, &mu, &lambda);
    int32_t ntd = s->domains.dom_tet_ptr[dm + 1] - s->domains.dom_tet_ptr[dm];
    const int64_t cols = 7 * STRAIN_CHUNK;
    int32_t *local_of = malloc((size_t)s->rig.nv * sizeof(int32_t)),
            *tet_local = malloc((size_t)ntd * 4 * sizeof(int32_t) + 1);
    double *dminv = malloc((size_t)ntd * 9 * sizeof(double) + 1),
           *vol = malloc((size_t)ntd * sizeof(double) + 1),
           *SA = malloc((size_t)na * cols * sizeof(double) + 1),
           *SB = sym ? SA : malloc((size_t)nb * cols * sizeof(double) + 1);
    int ok = local_of && tet_local && dminv && vol && SA && SB;
    openblas_set_num_threads(1);
    if (ok) {
        sw_bake_domain_tets(s, dm, local_of, tet_local, dminv, vol);
        memset(G, 0, (size_t)na * nb * sizeof(double));
    }
    for (int32_t c0 = 0; ok && c0 < ntd; c0 += STRAIN_CHUNK) {
        int32_t nc = ntd - c0 < STRAIN_CHUNK ? ntd - c0 : STRAIN_CHUNK;
        for (int32_t c = 0; c < nc; ++c) {
            double Dg[12];
            sw_tet_shape_gradients(dminv + 9 * (c0 + c), Dg);
            double dev = sqrt(2 * mu * vol[c0 + c]),
                   bulk = sqrt(fmax(2 * mu / 3 + lambda, 0) * vol[c0 + c]);
            strain_numbers(A, na, m, tet_local + 4 * (c0 + c), Dg, dev, bulk, SA, cols, c);
            if (!sym)
                strain_numbers(B, nb, m, tet_local + 4 * (c0 + c), Dg, dev, bulk, SB, cols, c);
        }
        if (sym)
            cblas_dsyrk(CblasRowMajor, CblasUpper, CblasNoTrans, na, 7 * nc, 1.0, SA, (int)cols,
                        1.0, G, na);
        else
            cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, na, nb, 7 * nc, 1.0, SA, (int)cols,
                        SB, (int)cols, 1.0, G, nb);
    }
    for (int32_t a = 0; ok && sym && a < na; ++a)
        for (int32_t b = a + 1; b < na; ++b)
            G[(size_t)b * na + a] = G[(size_t)a * na + b];
    free(local_of);
    free(tet_local);
    free(dminv);
    free(vol);
    if (!sym) free(SB);
    free(SA);
    return ok;
}
