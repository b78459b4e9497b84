/* The instance: its state, the subsystems' views of its memory, and its last step's
 * figures. Private to runtime/instance (the phases are in step.c). */
#ifndef SW_INSTANCE_INTERNAL_H
#define SW_INSTANCE_INTERNAL_H

#include "blob_load.h"
#include "condense.h"
#include "inertia.h"
#include "novel_contact.h"
#include "pose_space.h"
#include "reduced_map.h"
#include "solver.h"
#include "world_contact.h"

/* Where the collision surface of the last step is: skinned at the pose (no step yet, or
 * a pose-space step), surf_x (the output is the boundary), coll_x, or nowhere (a render
 * mesh's boundary not asked for). */
typedef enum sw_coll_source {
    SW_COLL_SKINNED = 0,
    SW_COLL_OUTPUT = 1,
    SW_COLL_BOUNDARY = 2,
    SW_COLL_NONE = 3
} sw_coll_source;

/* The step's scratch (workspace.c): what a step computes afresh and no later call reads,
 * the bulk of an instance's memory (the rank-squared Hessian and its factor). An instance
 * holds its own (own) unless its def shares a workspace; the step binds one into the
 * subsystems' views (sw_scratch_bind). */
typedef struct sw_scratch {
    double *H, *L;               /* R x R: the reduced Hessian (red.H) and its factor (solver.L) */
    double *pack;                /* the factor's packing scratch (solver.pack, dense.h) */
    double *Hn;                  /* R x R: the step's damping Hessian (solver.Hn; dynamic only) */
    double *Hq;                  /* R x R: the patch's copy of H (cond.Hq; condensation only) */
    double *act_R, *act_t;       /* 9 and 3 per active vertex: their skinning (red) */
    double *corner_x, *corner_f; /* 3 per cubature corner each (red) */
    double *ecub;                /* ncub: each cubature tet's weighted energy (red) */
    unsigned char *H_nz, *Hn_nz; /* ndomains^2: H's and Hn's blocks that may be nonzero */
    unsigned char *Hq_nz;        /* ndomains^2: the same of Hq (condensation only) */
} sw_scratch;

/* Marks every block of the scratch's matrices as possibly nonzero: their first copies
 * write every block (a new scratch's memory holds anything). */
void sw_scratch_clear(sw_scratch *sc, const sw_blob_view *v);

/* Sizes of an instance's layout that the blob alone does not fix (instance.c). */
typedef struct sw_layout_sizes {
    int32_t nact;       /* active vertices (the blob's active map, blob_active.h) */
    int32_t nact_step;  /* those the step itself reads */
    int32_t rmax;       /* the largest domain rank */
    int32_t ncorner;    /* the cubature tets' corners (the same map's) */
    int32_t ncl;        /* the output surface's clusters (the blob's, blob_clusters.h) */
    int32_t max_pairs;  /* the contact pair budget */
    int32_t max_world;  /* the world candidate budget */
    int32_t nworkers;   /* the host's task workers, 1 without task callbacks */
    sw_cond_sizes cond; /* the condensation patch's budget (all 0: off) */
    double rho;         /* its radius, in units of the rest diagonal */
    int per_pair;       /* SINEW_SELF_CONTACT_POSE_PAIRS: the groups' samples */
    /* the exhaustive detection's arrays: SINEW_SELF_CONTACT_EXHAUSTIVE, or the pose-pairs
       mode's fallback on novel contact when the blob has the tet mesh */
    int detect;
    int novel;   /* the def's novel_contact */
    int rest;    /* the rest Hessian's blocks: SINEW_NEWTON_HESSIAN_AUTO or _REST_FIRST */
    int dynamic; /* the frozen damping Hessian and its point: SINEW_STEP_DYNAMIC only */
    int shared;  /* the def's shared_workspace: no scratch of its own */
} sw_layout_sizes;

/* The def resolved and checked (`caller` names the API function in messages), with the
 * sizes of its layout. */
sinew_result sw_instance_read_def(const sinew_blob *blob, const sinew_instance_def *def,
                                  const char *caller, sinew_instance_def *d, sw_layout_sizes *z);

/* The block a sized plan asks for, through the def's allocator; NULL when the plan
 * overflowed or the allocator failed (logged as `caller`'s). */
unsigned char *sw_instance_reserve(const struct sw_mem_plan *plan, const sinew_instance_def *d,
                                   const char *caller);

/* Places a scratch's arrays in the plan (workspace.c; base NULL: sizes only). */
void sw_scratch_layout(struct sw_mem_plan *p, sw_scratch *sc, const sw_blob_view *v,
                       const sw_layout_sizes *z);

struct sinew_instance {
    const sw_blob_view *v;
    sinew_allocator allocator; /* frees the block */
    sinew_logger logger;       /* the def's (or the blob's) */
    sinew_step_mode mode;
    double size;          /* rest bounding-box diagonal */
    double grid;          /* the translations' snapping grid (sw_pose_grid of size) */
    double *bone_ball;    /* 4 nbones: the ball of the rest vertices each bone skins
                             (centre, radius; radius -1: none), sw_pose_jump's */
    double *q_bound;      /* ndomains: the largest |q_k| a step may leave (step.c) */
    double *u_max;        /* ndomains: the largest |U_v|_F of a domain's vertex */
    sw_dualquat *bone_dq; /* nbones: the current pose */
    /* Where the actor is (pose.c): the host's bone transforms as given (12 nbones, in the
     * actor's frame, each a rotation times the pose's uniform scale), the actor's rigid
     * transform to the world (R row-major, t) and its uniform scale. The step works in
     * the simulation frame, the world divided by the whole scale s = actor_scale *
     * pose_scale, so the flesh is the rest-size physics whatever the scale; pose.T_cur
     * holds the bones there, and the host reads its surface back in the actor's frame. */
    double *pose_host;
    double actor[12];
    double actor_scale, pose_scale, scale;
    sw_pose_history pose; /* the current pose and the two before */
    /* The step's frame (pose.c, sw_instance_frame): the step works in bone 0's frame F
     * (frame: R row-major, t, in the simulation frame). loc holds the pose history there,
     * each bone F^-1 T snapped to a grid (sw_pose_snap), and the world's answers come in
     * snapped the same way (world_contact.c), so that the same pose carried by any rigid
     * motion gives the step bitwise the same inputs and the decisions that flip with
     * rounding (self-contact detection, ties, line searches) the same answers. The output
     * surface is written back in the simulation frame. L_last: loc's T_cur of the last
     * step, the frame of its output (the broad phases carry its boxes from there);
     * frame_last: its F. */
    sw_pose_history loc;
    double *L_last;
    double frame[12], frame_last[12];
    sw_reduced red;               /* the subspace map and the evaluation accumulators */
    sw_pose_space ps;             /* training poses near the current one, contact pairs */
    sw_solver solver;             /* state and Newton */
    sw_world_contacts wc;         /* the collision world's candidates of the step */
    sw_cond cond;                 /* subspace condensation (cond.z.max_verts 0: off) */
    sinew_self_contact self_mode; /* the def's self_contact */
    sw_novel novel;               /* self-contact nobody trained (novel_on: the def's) */
    int novel_on;
    sw_self_contacts sc;     /* the exhaustive mode's detection (unused arrays otherwise) */
    double *surf_x, *surf_n; /* 3 per output surface vertex each (sw_blob_output_verts) */
    double *node_x;          /* 3 per render node: the mean of its copies (render mesh only) */
    int32_t *weld_tris;      /* 3 per render triangle: its corners' weld representatives */
    /* The collision surface (sinew_instance_read_collision_surface): coll_on the def's;
     * coll_x (a blob with a render mesh only) the boundary of the last step, simulation
     * frame, when coll_src says so. */
    int coll_on;
    sw_coll_source coll_src;
    double *coll_x;
    /* Levels of detail (lod.c): the level set for the next steps and the level the last
     * output is of; after a change the surface shows lod_w (1 at the change, fading to 0
     * as the character moves) times lod_off (3 per output vertex: the old level's surface
     * less the new one's at the change, in bone 0's frame; lod_off_max its largest);
     * lod_tmp holds the new level's last surface (what the fade measures the motion by),
     * or a surface while the other is written; lod_dq the bones of the pose-space level
     * (simulation frame), lod_feat its regressors. */
    sinew_lod lod, lod_last;
    double lod_w, lod_off_max;
    sinew_lod lod_run; /* the level the step in progress runs (step.c) */
    int stepped;       /* a step has written the surface since creation or the last reset */
    double *lod_off, *lod_tmp;
    sw_dualquat *lod_dq;
    double *lod_feat; /* the pose's joint rotations (sw_pose_rotation_feature) */
    float *lod_disp;  /* 3 per output vertex: the rest-frame displacements */
    double *h_ref;    /* Newton's reference Hessian's domain blocks (red.h_ref when in use) */
    sinew_step_stats stats;
    sinew_task_callbacks tasks; /* the def's (red.tasks points here when they are set) */
    sinew_profiler profiler;    /* the def's zones (zone_begin NULL: none) */
    const sinew_blob *blob;     /* the blob the view is of (bone binds, a recording) */
    sinew_instance_def def;     /* as resolved at creation (a recording's BEGIN) */
    sinew_recorder *rec;        /* the attached recorder, or NULL (recorder.c) */
    int touched;                /* posed, placed or stepped since creation */
    /* The step's scratch of its own (all NULL with a shared workspace: shared set, and the
     * step runs only through sinew_instance_step_in). */
    sw_scratch own;
    int shared;
};

/* Points the subsystems' views at a scratch (the instance's own, or a workspace's for
 * one step). */
void sw_scratch_bind(sinew_instance *in, const sw_scratch *sc);

/* The step proper, recorded when a recorder is attached (step.c), with the scratch bound. */
sinew_result sw_instance_step_bound(sinew_instance *inst, float dt);

/* The most task workers an instance reserves scratch for (sinew_task_callbacks). */
#define SW_MAX_TASK_WORKERS 256u

/* The state's bounds (DESIGN.md §3, "never blow up"), per domain k with
 * u_k = u_max[k], Q_k the largest |q_k| of the blob's training solutions and L = size:
 *   |q_k| <= q_bound[k] = max(SW_LIMIT_TRAIN Q_k, SW_LIMIT_SIZE L / u_k),
 * so no vertex copy's correction |U_v q_k| exceeds max(SW_LIMIT_TRAIN u_k Q_k,
 * SW_LIMIT_SIZE L); and (dynamic) |qdot_k| u_k <= SW_JUMP_MAX_SPIN L. */
#define SW_LIMIT_TRAIN 4.0
#define SW_LIMIT_SIZE 0.25

/* The contact terms of the instance's step (the world's when it has one); self_seconds
 * as sw_step_contacts. */
sw_step_contacts sw_instance_contacts(sinew_instance *in, double *self_seconds);

/* The actor at the world's origin, unscaled (creation). */
void sw_instance_actor_identity(sinew_instance *in);

/* The rest pose where the actor stands: the host's bones the identity, composed into
 * pose.T_cur and bone_dq (reset). */
void sw_instance_rest_pose(sinew_instance *in);

/* The step's frame and loc from the pose history, and bone_dq from loc (pose.c). */
void sw_instance_frame(sinew_instance *in);

/* A point (or with direction, a vector) of the step's frame in the simulation frame, and
 * back. */
void sw_instance_from_step(const sinew_instance *in, const double x[3], int direction, double y[3]);
void sw_instance_to_step(const sinew_instance *in, const double x[3], int direction, double y[3]);

/* Surface vertex i (position, or with direction set a normal) of the simulation frame
 * in the actor's frame, as the host reads it. */
void sw_instance_to_actor(const sinew_instance *in, const double x[3], int direction, double y[3]);

/* The output surface (positions and normals) of the state q (output.c). */
void sw_instance_write_surface(sinew_instance *in);

/* The output surface's normals from its positions (output.c). */
void sw_instance_surface_normals(sinew_instance *in);

/* The pose-space level (lod.c): the output surface (positions and normals, simulation
 * frame) of the pose, each vertex skinned on its own and displaced by the modes at the
 * coefficients the pose's joint rotations map to (0: a coefficient beyond bounds, and the
 * surface plain skinning); the step of that level (no solve: the
 * surface, the pose history), its figures into st. */
int sw_lod_pose_surface(sinew_instance *in);
sinew_result sw_lod_pose_step(sinew_instance *in, float dt, sinew_step_stats *st);
/* Before the first solving step after the pose-space level: the state at the pose-space
 * prediction with no velocity, no patch, the pose history afresh. */
void sw_lod_leave_pose_space(sinew_instance *in);

/* After a step that ran level `ran` (the old level `from` at a change to the pose-space
 * level, otherwise the new `to`): the surface the change shows, the old level's, with the
 * blend of the steps after it (lod.c). */
void sw_lod_finish(sinew_instance *in, sinew_lod from, sinew_lod to, sinew_lod ran);

/* The render mesh as output surface (output_render.c): positions x (3 per render vertex)
 * from the render nodes' positions node_x; normals n over the welded triangles
 * weld_tris (sw_render_weld_tris fills them at creation), duplicates copying their
 * representative's. */
void sw_render_positions(const sw_blob_view *v, const double *node_x, double *x);
void sw_render_normals(const sw_blob_view *v, const int32_t *weld_tris, const double *x, double *n);
void sw_render_weld_tris(const sw_blob_view *v, int32_t *weld_tris);

/* The detection's pairs (in->sc) are in use: the exhaustive mode, the pose-pairs mode's
 * fallback on novel contact, or the novel self-contact beside the pose-space pairs. */
static inline int sw_instance_detects(const sinew_instance *in) {
    return in->self_mode == SINEW_SELF_CONTACT_EXHAUSTIVE ||
           ((in->ps.novel_mask || in->novel_on) && in->sc.npairs > 0);
}

#endif
