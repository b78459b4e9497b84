/* Co-rotational linear tetrahedra (thesis eq. 2.3): energy, forces and Hessian of
 *   Psi(F) = mu ||F - R||_F^2 + lambda/2 tr^2(R^T F - I).
 * With the rotation-variant SVD F = U diag(s) V^T (R = U V^T) this is an isotropic
 * function of the signed singular values,
 *   Psi(s) = mu sum (s_i - 1)^2 + lambda/2 (sum s_i - 3)^2,
 * so P = dPsi/dF = U diag(dPsi/ds) V^T and dP/dF has a closed-form eigen system
 * (Teran et al. 2005; Smith et al. 2019): three "scaling" modes U diag(v) V^T from
 * the 3x3 block d2Psi/ds2, and per singular-value pair (i, j) a "flip" and a "twist"
 * mode U (e_i e_j^T +- e_j e_i^T) V^T / sqrt(2). The element Hessian is
 * K = vol B^T (dP/dF) B = vol sum_k lambda_k g_k g_k^T with g_k = B^T vec(Q_k), and the
 * McAdams et al. 2011 definiteness fix clamps the lambda_k at zero. */
#include "fem_corot.h"

#include "mat3.h"
#include "svd3.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* Twist eigenvalues divide by s_i + s_j, which is >= 0 for the rotation-variant SVD
 * (s_0 >= s_1 >= |s_2|) and vanishes only when the element is flattened with two
 * singular values of opposite sign: there R itself is not differentiable and the exact
 * Hessian is unbounded. Clamping the denominator (as Teran et al. 2005 do) keeps K finite. */
static const double COROT_MIN_PAIR_SUM = 1e-6;

void sw_lame(double youngs, double poisson, double *mu, double *lambda) {
    *mu = youngs / (2.0 * (1.0 + poisson));
    *lambda = youngs * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
}

void sw_lumped_mass_add(const int32_t tet[4], double density, double vol, double *mass) {
    double m = density * vol * 0.25;
    for (int i = 0; i < 4; ++i)
        mass[tet[i]] += m;
}

/* dF/dx as a 4x3 table D: F = sum_n x_n D[n]^T, so d(F_cb)/d(x_n)_c = D[n][b]. Row 0 is
 * minus the sum of the others (translations leave F unchanged). */
void sw_tet_shape_gradients(const double DmInv[9], double D[12]) {
    for (int b = 0; b < 3; ++b) {
        D[3 + b] = DmInv[b];
        D[6 + b] = DmInv[3 + b];
        D[9 + b] = DmInv[6 + b];
        D[b] = -(DmInv[b] + DmInv[3 + b] + DmInv[6 + b]);
    }
}

/* g = B^T vec(Q): g[3n + c] = sum_b Q[c][b] D[n][b]. */
static void pull_to_nodes(const double Q[9], const double D[12], double g[12]) {
    for (int n = 0; n < 4; ++n)
        for (int c = 0; c < 3; ++c)
            g[3 * n + c] =
                Q[3 * c] * D[3 * n] + Q[3 * c + 1] * D[3 * n + 1] + Q[3 * c + 2] * D[3 * n + 2];
}

/* Mode k's matrix M_k (fem_corot.h); the pairs (i, j) in mode order. */
static const int mode_pair[3][2] = {{0, 1}, {0, 2}, {1, 2}};

static void mode_matrix(int k, double M[9]) {
    static const double dirs[3][3] = {{SW_COROT_R3, SW_COROT_R3, SW_COROT_R3},
                                      {SW_COROT_R2, -SW_COROT_R2, 0.0},
                                      {SW_COROT_R6, SW_COROT_R6, -2.0 * SW_COROT_R6}};
    for (int i = 0; i < 9; ++i)
        M[i] = 0.0;
    if (k < 3) {
        M[0] = dirs[k][0];
        M[4] = dirs[k][1];
        M[8] = dirs[k][2];
        return;
    }
    int i = mode_pair[(k - 3) / 2][0], j = mode_pair[(k - 3) / 2][1];
    M[3 * i + j] = SW_COROT_R2;
    M[3 * j + i] = (k - 3) % 2 ? SW_COROT_R2 : -SW_COROT_R2; /* flip : twist */
}

/* The nine modes' weights vol * lambda_k (clamped at 0 with SW_COROT_PROJECT_PSD). */
static void corot_mode_weights(const double s[3], double vol, double mu, double lambda,
                               uint32_t flags, double w[9]) {
    int project = (flags & SW_COROT_PROJECT_PSD) != 0;
    double e = s[0] + s[1] + s[2] - 3.0;
    /* Scaling block d2Psi/ds2 = 2 mu I + lambda 1 1^T: eigenvalue 2mu + 3lambda along
     * (1,1,1)/sqrt(3), 2mu on its orthogonal complement. */
    double lam_scale[3] = {2.0 * mu + 3.0 * lambda, 2.0 * mu, 2.0 * mu};
    for (int k = 0; k < 3; ++k)
        w[k] = vol * (project && lam_scale[k] < 0.0 ? 0.0 : lam_scale[k]);
    /* Pair (i, j): flip eigenvalue (psi_i - psi_j)/(s_i - s_j) = 2mu exactly (no division,
     * so equal singular values are harmless); twist eigenvalue (psi_i + psi_j)/(s_i + s_j)
     * = 2mu + (2 lambda e - 4 mu)/(s_i + s_j), zero at any rotation of the rest state. */
    for (int p = 0; p < 3; ++p) {
        int i = mode_pair[p][0], j = mode_pair[p][1];
        double sum = fmax(s[i] + s[j], COROT_MIN_PAIR_SUM);
        double lam_twist = 2.0 * mu + (2.0 * lambda * e - 4.0 * mu) / sum;
        double lam_flip = 2.0 * mu;
        if (project) {
            lam_twist = fmax(lam_twist, 0.0);
            lam_flip = fmax(lam_flip, 0.0);
        }
        w[3 + 2 * p] = vol * lam_twist;
        w[4 + 2 * p] = vol * lam_flip;
    }
}

/* The element Hessian vol B^T (dP/dF) B as nine rank-one modes K = sum_k w_k g_k g_k^T,
 * g_k = B^T vec(U M_k V^T) (w: 9, g: 9 x 12). */
static void corot_modes(const double U[9], const double s[3], const double V[9], const double D[12],
                        double vol, double mu, double lambda, uint32_t flags, double w[9],
                        double g[108]) {
    corot_mode_weights(s, vol, mu, lambda, flags, w);
    for (int k = 0; k < 9; ++k) {
        double M[9], UM[9], Q[9];
        mode_matrix(k, M);
        sw_m3_mul(U, M, UM);
        sw_m3_mul_nt(UM, V, Q);
        pull_to_nodes(Q, D, g + 12 * k);
    }
}

/* K = sum_k w_k g_k g_k^T: the upper triangle summed, the lower its mirror. (j, i)'s own sum
 * would round alike (the same products, in the same order), so K is exactly symmetric and
 * the same bit for bit as the whole square summed. */
static void corot_hessian(const double U[9], const double s[3], const double V[9],
                          const double D[12], double vol, double mu, double lambda, uint32_t flags,
                          double K[144]) {
    double w[9], g[108];
    corot_modes(U, s, V, D, vol, mu, lambda, flags, w, g);
    for (int i = 0; i < 144; ++i)
        K[i] = 0.0;
    for (int k = 0; k < 9; ++k) {
        if (w[k] == 0.0) continue;
        const double *gk = g + 12 * k;
        for (int i = 0; i < 12; ++i)
            for (int j = i; j < 12; ++j)
                K[12 * i + j] += w[k] * (gk[i] * gk[j]);
    }
    for (int i = 1; i < 12; ++i)
        for (int j = 0; j < i; ++j)
            K[12 * i + j] = K[12 * j + i];
}

/* Energy and forces alone, from the polar rotation R of F (no SVD): psi = mu |F - R|^2 +
 * lambda/2 tr^2(R^T F - I) (eq. 2.3) and P = 2 mu (F - R) + lambda tr(R^T F - I) R, the
 * same function as the singular-value form below. Returns 0 when F is nearly flat or
 * inverted (sw_polar3_newton declines): the rotation-variant SVD decides there. */
static int corot_eval_polar(const double F[9], const double D[12], double vol, double mu,
                            double lambda, double f[12], double *psi) {
    double R[9];
    if (!sw_polar3_newton(F, R)) return 0;
    double dev2 = 0.0, tr = 0.0;
    for (int i = 0; i < 9; ++i) {
        double d = F[i] - R[i];
        dev2 += d * d;
        tr += R[i] * F[i]; /* tr(R^T F) */
    }
    double e = tr - 3.0;
    *psi = mu * dev2 + 0.5 * lambda * e * e;
    if (f) {
        double P[9], g[12];
        for (int i = 0; i < 9; ++i)
            P[i] = 2.0 * mu * (F[i] - R[i]) + lambda * e * R[i];
        pull_to_nodes(P, D, g); /* dE/dx = vol B^T vec(P) */
        for (int i = 0; i < 12; ++i)
            f[i] = -vol * g[i];
    }
    return 1;
}

/* F = Ds Dm^-1 of the element at x, and its shape gradients D. */
static void deformation_gradient(const double x[12], const double DmInv[9], double F[9],
                                 double D[12]) {
    double Ds[9];
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            Ds[3 * a + k] = x[3 * (k + 1) + a] - x[a];
    sw_m3_mul(Ds, DmInv, F);
    sw_tet_shape_gradients(DmInv, D);
}

/* Psi and dPsi/ds (dpsi) through the rotation-variant SVD F = U diag(s) V^T,
 * warm-started from V_cache (stored back) when given. */
static double svd_psi(const double F[9], double *V_cache, double mu, double lambda, double U[9],
                      double s[3], double V[9], double dpsi[3]) {
    if (V_cache) {
        sw_svd3_warm(F, V_cache, U, s, V);
        memcpy(V_cache, V, 9 * sizeof *V);
    } else {
        sw_svd3(F, U, s, V);
    }
    double e = s[0] + s[1] + s[2] - 3.0;
    double d0 = s[0] - 1.0, d1 = s[1] - 1.0, d2 = s[2] - 1.0;
    dpsi[0] = 2.0 * mu * d0 + lambda * e;
    dpsi[1] = 2.0 * mu * d1 + lambda * e;
    dpsi[2] = 2.0 * mu * d2 + lambda * e;
    return mu * (d0 * d0 + d1 * d1 + d2 * d2) + 0.5 * lambda * e * e; /* eq. 2.3 */
}

double sw_corot_eval(const double x[12], const double DmInv[9], double vol, double mu,
                     double lambda, double f[12], double K[144], uint32_t flags) {
    double F[9], U[9], s[3], V[9], D[12], dpsi[3];
    deformation_gradient(x, DmInv, F, D);
    /* Without the Hessian (line-search trials, forces) the rotation alone is needed: the
     * polar Newton iteration costs a fraction of the Jacobi SVD. */
    double psi_polar;
    if (!K && corot_eval_polar(F, D, vol, mu, lambda, f, &psi_polar)) return vol * psi_polar;
    double psi = svd_psi(F, NULL, mu, lambda, U, s, V, dpsi);
    if (f) {
        /* P = U diag(dPsi/ds) V^T = 2mu (F - R) + lambda tr(R^T F - I) R. */
        double UP[9], P[9], g[12];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                UP[3 * r + c] = U[3 * r + c] * dpsi[c];
        sw_m3_mul_nt(UP, V, P);
        pull_to_nodes(P, D, g); /* dE/dx = vol B^T vec(P) */
        for (int i = 0; i < 12; ++i)
            f[i] = -vol * g[i];
    }
    if (K) corot_hessian(U, s, V, D, vol, mu, lambda, flags, K);
    return vol * psi;
}

double sw_corot_eval_svd(const double x[12], const double DmInv[9], double vol, double mu,
                         double lambda, double V_cache[9], uint32_t flags, double U[9], double s[3],
                         double V[9], double dpsi[3], double w[9]) {
    double F[9], D[12];
    deformation_gradient(x, DmInv, F, D);
    double psi = svd_psi(F, V_cache, mu, lambda, U, s, V, dpsi);
    corot_mode_weights(s, vol, mu, lambda, flags, w);
    return vol * psi;
}
