/* The bake's state and the helpers its stages share (bake_state.c), below the stages:
 * every stage file includes this, none the orchestrator's bake.h. */
#ifndef SW_BAKE_STATE_H
#define SW_BAKE_STATE_H

#include <pthread.h>

#include "bake_eval.h"
#include "bake_params.h"
#include "dqs.h"
#include "embed.h"
#include "fullsim.h"
#include "selfcontact.h"
#include "thread_pool.h"

/* OpenBLAS (linked explicitly, precompute/CMakeLists.txt). The bake's dense products are
 * small and its parallelism is across training poses and domains, so its stages call
 * this with 1: OpenBLAS's own worker threads only add contention (and races a thread
 * sanitizer cannot see through). */
void openblas_set_num_threads(int num_threads);

/* A sequence of poses simulated in order (each warm-starts the next). */
typedef struct sw_pose_seq {
    int32_t npose;
    double *T;      /* npose * 12 * nbones bone transforms */
    double *x;      /* npose * 3 * nverts full-space solutions (filled by simulate) */
    int32_t *clip;  /* npose: the clip a pose is a frame of (sw_bake_result.train_clip), or -1 */
    int32_t *frame; /* npose: its frame in that clip, or -1 */
    int failed;     /* poses whose solve returned NOT_FINITE */
    int unsettled;  /* poses whose contact set the simulator's round cap left unsettled */
    /* the reference's self-contact set of every solution (filled by simulate): pose k
       owns contacts[contact_ptr[k], contact_ptr[k+1]) */
    int32_t *contact_ptr; /* npose + 1 */
    sw_contact *contacts;
    int32_t ncontacts, contact_cap;
    int oom; /* the contact sets did not fit in memory */
    /* solved after this sequence, each warm-started from its last solution: the clip's
       held-out frames and its return path continue the training frames' path */
    struct sw_pose_seq *then[2];
    int continues;  /* this sequence is another's `then`: not scheduled on its own */
    int from_cache; /* its solutions were read from the simulate cache: not solved again */
    int skip;       /* another shard's item (sw_bake_params.shard_count): not solved here */
    double seconds; /* wall time of its chain's solves (simulate, on the chain's first) */
} sw_pose_seq;

/* The state, grouped by the stage that writes it (bake.c, sw_bake_stages): a stage
 * reads the groups of the stages before it and writes its own. */
typedef struct sw_rig_state { /* prepare */
    sw_character ch;          /* the character with the bake's weights (mesh/skeleton borrowed) */
    double *weights;          /* owned nverts * nbones */
    int32_t nv, nt, nb;
    /* top-4 skin influences (runtime's DQS) */
    int32_t *skin_bone;  /* 4 nv */
    double *skin_weight; /* 4 nv */
    double *mass;        /* nv lumped masses (all tets) */
} sw_rig_state;

typedef struct sw_domains_state { /* domains */
    int32_t nd;
    int32_t *tet_domain;   /* nt */
    int32_t *domain_bone;  /* nd */
    int32_t *dom_vert_ptr; /* nd + 1 into dom_verts */
    int32_t *dom_verts;    /* copies: global vertex ids, ascending per domain */
    int32_t *dom_tet_ptr;  /* nd + 1 into dom_tets */
    int32_t *dom_tets;     /* tets of each domain, ascending */
    double *copy_mass;     /* per copy: mass from the domain's own tets */
} sw_domains_state;

typedef struct sw_poses_state { /* poses; simulate fills the sequences' solutions */
    sw_pose_seq *train;
    int32_t ntrain_seq;
    double *sweep_axis, *sweep_angle; /* per bone: each joint's sweep (bake_poses.c) */
    int32_t return_poses;             /* poses on the way home (bake_poses.c, return_frames) */
    int32_t pair_sweep_poses; /* poses of the joints swept with their parents (sweep_pairs) */
    sw_pose_seq heldout;
    int64_t solved_poses; /* poses the simulate stage solved (not read from the cache) */
} sw_poses_state;

typedef struct sw_basis_state { /* basis: per domain 3 n_d x r_d, row-major */
    int32_t *rank;
    int32_t *rank_trained; /* per domain: its columns from rank_trained on are from physics */
    int32_t *rank_dynamic; /* per domain: its columns from rank_dynamic on are inertia modes */
    double **U;
    int32_t rank_total;
    double *train_q;    /* ntrain x rank_total: projected training solutions */
    double *train_pose; /* ntrain x 4 nbones: pose features */
    int32_t ntrain;
} sw_basis_state;

typedef struct sw_cubature_state { /* cubature: per domain local tet index into dom_tets and weights
                                    */
    int32_t *n;
    int32_t **local; /* index into the domain's dom_tets range */
    double **w;
} sw_cubature_state;

typedef struct sw_contacts_state { /* contacts: pose-space self-contact pairs of the training
                                     solutions (bake_contacts.c) */
    int32_t ncontacts;
    int32_t *contact_ptr;   /* ntrain + 1 */
    int32_t *contact_verts; /* 8 per contact */
    double *contact_data;   /* 7 per contact */
} sw_contacts_state;

typedef struct sw_reduce_state { /* reduce */
    /* interface springs (bake_reduce.c): their Hessian at unit stiffness (rank_total^2)
       and the stiffness of one vertex of the mesh, E h, the unit of the choice */
    double *spring_unit;
    double spring_eh;
    /* the view's spring Hessian by domain blocks (nspring doubles, owned by the result):
     * springs scales spring_unit_packed, the same blocks of spring_unit, into it */
    double *spring, *spring_unit_packed;
    int64_t nspring;
} sw_reduce_state;

typedef struct sw_bake_state {
    /* inputs */
    const sw_bake_params *p;
    const sw_character *c;
    sw_pool *pool;
    /* the stages' results */
    sw_rig_state rig;
    sw_embedding embed; /* embed: the render mesh in the tets (none: nverts 0) */
    sw_domains_state domains;
    sw_poses_state poses;
    sw_basis_state basis;
    sw_cubature_state cubature;
    sw_contacts_state contacts;
    sw_reduce_state reduce;
    /* progress of the running stage (sw_bake_progress) */
    pthread_mutex_t progress_lock;
    int64_t progress_done, progress_total;
    double progress_t0;
    const char *progress_stage;
} sw_bake_state;

/* The state's memory (every group; what a failed stage leaves too) and the pool. */
void sw_bake_state_free(sw_bake_state *s);

/* Starts stage progress over `total` units; then sw_bake_progress(s, 1) from any thread
 * as units finish: params->on_progress sees them one call at a time. */
void sw_bake_progress_begin(sw_bake_state *s, const char *stage, int64_t total);
void sw_bake_progress(sw_bake_state *s, int64_t units);

/* Bone transforms T as the runtime's step sees them (sw_pose_snap: relative to bone 0,
 * snapped to the grid of the rest mesh's size), into L (12 nb): what the pose features and
 * the per-pair features are measured on, so that the step at a training pose finds it at
 * distance 0. */
void sw_bake_pose_snapped(const sw_bake_state *s, const double *T, double *L);
/* The translations' grid of it (sw_pose_grid of the rest mesh's size). O(nv). */
double sw_bake_pose_grid(const sw_bake_state *s);

/* Per-vertex DQS transforms of all vertices for bone transforms T. */
void sw_bake_skin_transforms(const sw_bake_state *s, const double *T, double *R /* 9 nv */,
                             double *t /* 3 nv */);

/* Helpers of the stages after domains and basis (bake_shapes.c). */
/* Rest data of domain dm's tets in dom_tets order: each corner's copy in the domain
 * (tet_local, 4 a tet), Dm^-1 (9 a tet; zero for a degenerate tet) and the weight of its
 * elastic energy at the character's mu and lambda, evol: its rest volume times its painted
 * stiffness multiplier (0 for a degenerate tet). local_of: nverts ints of scratch. */
void sw_bake_domain_tets(const sw_bake_state *s, int32_t dm, int32_t *local_of, int32_t *tet_local,
                         double *dminv, double *evol);
/* The reference simulator's parameters of the simulate stage (threads aside). */
sw_fullsim_params sw_bake_sim_params(const sw_bake_params *p);
/* The simulate stage's cache (bake_cache.c; sw_bake_params.cache_dir, nothing without
 * one): read marks the pose chains the cache holds as solved (sw_pose_seq.from_cache),
 * *all when it holds every one; store writes the chains that were solved and returns
 * how many it could not. */
sinew_result sw_bake_cache_read(sw_bake_state *s, int *all, sw_error *err);
int32_t sw_bake_cache_store(sw_bake_state *s);
/* The simulate stage's work items (sw_bake_item), one per chain the cache keeps, into
 * out->items in the stage's order, each with its shard (the longest first to the shard
 * with the fewest poses so far: a deterministic balance of the poses); the chains not to
 * solve here are marked skip: all of them for a plan, the other shards' for a shard.
 * Called after sw_bake_cache_read. */
sinew_result sw_bake_cache_items(sw_bake_state *s, sw_bake_result *out, sw_error *err);
/* Each item's solve time from its chain (after the solves). */
void sw_bake_cache_item_times(const sw_bake_state *s, sw_bake_result *out);
/* The un-skinned displacements of one pose (thesis eq. 4.13): d (3 nv) from
 * positions x and bone transforms T, d_v = R_v^T (x_v - t_v) - rest_v (0 at bone-driven
 * vertices); R (9 nv) and t (3 nv) are scratch for the skinning transforms. */
void sw_bake_unskin(const sw_bake_state *s, const double *T, const double *x, double *R, double *t,
                    double *d);
/* G (na x nb) = A K B^T: the products of the rows of A and B (na and nb rows of domain dm's
 * 3 n copies' displacements) in the rest linear-elastic energy of the domain's tets, K
 * the stiffness of the co-rotational energy (eq. 2.3) at rest. B NULL: the
 * Gram matrix of A (na x na). 0 when out of memory. The PCA's strain share
 * (sw_bake_params.pca_strain) and the Galerkin errors (bake_galerkin.c) take them. */
int sw_bake_strain_products(const sw_bake_state *s, int32_t dm, const double *A, int32_t na,
                            const double *B, int32_t nb, double *G);
/* The ritz lowest vibration modes in the span of nl static responses U (n3 doubles each,
 * U = K^-1 F with K the rest stiffness, driven vertices held) to the loads F, mass-weighted
 * by the vertices' lumped masses m (n3 / 3): a Rayleigh-Ritz step, written over U's first
 * rows, lowest first. With B = U M U^T = V diag(l) V^T and W = V diag(l^-1/2) over B's
 * independent directions (l above SW_RITZ_DEPENDENT of the largest), the modes are
 * (W z)^T U for the eigenvectors z of W^T (U F^T) W (u_i^T K u_j = u_i^T f_j: no K needed).
 * Returns how many were written (fewer than ritz when the span is smaller), 0 when the
 * responses span nothing, -1 out of memory; lambda (ritz doubles, or NULL) takes their
 * eigenvalues, the squared angular frequencies. The inertia modes take them (bake_basis.c). */
int32_t sw_bake_ritz_modes(double *U, const double *F, const double *m, int32_t nl, int64_t n3,
                           int32_t ritz, double *lambda);
/* How many of n vibration modes, squared frequencies lambda ascending, swing at time step h:
 * the leading ones with omega h <= SW_INERTIA_MAX_OMEGA_H and omega <= SW_INERTIA_OMEGA_SPREAD
 * times the lowest (bake_params.h). */
int32_t sw_bake_ritz_swinging(const double *lambda, int32_t n, double h);
/* The pairs stage's cubature of one (pose, group): weights w (n) >= 0 for the columns of A
 * (m x n, column-major: each pair's reduced contact force) with |A w - A 1| <= tol |A 1|,
 * by the cubature trainer's greedy selector (cubature_train.h); a zero column keeps
 * weight 0. */
sinew_result sw_bake_pair_cubature(const double *A, int64_t m, int32_t n, double tol, double *w,
                                   sw_error *err);

/* The stages, in the order sw_bake runs them (bake.c, sw_bake_stages, says what each reads
 * and writes; so does each stage file's opening comment). */
sinew_result sw_bake_prepare(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_embed(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_domains(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_poses(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_simulate(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_basis(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_cubature(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_contacts(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_reduce(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_render(sw_bake_state *s, sw_bake_result *out, sw_error *err);
/* The asset description's sections (bake_asset.c), after the render mesh's. */
sinew_result sw_bake_asset(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_cond(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_pairs(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_springs(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_galerkin(sw_bake_state *s, sw_bake_result *out, sw_error *err);
sinew_result sw_bake_equilibrium(sw_bake_state *s, sw_bake_result *out, sw_error *err);
/* The pose-space level of detail's sections and every level's held-out error (bake_lod.c). */
sinew_result sw_bake_lod(sw_bake_state *s, sw_bake_result *out, sw_error *err);

#endif
