/* sw_svd3 / sw_polar3: reconstruction, orthogonality, proper rotations and ordering
 * over thousands of random, inverted, rank-deficient, repeated-singular-value,
 * near-degenerate, extreme-scale and zero matrices (fixed seed). */
#include "svd3.h"
#include "dqs.h"
#include "sw_test.h"

#include <stdint.h>

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

/* splitmix64 -> uniform in [-1, 1). */
static double urand(void) {
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

static void mul(const double A[9], const double B[9], double C[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

static double det3(const double A[9]) {
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

static double fro(const double A[9]) {
    double s = 0;
    for (int i = 0; i < 9; ++i)
        s += A[i] * A[i];
    return sqrt(s);
}

/* A random rotation from a normalised random quaternion. */
static void random_rotation(double R[9]) {
    double q[4], n = 0;
    do {
        n = 0;
        for (int i = 0; i < 4; ++i) {
            q[i] = urand();
            n += q[i] * q[i];
        }
    } while (n < 1e-3 || n > 1);
    n = sqrt(n);
    for (int i = 0; i < 4; ++i)
        q[i] /= n;
    sw_quat_to_matrix(q, R);
}

/* A = Ra diag(d) Rb^T. */
static void compose(const double d[3], double A[9]) {
    double Ra[9], Rb[9], T[9];
    random_rotation(Ra);
    random_rotation(Rb);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] = Ra[3 * i + j] * d[j];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            A[3 * i + j] =
                T[3 * i] * Rb[3 * j] + T[3 * i + 1] * Rb[3 * j + 1] + T[3 * i + 2] * Rb[3 * j + 2];
}

/* Checks every contract property of sw_svd3 on A; returns 0 and prints on failure.
 * scale is the size errors are measured against (|A|, or 1 for the zero matrix). */
static int check_svd(const double A[9], double tol) {
    double U[9], s[3], V[9];
    sw_svd3(A, U, s, V);
    double scale = fro(A) > 0 ? fro(A) : 1.0;
    for (int i = 0; i < 3; ++i)
        if (!isfinite(s[i])) {
            fprintf(stderr, "  non-finite s\n");
            return 0;
        }
    for (int i = 0; i < 9; ++i)
        if (!isfinite(U[i]) || !isfinite(V[i])) {
            fprintf(stderr, "  non-finite U/V\n");
            return 0;
        }
    /* Reconstruction. */
    double err = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double r = 0;
            for (int k = 0; k < 3; ++k)
                r += U[3 * i + k] * s[k] * V[3 * j + k];
            err += (r - A[3 * i + j]) * (r - A[3 * i + j]);
        }
    if (!(sqrt(err) <= tol * scale)) {
        fprintf(stderr, "  reconstruction error %g (|A| = %g)\n", sqrt(err), scale);
        return 0;
    }
    /* Orthonormality and det +1 of U and V. */
    const double *M[2] = {U, V};
    for (int m = 0; m < 2; ++m) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double d = 0;
                for (int k = 0; k < 3; ++k)
                    d += M[m][3 * k + i] * M[m][3 * k + j];
                if (!(fabs(d - (i == j)) <= 1e-13)) {
                    fprintf(stderr, "  %c not orthonormal (%d,%d): %g\n", "UV"[m], i, j, d);
                    return 0;
                }
            }
        if (!(fabs(det3(M[m]) - 1.0) <= 1e-13)) {
            fprintf(stderr, "  det %c = %.17g\n", "UV"[m], det3(M[m]));
            return 0;
        }
    }
    /* Ordering s0 >= s1 >= |s2|; only s2 may be negative, and only when det A < 0. */
    if (!(s[0] >= s[1] && s[1] >= fabs(s[2]) && s[1] >= 0)) {
        fprintf(stderr, "  order broken: %g %g %g\n", s[0], s[1], s[2]);
        return 0;
    }
    double dA = det3(A);
    if (fabs(dA) > 1e-10 * scale * scale * scale && (dA < 0) != (s[2] < 0)) {
        fprintf(stderr, "  sign of s2 (%g) disagrees with det A (%g)\n", s[2], dA);
        return 0;
    }
    return 1;
}

TEST(random_matrices) {
    for (int t = 0; t < 20000; ++t) {
        double A[9];
        for (int i = 0; i < 9; ++i)
            A[i] = urand();
        ENSUREF(check_svd(A, 1e-14), "case %d", t);
    }
}

TEST(inverted_matrices_flip_only_the_smallest) {
    for (int t = 0; t < 5000; ++t) {
        double d[3] = {urand() + 1.5, urand() + 1.5, -(urand() + 1.0) * 0.5};
        double A[9], U[9], s[3], V[9];
        compose(d, A);
        ENSURE(det3(A) < 0);
        ENSUREF(check_svd(A, 1e-14), "case %d", t);
        sw_svd3(A, U, s, V);
        ENSURE(s[2] < 0);
        /* The signed singular values are the given ones, sorted by magnitude. */
        double a[3] = {fabs(d[0]), fabs(d[1]), fabs(d[2])};
        for (int i = 0; i < 3; ++i)
            for (int j = i + 1; j < 3; ++j)
                if (a[j] > a[i]) {
                    double x = a[i];
                    a[i] = a[j];
                    a[j] = x;
                }
        ENSURE_NEAR(s[0], a[0], 1e-13);
        ENSURE_NEAR(s[1], a[1], 1e-13);
        ENSURE_NEAR(s[2], -a[2], 1e-13);
    }
}

TEST(rank_deficient_matrices) {
    for (int t = 0; t < 5000; ++t) {
        double A[9], U[9], s[3], V[9];
        if (t % 3 == 0) { /* rank 1: a b^T */
            double a[3] = {urand(), urand(), urand()}, b[3] = {urand(), urand(), urand()};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    A[3 * i + j] = a[i] * b[j];
        } else if (t % 3 == 1) { /* rank 2: third column a combination of the others */
            for (int i = 0; i < 3; ++i) {
                A[3 * i] = urand();
                A[3 * i + 1] = urand();
                A[3 * i + 2] = 0.3 * A[3 * i] - 0.7 * A[3 * i + 1];
            }
        } else { /* rank 2 or 1 with exact zero rows/columns */
            for (int i = 0; i < 9; ++i)
                A[i] = urand();
            int row = (t / 3) % 3;
            A[3 * row] = A[3 * row + 1] = A[3 * row + 2] = 0;
            if (t % 2) A[1] = A[4] = A[7] = 0;
        }
        ENSUREF(check_svd(A, 1e-14), "case %d", t);
        sw_svd3(A, U, s, V);
        ENSUREF(fabs(s[2]) <= 1e-14 * s[0], "case %d: s2 = %g", t, s[2]);
        if (t % 3 == 0) ENSUREF(s[1] <= 1e-14 * s[0], "case %d: s1 = %g", t, s[1]);
    }
}

TEST(repeated_singular_values) {
    const double sets[][3] = {{1, 1, 1},  {2, 2, 1},    {3, 1, 1},       {2, 2, -2},
                              {1, 1, 0},  {1, 0, 0},    {5, 5, 5},       {1, 1, -1},
                              {2, 1, -1}, {1, 1, 1e-9}, {1, 1e-9, 1e-9}, {4, 4, -1e-12}};
    for (size_t k = 0; k < sizeof sets / sizeof sets[0]; ++k)
        for (int t = 0; t < 200; ++t) {
            double A[9], U[9], s[3], V[9];
            compose(sets[k], A);
            ENSUREF(check_svd(A, 1e-14), "set %zu case %d", k, t);
            sw_svd3(A, U, s, V);
            ENSUREF(fabs(s[0] - fabs(sets[k][0])) <= 1e-13 * fabs(sets[k][0]) &&
                        fabs(s[1] - fabs(sets[k][1])) <= 1e-13 * fabs(sets[k][0]) &&
                        fabs(s[2] - sets[k][2]) <= 1e-13 * fabs(sets[k][0]),
                    "set %zu: got %.17g %.17g %.17g", k, s[0], s[1], s[2]);
        }
    /* Exactly diagonal and exactly orthogonal inputs. */
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Rf[9] = {0, 1, 0, 1, 0, 0, 0, 0, 1};
    ENSURE(check_svd(I, 1e-15));
    ENSURE(check_svd(Rf, 1e-15)); /* a reflection: s = (1, 1, -1) */
    double U[9], s[3], V[9];
    sw_svd3(Rf, U, s, V);
    ENSURE(s[0] == 1 && s[1] == 1 && s[2] == -1);
}

TEST(near_degenerate_and_extreme_scales) {
    const double scales[] = {1e-150, 1e-30, 1e-8, 1.0, 1e8, 1e30, 1e150};
    for (size_t k = 0; k < sizeof scales / sizeof scales[0]; ++k)
        for (int t = 0; t < 500; ++t) {
            double d[3] = {1.0, pow(10.0, -8.0 * (urand() + 1.0)), 1e-12 * urand()};
            double A[9];
            compose(d, A);
            for (int i = 0; i < 9; ++i)
                A[i] *= scales[k];
            ENSUREF(check_svd(A, 1e-14), "scale %g case %d", scales[k], t);
        }
}

TEST(zero_and_non_finite) {
    double Z[9] = {0}, U[9], s[3], V[9];
    ENSURE(check_svd(Z, 1e-15));
    sw_svd3(Z, U, s, V);
    ENSURE(s[0] == 0 && s[1] == 0 && s[2] == 0);
    /* A NaN must show up in s rather than vanish. */
    double N[9] = {1, 0, 0, 0, NAN, 0, 0, 0, 1};
    sw_svd3(N, U, s, V);
    ENSURE(isnan(s[0]) && isnan(s[1]) && isnan(s[2]));
    N[4] = INFINITY;
    sw_svd3(N, U, s, V);
    ENSURE(isnan(s[0]) && isnan(s[1]) && isnan(s[2]));
    for (int i = 0; i < 9; ++i)
        ENSURE(isfinite(U[i]) && isfinite(V[i]));
}

TEST(polar_decomposition) {
    for (int t = 0; t < 5000; ++t) {
        double A[9], R[9], S[9], RS[9];
        for (int i = 0; i < 9; ++i)
            A[i] = urand();
        sw_polar3(A, R, S);
        mul(R, S, RS);
        for (int i = 0; i < 9; ++i)
            ENSURE_NEAR(RS[i], A[i], 1e-14 * fro(A));
        ENSURE_NEAR(det3(R), 1.0, 1e-13);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                ENSURE(S[3 * i + j] == S[3 * j + i]);
        /* det R = 1, so det S carries det A (negative for inverted A). */
        ENSURE_NEAR(det3(S), det3(A), 1e-13);
        double R2[9];
        sw_polar3(A, R2, NULL); /* S is optional */
        for (int i = 0; i < 9; ++i)
            ENSURE(R2[i] == R[i]);
    }
    /* A rotation is its own polar factor. */
    double Q[9], R[9], S[9];
    random_rotation(Q);
    sw_polar3(Q, R, S);
    for (int i = 0; i < 9; ++i) {
        ENSURE_NEAR(R[i], Q[i], 1e-15);
        ENSURE_NEAR(S[i], (i % 4 == 0) ? 1.0 : 0.0, 1e-15);
    }
}

/* Warm-started from any proper rotation (near or far from the answer) the SVD is the
 * same decomposition as cold: same singular values, A = U S V^T, U and V rotations. */
TEST(warm_start_gives_the_same_decomposition) {
    uint64_t seed = 4242;
    for (int trial = 0; trial < 3000; ++trial) {
        double A[9], B[9], U0[9], s0[3], V0[9], U[9], s[3], V[9];
        for (int i = 0; i < 9; ++i) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            A[i] = (double)(seed >> 11) * 0x1.0p-52 - 1.0;
        }
        if (trial % 4 == 0) A[0] = -A[0]; /* some inverted */
        sw_svd3(A, U0, s0, V0);
        /* start from the V of a perturbed matrix (near), or of an unrelated one (far) */
        for (int i = 0; i < 9; ++i)
            B[i] = trial % 2 ? A[i] + 1e-3 * (double)((i * 7 + trial) % 5) : A[8 - i];
        double Ub[9], sb[3], Vb[9];
        sw_svd3(B, Ub, sb, Vb);
        sw_svd3_warm(A, Vb, U, s, V);
        double scale = fabs(s0[0]) + 1e-300;
        for (int k = 0; k < 3; ++k)
            ENSURE_NEAR(s[k], s0[k], 1e-12 * scale);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double r = 0;
                for (int k = 0; k < 3; ++k)
                    r += U[3 * i + k] * s[k] * V[3 * j + k];
                ENSURE_NEAR(r, A[3 * i + j], 1e-13 * scale);
            }
        ENSURE_NEAR(det3(U), 1.0, 1e-12);
        ENSURE_NEAR(det3(V), 1.0, 1e-12);
    }
}

/* The Newton polar iteration gives sw_polar3's rotation wherever it accepts a matrix:
 * random ones, stretches up to 20x, near-rotations with clustered singular values; it
 * declines inverted, flat, non-finite and hugely stretched matrices (the caller then
 * takes the SVD), and leaves R untouched when it does. */
TEST(polar_newton_matches_the_svd_polar_factor) {
    int accepted = 0, declined = 0;
    for (int t = 0; t < 6000; ++t) {
        double A[9], R[9], R0[9];
        if (t % 3 == 0) {
            for (int i = 0; i < 9; ++i)
                A[i] = urand();
        } else if (t % 3 == 1) { /* strain up to 20x either way */
            double d[3];
            for (int i = 0; i < 3; ++i)
                d[i] = pow(20.0, urand());
            compose(d, A);
        } else { /* near rest: a rotation times I + 1e-3 noise (clustered) */
            double d[3] = {1.0 + 1e-3 * urand(), 1.0 + 1e-3 * urand(), 1.0 + 1e-3 * urand()};
            compose(d, A);
        }
        sw_polar3(A, R0, NULL);
        for (int i = 0; i < 9; ++i)
            R[i] = 7.0;
        if (!sw_polar3_newton(A, R)) {
            ENSURE(det3(A) <= 1e-6 * pow(fro(A) / sqrt(3.0), 3.0) * (1 + 1e-12) || t % 3 != 2);
            for (int i = 0; i < 9; ++i)
                ENSURE(R[i] == 7.0);
            ++declined;
            continue;
        }
        ++accepted;
        ENSURE(det3(A) > 0.0);
        for (int i = 0; i < 9; ++i)
            ENSURE_NEAR(R[i], R0[i], 1e-13);
    }
    ENSURE(accepted > 3000 && declined > 500); /* both branches were exercised */
    double flat[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1e-9}, inv[9] = {1, 0, 0, 0, 1, 0, 0, 0, -0.5};
    double nan_m[9] = {1, 0, 0, 0, NAN, 0, 0, 0, 1}, R[9];
    ENSURE(!sw_polar3_newton(flat, R));
    ENSURE(!sw_polar3_newton(inv, R));
    ENSURE(!sw_polar3_newton(nan_m, R));
}

SW_TEST_MAIN(CASE(polar_newton_matches_the_svd_polar_factor),
             CASE(warm_start_gives_the_same_decomposition), CASE(random_matrices),
             CASE(inverted_matrices_flip_only_the_smallest), CASE(rank_deficient_matrices),
             CASE(repeated_singular_values), CASE(near_degenerate_and_extreme_scales),
             CASE(zero_and_non_finite), CASE(polar_decomposition))
