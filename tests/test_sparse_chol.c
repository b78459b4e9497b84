/* The reference's sparse direct solve (precompute/reference/sparse_chol.c): on a tet
 * mesh's stiffness-like matrix plus contact couplings outside the tet pattern, the
 * solution's residual is at round-off, the analysis is redone only when the contacts
 * couple a new vertex pair, an indefinite or non-finite matrix is reported as such (not
 * solved), and masked vertices stay zero. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bsr_matrix.h"
#include "samples.h"
#include "sparse_chol.h"
#include "sw_test.h"

static uint64_t rng = 12345;
static double urand(void) {
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1.0p-53;
}

/* K = sum over tets of B^T B + shift I per block diagonal (SPD), or with a negative
 * shift (indefinite). */
static void fill_matrix(sw_bsr *K, const sw_tetmesh *m, double shift) {
    double *Ke = malloc((size_t)m->ntets * 144 * sizeof(double));
    for (int32_t t = 0; t < m->ntets; ++t) {
        double B[6 * 12];
        for (int i = 0; i < 72; ++i)
            B[i] = urand() - 0.5;
        for (int r = 0; r < 12; ++r)
            for (int c = 0; c < 12; ++c) {
                double s = 0;
                for (int k = 0; k < 6; ++k)
                    s += B[12 * k + r] * B[12 * k + c];
                Ke[144 * t + 12 * r + c] = s;
            }
    }
    sw_bsr_assemble(K, Ke, NULL);
    free(Ke);
    for (int32_t v = 0; v < K->nrows; ++v) {
        double *D = K->val + 9 * K->diag[v];
        D[0] += shift, D[4] += shift, D[8] += shift;
    }
}

static double residual(const sw_bsr *K, const sw_contact *c, int32_t nc, double kc, const double *b,
                       const double *sol, const unsigned char *mask) {
    int32_t nv = K->nrows;
    double *y = calloc((size_t)nv * 3, sizeof(double));
    sw_bsr_multiply(K, sol, y, NULL);
    sw_contact_apply_hessian(c, nc, kc, 0.5, sol, y);
    double r = 0, bn = 0;
    for (int32_t v = 0; v < nv; ++v)
        if (mask[v])
            for (int i = 0; i < 3; ++i) {
                double e = y[3 * v + i] - b[3 * v + i];
                r += e * e;
                bn += b[3 * v + i] * b[3 * v + i];
            }
    free(y);
    return sqrt(r / bn);
}

static void direct_solve_matches_the_system(void) {
    sw_character ch;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1500, 2, &ch, &err) == SINEW_OK);
    const sw_tetmesh *m = &ch.mesh;
    int32_t nv = m->nverts;
    sw_bsr K;
    ENSURE(sw_bsr_create_from_tets(nv, m->ntets, m->tets, &K, &err) == SINEW_OK);
    unsigned char *mask = malloc((size_t)nv);
    for (int32_t v = 0; v < nv; ++v)
        mask[v] = v % 7 != 0; /* some fixed vertices */
    sw_sparse_chol *s;
    ENSURE(sw_sparse_chol_create(nv, mask, &s, &err) == SINEW_OK);
    fill_matrix(&K, m, 1e-2);

    double *b = malloc((size_t)nv * 3 * sizeof(double)),
           *x = malloc((size_t)nv * 3 * sizeof(double));
    for (int32_t i = 0; i < 3 * nv; ++i)
        b[i] = urand() - 0.5;

    /* 1. no contact */
    ENSURE(sw_sparse_chol_factor(s, &K, NULL, 0, 1.0, 0.5, &err) == SINEW_OK);
    ENSURE(sw_sparse_chol_solve(s, b, x, &err) == SINEW_OK);
    double r0 = residual(&K, NULL, 0, 1.0, b, x, mask);
    ENSURE(r0 < 1e-10);
    for (int32_t v = 0; v < nv; ++v)
        if (!mask[v]) ENSURE(x[3 * v] == 0 && x[3 * v + 1] == 0 && x[3 * v + 2] == 0);
    ENSURE(sw_sparse_chol_get_stats(s).analyses == 1);

    /* 2. contacts between far-apart vertices (outside the tet pattern) */
    sw_contact c[3];
    memset(c, 0, sizeof c);
    for (int k = 0; k < 3; ++k) {
        c[k].p = 1 + 50 * k;
        for (int j = 0; j < 3; ++j)
            c[k].tri[j] = nv - 1 - 3 * k - j;
        c[k].beta[0] = 0.2, c[k].beta[1] = 0.3, c[k].beta[2] = 0.5;
        c[k].ka = 0.5;
        c[k].n[1] = 1;
    }
    double kc = 3.0;
    ENSURE(sw_sparse_chol_factor(s, &K, c, 3, kc, 0.5, &err) == SINEW_OK);
    ENSURE(sw_sparse_chol_get_stats(s).analyses == 2);
    ENSURE(sw_sparse_chol_solve(s, b, x, &err) == SINEW_OK);
    double r1 = residual(&K, c, 3, kc, b, x, mask);
    ENSURE(r1 < 1e-10);
    /* the same couplings again: refactored without a new analysis */
    fill_matrix(&K, m, 2e-2);
    ENSURE(sw_sparse_chol_factor(s, &K, c, 3, kc, 0.5, &err) == SINEW_OK);
    ENSURE(sw_sparse_chol_get_stats(s).analyses == 2);
    ENSURE(sw_sparse_chol_get_stats(s).factorizations == 3);
    ENSURE(sw_sparse_chol_solve(s, b, x, &err) == SINEW_OK);
    ENSURE(residual(&K, c, 3, kc, b, x, mask) < 1e-10);
    /* 3. indefinite: reported, and solve refuses until a good factorisation */
    fill_matrix(&K, m, -50.0);
    ENSURE(sw_sparse_chol_factor(s, &K, NULL, 0, kc, 0.5, &err) == SINEW_ERROR_DEGENERATE);
    ENSURE(sw_sparse_chol_solve(s, b, x, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    /* 4. non-finite entries */
    fill_matrix(&K, m, 1e-2);
    K.val[9 * K.diag[1] + 4] = NAN; /* vertex 1 is free */
    ENSURE(sw_sparse_chol_factor(s, &K, NULL, 0, kc, 0.5, &err) == SINEW_ERROR_NOT_FINITE);
    /* 5. bad arguments */
    sw_sparse_chol *bad;
    ENSURE(sw_sparse_chol_create(0, mask, &bad, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    memset(mask, 0, (size_t)nv);
    ENSURE(sw_sparse_chol_create(nv, mask, &bad, &err) == SINEW_ERROR_INVALID_ARGUMENT);

    sw_sparse_chol_destroy(s);
    sw_bsr_free(&K);
    free(mask);
    free(b);
    free(x);
    sw_character_free(&ch);
}

SW_TEST_MAIN(CASE(direct_solve_matches_the_system))
