/* Internal view of an instance for tools and tests (the host API is in sinew.h):
 * double-precision pose input, the reduced state, and an O(N) evaluation helper that
 * is never part of the step. */
#ifndef SW_INSTANCE_H
#define SW_INSTANCE_H

#include "blob_view.h"
#include "sinew/sinew.h"

/* Sets the pose from double transforms (12 per bone, rest -> world). */
sinew_result sw_instance_set_pose_d(sinew_instance *inst, const double *T);

/* Output surface positions (3 per surface vertex) of the last step. */
const double *sw_instance_surface(const sinew_instance *inst);

/* Reduced coordinates (rank_total) of the last step. */
const double *sw_instance_q(const sinew_instance *inst);

/* Evaluation only (O(N), not part of the step): every simulation vertex's position,
 * the mean of its domain copies, into x (3 nverts); count is caller scratch (nverts).
 * Vertices in no domain get their skinned position. */
void sw_instance_full_positions(const sinew_instance *inst, double *x, double *count);

/* Overwrites the reduced coordinates (rank_total doubles), e.g. to start a solve from a
 * known state. */
void sw_instance_set_q(sinew_instance *inst, const double *q);

/* Tests: the quasistatic reduced potential (cubature, springs and the pose-space
 * contact pairs in use) at q for the pose last set, with its gradient into g and its
 * (PSD-projected) Hessian into H (rank_total^2, row-major) when they are not NULL. */
double sw_instance_potential(sinew_instance *inst, const double *q, double *g, double *H);

/* Evaluation only (O(N)): plain DQS of every simulation vertex at the current pose. */
void sw_instance_dqs_positions(const sinew_instance *inst, double *x);

/* Evaluation only (O(N)): the output surface of the current pose with no correction
 * (q = 0), the plain DQS surface the step's output deviates from (3 per surface vertex). */
void sw_instance_skinned_surface(const sinew_instance *inst, double *x);

/* The state's bounds (sinew_types.h, status flags): the largest distance of an output
 * vertex from its skinned position the step allows, max_k max(4 u_k Q_k, L / 4), and
 * the largest |q_k| / bound_k of the current state (<= 1). */
double sw_instance_displacement_bound(const sinew_instance *inst);
double sw_instance_bound_usage(const sinew_instance *inst);

#endif
