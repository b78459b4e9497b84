/* A mesh collider's add-time work (mesh.c queries it): validation of the def's
 * triangles, the edge map that proves them edge-manifold and consistently oriented (kept
 * as each edge's twin), the pseudonormals (mesh_update.c, which also moves the mesh), and
 * the Embree scene, committed here and at each move, only read by queries. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "collision_internal.h"

/* One triangle's directed edge, keyed by its undirected vertex pair. */
typedef struct edge_use {
    uint32_t lo, hi; /* vertex ids, lo < hi */
    uint32_t tri;
    uint8_t e;       /* edge e runs from corner e to corner e + 1 */
    uint8_t forward; /* whether it runs lo -> hi */
} edge_use;

static int edge_cmp(const void *pa, const void *pb) {
    const edge_use *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->tri < b->tri ? -1 : a->tri > b->tri;
}

static const char *add_fail_prefix = "sinew_world_add_collider: mesh";

/* Counts, pointers, finite vertices of sane magnitude, indices in range. */
static sinew_result check_arrays(sinew_world *w, const sinew_collider_def *d) {
    if (!d->vertices || !d->indices || d->triangle_count < 1 ||
        d->triangle_count > SW_MESH_MAX_TRIANGLES || d->vertex_count < 3 ||
        d->vertex_count > SW_MESH_MAX_VERTICES)
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s needs vertices and indices, 1 to 2^24 triangles and 3 to 3*2^24 "
                             "vertices (got %u triangles, %u vertices)",
                             add_fail_prefix, (unsigned)d->triangle_count,
                             (unsigned)d->vertex_count);
    for (uint32_t i = 0; i < 3 * d->vertex_count; ++i) {
        double x = d->vertices[i];
        if (!isfinite(x))
            return sw_world_fail(w, SINEW_ERROR_NOT_FINITE, "%s vertex %u is not finite",
                                 add_fail_prefix, (unsigned)(i / 3));
        if (!(fabs(x) <= SW_COLLIDER_MAX_SIZE))
            return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT, "%s vertex %u is beyond 1e15",
                                 add_fail_prefix, (unsigned)(i / 3));
    }
    for (uint32_t i = 0; i < 3 * d->triangle_count; ++i)
        if (d->indices[i] >= d->vertex_count)
            return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                                 "%s triangle %u has vertex index %u, not below %u",
                                 add_fail_prefix, (unsigned)(i / 3), (unsigned)d->indices[i],
                                 (unsigned)d->vertex_count);
    return SINEW_OK;
}

/* Unit face normals (mesh_update.c): a triangle whose area is below 1e-12 of its longest
 * edge squared (a repeated vertex, collinear corners) is degenerate at add time. */
static sinew_result face_normals(sinew_world *w, sw_mesh *m) {
    if (sw_mesh_face_normals(m) == 0) return SINEW_OK;
    uint32_t t = 0;
    while (!m->dead[t])
        ++t;
    const uint32_t *v = m->tris + 3 * t;
    return sw_world_fail(w, SINEW_ERROR_DEGENERATE, "%s triangle %u (%u %u %u) has zero area",
                         add_fail_prefix, (unsigned)t, (unsigned)v[0], (unsigned)v[1],
                         (unsigned)v[2]);
}

/* The two uses of an undirected edge as each other's twin (one use: a boundary edge). */
static void edge_twins(sw_mesh *m, const edge_use *g, size_t k) {
    for (size_t j = 0; j < k; ++j)
        m->twin[3 * g[j].tri + g[j].e] = k == 2 ? 3 * g[1 - j].tri + g[1 - j].e : UINT32_MAX;
}

/* Sorts the 3 * ntris edge uses by vertex pair: more than two uses of a pair, or two
 * running the same way (the faces disagree on which side is out), is degenerate. */
static sinew_result edges(sinew_world *w, sw_mesh *m) {
    size_t ne = (size_t)3 * m->ntris;
    edge_use *u = sw_alloc(&w->allocator, sizeof(edge_use) * ne, SW_ALLOC_ALIGN);
    if (!u)
        return sw_world_fail(w, SINEW_ERROR_OUT_OF_MEMORY, "%s: no memory for its %zu edges",
                             add_fail_prefix, ne);
    for (uint32_t t = 0; t < m->ntris; ++t)
        for (uint8_t e = 0; e < 3; ++e) {
            uint32_t a = m->tris[3 * t + e], b = m->tris[3 * t + (e + 1) % 3];
            edge_use x = {a < b ? a : b, a < b ? b : a, t, e, (uint8_t)(a < b)};
            u[3 * (size_t)t + e] = x;
        }
    qsort(u, ne, sizeof *u, edge_cmp);
    sinew_result r = SINEW_OK;
    for (size_t i = 0, j; i < ne && r == SINEW_OK; i = j) {
        for (j = i + 1; j < ne && u[j].lo == u[i].lo && u[j].hi == u[i].hi;)
            ++j;
        if (j - i > 2)
            r = sw_world_fail(w, SINEW_ERROR_DEGENERATE,
                              "%s edge (%u, %u) is shared by %zu triangles (at most 2: not "
                              "edge-manifold)",
                              add_fail_prefix, (unsigned)u[i].lo, (unsigned)u[i].hi, j - i);
        else if (j - i == 2 && u[i].forward == u[i + 1].forward)
            r = sw_world_fail(w, SINEW_ERROR_DEGENERATE,
                              "%s triangles %u and %u run edge (%u, %u) the same way "
                              "(inconsistently oriented)",
                              add_fail_prefix, (unsigned)u[i].tri, (unsigned)u[i + 1].tri,
                              (unsigned)u[i].lo, (unsigned)u[i].hi);
        else
            edge_twins(m, u + i, j - i);
    }
    sw_free(&w->allocator, u);
    return r;
}

/* Embree's result as ours (its error callback has logged the details). */
static sinew_result embree_result(sinew_world *w, const char *what) {
    enum RTCError e = rtcGetDeviceError(w->device);
    sinew_result r = e == RTC_ERROR_OUT_OF_MEMORY     ? SINEW_ERROR_OUT_OF_MEMORY
                     : e == RTC_ERROR_UNSUPPORTED_CPU ? SINEW_ERROR_UNSUPPORTED
                                                      : SINEW_ERROR_INVALID_ARGUMENT;
    return sw_world_fail(w, r, "%s: Embree failed to %s (error %d)", add_fail_prefix, what, (int)e);
}

/* A triangle geometry in float (Embree's own buffers) in a new scene, committed. */
static sinew_result build_scene(sinew_world *w, sw_mesh *m) {
    rtcGetDeviceError(w->device); /* clear an earlier error */
    m->scene = rtcNewScene(w->device);
    RTCGeometry g = rtcNewGeometry(w->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!m->scene || !g) {
        if (g) rtcReleaseGeometry(g);
        return embree_result(w, "create a scene");
    }
    rtcSetSceneBuildQuality(m->scene, RTC_BUILD_QUALITY_HIGH);
    m->geom = g; /* kept for moves (sinew_world_set_mesh_vertices) */
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), m->nverts);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), m->ntris);
    if (!vb || !ib) return embree_result(w, "allocate its buffers");
    m->vb = vb;
    for (size_t i = 0; i < (size_t)3 * m->nverts; ++i)
        vb[i] = (float)m->X[i];
    for (size_t i = 0; i < (size_t)3 * m->ntris; ++i)
        ib[i] = m->tris[i];
    rtcCommitGeometry(g);
    rtcAttachGeometry(m->scene, g);
    rtcCommitScene(m->scene);
    if (rtcGetDeviceError(w->device) != RTC_ERROR_NONE) return embree_result(w, "build its BVH");
    return SINEW_OK;
}

/* The copies and normals arrays of m (nverts, ntris set). */
static sinew_result alloc_arrays(sinew_world *w, sw_mesh *m) {
    const sinew_allocator *a = &w->allocator;
    m->X = sw_alloc(a, sizeof(double) * 3 * m->nverts, SW_ALLOC_ALIGN);
    m->vert_n = sw_alloc(a, sizeof(double) * 3 * m->nverts, SW_ALLOC_ALIGN);
    m->tris = sw_alloc(a, sizeof(uint32_t) * 3 * (size_t)m->ntris, SW_ALLOC_ALIGN);
    m->face_n = sw_alloc(a, sizeof(double) * 3 * (size_t)m->ntris, SW_ALLOC_ALIGN);
    m->edge_n = sw_alloc(a, sizeof(double) * 9 * (size_t)m->ntris, SW_ALLOC_ALIGN);
    m->twin = sw_alloc(a, sizeof(uint32_t) * 3 * (size_t)m->ntris, SW_ALLOC_ALIGN);
    m->dead = sw_alloc(a, m->ntris, SW_ALLOC_ALIGN);
    if (m->X && m->vert_n && m->tris && m->face_n && m->edge_n && m->twin && m->dead)
        return SINEW_OK;
    return sw_world_fail(w, SINEW_ERROR_OUT_OF_MEMORY, "%s: no memory for %u triangles",
                         add_fail_prefix, (unsigned)m->ntris);
}

sinew_result sw_mesh_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    sinew_result r = check_arrays(w, d);
    if (r != SINEW_OK) return r;
    sw_mesh *m = &c->mesh;
    m->nverts = d->vertex_count;
    m->ntris = d->triangle_count;
    if ((r = alloc_arrays(w, m)) == SINEW_OK) {
        for (size_t i = 0; i < (size_t)3 * m->nverts; ++i)
            m->X[i] = d->vertices[i];
        memcpy(m->tris, d->indices, sizeof(uint32_t) * 3 * (size_t)m->ntris);
        sw_mesh_bounds(c);
    }
    if (r == SINEW_OK) r = face_normals(w, m);
    if (r == SINEW_OK) r = edges(w, m);
    if (r == SINEW_OK) sw_mesh_feature_normals(m);
    if (r == SINEW_OK) r = build_scene(w, m);
    if (r != SINEW_OK) sw_mesh_release(w, c);
    return r;
}

void sw_mesh_release(sinew_world *w, sw_collider *c) {
    sw_mesh *m = &c->mesh;
    if (m->geom) rtcReleaseGeometry(m->geom);
    if (m->scene) rtcReleaseScene(m->scene);
    const sinew_allocator *a = &w->allocator;
    sw_free(a, m->X);
    sw_free(a, m->tris);
    sw_free(a, m->face_n);
    sw_free(a, m->edge_n);
    sw_free(a, m->vert_n);
    sw_free(a, m->twin);
    sw_free(a, m->dead);
    memset(m, 0, sizeof *m);
}
