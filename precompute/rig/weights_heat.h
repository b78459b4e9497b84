/* Heat-diffusion skin weights (Baran & Popovic 2007, "Automatic rigging and animation
 * of 3D characters", on the tet mesh's volume graph; DESIGN.md §8 "Weights").
 *
 * For every bone b: (L + H) w_b = H p_b, where
 *  - L is the graph Laplacian of the tet mesh's edges with edge weights 1/|e|^2,
 *  - H is diagonal, H_vv = c / d(v)^2, d(v) the distance from v to its nearest bone
 *    segment (clamped below at 1e-3 of the model's bounding-box diagonal),
 *  - p_b(v) = 1 when b is v's nearest bone (shared 1/k among k bones tied within
 *    round-off, e.g. on a joint's bisecting plane), else 0.
 * L + H is symmetric positive definite; each system is solved by Jacobi-preconditioned
 * conjugate gradients. The weights are then clamped to [0, 1] and every row is
 * normalised to sum 1; a row that ends up all zero goes wholly to its nearest bone.
 * Unlike Baran & Popovic there is no visibility test on the bone term. */
#ifndef SW_WEIGHTS_HEAT_H
#define SW_WEIGHTS_HEAT_H

#include "sw_mesh.h"

/* Default strength of the bone term (DESIGN.md §8: c ~ 20). */
#define SW_WEIGHTS_HEAT_C 20.0

/* Heat-diffusion weights of mesh `m` for skeleton `s` into `out` (malloc'd; free with
 * sw_weights_free). `c` <= 0 means SW_WEIGHTS_HEAT_C. Runs the bones' solves in
 * parallel on a pool of the machine's cores (the result does not depend on the thread
 * count). Errors: INVALID_ARGUMENT (NULL, non-finite c), DEGENERATE (no vertices, no
 * tets, no bones, a zero-length edge), PARSE (a tet vertex id out of range),
 * NOT_FINITE (a NaN coordinate), NOT_CONVERGED, OUT_OF_MEMORY. On error `out` is
 * zeroed and nothing leaks. */
sinew_result sw_weights_heat(const sw_tetmesh *m, const sw_skeleton *s, double c, sw_weights *out,
                             sw_error *err);

#endif
