/* The debug draw (sinew_debug_draw, sinew.h): what the last step left readable, handed
 * to the host's callbacks in the actor's frame. It only reads the instance, outside the
 * step: the world contacts' frozen laws, the pairs in use, the patch, the world, the pose.
 * Nothing here allocates or locks, and a step never calls it. */
#include <math.h>

#include "collision.h"
#include "instance_internal.h"
#include "pose_contact.h"
#include "self_contact.h"

typedef struct dd_ctx {
    const sinew_instance *in;
    const sinew_debug_draw *d;
    float normal_len, point_size;
} dd_ctx;

/* A point of the step's frame (or with direction, a vector) as the host's floats. */
static void to_host(const dd_ctx *c, const double x[3], int direction, float y[3]) {
    double a[3], w[3];
    sw_instance_from_step(c->in, x, direction, w);
    sw_instance_to_actor(c->in, w, direction, a);
    for (int i = 0; i < 3; ++i)
        y[i] = (float)a[i];
}

static void line(const dd_ctx *c, const float a[3], const float b[3], uint32_t rgba) {
    if (c->d->draw_line) c->d->draw_line(a, b, rgba, c->d->context);
}

static void point(const dd_ctx *c, const float a[3], uint32_t rgba) {
    if (c->d->draw_point) c->d->draw_point(a, c->point_size, rgba, c->d->context);
}

/* A contact: its point and a segment along its normal n (both in the simulation frame). */
static void contact(const dd_ctx *c, const double x[3], const double n[3], uint32_t rgba) {
    float p[3], m[3], e[3];
    to_host(c, x, 0, p);
    to_host(c, n, 1, m);
    double len = sqrt((double)m[0] * m[0] + (double)m[1] * m[1] + (double)m[2] * m[2]);
    for (int i = 0; i < 3; ++i)
        e[i] = p[i] + (len > 0 ? (float)(c->normal_len * m[i] / len) : 0.0f);
    point(c, p, rgba);
    line(c, p, e, rgba);
}

/* The world contacts in force at the solution (as stats.world_contacts counts them) and
 * the self-contact pairs in use (as stats.self_contacts). */
static void draw_contacts(const dd_ctx *c) {
    const sinew_instance *in = c->in;
    for (int32_t j = 0; in->wc.world && j < in->wc.ncand; ++j)
        if (in->wc.cand[j].active)
            contact(c, in->wc.cand[j].law.a, in->wc.cand[j].law.n, SINEW_DEBUG_COLOR_WORLD_CONTACT);
    double x[3], n[3];
    if (in->self_mode != SINEW_SELF_CONTACT_EXHAUSTIVE && in->ps.npairs > 0) {
        sw_pair_set set = sw_pose_pair_set(&in->red);
        for (int32_t p = 0; p < in->ps.npairs; ++p) {
            sw_contact_pair_point(&in->red, &set, in->ps.pairs[p], in->solver.q, x, n);
            contact(c, x, n, SINEW_DEBUG_COLOR_SELF_CONTACT);
        }
    }
    if (sw_instance_detects(in)) {
        sw_pair_set set = sw_self_contacts_pairs(&in->sc);
        for (int32_t p = 0; p < in->sc.npairs; ++p) {
            sw_contact_pair_point(&in->red, &set, p, in->solver.q, x, n);
            contact(c, x, n, SINEW_DEBUG_COLOR_SELF_CONTACT);
        }
    }
}

/* The patch: its vertices as points, its full tets' faces as triangles. */
static void draw_patch(const dd_ctx *c) {
    const sw_cond *cd = &c->in->cond;
    if (cd->z.max_verts == 0) return;
    float p[4][3];
    for (int32_t i = 0; i < cd->nf; ++i) {
        to_host(c, cd->x + 3 * (int64_t)i, 0, p[0]);
        point(c, p[0], SINEW_DEBUG_COLOR_PATCH);
    }
    const sinew_debug_draw *d = c->d;
    if (!d->draw_triangle) return;
    static const int face[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
    for (int32_t e = 0; e < cd->nt; ++e) {
        const int32_t *slot = cd->ft_slot + 4 * (int64_t)e;
        for (int k = 0; k < 4; ++k)
            to_host(c,
                    slot[k] >= 0 ? cd->x + 3 * (int64_t)slot[k] : cd->ring_x + 3 * (-1 - slot[k]),
                    0, p[k]);
        for (int f = 0; f < 4; ++f)
            d->draw_triangle(p[face[f][0]], p[face[f][1]], p[face[f][2]], SINEW_DEBUG_COLOR_PATCH,
                             d->context);
    }
}

/* Each collider's outline: a box's 12 edges, a plane's square around the actor. */
static void draw_colliders(const dd_ctx *c) {
    const sinew_instance *in = c->in;
    const sinew_world *w = in->wc.world;
    double around[3] = {in->actor[9], in->actor[10], in->actor[11]}, k[8][3];
    for (uint32_t s = 0; s < sw_world_slot_count(w); ++s) {
        const sw_collider *col = sw_world_slot(w, s);
        if (!col) continue;
        int n = sw_collider_outline(col, around, in->size, k);
        float p[8][3];
        for (int j = 0; j < n; ++j) { /* in the world, not the step's frame */
            double a[3];
            sw_instance_to_actor(in, k[j], 0, a);
            for (int i = 0; i < 3; ++i)
                p[j][i] = (float)a[i];
        }
        if (n == 4) {
            for (int j = 0; j < 4; ++j)
                line(c, p[j], p[(j + 1) % 4], SINEW_DEBUG_COLOR_COLLIDER);
            continue;
        }
        for (int j = 0; j < 8; ++j) /* an edge joins corners one bit apart */
            for (int b = 1; b < 8; b <<= 1)
                if (!(j & b)) line(c, p[j], p[j | b], SINEW_DEBUG_COLOR_COLLIDER);
    }
}

/* Bone b's transform (the host's, in the actor's frame) applied to the rest point x. */
static void posed(const sinew_instance *in, int32_t b, const double x[3], float y[3]) {
    const double *T = in->pose_host + 12 * (int64_t)b;
    for (int i = 0; i < 3; ++i)
        y[i] = (float)(T[3 * i] * x[0] + T[3 * i + 1] * x[1] + T[3 * i + 2] * x[2] + T[9 + i]);
}

/* Each bone from its parent's joint to its own (the joints the blob's bind poses give);
 * without them, a point at the middle of the flesh each bone skins. */
static void draw_bones(const dd_ctx *c) {
    const sinew_instance *in = c->in;
    for (int32_t b = 0; b < in->v->nbones; ++b) {
        double bind[12], pbind[12];
        int32_t parent = -1;
        float p[3], q[3];
        if (sinew_blob_bone_bind(in->blob, (uint32_t)b, bind) != SINEW_OK) {
            if (in->bone_ball[4 * b + 3] < 0) continue;
            posed(in, b, in->bone_ball + 4 * b, p);
            point(c, p, SINEW_DEBUG_COLOR_BONE);
            continue;
        }
        sinew_blob_bone_parent(in->blob, (uint32_t)b, &parent);
        posed(in, b, bind + 9, p);
        if (parent < 0 || sinew_blob_bone_bind(in->blob, (uint32_t)parent, pbind) != SINEW_OK) {
            point(c, p, SINEW_DEBUG_COLOR_BONE);
            continue;
        }
        posed(in, parent, pbind + 9, q);
        line(c, q, p, SINEW_DEBUG_COLOR_BONE);
    }
}

SINEW_API sinew_result sinew_instance_debug_draw(const sinew_instance *inst,
                                                 const sinew_debug_draw *draw) {
    if (!inst || !draw) return SINEW_ERROR_INVALID_ARGUMENT;
    float len = draw->normal_length > 0 ? draw->normal_length : (float)(0.02 * inst->size);
    dd_ctx c = {inst, draw, len, 0.25f * len};
    if (draw->flags & SINEW_DEBUG_DRAW_CONTACTS) draw_contacts(&c);
    if (draw->flags & SINEW_DEBUG_DRAW_PATCH) draw_patch(&c);
    if (draw->flags & SINEW_DEBUG_DRAW_COLLIDERS) draw_colliders(&c);
    if (draw->flags & SINEW_DEBUG_DRAW_BONES) draw_bones(&c);
    return SINEW_OK;
}
