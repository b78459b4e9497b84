/* Pose-space self-contact in the step (thesis §3.2.3 with the penalty of eqs. 3.4-3.6,
 * penalty.h): the reference's converged contact pairs of the two nearest training
 * poses (pose_space.h), each applied while it collides, their forces blended by the
 * pose-space weight. Cost: the pairs in use, not the mesh. */
#ifndef SW_POSE_CONTACT_H
#define SW_POSE_CONTACT_H

#include "pose_space.h"
#include "reduced_map.h"

/* Contact energy at q of the pairs ps gathered; with want_grad it adds the gradient to
 * red->g, with want_hess the Hessian blocks (which may couple two domains) to red->H.
 * Call after the cubature, so the blocks land on the full (mirrored) matrix. */
double sw_pose_contact_eval(sw_reduced *red, const sw_pose_space *ps, const double *q,
                            int want_grad, int want_hess);

#endif
