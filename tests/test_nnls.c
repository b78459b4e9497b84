/* NNLS (precompute/train/nnls.c): KKT conditions on random problems of every shape, both
 * methods agreeing, exact recovery of sparse solutions, brute force over all active
 * sets on tiny problems, warm starts, error paths, and a timing of LH vs FNNLS. */
#include "nnls.h"
#include "sw_test.h"

#include <stdint.h>
#include <time.h>

static uint64_t rng_state;
static double urand(void) { /* splitmix64 -> [0, 1) */
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}
static double nrand(void) {
    return sqrt(-2 * log(1 - urand())) * cos(6.283185307179586 * urand());
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double *random_matrix(int64_t m, int64_t n) {
    double *A = malloc((size_t)(m * n) * sizeof(double));
    for (int64_t i = 0; i < m * n; ++i)
        A[i] = nrand();
    return A;
}

/* Rank-deficient: A = B C with B m x k, C k x n, plus an exactly repeated column. */
static double *lowrank_matrix(int64_t m, int64_t n, int64_t k) {
    double *B = random_matrix(m, k), *C = random_matrix(k, n);
    double *A = calloc((size_t)(m * n), sizeof(double));
    for (int64_t j = 0; j < n; ++j)
        for (int64_t l = 0; l < k; ++l)
            for (int64_t i = 0; i < m; ++i)
                A[j * m + i] += B[l * m + i] * C[j * k + l];
    memcpy(A + (n - 1) * m, A, (size_t)m * sizeof(double));
    free(B);
    free(C);
    return A;
}

/* KKT of min |Ax-b|, x >= 0: x >= 0; g = A^T(Ax - b) >= -tol where x = 0 and |g| <=
 * tol where x > 0, tol relative to |A^T b|_inf. Returns the worst violation / scale. */
static double kkt_violation(const double *A, int64_t m, int64_t n, const double *b,
                            const double *x) {
    double *r = malloc((size_t)m * sizeof(double));
    for (int64_t i = 0; i < m; ++i)
        r[i] = -b[i];
    for (int64_t j = 0; j < n; ++j)
        for (int64_t i = 0; i < m; ++i)
            r[i] += A[j * m + i] * x[j];
    double scale = 0, worst = 0;
    for (int64_t j = 0; j < n; ++j) {
        double atb = 0, g = 0;
        for (int64_t i = 0; i < m; ++i) {
            atb += A[j * m + i] * b[i];
            g += A[j * m + i] * r[i];
        }
        scale = fmax(scale, fabs(atb));
        if (x[j] < 0)
            worst = fmax(worst, INFINITY);
        else if (x[j] == 0)
            worst = fmax(worst, -g);
        else
            worst = fmax(worst, fabs(g));
    }
    free(r);
    return scale > 0 ? worst / scale : worst;
}

static double resid(const double *A, int64_t m, int64_t n, const double *b, const double *x) {
    double s = 0;
    for (int64_t i = 0; i < m; ++i) {
        double r = -b[i];
        for (int64_t j = 0; j < n; ++j)
            r += A[j * m + i] * x[j];
        s += r * r;
    }
    return sqrt(s);
}

typedef struct {
    int64_t m, n;
    int kind; /* 0 random, 1 low rank */
} shape;

TEST(kkt_random_shapes) {
    static const shape shapes[] = {{60, 30, 0}, {30, 30, 0}, {20, 50, 0},  {5, 40, 0},
                                   {60, 30, 1}, {20, 50, 1}, {200, 80, 0}, {1, 7, 0}};
    rng_state = 1;
    for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; ++s) {
        for (int trial = 0; trial < 5; ++trial) {
            int64_t m = shapes[s].m, n = shapes[s].n;
            double *A = shapes[s].kind ? lowrank_matrix(m, n, n / 3 < m / 2 ? n / 3 : m / 2)
                                       : random_matrix(m, n);
            double *b = random_matrix(m, 1);
            double *x[2] = {malloc((size_t)n * sizeof(double)), malloc((size_t)n * sizeof(double))};
            double rn[2];
            for (int meth = 0; meth < 2; ++meth) {
                sw_nnls_stats st;
                sw_error err;
                sinew_result r =
                    sw_nnls((sw_nnls_method)meth, A, m, n, b, 0, 0, x[meth], &st, &err);
                double v = kkt_violation(A, m, n, b, x[meth]);
                rn[meth] = resid(A, m, n, b, x[meth]);
                int ok = r == SINEW_OK && st.converged && v < 1e-8 &&
                         fabs(st.residual - rn[meth]) <= 1e-9 * (1 + rn[meth]);
                if (!ok) {
                    free(A), free(b), free(x[0]), free(x[1]);
                    ENSUREF(0, "shape %zu trial %d method %d: result %d (%s) kkt %g res %g/%g", s,
                            trial, meth, (int)r, r ? err.msg : "", v, st.residual, rn[meth]);
                }
            }
            /* The optimal residual is unique even where x is not (rank deficient). */
            double drn = fabs(rn[0] - rn[1]);
            double dx = 0;
            for (int64_t j = 0; j < n; ++j)
                dx = fmax(dx, fabs(x[0][j] - x[1][j]));
            int unique = !shapes[s].kind && m >= n;
            free(A), free(b), free(x[0]), free(x[1]);
            ENSUREF(drn <= 1e-8 * (1 + rn[0]), "shape %zu: residuals %g vs %g", s, rn[0], rn[1]);
            if (unique) ENSUREF(dx <= 1e-7, "shape %zu: LH and FNNLS differ by %g", s, dx);
        }
    }
}

TEST(exact_sparse_recovery) {
    rng_state = 7;
    for (int trial = 0; trial < 10; ++trial) {
        int64_t m = 80, n = 60;
        double *A = random_matrix(m, n), *b = calloc((size_t)m, sizeof(double));
        double xs[60] = {0}, x[60];
        for (int k = 0; k < 10; ++k)
            xs[(int64_t)(urand() * n)] = 0.5 + urand();
        for (int64_t j = 0; j < n; ++j)
            for (int64_t i = 0; i < m; ++i)
                b[i] += A[j * m + i] * xs[j];
        double worst = 0, rn = 0;
        for (int meth = 0; meth < 2; ++meth) {
            sinew_result r = sw_nnls((sw_nnls_method)meth, A, m, n, b, 0, 0, x, NULL, NULL);
            if (r != SINEW_OK) worst = INFINITY;
            for (int64_t j = 0; j < n; ++j)
                worst = fmax(worst, fabs(x[j] - xs[j]));
            rn = fmax(rn, resid(A, m, n, b, x));
        }
        free(A), free(b);
        ENSUREF(worst < 1e-9 && rn < 1e-9, "trial %d: |x - x*| = %g, residual %g", trial, worst,
                rn);
    }
}

/* Least squares on the columns in mask by Gaussian elimination with partial pivoting
 * on the normal equations (tiny, well-conditioned subsets); 0 if singular. */
static int subset_ls(const double *A, int64_t m, int n, unsigned mask, const double *b, double *x) {
    int idx[8], k = 0;
    for (int j = 0; j < n; ++j)
        if (mask >> j & 1) idx[k++] = j;
    double M[8][9];
    for (int a = 0; a < k; ++a) {
        for (int c = 0; c < k; ++c) {
            double s = 0;
            for (int64_t i = 0; i < m; ++i)
                s += A[idx[a] * m + i] * A[idx[c] * m + i];
            M[a][c] = s;
        }
        double s = 0;
        for (int64_t i = 0; i < m; ++i)
            s += A[idx[a] * m + i] * b[i];
        M[a][k] = s;
    }
    for (int c = 0; c < k; ++c) {
        int piv = c;
        for (int a = c + 1; a < k; ++a)
            if (fabs(M[a][c]) > fabs(M[piv][c])) piv = a;
        if (fabs(M[piv][c]) < 1e-10 * (1 + fabs(M[c][c]))) return 0;
        for (int t = 0; t <= k; ++t) {
            double tmp = M[c][t];
            M[c][t] = M[piv][t];
            M[piv][t] = tmp;
        }
        for (int a = 0; a < k; ++a) {
            if (a == c) continue;
            double f = M[a][c] / M[c][c];
            for (int t = c; t <= k; ++t)
                M[a][t] -= f * M[c][t];
        }
    }
    for (int j = 0; j < n; ++j)
        x[j] = 0;
    for (int a = 0; a < k; ++a)
        x[idx[a]] = M[a][k] / M[a][a];
    return 1;
}

TEST(brute_force_active_sets) {
    rng_state = 99;
    for (int trial = 0; trial < 60; ++trial) {
        int n = 1 + trial % 8;
        int64_t m = 2 + (int64_t)(urand() * 10);
        double *A = random_matrix(m, n), *b = random_matrix(m, 1);
        /* The optimum lies on some active set with independent columns whose
         * unconstrained LS solution is non-negative: take the best such one. */
        double best = resid(A, m, n, b, (double[8]){0}), xb[8];
        for (unsigned mask = 1; mask < (1u << n); ++mask) {
            if (!subset_ls(A, m, n, mask, b, xb)) continue;
            int feas = 1;
            for (int j = 0; j < n; ++j)
                feas &= xb[j] >= 0;
            if (feas) best = fmin(best, resid(A, m, n, b, xb));
        }
        double x[8], got[2];
        for (int meth = 0; meth < 2; ++meth) {
            sinew_result r = sw_nnls((sw_nnls_method)meth, A, m, n, b, 0, 0, x, NULL, NULL);
            got[meth] = r == SINEW_OK ? resid(A, m, n, b, x) : INFINITY;
        }
        free(A), free(b);
        for (int meth = 0; meth < 2; ++meth)
            ENSUREF(fabs(got[meth] - best) <= 1e-9 * (1 + best),
                    "trial %d (m %lld n %d) method %d: residual %.15g, brute force %.15g", trial,
                    (long long)m, n, meth, got[meth], best);
    }
}

TEST(normal_equations_warm_start) {
    rng_state = 3;
    int64_t m = 100, n = 40;
    double *A = random_matrix(m, n), *b = random_matrix(m, 1);
    for (int64_t i = 0; i < m; ++i)
        b[i] += 3; /* many positive weights */
    for (int64_t i = 0; i < m * n; ++i)
        A[i] = fabs(A[i]);
    double G[40 * 40], Atb[40], btb = 0, xc[40], xw[40], xr[40], x0[40];
    for (int64_t i = 0; i < m; ++i)
        btb += b[i] * b[i];
    for (int64_t j = 0; j < n; ++j) {
        Atb[j] = 0;
        for (int64_t i = 0; i < m; ++i)
            Atb[j] += A[j * m + i] * b[i];
        for (int64_t k = 0; k < n; ++k) {
            double s = 0;
            for (int64_t i = 0; i < m; ++i)
                s += A[j * m + i] * A[k * m + i];
            G[j * n + k] = s;
        }
    }
    sw_nnls_stats st;
    ENSURE(sw_nnls(SW_NNLS_LAWSON_HANSON, A, m, n, b, 0, 0, xr, NULL, NULL) == SINEW_OK);
    ENSURE(sw_nnls_normal(G, Atb, btb, n, 0, 0, NULL, xc, &st, NULL) == SINEW_OK);
    double rn = resid(A, m, n, b, xr);
    ENSURE_NEAR(st.residual, rn, 1e-6 * rn);
    /* Warm start from a perturbed, partly wrong support. */
    for (int64_t j = 0; j < n; ++j)
        x0[j] = (j % 3 == 0) ? urand() : 0;
    ENSURE(sw_nnls_normal(G, Atb, btb, n, 0, 0, x0, xw, &st, NULL) == SINEW_OK);
    ENSURE(st.converged);
    double dx = 0;
    for (int64_t j = 0; j < n; ++j)
        dx = fmax(dx, fmax(fabs(xc[j] - xr[j]), fabs(xw[j] - xr[j])));
    free(A), free(b);
    ENSUREF(dx < 1e-8, "cold/warm normal-equation solutions differ from LH by %g", dx);
}

TEST(iteration_limit) {
    rng_state = 5;
    int64_t m = 50, n = 30;
    double *A = random_matrix(m, n), *b = random_matrix(m, 1);
    for (int64_t i = 0; i < m * n; ++i)
        A[i] = fabs(A[i]);
    for (int64_t i = 0; i < m; ++i)
        b[i] = fabs(b[i]) + 1;
    double x[30];
    sw_nnls_stats st;
    sw_error err;
    for (int meth = 0; meth < 2; ++meth) {
        sinew_result r = sw_nnls((sw_nnls_method)meth, A, m, n, b, 0, 2, x, &st, &err);
        int feasible = 1;
        for (int64_t j = 0; j < n; ++j)
            feasible &= x[j] >= 0;
        if (r != SINEW_ERROR_NOT_CONVERGED || st.converged || st.iterations != 2 || !feasible) {
            free(A), free(b);
            ENSUREF(0, "method %d: result %d, converged %d, iterations %d", meth, (int)r,
                    st.converged, st.iterations);
        }
        ENSURE(strstr(err.msg, "nnls") != NULL);
    }
    free(A), free(b);
}

TEST(bad_input) {
    double A[6] = {1, 2, 3, 4, 5, 6}, b[3] = {1, 1, 1}, x[2];
    sw_error err;
    sw_error_clear(&err);
    A[4] = NAN;
    for (int meth = 0; meth < 2; ++meth) {
        ENSURE(sw_nnls((sw_nnls_method)meth, A, 3, 2, b, 0, 0, x, NULL, &err) ==
               SINEW_ERROR_INVALID_ARGUMENT);
        ENSURE(strstr(err.msg, "column 1") != NULL);
    }
    A[4] = 5;
    b[2] = INFINITY;
    ENSURE(sw_nnls(SW_NNLS_FAST, A, 3, 2, b, 0, 0, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    b[2] = 1;
    ENSURE(sw_nnls(SW_NNLS_FAST, A, 0, 2, b, 0, 0, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_nnls(SW_NNLS_FAST, A, 3, 0, b, 0, 0, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_nnls(SW_NNLS_FAST, NULL, 3, 2, b, 0, 0, x, NULL, &err) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_nnls(SW_NNLS_FAST, A, 3, 2, b, -1, 0, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_nnls(SW_NNLS_FAST, A, 3, 2, b, NAN, 0, x, NULL, &err) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_nnls((sw_nnls_method)7, A, 3, 2, b, 0, 0, x, NULL, &err) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    double G[4] = {1, 0, 0, NAN}, Atb[2] = {1, 1}, x0[2] = {-1, 0};
    ENSURE(sw_nnls_normal(G, Atb, 2, 2, 0, 0, NULL, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    G[3] = 1;
    ENSURE(sw_nnls_normal(G, Atb, 2, 2, 0, 0, x0, x, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    /* b = 0 and A = 0 are valid: x = 0. */
    double Z[6] = {0};
    ENSURE(sw_nnls(SW_NNLS_LAWSON_HANSON, Z, 3, 2, b, 0, 0, x, NULL, &err) == SINEW_OK);
    ENSURE(x[0] == 0 && x[1] == 0);
}

/* m = 3000, n = 200 with a dense positive solution (the slow case: every column
 * enters). Prints both times; asserts only that the answers agree. */
TEST(timing_lh_vs_fnnls) {
    rng_state = 11;
    int64_t m = 3000, n = 200;
    double *A = random_matrix(m, n), *b = calloc((size_t)m, sizeof(double));
    for (int64_t i = 0; i < m * n; ++i)
        A[i] = fabs(A[i]);
    for (int64_t j = 0; j < n; ++j)
        for (int64_t i = 0; i < m; ++i)
            b[i] += A[j * m + i] * (j % 4 ? urand() : 0);
    for (int64_t i = 0; i < m; ++i)
        b[i] += 0.3 * nrand();
    double *x[2] = {malloc((size_t)n * sizeof(double)), malloc((size_t)n * sizeof(double))};
    double t[2];
    sw_nnls_stats st[2];
    for (int meth = 0; meth < 2; ++meth) {
        double t0 = now();
        sinew_result r = sw_nnls((sw_nnls_method)meth, A, m, n, b, 0, 0, x[meth], &st[meth], NULL);
        t[meth] = now() - t0;
        if (r != SINEW_OK) st[meth].residual = INFINITY;
    }
    double dx = 0;
    int npos = 0;
    for (int64_t j = 0; j < n; ++j) {
        dx = fmax(dx, fabs(x[0][j] - x[1][j]));
        npos += x[0][j] > 0;
    }
    fprintf(stderr,
            "  m %lld n %lld (%d positive): Lawson-Hanson %.3f s (%d it), FNNLS %.3f s (%d it), "
            "|dx| %.2g\n",
            (long long)m, (long long)n, npos, t[0], st[0].iterations, t[1], st[1].iterations, dx);
    free(A), free(b), free(x[0]), free(x[1]);
    ENSURE(isfinite(st[0].residual) &&
           fabs(st[0].residual - st[1].residual) < 1e-8 * st[0].residual);
    ENSURE(dx < 1e-6);
}

SW_TEST_MAIN(CASE(kkt_random_shapes), CASE(exact_sparse_recovery), CASE(brute_force_active_sets),
             CASE(normal_equations_warm_start), CASE(iteration_limit), CASE(bad_input),
             CASE(timing_lh_vs_fnnls))
