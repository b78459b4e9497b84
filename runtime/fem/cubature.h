/* Material forces and Hessians of the reduced model by cubature (thesis eqs. 2.11-2.12):
 *   E_cub(q) = sum_c w_c E_c(x_c(q)),  gradient -sum_c w_c J_c^T f_c,
 *   Hessian  sum_c w_c J_c^T K_c J_c  with J_c = blockdiag(R_k) U_c,
 * on the co-rotational energy (eq. 2.3) with each element's stiffness projected to PSD
 * through its nine analytic eigen-modes (fem_corot.h). */
#ifndef SW_CUBATURE_H
#define SW_CUBATURE_H

#include "reduced_map.h"

/* Cubature energy at q. With want_grad it adds -sum w J^T f to m->g; with want_hess it
 * adds the domain blocks sum w J^T K J to m->H (both initialised by the caller), K
 * projected to PSD, or exact with want_hess == SW_CUB_HESSIAN_EXACT (the finite-difference
 * tests; the step never asks for it). Warm starts each element's SVD from m->svd_V and
 * updates it. */
#define SW_CUB_HESSIAN_EXACT 2
/* want_hess == SW_CUB_HESSIAN_REF: a gradient pass, and the reference Hessian's domain
 * blocks (m->h_ref) added to m->H in place of the Hessian at q: the first updates of a
 * Newton step (newton.c says why and when). With m->h_ref set, a pass with the
 * (projected) Hessian at q also stores its domain blocks there: the next steps' reference
 * is the Hessian last evaluated, which follows the pose far closer than the rest one. */
#define SW_CUB_HESSIAN_REF 3
double sw_cubature_eval(sw_reduced *m, const double *q, int want_grad, int want_hess);

/* The cubature's Hessian at the rest shape (q = 0, every skinning rotation the identity:
 * the elements' linear stiffness, eq. 2.12 at F = I), domain k's block (r_k x r_k,
 * row-major) at blocks + sum_{j<k} r_j^2. A tet whose corners turn with one rotation R
 * has the Hessian U^T R^T (R K0 R^T) R U = U^T K0 U at any pose as long as it does not
 * deform, so this stands for the Hessian wherever the flesh follows its bones. Uses the
 * first worker's scratch; at creation and at sinew_instance_reset. */
void sw_cubature_rest_hessian(sw_reduced *m, double *blocks);

/* sum over domains of r_k^2: the rest Hessian's doubles. */
int64_t sw_cubature_rest_hessian_size(const sw_blob_view *v);

/* Multiply-adds a Hessian pass costs beyond a gradient pass (the element modes'
 * projections, about 100 a basis column, and their products, 9 r (r + 1) / 2, less the
 * gradient's 12 r), summed over the cubature tets: what SW_CUB_HESSIAN_REF saves. */
double sw_cubature_hessian_madds(const sw_blob_view *v);

#endif
