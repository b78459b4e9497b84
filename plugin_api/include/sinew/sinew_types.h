/* sinew — the types of the public ABI: opaque handles, the def structs with their
 * defaults, the task callbacks, the step's status flags and statistics, the debug-draw
 * callbacks and the recorder's def. The functions are in sinew.h, the collision world's in
 * sinew_world.h.
 *
 * Conventions (STYLE.md §1-§5):
 *  - Functions are sinew_<object>_<verb>; types are sinew_<snake_name>; macros SINEW_*.
 *  - Objects are opaque handles. A blob (baked character) is immutable once loaded and
 *    may be shared by any number of instances on any number of threads. An instance is
 *    owned by one thread at a time.
 *  - Every def struct starts with `struct_size` and is initialised by the inline
 *    sinew_*_def_default(). Zero in a field means "the default". The library reads
 *    only the bytes that the caller's struct_size covers, so adding fields at the end
 *    never breaks an old binary.
 *  - Every fallible call returns a sinew_result; output handles are written only on
 *    SINEW_OK.
 *  - Units: lengths in the character's own units, time in seconds, angles in radians.
 */
#ifndef SINEW_TYPES_H
#define SINEW_TYPES_H

#include "sinew_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A loaded, validated, immutable baked character (opaque). */
typedef struct sinew_blob sinew_blob;

/** One simulated character: pose, state and all its scratch memory (opaque). */
typedef struct sinew_instance sinew_instance;

/** A step's scratch memory, lent to instances of one blob that never step at the same
 * time (opaque; sinew_workspace_create): one per worker thread in a crowd. */
typedef struct sinew_workspace sinew_workspace;

/** The static and moving colliders instances collide with (opaque; sinew_world.h). */
typedef struct sinew_world sinew_world;

/** How to load a blob: from a file path (mapped) or from a host-owned buffer. */
typedef struct sinew_blob_def {
    uint32_t struct_size;      /**< sizeof(sinew_blob_def), set by the default */
    const char *path;          /**< file to map, or NULL when `data` is given */
    const void *data;          /**< host buffer, 64-byte aligned, outliving the blob */
    size_t data_size;          /**< bytes in `data` */
    sinew_allocator allocator; /**< memory hooks; zero means the C library */
    /** Log hook (zero: errors to stderr; sinew_logger_silent: none). The blob keeps it for
     * its life, and instances created without a logger of their own log through it, from
     * any thread: `user` must outlive the blob. */
    sinew_logger logger;
} sinew_blob_def;

/** A sinew_blob_def with every field at its default. */
static inline sinew_blob_def sinew_blob_def_default(void) {
    sinew_blob_def d;
    d.struct_size = (uint32_t)sizeof(sinew_blob_def);
    d.path = NULL;
    d.data = NULL;
    d.data_size = 0;
    d.allocator = sinew_allocator_default();
    d.logger = sinew_logger_default();
    return d;
}

/** Stable log message ids of blob loading (sinew_logger). */
#define SINEW_MSG_BLOB_INVALID_ARGUMENT 0x0100u /**< error: bad def or arguments */
#define SINEW_MSG_BLOB_IO 0x0101u               /**< error: the file could not be mapped */
#define SINEW_MSG_BLOB_INVALID 0x0102u          /**< error: validation failed (names section) */
#define SINEW_MSG_BLOB_OUT_OF_MEMORY 0x0103u    /**< error: the allocator returned NULL */
#define SINEW_MSG_BLOB_LOADED 0x0104u           /**< info: loaded, with its counts */

/** Stable log message ids of instance creation (sinew_logger). */
#define SINEW_MSG_INSTANCE_INVALID_ARGUMENT 0x0200u /**< error: bad def or arguments */
#define SINEW_MSG_INSTANCE_OUT_OF_MEMORY 0x0201u    /**< error: the allocator returned NULL */
#define SINEW_MSG_INSTANCE_UNSUPPORTED                                                             \
    0x0202u /**< error: a def field this version lacks (none today) */
#define SINEW_MSG_INSTANCE_CREATED 0x0203u /**< info: created, with its memory */
#define SINEW_MSG_INSTANCE_POSE                                                                    \
    0x0204u                            /**< error: a pose or actor transform refused (says         \
                                            which bone and why) */
#define SINEW_MSG_INSTANCE_LOD 0x0205u /**< error: a level of detail the blob lacks */

/** A range task of the library: items [begin, end) on the host's worker `worker`. */
typedef void sinew_task_fn(uint32_t begin, uint32_t end, uint32_t worker, void *task_context);

/** The host's job system, in the manner of Box2D v3's enqueueTask / finishTask: enqueue
 * runs `task` over [0, item_count) split into ranges of at least min_range items on
 * the host's workers and returns a handle (or NULL after running it inline); finish
 * waits for that handle. Called only from inside the step of the instance that owns
 * them, a few times a Newton iteration (once a cubature pass: the items are the blob's
 * domains, so a character with one domain never calls them). Every range of one task
 * must run on a distinct worker index at a time, worker < worker_count; the step's
 * result is bitwise the same whatever the split and the workers (each domain writes
 * only its own rows, and sums are taken in the blob's order afterwards). The step
 * itself still never allocates or locks; what the host's enqueue and finish do is the
 * host's. */
typedef struct sinew_task_callbacks {
    void *(*enqueue)(sinew_task_fn *task, uint32_t item_count, uint32_t min_range,
                     void *task_context, void *user);
    void (*finish)(void *user_task, void *user);
    uint32_t worker_count; /**< workers the host runs tasks on (worker < worker_count) */
    void *user;
} sinew_task_callbacks;

/** Integration mode of an instance. */
typedef enum sinew_step_mode {
    SINEW_STEP_QUASISTATIC = 0, /**< equilibrium every frame: no inertia */
    SINEW_STEP_DYNAMIC = 1      /**< implicit dynamics: flesh lags, jiggles and settles */
} sinew_step_mode;

/** Self-contact of an instance (sinew_instance_def.self_contact). */
typedef enum sinew_self_contact {
    /** the reference's contact pairs at the two nearest training poses, blended (thesis
     * §3.2.3): a cost that follows those pairs, contacts only where the bake saw them */
    SINEW_SELF_CONTACT_POSE_SPACE = 0,
    /** every boundary vertex tested against the whole deformed mesh at the step's start
     * state, and again at its solution (a second solve when that found new contact), with
     * the reference's detection rule: contacts the bake never saw, at a cost that follows
     * the mesh (every vertex mapped, every tet's box refit). Needs a blob with the tet
     * mesh (sinew-bake writes it); INVALID_ARGUMENT otherwise */
    SINEW_SELF_CONTACT_EXHAUSTIVE = 1,
    /** pose-space contact per pair of domains (thesis §3.2.3): each pair of domains finds
     * its own two nearest training samples by a feature of those two bones alone, and
     * applies their cubature pairs, blended; combinations of joints the bake never saw
     * together still find close samples pair by pair. A pair whose nearest sample is far
     * counts as novel contact (sinew_step_stats.self_contact_novel). Needs a blob with
     * per-pair sections (sinew-bake writes them when training poses touch themselves);
     * INVALID_ARGUMENT otherwise */
    SINEW_SELF_CONTACT_POSE_PAIRS = 2
} sinew_self_contact;

/** The Hessian a step's Newton updates start on (sinew_instance_def). */
typedef enum sinew_newton_hessian {
    /** the library chooses per blob at creation: the rest Hessian first where a
     * factorisation of the reduced Hessian costs less than 0.3 of the multiply-adds the
     * rest Hessian saves a cubature pass (most characters), the current one where the
     * domains' couplings make the factorisation dear (the 24-bone elephant) */
    SINEW_NEWTON_HESSIAN_AUTO = 0,
    /** every Newton update on the Hessian at an iterate of the step (a cubature pass
     * with the element Hessians), chord updates on an earlier factor once it converges */
    SINEW_NEWTON_HESSIAN_CURRENT = 1,
    /** the updates start on a reference Hessian (the cubature's: at the rest shape after
     * creation or a reset, then the last one a step evaluated; the contact pairs' and
     * springs' Hessians at the iterate), factored at each update, each trial a gradient
     * pass; an update the energy rejects or one shrinking the gradient too little hands
     * the step to SINEW_NEWTON_HESSIAN_CURRENT's iteration, whose Hessian becomes the
     * reference. The stationary point is the same, so the shape at a pose depends on the
     * frames before only within the solve's tolerance (replays from a reset are bitwise
     * the same). A dynamic step's Rayleigh stiffness damping then takes the reference
     * Hessian at the step's start. Reserves the reference Hessian's domain blocks */
    SINEW_NEWTON_HESSIAN_REST_FIRST = 2
} sinew_newton_hessian;

/** Profiler zones around each phase of a step (in the manner of Jolt's external profile
 * and PhysX's PxProfilerCallback): zone_begin(name) before a phase, zone_end(name) after
 * it, on the stepping thread, nested in none and balanced; `name` is a static string
 * ("skin", "contact", "dynamics", "self_contact", "world", "oracle", "solve", "advance",
 * "output"), the same pointer every step. Both set or both NULL; unset, a step pays one
 * test a phase. The callbacks must not call into the instance. */
typedef struct sinew_profiler {
    void (*zone_begin)(const char *name, void *user);
    void (*zone_end)(const char *name, void *user);
    void *user;
} sinew_profiler;

/** Levels of detail of a step (sinew_instance_set_lod), from the dearest to the cheapest.
 * A host picks one per instance per frame, or lets sinew_lod_for_screen_size pick it from
 * how much of the screen the character covers. */
typedef enum sinew_lod {
    /** the step as the instance def configures it: the subspace solve with its contact,
     * the collision world, condensation patches and novel contact */
    SINEW_LOD_FULL = 0,
    /** the subspace solve alone: one Newton update from the pose-space start with the
     * trained self-contact; no collision world, no patches, no novel contact */
    SINEW_LOD_REDUCED = 1,
    /** no solve: each output vertex skinned on its own, displaced by the training poses'
     * shapes blended at the pose (what a learned deformer costs); quasistatic, no world.
     * Needs a blob that holds it (sinew_blob_lod_count 3) */
    SINEW_LOD_POSE_SPACE = 2
} sinew_lod;

/** The fewest steps over which a change of level fades from the old level's surface to
 * the new one's (sinew_instance_set_lod). */
#define SINEW_LOD_BLEND_FRAMES 8u

/** How to create an instance of a blob. All memory is reserved at creation. */
typedef struct sinew_instance_def {
    uint32_t struct_size;      /**< sizeof(sinew_instance_def), set by the default */
    sinew_step_mode mode;      /**< default quasistatic */
    uint32_t max_newton_iters; /**< per step; 0 means 5 */
    sinew_allocator allocator; /**< memory hooks; zero means the blob's */
    sinew_logger logger;       /**< log hook; zero means the blob's */
    /** Budget: the pose-space self-contact pairs one step may evaluate (the pairs of the
     * two nearest training poses). 0 means the pairs of the blob's two fullest training
     * poses, which never runs out. A step that needs more evaluates the nearest pose's
     * pairs first, drops the rest and flags SINEW_STEP_BUDGET. */
    uint32_t max_contact_pairs;
    /** The host's job system for one instance's parallel work (the cubature passes),
     * or zero: the step runs serially on the calling thread. enqueue and finish are
     * both set or both NULL, with worker_count 1..256 (the instance reserves scratch for
     * each worker; INVALID_ARGUMENT otherwise). */
    sinew_task_callbacks tasks;
    /** Budget: the (surface vertex, collider) candidates one step may hold against the
     * collision world (sinew_world.h). 0 means one per output-surface vertex copy. A
     * step that finds more keeps those found first, drops the rest and flags
     * SINEW_STEP_BUDGET with SINEW_BUDGET_WORLD_CONTACTS. */
    uint32_t max_world_contacts;
    /** Budget: the simulation vertices one step may simulate in full space (subspace
     * condensation, thesis §4.3: a patch around world contact the subspace has never
     * seen). 0 (the default) turns condensation off; otherwise every patch array is
     * reserved at creation for this many vertices (sinew_instance_memory_size counts
     * them). A step whose oracle asks for more keeps the vertices nearest the contacts,
     * drops the rest and flags SINEW_STEP_BUDGET with SINEW_BUDGET_PATCH. Needs a blob
     * with the tet mesh (sinew-bake writes it) and pose-space self-contact (the default);
     * INVALID_ARGUMENT otherwise. */
    uint32_t max_patch_vertices;
    /** The patch radius: the breadth-first growth from a contact vertex accepts the
     * vertices within this rest-space distance of it, in units of the rest bounding-box
     * diagonal (the thesis's radii, for a mesh normalised to a unit cube, are this times
     * diagonal / longest side). 0 means 0.05; otherwise 0 < patch_radius <= 1. */
    float patch_radius;
    /** Self-contact detection: SINEW_SELF_CONTACT_POSE_SPACE (the default),
     * SINEW_SELF_CONTACT_EXHAUSTIVE or SINEW_SELF_CONTACT_POSE_PAIRS (see there). */
    sinew_self_contact self_contact;
    /** The Hessian quasistatic Newton updates start on: SINEW_NEWTON_HESSIAN_AUTO (the
     * default), _CURRENT or _REST_FIRST (see there). */
    sinew_newton_hessian newton_hessian;
    /** Profiler zones around the step's phases (see sinew_profiler); zero: none. */
    sinew_profiler profiler;
    /** Self-contact nobody trained: 1 detects, at each step's start, where two parts of
     * the body that no training pose pressed together meet (a fist past the bake's
     * sweeps, a limb against the chest), with the full-space reference's own rule, at a
     * cost that follows what is near each other; the pose-space pairs keep what the bake
     * trained. With a patch budget (max_patch_vertices) the contact seeds a condensation
     * patch, where it is solved in full space; without one it is applied through the
     * subspace. 0 (the default): off. Needs a blob with the tet mesh and pose-space
     * self-contact; INVALID_ARGUMENT otherwise. */
    uint32_t novel_contact;
    /** The collision surface (sinew_instance_read_collision_surface): 1 has every step
     * write the simulation mesh's closed boundary, which another character collides with
     * (a mesh collider of a shared world). Only a blob with a render mesh needs it: without
     * one the boundary is the output surface, and with a world attached or novel_contact
     * on the step writes it anyway. It costs the boundary's mapping a step. 0 (the
     * default): off. */
    uint32_t collision_surface;
    /** The step's scratch: 0 (the default) reserves it in the instance; 1 reserves none
     * (sinew_instance_memory_size then counts only the state, a small part of it at high
     * rank: the reduced Hessian and its factor, rank squared each, are scratch) and the
     * instance steps only through sinew_instance_step_in, in a workspace made for its
     * blob with patches if it has them (sinew_workspace_create). */
    uint32_t shared_workspace;
} sinew_instance_def;

/** A sinew_instance_def with every field at its default. */
static inline sinew_instance_def sinew_instance_def_default(void) {
    sinew_instance_def d;
    d.struct_size = (uint32_t)sizeof(sinew_instance_def);
    d.mode = SINEW_STEP_QUASISTATIC;
    d.max_newton_iters = 0;
    d.allocator = sinew_allocator_default();
    d.logger = sinew_logger_default();
    d.max_contact_pairs = 0;
    d.tasks.enqueue = NULL;
    d.tasks.finish = NULL;
    d.tasks.worker_count = 0;
    d.tasks.user = NULL;
    d.max_world_contacts = 0;
    d.max_patch_vertices = 0;
    d.patch_radius = 0.0f;
    d.self_contact = SINEW_SELF_CONTACT_POSE_SPACE;
    d.newton_hessian = SINEW_NEWTON_HESSIAN_AUTO;
    d.profiler.zone_begin = NULL;
    d.profiler.zone_end = NULL;
    d.profiler.user = NULL;
    d.novel_contact = 0;
    d.collision_surface = 0;
    d.shared_workspace = 0;
    return d;
}

/** Status flags of a step (sinew_step_stats.status). Any combination may be set; a step
 * that returned SINEW_OK left a finite state within the bounds below, whatever it flags.
 *
 * The bounds (L the rest bounding-box diagonal of the blob, q_k domain k's reduced
 * coordinates, u_k the largest norm of its basis rows, Q_k the largest |q_k| of the
 * blob's training solutions):
 *  - |q_k| <= max(4 Q_k, L / (4 u_k)): no vertex strays further from its skinned position
 *    than max(4 u_k Q_k, L / 4) (four times the largest correction the bake trained, at
 *    least a quarter of the size; a vertex of an embedded render mesh by that times the
 *    sum of its barycentric weights' magnitudes, 1 inside its tet), so the elastic energy
 *    is bounded too;
 *  - dynamic: the flesh's speed relative to its bone, u_k |dq_k/dt| <= 200 L per second.
 * A pose jump (SINEW_STEP_TELEPORT) is any bone, between the last step's pose and this
 * one, turning by more than 120 degrees, moving a rest point it skins by more than L / 2,
 * or implying a joint spin above 200 rad/s (no human joint exceeds ~140 rad/s) or a
 * point speed above 200 L/s at this dt; a 5 degree change over dt = 1e-6 s is one. A
 * change slower than that is motion, however abrupt the host meant it to be: a host
 * declares such a cut with sinew_instance_mark_teleport and the step flags it too.
 * Poses are checked by sinew_instance_set_pose before any step: a non-finite value gives
 * SINEW_ERROR_NOT_FINITE, a rotation part that is not orthonormal within 1e-3 (scale,
 * shear) or is a reflection gives SINEW_ERROR_INVALID_ARGUMENT; either way the pose and
 * the state stay as they were. */
/** Newton stopped at a solution: its gradient fell below 1e-5 of the step's first (or
 * was zero), the last update moved the shape by less than 5% of its correction, or the
 * predicted decrease of a further update is below the energy's rounding (a state already
 * at its minimum, e.g. a step at rest, converges with 0 iterations). */
#define SINEW_STEP_CONVERGED 1u
/** the energy guard stopped Newton before convergence: no step along the Newton direction
 * (halved up to five times) lowered the energy; the best iterate is kept */
#define SINEW_STEP_GUARD 2u
/** the pose jumped (see above): the velocity was zeroed and the pose history restarted,
 * so no inertia is taken from the jump; the flesh keeps its shape relative to the bones
 * and settles from there */
#define SINEW_STEP_TELEPORT 4u
/** non-finite state: the step was undone (the call returns SINEW_ERROR_NOT_FINITE) */
#define SINEW_STEP_FAILED 8u
/** quasistatic: started from the pose-space blend of training solutions */
#define SINEW_STEP_POSE_SPACE 16u
/** a budget of the instance def ran out (budget_exceeded says which): the step did what
 * fit */
#define SINEW_STEP_BUDGET 32u
/** the solve left the bounds above and the state was limited: a domain's coordinates
 * scaled back onto their bound (its velocity zeroed), or a velocity scaled down to the
 * speed bound; the output is the limited state */
#define SINEW_STEP_LIMITED 64u
/** the pose bends a joint beyond the bake's training: more than 1.25 times and 5 degrees
 * further than any training pose bends it (joints_beyond_training says how many). The
 * subspace then extrapolates, and the correction it gives can miss far more than on the
 * motion it was baked from (the bake report measures it on held-out clips); bake with
 * motion that reaches those bends. */
#define SINEW_STEP_BEYOND_TRAINING 128u

/** Budgets of an instance (sinew_step_stats.budget_exceeded bits). */
#define SINEW_BUDGET_CONTACT_PAIRS 1u  /**< sinew_instance_def.max_contact_pairs */
#define SINEW_BUDGET_WORLD_CONTACTS 2u /**< sinew_instance_def.max_world_contacts */
#define SINEW_BUDGET_PATCH 4u          /**< sinew_instance_def.max_patch_vertices */

/** What a blob was baked from (sinew_blob_get_provenance): compare with the asset and the
 * library an engine ships, and bake again when either changed. Hashes are FNV-1a 64
 * (sinew_hash_bytes), 0 when not known. */
typedef struct sinew_blob_provenance {
    uint32_t struct_size;    /**< set by the caller to sizeof(sinew_blob_provenance) */
    uint32_t sinew_version;  /**< SINEW_VERSION of the bake that wrote the blob */
    uint64_t source_hash;    /**< of the source asset file's bytes (0: no file) */
    uint64_t options_hash;   /**< of the bake options that shape the blob */
    uint32_t format_version; /**< the blob's format version (its header's) */
    uint32_t reserved;       /**< zero */
} sinew_blob_provenance;

/** Figures of an instance's last step. */
typedef struct sinew_step_stats {
    uint32_t struct_size;       /**< set by the caller to sizeof(sinew_step_stats) */
    uint32_t newton_iterations; /**< Newton updates taken */
    uint32_t status;            /**< SINEW_STEP_* flags */
    uint32_t reserved;          /**< zero */
    double residual;            /**< |gradient| at exit relative to its value at entry */
    double energy;              /**< the step's potential at exit */
    /* The step's phases (DESIGN.md §4), wall-clock milliseconds each: */
    double ms_skin;           /**< skinning the active vertices */
    double ms_contact;        /**< pose-space lookup and the contact pairs in use */
    double ms_dynamics;       /**< inertial forces, the start state, the frozen damping Hessian */
    double ms_solve;          /**< the potential and Newton */
    double ms_output;         /**< the output surface and its normals */
    uint32_t active_vertices; /**< vertices skinned each step */
    uint32_t cubature_tets;   /**< tets of one potential evaluation */
    uint32_t potential_evals; /**< evaluations of the potential (cubature passes) */
    uint32_t contact_pairs;   /**< pose-space contact pairs in use */
    uint32_t contact_pairs_dropped; /**< pairs the max_contact_pairs budget left out */
    uint32_t budget_exceeded;       /**< SINEW_BUDGET_* bits of the budgets that ran out */
    /* The collision world (zero without one): */
    double ms_world;                 /**< detection against the world (broad and narrow) */
    uint32_t world_queries;          /**< collider queries (vertex, collider) made */
    uint32_t world_candidates;       /**< (vertex copy, collider) candidates in the solve */
    uint32_t world_contacts;         /**< candidates in contact at the solution */
    uint32_t world_contacts_dropped; /**< candidates the max_world_contacts budget left out */
    uint32_t world_rounds;           /**< detections: 2 when the solve ran into new contact */
    /** reduced Hessians factored (the other updates reuse the last factor) */
    uint32_t factorizations;
    /* Subspace condensation (zero without a patch): */
    uint32_t patch_vertices; /**< vertices simulated in full space this step */
    uint32_t patch_tets;     /**< tets touching them (evaluated in full space) */
    uint32_t patch_dropped;  /**< vertices the max_patch_vertices budget left out */
    uint32_t pcg_iterations; /**< conjugate-gradient iterations of the coupled solves */
    double ms_oracle;        /**< the partition oracle: seeds, growth, the patch's tets */
    /** Self-contact, wall-clock milliseconds: the pose-space lookup and pair gathering
     * or the exhaustive detections, plus the contact terms' share of every potential
     * evaluation (inside ms_contact and ms_solve, which include it) */
    double ms_self_contact;
    /** self-contact candidates tested this step: the pose-space pairs in use, or the
     * exhaustive detections' (vertex, tet) candidates whose boxes overlap; with
     * SINEW_SELF_CONTACT_POSE_PAIRS also the tets each cubature vertex was tested
     * against (those around its trained triangle) */
    uint32_t self_contact_tests;
    /** self-contact pairs in the solve: the pose-space pairs in use, or the exhaustive
     * detection's pairs at the end of the step */
    uint32_t self_contacts;
    /** SINEW_SELF_CONTACT_POSE_PAIRS: pairs of domains whose nearest training sample was
     * farther than half the feature's size (novel contact the bake never saw); 0 in the
     * other modes */
    uint32_t self_contact_novel;
    /** Newton updates taken on the rest Hessian (SINEW_NEWTON_HESSIAN_REST_FIRST, or
     * _AUTO where it chose it); the other updates are counted in newton_iterations too */
    uint32_t rest_updates;
    /** pose-space modes: the nearest samples' pairs left out this step because their
     * vertex had come apart from its triangle at the start state (farther from its
     * contact point than the triangle's longest edge, and farther still the nearer the
     * pose is to the pair's own training pose, where a pair always stays); counted in
     * self_contact_tests, not in contact_pairs or self_contacts */
    uint32_t self_contacts_apart;
    /** joints the pose bends beyond the bake's training (SINEW_STEP_BEYOND_TRAINING): a
     * joint's bend is its bone's rotation from rest in its parent's frame, the angle the
     * bake's held-out list (heldout_beyond_training) measures too */
    uint32_t joints_beyond_training;
    /** the bone whose joint is bent furthest beyond training, -1 when none is */
    int32_t beyond_training_bone;
    uint32_t reserved2; /**< zero */
    /** how far (degrees) that joint's bend exceeds the largest of the training poses */
    double beyond_training_deg;
    /** sinew_instance_def.novel_contact: the contacts found this step that no pose-space
     * pair in use held, and the pairs of surface clusters whose boxes met */
    uint32_t novel_contacts;
    uint32_t novel_cluster_pairs;
    /** wall-clock milliseconds of that detection (inside ms_self_contact) */
    double ms_novel;
    /** the level of detail this step ran at (sinew_lod) */
    uint32_t lod;
    /** the share of the last level's surface the surface still shows after a change of
     * level (1 at the change, fading to 0 as the character moves; 0: none) */
    float lod_blend;
} sinew_step_stats;

/** What sinew_instance_debug_draw draws (sinew_debug_draw.flags). */
#define SINEW_DEBUG_DRAW_CONTACTS 1u  /**< world contacts and self-contact pairs */
#define SINEW_DEBUG_DRAW_PATCH 2u     /**< the condensation patch's vertices and tets */
#define SINEW_DEBUG_DRAW_COLLIDERS 4u /**< the attached world's colliders (oriented boxes) */
#define SINEW_DEBUG_DRAW_BONES 8u     /**< the pose's bones (parent joint to joint) */

/** The colours sinew_instance_debug_draw uses, packed 0xRRGGBBAA, one per kind of item
 * (a host may tell the kinds apart by them). */
#define SINEW_DEBUG_COLOR_WORLD_CONTACT 0xff4020ffu /**< a world contact and its normal */
#define SINEW_DEBUG_COLOR_SELF_CONTACT 0x20c0ffffu  /**< a self-contact pair and its normal */
#define SINEW_DEBUG_COLOR_PATCH 0xffd000ffu         /**< a patch vertex, a patch tet's face */
#define SINEW_DEBUG_COLOR_COLLIDER 0x80ff80ffu      /**< a collider's box */
#define SINEW_DEBUG_COLOR_BONE 0xffffffffu          /**< a bone */

/** Debug-draw callbacks in the manner of Box2D's b2DebugDraw: a zero-initialised struct
 * of function pointers with a context pointer, and flags saying what to draw. Positions
 * are floats in the actor's frame, as sinew_instance_read_surface gives the surface (draw
 * them with the actor's matrix); colours are packed 0xRRGGBBAA (SINEW_DEBUG_COLOR_*). A
 * NULL callback skips its items. The callbacks must not call into the instance. */
typedef struct sinew_debug_draw {
    /** a segment from p0 to p1 (a contact's normal, a box edge, a bone) */
    void (*draw_line)(const float p0[3], const float p1[3], uint32_t rgba, void *context);
    /** a point of `size` in the surface's units (a contact point, a patch vertex) */
    void (*draw_point)(const float p[3], float size, uint32_t rgba, void *context);
    /** a triangle (a patch tet's face) */
    void (*draw_triangle)(const float p0[3], const float p1[3], const float p2[3], uint32_t rgba,
                          void *context);
    uint32_t flags; /**< SINEW_DEBUG_DRAW_* bits; 0 draws nothing */
    /** length of a contact's normal segment, in the surface's units; 0 means 2% of the
     * character's rest bounding-box diagonal */
    float normal_length;
    void *context; /**< handed to every callback */
} sinew_debug_draw;

/** A recorder: writes every call an instance receives to a file a host can send with a
 * bug report, for sinew-replay to play back bitwise (opaque; sinew_recorder_open). */
typedef struct sinew_recorder sinew_recorder;

/** How to open a recorder. */
typedef struct sinew_recorder_def {
    uint32_t struct_size;      /**< sizeof(sinew_recorder_def), set by the default */
    uint32_t buffer_bytes;     /**< the in-memory buffer; 0 means 1 MiB, at least 64 KiB */
    const char *path;          /**< the file to create (truncated when it exists) */
    sinew_allocator allocator; /**< memory hooks; zero means the C library */
    sinew_logger logger;       /**< log hook; zero means the default (stderr) */
} sinew_recorder_def;

/** A sinew_recorder_def with every field at its default. */
static inline sinew_recorder_def sinew_recorder_def_default(void) {
    sinew_recorder_def d;
    d.struct_size = (uint32_t)sizeof(sinew_recorder_def);
    d.buffer_bytes = 0;
    d.path = NULL;
    d.allocator = sinew_allocator_default();
    d.logger = sinew_logger_default();
    return d;
}

/** Stable log message ids of the recorder (sinew_logger). */
#define SINEW_MSG_RECORDER_IO 0x0500u      /**< error: the file could not be written */
#define SINEW_MSG_RECORDER_REFUSED 0x0501u /**< error: attached too late, or twice */

#ifdef __cplusplus
}
#endif
#endif /* SINEW_TYPES_H */
