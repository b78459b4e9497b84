/* The step's scratch (DESIGN.md §3): what a step computes afresh and no later call reads,
 * the reduced Hessian, its factor and the dynamic step's damping Hessian first (rank
 * squared each: most of an instance at high rank). An instance holds its own, or
 * (def.shared_workspace) none and steps in a workspace the host lends it, one per worker
 * thread, so that a crowd reserves the state of each character and the scratch of each
 * thread. The step writes every scratch array before it reads it, so the workspace a step
 * runs in never changes its result. */
#include <string.h>

#include "dense.h"
#include "instance_internal.h"
#include "log.h"
#include "mem_plan.h"

struct sinew_workspace {
    const sinew_blob *blob;    /* the blob it was made for */
    sinew_allocator allocator; /* frees the block */
    sw_scratch sc;
};

void sw_scratch_layout(sw_mem_plan *p, sw_scratch *sc, const sw_blob_view *v,
                       const sw_layout_sizes *z) {
    const uint64_t R = (uint64_t)v->rank_total, na = (uint64_t)z->nact, nc = (uint64_t)z->ncorner;
    SW_PLAN_TAKE(p, sc->H, R * R);
    SW_PLAN_TAKE(p, sc->L, R * R);
    SW_PLAN_TAKE(p, sc->pack, sw_block_cholesky_pack_size(z->rmax));
    SW_PLAN_TAKE(p, sc->Hn, z->dynamic ? R * R : 0);
    SW_PLAN_TAKE(p, sc->Hq, z->cond.max_verts > 0 ? R * R : 0);
    SW_PLAN_TAKE(p, sc->act_R, 9 * na);
    SW_PLAN_TAKE(p, sc->act_t, 3 * na);
    SW_PLAN_TAKE(p, sc->corner_x, 3 * nc);
    SW_PLAN_TAKE(p, sc->corner_f, 3 * nc);
    SW_PLAN_TAKE(p, sc->ecub, (uint64_t)v->ncub);
    const uint64_t nd = (uint64_t)v->ndomains;
    SW_PLAN_TAKE(p, sc->H_nz, nd * nd);
    SW_PLAN_TAKE(p, sc->Hn_nz, z->dynamic ? nd * nd : 0);
    SW_PLAN_TAKE(p, sc->Hq_nz, z->cond.max_verts > 0 ? nd * nd : 0);
}

void sw_scratch_clear(sw_scratch *sc, const sw_blob_view *v) {
    size_t n = (size_t)v->ndomains * (size_t)v->ndomains;
    if (sc->H_nz) memset(sc->H_nz, 1, n);
    if (sc->Hn_nz) memset(sc->Hn_nz, 1, n);
    if (sc->Hq_nz) memset(sc->Hq_nz, 1, n);
}

void sw_scratch_bind(sinew_instance *in, const sw_scratch *sc) {
    in->red.H = sc->H;
    in->solver.L = sc->L;
    in->solver.pack = sc->pack;
    in->solver.Hn = sc->Hn;
    in->cond.Hq = sc->Hq;
    in->cond.Hq_nz = sc->Hq_nz;
    in->red.act_R = sc->act_R;
    in->red.act_t = sc->act_t;
    in->red.corner_x = sc->corner_x;
    in->red.corner_f = sc->corner_f;
    in->red.ecub = sc->ecub;
    in->red.H_nz = sc->H_nz;
    in->solver.Hn_nz = sc->Hn_nz;
}

/* The workspace's layout: the struct, then its scratch. */
static void layout(sw_mem_plan *p, sinew_workspace *ws, const sw_blob_view *v,
                   const sw_layout_sizes *z) {
    (void)sw_plan_take(p, 1, sizeof *ws);
    sw_scratch_layout(p, &ws->sc, v, z);
}

SINEW_API sinew_result sinew_workspace_memory_size(const sinew_blob *blob,
                                                   const sinew_instance_def *def, size_t *bytes) {
    if (!blob || !bytes) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance_def d;
    sw_layout_sizes z;
    sinew_result r = sw_instance_read_def(blob, def, "sinew_workspace_memory_size", &d, &z);
    if (r != SINEW_OK) return r;
    sinew_workspace sized;
    sw_mem_plan plan = {NULL, 0, 0};
    layout(&plan, &sized, sw_blob_get_view(blob), &z);
    if (plan.overflow) return SINEW_ERROR_OUT_OF_MEMORY;
    *bytes = sw_plan_size(&plan);
    return SINEW_OK;
}

SINEW_API sinew_result sinew_workspace_create(const sinew_blob *blob, const sinew_instance_def *def,
                                              sinew_workspace **out) {
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!blob) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance_def d;
    sw_layout_sizes z;
    sinew_result r = sw_instance_read_def(blob, def, "sinew_workspace_create", &d, &z);
    if (r != SINEW_OK) return r;
    const sw_blob_view *v = sw_blob_get_view(blob);
    sinew_workspace sized;
    sw_mem_plan plan = {NULL, 0, 0};
    layout(&plan, &sized, v, &z);
    unsigned char *block = sw_instance_reserve(&plan, &d, "sinew_workspace_create");
    if (!block) return SINEW_ERROR_OUT_OF_MEMORY;
    sinew_workspace *ws = (sinew_workspace *)(void *)block;
    plan = (sw_mem_plan){block, 0, 0};
    layout(&plan, ws, v, &z);
    ws->blob = blob;
    sw_scratch_clear(&ws->sc, v);
    ws->allocator = d.allocator;
    *out = ws;
    return SINEW_OK;
}

SINEW_API void sinew_workspace_destroy(sinew_workspace *ws) {
    if (!ws) return;
    sinew_allocator a = ws->allocator;
    sw_free(&a, ws);
}

SINEW_API sinew_result sinew_instance_step_in(sinew_instance *inst, sinew_workspace *ws, float dt) {
    if (!inst || !ws) return SINEW_ERROR_INVALID_ARGUMENT;
    const char *bad = ws->blob != inst->blob ? "the workspace was made for another blob"
                      : inst->mode == SINEW_STEP_DYNAMIC && !ws->sc.Hn
                          ? "the instance is dynamic and the workspace was made for "
                            "quasistatic instances"
                      : inst->cond.z.max_verts > 0 && !ws->sc.Hq
                          ? "the instance has patches (max_patch_vertices) and the workspace "
                            "was made without them"
                          : NULL;
    if (bad) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
               "sinew_instance_step_in: %s", bad);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    sw_scratch_bind(inst, &ws->sc);
    sinew_result r = sw_instance_step_bound(inst, dt);
    sw_scratch_bind(inst, &inst->own); /* NULL for a shared instance: nothing dangles */
    return r;
}
