/* Mesh colliders (runtime/collision/mesh.c, Embree rtcPointQuery) on a real closed
 * surface from ../shared/data (libigl's arm, 16,618 triangles): the distance against
 * the brute-force closest triangle, the inside/outside sign (from the pseudonormals)
 * against the generalized winding number, for random points and for points placed near
 * vertices and edges; deep points found through the second, box-wide query; the cost of
 * one query printed. */
#include "sw_test.h"

#include <time.h>

#include "collision_ref.h"
#include "mesh_io.h"

static sw_trimesh arm;
static int arm_ok = -1;
static double lo[3], hi[3], diag;

static const sw_trimesh *load(void) {
    if (arm_ok < 0) {
        sw_error err;
        arm_ok = sw_read_obj(SINEW_SHARED_DATA_DIR "/arm-libigl/arm.obj", &arm, &err) == SINEW_OK;
        if (!arm_ok) fprintf(stderr, "    %s\n", err.msg);
        for (int k = 0; arm_ok && k < 3; ++k) {
            lo[k] = HUGE_VAL, hi[k] = -HUGE_VAL;
            for (int i = 0; i < arm.nverts; ++i)
                lo[k] = fmin(lo[k], arm.X[3 * i + k]), hi[k] = fmax(hi[k], arm.X[3 * i + k]);
        }
        double e[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        diag = sqrt(ref_dot(e, e));
    }
    return arm_ok ? &arm : NULL;
}

/* The arm as a collider def (float copies the caller owns). */
static sinew_collider_def mesh_def(const sw_trimesh *m, float **v, uint32_t **ix) {
    *v = malloc(sizeof(float) * 3 * m->nverts);
    *ix = malloc(sizeof(uint32_t) * 3 * m->ntris);
    for (int i = 0; i < 3 * m->nverts; ++i)
        (*v)[i] = (float)m->X[i];
    for (int i = 0; i < 3 * m->ntris; ++i)
        (*ix)[i] = (uint32_t)m->tris[i];
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_MESH;
    d.vertices = *v;
    d.vertex_count = (uint32_t)m->nverts;
    d.indices = *ix;
    d.triangle_count = (uint32_t)m->ntris;
    return d;
}

/* Brute force over the float vertices the collider was given: distance and winding
 * number (1 inside, 0 outside). */
static double brute(const float *v, const sw_trimesh *m, const double y[3], double *winding) {
    double best = HUGE_VAL, w = 0;
    for (int t = 0; t < m->ntris; ++t) {
        double a[3], b[3], c[3];
        for (int i = 0; i < 3; ++i) {
            a[i] = v[3 * m->tris[3 * t] + i];
            b[i] = v[3 * m->tris[3 * t + 1] + i];
            c[i] = v[3 * m->tris[3 * t + 2] + i];
        }
        best = fmin(best, ref_triangle_dist(y, a, b, c));
        w += ref_solid_angle(y, a, b, c);
    }
    *winding = w / (4 * 3.14159265358979323846);
    return best;
}

/* Points: uniform in the box grown by 10%, and near random vertices and edge points. */
static void sample(const float *v, const sw_trimesh *m, int k, double y[3]) {
    if (k % 3 == 0) {
        for (int i = 0; i < 3; ++i)
            y[i] = lo[i] - 0.05 * diag + (hi[i] - lo[i] + 0.1 * diag) * urand();
        return;
    }
    int t = (int)(urand() * m->ntris), e = (int)(urand() * 3);
    const float *a = v + 3 * m->tris[3 * t + e], *b = v + 3 * m->tris[3 * t + (e + 1) % 3];
    double s = k % 3 == 1 ? 0.0 : urand(), r = 0.02 * diag;
    for (int i = 0; i < 3; ++i)
        y[i] = a[i] + s * (b[i] - a[i]) + r * srand1();
}

TEST(arm_mesh_matches_brute_force) {
    NEED_DATA("arm-libigl/arm.obj");
    const sw_trimesh *m = load();
    ENSUREF(m, "arm-libigl/arm.obj is present but not readable");
    float *v;
    uint32_t *ix;
    sinew_collider_def d = mesh_def(m, &v, &ix);
    d.transform = random_transform();
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &d, &id) == SINEW_OK);
    const sw_collider *c = sw_world_slot(w, (uint32_t)sw_world_slot_of(w, id));
    double radius = 0.01 * diag, worst = 0, worst_n = 0;
    int sign_wrong = 0, hits = 0, inside = 0, deep = 0, n = 1500;
    for (int k = 0; k < n; ++k) {
        double y[3], x[3], wn, p[3], nl[3];
        sample(v, m, k, y);
        double dist = brute(v, m, y, &wn);
        int in = wn > 0.5;
        to_world(&d.transform, y, x);
        sw_collider_hit h;
        int got = sw_collider_query(c, x, radius, &h);
        int expect = in || dist <= radius;
        if (fabs(dist - radius) < 1e-6 * diag) continue; /* the radius' own rounding */
        ENSUREF(got == expect, "point %d: got %d, dist %g, winding %g", k, got, dist, wn);
        if (!got) continue;
        hits++;
        inside += in;
        deep += in && dist > radius;
        sign_wrong += (h.phi < 0) != in && dist > 1e-6 * diag;
        worst = fmax(worst, fabs(fabs(h.phi) - dist));
        to_local(&d.transform, h.point, 1, p);
        to_local(&d.transform, h.normal, 0, nl);
        double back[3] = {p[0] + h.phi * nl[0], p[1] + h.phi * nl[1], p[2] + h.phi * nl[2]};
        worst_n = fmax(worst_n, ref_dist(back, y) + fabs(sqrt(ref_dot(nl, nl)) - 1));
    }
    fprintf(stderr,
            "    arm (%d tris, diag %.3g): %d hits (%d inside, %d deep), max ||phi| - dist| "
            "%.2e, |p + phi n - x| %.2e, wrong signs %d\n",
            m->ntris, diag, hits, inside, deep, worst, worst_n, sign_wrong);
    ENSURE(sign_wrong == 0 && deep > 0);
    ENSURE(worst < 1e-5 * diag && worst_n < 1e-5 * diag);
    sinew_world_destroy(w);
    free(v);
    free(ix);
}

TEST(arm_mesh_query_cost) {
    NEED_DATA("arm-libigl/arm.obj");
    const sw_trimesh *m = load();
    ENSUREF(m, "arm-libigl/arm.obj is present but not readable");
    float *v;
    uint32_t *ix;
    sinew_collider_def d = mesh_def(m, &v, &ix);
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &d, &id) == SINEW_OK);
    const sw_collider *c = sw_world_slot(w, (uint32_t)sw_world_slot_of(w, id));
    int n = 100000, hits = 0;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int k = 0; k < n; ++k) {
        double y[3];
        sample(v, m, k, y);
        sw_collider_hit h;
        hits += sw_collider_query(c, y, 0.01 * diag, &h);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double us = ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / 1e3 / n;
    fprintf(stderr, "    %d queries (radius 1%% of the diagonal, %d hits): %.2f us each\n", n, hits,
            us);
    ENSURE(hits > 0);
    sinew_world_destroy(w);
    free(v);
    free(ix);
}

SW_TEST_MAIN(CASE(arm_mesh_matches_brute_force), CASE(arm_mesh_query_cost))
