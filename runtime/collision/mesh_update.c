/* What a mesh collider's vertices determine, computed when it is added (mesh_build.c)
 * and again, by the same code, whenever the host moves its vertices
 * (sinew_world_set_mesh_vertices: another character's surface after its step): the
 * local box, the face, edge and vertex pseudonormals (Bærentzen and Aanæs 2005) and the
 * Embree BVH. A move allocates nothing of ours (the edge map is kept from the add);
 * Embree's commit does, which is why a move, like an add, never runs during a step.
 *
 * A triangle the motion collapsed (area below 1e-12 of its longest edge squared, the
 * add's test) is dead until it opens again: its face normal is zero, so it adds nothing
 * to the pseudonormals of its edges and corners, and queries skip it (mesh.c). */
#include <math.h>
#include <string.h>

#include "collision_internal.h"

void sw_mesh_bounds(sw_collider *c) {
    sw_mesh *m = &c->mesh;
    for (int k = 0; k < 3; ++k)
        c->lo[k] = HUGE_VAL, c->hi[k] = -HUGE_VAL;
    for (size_t i = 0; i < (size_t)3 * m->nverts; ++i) {
        c->lo[i % 3] = fmin(c->lo[i % 3], m->X[i]);
        c->hi[i % 3] = fmax(c->hi[i % 3], m->X[i]);
    }
    double ext[3];
    sw_v3_sub(c->hi, c->lo, ext);
    m->diagonal = sw_v3_norm(ext);
}

uint32_t sw_mesh_face_normals(sw_mesh *m) {
    m->ndead = 0;
    for (uint32_t t = 0; t < m->ntris; ++t) {
        const uint32_t *v = m->tris + 3 * t;
        const double *a = m->X + 3 * v[0], *b = m->X + 3 * v[1], *c = m->X + 3 * v[2];
        double e0[3], e1[3], e2[3], *n = m->face_n + 3 * t;
        sw_v3_sub(b, a, e0);
        sw_v3_sub(c, a, e1);
        sw_v3_sub(c, b, e2);
        double l2 = fmax(fmax(sw_v3_dot(e0, e0), sw_v3_dot(e1, e1)), sw_v3_dot(e2, e2));
        sw_v3_cross(e0, e1, n);
        double a2 = sw_v3_normalize(n);
        m->dead[t] = !(a2 > 1e-12 * l2) || !(l2 > 0);
        if (m->dead[t]) {
            n[0] = n[1] = n[2] = 0;
            m->ndead++;
        }
    }
    return m->ndead;
}

/* Edge e of triangle t: the sum of its faces' normals, each of weight pi (a boundary
 * edge: its face's), summed lower triangle first, so both uses get the same bits. */
static void edge_normal(sw_mesh *m, uint32_t t, uint32_t e) {
    uint32_t u = m->twin[3 * t + e], lo = t, hi = t;
    if (u != UINT32_MAX) {
        lo = t < u / 3 ? t : u / 3;
        hi = t < u / 3 ? u / 3 : t;
    }
    double n[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i)
        n[i] += m->face_n[3 * lo + i];
    if (hi != lo)
        for (int i = 0; i < 3; ++i)
            n[i] += m->face_n[3 * hi + i];
    /* Two faces folded flat onto each other cancel: keep the lower face's normal (the
     * other's when that one is dead; zero when both are). */
    if (!(sw_v3_normalize(n) > 1e-12)) memcpy(n, m->face_n + 3 * (m->dead[lo] ? hi : lo), sizeof n);
    memcpy(m->edge_n + 9 * t + 3 * e, n, sizeof n);
}

/* Angle-weighted vertex pseudonormals: sum over incident live faces of the face normal
 * times the face's angle at the vertex. */
static void vertex_normals(sw_mesh *m) {
    memset(m->vert_n, 0, sizeof(double) * 3 * m->nverts);
    for (uint32_t t = 0; t < m->ntris; ++t)
        for (int k = 0; k < 3 && !m->dead[t]; ++k) {
            const uint32_t *v = m->tris + 3 * t;
            double e0[3], e1[3];
            sw_v3_sub(m->X + 3 * v[(k + 1) % 3], m->X + 3 * v[k], e0);
            sw_v3_sub(m->X + 3 * v[(k + 2) % 3], m->X + 3 * v[k], e1);
            double x[3];
            sw_v3_cross(e0, e1, x);
            double angle = atan2(sw_v3_norm(x), sw_v3_dot(e0, e1));
            for (int i = 0; i < 3; ++i)
                m->vert_n[3 * v[k] + i] += angle * m->face_n[3 * t + i];
        }
    for (uint32_t i = 0; i < m->nverts; ++i)
        sw_v3_normalize(m->vert_n + 3 * i); /* unused vertices stay zero, never queried */
}

void sw_mesh_feature_normals(sw_mesh *m) {
    for (uint32_t t = 0; t < m->ntris; ++t)
        for (uint32_t e = 0; e < 3; ++e)
            edge_normal(m, t, e);
    vertex_normals(m);
}

/* The new vertices into Embree's own buffer, and the BVH refitted: the first move
 * switches the scene from the add's high-quality build to a dynamic one whose geometry
 * refits (the triangles stay, so the tree's topology stays valid; docs/notes/world.md
 * has the costs). Queries cull with the tree and pick the closest triangle exactly, so
 * its quality changes their cost, never their answer. */
static sinew_result refit(sinew_world *w, sw_mesh *m) {
    rtcGetDeviceError(w->device); /* clear an earlier error */
    for (size_t i = 0; i < (size_t)3 * m->nverts; ++i)
        m->vb[i] = (float)m->X[i];
    if (!m->refits) {
        rtcSetSceneFlags(m->scene, RTC_SCENE_FLAG_DYNAMIC);
        rtcSetSceneBuildQuality(m->scene, RTC_BUILD_QUALITY_LOW);
        rtcSetGeometryBuildQuality(m->geom, RTC_BUILD_QUALITY_REFIT);
        m->refits = 1;
    }
    rtcUpdateGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(m->geom);
    rtcCommitScene(m->scene);
    enum RTCError e = rtcGetDeviceError(w->device);
    if (e == RTC_ERROR_NONE) return SINEW_OK;
    return sw_world_fail(
        w, e == RTC_ERROR_OUT_OF_MEMORY ? SINEW_ERROR_OUT_OF_MEMORY : SINEW_ERROR_INVALID_ARGUMENT,
        "sinew_world_set_mesh_vertices: Embree failed to refit (error %d)", (int)e);
}

sinew_result sw_mesh_move(sinew_world *w, sw_collider *c, const float *xyz) {
    sw_mesh *m = &c->mesh;
    for (size_t i = 0; i < (size_t)3 * m->nverts; ++i)
        m->X[i] = xyz[i];
    m->moves++; /* X changed even if the refit below fails */
    sw_mesh_bounds(c);
    sw_mesh_face_normals(m);
    sw_mesh_feature_normals(m);
    double R[9], t[3];
    memcpy(R, c->R, sizeof R);
    memcpy(t, c->t, sizeof t);
    sw_collider_place(c, R, t); /* the world box from the new local box */
    return refit(w, m);
}
