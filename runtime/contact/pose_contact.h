/* Self-contact pairs in the step (thesis §3.2.3 with the penalty of eqs. 3.4-3.6,
 * penalty.h): the pose-space mode applies the reference's converged contact pairs of the
 * two nearest training poses (pose_space.h), each while it collides, their forces blended
 * by the pose-space weight; the exhaustive mode (self_contact.h) the pairs it detected.
 * Cost: the pairs in use, not the mesh. */
#ifndef SW_POSE_CONTACT_H
#define SW_POSE_CONTACT_H

#include "pose_space.h"
#include "reduced_map.h"

/* A list of contact pairs as the blob stores the training poses': pair c is vertex p and
 * triangle (t0, t1, t2) as (domain, local vertex) pairs verts[8c..], the triangle
 * barycentrics, the normal in p's un-skinned frame (R_p^T n) and the area weight ka in
 * data[7c..], and the slots' indices into the skinning transforms act_R/act_t in
 * act[4c..]. */
typedef struct sw_pair_set {
    const int32_t *verts;
    const double *data;
    const int32_t *act;
    const double *act_R, *act_t;
} sw_pair_set;

/* The blob's training-pose pairs, with the active vertices' transforms of red. */
sw_pair_set sw_pose_pair_set(const sw_reduced *red);

/* Contact energy at q of the pairs ids[0..n) of set (ids NULL: pairs 0..n-1) but those
 * whose skip[i] is set (skip NULL: none; a condensation patch evaluates them), pair i
 * scaled by weight[i], its tangential term at share tangent[i] of SW_CONTACT_ALPHA (either
 * NULL: 1 for every pair); with
 * want_grad it adds the gradient to red->g, with want_hess the Hessian blocks (which may
 * couple two domains) to red->H. Call after the cubature, so the blocks land on the full
 * (mirrored) matrix. */
double sw_contact_pairs_eval(sw_reduced *red, const sw_pair_set *set, const int32_t *ids,
                             const unsigned char *skip, int32_t n, const double *weight,
                             const double *tangent, const double *q, int want_grad, int want_hess);

/* Pair c of set at q (red's skinning): the vertex's position x and the triangle's
 * normal n there, in the simulation frame (the debug draw's). */
void sw_contact_pair_point(const sw_reduced *red, const sw_pair_set *set, int32_t c,
                           const double *q, double x[3], double n[3]);

/* Contact energy at q of the pairs ps gathered (sw_contact_pairs_eval of the blob's
 * pairs at ps->pair_w and ps->pair_tan). */
double sw_pose_contact_eval(sw_reduced *red, const sw_pose_space *ps, const double *q,
                            int want_grad, int want_hess);

/* A pose-space pair is where the reference found vertex p pressed against the triangle
 * at a training pose. At another pose the two may have come apart while p still lies
 * behind the triangle's plane, and the penalty, quadratic in the gap, would pull p across
 * it to a surface it does not touch. A pair whose vertex lies farther from its contact
 * point than this many triangle edges (the longest), over 1 - s where s is the pair's
 * locality share (pair_tan: 1 at its own training pose, 0 at the nearest other one), is
 * not the reference's contact there; at its own pose a pair always stays, so the step
 * applies the reference's contact set where the bake solved it. Without the drop, a gait
 * that swings less than the training's is pulled across surfaces it does not touch; the
 * threshold is not sensitive between one and one and a half edges (figures:
 * docs/notes/runtime-constants.md). */
#define SW_PAIR_APART 1.0

/* Drops from ps->pairs (with pair_w, pair_tan) every pair that has come apart at q
 * (SW_PAIR_APART), keeping the others' order; returns how many. The step decides once, at
 * its start state, so every evaluation of the solve sums the same pairs (as a reference
 * contact round does). O(npairs r). */
int32_t sw_pose_contacts_drop_apart(sw_pose_space *ps, const sw_reduced *red, const double *q);

#endif
