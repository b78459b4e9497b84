/* The debug draw (sinew_instance_debug_draw): the finger pressed into a table hands the
 * host one contact line a world contact the step counted and one a self-contact pair in
 * use; the table is drawn as its box's 12 edges and a plane as a square; the bones as
 * lines from their parents (points at the roots); the patch's vertices and tets as the
 * stats count them; nothing at all for flags off; and a draw allocates and locks nothing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt_interpose.h"
#include "sw_test.h"
#include "world_fixture.h"

typedef struct tally {
    int lines[6], points[6], tris[6]; /* by kind: world, self, patch, collider, bone, other */
    int calls, bad;
    double top_err, rise_min; /* world contact lines: |y - the table top|, end y - start y */
} tally;

static const double table_top = -0.44 + 0.08;

static int kind(uint32_t rgba) {
    switch (rgba) {
    case SINEW_DEBUG_COLOR_WORLD_CONTACT:
        return 0;
    case SINEW_DEBUG_COLOR_SELF_CONTACT:
        return 1;
    case SINEW_DEBUG_COLOR_PATCH:
        return 2;
    case SINEW_DEBUG_COLOR_COLLIDER:
        return 3;
    case SINEW_DEBUG_COLOR_BONE:
        return 4;
    }
    return 5;
}

static int finite3(const float p[3]) {
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

static void on_line(const float a[3], const float b[3], uint32_t rgba, void *ctx) {
    tally *t = ctx;
    t->calls++;
    t->lines[kind(rgba)]++;
    t->bad += !finite3(a) || !finite3(b);
    if (kind(rgba) == 0) {
        t->top_err = fmax(t->top_err, fabs(a[1] - table_top));
        t->rise_min = fmin(t->rise_min, (double)b[1] - a[1]);
    }
}

static void on_point(const float a[3], float size, uint32_t rgba, void *ctx) {
    tally *t = ctx;
    t->calls++;
    t->points[kind(rgba)]++;
    t->bad += !finite3(a) || !(size > 0);
}

static void on_tri(const float a[3], const float b[3], const float c[3], uint32_t rgba, void *ctx) {
    tally *t = ctx;
    t->calls++;
    t->tris[kind(rgba)]++;
    t->bad += !finite3(a) || !finite3(b) || !finite3(c);
}

static sinew_debug_draw drawer(tally *t, uint32_t flags) {
    memset(t, 0, sizeof *t);
    t->rise_min = INFINITY;
    sinew_debug_draw d;
    memset(&d, 0, sizeof d);
    d.draw_line = on_line;
    d.draw_point = on_point;
    d.draw_triangle = on_tri;
    d.flags = flags;
    d.context = t;
    return d;
}

/* The finger at its rest pose on the table `depth` deep, stepped `steps` times. */
static sinew_instance *pressed(const sinew_instance_def *def, sinew_world *w, int steps) {
    const bake_fixture *f = fixture();
    sinew_instance *inst = NULL;
    if (!f || sinew_instance_create(f->blob, def, &inst) != SINEW_OK) return NULL;
    sinew_instance_set_world(inst, w);
    float *pose = malloc(sizeof(float) * 12 * (size_t)f->ch.skel.nbones);
    bake_fixture_pose(f, 3, pose);
    sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones);
    for (int k = 0; k < steps; ++k)
        sinew_instance_step(inst, 1.0f / 30);
    free(pose);
    return inst;
}

/* Over the clip, in self-contact mode `self` (the pairs in use come from the pose space,
 * or from the exhaustive detection). */
static void contact_lines_in_mode(sinew_self_contact self) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    ENSURE(w);
    sinew_instance_def def = sinew_instance_def_default();
    def.self_contact = self;
    sinew_instance *inst = pressed(&def, w, 3);
    ENSURE(inst);
    uint32_t nb = (uint32_t)f->ch.skel.nbones, world_seen = 0, self_seen = 0;
    float *pose = malloc(sizeof(float) * 12 * nb);
    unsigned active = sw_rt_interpose_active();
    sw_rt_counts c = {0};
    tally t;
    for (int k = 0; k < f->ch.clip.nframes; ++k) { /* the clip folds the finger */
        bake_fixture_pose(f, k, pose);
        ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st;
        st.struct_size = sizeof st;
        ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK);
        sinew_debug_draw d = drawer(&t, SINEW_DEBUG_DRAW_CONTACTS);
        sw_rt_count_begin();
        ENSURE(sinew_instance_debug_draw(inst, &d) == SINEW_OK);
        sw_rt_counts ck = sw_rt_count_end();
        c.allocs += ck.allocs + ck.frees;
        c.locks += ck.locks;
        ENSUREF(t.lines[0] == (int)st.world_contacts && t.points[0] == t.lines[0],
                "frame %d: %d world contact lines, %u contacts", k, t.lines[0], st.world_contacts);
        ENSUREF(t.lines[1] == (int)st.self_contacts && t.points[1] == t.lines[1],
                "frame %d: %d self-contact lines, %u pairs", k, t.lines[1], st.self_contacts);
        ENSURE(t.bad == 0 && t.lines[5] + t.points[5] + t.tris[5] == 0);
        ENSURE(t.lines[2] + t.lines[3] + t.lines[4] == 0); /* only what the flags ask */
        /* the world contacts lie on the table's top face, their normals up */
        if (t.lines[0] > 0)
            ENSUREF(t.top_err < 1e-4 && t.rise_min > 0, "top %g rise %g", t.top_err, t.rise_min);
        world_seen += st.world_contacts;
        self_seen += st.self_contacts;
    }
    fprintf(stderr,
            "    %s, over the clip: %u world contact and %u self-contact lines, as counted; "
            "the draws: %llu allocations, %llu locks\n",
            self == SINEW_SELF_CONTACT_EXHAUSTIVE ? "exhaustive" : "pose space", world_seen,
            self_seen, (unsigned long long)c.allocs, (unsigned long long)c.locks);
    ENSURE(world_seen > 0 && self_seen > 0);
    if (active & SW_RT_CAT_ALLOCS) ENSURE(c.allocs == 0);
    if (active & SW_RT_CAT_LOCKS) ENSURE(c.locks == 0);
    tally none;
    sinew_debug_draw off = drawer(&none, 0);
    ENSURE(sinew_instance_debug_draw(inst, &off) == SINEW_OK && none.calls == 0);
    sinew_debug_draw nulls = drawer(&none, ~0u);
    nulls.draw_line = NULL;
    nulls.draw_point = NULL;
    nulls.draw_triangle = NULL;
    ENSURE(sinew_instance_debug_draw(inst, &nulls) == SINEW_OK && none.calls == 0);
    ENSURE(sinew_instance_debug_draw(NULL, &off) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_debug_draw(inst, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    free(pose);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(contact_lines_are_the_steps_contacts) {
    contact_lines_in_mode(SINEW_SELF_CONTACT_POSE_SPACE);
}

TEST(contact_lines_are_the_detected_contacts) {
    contact_lines_in_mode(SINEW_SELF_CONTACT_EXHAUSTIVE);
}

TEST(colliders_and_bones_are_drawn) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id, pid;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    ENSURE(w);
    sinew_collider_def plane = sinew_collider_def_default(); /* y = -3 */
    plane.offset = -3;
    ENSURE(sinew_world_add_collider(w, &plane, &pid) == SINEW_OK);
    sinew_instance *inst = pressed(NULL, w, 1);
    ENSURE(inst);
    tally t;
    sinew_debug_draw d = drawer(&t, SINEW_DEBUG_DRAW_COLLIDERS | SINEW_DEBUG_DRAW_BONES);
    ENSURE(sinew_instance_debug_draw(inst, &d) == SINEW_OK);
    int nb = f->ch.skel.nbones;
    fprintf(stderr, "    collider lines %d, bone lines %d and points %d of %d bones\n", t.lines[3],
            t.lines[4], t.points[4], nb);
    ENSURE(t.lines[3] == 12 + 4);
    ENSURE(t.lines[4] + t.points[4] == nb && t.lines[4] >= 1);
    ENSURE(t.bad == 0 && t.lines[0] + t.lines[1] == 0);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(the_patch_is_drawn_as_the_stats_count_it) {
    ENSURE(fixture());
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    ENSURE(w);
    sinew_instance_def def = sinew_instance_def_default();
    def.max_patch_vertices = 400;
    sinew_instance *inst = pressed(&def, w, 3);
    ENSURE(inst);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK);
    tally t;
    sinew_debug_draw d = drawer(&t, SINEW_DEBUG_DRAW_PATCH);
    ENSURE(sinew_instance_debug_draw(inst, &d) == SINEW_OK);
    fprintf(stderr, "    patch: %u vertices, %u tets; drawn %d points, %d triangles\n",
            st.patch_vertices, st.patch_tets, t.points[2], t.tris[2]);
    ENSURE(st.patch_vertices > 0);
    ENSURE(t.points[2] == (int)st.patch_vertices && t.tris[2] == 4 * (int)st.patch_tets);
    ENSURE(t.bad == 0);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(contact_lines_are_the_steps_contacts),
             CASE(contact_lines_are_the_detected_contacts), CASE(colliders_and_bones_are_drawn),
             CASE(the_patch_is_drawn_as_the_stats_count_it), CASE(release_fixture))
