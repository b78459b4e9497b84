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

#include <math.h>
#include <stddef.h>

enum { SVD3_MAX_SWEEPS = 40 };

/* Columns of the (prescaled, max |entry| = 1) matrix shorter than this carry no usable
 * direction: their squares underflow. Their singular value is <= 1e-150 * max|A|. */
static const double SVD3_TINY = 1e-150;

/* Rotates columns p, q of W (and V alike) so that w_p . w_q = 0. Returns 1 when a
 * rotation was applied, 0 when the pair was already orthogonal to working precision. */
static int orthogonalize_pair(double W[9], double V[9], int p, int q) {
    double alpha = 0.0, beta = 0.0, gamma = 0.0;
    for (int r = 0; r < 3; ++r) {
        double a = W[3 * r + p], b = W[3 * r + q];
        alpha += a * a;
        beta += b * b;
        gamma += a * b;
    }
    /* sqrt(alpha)*sqrt(beta), not sqrt(alpha*beta): the product may underflow. */
    if (!(fabs(gamma) > 1e-15 * sqrt(alpha) * sqrt(beta))) return 0;
    /* Smaller root of t^2 + 2 zeta t - 1 = 0: a rotation of at most 45 degrees. */
    double zeta = (beta - alpha) / (2.0 * gamma);
    double t = fabs(zeta) > 1e100
                   ? 0.5 / zeta
                   : (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
    double c = 1.0 / sqrt(1.0 + t * t), s = c * t;
    for (int r = 0; r < 3; ++r) {
        double a = W[3 * r + p], b = W[3 * r + q];
        W[3 * r + p] = c * a - s * b;
        W[3 * r + q] = s * a + c * b;
        a = V[3 * r + p];
        b = V[3 * r + q];
        V[3 * r + p] = c * a - s * b;
        V[3 * r + q] = s * a + c * b;
    }
    return 1;
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
        int rotated = orthogonalize_pair(W, V, 0, 1);
        rotated += orthogonalize_pair(W, V, 0, 2);
        rotated += orthogonalize_pair(W, V, 1, 2);
        if (!rotated) break;
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
