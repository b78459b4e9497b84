/* Internal view of an instance for tools and tests (the host API is in sinew.h):
 * double-precision pose input, the reduced state, and an O(N) evaluation helper that
 * is never part of the step. */
#ifndef SW_INSTANCE_H
#define SW_INSTANCE_H

#include "blob_view.h"
#include "sinew/sinew.h"

/* Sets the pose from double transforms (12 per bone, rest -> the actor's frame), as
 * sinew_instance_set_pose. */
sinew_result sw_instance_set_pose_d(sinew_instance *inst, const double *T);

/* Output surface positions (3 per output vertex, sw_blob_output_verts: the render mesh's
 * when the blob has one) of the last step. */
const double *sw_instance_surface(const sinew_instance *inst);

/* The output surface of the last step as the host reads it, in the actor's frame
 * (sinew_instance_set_actor), in double precision (3 per output vertex). */
void sw_instance_read_surface_d(const sinew_instance *inst, double *x);

/* Reduced coordinates (rank_total) of the last step. */
const double *sw_instance_q(const sinew_instance *inst);

/* The training pose the last step (or sw_instance_step_prepare) took as the nearest to
 * its pose (-1: none). */
int32_t sw_instance_nearest_pose(const sinew_instance *inst);

/* Evaluation only (O(N), not part of the step): every simulation vertex's position,
 * the mean of its domain copies, into x (3 nverts); count is caller scratch (nverts).
 * Vertices in no domain get their skinned position. */
void sw_instance_full_positions(const sinew_instance *inst, double *x, double *count);

/* Evaluation only (O(N)): how far the domains' copies of a vertex stand apart, the seam
 * the interface springs (thesis eq. 4.20) leave (the output takes the copies' mean, and
 * the vertices beside an interface follow their own domain's copy): with x
 * from sw_instance_full_positions, spread[v] = sum over v's copies of |x_copy - x[v]|^2
 * (nverts; 0 for a vertex with one copy or in a condensation patch). Returns the largest
 * |x_copy - x[v]|. */
double sw_instance_copy_spread(const sinew_instance *inst, const double *x, double *spread);

/* Overwrites the reduced coordinates (rank_total doubles), e.g. to start a solve from a
 * known state. */
void sw_instance_set_q(sinew_instance *inst, const double *q);

/* The output surface (sw_instance_surface) of the reduced state q at the pose last set, as
 * a step that ended at q leaves it (no patch): the pose-space level's table (bake_lod.c). */
void sw_instance_surface_at(sinew_instance *inst, const double *q);

/* Tests: the quasistatic reduced potential (cubature, springs and the pose-space
 * contact pairs in use) at q for the pose last set, with its gradient into g and its
 * (PSD-projected) Hessian into H (rank_total^2, row-major) when they are not NULL. */
double sw_instance_potential(sinew_instance *inst, const double *q, double *g, double *H);

/* Tests: the first phases of the step sinew_instance_step(inst, dt) would take from the
 * current state and pose (skinning, pose-space contact pairs, teleport check, in dynamic
 * mode q_n, the inertial forces and the frozen H(q_n), world candidates at the start
 * state), without the solve and without advancing: afterwards
 * sw_instance_step_potential evaluates the very potential that step minimises. The
 * instance is left mid-step (a quasistatic one at its pose-space start): set a pose
 * before stepping it again. */
void sw_instance_step_prepare(sinew_instance *inst, float dt);

/* Tests: the potential of the step prepared by sw_instance_step_prepare with the step's
 * own coefficients for dt and the instance's mode (cubature, springs, pose-space and
 * world contact; dynamic: backward-Euler inertia, Rayleigh damping, inertial forces) at
 * q, its gradient into g and its Hessian into H (rank_total^2, row-major) when not NULL:
 * the step's Newton matrix (the material part projected to PSD), or with exact_hessian
 * the exact second derivative. */
double sw_instance_step_potential(sinew_instance *inst, float dt, const double *q, double *g,
                                  double *H, int exact_hessian);

/* Tests: the potential, gradient and Newton matrix of the prepared step at its start, as
 * the step's first Newton evaluation takes them (sw_potential_start: in dynamic mode from
 * the material part evaluated for H(q_n), *cubature_pass 0); once after a prepare. */
double sw_instance_step_start_potential(sinew_instance *inst, float dt, double *g, double *H,
                                        int *cubature_pass);

/* Evaluation only (O(N)): plain DQS of every simulation vertex at the current pose. */
void sw_instance_dqs_positions(const sinew_instance *inst, double *x);

/* Evaluation only (O(N)): the output surface of the current pose with no correction
 * (q = 0), the plain DQS surface the step's output deviates from (3 per output vertex;
 * a render mesh's through its embedding, from its nodes skinned). */
void sw_instance_skinned_surface(const sinew_instance *inst, double *x);

/* Evaluation only: the output surface (3 per output vertex) of positions x_full of every
 * simulation vertex (a reference's solution, say): the boundary's vertices picked out,
 * or the render mesh through the blob's embedding, as the runtime places it. */
void sw_output_from_full(const sw_blob_view *v, const double *x_full, double *out);

/* The simulation vertex of render node n (of a blob with a render mesh). */
int32_t sw_render_node_vertex(const sw_blob_view *v, int32_t n);

/* The state's bounds (sinew_types.h, status flags): the largest distance of an output
 * vertex from its skinned position the step allows, max_k max(4 u_k Q_k, L / 4) (times
 * the largest sum of a render vertex's barycentric magnitudes, with a render mesh), and
 * the largest |q_k| / bound_k of the current state (<= 1). */
double sw_instance_displacement_bound(const sinew_instance *inst);
double sw_instance_bound_usage(const sinew_instance *inst);

#endif
