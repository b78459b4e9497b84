/* The generalised winding number of a triangle surface (Jacobson et al. 2013): the
 * sum of its triangles' solid angles seen from a point, over 4 pi. 1 inside a closed,
 * outward-oriented surface, 0 outside, -1 inside an inside-out one, and a smooth value
 * between where the surface has holes, so |w| >= 1/2 is a robust inside test for render
 * meshes that are not closed (tet_lattice.h).
 *
 * sw_winding_number sums every triangle exactly (Van Oosterom and Strackee's solid
 * angle). The tree (Barill et al. 2018, first order) sums a cluster of triangles far
 * from the point as one dipole, its area vector at its area centroid: a cluster farther
 * than SW_WINDING_BETA times its radius contributes its solid angle to first order,
 * with a relative error of order 1 / beta^2 of that (small) contribution, small enough
 * to classify lattice cells (test_tet_lattice) at a thirtieth of the exact sum's cost. */
#ifndef SW_WINDING_H
#define SW_WINDING_H

#include "sw_mesh.h"

double sw_winding_number(const sw_trimesh *surf, const double p[3]);

typedef struct sw_winding_tree sw_winding_tree;

/* A tree over surf's triangles (surf must outlive it and be valid: indices in range,
 * finite coordinates). NULL when out of memory. */
sw_winding_tree *sw_winding_tree_create(const sw_trimesh *surf);
void sw_winding_tree_destroy(sw_winding_tree *t);
/* The winding number at p through the tree; thread-safe (no state is written). */
double sw_winding_tree_eval(const sw_winding_tree *t, const double p[3]);

#endif
