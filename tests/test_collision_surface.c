/* The collision surface's sheets (blob_collision.h): a boundary that is manifold comes
 * back as it is; two tets that touch along an edge, or at a vertex only, are split into
 * one closed sheet each, which the world takes as a mesh collider where it refuses the
 * boundary as it was; every edge then joins two triangles run opposite ways. */
#include "blob_collision.h"
#include "sinew/sinew_world.h"
#include "sw_test.h"

/* The four faces of tet (a, b, c, d) with corners 0..3 at p0..p3, facing out. */
static void tet_faces(int32_t a, int32_t b, int32_t c, int32_t d, int32_t *f) {
    const int32_t t[12] = {a, c, b, a, b, d, a, d, c, b, c, d};
    memcpy(f, t, sizeof t);
}

/* A view holding only the boundary the build reads. */
static sw_blob_view boundary(int32_t nverts, int32_t ntris, int32_t *tris) {
    sw_blob_view v;
    memset(&v, 0, sizeof v);
    v.nsurf_verts = nverts;
    v.nsurf_tris = ntris;
    v.surf_tris = tris;
    return v;
}

/* Each undirected edge's uses: 2 for all, run opposite ways. */
static int every_edge_twice(const sw_coll_surface *cs) {
    for (int32_t i = 0; i < 3 * cs->ntris; ++i) {
        int32_t a = cs->tris[i], b = cs->tris[i - i % 3 + (i % 3 + 1) % 3], same = 0, back = 0;
        for (int32_t j = 0; j < 3 * cs->ntris; ++j) {
            int32_t c = cs->tris[j], d = cs->tris[j - j % 3 + (j % 3 + 1) % 3];
            same += c == a && d == b;
            back += c == b && d == a;
        }
        if (same != 1 || back != 1) return 0;
    }
    return 1;
}

/* Whether a world takes triangles `tris` over points x (float) as a mesh collider. */
static sinew_result world_takes(const float *x, int32_t nv, const int32_t *tris, int32_t nt) {
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, &w) != SINEW_OK) return SINEW_ERROR_OUT_OF_MEMORY;
    uint32_t *idx = malloc(sizeof(uint32_t) * 3 * (size_t)nt);
    for (int32_t i = 0; i < 3 * nt; ++i)
        idx[i] = (uint32_t)tris[i];
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_MESH;
    c.vertices = x;
    c.vertex_count = (uint32_t)nv;
    c.indices = idx;
    c.triangle_count = (uint32_t)nt;
    sinew_collider_id id;
    sinew_result r = sinew_world_add_collider(w, &c, &id);
    free(idx);
    sinew_world_destroy(w);
    return r;
}

TEST(a_manifold_boundary_comes_back_unchanged) {
    int32_t tris[12];
    tet_faces(0, 1, 2, 3, tris);
    sw_blob_view v = boundary(4, 4, tris);
    sinew_allocator al = sinew_allocator_default();
    sw_coll_surface cs;
    ENSURE(sw_coll_surface_build(&v, &al, &cs) == SINEW_OK);
    ENSURE(cs.nverts == 4 && cs.ntris == 4);
    for (int32_t i = 0; i < 4; ++i)
        ENSURE(cs.vert[i] == i);
    ENSURE(memcmp(cs.tris, tris, sizeof tris) == 0);
    ENSURE(every_edge_twice(&cs));
    sw_coll_surface_free(&al, &cs);
}

/* Points: tet A on 0..3, tet B on 0, 1 (the shared edge) and 4, 5 across it, or on 0 (the
 * shared vertex) and 6..8. */
static const float pts[27] = {0, 0, 0,  0, 0,  1,  1,  0,  0,  0,  1,  0,  -1, 0,
                              0, 0, -1, 0, -1, -1, -1, -2, -1, -1, -1, -2, -1};

TEST(tets_touching_along_an_edge_become_two_closed_sheets) {
    int32_t tris[24];
    tet_faces(0, 1, 2, 3, tris);
    tet_faces(1, 0, 4, 5, tris + 12); /* edge 0-1 shared: four faces on it */
    sinew_allocator al = sinew_allocator_default();
    ENSURE(world_takes(pts, 6, tris, 8) == SINEW_ERROR_DEGENERATE); /* as it was */
    sw_blob_view v = boundary(6, 8, tris);
    sw_coll_surface cs;
    ENSURE(sw_coll_surface_build(&v, &al, &cs) == SINEW_OK);
    ENSUREF(cs.nverts == 8, "%d vertices (6 and the two ends of the edge again)", cs.nverts);
    ENSURE(cs.vert[6] == 0 || cs.vert[6] == 1);
    ENSURE(cs.vert[7] == 0 || cs.vert[7] == 1);
    ENSURE(cs.vert[6] != cs.vert[7]);
    for (int32_t i = 0; i < 24; ++i) /* the same corners, some on the copies */
        ENSURE(cs.vert[cs.tris[i]] == tris[i]);
    ENSURE(every_edge_twice(&cs));
    float x[24];
    for (int32_t i = 0; i < cs.nverts; ++i)
        memcpy(x + 3 * i, pts + 3 * cs.vert[i], 3 * sizeof(float));
    ENSURE(world_takes(x, cs.nverts, cs.tris, cs.ntris) == SINEW_OK);
    sw_coll_surface_free(&al, &cs);
}

TEST(tets_touching_at_a_vertex_become_two_sheets) {
    int32_t tris[24];
    tet_faces(0, 1, 2, 3, tris);
    tet_faces(0, 6, 7, 8, tris + 12);
    sinew_allocator al = sinew_allocator_default();
    sw_blob_view v = boundary(9, 8, tris);
    sw_coll_surface cs;
    ENSURE(sw_coll_surface_build(&v, &al, &cs) == SINEW_OK);
    ENSUREF(cs.nverts == 10 && cs.vert[9] == 0, "%d vertices", cs.nverts);
    ENSURE(every_edge_twice(&cs));
    sw_coll_surface_free(&al, &cs);
}

SW_TEST_MAIN(CASE(a_manifold_boundary_comes_back_unchanged),
             CASE(tets_touching_along_an_edge_become_two_closed_sheets),
             CASE(tets_touching_at_a_vertex_become_two_sheets))
