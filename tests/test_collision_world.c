/* The world's bookkeeping and every error path of sinew_world.h: ids with generations
 * (a removed id stays invalid after its slot is reused), capacity, the host allocator
 * (every byte back at destroy), and each bad def rejected with its result code and a
 * logged message of the right id, the world unchanged. */
#include "sw_test.h"

#include "collision_ref.h"

static uint32_t last_id;
static int logged;
static char last_msg[512];

static void on_log(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    (void)level;
    (void)user;
    last_id = id;
    logged++;
    snprintf(last_msg, sizeof last_msg, "%s", msg);
}

static long live_allocs;
static void *count_alloc(size_t size, size_t align, void *user) {
    (void)user;
    void *p = NULL;
    if (posix_memalign(&p, align, size) != 0) return NULL;
    live_allocs++;
    return p;
}
static void count_free(void *p, void *user) {
    (void)user;
    if (p) live_allocs--;
    free(p);
}

static sinew_world *make(uint32_t cap) {
    sinew_world_def wd = sinew_world_def_default();
    wd.max_colliders = cap;
    wd.logger.log = on_log;
    wd.allocator.alloc = count_alloc;
    wd.allocator.free = count_free;
    sinew_world *w = NULL;
    return sinew_world_create(&wd, &w) == SINEW_OK ? w : NULL;
}

static const float tet_pts[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t tet_ix[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

static sinew_collider_def sphere(void) {
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_SPHERE;
    d.radius = 1;
    return d;
}

/* add_collider must fail with `code`, log `msg_id`, and leave the world unchanged. */
static int rejects(sinew_world *w, const sinew_collider_def *d, sinew_result code,
                   uint32_t msg_id) {
    uint32_t before = sinew_world_collider_count(w);
    sinew_collider_id id = 12345;
    logged = 0;
    sinew_result r = sinew_world_add_collider(w, d, &id);
    if (r != code || logged != 1 || last_id != msg_id || id != 12345 ||
        sinew_world_collider_count(w) != before) {
        fprintf(stderr, "    got %d (want %d), logged %d id 0x%x: %s\n", (int)r, (int)code, logged,
                (unsigned)last_id, last_msg);
        return 0;
    }
    fprintf(stderr, "    rejected (%d): %s\n", (int)r, last_msg);
    return 1;
}

TEST(ids_generations_and_capacity) {
    sinew_world *w = make(2);
    ENSURE(w);
    sinew_collider_def d = sphere();
    sinew_collider_id a, b, c;
    ENSURE(sinew_world_add_collider(w, &d, &a) == SINEW_OK && a != 0);
    ENSURE(sinew_world_add_collider(w, &d, &b) == SINEW_OK && b != 0 && b != a);
    ENSURE(rejects(w, &d, SINEW_ERROR_CAPACITY, SINEW_MSG_WORLD_CAPACITY));
    ENSURE(sinew_world_collider_count(w) == 2 && sw_world_slot_count(w) == 2);
    ENSURE(sinew_world_remove_collider(w, a) == SINEW_OK);
    ENSURE(sinew_world_collider_count(w) == 1 && sw_world_slot(w, 0) == NULL);
    ENSURE(sinew_world_add_collider(w, &d, &c) == SINEW_OK && c != a); /* slot reused */
    ENSURE(sw_world_slot_of(w, c) == 0 && sw_world_slot_of(w, a) == -1);
    ENSURE(sw_collider_id_of(w, 0) == c && sw_collider_id_of(w, 1) == b);
    logged = 0;
    ENSURE(sinew_world_remove_collider(w, a) == SINEW_ERROR_INVALID_ARGUMENT && logged == 1);
    sinew_transform t = sinew_transform_identity();
    ENSURE(sinew_world_set_collider_transform(w, a, &t) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_remove_collider(w, 0) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_remove_collider(w, 0xFFFFFFFFu) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_collider_transform(w, c, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    const sw_collider *col = sw_world_slot(w, 1);
    ENSURE(col && sw_collider_stiffness(col) == 0 && sw_collider_friction(col) == 0);
    sinew_world_destroy(w);
    ENSURE(live_allocs == 0);
}

TEST(null_arguments) {
    sinew_world *w = make(4);
    ENSURE(w);
    sinew_collider_def d = sphere();
    sinew_collider_id id;
    ENSURE(sinew_world_create(NULL, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_add_collider(NULL, &d, &id) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_add_collider(w, NULL, &id) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_add_collider(w, &d, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_remove_collider(NULL, 1) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_collider_transform(NULL, 1, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_collider_count(NULL) == 0);
    sinew_world_destroy(NULL);
    sinew_world_def bad = sinew_world_def_default();
    sinew_world *w2 = NULL;
    bad.max_colliders = 70000;
    ENSURE(sinew_world_create(&bad, &w2) == SINEW_ERROR_INVALID_ARGUMENT && !w2);
    bad = sinew_world_def_default();
    bad.allocator.alloc = count_alloc; /* free missing */
    ENSURE(sinew_world_create(&bad, &w2) == SINEW_ERROR_INVALID_ARGUMENT && !w2);
    bad = sinew_world_def_default();
    bad.struct_size = 2;
    ENSURE(sinew_world_create(&bad, &w2) == SINEW_ERROR_INVALID_ARGUMENT && !w2);
    ENSURE(sinew_world_create(NULL, &w2) == SINEW_OK && w2); /* NULL def: the defaults */
    sinew_world_destroy(w2);
    sinew_world_destroy(w);
    ENSURE(live_allocs == 0);
}

TEST(bad_transforms_and_sizes) {
    sinew_world *w = make(4);
    ENSURE(w);
    sinew_collider_def d = sphere();
    d.transform.position[1] = NAN;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d = sphere();
    d.transform.rotation[2] = INFINITY;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d = sphere();
    d.transform.rotation[0] = 0;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    float sizes[4] = {0, -1, 2e15f, NAN};
    sinew_result want[4] = {SINEW_ERROR_INVALID_ARGUMENT, SINEW_ERROR_INVALID_ARGUMENT,
                            SINEW_ERROR_INVALID_ARGUMENT, SINEW_ERROR_NOT_FINITE};
    for (int k = 0; k < 4; ++k) {
        d = sphere();
        d.radius = sizes[k];
        ENSURE(rejects(w, &d, want[k], SINEW_MSG_WORLD_INVALID_ARGUMENT));
        d.shape = SINEW_SHAPE_CAPSULE;
        ENSURE(rejects(w, &d, want[k], SINEW_MSG_WORLD_INVALID_ARGUMENT));
        d.radius = 1;
        d.half_height = sizes[k];
        if (k > 0) ENSURE(rejects(w, &d, want[k], SINEW_MSG_WORLD_INVALID_ARGUMENT));
        d.shape = SINEW_SHAPE_BOX;
        d.half_extents[0] = d.half_extents[1] = 1;
        d.half_extents[2] = sizes[k];
        ENSURE(rejects(w, &d, want[k], SINEW_MSG_WORLD_INVALID_ARGUMENT));
    }
    d = sinew_collider_def_default();
    d.normal[0] = d.normal[1] = d.normal[2] = 0;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.normal[1] = NAN;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d = sphere();
    d.shape = (sinew_shape)17;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d = sphere();
    d.friction = -1;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.friction = NAN;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    /* set_transform keeps the old transform on a bad one. */
    d = sphere();
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &d, &id) == SINEW_OK);
    sinew_transform t = sinew_transform_identity();
    t.position[0] = 3;
    ENSURE(sinew_world_set_collider_transform(w, id, &t) == SINEW_OK);
    t.position[0] = NAN;
    ENSURE(sinew_world_set_collider_transform(w, id, &t) == SINEW_ERROR_NOT_FINITE);
    t.position[0] = 0;
    t.rotation[0] = 0;
    ENSURE(sinew_world_set_collider_transform(w, id, &t) == SINEW_ERROR_INVALID_ARGUMENT);
    double R[9], tt[3];
    sw_collider_transform(sw_world_slot(w, 0), R, tt);
    ENSURE(tt[0] == 3 && R[0] == 1);
    /* in doubles: kept as given (no float between), bad ones refused alike */
    const double far[3] = {1e5 + 1e-6, -2.5e-9, 0}, turn[4] = {1, 0, 0, 0};
    ENSURE(sinew_world_set_collider_transform_d(w, id, far, turn) == SINEW_OK);
    sw_collider_transform(sw_world_slot(w, 0), R, tt);
    ENSURE(tt[0] == far[0] && tt[1] == far[1] && R[0] == 1);
    double pos[3], rot[4];
    sw_collider_placement(sw_world_slot(w, 0), pos, rot);
    ENSURE(pos[0] == far[0] && rot[0] == 1);
    const double bad_pos[3] = {0, NAN, 0}, zero[4] = {0, 0, 0, 0};
    ENSURE(sinew_world_set_collider_transform_d(w, id, bad_pos, turn) == SINEW_ERROR_NOT_FINITE);
    ENSURE(sinew_world_set_collider_transform_d(w, id, far, zero) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_collider_transform_d(w, id, NULL, turn) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_collider_transform_d(w, 12345, far, turn) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    sw_collider_transform(sw_world_slot(w, 0), R, tt);
    ENSURE(tt[0] == far[0]); /* the refused ones left it */
    sinew_world_destroy(w);
    ENSURE(live_allocs == 0);
}

TEST(bad_hulls) {
    sinew_world *w = make(4);
    ENSURE(w);
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_HULL;
    d.points = tet_pts;
    d.point_count = 3;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.point_count = 5000;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.point_count = 4;
    d.points = NULL;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    float flat[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1e-7f, 0.5f, 0.5f, -1e-7f};
    d.points = flat;
    d.point_count = 5;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    float line[12] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
    d.points = line;
    d.point_count = 4;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    float same[12] = {1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3};
    d.points = same;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    float nan[12] = {0, 0, 0, 1, 0, 0, 0, NAN, 0, 0, 0, 1};
    d.points = nan;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    float huge[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1e16f};
    d.points = huge;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    /* A tiny but real tetrahedron is accepted: flatness is relative to the hull's size. */
    float tiny[12] = {0, 0, 0, 1e-6f, 0, 0, 0, 1e-6f, 0, 0, 0, 1e-6f};
    d.points = tiny;
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &d, &id) == SINEW_OK);
    sinew_world_destroy(w);
    ENSURE(live_allocs == 0);
}

TEST(bad_meshes) {
    sinew_world *w = make(4);
    ENSURE(w);
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_MESH;
    d.vertices = tet_pts;
    d.vertex_count = 4;
    d.indices = tet_ix;
    d.triangle_count = 0;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.triangle_count = 4;
    d.indices = NULL;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    uint32_t out_of_range[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 4};
    d.indices = out_of_range;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    uint32_t zero_area[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 1, 3};
    d.indices = zero_area;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    float collinear[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 0, 0};
    uint32_t sliver[3] = {0, 1, 4};
    d.vertices = collinear;
    d.vertex_count = 5;
    d.indices = sliver;
    d.triangle_count = 1;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    /* Three triangles on the edge (0, 1). */
    uint32_t fan[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    float fanv[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0.5f};
    d.vertices = fanv;
    d.indices = fan;
    d.triangle_count = 3;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    /* Two triangles running their shared edge the same way. */
    uint32_t flipped[6] = {0, 1, 2, 0, 1, 3};
    d.indices = flipped;
    d.triangle_count = 2;
    ENSURE(rejects(w, &d, SINEW_ERROR_DEGENERATE, SINEW_MSG_WORLD_DEGENERATE));
    float nanv[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, INFINITY};
    d.vertices = nanv;
    d.vertex_count = 4;
    d.indices = tet_ix;
    d.triangle_count = 4;
    ENSURE(rejects(w, &d, SINEW_ERROR_NOT_FINITE, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    d.vertices = tet_pts;
    d.triangle_count = (1u << 24) + 1;
    ENSURE(rejects(w, &d, SINEW_ERROR_INVALID_ARGUMENT, SINEW_MSG_WORLD_INVALID_ARGUMENT));
    /* The good tetrahedron: inside, outside, and on an edge. */
    d.triangle_count = 4;
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &d, &id) == SINEW_OK);
    const sw_collider *c = sw_world_slot(w, (uint32_t)sw_world_slot_of(w, id));
    double in[3] = {0.1, 0.1, 0.1}, out[3] = {-0.2, 0.3, 0.3}, edge[3] = {0.5, 0.5, 0};
    sw_collider_hit h;
    ENSURE(sw_collider_query(c, in, 0.5, &h) && fabs(h.phi + 0.1) < 1e-12);
    ENSURE(sw_collider_query(c, out, 0.5, &h) && fabs(h.phi - 0.2) < 1e-12 && h.normal[0] == -1);
    ENSURE(sw_collider_query(c, edge, 0.5, &h) && fabs(h.phi) < 1e-12 && isfinite(h.normal[0]));
    ENSURE(fabs(ref_dot(h.normal, h.normal) - 1) < 1e-12);
    ENSURE(!sw_collider_query(c, out, 0.1, &h));
    sinew_world_destroy(w);
    ENSURE(live_allocs == 0);
}

SW_TEST_MAIN(CASE(ids_generations_and_capacity), CASE(null_arguments),
             CASE(bad_transforms_and_sizes), CASE(bad_hulls), CASE(bad_meshes))
