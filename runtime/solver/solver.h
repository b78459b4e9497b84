/* The reduced solve of one step (thesis §4.4, DESIGN.md §4): the state q and its history,
 * the potential Phi(q) of a quasistatic or backward-Euler step, and Newton with an energy
 * guard on a block-sparse Cholesky of its Hessian. The instance owns the arrays. */
#ifndef SW_SOLVER_H
#define SW_SOLVER_H

#include <stdint.h>

#include "mem_plan.h"
#include "pose_space.h"
#include "reduced_map.h"
#include "self_contact.h"
#include "world_contact.h"
#include "sinew/sinew.h"

/* A Newton update that moves the shape by less than this share of its correction |q| is
 * the step's last (newton.c says why 5%). */
#define SW_NEWTON_LAST_UPDATE 5e-2

typedef struct sw_solver {
    double *q, *qn, *qdot; /* R each: the state, its value at step start, its velocity */
    double *fin;           /* R: inertial forces of the step (inertia.h) */
    /* R x R: the material Hessian at the dynamic step's start q_s, of kind mat_hess (the
     * Hessian at q_s, or with rest_first the reference Hessian): the Rayleigh stiffness
     * damping, frozen for the step (step.c, dynamic_start) */
    double *Hn;
    unsigned char *Hn_nz; /* ndomains^2: Hn's blocks that may be nonzero (sw_reduced.H_nz) */
    /* The material part of Phi at q_mat = q_s (sw_potential_material: its value, gradient
     * and, in Hn, Hessian), valid for the step's first evaluation when mat_at_start: a
     * dynamic step evaluates it for Hn, and Newton starts there. */
    double *g_mat, phi_mat, *q_mat;
    int mat_at_start;
    int mat_hess; /* 1, or SW_CUB_HESSIAN_REF (rest_first) */
    /* the step started elsewhere than q_n (a dynamic step's predicted start): when an
       update finds no descent however short, Newton starts again from q_n (newton.c) */
    int fallback_qn;
    double *L;           /* R x R: the block Cholesky factor */
    double *pack;        /* sw_block_cholesky_pack_size(rmax): the factor's scratch */
    double *dq, *qtrial; /* R each: Newton update, the iterate before it */
    /* R: the pose-space prediction the last step started from (step.c, pose_space_start
     * and dynamic_start), valid while the steps since it moved the pose continuously and
     * did not fail */
    double *q_pred;
    int pred_valid;
    double *tmp, *tmp2; /* R each: scratch */
    /* H's domain blocks and their elimination order (leaves of the coupling graph first) */
    int32_t *blk_off, *blk_size, *blk_order; /* ndomains each */
    int32_t *blk_pos;                        /* domain -> its place in blk_order */
    unsigned char *blk_nz;                   /* ndomains^2: the factor's block pattern */
    unsigned char *blk_adj;                  /* ndomains^2: spring-coupled domain pairs */
    unsigned char *mass_adj;                 /* ndomains^2: mass-coupled domain pairs */
    int mass_blockdiag;  /* the blob's reduced mass is zero outside the domains' blocks */
    uint32_t max_newton; /* Newton updates a step at most */
    int rest_first;      /* steps start on the reference Hessian (red->h_ref) */
    double dq_tiny;      /* an update shorter than this converged (1e-9 of the size) */
    unsigned char *hold; /* ndomains: the domain's inertia modes are held (inertia_hold.c) */
    int hold_inertia;    /* this solve holds some (sw_solver_hold_decide) */
} sw_solver;

/* Lays out the solver's vectors and its block layout; the frozen Hessian's point only for
 * dynamic steps. */
void sw_solver_take(sw_mem_plan *p, const sw_blob_view *v, int dynamic, sw_solver *s);

/* The time discretisation of a step: quasistatic (dynamic = 0) or backward Euler with
 * cm = 1/h^2, cd = 1/h and Rayleigh damping alpha M + beta H(q_n). */
typedef struct sw_dyn_coef {
    double h, cm, cd, alpha, beta;
    int dynamic;
} sw_dyn_coef;

/* The block layout of H and its minimum-degree elimination order, once at creation. */
void sw_solver_order_blocks(sw_solver *s, const sw_blob_view *v);

/* The contact terms of a step: pose-space self-contact pairs, the exhaustive mode's
 * detected pairs and world candidates (any may be empty; sc and wc may be NULL). With
 * self_seconds, every evaluation adds the wall time of its self-contact terms there. */
typedef struct sw_step_contacts {
    const sw_pose_space *ps;
    const sw_world_contacts *wc;
    const sw_self_contacts *sc;
    double *self_seconds;
} sw_step_contacts;

/* Inertia modes held in quasistatic steps (inertia_hold.c). A quasistatic step has no
 * inertia for the inertia modes (each domain's last inertia_count columns,
 * sinew_blob_format.h) to carry: left free they settle where the cubature fits least and
 * the held-out error grows, so they are held at the pose-space prediction q_pred, where
 * the training poses' blend places them. Not where the step has contact nobody trained
 * (a world candidate, a detected self-contact pair on the domain's copies): there they
 * are static responses to loads, as contact is one, and the flesh gives way through
 * them. A dynamic step leaves them all free: they are its swing. (docs/notes/jiggle.md,
 * The inertia modes held where nothing untrained touches.) */
/* s->hold for this solve; returns whether any domain is held (s->hold_inertia). */
int sw_solver_hold_decide(sw_solver *s, const sw_blob_view *v, const sw_dyn_coef *dc,
                          const sw_step_contacts *ct);
/* The held coordinates of s->q set to their prediction. */
void sw_solver_hold_start(sw_solver *s, const sw_blob_view *v);
/* x (R) zero at the held coordinates. */
void sw_solver_hold_zero(const sw_solver *s, const sw_blob_view *v, double *x);
/* Their rows of red->g, and with want_hess of red->H, made a fixed coordinate's: g_i = 0,
 * H's row and column i zero but for the diagonal. Newton's update then leaves them where
 * they are. */
void sw_solver_hold_rows(const sw_solver *s, sw_reduced *red, int want_hess);

/* Phi(q): cubature + contact (self and world) + springs [+ inertia, damping and inertial
 * forces]. With want_grad also red->g (and red->H with want_hess: the material part
 * projected to PSD, exact with want_hess == SW_CUB_HESSIAN_EXACT, cubature.h); H_n is frozen
 * for the step. */
double sw_potential(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                    const double *q, const sw_dyn_coef *dc, int want_grad, int want_hess);

/* Phi in two parts, sw_potential = rest(material): the material part (cubature, pose-space
 * self-contact; red->g and red->H initialised, H with the springs' constant Hessian), whose
 * value it returns, adding its self-contact time to self_seconds (may be NULL); and the
 * rest, added to phi, red->g and red->H (detected self-contact, world contact, the springs'
 * energy and gradient, the dynamic terms), in sw_potential's order (bitwise the same). */
double sw_potential_material(sw_reduced *red, const sw_pose_space *ps, const double *q,
                             int want_grad, int want_hess, double *self_seconds);
double sw_potential_rest(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                         const double *q, const sw_dyn_coef *dc, double phi, int want_grad,
                         int want_hess);

/* Phi, g and H (of kind want_hess: 1, or SW_CUB_HESSIAN_REF) at the step's start s->q,
 * as sw_potential: a dynamic step's material part at its start is already known
 * (phase_dynamics evaluates it for the damping Hessian), so while s->q is still there and
 * the kind is the one asked for, only the rest is added, without a second cubature pass at
 * the same point (*cubature_pass 0; it is used once a step). The second pass gave bitwise
 * the same part, so the saving changes no result. */
double sw_potential_start(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                          const sw_dyn_coef *dc, int want_hess, int *cubature_pass);

/* The structural block pattern of H for this step: spring-coupled domains and the
 * domains the self-contact pairs in use join (no scan of H's values). */
void sw_solver_block_pattern(sw_solver *s, const sw_blob_view *v, const sw_step_contacts *ct);

/* Factors red->H (the block-sparse Cholesky into s->L, the step's block pattern),
 * shifting the diagonal if H is not positive definite; 0 if no shift makes it so. */
int sw_solver_factor(sw_reduced *red, sw_solver *s);

/* x = H^-1 x with the factor of sw_solver_factor. */
void sw_solver_factor_solve(const sw_reduced *red, const sw_solver *s, double *x);

/* Multiply-adds of one factorisation of the springs' block pattern (the fill included, no
 * contact pairs), for the choice of SINEW_NEWTON_HESSIAN_AUTO. At creation: it uses
 * s->blk_nz as scratch (every step sets it again). */
double sw_solver_factor_madds(sw_solver *s, const sw_blob_view *v);

/* Newton from s->q with the energy guard, into s->q; fills st's iterations, status
 * (CONVERGED, GUARD), residual, energy and potential_evals. A non-finite potential
 * restores q_n, sets FAILED and returns SINEW_ERROR_NOT_FINITE. */
sinew_result sw_newton_solve(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                             const sw_dyn_coef *dc, sinew_step_stats *st);

#endif
