/* Full-space self-contact for the reference simulator: detection of surface vertices
 * that have entered the mesh, and the penalty force of thesis eqs. 3.4-3.6.
 *
 * Detection (DESIGN.md §8): a bounding-volume hierarchy over the deformed tets (built
 * once, refit per call without allocating) finds a tet that contains a surface vertex
 * p (tets incident to p excluded). The point's rest position is interpolated with
 * that tet's barycentrics, projected to the closest point of the rest surface (a
 * static BVH over rest surface triangles), and mapped back to the deformed surface:
 * v_s = sum beta_i x_{t_i}. Pairs whose rest-space distance (p to the triangle) is
 * below `neighbour_factor` times the triangle's longest rest edge are neighbours,
 * not contacts, and are skipped.
 *
 * Penalty (eqs. 3.4-3.6; the law is the runtime's contact/penalty.h), with n and beta
 * frozen at detection:
 *   E = 1/2 kc ka d^T N d,  d = v_s - v_p,  N = (1-alpha) n n^T + alpha I,
 *   f_p = kc ka N d,  f_{t_i} = -beta_i kc ka N d,
 *   Hessian kc ka J^T N J with J = [-I, beta_0 I, beta_1 I, beta_2 I] (PSD).
 * ka = (one-ring rest area of p + rest area of the triangle) / 4 (DESIGN.md §8).
 */
#ifndef SW_SELFCONTACT_H
#define SW_SELFCONTACT_H

#include <stdint.h>

#include "self_detect.h"
#include "sw_mesh.h"
#include "thread_pool.h"

typedef struct sw_selfcontact sw_selfcontact;

/* Builds the static rest-surface structures and the tet BVH topology. `surf` must be
 * the boundary of `mesh`. max_contacts bounds the list (0: one per surface vertex). */
sinew_result sw_selfcontact_create(const sw_tetmesh *mesh, const sw_surface *surf,
                                   double neighbour_factor, int32_t max_contacts,
                                   sw_selfcontact **out, sw_error *err);
void sw_selfcontact_destroy(sw_selfcontact *sc);

/* Refits the BVH to deformed positions x (3*nverts) and detects penetrations
 * (parallel over surface vertices when pool != NULL; the result's order does not
 * depend on the thread count). Returns the number of contacts. */
int32_t sw_selfcontact_detect(sw_selfcontact *sc, const double *x, sw_pool *pool);

/* The contacts of the last detect call. */
const sw_contact *sw_selfcontact_list(const sw_selfcontact *sc, int32_t *count);

/* Largest depth among the contacts of the last detect call (0 when none). */
double sw_selfcontact_max_depth(const sw_selfcontact *sc);

/* <n, d> of one contact at positions x: positive while p is behind its surface point
 * along the frozen normal (the pair collides, eq. 3.12). */
double sw_contact_gap(const sw_contact *c, const double *x);

/* The four (vertex, coefficient) slots of d = J x: (p, -1), (tri_k, beta_k). */
void sw_contact_slots(const sw_contact *c, int32_t v[4], double a[4]);

/* Penalty energy of contacts c[0..n) at positions x (n, beta frozen). */
double sw_contact_energy(const sw_contact *c, int32_t n, const double *x, double kc, double alpha);
/* f (3*nverts) += penalty forces. */
void sw_contact_add_forces(const sw_contact *c, int32_t n, const double *x, double kc, double alpha,
                           double *f);
/* diag (9 per vertex, row-major 3x3 blocks) += diagonal blocks of the Hessian. */
void sw_contact_add_diag(const sw_contact *c, int32_t n, double kc, double alpha, double *diag);
/* y (3*nverts) += H v with H the penalty Hessian. */
void sw_contact_apply_hessian(const sw_contact *c, int32_t n, double kc, double alpha,
                              const double *v, double *y);
#endif
