/* Small dense kernels of the step: Cholesky and the block-sparse Cholesky against it. */
#include <stdint.h>

#include "dense.h"
#include "sw_test.h"

static uint64_t rng = 12345;
static double urand(void) {
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1.0p-53 - 0.5;
}

/* A random SPD matrix whose off-diagonal blocks are nonzero only where couple[i][j]. */
static void make_spd(int32_t n, int32_t nb, const int32_t *off, const int32_t *size,
                     const unsigned char *couple, double *A) {
    double *B = calloc((size_t)n * n, sizeof(double));
    for (int32_t i = 0; i < nb; ++i)
        for (int32_t j = 0; j <= i; ++j) {
            if (i != j && !couple[i * nb + j]) continue;
            for (int32_t r = 0; r < size[i]; ++r)
                for (int32_t c = 0; c < size[j]; ++c)
                    B[(off[i] + r) * n + off[j] + c] = urand();
        }
    /* A = B B^T restricted to the coupling pattern would fill; instead a diagonally
     * dominant symmetric matrix with the pattern */
    for (int32_t r = 0; r < n; ++r)
        for (int32_t c = 0; c <= r; ++c)
            A[r * n + c] = A[c * n + r] = B[r * n + c];
    for (int32_t r = 0; r < n; ++r) {
        double s = 0;
        for (int32_t c = 0; c < n; ++c)
            s += fabs(A[r * n + c]);
        A[r * n + r] = s + 1.0;
    }
    free(B);
}

static void check_solve(int32_t nb, const int32_t *size, const unsigned char *couple,
                        const int32_t *order, double *maxerr) {
    int32_t off[16], n = 0;
    for (int32_t b = 0; b < nb; ++b) {
        off[b] = n;
        n += size[b];
    }
    double *A = calloc((size_t)n * n, sizeof(double)), *L = calloc((size_t)n * n, sizeof(double));
    double *Ld = malloc(sizeof(double) * n * n), *x = malloc(sizeof(double) * n),
           *y = malloc(sizeof(double) * n);
    unsigned char nz[256];
    double *pack = malloc(sizeof(double) * sw_block_cholesky_pack_size(17));
    make_spd(n, nb, off, size, couple, A);
    for (int32_t i = 0; i < n; ++i)
        x[i] = y[i] = urand();
    memcpy(Ld, A, sizeof(double) * n * n);
    sw_block_pattern(A, n, nb, off, size, order, nz);
    int ok1 = sw_cholesky(Ld, n), ok2 = sw_block_cholesky(A, n, nb, off, size, order, nz, L, pack);
    if (ok1 && ok2) {
        sw_cholesky_solve(Ld, n, x);
        sw_block_cholesky_solve(L, n, nb, off, size, order, nz, y);
        for (int32_t i = 0; i < n; ++i)
            *maxerr = fmax(*maxerr, fabs(x[i] - y[i]) / (fabs(x[i]) + 1e-3));
    } else {
        *maxerr = INFINITY;
    }
    free(A);
    free(L);
    free(pack);
    free(Ld);
    free(x);
    free(y);
}

TEST(block_cholesky_matches_dense_on_chains_trees_and_fill) {
    /* blocks up to 17: the factor packs eight columns at a time (9 and 17 leave one over) */
    const int32_t size[6] = {3, 9, 1, 4, 17, 2};
    unsigned char chain[36] = {0}, tree[36] = {0}, loop[36] = {0};
    for (int i = 1; i < 6; ++i)
        chain[i * 6 + i - 1] = chain[(i - 1) * 6 + i] = 1;
    const int parent[6] = {-1, 0, 0, 1, 1, 2};
    for (int i = 1; i < 6; ++i)
        tree[i * 6 + parent[i]] = tree[parent[i] * 6 + i] = 1;
    memcpy(loop, tree, sizeof loop);
    loop[5 * 6 + 4] = loop[4 * 6 + 5] = 1; /* a contact between two leaves: fill */
    const int32_t orders[4][6] = {
        {0, 1, 2, 3, 4, 5}, {5, 4, 3, 2, 1, 0}, {3, 4, 5, 1, 2, 0}, {2, 0, 5, 3, 1, 4}};
    double worst = 0;
    for (int t = 0; t < 20; ++t)
        for (int o = 0; o < 4; ++o) {
            check_solve(6, size, chain, orders[o], &worst);
            check_solve(6, size, tree, orders[o], &worst);
            check_solve(6, size, loop, orders[o], &worst);
        }
    fprintf(stderr, "    worst relative difference to the dense solve: %.3g\n", worst);
    ENSURE(worst < 1e-10);
}

TEST(block_cholesky_rejects_indefinite) {
    const int32_t size[2] = {2, 2}, off[2] = {0, 2}, order[2] = {1, 0};
    double A[16] = {2, 0, 1, 0, 0, 2, 0, 0, 1, 0, -1, 0, 0, 0, 0, 1}, L[16];
    unsigned char nz[4];
    sw_block_pattern(A, 4, 2, off, size, order, nz);
    double pack[16];
    ENSURE(sw_block_cholesky(A, 4, 2, off, size, order, nz, L, pack) == 0);
}

SW_TEST_MAIN(CASE(block_cholesky_matches_dense_on_chains_trees_and_fill),
             CASE(block_cholesky_rejects_indefinite))
