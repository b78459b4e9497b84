/* Robust 3x3 SVD by one-sided (Hestenes) Jacobi: right-multiply A by plane rotations
 * until its columns are mutually orthogonal, A V = W; then sigma_i = |w_i| and
 * u_i = w_i / sigma_i. Working on A itself rather than on A^T A keeps small singular
 * values accurate (A^T A would square the condition number), which matters for the
 * co-rotational energy of nearly flat or inverted tets (thesis eq. 2.3).
 * U is completed by Gram-Schmidt and a cross product, so it is a rotation by
 * construction even for rank-deficient A; the sign of the last singular value then
 * absorbs det A (rotation-variant SVD, Irving et al. 2004).
 * No allocation, a fixed maximum number of sweeps, deterministic. */
#include "svd3.h"

#include "mat3.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

enum { SVD3_MAX_SWEEPS = 40 };

/* Columns of the (prescaled, max |entry| = 1) matrix shorter than this carry no usable
 * direction: their squares underflow. Their singular value is <= 1e-150 * max|A|. */
static const double SVD3_TINY = 1e-150;

/* Columns p, q of W and of V rotated by (c, s). */
static void rotate_columns(double W[9], double V[9], int p, int q, double c, double s) {
    for (int r = 0; r < 3; ++r) {
        double a = W[3 * r + p], b = W[3 * r + q];
        W[3 * r + p] = c * a - s * b;
        W[3 * r + q] = s * a + c * b;
        a = V[3 * r + p];
        b = V[3 * r + q];
        V[3 * r + p] = c * a - s * b;
        V[3 * r + q] = s * a + c * b;
    }
}

/* |w_p|^2, |w_q|^2 and w_p . w_q of columns p, q of W. */
static void column_products(const double W[9], int p, int q, double *alpha, double *beta,
                            double *gamma) {
    double aa = 0.0, bb = 0.0, ab = 0.0;
    for (int r = 0; r < 3; ++r) {
        double a = W[3 * r + p], b = W[3 * r + q];
        aa += a * a;
        bb += b * b;
        ab += a * b;
    }
    *alpha = aa;
    *beta = bb;
    *gamma = ab;
}

/* Rotates columns p, q of W (and V alike) so that w_p . w_q = 0. Returns 1 when a
 * rotation was applied, 0 when the pair was already orthogonal to working precision. */
static int orthogonalize_pair(double W[9], double V[9], int p, int q) {
    double alpha, beta, gamma;
    column_products(W, p, q, &alpha, &beta, &gamma);
    /* sqrt(alpha)*sqrt(beta), not sqrt(alpha*beta): the product may underflow. */
    if (!(fabs(gamma) > 1e-15 * sqrt(alpha) * sqrt(beta))) return 0;
    /* Smaller root of t^2 + 2 zeta t - 1 = 0: a rotation of at most 45 degrees. */
    double zeta = (beta - alpha) / (2.0 * gamma);
    double t = fabs(zeta) > 1e100
                   ? 0.5 / zeta
                   : (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
    double c = 1.0 / sqrt(1.0 + t * t), s = c * t;
    rotate_columns(W, V, p, q, c, s);
    return 1;
}

/* Off-orthogonality below which the warm Jacobi leaves a pair alone: |w_p . w_q| <=
 * 1e-15 |w_p| |w_q|, compared in squares. */
static const double SVD3_WARM_TOL2 = 1e-30;
/* A warm sweep whose pairs were all this close to orthogonal (relative |w_p . w_q|)
 * before their rotation ends the iteration: cyclic Jacobi converges quadratically, so
 * what is left after it is ~1e-16, below what another (checking) sweep would act on;
 * and where singular values cluster and it is not, R = U V^T is off by the residual
 * itself (its polar correction divides by s_i + s_j, not s_i - s_j), ~1e-8 at worst. */
static const double SVD3_WARM_LAST_SWEEP_TOL2 = 1e-16;

/* orthogonalize_pair for the warm start (the runtime's per-step elements, where the
 * SVD was a quarter of the step): no square root in the test and two, with one
 * division, in the rotation. Returns the squared relative off-orthogonality
 * gamma^2 / (alpha beta) the pair had, 0 when no rotation was applied. The cold SVD
 * (the full-space reference, the bake's training solves) keeps the textbook form above:
 * the bake's training set is sensitive to the last bits of its solves (a rounding-level
 * change moved the 20K finger's held-out error by 2-14%), so its bits stay as they were. */
static double orthogonalize_pair_warm(double W[9], double V[9], int p, int q) {
    double alpha, beta, gamma;
    column_products(W, p, q, &alpha, &beta, &gamma);
    double ab = alpha * beta, g2 = gamma * gamma;
    if (!(g2 > SVD3_WARM_TOL2 * ab)) return 0.0;
    /* tan = t the smaller root of gamma t^2 + d t - gamma = 0 (d = beta - alpha): with
     * h = sqrt(d^2 + 4 gamma^2) and u = |d| + h, t = 2 gamma sgn(d) / u, so
     * c = u / sqrt(u^2 + 4 gamma^2) and s = 2 gamma sgn(d) / sqrt(..), where
     * u^2 + 4 gamma^2 = 2 h u. After the prescaling d, gamma <= 3 in magnitude: no
     * overflow. Columns so short (< 1e-75) that 2 h u underflows hold singular values of
     * no consequence: left as they are. */
    double d = beta - alpha;
    double h = sqrt(d * d + 4.0 * gamma * gamma), u = fabs(d) + h;
    double hu2 = 2.0 * h * u;
    if (!(hu2 >= DBL_MIN)) return 0.0;
    double inv = 1.0 / sqrt(hu2);
    rotate_columns(W, V, p, q, u * inv, (d >= 0.0 ? 2.0 : -2.0) * gamma * inv);
    return ab > 0.0 ? g2 / ab : 1.0;
}

static void swap_columns(double M[9], int p, int q) {
    for (int r = 0; r < 3; ++r) {
        double t = M[3 * r + p];
        M[3 * r + p] = M[3 * r + q];
        M[3 * r + q] = t;
    }
}

/* A unit vector orthogonal to the unit vector u: cross with the axis u is least aligned
 * with, so the result is never short. */
static void any_orthogonal(const double u[3], double out[3]) {
    double ax = fabs(u[0]), ay = fabs(u[1]), az = fabs(u[2]);
    double e[3] = {0.0, 0.0, 0.0};
    e[(ax <= ay && ax <= az) ? 0 : (ay <= az ? 1 : 2)] = 1.0;
    sw_v3_cross(u, e, out);
    double n = sqrt(sw_v3_dot(out, out));
    for (int i = 0; i < 3; ++i)
        out[i] /= n;
}

/* The SVD with Jacobi started from the rotation V0 (NULL: identity). */
static void svd3(const double A[9], const double *V0, double U[9], double s[3], double V[9]) {
    /* Prescale so the largest entry is 1: no overflow in the squared norms. */
    double m = 0.0;
    int finite = 1;
    for (int i = 0; i < 9; ++i) {
        finite &= isfinite(A[i]) != 0;
        m = fmax(m, fabs(A[i]));
    }
    sw_m3_identity(U);
    sw_m3_identity(V);
    if (m == 0.0 || !finite) {
        /* Zero: any rotations will do. Non-finite: report it in s, do not hide it. */
        s[0] = s[1] = s[2] = finite ? 0.0 : NAN;
        return;
    }
    double W[9], Am[9];
    for (int i = 0; i < 9; ++i)
        Am[i] = A[i] / m;
    if (V0) { /* W = A V0: a good V0 leaves W nearly column-orthogonal already */
        for (int i = 0; i < 9; ++i)
            V[i] = V0[i];
        sw_m3_mul(Am, V0, W);
    } else {
        for (int i = 0; i < 9; ++i)
            W[i] = Am[i];
    }
    for (int sweep = 0; sweep < SVD3_MAX_SWEEPS; ++sweep) {
        if (V0) { /* three statements: the pairs must rotate in this order */
            double off = orthogonalize_pair_warm(W, V, 0, 1);
            off = fmax(off, orthogonalize_pair_warm(W, V, 0, 2));
            off = fmax(off, orthogonalize_pair_warm(W, V, 1, 2));
            if (off < SVD3_WARM_LAST_SWEEP_TOL2) break;
        } else {
            int rotated = orthogonalize_pair(W, V, 0, 1);
            rotated += orthogonalize_pair(W, V, 0, 2);
            rotated += orthogonalize_pair(W, V, 1, 2);
            if (!rotated) break;
        }
    }
    double n[3];
    for (int j = 0; j < 3; ++j)
        n[j] = sqrt(W[j] * W[j] + W[3 + j] * W[3 + j] + W[6 + j] * W[6 + j]);
    /* Sort columns by decreasing length (three compare-swaps). */
    static const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 1}};
    for (int k = 0; k < 3; ++k) {
        int p = pairs[k][0], q = pairs[k][1];
        if (n[q] > n[p]) {
            double t = n[p];
            n[p] = n[q];
            n[q] = t;
            swap_columns(W, p, q);
            swap_columns(V, p, q);
        }
    }
    double w[3][3], u[3][3];
    for (int j = 0; j < 3; ++j)
        for (int r = 0; r < 3; ++r)
            w[j][r] = W[3 * r + j];
    /* n[0] >= 1/sqrt(3) after prescaling, so u0 always has a direction. */
    for (int r = 0; r < 3; ++r)
        u[0][r] = w[0][r] / n[0];
    double d = 0.0;
    if (n[1] > SVD3_TINY) {
        double proj = sw_v3_dot(u[0], w[1]);
        for (int r = 0; r < 3; ++r)
            u[1][r] = w[1][r] - proj * u[0][r];
        d = sqrt(sw_v3_dot(u[1], u[1]));
    }
    if (d > SVD3_TINY) {
        for (int r = 0; r < 3; ++r)
            u[1][r] /= d;
    } else {
        any_orthogonal(u[0], u[1]); /* rank 1: sigma_1 is (numerically) zero */
    }
    sw_v3_cross(u[0], u[1], u[2]); /* det U = +1 by construction */
    /* w2 is orthogonal to w0, w1, hence parallel to u2: its signed length is sigma_2. */
    double s2 = sw_v3_dot(u[2], w[2]);
    if (sw_m3_det(V) < 0.0) {
        /* Make V proper too; the flip moves onto the last singular value. */
        for (int r = 0; r < 3; ++r)
            V[3 * r + 2] = -V[3 * r + 2];
        s2 = -s2;
    }
    if (fabs(s2) > n[1]) s2 = copysign(n[1], s2); /* rounding must not break the order */
    for (int j = 0; j < 3; ++j)
        for (int r = 0; r < 3; ++r)
            U[3 * r + j] = u[j][r];
    s[0] = n[0] * m;
    s[1] = n[1] * m;
    s[2] = s2 * m;
}

void sw_svd3(const double A[9], double U[9], double s[3], double V[9]) {
    svd3(A, NULL, U, s, V);
}

void sw_svd3_warm(const double A[9], const double V0[9], double U[9], double s[3], double V[9]) {
    svd3(A, V0, U, s, V);
}

void sw_polar3(const double A[9], double R[9], double S[9]) {
    double U[9], s[3], V[9];
    sw_svd3(A, U, s, V);
    sw_m3_mul_nt(U, V, R);
    if (S) {
        /* S = V diag(s) V^T, symmetric by construction. */
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                S[3 * i + j] = s[0] * (V[3 * i] * V[3 * j]) + s[1] * (V[3 * i + 1] * V[3 * j + 1]) +
                               s[2] * (V[3 * i + 2] * V[3 * j + 2]);
    }
}

enum { POLAR_MAX_ITERS = 16 };

int sw_polar3_newton(const double A[9], double R[9]) {
    double n2 = 0.0;
    for (int i = 0; i < 9; ++i)
        n2 += A[i] * A[i];
    /* det of a matrix with |A|_F^2 = n2 is at most (n2 / 3)^(3/2) (all singular values
     * equal): below 1e-6 of that the element is nearly flat or inverted */
    double det = sw_m3_det(A), dmax = (n2 / 3.0) * sqrt(n2 / 3.0);
    if (!isfinite(det) || !isfinite(dmax) || !(det > 1e-6 * dmax)) return 0;
    double X[9];
    for (int i = 0; i < 9; ++i)
        X[i] = A[i];
    for (int it = 0; it < POLAR_MAX_ITERS; ++it) {
        double C[9]; /* X^-T = cofactor(X) / det X */
        sw_m3_cofactor(X, C);
        double dx = X[0] * C[0] + X[1] * C[1] + X[2] * C[2];
        if (!(dx > 0.0)) return 0;
        double inv = 1.0 / dx, change = 0.0, size = 0.0;
        for (int i = 0; i < 9; ++i) {
            double xn = 0.5 * (X[i] + C[i] * inv);
            double dlt = xn - X[i];
            change += dlt * dlt;
            size += xn * xn;
            X[i] = xn;
        }
        /* the error after an update is about half its square: a change below 1e-8 of
         * |X| (= sqrt 3 at convergence) leaves ~1e-16, so this update was the last */
        if (change <= 1e-16 * size) {
            for (int i = 0; i < 9; ++i)
                R[i] = X[i];
            return 1;
        }
    }
    return 0;
}
