/* Subspace condensation (thesis §4.3-4.4, Algorithm 4; DESIGN.md §4.6): where the flesh
 * meets a collider the subspace was never trained on, a small patch of simulation
 * vertices is solved in full space, coupled both ways to the reduced coordinates of
 * everything else, with no O(N) work a step.
 *
 * The partition oracle (oracle.c, thesis §4.4.2): the vertices of the world candidates
 * that penetrate at the step's start state are this step's seeds; with the seeds of the
 * two steps before, each grows breadth-first over the mesh's edges (through shared tets),
 * accepting the vertices within the rest-space radius rho of that seed (a vertex another
 * seed rejected can still be accepted from this one). The full tets are those touching a
 * patch vertex; their corners outside the patch are "ring" copies, the subspace vertex
 * copies of the tet's domain that carry the coupling. Over budget, the vertices nearest
 * their seeds are kept.
 *
 * The coupled solve (coupled.c): one potential in z = (q, x_f), the reduced coordinates
 * and the patch vertices' positions,
 *   Phi(q, x_f) = sum_{t full} E_t(x_t)                        (ring corners at q)
 *               + sum_{c cubature, not full} s_d w_c E_c(q)    (eq. 4.12's second sum)
 *               + sum_{t rest} E_t(q)   (the other tets of a domain the patch mostly covers)
 *               + springs, pose-space contact, world contact of the subspace copies
 *               + world contact of the patch vertices at x_f (the full block),
 * whose gradient in q is eq. 4.12: the boundary tets' forces projected through the ring
 * copies' rows, plus the cubature tets wholly in the subspace, their weights renormalised
 * (s_d: the domain's cubature then stands for its volume outside the patch, the
 * prototype's third flaw). Newton with the energy guard; each update solves eq. 4.11 by
 * PCG preconditioned with 3x3 Jacobi blocks on x_f and the factored reduced block on q.
 * The element Hessians are projected to PSD, so the coupled matrix is too. The reduced
 * block of the preconditioner (the factor) holds the full tets' ring-ring terms J^T K J
 * too; the matrix-vector product applies them tet by tet instead. */
#ifndef SW_CONDENSE_H
#define SW_CONDENSE_H

#include <stdint.h>

#include "mem_plan.h"
#include "self_contact.h"
#include "solver.h"

/* The patch radius when the def leaves it 0, in units of the rest diagonal. */
#define SW_COND_DEFAULT_RADIUS 0.05
/* The least share of its cubature weight a domain the patch reaches keeps (coupled.c,
 * sw_cond_weights_apply): the patch takes the place of its vertices, not the stiffness of
 * the domain's reduced coordinates. */
#define SW_COND_MIN_SHARE 0.1
/* The share of a domain's rest volume in the patch past which the domain's other tets are
 * evaluated exactly at q instead of by its scaled cubature (oracle.c, exact_domains). */
#define SW_COND_EXACT_SHARE 0.5

/* Sizes an instance reserves for a patch budget (all 0 when condensation is off). */
typedef struct sw_cond_sizes {
    int32_t max_verts;    /* patch vertices */
    int32_t max_tets;     /* full tets */
    int32_t max_pairs;    /* contact pair elements: pose-space pairs a step may use, then
                             detected pairs (self_contact.h) a patch may take over */
    int32_t max_detected; /* detected pairs a step may hold (sc's skip flags) */
    int32_t max_ring;     /* ring copies */
    int32_t max_cand;     /* vertices the growth may accept before the budget's cut */
    int32_t max_seeds;    /* seeds of one step */
    int32_t rmax;         /* the largest domain rank */
} sw_cond_sizes;

typedef struct sw_cond {
    const sw_blob_view *v;
    sw_cond_sizes z;
    double rho; /* rest-space radius of the growth (world units) */
    /* the oracle's memory: the seeds of this step and the two before (a ring buffer) */
    int32_t *seeds;    /* 3 max_seeds */
    int32_t nseeds[3]; /* seeds per slot */
    int32_t slot;      /* this step's slot */
    /* per simulation vertex (memory only: a step touches the patch's entries) */
    uint32_t *vis;         /* growth visit stamp */
    uint32_t *in_patch;    /* patch stamp: == stamp when the vertex is a patch vertex */
    int32_t *vloc;         /* its patch index, or (ring) -1 - its first ring copy */
    uint32_t *in_ring;     /* ring stamp */
    uint32_t *seeded;      /* seed stamp (a vertex seeded twice grows once) */
    unsigned char *pinned; /* kinematic (a bone vertex): never in a patch */
    int32_t *surf_of;      /* its boundary surface vertex, or -1 */
    double *dev;           /* 3 per vertex: its last patch position minus its subspace one */
    uint32_t *dev_at;      /* the stamp of the step that left dev */
    uint32_t *tvis;        /* per tet: full-tet stamp */
    double *dom_vol;       /* ndomains: rest volume of the domain's tets */
    int32_t *dom_tet_ptr;  /* ndomains + 1: each domain's tets are dom_tets[ptr[d] .. ptr[d+1]) */
    int32_t *dom_tets;     /* ntets */
    uint32_t stamp, vstamp;
    /* the growth */
    int32_t *queue; /* max_cand */
    int32_t *cand;  /* max_cand accepted vertices */
    double *cand_d; /* their rest distance to the seed that accepted them */
    int32_t ncand;
    int32_t dropped; /* vertices the budget left out this step */
    /* the patch */
    int32_t nf, nt, nring;
    int32_t np;             /* pose-space contact pairs with a patch corner (elements nt ..) */
    int32_t nrest;          /* the other tets of the domains the patch mostly covers, all four
                               corners ring copies, evaluated at q (elements nt + np ..) */
    int32_t nring_patch;    /* ring copies [0, nring_patch) are those of the patch's tets and
                               pairs; the rest's own come after */
    int32_t *pp_id;         /* max_pairs: their contact ids */
    double *pp_w;           /* max_pairs: their pose-space blend weights */
    double *pp_alpha;       /* max_pairs: their law's anisotropy (pose_contact.c) */
    unsigned char *pp_skip; /* max_pairs: per ps->pairs entry, the patch evaluates it */
    unsigned char *pp_src;  /* max_pairs: the element's pair list, SW_COND_TRAINED or
                               SW_COND_DETECTED */
    unsigned char *sc_skip; /* max_detected: per detected pair in use, the patch evaluates it */
    sw_pair_set pp_sets[2]; /* the two lists, as the oracle found them this step */
    signed char *pp_active; /* max_pairs: in contact for this solve (-1: not decided yet) */
    int32_t *fv;            /* nf: patch vertices (global ids) */
    int32_t *ft;            /* nt full tets, then (from nt + np) the rest's nrest tets */
    int32_t *ft_slot;       /* 4 per element: patch index >= 0, or -1 - ring copy */
    int32_t *ring_v;        /* per ring copy: global vertex, domain, local index, next copy */
    int32_t *ring_d, *ring_l, *ring_next;
    double *ring_x0;      /* 3 per ring copy: R rest + t (its position at q = 0) */
    double *ring_J;       /* 3 rmax per ring copy: J = R U (3 x r_d) */
    double *ring_x;       /* 3 per ring copy: its position at the iterate */
    double *ring_dx;      /* 3 per ring copy: scratch (J dq) */
    double *ring_M;       /* 3 rmax per ring copy: its tets' K J gathered (coupled.c; kept 0) */
    double *Hq;           /* R x R: the reduced potential's Hessian and the rest's ring blocks
                             (without the patch's: the product applies those tet by tet) */
    unsigned char *Hq_nz; /* ndomains^2: Hq's blocks that may be nonzero (reduced_map.h) */
    double *dom_fv;       /* ndomains: the patch's tets' volume (the oracle's), all of the
                             domain's when its rest is evaluated at q */
    double g0_step;       /* |grad| at the step's first coupled iterate (0: not solved yet) */
    /* the coupled Newton */
    double *x, *xt, *dx; /* 3 nf: patch positions, the iterate before an update, update */
    double *gf;          /* 3 nf: gradient in x_f */
    double *gf_el;       /* 3 nf: gf without the patch's world and inertia terms, and */
    double phi_el;       /* Phi likewise, at the last evaluation (a law refresh's base) */
    double *Kt;          /* 144 per element: its PSD Hessian */
    double *Dw;          /* 9 nf: world-contact 3x3 Hessians of the patch vertices */
    double *Pf;          /* 9 nf: the inverted 3x3 diagonal blocks (preconditioner) */
    double *cg_r, *cg_z, *cg_p, *cg_Ap, *rhs, *sol; /* R + 3 nf each */
    double *cub_w;      /* ncub: the cubature weights in use (red->cub_w points here) */
    uint32_t pcg_iters; /* of the last solve */
    /* dynamics (patch_dynamics.c): per vertex its last patch step's position, velocity,
       deviation from the subspace and that deviation's rate (3 each), stamped dyn_at */
    double *px, *pv, *pdev, *prate;
    uint32_t *dyn_at;
    double *xn, *vn, *dev_n, *rate_n; /* 3 nf: the patch vertices' start state */
    double *mass;                     /* nf: their lumped masses */
    double *q_prev;                   /* R: q one step before q_n */
    sw_dualquat *dq_prev, *dq_prev2;  /* nbones each: the two poses before (scratch) */
    int32_t *keep_v;                  /* max_verts: the last patch, kept while unsettled */
    int32_t nkeep, keep;
} sw_cond;

/* Lays out the patch's budget (cz, from sw_cond_plan) and its per vertex and tet stamps. */
void sw_cond_take(sw_mem_plan *p, const sw_blob_view *v, const sw_cond_sizes *cz, sw_cond *c);

/* The lists a patch's pair elements come from. */
enum { SW_COND_TRAINED = 0, SW_COND_DETECTED = 1 };

/* The sizes for a budget of max_verts patch vertices (0: off), max_pairs pose-space pairs
 * and max_detected detected pairs (self_contact.h), of which max_self_seeds may seed. */
sw_cond_sizes sw_cond_plan(const sw_blob_view *v, uint32_t max_verts, int32_t max_world,
                           int32_t max_pairs, int32_t max_detected, int32_t max_self_seeds);

/* Creation (no allocation: the arrays are laid out by the instance): per-domain volumes,
 * the tet -> cubature map, cleared stamps. rho in world units. */
void sw_cond_build(sw_cond *c, const sw_blob_view *v, double rho);

/* Forgets the seeds and the patch history (a reset or a teleport). */
void sw_cond_forget(sw_cond *c);

/* The partition oracle at the state q: seeds from the world's candidates penetrating at
 * q (wc NULL: no world) and, with seed_self, the vertices of the detected self-contact
 * pairs in use (sc; novel_contact.h), with those of the two steps before, and in a dynamic
 * step the last patch while it has not settled; the growth, the full tets and ring copies
 * (their skinning and Jacobians), the pose-space and detected pairs the patch touches, and
 * the patch's start positions (the subspace position plus the deviation the vertex had
 * when it was last in a patch). Returns the patch's vertex count; then sw_cond_detect and
 * sw_cond_tag_candidates. */
int32_t sw_cond_oracle(sw_cond *c, const sw_reduced *red, sw_world_contacts *wc, sw_pose_space *ps,
                       sw_self_contacts *sc, int seed_self, const double *q);

/* The world's candidates of the patch's surface vertices at their patch positions, as
 * sw_world_contacts_at's mode says (world_contact.h). Returns how many were added; tag
 * them afterwards. */
int32_t sw_cond_detect(const sw_cond *c, sw_world_contacts *wc, sw_wc_at_mode mode);

/* Tags the world candidates whose vertex is in the patch (after new ones were added). */
void sw_cond_tag_candidates(const sw_cond *c, sw_world_contacts *wc);

/* The coupled Newton (see above) from (s->q, c->x) into them; fills st like
 * sw_newton_solve plus pcg_iterations. wc (ct's world contacts, or NULL without a world)
 * gets the patch's laws taken again at the iterate after the first updates. */
sinew_result sw_cond_solve(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                           sw_world_contacts *wc, sw_solver *s, const sw_dyn_coef *dc,
                           sinew_step_stats *st);

/* The pieces of the solve, for tests: the patch's cubature weights (eq. 4.12's
 * renormalisation) applied and restored; Phi(q, x) with its gradient into (red->g, c->gf)
 * and with want_hess the Hessian's parts; y = H z for z = (dq, dx) (R + 3 nf) with the
 * parts of the last evaluation, ctx an sw_cond_system. */
typedef struct sw_cond_system {
    sw_cond *c;
    sw_reduced *red;
    const sw_solver *s;
} sw_cond_system;
void sw_cond_weights_apply(sw_cond *c);
void sw_cond_weights_restore(sw_cond *c);
double sw_cond_potential(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                         const sw_solver *s, const double *q, const double *x,
                         const sw_dyn_coef *dc, int want_hess);
void sw_cond_hessian_apply(void *ctx, const double *z, double *y);
/* Phi at the iterate of the last evaluation (which took the Hessian) once the patch's
 * world laws were taken again and its undecided pairs reset: the elastic terms and the
 * decided pairs kept, the undecided pairs, the world and the inertia evaluated, as
 * sw_cond_potential would give them (to rounding: the new terms are summed last). */
double sw_cond_potential_refreshed(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                                   const double *x, const sw_dyn_coef *dc);

/* Dynamic steps (patch_dynamics.c): the patch vertices' start state x_n, v_n (their own
 * from the last step when they were in its patch, else the subspace's motion under the
 * two poses before, dq_prev2 NULL: at rest, dq_prev NULL: no pose history) and their
 * start at x_n + h v_n; the backward-Euler terms of Phi, sum m/2 (cm |x - x_n - h v_n|^2
 * + cd alpha |x - x_n|^2), with their gradient into c->gf and Hessian into c->Dw (the
 * Rayleigh stiffness part is left to the reduced coordinates); after the step the state
 * kept and the dynamics oracle (keep: the patch stays while it moves). */
void sw_cond_dynamics_start(sw_cond *c, const sw_reduced *red, const sw_solver *s,
                            const sw_dyn_coef *dc, const sw_dualquat *dq_prev,
                            const sw_dualquat *dq_prev2);
double sw_cond_inertia(sw_cond *c, const sw_dyn_coef *dc, const double *x, int want_hess);
void sw_cond_dynamics_finish(sw_cond *c, const sw_reduced *red, const double *q,
                             const sw_dyn_coef *dc, double size);

/* After a step: each patch vertex's deviation from its subspace position at q (the next
 * patch's start); the patch stays readable until the next oracle. */
void sw_cond_finish(sw_cond *c, const sw_reduced *red, const double *q);

/* Patch vertex i's subspace position at q (its first tet's domain copy), skinned by the
 * pose dq (NULL: the step's). */
void sw_cond_subspace_position(const sw_cond *c, const sw_reduced *red, int32_t i,
                               const sw_dualquat *dq, const double *q, double x[3]);

/* The patch position of simulation vertex gv, or NULL when it is not in the patch. */
static inline const double *sw_cond_position(const sw_cond *c, int32_t gv) {
    if (!c->in_patch || c->nf == 0 || c->in_patch[gv] != c->stamp) return 0;
    return c->x + 3 * (int64_t)c->vloc[gv];
}

/* The subspace position of vertex gv's copy (domain d, local lv) at q, with the skinning
 * of the current pose (red's bone dual quaternions): R (rest + U q_d) + t; J = R U
 * (3 x r_d) when J is not NULL. */
void sw_cond_copy_position(const sw_reduced *red, int32_t gv, int32_t d, int32_t lv,
                           const double *q, double x[3], double *J);

#endif
