/* The full-space reference simulator (thesis §2.1, §3.1): co-rotational linear tets,
 * vertices inside bones driven kinematically by the skeleton, quasistatic Newton or
 * implicit dynamics (backward Euler or Newmark average acceleration) with Rayleigh
 * damping, penalty self-contact (eqs. 3.4-3.6), a ground plane and the collision world
 * (sinew_world.h, worldcontact.h: the runtime's law, detected every contact round).
 *
 * Every step minimises one incremental potential over the free vertices,
 *   Phi(x) = E(x) + Ec(x) + Eg(x) + Ew(x) + c_m/2 |x - xhat|_M^2 + c_d/2 |x - x_n|_D^2
 *            - s (x - x_n)^T D v_n - f_ext^T x,
 * with D = alpha M + beta K(x_n) frozen at the start of the step (Rayleigh), so a
 * backtracking line search on Phi makes Newton robust:
 *   quasistatic:    c_m = c_d = s = 0;
 *   backward Euler: c_m = 1/h^2, xhat = x_n + h v_n, c_d = 1/h, s = 0;
 *   Newmark (1/4, 1/2): c_m = 4/h^2, xhat = x_n + h v_n + h^2/4 a_n, c_d = 2/h, s = 1.
 * The Newton system (K + Kc + Kg + c_m M + c_d D) dx = -grad Phi is solved by
 * block-Jacobi PCG, warm-started from the previous Newton update, or by a sparse direct
 * Cholesky (CHOLMOD, sparse_chol.h; --solver cholmod); assembly and the matrix product
 * run on a pthread pool. Self-contacts are detected once per contact
 * round and frozen while Newton converges (re-detecting every iteration makes Newton
 * chase a changing energy and stall); a round's Newton ends early once its set would
 * change (the set check, fullsim_step.c). Between rounds the set is updated as an active
 * set: new penetrations join, and a pair the solve held by pulling (its vertex in
 * front of its surface point, eq. 3.12, by more than half its detection depth: a
 * hysteresis band, fullsim_step.c) leaves, so contacts push but never glue a fold shut;
 * a resolved contact sits near its surface and stays. Each step
 * starts a fresh set. Results are bitwise identical for any thread
 * count: every reduction has a fixed order. */
#ifndef SW_FULLSIM_H
#define SW_FULLSIM_H

#include "selfcontact.h"
#include "sinew/sinew_world.h"
#include "sw_mesh.h"

typedef enum sw_integrator {
    SW_QUASISTATIC = 0,
    SW_BACKWARD_EULER = 1,
    SW_NEWMARK = 2
} sw_integrator;

/* Which element Hessian Newton uses. Clamping compressed elements' negative
 * eigenvalues (McAdams 2011) keeps every solve SPD but slows Newton to a linear rate
 * (measured ~0.4 per iteration on a bent cylinder); the exact Hessian converges
 * quadratically wherever the global Hessian is positive definite. */
typedef enum sw_hessian_mode {
    SW_HESSIAN_ADAPTIVE = 0,  /* exact; where PCG meets negative curvature before it has made
                                 progress, projected for that iteration (fullsim_system.c)
                                 (default) */
    SW_HESSIAN_PROJECTED = 1, /* always projected to PSD */
    SW_HESSIAN_EXACT = 2      /* always exact, truncated PCG (Newton-CG) */
} sw_hessian_mode;

const char *sw_hessian_mode_name(sw_hessian_mode m);

/* Which linear solver takes the Newton systems. */
typedef enum sw_linear_solver {
    /* PCG: measured on the finger's 40-frame fold at 20K tets (3,984 vertices, 2 cores),
     * a CHOLMOD factorisation costs 140-270 ms, more than a whole PCG solve of the same
     * Newton system, and the exact co-rotational Hessian of the fold is indefinite in
     * most iterations, so adaptive Newton factors twice (docs/notes/reference.md) */
    SW_SOLVER_AUTO = 0,
    SW_SOLVER_CHOLMOD = 1, /* sparse direct, supernodal Cholesky (sparse_chol.h) */
    SW_SOLVER_PCG = 2      /* block-Jacobi PCG */
} sw_linear_solver;

const char *sw_linear_solver_name(sw_linear_solver s);

typedef struct sw_fullsim_params {
    sw_integrator integrator;
    double dt;               /* seconds per step (default 1/30) */
    double rayleigh_alpha;   /* mass damping (default 0.01, thesis §2.1.3) */
    double rayleigh_beta;    /* stiffness damping (default 0.001) */
    double gravity[3];       /* default 0: the reference isolates the skin's own physics */
    int self_contact;        /* penalty self-contact forces on (default 1) */
    double contact_k;        /* kc of eq. 3.4 (default 1e6, DESIGN.md §8) */
    double contact_alpha;    /* anisotropy alpha of eq. 3.5 (default 0.5) */
    double neighbour_factor; /* DESIGN.md §8 (default 1.8) */
    int ground;              /* ground plane y = ground_height on (default 0) */
    double ground_height;
    double ground_k;         /* penalty per unit rest area (default contact_k) */
    sw_hessian_mode hessian; /* default SW_HESSIAN_ADAPTIVE */
    sw_linear_solver solver; /* default SW_SOLVER_AUTO */
    int contact_rounds;      /* self-contact: detect, freeze the contacts, converge Newton on
                                that smooth energy, re-detect and add new penetrations; stop
                                when none is new or after this many rounds (default 60:
                                with 8, every contact frame of the 20K and 50K finger
                                stopped unsettled and its fold moved by up to 0.45 of the
                                skinning correction when the cap was raised to 30; with
                                the set check, 30 left 2 of the 50K bake's 42 solutions
                                unsettled, 60 none) */
    int contact_set_check;   /* 1 (default): a round's Newton stops once its contact set
                                would change (fullsim_step.c); 0: every round converges */
    int max_newton;          /* per step (default 20) */
    double newton_rtol;      /* stop when |grad| <= rtol * |grad at first iterate| (1e-4) */
    double pcg_rtol;         /* PCG relative residual (default 1e-3) */
    int pcg_max;             /* default 1000 */
    int threads;             /* 0: all cores */
    /* the collision world (NULL: none), with the runtime's law (world_penalty.h); the
     * caller moves its colliders between steps and keeps it alive */
    const sinew_world *world;
    double world_radius; /* detection radius; 0: 2% of the rest bounding-box diagonal */
} sw_fullsim_params;

sw_fullsim_params sw_fullsim_params_default(void);

/* The solver options the tools take for the reference (tools/common/reference_args.h):
 * from's solver, hessian, contact_rounds and contact_set_check into *to, which keeps the
 * rest (the physics, the tolerances, the threads). */
void sw_fullsim_params_take_solver(sw_fullsim_params *to, const sw_fullsim_params *from);

typedef struct sw_fullsim_stats {
    int newton_iters;
    int pcg_iters;       /* summed over the step's Newton iterations */
    int projected_iters; /* Newton iterations that fell back to the projected Hessian */
    int contact_rounds;  /* contact rounds used (0 without self-contact) */
    double grad_norm0;   /* |grad Phi| at the first iterate */
    double grad_norm;    /* at exit */
    int converged;
    int32_t contacts;          /* penetrating vertices at the final positions */
    int contacts_unsettled;    /* 1: the round cap stopped the contact rounds while the set
                                  still changed (a penetrating vertex outside it, or a pair
                                  that no longer collides): the result depends on the cap */
    sw_linear_solver solver;   /* the solver that ran (CHOLMOD or PCG) */
    int factorizations;        /* numeric factorisations (direct solver) */
    double max_penetration;    /* deepest self-penetration at the final iterate (world units) */
    double ground_penetration; /* deepest vertex below the ground plane */
    double world_penetration;  /* deepest surface vertex inside a world collider */
    int32_t world_candidates;  /* (vertex, collider) candidates of the final round */
    int32_t world_contacts;    /* surface vertices inside a collider at the final positions */
    double seconds;            /* wall time of the step */
    double energy_elastic;     /* E(x) at exit */
    double energy_kinetic;     /* 1/2 v^T M v at exit (0 in quasistatic) */
    double grad_history[32];   /* |grad Phi| after k Newton updates (k < 32; a contact round
                                  re-detection overwrites its entry) */
} sw_fullsim_stats;

typedef struct sw_fullsim sw_fullsim;

/* The character must outlive the simulator. Starts at the rest shape, at rest. */
sinew_result sw_fullsim_create(const sw_character *c, const sw_fullsim_params *p, sw_fullsim **out,
                               sw_error *err);
void sw_fullsim_destroy(sw_fullsim *sim);

/* One step towards the pose given by bone transforms T (12*nbones, rest -> world).
 * Returns SINEW_ERROR_NOT_FINITE (state restored to the previous step) when T or
 * the solve produced a non-finite value, SINEW_ERROR_NOT_CONVERGED when Newton hit
 * max_newton without reaching its tolerance (the state is kept: it is the best
 * iterate), SINEW_OK otherwise. */
sinew_result sw_fullsim_step(sw_fullsim *sim, const double *T, sw_fullsim_stats *stats);

/* The last step's self-contact set: every pair its contact rounds gathered, with the
 * triangle, barycentrics and normal of the round that last saw it (the set the final
 * solve converged with; empty without self-contact). Valid until the next step. */
const struct sw_contact *sw_fullsim_contacts(const sw_fullsim *sim, int32_t *count);

/* Current positions / velocities (3*nverts). */
const double *sw_fullsim_positions(const sw_fullsim *sim);
double *sw_fullsim_velocities(sw_fullsim *sim);
/* Overwrites the state (e.g. to start an oscillation test from a perturbed shape, or
 * a second path from a solution of an earlier step); v may be NULL (zero). T, when not
 * NULL, is the pose x was solved at: the next step's warm start moves the flesh by the
 * change of the skinned shape since that pose (NULL: since the last step's pose).
 * Accelerations are set consistent with x: M a = f(x) + M g (damping and contact
 * forces left out). */
void sw_fullsim_set_state(sw_fullsim *sim, const double *T, const double *x, const double *v);

/* The surface (boundary triangles) the simulator uses. */
const sw_surface *sw_fullsim_surface(const sw_fullsim *sim);
/* Lumped vertex masses (nverts). */
const double *sw_fullsim_masses(const sw_fullsim *sim);
/* Number of vertices driven by bones. */
int32_t sw_fullsim_driven_count(const sw_fullsim *sim);
/* Static responses u_j = K^-1 f_j of the rest shape (the linear elasticity of the free
 * vertices, driven vertices held, no contact) to n loads f_j (3 nverts each; entries of
 * driven vertices ignored), solved as the simulator's Newton systems are (sparse direct
 * or PCG to pcg_rtol). A quasistatic simulator only; it leaves the simulator at rest.
 * The bake's load-dependent Ritz vectors (bake_basis.c). */
sinew_result sw_fullsim_rest_response(sw_fullsim *sim, int32_t n, const double *f, double *u,
                                      sw_error *err);
/* Elastic energy E(x) of the current positions. */
double sw_fullsim_elastic_energy(sw_fullsim *sim);
#endif
