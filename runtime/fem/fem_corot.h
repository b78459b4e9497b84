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

/* Lamé parameters from Young's modulus and Poisson ratio. */
void sw_lame(double youngs, double poisson, double *mu, double *lambda);

/* Rest-state data of one tet: Dm^-1 (9, row-major) and rest volume. Returns 0 and
 * leaves outputs untouched when the rest tet is degenerate (|det Dm| below 1e-300 or
 * non-finite); 1 on success. Negative rest volume is allowed (vol is then |vol| and
 * Dm^-1 still maps to F = I at rest). */
int sw_tet_rest(const double X[12], double DmInv[9], double *vol);

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

/* As sw_corot_eval, but the Hessian as its nine rank-one modes: K = sum_k w[k] g_k g_k^T
 * with g_k = g[12k .. 12k+11]. A caller projecting K onto a basis J (12 x r) gets
 * J^T K J = sum_k w[k] (J^T g_k)(J^T g_k)^T without forming K (the step's cubature).
 * V_cache (may be NULL) holds a proper rotation from this element's previous call: the
 * SVD starts from it and stores its new V there (fewer Jacobi sweeps frame to frame). */
double sw_corot_eval_modes(const double x[12], const double DmInv[9], double vol, double mu,
                           double lambda, double f[12], double w[9], double g[108],
                           double V_cache[9], uint32_t flags);

/* Lumped mass: adds density*vol/4 to each of the tet's four vertices' entry of mass. */
void sw_lumped_mass_add(const int32_t tet[4], double density, double vol, double *mass);

#endif
