/* Mesh colliders whose vertices move (sinew_world_set_mesh_vertices) and instances that
 * ignore one collider (sinew_instance_ignore_collider): a moved mesh is queried where it
 * is now, exactly as a mesh added fresh there; an ignored collider gives no contact; two
 * fingers, each one's surface a collider of one shared world that the other touches,
 * push each other apart; the steps with deforming meshes allocate and lock nothing; the
 * error paths keep the old vertices. */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <time.h>

#include "bake_fixture.h"
#include "collision.h"
#include "rt_interpose.h"
#include "sinew/sinew_world.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

/* The finger (along +x from 0 to 3.6, radius 0.45 at the root) at about 1000 tets. */
static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 1000, 8, 0);
    return fx_ok ? &fx : NULL;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The bind pose moved by (dx, dy, 0): every bone's transform is a translation. */
static void moved_rest_pose(int nb, float dx, float dy, float *p) {
    memset(p, 0, sizeof(float) * 12 * (size_t)nb);
    for (int b = 0; b < nb; ++b) {
        p[12 * b] = p[12 * b + 4] = p[12 * b + 8] = 1;
        p[12 * b + 9] = dx;
        p[12 * b + 10] = dy;
    }
}

/* A closed box [lo, hi], its 12 triangles counter-clockwise seen from outside. */
static const uint32_t box_tris[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                      2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};

static void box_vertices(const float lo[3], const float hi[3], float v[24]) {
    for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 3; ++k)
            v[3 * j + k] = (j >> k) & 1 ? hi[k] : lo[k];
}

/* The box under the finger as the world tests' table (top face at y = -0.39, 0.05 into
 * the flesh), sheared and turned a little so that its normals differ from the add's. */
static void table_vertices(float dy, float v[24]) {
    static const float lo[3] = {-0.7f, -0.79f, -1}, hi[3] = {4.3f, -0.39f, 1};
    box_vertices(lo, hi, v);
    for (int j = 0; j < 8; ++j) {
        v[3 * j + 1] += dy + 0.01f * v[3 * j]; /* a slope of 1/100 along x */
        v[3 * j + 2] += 0.05f * v[3 * j + 1];  /* a shear of z along y */
    }
}

static int add_mesh(sinew_world *w, const float *v, uint32_t nv, const uint32_t *t, uint32_t nt,
                    sinew_collider_id *id) {
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_MESH;
    c.vertices = v;
    c.vertex_count = nv;
    c.indices = t;
    c.triangle_count = nt;
    return sinew_world_add_collider(w, &c, id) == SINEW_OK;
}

static sinew_world *new_world(void) {
    sinew_world *w = NULL;
    sinew_world_def wd = sinew_world_def_default();
    return sinew_world_create(&wd, &w) == SINEW_OK ? w : NULL;
}

/* Steps `inst` `steps` times at the bind pose; its world contacts in the last step and
 * the force on collider id. */
static uint32_t press(sinew_instance *inst, int nb, int steps, sinew_collider_id id, float F[3]) {
    float *pose = malloc(sizeof(float) * 12 * (size_t)nb), M[3];
    moved_rest_pose(nb, 0, 0, pose);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    st.world_contacts = UINT32_MAX;
    for (int s = 0; s < steps; ++s) {
        sinew_instance_set_pose(inst, pose, (uint32_t)nb);
        sinew_instance_step(inst, 1.0f / 30);
    }
    sinew_instance_get_stats(inst, &st);
    if (sinew_instance_collider_force(inst, id, F, M) != SINEW_OK) F[0] = F[1] = F[2] = NAN;
    free(pose);
    return st.world_contacts;
}

TEST(a_moved_mesh_is_queried_where_it_is_now) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int nb = f->ch.skel.nbones;
    sinew_world *w = new_world();
    ENSURE(w);
    float v[24];
    table_vertices(-5, v); /* far below the finger */
    sinew_collider_id table;
    ENSURE(add_mesh(w, v, 8, box_tris, 12, &table));
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_world(inst, w) == SINEW_OK);
    float F[3];
    ENSURE(press(inst, nb, 1, table, F) == 0 && F[0] == 0 && F[1] == 0 && F[2] == 0);
    table_vertices(0, v); /* pressed 0.05 into the flesh */
    ENSURE(sinew_world_set_mesh_vertices(w, table, v, 8) == SINEW_OK);
    uint32_t n = press(inst, nb, 2, table, F);
    fprintf(stderr, "    pressed: %u contacts, force on the mesh (%.4g, %.4g, %.4g)\n", n,
            (double)F[0], (double)F[1], (double)F[2]);
    ENSURE(n > 0 && F[1] < 0); /* the flesh pushes the table down */
    table_vertices(-5, v);
    ENSURE(sinew_world_set_mesh_vertices(w, table, v, 8) == SINEW_OK);
    ENSURE(press(inst, nb, 2, table, F) == 0 && F[0] == 0 && F[1] == 0 && F[2] == 0);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

/* Every query of a grid of points around [lo, hi] answers the same bits in both worlds'
 * colliders in `slot`. */
static int same_queries(const sinew_world *a, const sinew_world *b, uint32_t slot,
                        const float lo[3], const float hi[3], int *hits) {
    const sw_collider *ca = sw_world_slot(a, slot), *cb = sw_world_slot(b, slot);
    *hits = 0;
    for (int i = 0; i <= 12; ++i)
        for (int j = 0; j <= 12; ++j)
            for (int k = 0; k <= 12; ++k) {
                double x[3] = {lo[0] - 0.3 + (hi[0] - lo[0] + 0.6) * i / 12.0,
                               lo[1] - 0.3 + (hi[1] - lo[1] + 0.6) * j / 12.0,
                               lo[2] - 0.3 + (hi[2] - lo[2] + 0.6) * k / 12.0};
                sw_collider_hit ha, hb;
                memset(&ha, 0, sizeof ha);
                memset(&hb, 0, sizeof hb);
                int qa = sw_collider_query(ca, x, 0.25, &ha),
                    qb = sw_collider_query(cb, x, 0.25, &hb);
                if (qa != qb || memcmp(&ha, &hb, sizeof ha)) {
                    fprintf(stderr,
                            "    at (%g, %g, %g): %d phi %.17g n (%g %g %g) vs %d phi %.17g n (%g "
                            "%g %g)\n",
                            x[0], x[1], x[2], qa, ha.phi, ha.normal[0], ha.normal[1], ha.normal[2],
                            qb, hb.phi, hb.normal[0], hb.normal[1], hb.normal[2]);
                    return 0;
                }
                *hits += qa;
            }
    return 1;
}

/* An icosphere of radius 1 at the origin, subdivided twice (162 vertices, 320 triangles,
 * counter-clockwise seen from outside): enough triangles for Embree's BVH to have inner
 * nodes, so a stale tree would cull where the mesh is now. */
enum { ICO_V = 162, ICO_T = 320 };

static uint32_t ico_mid(float *v, uint32_t *nv, uint32_t a, uint32_t b) {
    float m[3];
    double r = 0;
    for (int k = 0; k < 3; ++k) {
        m[k] = 0.5f * (v[3 * a + k] + v[3 * b + k]);
        r += (double)m[k] * m[k];
    }
    for (int k = 0; k < 3; ++k)
        m[k] = (float)(m[k] / sqrt(r));
    for (uint32_t i = 0; i < *nv && i < ICO_V; ++i)
        if (v[3 * i] == m[0] && v[3 * i + 1] == m[1] && v[3 * i + 2] == m[2]) return i;
    if (*nv >= ICO_V) { /* more than an icosphere has: icosphere() reports it */
        *nv = ICO_V + 1;
        return 0;
    }
    memcpy(v + 3 * *nv, m, sizeof m);
    return (*nv)++;
}

static uint32_t icosphere(float v[3 * ICO_V], uint32_t t[3 * ICO_T]) {
    static const uint32_t t0[60] = {0, 11, 5, 0, 5,  1,  0,  1,  7,  0,  7, 10, 0, 10, 11,
                                    1, 5,  9, 5, 11, 4,  11, 10, 2,  10, 7, 6,  7, 1,  8,
                                    3, 9,  4, 3, 4,  2,  3,  2,  6,  3,  6, 8,  3, 8,  9,
                                    4, 9,  5, 2, 4,  11, 6,  2,  10, 8,  6, 7,  9, 8,  1};
    const float p = 1.6180339887f, s = 1 / sqrtf(1 + p * p), q = p * s;
    const float c[36] = {-s, q,  0,  s, q, 0,  -s, -q, 0,  s, -q, 0, 0,  -s, q,  0,  s, q,
                         0,  -s, -q, 0, s, -q, q,  0,  -s, q, 0,  s, -q, 0,  -s, -q, 0, s};
    uint32_t nv = 12, nt = 20, tmp[3 * ICO_T];
    memcpy(v, c, sizeof c);
    memcpy(t, t0, sizeof t0);
    for (int level = 0; level < 2; ++level) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < nt; ++i) {
            uint32_t a = t[3 * i], b = t[3 * i + 1], d = t[3 * i + 2];
            uint32_t ab = ico_mid(v, &nv, a, b), bd = ico_mid(v, &nv, b, d),
                     da = ico_mid(v, &nv, d, a);
            uint32_t f[12] = {a, ab, da, b, bd, ab, d, da, bd, ab, bd, da};
            memcpy(tmp + 3 * n, f, sizeof f);
            n += 4;
        }
        nt = n;
        memcpy(t, tmp, sizeof(uint32_t) * 3 * nt);
    }
    return nv == ICO_V && nt == ICO_T ? nv : 0;
}

TEST(a_moved_mesh_answers_as_one_added_there) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int nb = f->ch.skel.nbones;
    float v0[24], v[24];
    table_vertices(0, v);
    for (int j = 0; j < 8; ++j) { /* added turned a quarter about z: every normal differs */
        v0[3 * j] = -v[3 * j + 1];
        v0[3 * j + 1] = v[3 * j];
        v0[3 * j + 2] = v[3 * j + 2];
    }
    sinew_world *moved = new_world(), *fresh = new_world();
    ENSURE(moved && fresh);
    sinew_collider_id a, b, sa, sb;
    ENSURE(add_mesh(moved, v0, 8, box_tris, 12, &a) && add_mesh(fresh, v, 8, box_tris, 12, &b));
    /* an icosphere far away, then squashed into an ellipsoid beside the table, turned */
    static float s0[3 * ICO_V], s1[3 * ICO_V];
    static uint32_t st[3 * ICO_T];
    ENSURE(icosphere(s0, st) == ICO_V);
    for (int j = 0; j < ICO_V; ++j) {
        float x = s0[3 * j], y = s0[3 * j + 1], z = s0[3 * j + 2];
        s1[3 * j] = 6 + 1.5f * (0.8f * x - 0.6f * y);
        s1[3 * j + 1] = 0.5f * (0.6f * x + 0.8f * y);
        s1[3 * j + 2] = z;
        s0[3 * j] = x - 20;
    }
    ENSURE(add_mesh(moved, s0, ICO_V, st, ICO_T, &sa) &&
           add_mesh(fresh, s1, ICO_V, st, ICO_T, &sb));
    ENSURE(sinew_world_set_mesh_vertices(moved, a, v, 8) == SINEW_OK);
    ENSURE(sinew_world_set_mesh_vertices(moved, sa, s1, ICO_V) == SINEW_OK);
    static const float tlo[3] = {-0.7f, -0.9f, -1.1f}, thi[3] = {4.3f, 0, 1.1f};
    static const float slo[3] = {4.5f, -0.5f, -1}, shi[3] = {7.5f, 0.5f, 1};
    int hits, shits;
    ENSURE(same_queries(moved, fresh, 0, tlo, thi, &hits));
    ENSURE(same_queries(moved, fresh, 1, slo, shi, &shits));
    fprintf(stderr, "    %d and %d of 2197 grid points hit the box and the ellipsoid\n", hits,
            shits);
    ENSURE(hits > 100 && shits > 100);
    /* collapsed: corner 7 onto corner 6 leaves triangles of zero area (skipped, no error);
       then open again, the same as fresh */
    float c[24];
    memcpy(c, v, sizeof c);
    memcpy(c + 21, c + 18, 3 * sizeof(float));
    ENSURE(sinew_world_set_mesh_vertices(moved, a, c, 8) == SINEW_OK);
    int finite = 1;
    for (int i = 0; i <= 20; ++i) {
        double x[3] = {-1 + 0.3 * i, -0.5, 0.9}; /* through the collapsed corner's region */
        sw_collider_hit h;
        if (sw_collider_query(sw_world_slot(moved, 0), x, 0.5, &h))
            finite &= isfinite(h.phi) && isfinite(h.normal[0]) && isfinite(h.normal[1]) &&
                      isfinite(h.normal[2]);
    }
    ENSURE(finite);
    ENSURE(sinew_world_set_mesh_vertices(moved, a, v, 8) == SINEW_OK);
    ENSURE(same_queries(moved, fresh, 0, tlo, thi, &hits));
    /* and the steps against them: the same surface and force, bit for bit */
    sinew_instance *ia, *ib;
    ENSURE(sinew_instance_create(f->blob, NULL, &ia) == SINEW_OK);
    ENSURE(sinew_instance_create(f->blob, NULL, &ib) == SINEW_OK);
    ENSURE(sinew_instance_set_world(ia, moved) == SINEW_OK);
    ENSURE(sinew_instance_set_world(ib, fresh) == SINEW_OK);
    float Fa[3], Fb[3];
    uint32_t na = press(ia, nb, 3, a, Fa), nbc = press(ib, nb, 3, b, Fb);
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    float *xa = malloc(sizeof(float) * 3 * ns), *xb = malloc(sizeof(float) * 3 * ns);
    ENSURE(xa && xb);
    ENSURE(sinew_instance_read_surface(ia, xa, NULL, ns) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(ib, xb, NULL, ns) == SINEW_OK);
    ENSURE(na > 0 && na == nbc && memcmp(Fa, Fb, sizeof Fa) == 0);
    ENSURE(memcmp(xa, xb, sizeof(float) * 3 * ns) == 0);
    free(xa);
    free(xb);
    sinew_instance_destroy(ia);
    sinew_instance_destroy(ib);
    sinew_world_destroy(moved);
    sinew_world_destroy(fresh);
}

TEST(an_ignored_collider_gives_no_contact) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int nb = f->ch.skel.nbones;
    sinew_world *w = new_world();
    ENSURE(w);
    float v[24];
    table_vertices(0, v);
    sinew_collider_id table;
    ENSURE(add_mesh(w, v, 8, box_tris, 12, &table));
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_ignore_collider(inst, table) == SINEW_OK); /* before attaching */
    ENSURE(sinew_instance_set_world(inst, w) == SINEW_OK);
    float F[3];
    ENSURE(press(inst, nb, 2, table, F) == 0 && F[0] == 0 && F[1] == 0 && F[2] == 0);
    ENSURE(sinew_instance_ignore_collider(inst, 0) == SINEW_OK); /* cleared: it touches */
    ENSURE(press(inst, nb, 2, table, F) > 0 && F[1] < 0);
    ENSURE(sinew_instance_ignore_collider(inst, table + (1u << 16)) ==
           SINEW_ERROR_INVALID_ARGUMENT); /* not live in the attached world */
    ENSURE(sinew_instance_ignore_collider(NULL, table) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(errors_keep_the_old_vertices) {
    sinew_world *w = new_world();
    ENSURE(w);
    float v[24], bad[24];
    table_vertices(0, v);
    sinew_collider_id table, ball, gone;
    ENSURE(add_mesh(w, v, 8, box_tris, 12, &table) && add_mesh(w, v, 8, box_tris, 12, &gone));
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_SPHERE;
    c.radius = 1;
    ENSURE(sinew_world_add_collider(w, &c, &ball) == SINEW_OK);
    ENSURE(sinew_world_remove_collider(w, gone) == SINEW_OK);
    table_vertices(3, bad);
    ENSURE(sinew_world_set_mesh_vertices(w, table, bad, 7) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(w, table, bad, 9) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(w, ball, bad, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(w, gone, bad, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(w, 0, bad, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(w, table, NULL, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_world_set_mesh_vertices(NULL, table, bad, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    bad[23] = NAN;
    ENSURE(sinew_world_set_mesh_vertices(w, table, bad, 8) == SINEW_ERROR_NOT_FINITE);
    bad[23] = INFINITY;
    ENSURE(sinew_world_set_mesh_vertices(w, table, bad, 8) == SINEW_ERROR_NOT_FINITE);
    bad[23] = 1e16f;
    ENSURE(sinew_world_set_mesh_vertices(w, table, bad, 8) == SINEW_ERROR_INVALID_ARGUMENT);
    /* none of them moved it: the table's top face is still at y = -0.39 under x = 1 */
    sw_collider_hit h;
    double x[3] = {1, -0.33, 0}; /* 0.05 above the top face (y = -0.38 at x = 1) */
    ENSURE(sw_collider_query(sw_world_slot(w, 0), x, 0.2, &h) && fabs(h.phi - 0.05) < 1e-3);
    uint32_t n;
    const double *X = sw_collider_points(sw_world_slot(w, 0), &n);
    ENSURE(n == 8);
    for (int i = 0; i < 24; ++i)
        ENSURE(X[i] == v[i]);
    sinew_world_destroy(w);
}

/* Two fingers in one world, each one's output surface a mesh collider that it ignores;
 * the host's frame loop: step both (the world read-only), then copy each surface into
 * its collider. Finger B starts above A and is lowered into it. */
TEST(two_fingers_push_each_other_apart) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int nb = f->ch.skel.nbones;
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob),
             nt = sinew_blob_surface_triangle_count(f->blob);
    uint32_t *tris = malloc(sizeof(uint32_t) * 3 * nt);
    float *x[2], *pose = malloc(sizeof(float) * 12 * (size_t)nb);
    ENSURE(tris && pose);
    ENSURE(sinew_blob_surface_triangles(f->blob, tris, 3 * nt) == SINEW_OK);
    sinew_world *w = new_world();
    ENSURE(w);
    sinew_instance *in[2];
    sinew_collider_id id[2];
    static const float start_y[2] = {0, 1.2f};
    for (int i = 0; i < 2; ++i) {
        x[i] = malloc(sizeof(float) * 3 * ns);
        ENSURE(x[i]);
        ENSURE(sinew_instance_create(f->blob, NULL, &in[i]) == SINEW_OK);
        moved_rest_pose(nb, 0, start_y[i], pose);
        ENSURE(sinew_instance_set_pose(in[i], pose, (uint32_t)nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in[i], 1.0f / 30) == SINEW_OK);
        ENSURE(sinew_instance_read_surface(in[i], x[i], NULL, ns) == SINEW_OK);
        ENSURE(add_mesh(w, x[i], ns, tris, nt, &id[i]));
    }
    for (int i = 0; i < 2; ++i) {
        ENSURE(sinew_instance_set_world(in[i], w) == SINEW_OK);
        ENSURE(sinew_instance_ignore_collider(in[i], id[i]) == SINEW_OK);
    }
    unsigned active = sw_rt_interpose_active();
    sw_rt_counts total;
    memset(&total, 0, sizeof total);
    float F[2][3], M[3];
    uint32_t contacts[2] = {0, 0}, failed = 0;
    double t_update = 0, t_step = 0;
    int steps = 12;
    for (int s = 0; s < steps; ++s) {
        /* B goes from 1.2 above A down to 0.78 (its flesh 0.12 into A's), then stays */
        float yb = 1.2f - 0.06f * (float)(s < 7 ? s : 7);
        double t0 = now();
        sw_rt_count_begin(); /* the steps only: the copies below commit Embree scenes */
        for (int i = 0; i < 2; ++i) {
            moved_rest_pose(nb, 0, i ? yb : 0, pose);
            if (sinew_instance_set_pose(in[i], pose, (uint32_t)nb) != SINEW_OK ||
                sinew_instance_step(in[i], 1.0f / 30) != SINEW_OK)
                failed++;
        }
        sw_rt_counts c = sw_rt_count_end();
        double t1 = now();
        total.allocs += c.allocs;
        total.frees += c.frees;
        total.maps += c.maps;
        total.locks += c.locks;
        for (int k = 0; k < SW_RT_FN_COUNT; ++k)
            total.by_fn[k] += c.by_fn[k];
        for (int i = 0; i < 2; ++i) {
            ENSURE(sinew_instance_read_surface(in[i], x[i], NULL, ns) == SINEW_OK);
            ENSURE(sinew_world_set_mesh_vertices(w, id[i], x[i], ns) == SINEW_OK);
        }
        t_update += now() - t1;
        t_step += t1 - t0;
        for (int i = 0; i < 2; ++i) {
            sinew_step_stats st;
            st.struct_size = sizeof st;
            ENSURE(sinew_instance_get_stats(in[i], &st) == SINEW_OK);
            contacts[i] += st.world_contacts;
        }
    }
    /* each finger's force on the other's surface: A pushes B up, B pushes A down */
    ENSURE(sinew_instance_collider_force(in[0], id[1], F[0], M) == SINEW_OK);
    ENSURE(sinew_instance_collider_force(in[1], id[0], F[1], M) == SINEW_OK);
    double sum[3], n0 = 0, ns_ = 0;
    for (int k = 0; k < 3; ++k) {
        sum[k] = (double)F[0][k] + (double)F[1][k];
        n0 += (double)F[0][k] * F[0][k];
        ns_ += sum[k] * sum[k];
    }
    fprintf(stderr,
            "    %u and %u contacts over %d frames; A on B (%.4g, %.4g, %.4g), B on A (%.4g, "
            "%.4g, %.4g): |sum| / |A on B| = %.3g\n",
            contacts[0], contacts[1], steps, (double)F[0][0], (double)F[0][1], (double)F[0][2],
            (double)F[1][0], (double)F[1][1], (double)F[1][2], sqrt(ns_ / n0));
    fprintf(stderr,
            "    %u vertices, %u triangles a surface: %.3f ms a frame for both steps, %.3f ms "
            "for both surface copies (set_mesh_vertices)\n",
            ns, nt, 1e3 * t_step / steps, 1e3 * t_update / steps);
    double t2 = now(); /* the copy alone, A's surface over again */
    for (int r = 0; r < 50; ++r)
        ENSURE(sinew_world_set_mesh_vertices(w, id[0], x[0], ns) == SINEW_OK);
    fprintf(stderr, "    one set_mesh_vertices: %.3f ms\n", 1e3 * (now() - t2) / 50);
    ENSURE(failed == 0 && contacts[0] > 0 && contacts[1] > 0);
    ENSURE(F[0][1] > 0 && F[1][1] < 0);
    ENSURE((double)F[0][0] * F[1][0] + (double)F[0][1] * F[1][1] + (double)F[0][2] * F[1][2] < 0);
    char buf[512];
    sw_rt_counts_describe(&total, buf, sizeof buf);
    fprintf(stderr, "    the steps: %s\n", buf);
    if (active & SW_RT_CAT_ALLOCS) ENSUREF(total.allocs == 0, "%s", buf);
    if (active & SW_RT_CAT_FREES) ENSUREF(total.frees == 0, "%s", buf);
    if (active & SW_RT_CAT_MAPS) ENSUREF(total.maps == 0, "%s", buf);
    if (active & SW_RT_CAT_LOCKS) ENSUREF(total.locks == 0, "%s", buf);
    for (int i = 0; i < 2; ++i) {
        sinew_instance_destroy(in[i]);
        free(x[i]);
    }
    sinew_world_destroy(w);
    free(tris);
    free(pose);
}

/* One finger's step of a frame (set_pose, step), on whichever thread runs it. */
typedef struct step_job {
    sinew_instance *inst;
    const float *pose;
    uint32_t nb;
    sinew_result r;
} step_job;

static void *step_job_run(void *p) {
    step_job *j = p;
    j->r = sinew_instance_set_pose(j->inst, j->pose, j->nb);
    if (j->r == SINEW_OK) j->r = sinew_instance_step(j->inst, 1.0f / 30);
    return NULL;
}

/* The two fingers' frame loop (as above, 8 frames) with the steps of each frame run A then
 * B (order 0), B then A (1) or on two threads at once (2); the last surfaces into out. */
static int run_fingers(const bake_fixture *f, int order, float *out[2]) {
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob),
             nt = sinew_blob_surface_triangle_count(f->blob);
    uint32_t *tris = malloc(sizeof(uint32_t) * 3 * nt);
    float *pose[2] = {malloc(sizeof(float) * 12 * nb), malloc(sizeof(float) * 12 * nb)};
    sinew_world *w = new_world();
    sinew_instance *in[2] = {NULL, NULL};
    sinew_collider_id id[2];
    int ok = tris && pose[0] && pose[1] && w &&
             sinew_blob_surface_triangles(f->blob, tris, 3 * nt) == SINEW_OK;
    for (int i = 0; i < 2 && ok; ++i) {
        moved_rest_pose((int)nb, 0, i ? 1.2f : 0, pose[i]);
        ok = sinew_instance_create(f->blob, NULL, &in[i]) == SINEW_OK &&
             sinew_instance_set_pose(in[i], pose[i], nb) == SINEW_OK &&
             sinew_instance_step(in[i], 1.0f / 30) == SINEW_OK &&
             sinew_instance_read_surface(in[i], out[i], NULL, ns) == SINEW_OK &&
             add_mesh(w, out[i], ns, tris, nt, &id[i]);
    }
    for (int i = 0; i < 2 && ok; ++i)
        ok = sinew_instance_set_world(in[i], w) == SINEW_OK &&
             sinew_instance_ignore_collider(in[i], id[i]) == SINEW_OK;
    for (int s = 0; s < 8 && ok; ++s) {
        moved_rest_pose((int)nb, 0, 1.2f - 0.06f * (float)s, pose[1]);
        step_job job[2] = {{in[0], pose[0], nb, SINEW_OK}, {in[1], pose[1], nb, SINEW_OK}};
        if (order == 2) {
            pthread_t t;
            ok = pthread_create(&t, NULL, step_job_run, &job[1]) == 0;
            step_job_run(&job[0]);
            if (ok) pthread_join(t, NULL);
        } else {
            step_job_run(&job[order]);
            step_job_run(&job[1 - order]);
        }
        ok = ok && job[0].r == SINEW_OK && job[1].r == SINEW_OK;
        for (int i = 0; i < 2 && ok; ++i)
            ok = sinew_instance_read_surface(in[i], out[i], NULL, ns) == SINEW_OK &&
                 sinew_world_set_mesh_vertices(w, id[i], out[i], ns) == SINEW_OK;
    }
    for (int i = 0; i < 2; ++i) {
        sinew_instance_destroy(in[i]);
        free(pose[i]);
    }
    sinew_world_destroy(w);
    free(tris);
    return ok;
}

/* The world is read-only during the steps and holds the last frame's surfaces: the order
 * and the threads of a frame's steps do not change a bit. */
TEST(two_fingers_are_the_same_whatever_the_step_order) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    size_t n = 3 * (size_t)sinew_blob_surface_vertex_count(f->blob);
    float *x = malloc(sizeof(float) * 4 * n);
    ENSURE(x);
    for (int order = 0; order < 3; ++order) {
        float *out[2] = {x + 2 * n * (order > 0), x + 2 * n * (order > 0) + n};
        ENSURE(run_fingers(f, order, out));
        if (order > 0) ENSURE(memcmp(x, out[0], sizeof(float) * 2 * n) == 0);
    }
    free(x);
}

SW_TEST_MAIN({"a_moved_mesh_is_queried_where_it_is_now", a_moved_mesh_is_queried_where_it_is_now},
             {"a_moved_mesh_answers_as_one_added_there", a_moved_mesh_answers_as_one_added_there},
             {"an_ignored_collider_gives_no_contact", an_ignored_collider_gives_no_contact},
             {"errors_keep_the_old_vertices", errors_keep_the_old_vertices},
             {"two_fingers_push_each_other_apart", two_fingers_push_each_other_apart},
             {"two_fingers_are_the_same_whatever_the_step_order",
              two_fingers_are_the_same_whatever_the_step_order})
