/* The query's real-time contract (collision.h): 10,000 queries of every shape (plane,
 * sphere, capsule, box, libccd MPR hull, Embree mesh) allocate nothing and lock nothing,
 * counted by the interposer (tools/testkit/rt_interpose.h) after a warm-up. */
#include "sw_test.h"

#include "collision_ref.h"
#include "rt_interpose.h"

/* A closed octahedron mesh and its 6 corners as a hull. */
static const float octa_v[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
static const uint32_t octa_ix[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                                     2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};

static int add_all(sinew_world *w) {
    sinew_collider_def d = sinew_collider_def_default();
    sinew_collider_id id;
    int ok = sinew_world_add_collider(w, &d, &id) == SINEW_OK;
    d.shape = SINEW_SHAPE_SPHERE;
    d.radius = 0.7f;
    d.half_height = 0.5f;
    d.half_extents[0] = d.half_extents[1] = d.half_extents[2] = 0.6f;
    d.points = octa_v;
    d.point_count = 6;
    d.vertices = octa_v;
    d.vertex_count = 6;
    d.indices = octa_ix;
    d.triangle_count = 8;
    sinew_shape s[5] = {SINEW_SHAPE_SPHERE, SINEW_SHAPE_CAPSULE, SINEW_SHAPE_BOX, SINEW_SHAPE_HULL,
                        SINEW_SHAPE_MESH};
    for (int k = 0; k < 5; ++k) {
        d.shape = s[k];
        d.transform = random_transform();
        d.transform.position[0] = d.transform.position[1] = d.transform.position[2] = 0;
        ok &= sinew_world_add_collider(w, &d, &id) == SINEW_OK;
    }
    return ok;
}

/* Every collider, `n` points in [-1.5, 1.5]^3; returns the hits. */
static long query_all(const sinew_world *w, int n) {
    long hits = 0;
    for (uint32_t s = 0; s < sw_world_slot_count(w); ++s) {
        const sw_collider *c = sw_world_slot(w, s);
        for (int k = 0; k < n; ++k) {
            double x[3] = {1.5 * srand1(), 1.5 * srand1(), 1.5 * srand1()};
            sw_collider_hit h;
            hits += sw_collider_query(c, x, 0.25, &h);
        }
    }
    return hits;
}

TEST(queries_allocate_and_lock_nothing) {
    int active = sw_rt_interpose_active(); /* outside the counted section */
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    ENSURE(add_all(w) && sinew_world_collider_count(w) == 6);
    ENSURE(query_all(w, 100) > 0); /* warm-up */
    sw_rt_count_begin();
    long hits = query_all(w, 10000);
    sw_rt_counts c = sw_rt_count_end();
    char buf[512];
    fprintf(stderr, "    6 x 10000 queries (%ld hits): %s\n", hits,
            sw_rt_counts_describe(&c, buf, sizeof buf));
    ENSURE(hits > 0);
    if (active & SW_RT_CAT_ALLOCS) ENSUREF(c.allocs == 0, "%s", buf);
    if (active & SW_RT_CAT_FREES) ENSUREF(c.frees == 0, "%s", buf);
    if (active & SW_RT_CAT_MAPS) ENSUREF(c.maps == 0, "%s", buf);
    if (active & SW_RT_CAT_LOCKS) ENSUREF(c.locks == 0, "%s", buf);
    if (!(active & SW_RT_CAT_LOCKS)) fprintf(stderr, "    (locks not observable in this build)\n");
    sinew_world_destroy(w);
}

SW_TEST_MAIN(CASE(queries_allocate_and_lock_nothing))
