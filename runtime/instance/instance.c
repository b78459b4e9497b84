/* An instance's lifecycle (DESIGN.md §3): its memory is one block laid out once from the
 * blob and the def's budgets (layout()), reserved at creation through the allocator hook
 * and never grown; sinew_instance_memory_size walks the same layout without allocating.
 * The step (step.c) only ever uses that block. */
#include <math.h>
#include <string.h>

#include "bbox.h"
#include "cubature.h"
#include "def_read.h"
#include "instance.h"
#include "instance_internal.h"
#include "recording.h"
#include "log.h"
#include "dqs.h"
#include "mem_plan.h"

/* Places the instance and every array it uses in the plan's block, or (base NULL) only
 * sizes them: the one list of the instance's memory. The struct comes first, at the
 * block's start. */
static void layout(sw_mem_plan *p, sinew_instance *in, const sw_blob_view *v,
                   const sw_layout_sizes *z) {
    const uint64_t nb = (uint64_t)v->nbones, nd = (uint64_t)v->ndomains,
                   ns = (uint64_t)sw_blob_output_verts(v);
#define TAKE(ptr, count) SW_PLAN_TAKE(p, ptr, count)
    (void)sw_plan_take(p, 1, sizeof *in);
    TAKE(in->bone_dq, nb);
    TAKE(in->pose_host, 12 * nb);
    TAKE(in->pose.T_cur, 12 * nb);
    TAKE(in->pose.T_prev, 12 * nb);
    TAKE(in->pose.T_prev2, 12 * nb);
    TAKE(in->loc.T_cur, 12 * nb);
    TAKE(in->loc.T_prev, 12 * nb);
    TAKE(in->loc.T_prev2, 12 * nb);
    TAKE(in->L_last, 12 * nb);
    /* the subspace map: active vertices and their skinning, accumulators, Jacobians */
    sw_reduced_take(p, v, z->rmax, z->nworkers, &in->red);
    in->h_ref = NULL;
    if (z->rest) TAKE(in->h_ref, (uint64_t)sw_cubature_rest_hessian_size(v));
    /* the pose space */
    sw_pose_space_take(p, v, z->max_pairs, z->per_pair && z->detect, &in->ps);
    if (z->detect) sw_self_contacts_take(p, v, &in->sc);
    if (z->novel) sw_novel_take(p, v, z->ncl, &in->novel);
    sw_solver_take(p, v, z->dynamic, &in->solver);
    /* the collision world's candidates and its broad phase's boxes (the clusters are the
       blob's) */
    sw_world_contacts_take(p, v, z->ncl, z->max_world, &in->wc);
    /* subspace condensation: the patch's budget, and per vertex and tet stamps */
    if (z->cond.max_verts > 0) sw_cond_take(p, v, &z->cond, &in->cond);
    /* the step's scratch, unless a workspace lends it */
    memset(&in->own, 0, sizeof in->own);
    if (!z->shared) sw_scratch_layout(p, &in->own, v, z);
    /* the output */
    TAKE(in->surf_x, 3 * ns);
    TAKE(in->surf_n, 3 * ns);
    TAKE(in->node_x, 3 * (uint64_t)v->nrender_nodes);
    TAKE(in->weld_tris, 3 * (uint64_t)v->nrender_tris);
    TAKE(in->coll_x, v->nrender_verts > 0 ? 3 * (uint64_t)v->nsurf_verts : 0);
    TAKE(in->lod_off, 3 * ns);
    TAKE(in->lod_tmp, 3 * ns);
    TAKE(in->lod_dq, v->lod_rank > 0 ? nb : 0);
    TAKE(in->lod_feat, v->lod_rank > 0 ? SW_POSE_ROTATION_FEATURES(nb) : 0);
    TAKE(in->lod_disp, v->lod_rank > 0 ? 3 * ns : 0);
    /* the state's bounds */
    TAKE(in->bone_ball, 4 * nb);
    TAKE(in->q_bound, nd);
    TAKE(in->u_max, nd);
#undef TAKE
}

/* ---- creation -------------------------------------------------------------------- */

/* The def with its defaults, checked, and the layout's sizes; logs what it rejects. */
sinew_result sw_instance_read_def(const sinew_blob *blob, const sinew_instance_def *def,
                                  const char *caller, sinew_instance_def *d, sw_layout_sizes *z) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v) return SINEW_ERROR_INVALID_ARGUMENT;
    *d = sinew_instance_def_default();
    if (def &&
        sw_def_read(d, sizeof *d, def,
                    offsetof(sinew_instance_def, mode) + sizeof(sinew_step_mode)) != SINEW_OK) {
        sw_log(&blob->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
               "%s: def->struct_size %u is not a sinew_instance_def's", caller,
               (unsigned)def->struct_size);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    if (!d->logger.log) d->logger = blob->logger;
    int tasks = d->tasks.enqueue || d->tasks.finish;
    const char *bad =
        d->mode != SINEW_STEP_QUASISTATIC && d->mode != SINEW_STEP_DYNAMIC
            ? "mode is neither quasistatic nor dynamic"
        : d->max_newton_iters > 100 ? "max_newton_iters is above 100"
        : sw_allocator_check(&d->allocator) != SINEW_OK
            ? "allocator.alloc and allocator.free must both be set or both be NULL"
        : !d->profiler.zone_begin != !d->profiler.zone_end
            ? "profiler.zone_begin and profiler.zone_end must both be set or both be NULL"
        : tasks && (!d->tasks.enqueue || !d->tasks.finish)
            ? "tasks.enqueue and tasks.finish must both be set or both be NULL"
        : tasks && (d->tasks.worker_count < 1 || d->tasks.worker_count > SW_MAX_TASK_WORKERS)
            ? "tasks.worker_count must be 1..256 with task callbacks"
        : !(d->patch_radius >= 0 && d->patch_radius <= 1)
            ? "patch_radius must be 0 (the default) or in (0, 1]"
        : d->max_patch_vertices > 0 && v->ntets == 0
            ? "max_patch_vertices needs a blob with the tet mesh (bake it again)"
        : d->self_contact != SINEW_SELF_CONTACT_POSE_SPACE &&
                d->self_contact != SINEW_SELF_CONTACT_EXHAUSTIVE &&
                d->self_contact != SINEW_SELF_CONTACT_POSE_PAIRS
            ? "self_contact is none of pose-space, exhaustive, pose pairs"
        : d->self_contact == SINEW_SELF_CONTACT_EXHAUSTIVE && v->ntets == 0
            ? "exhaustive self-contact needs a blob with the tet mesh (bake it again)"
        : d->self_contact == SINEW_SELF_CONTACT_POSE_PAIRS && v->npair_groups == 0
            ? "pose-pairs self-contact needs a blob with per-pair sections (bake it again)"
        : d->novel_contact > 1 ? "novel_contact is neither 0 nor 1"
        : d->novel_contact && v->ntets == 0
            ? "novel_contact needs a blob with the tet mesh (bake it again)"
        : d->novel_contact && d->self_contact != SINEW_SELF_CONTACT_POSE_SPACE
            ? "novel_contact adds to pose-space self-contact; the exhaustive and pose-pairs "
              "modes detect contact themselves"
        : d->collision_surface > 1 ? "collision_surface is neither 0 nor 1"
        : d->shared_workspace > 1  ? "shared_workspace is neither 0 nor 1"
        : d->newton_hessian != SINEW_NEWTON_HESSIAN_AUTO &&
                d->newton_hessian != SINEW_NEWTON_HESSIAN_CURRENT &&
                d->newton_hessian != SINEW_NEWTON_HESSIAN_REST_FIRST
            ? "newton_hessian is none of auto, current, rest-first"
            : NULL;
    if (bad) {
        sw_log(&d->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT, "%s: %s", caller,
               bad);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    z->nworkers = tasks ? (int32_t)d->tasks.worker_count : 1;
    if (!d->allocator.alloc) d->allocator = blob->allocator;
    z->nact = blob->act.nact;
    z->nact_step = blob->act.nact_step;
    z->ncorner = blob->act.ncorner;
    z->ncl = blob->clusters.ncl;
    z->rmax = 0;
    for (int32_t k = 0; k < v->ndomains; ++k)
        if (v->domains[k].rank > z->rmax) z->rmax = v->domains[k].rank;
    /* a budget above what the blob can ever need is what it needs */
    z->per_pair = d->self_contact == SINEW_SELF_CONTACT_POSE_PAIRS;
    int32_t need =
        z->per_pair ? sw_pair_space_default_max_pairs(v) : sw_pose_space_default_max_pairs(v);
    z->max_pairs = d->max_contact_pairs == 0 || d->max_contact_pairs > (uint32_t)need
                       ? need
                       : (int32_t)d->max_contact_pairs;
    /* one candidate per surface copy and collider at most is what a step can use: the
     * default is one per copy, and a budget above four per copy is capped there */
    int64_t wneed = v->nsurf_copies > 0 ? v->nsurf_copies : 1;
    z->max_world = d->max_world_contacts == 0          ? (int32_t)wneed
                   : d->max_world_contacts > 4 * wneed ? (int32_t)(4 * wneed)
                                                       : (int32_t)d->max_world_contacts;
    z->rho = d->patch_radius > 0 ? d->patch_radius : SW_COND_DEFAULT_RADIUS;
    z->novel = d->novel_contact == 1;
    z->detect = d->self_contact == SINEW_SELF_CONTACT_EXHAUSTIVE || (z->per_pair && v->ntets > 0) ||
                z->novel;
    /* the detected pairs a patch may take over: as many as the novel detection keeps, or
       (exhaustive, pose-pairs) one per boundary vertex up to that many */
    int32_t detected = !z->detect                               ? 0
                       : v->nsurf_verts < SW_NOVEL_MAX_CONTACTS ? v->nsurf_verts
                                                                : SW_NOVEL_MAX_CONTACTS;
    z->cond = sw_cond_plan(v, d->max_patch_vertices, z->max_world, z->max_pairs, detected,
                           z->novel ? SW_NOVEL_MAX_CONTACTS : 0);
    z->rest = d->newton_hessian != SINEW_NEWTON_HESSIAN_CURRENT;
    z->dynamic = d->mode == SINEW_STEP_DYNAMIC;
    z->shared = d->shared_workspace == 1;
    return SINEW_OK;
}

unsigned char *sw_instance_reserve(const sw_mem_plan *plan, const sinew_instance_def *d,
                                   const char *caller) {
    unsigned char *block =
        plan->overflow ? NULL : sw_alloc(&d->allocator, sw_plan_size(plan), SW_ALLOC_ALIGN);
    if (!block)
        sw_log(&d->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_OUT_OF_MEMORY,
               "%s: out of memory (%zu bytes)", caller, sw_plan_size(plan));
    return block;
}

SINEW_API sinew_result sinew_instance_memory_size(const sinew_blob *blob,
                                                  const sinew_instance_def *def, size_t *bytes) {
    if (!blob || !bytes) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance_def d;
    sw_layout_sizes z;
    sinew_result r = sw_instance_read_def(blob, def, "sinew_instance_memory_size", &d, &z);
    if (r != SINEW_OK) return r;
    sinew_instance scratch;
    sw_mem_plan plan = {NULL, 0, 0};
    layout(&plan, &scratch, sw_blob_get_view(blob), &z);
    if (plan.overflow) return SINEW_ERROR_OUT_OF_MEMORY;
    *bytes = sw_plan_size(&plan);
    return SINEW_OK;
}

/* The rest bounding-box diagonal: the size a teleport is measured against. */
static double rest_size(const sw_blob_view *v) {
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, v->nverts, v->rest);
    return sw_bbox_diagonal(lo, hi);
}

/* The balls of the rest vertices each bone skins (sw_pose_jump) and the bound of each
 * domain's reduced coordinates (instance_internal.h). O(N r), at creation only. */
static void state_bounds(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    for (int32_t b = 0; b < v->nbones; ++b) {
        double lo[3], hi[3], *ball = in->bone_ball + 4 * b;
        sw_bbox_empty(lo, hi);
        for (int32_t gv = 0; gv < v->nverts; ++gv)
            for (int k = 0; k < SW_BLOB_INFLUENCES; ++k)
                if (v->skin_bone[SW_BLOB_INFLUENCES * gv + k] == b &&
                    v->skin_weight[SW_BLOB_INFLUENCES * gv + k] > 0)
                    sw_bbox_add(lo, hi, 1, v->rest + 3 * gv);
        int any = lo[0] <= hi[0];
        for (int i = 0; i < 3; ++i)
            ball[i] = any ? 0.5 * (lo[i] + hi[i]) : 0;
        ball[3] = any ? 0.5 * sw_bbox_diagonal(lo, hi) : -1;
    }
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank;
        double umax = 0, qmax = 0;
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r;
            double f2 = 0;
            for (int32_t j = 0; j < 3 * r; ++j)
                f2 += U[j] * U[j];
            umax = fmax(umax, sqrt(f2));
        }
        for (int32_t t = 0; t < v->ntrain; ++t) {
            const double *q = v->train_q + (int64_t)v->rank_total * t + D->q_offset;
            double n2 = 0;
            for (int32_t j = 0; j < r; ++j)
                n2 += q[j] * q[j];
            qmax = fmax(qmax, sqrt(n2));
        }
        in->u_max[k] = umax;
        in->q_bound[k] = SW_LIMIT_TRAIN * qmax;
        if (umax > 0) in->q_bound[k] = fmax(in->q_bound[k], SW_LIMIT_SIZE * in->size / umax);
    }
}

/* Where a factorisation costs at least this share of the multiply-adds the rest Hessian
 * saves a cubature pass, SINEW_NEWTON_HESSIAN_AUTO keeps the current Hessian: every
 * rest-first update costs a factorisation, and one the energy rejects also a gradient
 * pass before the step goes on as before. The share is sw_solver_factor_madds over
 * sw_cubature_hessian_madds (it tracks the ratio of the times). Characters whose factor
 * is sparse gain from the rest Hessian; one whose springs tie the whole body into a
 * dense factor, and whose stretched flesh stiffens in rotation so that most rest-first
 * updates are rejected, loses (figures: docs/notes/runtime-constants.md). */
#define SW_REST_FACTOR_SHARE 0.3

/* The def's newton_hessian made concrete: with the rest Hessian, its blocks computed
 * (red.h_ref set; sinew_instance_reset fills it). *share: a factorisation's multiply-adds
 * over those the rest Hessian saves a pass. */
static void choose_newton_hessian(sinew_instance *in, sinew_newton_hessian want, double *share) {
    const sw_blob_view *v = in->v;
    double saved = sw_cubature_hessian_madds(v);
    *share = saved > 0 ? sw_solver_factor_madds(&in->solver, v) / saved : INFINITY;
    int rest = want == SINEW_NEWTON_HESSIAN_REST_FIRST ||
               (want == SINEW_NEWTON_HESSIAN_AUTO && *share < SW_REST_FACTOR_SHARE);
    in->solver.rest_first = rest;
    in->red.h_ref = rest ? in->h_ref : NULL;
}

SINEW_API sinew_result sinew_instance_create(const sinew_blob *blob, const sinew_instance_def *def,
                                             sinew_instance **out) {
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!blob) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance_def d;
    sw_layout_sizes z;
    sinew_result r = sw_instance_read_def(blob, def, "sinew_instance_create", &d, &z);
    if (r != SINEW_OK) return r;
    const sw_blob_view *v = sw_blob_get_view(blob);
    sinew_instance sized;
    sw_mem_plan plan = {NULL, 0, 0};
    layout(&plan, &sized, v, &z);
    unsigned char *block = sw_instance_reserve(&plan, &d, "sinew_instance_create");
    if (!block) return SINEW_ERROR_OUT_OF_MEMORY;
    sinew_instance *in = (sinew_instance *)(void *)block;
    plan = (sw_mem_plan){block, 0, 0};
    layout(&plan, in, v, &z);
    in->v = v;
    in->shared = z.shared;
    sw_scratch_clear(&in->own, v);
    sw_scratch_bind(in, &in->own);
    in->allocator = d.allocator;
    in->mode = d.mode;
    in->lod = in->lod_last = in->lod_run = SINEW_LOD_FULL;
    in->size = rest_size(v);
    in->grid = sw_pose_grid(in->size);
    state_bounds(in);
    in->red.v = v;
    in->red.R = v->rank_total;
    in->red.rmax = z.rmax;
    in->red.nworkers = z.nworkers;
    in->tasks = d.tasks;
    in->red.tasks = d.tasks.enqueue ? &in->tasks : NULL;
    in->profiler = d.profiler;
    in->def = d;
    in->blob = blob;
    sw_reduced_bind_active(&in->red, &blob->act);
    /* without a render mesh the surface copies are the output */
    in->red.skin_surface = v->nrender_verts == 0;
    if (v->nrender_verts > 0) sw_render_weld_tris(v, in->weld_tris);
    in->ps.max_pairs = z.max_pairs;
    in->wc.max_cand = z.max_world;
    sw_world_contacts_build(&in->wc, v, &blob->clusters);
    /* 2% of the character's size: what a surface vertex can travel in one step */
    in->wc.radius = 0.01 * in->size;
    in->wc.frame = in->frame; /* the step's (pose.c) */
    in->wc.grid = in->grid;
    in->ps.twin_next = blob->poses.twin_next; /* the blob's, computed once at its load */
    in->ps.reach = blob->poses.reach;
    in->ps.joint_bend = blob->poses.joint_bend;
    in->ps.pair_reach = z.per_pair ? blob->poses.pair_reach : NULL;
    in->cond.z = z.cond;
    if (z.cond.max_verts > 0) sw_cond_build(&in->cond, v, z.rho * in->size);
    in->red.cub_w = z.cond.max_verts > 0 ? in->cond.cub_w : v->cub_weight;
    in->self_mode = d.self_contact;
    /* the bake's equilibrium forces hold for the contact it computed them with: the whole
       pose's pairs (bake_equilibrium.c) */
    in->ps.force = d.self_contact == SINEW_SELF_CONTACT_POSE_SPACE ? v->train_force : NULL;
    if (z.detect) {
        sw_error e;
        if (sw_self_contacts_build(&in->sc, v, &e) != SINEW_OK) {
            sw_log(&d.logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
                   "sinew_instance_create: %s", e.msg);
            sw_free(&d.allocator, block);
            return SINEW_ERROR_INVALID_ARGUMENT;
        }
    }
    in->novel_on = z.novel;
    /* the novel detection's broad phase reads the boundary's boxes of the last output */
    in->coll_on = d.collision_surface == 1;
    if (z.novel || in->coll_on) in->red.skin_surface = 1;
    if (z.novel) sw_novel_build(&in->novel, v, &in->wc, &in->sc);
    in->solver.max_newton = d.max_newton_iters ? d.max_newton_iters : 5;
    in->solver.dq_tiny = 1e-9 * in->size;
    sw_solver_order_blocks(&in->solver, v);
    in->red.spring_adj = in->solver.blk_adj;
    double share;
    choose_newton_hessian(in, d.newton_hessian, &share);
    in->logger = d.logger;
    sw_instance_actor_identity(in);
    in->rec = NULL;
    sinew_instance_reset(in);
    in->touched = 0;
    sw_log(&d.logger, SINEW_LOG_INFO, SINEW_MSG_INSTANCE_CREATED,
           "sinew_instance_create: %zu bytes in one block; %d active vertices, rank %d, %d "
           "contact pairs a step at most; quasistatic Newton starts on the %s Hessian (a "
           "factorisation costs %.2f of what the rest Hessian saves a pass)",
           sw_plan_size(&plan), in->red.nact, in->red.R, z.max_pairs,
           in->solver.rest_first ? "rest" : "current", share);
    *out = in;
    return SINEW_OK;
}

SINEW_API void sinew_instance_destroy(sinew_instance *inst) {
    if (!inst) return;
    if (inst->rec) sinew_instance_set_recorder(inst, NULL);
    sinew_allocator a = inst->allocator;
    sw_free(&a, inst);
}

SINEW_API sinew_result sinew_instance_reset(sinew_instance *inst) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    int32_t R = inst->red.R, nb = inst->v->nbones;
    memset(inst->solver.q, 0, (size_t)R * sizeof(double));
    memset(inst->solver.qdot, 0, (size_t)R * sizeof(double));
    inst->solver.pred_valid = 0;
    sw_pose_history *ph = &inst->pose;
    sw_instance_rest_pose(inst); /* where the actor stands */
    memcpy(ph->T_prev, ph->T_cur, 12 * (size_t)nb * sizeof(double));
    memcpy(ph->T_prev2, ph->T_cur, 12 * (size_t)nb * sizeof(double));
    ph->history = 0;
    ph->h_prev = 0;
    ph->declared_jump = 0;
    sw_instance_frame(inst);
    memcpy(inst->L_last, inst->loc.T_cur, 12 * (size_t)nb * sizeof(double));
    memcpy(inst->frame_last, inst->frame, sizeof inst->frame);
    sw_pose_space_reset(&inst->ps, nb);
    inst->wc.boxes_valid = 0;
    sw_world_contacts_clear(&inst->wc);
    if (inst->cond.z.max_verts > 0) sw_cond_forget(&inst->cond);
    if (inst->self_mode == SINEW_SELF_CONTACT_EXHAUSTIVE || inst->ps.novel_mask || inst->novel_on)
        sw_self_contacts_clear(&inst->sc);
    inst->sc.in_patch = NULL;
    inst->ps.in_patch = NULL;
    for (int32_t c = 0; c < inst->v->ncub; ++c) { /* identity: a cold start */
        double *V = inst->red.svd_V + 9 * (int64_t)c;
        memset(V, 0, 9 * sizeof(double));
        V[0] = V[4] = V[8] = 1;
    }
    /* Newton's reference Hessian back to the rest one (a cubature pass at rest) */
    if (inst->red.h_ref) sw_cubature_rest_hessian(&inst->red, inst->red.h_ref);
    inst->lod_last = inst->lod; /* the level stays the host's; nothing to blend from */
    inst->lod_w = 0;
    inst->stepped = 0;
    inst->coll_src = SW_COLL_SKINNED;
    memset(&inst->stats, 0, sizeof inst->stats);
    inst->stats.struct_size = sizeof inst->stats;
    inst->stats.lod = (uint32_t)inst->lod;
    sw_rec_mark(inst, SW_REC_RESET);
    return SINEW_OK;
}
