/* Axis-aligned bounding-volume hierarchy over n primitives given by their boxes.
 *
 * The topology is built once (median split of the box centroids along the longest
 * axis of their bounds; ties broken by primitive id, so the tree depends only on the
 * input) and stored in flat arrays in pre-order: an inner node's left child is the
 * next node, so every child comes after its parent and a refit is one backward sweep.
 * A deforming mesh keeps its topology and only refits its boxes (DESIGN.md §8, the
 * self-contact BVH "refits without allocating").
 *
 * Queries walk the tree with a fixed-size stack: no recursion, no allocation, no
 * locks, so several threads may query one tree at once (but never while it refits).
 *
 * A box is 6 doubles: min x, y, z then max x, y, z.
 */
#ifndef SW_BVH_H
#define SW_BVH_H

#include <stdint.h>

#include "mem_plan.h"
#include "sw_error.h"

/* Primitives per leaf at most. */
#define SW_BVH_LEAF_SIZE 4
/* Traversal stack depth; median splits keep the depth below log2(n) + 2 < 34. */
#define SW_BVH_STACK 64

typedef struct sw_bvh {
    int32_t nprims, nnodes;
    double *box;    /* 6*nnodes node boxes */
    int32_t *node;  /* 2*nnodes: inner (right child, 0), leaf (first index in prims, count) */
    int32_t *prims; /* nprims primitive ids in leaf order */
    double *pbox;   /* 6*nprims primitive boxes in leaf order (exact leaf tests) */
} sw_bvh;

/* Builds the tree over boxes[6*n] (n >= 1, finite, min <= max). On error `out` is
 * left zeroed. */
sinew_result sw_bvh_build(int32_t n, const double *boxes, sw_bvh *out, sw_error *err);
/* The same build into memory laid out by a memory plan (an instance's block):
 * sw_bvh_take places the arrays of a tree of n primitives in p; sw_bvh_build_in builds
 * into them with sw_bvh_scratch_size(n) bytes of scratch (8-byte aligned, free again
 * after the build) and no allocation of its own (the median splits' qsort may allocate:
 * creation only). The tree is then used as any other, but never passed to sw_bvh_free. */
size_t sw_bvh_scratch_size(int32_t n);
void sw_bvh_take(sw_mem_plan *p, int32_t n, sw_bvh *out);
sinew_result sw_bvh_build_in(int32_t n, const double *boxes, sw_bvh *t, void *scratch,
                             sw_error *err);
/* Releases the arrays and zeroes the struct; a zeroed struct is a no-op. */
void sw_bvh_free(sw_bvh *bvh);

/* Updates every node box from new primitive boxes (6*nprims, same order as at build).
 * Bottom-up, in place, allocation-free. */
void sw_bvh_refit(sw_bvh *bvh, const double *boxes);

/* The same refit in two steps, for element meshes, without a separate box array:
 * sw_bvh_refit_elements writes the boxes of the primitives at leaf positions
 * [begin, end) (element prims[j] of k vertices elems[k*prims[j]..], positions x) into
 * pbox; independent ranges may run on different threads. Then sw_bvh_refit_nodes
 * (one thread) updates the inner boxes from pbox. */
void sw_bvh_refit_elements(sw_bvh *bvh, const int32_t *elems, int k, const double *x, int32_t begin,
                           int32_t end);
void sw_bvh_refit_nodes(sw_bvh *bvh);

/* Box of each element of k vertices (k = 3 triangles, 4 tets): boxes[6*i..] from
 * the positions x (3 per vertex) of elems[k*i..k*i+k). For i in [begin, end). */
void sw_bvh_element_boxes(const int32_t *elems, int k, const double *x, int32_t begin, int32_t end,
                          double *boxes);

/* Visitor of a query: return nonzero to stop the traversal. */
typedef int (*sw_bvh_visit_fn)(void *ctx, int32_t prim);

/* Calls visit for every primitive whose box contains p (boundary included), in a
 * fixed order for a given tree. Returns the number of visits. */
int32_t sw_bvh_query_point(const sw_bvh *bvh, const double p[3], sw_bvh_visit_fn visit, void *ctx);
/* Calls visit for every primitive whose box overlaps `box` (touching counts). */
int32_t sw_bvh_query_box(const sw_bvh *bvh, const double box[6], sw_bvh_visit_fn visit, void *ctx);

/* Result of a closest-point query. */
typedef struct sw_bvh_closest {
    int32_t tri;     /* triangle id, -1 when none within the radius */
    double beta[3];  /* barycentrics of `point` on that triangle */
    double point[3]; /* the closest point */
    double dist;     /* |point - p| */
} sw_bvh_closest;

/* Closest point to p on the triangles tris[3*i..] (vertex positions X) of a tree
 * built over those triangles' boxes, searching within max_dist (finite). Equal
 * distances resolve to the lowest triangle id. Returns 1 when a triangle is within
 * max_dist (out filled), else 0 (out->tri = -1). */
int sw_bvh_closest_triangle(const sw_bvh *bvh, const double *X, const int32_t *tris,
                            const double p[3], double max_dist, sw_bvh_closest *out);

/* Closest point q on triangle (a, b, c) to p, with its barycentrics beta (the
 * Voronoi-region walk of Ericson, Real-Time Collision Detection §5.1.5). The
 * triangle must not be degenerate. */
void sw_closest_point_triangle(const double p[3], const double a[3], const double b[3],
                               const double c[3], double beta[3], double q[3]);

#endif
