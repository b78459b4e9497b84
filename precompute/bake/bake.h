/* The bake: a character (mesh, skeleton, weights, bone-driven vertices, clip) in, a
 * blob view out (DESIGN.md §5). Stages:
 *   prepare   weights (heat diffusion when the asset has none), bone-driven vertices
 *             made rigid (one-hot weights), surface, lumped masses
 *   domains   each tet to the strongest bone of the majority of its vertices (§2.3)
 *   poses     training = per-joint sweeps over the range the training clip uses plus
 *             the clip's first (1 - heldout) frames, and the caller's extra poses (the
 *             adaptive loop's, bake_adaptive.h); held-out = the clip's last frames
 *             (or random combined poses with a fixed seed when there is no clip)
 *   simulate  full-space quasistatic solutions with self-contact, all cores (each chain
 *             of poses read from the cache when it holds it, bake_cache.c); the
 *             clip's held-out frames continue its training frames' path (the solution
 *             depends on the path through contact and buckling), and every training
 *             solution's contact set is kept for the runtime (pose-space contact)
 *   basis     un-skinned snapshots d = R^T (x - t) - rest -> per-domain uncentred PCA,
 *             rank by an energy threshold, orthonormal columns, zero rows at
 *             bone-driven vertices (they follow their bone exactly); with
 *             inertia_modes, plus the static responses to the bones' accelerations
 *   cubature  per domain on the reduced elastic forces of snapshots and perturbed
 *             snapshots (eqs. 2.11-2.19)
 *   reduce    interface-spring Hessian (eq. 4.20) at unit stiffness, reduced mass,
 *             inertial projections
 *   springs   the springs' stiffness: the caller's, or of 20, 10, 5 and 2.5 E h the one
 *             whose blob has the lowest training error (bake_springs.c)
 *   embed     with a render mesh (sw_character.render): its embedding in the tets, computed
 *             right after prepare (a mesh that does not fit fails before the long
 *             stages), written as the blob's render sections after reduce: the blob's
 *             output surface is then the render mesh
 */
#ifndef SW_BAKE_H
#define SW_BAKE_H

#include "blob_view.h"
#include "cubature_train.h"
#include "subspace_eval.h"
#include "sw_mesh.h"

/* The interface springs' stiffnesses a bake chooses from (sw_bake_params.spring_k 0):
 * sw_bake_spring_mult(i) E h for i < SW_SPRING_CHOICES, stiffest first. */
#define SW_SPRING_CHOICES 4
double sw_bake_spring_mult(int i);

typedef struct sw_bake_params {
    int32_t max_rank;              /* per domain (default 30) */
    double fold_share;             /* a bone whose tets hold less than this share of the
                                      mesh's volume joins its parent's domain (default 0: every
                                      bone that owns tets is a domain; bake_domains.c) */
    double pca_energy;             /* fraction of snapshot energy kept (default 0.9999) */
    double pca_strain;             /* the PCA's inner product: this share from the snapshots'
                                      rest strain energy, the rest from their plain products
                                      (default 0: plain PCA; bake_basis.c: at the same rank
                                      no better, docs/generalisation.md) */
    double cubature_tol;           /* default 0.05 */
    int32_t cubature_max;          /* per domain (default 1000) */
    sw_cubature_selector selector; /* default NN-HTP */
    int32_t sweep_samples;         /* poses per joint sweep (default 6) */
    int pair_sweeps;               /* also sweep every joint together with its parent joint
                                      (combinations the single sweeps never show): 1 on, 0
                                      off, -1 (default) on where the character's joint range
                                      (sw_character.range) bounds the sweeps (bake_poses.c,
                                      docs/generalisation.md Joint ranges) */
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
                                      named in train_clips (finger 50K held-out 0.1358 ->
                                      0.0781, docs/accuracy.md The way home) */
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
                                      bones' accelerations and the cubature trained on them
                                      (bake_basis.c; default 0: they raise the rank, 33 -> 73
                                      on the 3K finger) */
    double heldout_fraction;       /* last part of the clip held out (default 0.4) */
    int32_t random_poses;          /* held-out poses when there is no clip (default 10) */
    int32_t heldout_steps;         /* ... each reached from the one before in this many
                                      held-out poses, 1..64 (default 4): the reference is
                                      path dependent, and a jump of up to 90 degrees a
                                      joint lands its contact on another branch
                                      (docs/generalisation.md, "Held-out poses on a path") */
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
    /* Training and held-out clips of their own (issue 14: a glTF/FBX file's clips, by
       name): with ntrain_clips > 0 the training poses are frames of train_clips (each its
       own path from rest, at most max_train_frames of it) and the joint sweeps, the
       held-out poses frames of heldout_clips (one path from rest, clip after clip, at most
       max_train_frames of each), and the character's clip and heldout_fraction are not
       used for poses. The clips must have the skeleton's bones; held-out clips need
       training clips. NULL/0 (default): the character's clip, split as above. */
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
} sw_bake_params;

sw_bake_params sw_bake_params_default(void);

/* What the bake made, plus the arrays the view points into (owned). */
typedef struct sw_bake_result {
    sw_blob_view view;
    void *storage[64]; /* owned arrays (freed by sw_bake_result_free) */
    int nstorage;
    /* report */
    double stage_seconds[8]; /* prepare, domains, poses+simulate, basis, cubature, reduce */
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
 * three times as far as the training clips is beyond what the bake learnt (docs/generalisation.md
 * "The Fox's Run is beyond its training"). Random held-out poses stay within the sweeps. */
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

sinew_result sw_bake(const sw_character *c, const sw_bake_params *p, sw_bake_result *out,
                     sw_error *err);
void sw_bake_result_free(sw_bake_result *r);

/* Only the bake's evaluation data: the stages prepare, domains, poses and simulate of sw_bake with
 * the same parameters, filling out's ntrain, nheldout, *_unsettled, mass, train_T/x and
 * heldout_T/x exactly as sw_bake does (no view). For a blob baked elsewhere with the
 * same parameters (sinew-bench --blob), so that sw_bake_errors measures it on the very
 * poses and reference solutions its bake measured it on. */
sinew_result sw_bake_solutions(const sw_character *c, const sw_bake_params *p, sw_bake_result *out,
                               sw_error *err);

/* The one definition of a bake's training and held-out error (sinew-bake and
 * sinew-bench report these): sw_eval_correction of `blob` over res's training poses (the
 * clip's training frames, then the return path when baked, then every joint sweep, in
 * that order, one quasistatic instance stepped through them all) and, separately, over
 * its held-out poses, the instance in self-contact mode `sc` (the pose-space mode is the
 * bake's figure) and otherwise as an engine creates it: SW_BAKE_EVAL_NEWTON is the
 * instance's default Newton cap (0: DESIGN.md's 5 a frame), so the bake reports what the
 * shipped step does, not what a step run to convergence would (held-out: the bare hand's
 * random poses 0.400 against 0.384 at 20 iterations, the elephant 0.091 against 0.089;
 * the Fox's, robot's, hand's and finger's figures are the same to four digits). */
#define SW_BAKE_EVAL_NEWTON 0
sinew_result sw_bake_errors(const sinew_blob *blob, const sw_bake_result *res,
                            sinew_self_contact sc, sw_eval_result *train, sw_eval_result *heldout,
                            sw_error *err);

/* The self-contact modes an instance can take (sinew_instance_def.self_contact), indexed
 * by sinew_self_contact's value: their names (the tools' flags; NULL after the last, for
 * sw_tool_choice) and JSON keys. */
#define SW_BAKE_MODES 3
extern const char *const sw_self_contact_names[SW_BAKE_MODES + 1];
extern const char *const sw_self_contact_keys[SW_BAKE_MODES];

/* The held-out error of `blob` in each self-contact mode, measured as sw_bake_errors
 * measures it, into err_mode (indexed by the mode's value): `measured_err` for the mode `measured`
 * (already measured), NaN for the pose-pairs mode of a blob without per-pair sections and for a
 * mode whose steps failed. Which mode suits the character's motion: on clips like its training
 * clips the pose-space mode, on combinations of joints no training pose holds the
 * detecting modes (docs/generalisation.md "The Fox's Run is beyond its training"). */
sinew_result sw_bake_mode_errors(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact measured, double measured_err,
                                 double err_mode[SW_BAKE_MODES], sw_error *err);

/* The held-out half of sw_bake_errors_frames, on_frame (NULL: none) called with ctx after
 * each held-out pose is measured (sw_eval_options; `pose` counts the path's leading
 * training poses too: sw_bake_heldout_path). */
sinew_result sw_bake_heldout_error(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_frame_fn on_frame, void *ctx,
                                   sw_eval_result *heldout, double *heldout_frames, sw_error *err);

/* How well the held-out references are defined (bake_spread.c; sinew-bake
 * --reference-spread): at every `every`-th held-out pose (every - 1, 2 every - 1, ...)
 * that the blob steps along the held-out path in self-contact mode sc, three full-space
 * solves with the reference's parameters at that pose, started from plain skinning, from
 * the reference and from the runtime's state. Each is measured as the correction error
 * measures the runtime (|x - x_ref|_M over |x_ref - x_dqs|_M, summed over the poses before
 * the ratio): `from_skin` is how far a reference that had not walked the path lands from
 * the bake's, `from_reference` how far a fresh solve moves the reference itself (its own
 * precision: the contact set starts afresh, Newton's tolerance is relative to its start),
 * `polished` how far the full-space equilibrium nearest the runtime's state is from the
 * reference (0: the runtime is off the one equilibrium; near `runtime`: it sits by
 * another), `polish_move` how far that solve moved the runtime's state; per pose the same
 * shares of that pose alone. */
typedef struct sw_bake_spread_pose {
    int32_t heldout;                                     /* the held-out pose's index */
    double runtime, from_skin, from_reference, polished; /* its own shares */
    double correction; /* |x_ref - x_dqs|_M: the shares' denominator (near 0: rounding) */
} sw_bake_spread_pose;
typedef struct sw_bake_spread {
    int32_t poses;         /* held-out poses measured */
    double runtime;        /* the runtime's correction error at those poses */
    double from_skin;      /* the full-space solve from plain skinning, against the reference */
    double from_reference; /* the solve from the reference, against it */
    double polished;       /* the full-space solve from the runtime's state, against it */
    double polish_move;    /* that solve against the runtime's state */
    int32_t unconverged;   /* solves that ended unconverged (kept, as the reference keeps them) */
    int32_t failed;        /* poses left out: a step or a solve that did not stay finite */
    sw_bake_spread_pose *per_pose; /* `poses` of them, in order (sw_bake_spread_free) */
} sw_bake_spread;
sinew_result sw_bake_reference_spread(const sw_character *ch, const sw_bake_params *p,
                                      const sinew_blob *blob, const sw_bake_result *res,
                                      sinew_self_contact sc, int32_t every, sw_bake_spread *out,
                                      sw_error *err);
void sw_bake_spread_free(sw_bake_spread *s);

/* The training half of sw_bake_errors_frames (train_frames: res->ntrain doubles or NULL). */
sinew_result sw_bake_train_error(const sinew_blob *blob, const sw_bake_result *res,
                                 sinew_self_contact sc, sw_eval_result *train, double *train_frames,
                                 sw_error *err);

/* The result's view written and loaded as a blob (its bytes in *mem, the caller's to
 * free after sinew_blob_destroy). */
sinew_result sw_bake_result_blob(const sw_bake_result *res, void **mem, sinew_blob **blob,
                                 sw_error *err);

/* The held-out poses on the path the reference solved them on (malloc'd, 12 nbones
 * each): the first *pre = res->heldout_after training poses, then the held-out ones,
 * *n in all. sw_bake_errors, the error gap and the report's contact sheet step one
 * instance along it and measure the poses after the first *pre. NULL: out of memory. */
double *sw_bake_heldout_path(const sw_bake_result *res, int32_t nbones, int32_t *pre, int32_t *n);

/* sw_bake_errors, also writing every pose's own correction error (res->ntrain and
 * res->nheldout doubles; sw_eval_correction_frames) when the arrays are not NULL. */
sinew_result sw_bake_errors_frames(const sinew_blob *blob, const sw_bake_result *res,
                                   sinew_self_contact sc, sw_eval_result *train,
                                   sw_eval_result *heldout, double *train_frames,
                                   double *heldout_frames, sw_error *err);

/* A training error at or above this share of the correction missed is no usable bake:
 * the subspace misses half of the physics correction on the very poses it was built
 * from (a sound bake misses 1-3%; 1 is no better than plain skinning). sinew-bake
 * refuses to write such a blob unless --force. */
#define SW_BAKE_MAX_TRAIN_ERROR 0.5

#endif
