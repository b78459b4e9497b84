/* The full-space reference's state, shared by its three files: fullsim.c (creation,
 * state access), fullsim_system.c (the incremental potential, its gradient and the
 * Newton system) and fullsim_step.c (the step: contact, Newton, line search). */
#ifndef SW_FULLSIM_INTERNAL_H
#define SW_FULLSIM_INTERNAL_H

#include "fullsim.h"

#include "bsr_matrix.h"
#include "pcg.h"
#include "sparse_chol.h"
#include "worldcontact.h"

struct sw_fullsim {
    sw_fullsim_params p;
    const sw_character *c;
    int32_t nv, nt;
    double mu, lambda;
    double *DmInv, *vol; /* 9*nt, nt */
    double *mass;        /* nv lumped masses */
    unsigned char *free_mask;
    int32_t ndriven;
    sw_surface surf;
    double *vert_area; /* nv: rest surface area around each surface vertex (0 inside) */
    sw_selfcontact *sc;
    sw_bsr K;               /* pattern; val holds the Newton system matrix during an iteration */
    double *Kn;             /* 9*nblocks: K(x_n), the Rayleigh stiffness term (dynamics only) */
    double *Ke;             /* 144*nt element Hessians */
    double *fe;             /* 12*nt element forces */
    double *ee;             /* nt element energies */
    int64_t *inc_ptr, *inc; /* vertex -> element entries (4*t + local), for force gathers */
    double *x, *v, *a, *xn, *vn, *an, *xhat, *Dvn;
    double *skin_prev, *skin_now;
    double *g, *dx, *dx_prev, *tmp, *xtrial, *diag, *Pinv, *fint;
    double *rhs, *kdx; /* Newton right-hand side; K_n (x - x_n) scratch */
    sw_pcg_workspace ws;
    sw_sparse_chol *chol; /* the direct solve, or NULL for PCG */
    sw_pool *pool;
    double c_m, c_d, s; /* integrator coefficients of this step */
    const sw_contact *contacts;
    int32_t ncontacts;
    double gfloor;        /* absolute gradient norm treated as converged */
    uint32_t hess_flags;  /* sw_corot_eval flags of the current evaluation */
    sw_contact *active;   /* the step's contact set: surf.nverts slots, one per vertex */
    int32_t *active_slot; /* nv: slot of a vertex in `active`, or -1 */
    sw_ref_world world;   /* the collision world's candidates of the step */
};
enum { EVAL_ENERGY = 0, EVAL_FORCE = 1, EVAL_HESSIAN = 2 };

int sw_fullsim_dynamic(const sw_fullsim *sim);
/* Evaluates all elements at x; returns the elastic energy (summed in element order). */
double sw_fullsim_evaluate(sw_fullsim *sim, const double *x, int want);
/* Phi(x) with the elastic part already evaluated at x and the contacts sim->contacts. */
double sw_fullsim_potential(sw_fullsim *sim, const double *x, double elastic);
/* y = K(x_n) u, the Rayleigh stiffness frozen at the start of the step (dynamics). */
void sw_fullsim_apply_Kn(sw_fullsim *sim, const double *u, double *y);
/* sim->g = grad Phi at x (masked); returns its norm. */
double sw_fullsim_gradient(sw_fullsim *sim, const double *x);
/* sim->dx = the Newton step for sim->rhs at sim->x (element Hessians in K by the
 * current flags), by the sparse direct solve or PCG; re-solves with projected element
 * Hessians where the system is indefinite (adaptive mode). */
sinew_result sw_fullsim_solve_system(sw_fullsim *sim, sw_fullsim_stats *st);
int sw_fullsim_all_finite(const double *a, int64_t n);
#endif
