/* What a bake takes and what it gives (sw_bake, bake.h): its parameters, its result with
 * the arrays the blob view points into, and the pose measures the bake, the report and the
 * tools share. The stages (bake_state.h) see these, never the orchestrator. */
#ifndef SW_BAKE_PARAMS_H
#define SW_BAKE_PARAMS_H

#include "blob_view.h"
#include "cubature_train.h"
#include "subspace_eval.h"
#include "sw_mesh.h"

/* The stages of sw_bake, in the order it runs them (bake.c, sw_bake_stages; their names,
 * what each reads and writes are there): sw_bake_result.stage_seconds has one slot each. */
#define SW_BAKE_NSTAGES 16
/* The levels of detail a bake measures (sinew_lod). */
#define SW_BAKE_LODS 3

/* The interface springs' stiffnesses a bake chooses from (sw_bake_params.spring_k 0):
 * sw_bake_spring_mult(i) E h for i < SW_SPRING_CHOICES, stiffest first. */
#define SW_SPRING_CHOICES 4
double sw_bake_spring_mult(int i);

/* Inertia modes (sw_bake_params.inertia_modes): the static responses to the domains' six
 * rigid accelerations are reduced to this many vibration modes a domain (bake_basis.c). */
#define SW_INERTIA_RITZ_PER_DOMAIN 3

/* Of those, a mode joins only if it swings at the clips' time step h. Backward Euler shrinks
 * a free swing of frequency omega by 1 / sqrt(1 + (omega h)^2) a step: above omega h = 5 to
 * under a fifth within one frame, no jiggle anyone sees, only rank (a stiff character's
 * modes all lie there). And a mode above three times the lowest frequency moves under a
 * ninth as far as the lowest under the same modal load (the spectra measured:
 * docs/notes/jiggle.md, Modes that swing). */
#define SW_INERTIA_MAX_OMEGA_H 5.0
#define SW_INERTIA_OMEGA_SPREAD 3.0

typedef struct sw_bake_params {
    int32_t max_rank;              /* per domain (default 30) */
    double fold_share;             /* a bone whose tets hold less than this share of the
                                      mesh's volume joins its parent's domain (default 0: every
                                      bone that owns tets is a domain; bake_domains.c) */
    double pca_energy;             /* fraction of snapshot energy kept (default 0.9999) */
    double pca_strain;             /* the PCA's inner product: this share from the snapshots'
                                      rest strain energy, the rest from their plain products
                                      (default 0: plain PCA; bake_basis.c: at the same rank
                                      no better, docs/notes/generalisation.md) */
    double cubature_tol;           /* default 0.05 */
    int32_t cubature_max;          /* per domain (default 1000) */
    sw_cubature_selector selector; /* default NN-HTP */
    int32_t sweep_samples;         /* poses per joint sweep (default 6) */
    int pair_sweeps;               /* also sweep every joint together with its parent joint
                                      (combinations the single sweeps never show): 1 on, 0
                                      off, -1 (default) on where the character's joint range
                                      (sw_character.range) bounds the sweeps (bake_poses.c,
                                      docs/notes/generalisation.md Joint ranges) */
    int sibling_sweeps;            /* also sweep every two sibling joints whose flesh meets
                                      together (default 1; bake_poses.c, sweep_pairs) */
    int32_t max_train_frames;      /* clip frames used for training at most (default 40) */
    int return_path;               /* also train on the way home (bake_poses.c, return_frames):
                                      the first training clip's frames from its last one
                                      backwards, each bent less than the one before, continuing
                                      from the last one's solution. 1 on, 0 off, -1 (default)
                                      on where the held-out frames continue the training
                                      clip (a character's own clip split by
                                      heldout_fraction: what plays after the training part
                                      starts from its last frame), off for training clips
                                      named in train_clips (docs/notes/accuracy.md The way
                                      home) */
    int pose_force;                /* the pose-space equilibrium force (bake_equilibrium.c:
                                      the training poses' projected solutions made the
                                      runtime's equilibria there; default 1) */
    int contact_modes;             /* self-contact force modes (thesis §3.3.1): the static
                                      responses to the training poses' contact forces join
                                      the basis (bake_basis.c; default 0) */
    double contact_cubature_tol;   /* pose-space pairs per pair of domains (bake_pairs.c): each
                                      training pose's pairs of a pair of domains reduced to
                                      a cubature that reproduces their reduced contact force
                                      to this tolerance (default 0.05; 0: every pair kept at
                                      weight 1) */
    int inertia_modes;             /* for the dynamic step: basis modes for the inertia of the
                                      bones' accelerations, the lowest vibration modes of
                                      their static responses (SW_INERTIA_RITZ_PER_DOMAIN a
                                      domain), and the cubature trained on them
                                      (bake_basis.c; default 0: they move the quasistatic
                                      shapes, docs/notes/jiggle.md) */
    double heldout_fraction;       /* last part of the clip held out (default 0.4) */
    int ship_split;                /* the blob a tool ships from a character's own clip split
                                      by heldout_fraction: 0 (default) re-baked on the whole
                                      clip once the split has been measured
                                      (sw_bake_ships_whole_clip), 1 the split's own blob, the
                                      one the held-out figures measure. sw_bake itself always
                                      bakes the split. */
    int32_t random_poses;          /* held-out poses when there is no clip (default 10) */
    int32_t heldout_steps;         /* ... each reached from the one before in this many
                                      held-out poses, 1..64 (default 4): the reference is
                                      path dependent, and a jump of up to 90 degrees a
                                      joint lands its contact on another branch
                                      (docs/notes/generalisation.md, "Held-out poses on a path") */
    int self_contact;              /* in the training simulations (default 1) */
    /* The full-space reference's solver options (fullsim.h): its solver, hessian,
       contact_rounds and contact_set_check are taken for every full-space solve of the
       bake (training, held-out, the spread), and a change of them misses the cache. NULL
       (default): sw_fullsim_params_default's. */
    const struct sw_fullsim_params *reference;
    /* A folder for the simulate stage's results (NULL, the default: none): a bake finds
       there the full-space solutions of a bake with the same mesh, weights, material,
       simulator and poses and skips solving them; otherwise it stores its own
       (bake_cache.c). A re-bake that changes only the cubature, the rank or the report
       then takes seconds, not minutes. */
    const char *cache_dir;
    /* the dynamic step's Rayleigh damping, C = alpha M + beta K (thesis §2.1.3; defaults
       0.01 and 0.001); beta K follows painted material, damping soft flesh less */
    double rayleigh_alpha, rayleigh_beta;
    double spring_k; /* interface springs per copy pair; 0 (default): the bake chooses among
                        SW_SPRING_CHOICES multiples of E h (h the mean rest edge) the one the
                        training poses prefer (bake_springs.c) */
    int threads;     /* 0: all cores */
    uint64_t seed;   /* the random draws: held-out poses, adaptive candidates, cubature
                        candidates (default 0x5eed5eed) */
    int progress;    /* print stage progress to stderr */
    /* Called as a long stage advances: `done` of `total` units (solved poses in
       "simulate", trained domains in "cubature"), `elapsed` seconds since the stage
       began. Called from the bake's worker threads, one call at a time (the bake
       serialises them), with `done` rising to `total`; NULL: none. */
    void (*on_progress)(void *user, const char *stage, int64_t done, int64_t total, double elapsed);
    void *progress_user;
    /* Training and held-out clips of their own (a glTF/FBX file's clips, by name): with
       ntrain_clips > 0 the training poses are frames of train_clips (each its own path from rest,
       at most max_train_frames of it) and the joint sweeps, the held-out poses frames of
       heldout_clips (one path from rest, clip after clip, at most max_train_frames of each), and
       the character's clip and heldout_fraction are not used for poses. The clips must have the
       skeleton's bones; held-out clips need training clips. NULL/0 (default): the character's clip,
       split as above. */
    const sw_clip *train_clips;
    int32_t ntrain_clips;
    const sw_clip *heldout_clips;
    int32_t nheldout_clips;
    /* Training poses of the caller's own (12 nbones each, as a clip's frames), solved
       extra_chain at a time on a path from rest after the sweeps (0: all on one path);
       the adaptive loop adds its poses here (bake_adaptive.h). NULL/0 (default): none. */
    const double *extra_poses;
    int32_t nextra_poses, extra_chain;
    int compare_selectors; /* also train the other two selectors on the same data and
                              report their sizes and times (the blob keeps `selector`) */
    /* The bake in work items for a farm (docs/baking.md, "Baking on a farm"): an item is
       one cache entry of the simulate stage, a chain of full-space solves from rest
       (bake_cache.c). With plan_only or shard_count > 0 sw_bake runs only the stages
       flagged `solutions` (bake.c) and stops after simulate, which lists its items in
       sw_bake_result.items: plan_only solves none; shard_count > 0 solves only the items
       of shard shard_index (0..shard_count-1) that cache_dir lacks and stores them there.
       A later sw_bake with the same cache_dir then reads them all and only reduces.
       Default 0: the whole bake. */
    int plan_only;
    int32_t shard_index, shard_count;
} sw_bake_params;

/* One work item of the simulate stage (sw_bake_params.plan_only, shard_count). */
typedef struct sw_bake_item {
    uint64_t key;   /* the hash of every input of its solves: its cache entry's name */
    int32_t nseq;   /* sequences in the chain (a path and the paths that continue it) */
    int32_t poses;  /* full-space solves in it */
    int32_t shard;  /* the shard that solves it (of shard_count; 0 without shards) */
    int cached;     /* found in the cache before this run solved anything */
    double seconds; /* wall time of its solves in this run (0: not solved here) */
} sw_bake_item;

sw_bake_params sw_bake_params_default(void);

/* What the bake made, plus the arrays the view points into (owned). */
typedef struct sw_bake_result {
    sw_blob_view view;
    /* the arrays the view points into (sw_bake_own; freed by sw_bake_result_free) */
    void **owned;
    int32_t nowned, owned_cap;
    /* report */
    double stage_seconds[SW_BAKE_NSTAGES]; /* per stage, sw_bake_stages' order (0: not run) */
    int32_t ntrain, nheldout;
    /* reference solutions whose self-contact set the simulator's round cap stopped
       while it still changed (sw_fullsim_stats.contacts_unsettled): their shape in the
       fold depends on the cap, and so does the error measured against them */
    int32_t train_unsettled, heldout_unsettled;
    int simulate_cached;       /* the simulate stage read all its solutions from the cache */
    int32_t simulate_solved;   /* poses it solved (the others it read from the cache) */
    int32_t return_poses;      /* training poses on the way home (sw_bake_params.return_path) */
    int32_t pair_sweep_poses;  /* training poses of the joints swept with their parents
                                  (sw_bake_params.pair_sweeps) */
    double train_proj_error;   /* basis projection error of the training snapshots */
    double heldout_proj_error; /* ... of the held-out snapshots (never used to build) */
    /* the held-out projection error onto the trained modes alone, without the modes from
       physics (--contact-modes, --inertia-modes), and their rank: what those modes add to
       motion never seen (equal to the above, and rank_total, without them) */
    double heldout_proj_error_trained;
    int32_t rank_trained;
    /* the same snapshots projected in the reduced model's linearised energy, its domains
       coupled by the blob's springs: the minimum the step finds, before the cubature, the
       contact and the nonlinearity (bake_galerkin.c; NAN when that energy is not
       definite) */
    double train_galerkin_error, heldout_galerkin_error;
    double cubature_error_max; /* worst per-domain relative cubature training error */
    /* the interface springs' stiffness in the blob, and the choices the bake measured
       (sw_bake_params.spring_k 0): their E h multiples and training errors, stiffest
       first (nspring_tried 0 when the caller gave the stiffness), and their unit E h */
    double spring_k, spring_eh;
    int32_t nspring_tried;
    int32_t force_poses; /* training poses the blob holds an equilibrium force for */
    /* the training error of the blob without its equilibrium force (the reduced model's
       own; -1 when the blob has none, and its training error is that): what the force
       hides on the training poses, and what the bake's sanity limit reads
       (SW_BAKE_MAX_TRAIN_ERROR) */
    double model_train_error;
    /* the pose-space level of detail (bake_lod.c): the share of its training displacements'
       norm its modes drop, and each level's held-out error on the output surface
       (sinew_lod's order; NaN: no held-out poses, or a failed step) */
    double lod_kept;
    double lod_ridge; /* the regression's ridge the validation chose (a share) */
    double lod_heldout[SW_BAKE_LODS];
    double spring_tried_mult[SW_SPRING_CHOICES], spring_tried_err[SW_SPRING_CHOICES];
    /* the render mesh's embedding (sw_character.render; all 0 without one): render
       vertices outside every tet, the largest distance of one from the tets, the largest
       |barycentric|, duplicates welded to another vertex, seconds (embed.h) */
    int32_t render_outside, render_welded;
    double render_max_outside, render_max_bary, embed_seconds;
    double *basis_energy; /* per domain: the share of its snapshots' energy its PCA rank keeps */
    /* per selector (greedy, importance, NN-HTP), summed over domains; filled for the
       chosen selector, and for all three with compare_selectors */
    int32_t selector_points[3];
    double selector_seconds[3];
    double selector_error[3]; /* worst domain's relative fit error */
    double *mass;             /* nverts lumped vertex masses (for evaluation) */
    /* full-space solutions of the held-out poses, for evaluation (3 nverts each) */
    double *heldout_x;
    double *heldout_T; /* 12 nbones per held-out pose */
    /* the reference solved the held-out poses on the path of the first heldout_after
       training poses, after them (the character's clip: its training frames, then the
       held-out ones, as a host plays the clip); 0: from rest (held-out clips of their
       own, random poses). sw_bake_errors steps the runtime along the same path. */
    int32_t heldout_after;
    double *train_x;
    double *train_T;
    /* where each pose came from (the report's per-clip plots): the index of its clip (in
       sw_bake_params.train_clips / heldout_clips, or 0 for the character's clip) and its
       frame there; -1 for poses of no clip (joint sweeps, the return path, random poses) */
    int32_t *train_clip, *train_frame;     /* ntrain */
    int32_t *heldout_clip, *heldout_frame; /* nheldout */
    /* every joint's sweep: its axis (3 per bone) and largest angle (per bone; 0 for a
       joint the training poses do not bend), the range random combined poses span */
    double *sweep_axis, *sweep_angle;
    /* the simulate stage's work items in its order (owned; filled when cache_dir is set
       or with plan_only / shard_count > 0), and the hash of what every item shares (the
       mesh, weights, material and simulator: two plans of one character agree on it) */
    sw_bake_item *items;
    int32_t nitems;
    uint64_t items_character;
} sw_bake_result;

/* n random combined poses, each reached in `steps` poses (n * steps poses of 12 nbones
 * doubles each into T): every joint turned about its sweep axis by a uniform share of its
 * sweep angle, from `seed`, and before each the steps - 1 poses on the way from the pose
 * before it (the first from rest), every joint's angle moved by equal shares. Pose
 * (k + 1) steps - 1 is random pose k whatever `steps` is. The held-out poses of a bake
 * without a clip are these with sw_bake_params.seed and .heldout_steps. local:
 * SW_RANDOM_POSE_SCRATCH nbones doubles of scratch. */
#define SW_RANDOM_POSE_SCRATCH 11
void sw_bake_random_poses(const sw_skeleton *sk, const double *sweep_axis,
                          const double *sweep_angle, uint64_t seed, int32_t n, int32_t steps,
                          double *local, double *T);

/* The largest angle (radians, in [0, pi]) each joint turns from rest in its parent's frame
 * over the n poses T (12 nbones each), raised into angle[nbones] (the caller starts it,
 * e.g. at 0), and with axis (3 per bone, may be NULL) the axis at that angle: the measure
 * of a joint's sweep (the largest bend the training poses give it). */
void sw_bake_joint_reach(const sw_skeleton *sk, const double *T, int32_t n, double *angle,
                         double *axis);

/* A joint the held-out poses turn further than the training poses do. */
typedef struct sw_joint_reach {
    int32_t bone;
    double heldout_deg, train_deg; /* the largest angles (degrees), sw_bake_joint_reach's */
} sw_joint_reach;

/* The joints r's held-out poses bend beyond its training range (its sweeps' angles; the
 * step's rule, sw_joint_beyond_training), the
 * largest multiple of the trained bend first, at most max of them into out; returns how many there
 * are (-1 out of memory). There the basis extrapolates: a held-out clip that turns a joint two or
 * three times as far as the training clips is beyond what the bake learnt
 * (docs/notes/generalisation.md "The Fox's Run is beyond its training"). Random held-out poses stay
 * within the sweeps. */
int32_t sw_bake_beyond_training(const sw_bake_result *r, const sw_skeleton *sk, sw_joint_reach *out,
                                int32_t max);

/* How many joints pose T (12 nbones) bends beyond the trained bends (trained: per bone,
 * radians; a bake's sweep_angle) by the step's rule (sw_joint_beyond_training): the
 * report marks such frames, as the step flags them (SINEW_STEP_BEYOND_TRAINING). -1 out
 * of memory. */
int32_t sw_bake_pose_beyond(const sw_skeleton *sk, const double *T, const double *trained);

/* The fewest clip frames a bake can train on: it trains on the first
 * floor((1 - heldout_fraction) F) frames and holds out the rest, and learns its basis and
 * cubature from the deformation of the training poses (each joint is also swept up to the
 * largest bend those frames give it). A clip that starts at rest (every procedural
 * sample's, every pose clip's) bends nothing in its first frame, so it needs 2 training
 * frames: 4 frames at the default held-out 0.4. Fewer is rejected by sw_bake. */
int32_t sw_bake_min_frames(double heldout_fraction);

void sw_bake_result_free(sw_bake_result *r);
/* Records an owned allocation in the result (freed with it); returns p, or NULL (p freed)
 * when the list cannot grow. */
void *sw_bake_own(sw_bake_result *out, void *p);

/* A training error at or above this share of the correction missed is no usable bake:
 * the subspace misses half of the physics correction on the very poses it was built
 * from (a sound bake misses 1-3%; 1 is no better than plain skinning). sinew-bake
 * refuses to write such a blob unless --force. */
#define SW_BAKE_MAX_TRAIN_ERROR 0.5

#endif
