/* What a step leaves for the host: the output surface (each boundary vertex the mean of
 * its domain copies, or the render mesh carried by its render nodes, output_render.c;
 * area-weighted normals), its float copy, the collision surface (the boundary, which
 * another character collides with), the step's figures; and the O(N) evaluation helpers
 * of tools and tests, which are never part of a step. */
#include <math.h>
#include <string.h>

#include "instance.h"
#include "hash.h"
#include "instance_internal.h"
#include "log.h"
#include "recording.h"
#include "surface_normals.h"

/* The mean x of copies [b, e) (domain, local vertex pairs, their active indices act) at
 * the state q; each copy's own position into copy_x[3 i ..] when copy_x is not NULL. A
 * vertex in the condensation patch is at its patch position, every copy of it too. */
static void copies_mean(const sinew_instance *in, const int32_t *copies, const int32_t *act,
                        int32_t b, int32_t e, double *copy_x, double x[3]) {
    const sw_blob_view *v = in->v;
    const double *xp = sw_cond_position(
        &in->cond, v->domain_verts[v->domains[copies[2 * b]].vert_begin + copies[2 * b + 1]]);
    if (xp) {
        memcpy(x, xp, 3 * sizeof(double));
        for (int32_t i = b; copy_x && i < e; ++i)
            memcpy(copy_x + 3 * i, xp, 3 * sizeof(double));
        return;
    }
    double acc[3] = {0, 0, 0};
    for (int32_t i = b; i < e; ++i) {
        const sw_blob_domain *D = &v->domains[copies[2 * i]];
        double y[3];
        sw_reduced_position(&in->red, D, copies[2 * i + 1], act[i], in->solver.q + D->q_offset, y,
                            NULL);
        for (int k = 0; k < 3; ++k) {
            acc[k] += y[k];
            if (copy_x) copy_x[3 * i + k] = y[k];
        }
    }
    for (int k = 0; k < 3; ++k)
        x[k] = acc[k] / (double)(e - b);
}

void sw_instance_surface_normals(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    if (v->nrender_verts > 0)
        sw_render_normals(v, in->weld_tris, in->surf_x, in->surf_n);
    else
        sw_surface_normals(v->nsurf_verts, in->surf_x, v->nsurf_tris, v->surf_tris, in->surf_n);
}

void sw_instance_write_surface(sinew_instance *in) {
    const sw_blob_view *v = in->v;
    /* the boundary is the output, or (under a render mesh) what carries the world's and
     * the novel self-contact's broad phase next step and the collision surface the host
     * asked for: without any of them it is skipped (attaching a world invalidates the
     * boxes, instance_world.c) */
    int boxes = in->wc.world || in->novel_on; /* a broad phase reads them next step */
    int boundary = v->nrender_verts == 0 || boxes || in->coll_on;
    for (int32_t s = 0; s < (boundary ? v->nsurf_verts : 0); ++s)
        copies_mean(in, v->surf_copies, in->red.copy_act, v->surf_copy_ptr[s],
                    v->surf_copy_ptr[s + 1], in->wc.copy_x,
                    v->nrender_verts ? in->coll_x + 3 * s : in->surf_x + 3 * s);
    in->coll_src = v->nrender_verts == 0 ? SW_COLL_OUTPUT
                   : boundary            ? SW_COLL_BOUNDARY
                                         : SW_COLL_NONE;
    for (int32_t s = 0; in->coll_src == SW_COLL_BOUNDARY && s < v->nsurf_verts; ++s) {
        double y[3];
        sw_instance_from_step(in, in->coll_x + 3 * s, 0, y);
        memcpy(in->coll_x + 3 * s, y, sizeof y);
    }
    if (v->nrender_verts > 0) {
        for (int32_t n = 0; n < v->nrender_nodes; ++n)
            copies_mean(in, v->render_node_copies, in->red.node_copy_act, v->render_node_ptr[n],
                        v->render_node_ptr[n + 1], NULL, in->node_x + 3 * n);
        sw_render_positions(v, in->node_x, in->surf_x);
    }
    sw_instance_surface_normals(in);
    if (boxes) sw_world_contacts_update_boxes(&in->wc); /* (of copy_x, in the step's frame) */
    for (int32_t i = 0; i < sw_blob_output_verts(v); ++i) {
        double y[3];
        sw_instance_from_step(in, in->surf_x + 3 * i, 0, y);
        memcpy(in->surf_x + 3 * i, y, sizeof y);
        sw_instance_from_step(in, in->surf_n + 3 * i, 1, y);
        memcpy(in->surf_n + 3 * i, y, sizeof y);
    }
}

SINEW_API sinew_result sinew_instance_read_surface(const sinew_instance *inst, float *positions,
                                                   float *normals, uint32_t vertex_count) {
    if (!inst || (!positions && !normals) ||
        vertex_count != (uint32_t)sw_blob_output_verts(inst->v))
        return SINEW_ERROR_INVALID_ARGUMENT;
    static const double identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    if (inst->scale == 1 && inst->actor_scale == 1 &&
        memcmp(inst->actor, identity, sizeof identity) == 0) { /* the same numbers, sooner */
        for (uint32_t i = 0; i < 3 * vertex_count; ++i) {
            if (positions) positions[i] = (float)inst->surf_x[i];
            if (normals) normals[i] = (float)inst->surf_n[i];
        }
        return SINEW_OK;
    }
    for (uint32_t i = 0; i < vertex_count; ++i) {
        double y[3];
        if (positions) {
            sw_instance_to_actor(inst, inst->surf_x + 3 * i, 0, y);
            for (int k = 0; k < 3; ++k)
                positions[3 * i + k] = (float)y[k];
        }
        if (normals) {
            sw_instance_to_actor(inst, inst->surf_n + 3 * i, 1, y);
            for (int k = 0; k < 3; ++k)
                normals[3 * i + k] = (float)y[k];
        }
    }
    return SINEW_OK;
}

void sw_instance_read_surface_d(const sinew_instance *inst, double *x) {
    for (int32_t i = 0; i < sw_blob_output_verts(inst->v); ++i)
        sw_instance_to_actor(inst, inst->surf_x + 3 * i, 0, x + 3 * i);
}

SINEW_API sinew_result sinew_instance_get_stats(const sinew_instance *inst, sinew_step_stats *out) {
    if (!inst || !out || out->struct_size < sizeof(uint32_t)) return SINEW_ERROR_INVALID_ARGUMENT;
    uint32_t n =
        out->struct_size < sizeof inst->stats ? out->struct_size : (uint32_t)sizeof inst->stats;
    memcpy(out, &inst->stats, n);
    out->struct_size = n;
    return SINEW_OK;
}

uint64_t sw_instance_surface_hash(const sinew_instance *in) {
    size_t n = 3 * (size_t)sw_blob_output_verts(in->v) * sizeof(double);
    return sw_fnv1a(sw_fnv1a(SW_FNV_START, in->surf_x, n), in->surf_n, n);
}

const double *sw_instance_surface(const sinew_instance *inst) {
    return inst->surf_x;
}
const double *sw_instance_q(const sinew_instance *inst) {
    return inst->solver.q;
}

int32_t sw_instance_nearest_pose(const sinew_instance *inst) {
    return inst->ps.nearest;
}

/* n points of the step's frame moved to the simulation frame, in place. */
static void to_sim(const sinew_instance *inst, int32_t n, double *x) {
    for (int32_t i = 0; i < n; ++i) {
        double y[3];
        sw_instance_from_step(inst, x + 3 * i, 0, y);
        memcpy(x + 3 * i, y, sizeof y);
    }
}

/* Domain D's copy lv of its vertex (global gv) in the step's frame, as the runtime's state
 * places it: rest + U q skinned by the vertex's own DQS transform. */
static void copy_position(const sinew_instance *inst, const sw_blob_domain *D, int32_t lv,
                          int32_t gv, double x[3]) {
    const sw_blob_view *v = inst->v;
    int32_t r = D->rank;
    double R[9], t[3], y[3];
    sw_dqs_blend(inst->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, R, t);
    const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r;
    for (int i = 0; i < 3; ++i) {
        double acc = v->rest[3 * gv + i];
        for (int32_t j = 0; j < r; ++j)
            acc += U[i * r + j] * inst->solver.q[D->q_offset + j];
        y[i] = acc;
    }
    for (int i = 0; i < 3; ++i)
        x[i] = R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + t[i];
}

void sw_instance_full_positions(const sinew_instance *inst, double *x, double *count) {
    const sw_blob_view *v = inst->v;
    memset(x, 0, 3 * (size_t)v->nverts * sizeof(double));
    memset(count, 0, (size_t)v->nverts * sizeof(double));
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            int32_t gv = v->domain_verts[D->vert_begin + lv];
            double y[3];
            copy_position(inst, D, lv, gv, y);
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] += y[i];
            count[gv] += 1;
        }
    }
    for (int32_t gv = 0; gv < v->nverts; ++gv) {
        const double *xp = sw_cond_position(&inst->cond, gv);
        if (xp) {
            memcpy(x + 3 * gv, xp, 3 * sizeof(double));
        } else if (count[gv] > 0) {
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] /= count[gv];
        } else {
            double R[9], t[3];
            sw_dqs_blend(inst->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, R, t);
            const double *X = v->rest + 3 * gv;
            for (int i = 0; i < 3; ++i)
                x[3 * gv + i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
        }
    }
    to_sim(inst, v->nverts, x);
}

double sw_instance_copy_spread(const sinew_instance *inst, const double *x, double *spread) {
    const sw_blob_view *v = inst->v;
    double gap = 0;
    memset(spread, 0, (size_t)v->nverts * sizeof(double));
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            int32_t gv = v->domain_verts[D->vert_begin + lv];
            if (sw_cond_position(&inst->cond, gv)) continue; /* solved in full space */
            double y[3], e = 0;
            copy_position(inst, D, lv, gv, y);
            to_sim(inst, 1, y);
            for (int i = 0; i < 3; ++i)
                e += (y[i] - x[3 * gv + i]) * (y[i] - x[3 * gv + i]);
            spread[gv] += e;
            if (sqrt(e) > gap) gap = sqrt(e);
        }
    }
    return gap;
}

void sw_instance_dqs_positions(const sinew_instance *inst, double *x) {
    const sw_blob_view *v = inst->v;
    sw_dqs_skin(v->nverts, v->rest, inst->bone_dq, v->skin_bone, v->skin_weight, 4, x);
    to_sim(inst, v->nverts, x);
}

double sw_instance_potential(sinew_instance *inst, const double *q, double *g, double *H) {
    sw_dyn_coef dc = {1.0 / 30, 0, 0, 0, 0, 0};
    size_t R = (size_t)inst->red.R;
    sw_reduced_skin(&inst->red, inst->bone_dq);
    sw_pose_space_lookup(&inst->ps, inst->v, inst->loc.T_cur);
    sw_pose_space_gather_pairs(&inst->ps, inst->v);
    sw_step_contacts ct = sw_instance_contacts(inst, NULL);
    double phi = sw_potential(&inst->red, &ct, &inst->solver, q, &dc, g || H, H != NULL);
    if (g) memcpy(g, inst->red.g, R * sizeof(double));
    if (H) memcpy(H, inst->red.H, R * R * sizeof(double));
    return phi;
}

void sw_instance_set_q(sinew_instance *inst, const double *q) {
    memcpy(inst->solver.q, q, (size_t)inst->red.R * sizeof(double));
}

void sw_instance_surface_at(sinew_instance *inst, const double *q) {
    sw_reduced_skin(&inst->red, inst->bone_dq);
    sw_instance_set_q(inst, q);
    sw_instance_write_surface(inst);
}

/* Simulation vertex gv skinned at the current pose (no correction) into y, in the
 * simulation frame. */
static void skin_vertex(const sinew_instance *inst, int32_t gv, double y[3]) {
    const sw_blob_view *v = inst->v;
    double R[9], t[3];
    const double *X = v->rest + 3 * (int64_t)gv;
    sw_dqs_blend(inst->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, R, t);
    for (int k = 0; k < 3; ++k)
        y[k] = R[3 * k] * X[0] + R[3 * k + 1] * X[1] + R[3 * k + 2] * X[2] + t[k];
    to_sim(inst, 1, y);
}

void sw_instance_skinned_surface(const sinew_instance *inst, double *x) {
    const sw_blob_view *v = inst->v;
    for (int32_t s = 0; s < v->nsurf_verts && v->nrender_verts == 0; ++s) {
        double acc[3] = {0, 0, 0};
        int32_t b = v->surf_copy_ptr[s], e = v->surf_copy_ptr[s + 1];
        for (int32_t i = b; i < e; ++i) {
            const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
            double y[3];
            skin_vertex(inst, v->domain_verts[D->vert_begin + v->surf_copies[2 * i + 1]], y);
            for (int k = 0; k < 3; ++k)
                acc[k] += y[k];
        }
        for (int k = 0; k < 3; ++k)
            x[3 * s + k] = acc[k] / (double)(e - b);
    }
    for (int32_t i = 0; i < v->nrender_verts; ++i) { /* the embedding of the skinned nodes */
        int32_t w = v->render_weld[i];
        const int32_t *c = v->render_tets + 4 * (int64_t)v->render_tet[w];
        const double *bary = v->render_bary + 4 * (int64_t)w;
        double y[4][3];
        for (int k = 0; k < 4; ++k)
            skin_vertex(inst, sw_render_node_vertex(v, c[k]), y[k]);
        for (int k = 0; k < 3; ++k)
            x[3 * (int64_t)i + k] =
                bary[0] * y[0][k] + bary[1] * y[1][k] + bary[2] * y[2][k] + bary[3] * y[3][k];
    }
}

double sw_instance_displacement_bound(const sinew_instance *inst) {
    const sw_blob_view *v = inst->v;
    double D = 0, gain = 1;
    for (int32_t k = 0; k < v->ndomains; ++k)
        D = fmax(D, inst->u_max[k] * inst->q_bound[k]);
    /* a render vertex is its tet's corners weighted by its barycentrics, which extrapolate
       (some negative) where it lies outside the tet: its displacement is at most the sum of
       their magnitudes times the corners' */
    for (int32_t i = 0; i < v->nrender_verts; ++i) {
        const double *b = v->render_bary + 4 * (int64_t)i;
        gain = fmax(gain, fabs(b[0]) + fabs(b[1]) + fabs(b[2]) + fabs(b[3]));
    }
    return D * gain;
}

double sw_instance_bound_usage(const sinew_instance *inst) {
    double use = 0;
    for (int32_t k = 0; k < inst->v->ndomains; ++k) {
        const sw_blob_domain *D = &inst->v->domains[k];
        double n2 = 0;
        for (int32_t j = 0; j < D->rank; ++j)
            n2 += inst->solver.q[D->q_offset + j] * inst->solver.q[D->q_offset + j];
        if (inst->q_bound[k] > 0) use = fmax(use, sqrt(n2) / inst->q_bound[k]);
    }
    return use;
}

/* The boundary vertex s of the last step, or skinned at the pose, in the simulation
 * frame (sw_coll_source). */
static void collision_vertex(const sinew_instance *inst, int32_t s, double y[3]) {
    const sw_blob_view *v = inst->v;
    switch (inst->coll_src) {
    case SW_COLL_OUTPUT:
        memcpy(y, inst->surf_x + 3 * (int64_t)s, 3 * sizeof(double));
        return;
    case SW_COLL_BOUNDARY:
        memcpy(y, inst->coll_x + 3 * (int64_t)s, 3 * sizeof(double));
        return;
    default: /* every copy of a vertex skins alike */
        skin_vertex(inst, sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]), y);
    }
}

SINEW_API sinew_result sinew_instance_read_collision_surface(const sinew_instance *inst,
                                                             float *positions,
                                                             uint32_t vertex_count) {
    if (!inst || !positions || vertex_count != (uint32_t)inst->blob->coll.nverts)
        return SINEW_ERROR_INVALID_ARGUMENT;
    const sw_coll_surface *cs = &inst->blob->coll;
    if (inst->coll_src == SW_COLL_NONE) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
               "sinew_instance_read_collision_surface: the blob's output is its render mesh and "
               "the last step did not write the boundary (set sinew_instance_def."
               "collision_surface, or attach a world)");
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    for (uint32_t i = 0; i < vertex_count; ++i) {
        double x[3], y[3];
        collision_vertex(inst, cs->vert[i], x);
        sw_instance_to_actor(inst, x, 0, y);
        for (int k = 0; k < 3; ++k)
            positions[3 * i + k] = (float)y[k];
    }
    return SINEW_OK;
}
