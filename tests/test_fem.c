/* Co-rotational tet kernels (thesis eq. 2.3): finite-difference checks of forces and the
 * exact Hessian on well-shaped, strongly deformed and inverted elements; the McAdams
 * projection (symmetric, PSD, exact when the exact Hessian is already PSD); rigid-motion
 * invariance; a multi-element patch test; closed-form energies; rest data and mass. */
#include "fem_corot.h"
#include "svd3.h"
#include "dqs.h"
#include "sw_test.h"

#include <stdint.h>

static uint64_t rng_state = 0x2545f4914f6cdd1dull;

/* splitmix64 -> uniform in [-1, 1). */
static double urand(void) {
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* Worst relative finite-difference errors seen, printed at the end of each FD test. */
static double worst_force_err = 0, worst_hess_err = 0;

typedef struct {
    double mu, lambda;
} material;

static const material materials[] = {
    {2314.8148148148148, 440.91710758377425}, /* the thesis hand: E = 5000, nu = 0.08 */
    {0.3448275862068966, 3.1034482758620690}, /* E = 1, nu = 0.45: nearly incompressible */
    {1.0, 0.0},
};
enum { NMAT = sizeof materials / sizeof materials[0] };

static void random_rotation(double R[9]) {
    double q[4], n;
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

static void mat_mul(const double A[9], const double B[9], double C[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* Ra diag(d) Rb^T with random rotations. */
static void random_with_singular_values(const double d[3], double F[9]) {
    double Ra[9], Rb[9], T[9];
    random_rotation(Ra);
    random_rotation(Rb);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] = Ra[3 * i + j] * d[j];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            F[3 * i + j] =
                T[3 * i] * Rb[3 * j] + T[3 * i + 1] * Rb[3 * j + 1] + T[3 * i + 2] * Rb[3 * j + 2];
}

/* x_n = A X_n + b for the four vertices. */
static void affine(const double A[9], const double b[3], const double X[12], double x[12]) {
    for (int n = 0; n < 4; ++n)
        for (int c = 0; c < 3; ++c)
            x[3 * n + c] = A[3 * c] * X[3 * n] + A[3 * c + 1] * X[3 * n + 1] +
                           A[3 * c + 2] * X[3 * n + 2] + b[c];
}

/* A random well-shaped rest tet of size ~L: a jittered regular tet, randomly rotated,
 * randomly oriented (either vertex order), anywhere in space. */
static void random_rest_tet(double L, double X[12]) {
    static const double reg[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
    double R[9], P[12], b[3] = {5 * urand(), 5 * urand(), 5 * urand()};
    random_rotation(R);
    for (int i = 0; i < 12; ++i)
        P[i] = 0.5 * L * (reg[i] + 0.25 * urand());
    if (urand() < 0) /* swap two vertices: negative rest orientation */
        for (int c = 0; c < 3; ++c) {
            double t = P[3 + c];
            P[3 + c] = P[6 + c];
            P[6 + c] = t;
        }
    affine(R, b, P, X);
}

static double norm(const double *v, int n) {
    double s = 0;
    for (int i = 0; i < n; ++i)
        s += v[i] * v[i];
    return sqrt(s);
}

/* Relative error of f against central differences of the energy. */
static double fd_force_error(const double x[12], const double DmInv[9], double vol, material m,
                             double h) {
    double f[12], fd[12], y[12];
    sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, NULL, 0);
    for (int i = 0; i < 12; ++i) {
        memcpy(y, x, sizeof y);
        y[i] = x[i] + h;
        double ep = sw_corot_eval(y, DmInv, vol, m.mu, m.lambda, NULL, NULL, 0);
        y[i] = x[i] - h;
        double em = sw_corot_eval(y, DmInv, vol, m.mu, m.lambda, NULL, NULL, 0);
        fd[i] = -(ep - em) / (2 * h);
    }
    double d[12];
    for (int i = 0; i < 12; ++i)
        d[i] = f[i] - fd[i];
    return norm(d, 12) / norm(f, 12);
}

/* Relative (Frobenius) error of the exact Hessian against central differences of f. */
static double fd_hessian_error(const double x[12], const double DmInv[9], double vol, material m,
                               double h) {
    double K[144], D[144], fp[12], fm[12], y[12];
    sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, NULL, K, 0);
    for (int i = 0; i < 12; ++i) {
        memcpy(y, x, sizeof y);
        y[i] = x[i] + h;
        sw_corot_eval(y, DmInv, vol, m.mu, m.lambda, fp, NULL, 0);
        y[i] = x[i] - h;
        sw_corot_eval(y, DmInv, vol, m.mu, m.lambda, fm, NULL, 0);
        for (int j = 0; j < 12; ++j)
            D[12 * j + i] = K[12 * j + i] + (fp[j] - fm[j]) / (2 * h);
    }
    return norm(D, 144) / norm(K, 144);
}

/* Singular values of F = Ds Dm^-1 at x (to keep FD samples off the kink s1 + s2 = 0). */
static void singular_values_at(const double x[12], const double DmInv[9], double s[3]) {
    double Ds[9], F[9], U[9], V[9];
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            Ds[3 * a + k] = x[3 * (k + 1) + a] - x[a];
    mat_mul(Ds, DmInv, F);
    sw_svd3(F, U, s, V);
}

/* Runs both FD checks on one element; returns 0 on failure (after printing). */
static int fd_check(const double x[12], const double X[12], double L, material m, const char *what,
                    int t) {
    double DmInv[9], vol;
    if (!sw_tet_rest(X, DmInv, &vol)) return 0;
    double h = 1e-6 * L;
    double ef = fd_force_error(x, DmInv, vol, m, h);
    double eh = fd_hessian_error(x, DmInv, vol, m, h);
    if (ef > worst_force_err) worst_force_err = ef;
    if (eh > worst_hess_err) worst_hess_err = eh;
    if (!(ef <= 1e-5 && eh <= 1e-5)) {
        double s[3];
        singular_values_at(x, DmInv, s);
        fprintf(stderr, "  %s case %d: force err %g, hessian err %g, s = %g %g %g\n", what, t, ef,
                eh, s[0], s[1], s[2]);
        return 0;
    }
    return 1;
}

TEST(fd_well_shaped_elements) {
    for (int t = 0; t < 600; ++t) {
        double L = exp(2.0 * urand()), X[12], x[12], R[9], b[3] = {urand(), urand(), urand()};
        random_rest_tet(L, X);
        random_rotation(R);
        affine(R, b, X, x);
        for (int i = 0; i < 12; ++i)
            x[i] += 0.1 * L * urand();
        ENSURE(fd_check(x, X, L, materials[t % NMAT], "well-shaped", t));
    }
    fprintf(stderr, "  max FD relative error so far: force %.3g, hessian %.3g\n", worst_force_err,
            worst_hess_err);
}

TEST(fd_strongly_deformed_elements) {
    int checked = 0, inverted = 0;
    for (int t = 0; t < 1500; ++t) {
        double L = exp(2.0 * urand()), X[12], x[12], DmInv[9], vol, s[3];
        random_rest_tet(L, X);
        for (int i = 0; i < 12; ++i)
            x[i] = X[i] + 0.8 * L * urand();
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        singular_values_at(x, DmInv, s);
        /* Stay off the kink s1 + s2 = 0, where R (hence the Hessian) is not smooth. */
        if (s[1] + s[2] < 0.05 * s[0]) continue;
        checked++;
        inverted += s[2] < 0;
        ENSURE(fd_check(x, X, L, materials[t % NMAT], "deformed", t));
    }
    ENSUREF(checked > 1000 && inverted > 100, "checked %d, inverted %d", checked, inverted);
    fprintf(stderr,
            "  %d elements (%d inverted); max FD relative error so far: force %.3g, "
            "hessian %.3g\n",
            checked, inverted, worst_force_err, worst_hess_err);
}

TEST(fd_inverted_elements) {
    for (int t = 0; t < 800; ++t) {
        double L = exp(2.0 * urand()), X[12], x[12], F[9], b[3] = {urand(), urand(), urand()};
        /* Signed singular values with s2 < 0 and s1 + s2 > 0: an inverted element. */
        double s1 = 0.3 + 1.5 * (urand() + 1);
        double d[3] = {s1 + 2 * (urand() + 1), s1, -(0.9 * (urand() + 1) / 2) * s1};
        if (t % 5 == 0) d[0] = d[1]; /* repeated singular values */
        random_with_singular_values(d, F);
        random_rest_tet(L, X);
        affine(F, b, X, x);
        double DmInv[9], vol, s[3];
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        singular_values_at(x, DmInv, s);
        ENSURE(s[2] < 0);
        ENSURE(fd_check(x, X, L, materials[t % NMAT], "inverted", t));
    }
    fprintf(stderr, "  max FD relative error: force %.3g, hessian %.3g\n", worst_force_err,
            worst_hess_err);
}

/* Eigenvalues of a symmetric 12x12 matrix by cyclic Jacobi, ascending. */
static void sym_eigenvalues(const double K[144], double ev[12]) {
    double A[144];
    memcpy(A, K, sizeof A);
    double total = norm(K, 144);
    for (int sweep = 0; sweep < 100; ++sweep) {
        double off = 0;
        for (int p = 0; p < 12; ++p)
            for (int q = 0; q < 12; ++q)
                if (p != q) off += A[12 * p + q] * A[12 * p + q];
        if (sqrt(off) <= 1e-17 * total) break;
        for (int p = 0; p < 11; ++p)
            for (int q = p + 1; q < 12; ++q) {
                double apq = A[12 * p + q];
                if (apq == 0) continue;
                double theta = (A[12 * q + q] - A[12 * p + p]) / (2 * apq);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 12; ++k) {
                    double akp = A[12 * k + p], akq = A[12 * k + q];
                    A[12 * k + p] = c * akp - s * akq;
                    A[12 * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < 12; ++k) {
                    double apk = A[12 * p + k], aqk = A[12 * q + k];
                    A[12 * p + k] = c * apk - s * aqk;
                    A[12 * q + k] = s * apk + c * aqk;
                }
            }
    }
    for (int i = 0; i < 12; ++i)
        ev[i] = A[13 * i];
    for (int i = 1; i < 12; ++i)
        for (int j = i; j > 0 && ev[j] < ev[j - 1]; --j) {
            double tmp = ev[j];
            ev[j] = ev[j - 1];
            ev[j - 1] = tmp;
        }
}

TEST(eigen_helper_is_correct) {
    /* The test's own Jacobi: a known spectrum Q diag(1..12) Q^T via Givens products. */
    double K[144] = {0}, ev[12];
    for (int i = 0; i < 12; ++i)
        K[13 * i] = i + 1 - 4.5;
    for (int r = 0; r < 40; ++r) {
        int p = r % 12, q = (5 * r + 3) % 12;
        if (p == q) continue;
        double a = urand(), c = cos(a), s = sin(a);
        for (int k = 0; k < 12; ++k) {
            double x = K[12 * k + p], y = K[12 * k + q];
            K[12 * k + p] = c * x - s * y;
            K[12 * k + q] = s * x + c * y;
        }
        for (int k = 0; k < 12; ++k) {
            double x = K[12 * p + k], y = K[12 * q + k];
            K[12 * p + k] = c * x - s * y;
            K[12 * q + k] = s * x + c * y;
        }
    }
    sym_eigenvalues(K, ev);
    for (int i = 0; i < 12; ++i)
        ENSURE_NEAR(ev[i], i + 1 - 4.5, 1e-12);
}

/* A random element in one of several regimes: near rest, stretched, compressed,
 * strongly deformed, inverted, flattened. */
static void random_element(int t, double L, double X[12], double x[12]) {
    double F[9], b[3] = {urand(), urand(), urand()};
    random_rest_tet(L, X);
    switch (t % 5) {
    case 0: {
        double d[3] = {1 + 0.01 * urand(), 1 + 0.01 * urand(), 1 + 0.01 * urand()};
        random_with_singular_values(d, F);
    } break;
    case 1: {
        double d[3] = {0.3 + urand(), 1 + 0.5 * urand(), 0.5 + 0.4 * urand()};
        random_with_singular_values(d, F);
    } break;
    case 2:
        for (int i = 0; i < 9; ++i)
            F[i] = urand();
        break;
    case 3: {
        double d[3] = {1.5 + urand(), 1 + 0.5 * urand(), -0.3 * (urand() + 1)};
        random_with_singular_values(d, F);
    } break;
    default: {
        double d[3] = {1 + 0.5 * urand(), 0.5 + 0.4 * urand(), 1e-9 * urand()};
        random_with_singular_values(d, F);
    } break;
    }
    affine(F, b, X, x);
}

TEST(projected_hessian_is_symmetric_psd) {
    int indefinite = 0;
    for (int t = 0; t < 1500; ++t) {
        double L = exp(urand()), X[12], x[12], DmInv[9], vol, K[144], Kx[144], ev[12], f[12], g[12];
        const material m = materials[t % NMAT];
        random_element(t, L, X, x);
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        double E = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, K, SW_COROT_PROJECT_PSD);
        double E2 = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, g, Kx, 0);
        ENSURE(E == E2); /* the flag only changes the Hessian */
        for (int i = 0; i < 12; ++i)
            ENSURE(f[i] == g[i]);
        for (int i = 0; i < 144; ++i)
            ENSURE(isfinite(K[i]));
        for (int i = 0; i < 12; ++i)
            for (int j = 0; j < 12; ++j)
                ENSURE(K[12 * i + j] == K[12 * j + i]);
        double nk = norm(K, 144);
        sym_eigenvalues(K, ev);
        ENSUREF(ev[0] >= -1e-9 * nk, "case %d: min eigenvalue %g, |K| %g", t, ev[0], nk);
        sym_eigenvalues(Kx, ev);
        indefinite += ev[0] < -1e-6 * norm(Kx, 144);
    }
    /* The sample must include elements the projection actually had to fix. */
    ENSUREF(indefinite > 100, "only %d indefinite exact Hessians", indefinite);
}

TEST(projection_is_identity_on_psd_hessians) {
    int psd = 0, not_psd = 0;
    for (int t = 0; t < 1000; ++t) {
        double L = exp(urand()), X[12], x[12], F[9], DmInv[9], vol, K[144], Kp[144], ev[12];
        const material m = materials[t % NMAT];
        random_rest_tet(L, X);
        /* Small deformations near rest: stretches (PSD) and compressions (twist modes go
         * negative), with an arbitrary rotation on top. */
        double a = 0.05 * urand(), d[3] = {1 + a + 0.01 * urand(), 1 + a, 1 + a - 0.01 * urand()};
        double b[3] = {urand(), urand(), urand()};
        random_with_singular_values(d, F);
        affine(F, b, X, x);
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, NULL, K, 0);
        sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, NULL, Kp, SW_COROT_PROJECT_PSD);
        double nk = norm(K, 144), diff[144];
        sym_eigenvalues(K, ev);
        for (int i = 0; i < 144; ++i)
            diff[i] = K[i] - Kp[i];
        if (ev[0] >= -1e-12 * nk) {
            psd++;
            ENSUREF(norm(diff, 144) <= 1e-12 * nk, "case %d: |K - Kp| = %g, |K| = %g", t,
                    norm(diff, 144), nk);
        } else {
            not_psd++;
            ENSURE(norm(diff, 144) > 1e-12 * nk); /* the projection did something */
        }
    }
    ENSUREF(psd > 200 && not_psd > 200, "psd %d, not psd %d", psd, not_psd);
}

TEST(rigid_motion_gives_zero_force_and_six_zero_modes) {
    for (int t = 0; t < 300; ++t) {
        double L = exp(2.0 * urand()), X[12], x[12], R[9], DmInv[9], vol, f[12], K[144], ev[12];
        double b[3] = {10 * urand(), 10 * urand(), 10 * urand()};
        const material m = materials[t % NMAT];
        random_rest_tet(L, X);
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        random_rotation(R);
        if (t == 0) memcpy(R, (double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, sizeof R);
        affine(R, b, X, x);
        /* Force scale: what a unit strain would produce. */
        double fscale = vol * (2 * m.mu + fabs(m.lambda)) * norm(DmInv, 9);
        for (int flags = 0; flags < 2; ++flags) {
            double E = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, K, (uint32_t)flags);
            ENSUREF(fabs(E) <= 1e-20 * vol * (2 * m.mu + fabs(m.lambda)), "case %d: E = %g", t, E);
            ENSUREF(norm(f, 12) <= 1e-10 * fscale, "case %d: |f| = %g vs %g", t, norm(f, 12),
                    fscale);
            /* K annihilates the 3 translations and the 3 rotations about the centroid of
             * the rotated configuration. */
            double nk = norm(K, 144), c[3] = {0, 0, 0};
            for (int n = 0; n < 4; ++n)
                for (int k = 0; k < 3; ++k)
                    c[k] += 0.25 * x[3 * n + k];
            for (int mode = 0; mode < 6; ++mode) {
                double v[12], Kv[12];
                for (int n = 0; n < 4; ++n) {
                    double r[3] = {x[3 * n] - c[0], x[3 * n + 1] - c[1], x[3 * n + 2] - c[2]};
                    for (int k = 0; k < 3; ++k)
                        v[3 * n + k] = (mode == k) ? 1.0 : 0.0;
                    if (mode >= 3) { /* omega = e_(mode-3): omega x r */
                        int a = mode - 3, p = (a + 1) % 3, q = (a + 2) % 3;
                        v[3 * n + a] = 0;
                        v[3 * n + p] = -r[q];
                        v[3 * n + q] = r[p];
                    }
                }
                for (int i = 0; i < 12; ++i) {
                    Kv[i] = 0;
                    for (int j = 0; j < 12; ++j)
                        Kv[i] += K[12 * i + j] * v[j];
                }
                ENSUREF(norm(Kv, 12) <= 1e-10 * nk * norm(v, 12), "case %d mode %d: %g", t, mode,
                        norm(Kv, 12) / (nk * norm(v, 12)));
            }
            /* Exactly six zero eigenvalues; the other six clearly positive. */
            sym_eigenvalues(K, ev);
            for (int i = 0; i < 6; ++i)
                ENSUREF(fabs(ev[i]) <= 1e-10 * nk, "case %d: ev[%d] = %g (|K| %g)", t, i, ev[i],
                        nk);
            for (int i = 6; i < 12; ++i)
                ENSUREF(ev[i] >= 1e-4 * nk, "case %d: ev[%d] = %g (|K| %g)", t, i, ev[i], nk);
        }
    }
}

TEST(forces_are_free_of_net_force_and_torque) {
    for (int t = 0; t < 1000; ++t) {
        double L = exp(urand()), X[12], x[12], DmInv[9], vol, f[12];
        const material m = materials[t % NMAT];
        random_element(t, L, X, x);
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, NULL, 0);
        double sum[3] = {0, 0, 0}, torque[3] = {0, 0, 0}, fbig = norm(f, 12), xmax = 0;
        for (int n = 0; n < 4; ++n) {
            const double *p = x + 3 * n, *q = f + 3 * n;
            for (int k = 0; k < 3; ++k)
                sum[k] += q[k];
            torque[0] += p[1] * q[2] - p[2] * q[1];
            torque[1] += p[2] * q[0] - p[0] * q[2];
            torque[2] += p[0] * q[1] - p[1] * q[0];
            xmax = fmax(xmax, norm(p, 3));
        }
        ENSUREF(norm(sum, 3) <= 1e-12 * fbig, "case %d: net force %g", t, norm(sum, 3));
        ENSUREF(norm(torque, 3) <= 1e-12 * fbig * xmax, "case %d: net torque %g", t,
                norm(torque, 3));
    }
}

/* Energy E = vol Psi for F = diag(1 + e, 1, 1): Psi = (mu + lambda/2) e^2, also through
 * inversion (e < -1: the flipped singular value keeps R = I). */
TEST(energy_matches_closed_form_for_uniaxial_stretch) {
    const double es[] = {0.0, 1e-3, 0.1, -0.2, 0.5, -1.0, -1.5, 2.0};
    for (int k = 0; k < (int)(sizeof es / sizeof es[0]); ++k)
        for (int mi = 0; mi < NMAT; ++mi) {
            double X[12], x[12], DmInv[9], vol, b[3] = {0.5, -2, 3};
            double F[9] = {1 + es[k], 0, 0, 0, 1, 0, 0, 0, 1};
            const material m = materials[mi];
            random_rest_tet(1.3, X);
            ENSURE(sw_tet_rest(X, DmInv, &vol));
            affine(F, b, X, x);
            double E = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, NULL, NULL, 0);
            double expect = vol * (m.mu + 0.5 * m.lambda) * es[k] * es[k];
            ENSUREF(fabs(E - expect) <= 1e-12 * (fabs(expect) + vol * m.mu),
                    "e = %g: E = %.17g, expected %.17g", es[k], E, expect);
        }
    /* A general F: Psi from the polar decomposition, computed independently. */
    for (int t = 0; t < 200; ++t) {
        double X[12], x[12], DmInv[9], vol, F[9], R[9], b[3] = {0, 0, 0};
        const material m = materials[t % NMAT];
        for (int i = 0; i < 9; ++i)
            F[i] = urand() + (i % 4 == 0);
        random_rest_tet(0.7, X);
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        affine(F, b, X, x);
        sw_polar3(F, R, NULL);
        double fr = 0, tr = -3;
        for (int i = 0; i < 9; ++i)
            fr += (F[i] - R[i]) * (F[i] - R[i]);
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k)
                tr += R[3 * k + i] * F[3 * k + i];
        double expect = vol * (m.mu * fr + 0.5 * m.lambda * tr * tr); /* eq. 2.3 */
        double E = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, NULL, NULL, 0);
        ENSUREF(fabs(E - expect) <= 1e-11 * (fabs(expect) + vol * m.mu), "case %d: %g vs %g", t, E,
                expect);
    }
}

/* A 2x2x2 block of unit cubes, each split into the six Kuhn tets (a conforming mesh of
 * 48 tets, both orientations) with one interior vertex, index 13. */
enum { GRID_NV = 27, GRID_NT = 48 };
static void grid_mesh(double V[GRID_NV * 3], int32_t T[GRID_NT][4]) {
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) {
                int v = i + 3 * j + 9 * k;
                V[3 * v] = i;
                V[3 * v + 1] = j;
                V[3 * v + 2] = k;
            }
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int nt = 0;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
                for (int p = 0; p < 6; ++p) {
                    int c[3] = {i, j, k};
                    T[nt][0] = c[0] + 3 * c[1] + 9 * c[2];
                    for (int s = 0; s < 3; ++s) {
                        c[perms[p][s]]++;
                        T[nt][s + 1] = c[0] + 3 * c[1] + 9 * c[2];
                    }
                    nt++;
                }
}

TEST(patch_test_uniform_stress) {
    double V[GRID_NV * 3];
    int32_t T[GRID_NT][4];
    grid_mesh(V, T);
    for (int t = 0; t < 40; ++t) {
        const material m = materials[t % NMAT];
        double A[9], b[3] = {urand(), urand(), urand()};
        for (int i = 0; i < 9; ++i)
            A[i] = 0.4 * urand() + (i % 4 == 0);
        if (t % 4 == 3) { /* inverted: mirror one axis */
            A[0] = -A[0];
            A[3] = -A[3];
            A[6] = -A[6];
        }
        double Pref[9], R[9], force[GRID_NV * 3] = {0}, fbig = 0;
        /* The expected stress: P = 2mu(F - R) + lambda tr(R^T F - I) R, from the polar
         * decomposition (independent of the kernel's SVD-space formula). */
        sw_polar3(A, R, NULL);
        double tr = -3;
        for (int i = 0; i < 9; ++i)
            tr += R[i] * A[i];
        for (int i = 0; i < 9; ++i)
            Pref[i] = 2 * m.mu * (A[i] - R[i]) + m.lambda * tr * R[i];
        for (int e = 0; e < GRID_NT; ++e) {
            double X[12], x[12], DmInv[9], vol, f[12], Ds[9], F[9], Dm[9], P[9];
            for (int n = 0; n < 4; ++n)
                for (int c = 0; c < 3; ++c)
                    X[3 * n + c] = V[3 * T[e][n] + c];
            ENSURE(sw_tet_rest(X, DmInv, &vol));
            ENSURE_NEAR(vol, 1.0 / 6.0, 1e-15);
            affine(A, b, X, x);
            for (int a = 0; a < 3; ++a)
                for (int k = 0; k < 3; ++k) {
                    Ds[3 * a + k] = x[3 * (k + 1) + a] - x[a];
                    Dm[3 * a + k] = X[3 * (k + 1) + a] - X[a];
                }
            mat_mul(Ds, DmInv, F);
            for (int i = 0; i < 9; ++i)
                ENSURE_NEAR(F[i], A[i], 1e-14);
            sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, NULL, 0);
            /* Recover the element's P from its nodal forces: [f1 f2 f3] = -vol P Dm^-T. */
            for (int c = 0; c < 3; ++c)
                for (int j = 0; j < 3; ++j) {
                    P[3 * c + j] = 0;
                    for (int k = 0; k < 3; ++k)
                        P[3 * c + j] -= f[3 * (k + 1) + c] * Dm[3 * j + k];
                    P[3 * c + j] /= vol;
                }
            for (int i = 0; i < 9; ++i)
                ENSUREF(fabs(P[i] - Pref[i]) <= 1e-12 * (norm(Pref, 9) + m.mu),
                        "case %d tet %d: P[%d] = %.17g, expected %.17g", t, e, i, P[i], Pref[i]);
            for (int n = 0; n < 4; ++n)
                for (int c = 0; c < 3; ++c)
                    force[3 * T[e][n] + c] += f[3 * n + c];
            fbig = fmax(fbig, norm(f, 12));
        }
        /* Uniform stress: the interior vertex is in equilibrium. */
        ENSUREF(norm(force + 3 * 13, 3) <= 1e-12 * fbig, "case %d: interior force %g (max %g)", t,
                norm(force + 3 * 13, 3), fbig);
        /* And the boundary is not (the test is not vacuous). */
        ENSURE(norm(force, 3) > 1e-3 * fbig);
    }
}

TEST(rest_data_and_lumped_mass) {
    double V[GRID_NV * 3], mass[GRID_NV] = {0}, total = 0;
    int32_t T[GRID_NT][4];
    grid_mesh(V, T);
    int negative = 0;
    for (int e = 0; e < GRID_NT; ++e) {
        double X[12], DmInv[9], vol;
        for (int n = 0; n < 4; ++n)
            for (int c = 0; c < 3; ++c)
                X[3 * n + c] = V[3 * T[e][n] + c];
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        double Dm[9], I[9];
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k < 3; ++k)
                Dm[3 * a + k] = X[3 * (k + 1) + a] - X[a];
        mat_mul(Dm, DmInv, I);
        for (int i = 0; i < 9; ++i)
            ENSURE_NEAR(I[i], i % 4 == 0, 1e-15);
        double det = Dm[0] * (Dm[4] * Dm[8] - Dm[5] * Dm[7]) -
                     Dm[1] * (Dm[3] * Dm[8] - Dm[5] * Dm[6]) +
                     Dm[2] * (Dm[3] * Dm[7] - Dm[4] * Dm[6]);
        negative += det < 0;
        ENSURE(vol > 0);
        total += vol;
        sw_lumped_mass_add(T[e], 2.5, vol, mass);
    }
    ENSURE(negative > 0 && negative < GRID_NT); /* both orientations were exercised */
    ENSURE_NEAR(total, 8.0, 1e-13);
    double msum = 0;
    for (int v = 0; v < GRID_NV; ++v)
        msum += mass[v];
    ENSURE_NEAR(msum, 2.5 * 8.0, 1e-12);
    ENSURE_NEAR(mass[13], 2.5 * 24 / 6.0 / 4.0, 1e-14); /* interior vertex: in 24 tets */
    ENSURE_NEAR(mass[0], 2.5 * 6 / 6.0 / 4.0, 1e-15);   /* corner (0,0,0): on 6 Kuhn tets */
    ENSURE_NEAR(mass[2], 2.5 * 2 / 6.0 / 4.0, 1e-15);   /* corner (2,0,0): on 2 */

    /* Degenerate rest tets are refused and leave the outputs untouched. */
    double DmInv[9] = {7, 7, 7, 7, 7, 7, 7, 7, 7}, vol = 7;
    double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    double point[12] = {1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3};
    double nan_tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN};
    double inf_tet[12] = {0, 0, 0, INFINITY, 0, 0, 0, 1, 0, 0, 0, 1};
    double tiny[12] = {0, 0, 0, 1e-110, 0, 0, 0, 1e-110, 0, 0, 0, 1e-110};
    ENSURE(!sw_tet_rest(flat, DmInv, &vol));
    ENSURE(!sw_tet_rest(point, DmInv, &vol));
    ENSURE(!sw_tet_rest(nan_tet, DmInv, &vol));
    ENSURE(!sw_tet_rest(inf_tet, DmInv, &vol));
    ENSURE(!sw_tet_rest(tiny, DmInv, &vol)); /* det 1e-330 < 1e-300 */
    for (int i = 0; i < 9; ++i)
        ENSURE(DmInv[i] == 7);
    ENSURE(vol == 7);
}

TEST(lame_parameters) {
    double mu, lambda;
    sw_lame(5000, 0.08, &mu, &lambda);
    ENSURE_NEAR(mu, 5000 / 2.16, 1e-9);
    ENSURE_NEAR(lambda, 400 / (1.08 * 0.84), 1e-9);
    ENSURE_NEAR(mu, materials[0].mu, 1e-9);
    ENSURE_NEAR(lambda, materials[0].lambda, 1e-9);
    sw_lame(1, 0.45, &mu, &lambda);
    ENSURE_NEAR(mu, materials[1].mu, 1e-12);
    ENSURE_NEAR(lambda, materials[1].lambda, 1e-12);
    sw_lame(7, 0, &mu, &lambda);
    ENSURE(mu == 3.5 && lambda == 0);
}

TEST(degenerate_deformations_stay_finite) {
    /* Collapsed to a point, flattened, and exactly on the kink s1 + s2 = 0. */
    double X[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, DmInv[9], vol;
    ENSURE(sw_tet_rest(X, DmInv, &vol));
    const double Fs[][9] = {{0, 0, 0, 0, 0, 0, 0, 0, 0},   {1, 0, 0, 0, 1, 0, 0, 0, 0},
                            {1, 0, 0, 0, 0, 0, 0, 0, 0},   {1, 0, 0, 0, 1, 0, 0, 0, -1},
                            {1, 0, 0, 0, -1, 0, 0, 0, -1}, {2, 0, 0, 0, 1, 0, 0, 0, -1}};
    for (int k = 0; k < (int)(sizeof Fs / sizeof Fs[0]); ++k)
        for (int flags = 0; flags < 2; ++flags) {
            double x[12], f[12], K[144], ev[12], b[3] = {1, 2, 3};
            affine(Fs[k], b, X, x);
            const material m = materials[k % NMAT];
            double E = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f, K, (uint32_t)flags);
            ENSURE(isfinite(E) && E >= 0);
            for (int i = 0; i < 12; ++i)
                ENSURE(isfinite(f[i]));
            for (int i = 0; i < 144; ++i)
                ENSURE(isfinite(K[i]));
            if (flags) {
                sym_eigenvalues(K, ev);
                ENSUREF(ev[0] >= -1e-9 * norm(K, 144), "F %d: min eigenvalue %g", k, ev[0]);
            }
        }
    /* Collapsed to a point: every singular value is 0, Psi = 3 mu + 9 lambda / 2. */
    double x[12] = {0};
    double E = sw_corot_eval(x, DmInv, vol, 2.0, 3.0, NULL, NULL, 0);
    ENSURE_NEAR(E, vol * (3 * 2.0 + 4.5 * 3.0), 1e-14);
}

TEST(outputs_are_optional_and_consistent) {
    double X[12], x[12], DmInv[9], vol, f1[12], f2[12], K1[144], K2[144];
    random_element(1, 1.0, X, x);
    ENSURE(sw_tet_rest(X, DmInv, &vol));
    double e0 = sw_corot_eval(x, DmInv, vol, 3, 4, NULL, NULL, 0);
    double e1 = sw_corot_eval(x, DmInv, vol, 3, 4, f1, NULL, 0);
    double e2 = sw_corot_eval(x, DmInv, vol, 3, 4, NULL, K1, 0);
    double e3 = sw_corot_eval(x, DmInv, vol, 3, 4, f2, K2, 0);
    /* e0, e1 without K (polar rotation), e2, e3 with it (SVD): equal within each pair,
     * equal to rounding across */
    ENSURE(e0 == e1 && e2 == e3 && e0 > 0);
    ENSURE_NEAR(e1, e2, 1e-12 * e2);
    for (int i = 0; i < 12; ++i)
        ENSURE_NEAR(f1[i], f2[i], 1e-10 * (norm(f2, 12) + 1e-300));
    for (int i = 0; i < 144; ++i)
        ENSURE(K1[i] == K2[i]);
}

/* The element through its SVD (sw_corot_eval_svd) and the modes in the singular frame
 * (sw_corot_modes_dot), as the step's cubature uses them: for every node coordinate,
 * E = dF/dx_(n,c) = e_c D_n^T in the singular frame gives g_k[3n + c] = <E, U M_k V^T> and
 * f[3n + c] = -vol <E, U diag(dPsi/ds) V^T>; sum_k w_k g_k g_k^T reproduces the assembled
 * K and f the forces (projected or not, with and without a warm start). */
TEST(hessian_modes_reproduce_K) {
    uint64_t seed = 77;
    for (int trial = 0; trial < 200; ++trial) {
        double X[12], x[12], Dm[9], vol;
        for (int i = 0; i < 12; ++i)
            X[i] = (double)((seed = seed * 6364136223846793005ull + 1) >> 11) * 0x1.0p-53;
        if (!sw_tet_rest(X, Dm, &vol)) continue;
        for (int i = 0; i < 12; ++i)
            x[i] = X[i] * (trial % 3 ? 1.0 : -0.5) +
                   0.3 * ((double)((seed = seed * 6364136223846793005ull + 1) >> 11) * 0x1.0p-53 -
                          0.5);
        double D[12];
        sw_tet_shape_gradients(Dm, D);
        for (uint32_t flags = 0; flags <= SW_COROT_PROJECT_PSD; ++flags) {
            double K[144], f1[12], f2[12], w[9], g[108], U[9], s[3], V[9], dpsi[3];
            double e1 = sw_corot_eval(x, Dm, vol, 1.0, 3.0, f1, K, flags);
            double Vc[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            double e2 = sw_corot_eval_svd(x, Dm, vol, 1.0, 3.0, trial % 2 ? Vc : NULL, flags, U, s,
                                          V, dpsi, w);
            ENSURE_NEAR(e1, e2, 1e-12 * (fabs(e1) + 1e-300));
            for (int n = 0; n < 4; ++n)
                for (int c = 0; c < 3; ++c) {
                    double Es[9], h[9]; /* U^T (e_c D_n^T) V: row c of U, D_n V */
                    for (int i = 0; i < 3; ++i)
                        for (int l = 0; l < 3; ++l)
                            Es[3 * i + l] =
                                U[3 * c + i] * (D[3 * n] * V[l] + D[3 * n + 1] * V[3 + l] +
                                                D[3 * n + 2] * V[6 + l]);
                    sw_corot_modes_dot(Es, h);
                    for (int k = 0; k < 9; ++k)
                        g[12 * k + 3 * n + c] = h[k];
                    f2[3 * n + c] = -vol * (dpsi[0] * Es[0] + dpsi[1] * Es[4] + dpsi[2] * Es[8]);
                }
            for (int i = 0; i < 12; ++i)
                ENSURE_NEAR(f1[i], f2[i], 1e-10 * (fabs(f1[i]) + 1.0));
            double scale = 0;
            for (int i = 0; i < 144; ++i)
                scale = fmax(scale, fabs(K[i]));
            for (int i = 0; i < 12; ++i)
                for (int j = 0; j < 12; ++j) {
                    double k = 0;
                    for (int m = 0; m < 9; ++m)
                        k += w[m] * g[12 * m + i] * g[12 * m + j];
                    ENSURE_NEAR(k, K[12 * i + j], 1e-12 * (scale + 1e-300));
                }
            if (flags)
                for (int m = 0; m < 9; ++m)
                    ENSURE(w[m] >= 0);
        }
    }
}

/* Without a Hessian the energy and forces come from the polar Newton rotation, with it
 * from the SVD (fem_corot.c): the two must be one function, to rounding, on elements
 * near rest, strongly deformed and inverted (where the polar path declines). */
TEST(polar_and_svd_paths_agree) {
    for (int t = 0; t < 3000; ++t) {
        double L = exp(2.0 * urand()), X[12], x[12], DmInv[9], vol;
        double amp = t % 3 == 0 ? 1e-3 : (t % 3 == 1 ? 0.1 : 0.8);
        random_rest_tet(L, X);
        double R[9], b[3] = {urand(), urand(), urand()};
        random_rotation(R);
        affine(R, b, X, x);
        for (int i = 0; i < 12; ++i)
            x[i] += amp * L * urand();
        ENSURE(sw_tet_rest(X, DmInv, &vol));
        material m = materials[t % NMAT];
        double f1[12], f2[12], K[144];
        double E1 = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f1, NULL, 0);
        double E2 = sw_corot_eval(x, DmInv, vol, m.mu, m.lambda, f2, K, 0);
        ENSURE_NEAR(E1, E2, 1e-11 * fabs(E2) + 1e-13 * vol * (m.mu + m.lambda) * amp * amp);
        double fs = norm(f2, 12) + 1e-12 * vol * (m.mu + m.lambda) / L;
        for (int i = 0; i < 12; ++i)
            ENSURE_NEAR(f1[i], f2[i], 1e-10 * fs);
    }
}

SW_TEST_MAIN(CASE(polar_and_svd_paths_agree), CASE(hessian_modes_reproduce_K),
             CASE(eigen_helper_is_correct), CASE(fd_well_shaped_elements),
             CASE(fd_strongly_deformed_elements), CASE(fd_inverted_elements),
             CASE(projected_hessian_is_symmetric_psd), CASE(projection_is_identity_on_psd_hessians),
             CASE(rigid_motion_gives_zero_force_and_six_zero_modes),
             CASE(forces_are_free_of_net_force_and_torque),
             CASE(energy_matches_closed_form_for_uniaxial_stretch), CASE(patch_test_uniform_stress),
             CASE(rest_data_and_lumped_mass), CASE(lame_parameters),
             CASE(degenerate_deformations_stay_finite), CASE(outputs_are_optional_and_consistent))
