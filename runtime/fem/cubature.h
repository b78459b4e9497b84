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
double sw_cubature_eval(sw_reduced *m, const double *q, int want_grad, int want_hess);

#endif
