/* Co-rotational linear-tet FEM kernels (thesis eq. 2.3), shared by the bake (the
 * full-space reference simulator) and the per-frame step, so both compute the same
 * physics. Hand-written small dense code: no allocation, no locks, no BLAS
 * (STYLE.md §6).
 *
 * Energy density  Psi(F) = mu ||F - R||_F^2 + lambda/2 tr^2(R^T F - I),
 * with R from the polar decomposition F = R S. Inverted elements (det F <= 0) are
 * handled by the rotation-variant SVD: the smallest singular value's sign is flipped
 * so that U and V are rotations (Irving et al. 2004), which makes Psi a smooth
 * function of the signed singular values.
 *
 * Element vertex order is (x0, x1, x2, x3); x is 12 doubles, xyz interleaved.
 * The deformation gradient is F = Ds * Dm^-1, Ds = [x1-x0, x2-x0, x3-x0].
 */
#ifndef SW_FEM_COROT_H
#define SW_FEM_COROT_H

#include <stdint.h>

#include "tet_rest.h"

/* Lamé parameters from Young's modulus and Poisson ratio. */
void sw_lame(double youngs, double poisson, double *mu, double *lambda);

/* sw_tet_rest, a tet's rest Dm^-1 and volume, is tet_rest.h's (the blob derives them too). */

/* Flags for sw_corot_eval. */
enum {
    SW_COROT_PROJECT_PSD = 1 /* clamp the element Hessian's eigenvalues at 0 (McAdams 2011) */
};

/* Evaluates one element at deformed positions x (12): returns the strain energy
 * vol * Psi(F); writes the nodal forces f = -dE/dx (12) when f != NULL and the
 * Hessian K = d2E/dx2 (12x12, row-major) when K != NULL. With SW_COROT_PROJECT_PSD
 * the Hessian is projected to positive semi-definite through its analytic eigen
 * system in singular-value space; without it the exact Hessian is returned. */
double sw_corot_eval(const double x[12], const double DmInv[9], double vol, double mu,
                     double lambda, double f[12], double K[144], uint32_t flags);

/* The element at x through its SVD, for a caller that projects the Hessian's modes
 * itself (the step's cubature): returns vol Psi; writes the rotation-variant SVD
 * F = U diag(s) V^T (warm-started from V_cache when it is not NULL, and the new V stored
 * there: fewer Jacobi sweeps frame to frame), dpsi = dPsi/ds (P = U diag(dpsi) V^T), and
 * the weights w (9) of the Hessian's modes: vol d2Psi/dF2 = sum_k w[k] vec(Q_k)
 * vec(Q_k)^T with Q_k = U M_k V^T (clamped at 0 with SW_COROT_PROJECT_PSD). */
double sw_corot_eval_svd(const double x[12], const double DmInv[9], double vol, double mu,
                         double lambda, double V_cache[9], uint32_t flags, double U[9], double s[3],
                         double V[9], double dpsi[3], double w[9]);

/* The nine modes of dP/dF are U M_k V^T (Teran et al. 2005): three scalings
 * M = diag(d) along (1,1,1)/sqrt(3), (1,-1,0)/sqrt(2), (1,1,-2)/sqrt(6), then per
 * singular-value pair (i, j) = (0,1), (0,2), (1,2) a twist (e_i e_j^T - e_j e_i^T)/sqrt(2)
 * and a flip (e_i e_j^T + e_j e_i^T)/sqrt(2). */
#define SW_COROT_R3 0.57735026918962576451
#define SW_COROT_R2 0.70710678118654752440
#define SW_COROT_R6 0.40824829046386301637

/* h[k] = <A, U M_k V^T> for the nine modes, from A written in the singular frame,
 * As = U^T A V (row-major): the M_k are sparse, so one to three products each. Inline:
 * the step's cubature calls it once per reduced coordinate of every tet. */
static inline void sw_corot_modes_dot(const double As[9], double h[9]) {
    h[0] = SW_COROT_R3 * As[0] + SW_COROT_R3 * As[4] + SW_COROT_R3 * As[8];
    h[1] = SW_COROT_R2 * As[0] - SW_COROT_R2 * As[4];
    h[2] = SW_COROT_R6 * As[0] + SW_COROT_R6 * As[4] - 2.0 * SW_COROT_R6 * As[8];
    h[3] = SW_COROT_R2 * As[1] - SW_COROT_R2 * As[3]; /* pair (0, 1) */
    h[4] = SW_COROT_R2 * As[1] + SW_COROT_R2 * As[3];
    h[5] = SW_COROT_R2 * As[2] - SW_COROT_R2 * As[6]; /* pair (0, 2) */
    h[6] = SW_COROT_R2 * As[2] + SW_COROT_R2 * As[6];
    h[7] = SW_COROT_R2 * As[5] - SW_COROT_R2 * As[7]; /* pair (1, 2) */
    h[8] = SW_COROT_R2 * As[5] + SW_COROT_R2 * As[7];
}

/* dF/dx of a tet as its 4 x 3 shape gradients: F = sum_n x_n D[3n .. 3n+2]^T. */
void sw_tet_shape_gradients(const double DmInv[9], double D[12]);

/* Lumped mass: adds density*vol/4 to each of the tet's four vertices' entry of mass. */
void sw_lumped_mass_add(const int32_t tet[4], double density, double vol, double *mass);

#endif
