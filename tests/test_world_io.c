/* World files (precompute/io/world_io.h): the schema's example, the sample worlds,
 * keyframe interpolation, and every error path (code and a message naming the file,
 * the collider and the field). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sw_test.h"
#include "world_io.h"

static const char example[] =
    "{\"sinew_world\": 1,\n"
    " \"colliders\": [\n"
    "   {\"name\": \"floor\", \"shape\": \"plane\", \"normal\": [0,1,0], \"offset\": 0.0},\n"
    "   {\"name\": \"ball\",  \"shape\": \"sphere\", \"radius\": 0.1},\n"
    "   {\"name\": \"bar\",   \"shape\": \"capsule\", \"radius\": 0.05, \"half_height\": 0.3},\n"
    "   {\"name\": \"wall\",  \"shape\": \"box\", \"half_extents\": [0.5, 0.5, 0.05]},\n"
    "   {\"name\": \"rock\",  \"shape\": \"hull\", \"points\": [[0,0,0], [1,0,0], [0,1,0], "
    "[0,0,1]]},\n"
    "   {\"name\": \"pipe\",  \"shape\": \"mesh\", \"obj\": \"pipe.obj\"}]}\n";

static sinew_result parse(const char *text, const char *dir, sw_world_file *w, sw_error *e) {
    sw_error_clear(e);
    return sw_world_file_parse(text, strlen(text), dir, "world.json", w, e);
}

static const char *tmp_dir(void) {
    static char dir[512];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "%s/test_world_io", SINEW_BINARY_DIR);
        char cmd[600];
        snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
        if (system(cmd) != 0) return NULL;
    }
    return dir;
}

static int write_file(const char *dir, const char *name, const char *text) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

/* A closed tetrahedron, counter-clockwise seen from outside, with one quad face split. */
static const char pipe_obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                               "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(example_parses_to_the_right_defs) {
    const char *dir = tmp_dir();
    ENSURE(dir && write_file(dir, "pipe.obj", pipe_obj));
    sw_world_file w;
    sw_error e;
    sinew_result rc = parse(example, dir, &w, &e);
    ENSUREF(rc == SINEW_OK, "%d %s", rc, e.msg);
    ENSURE(w.ncolliders == 6 && w.frames == -1);
    const sw_world_collider_spec *c = w.colliders;
    ENSURE(!strcmp(c[0].name, "floor") && c[0].def.shape == SINEW_SHAPE_PLANE);
    ENSURE(c[0].def.normal[0] == 0 && c[0].def.normal[1] == 1 && c[0].def.offset == 0);
    ENSURE(c[0].def.struct_size == sizeof(sinew_collider_def));
    ENSURE(!strcmp(c[1].name, "ball") && c[1].def.shape == SINEW_SHAPE_SPHERE);
    ENSURE(c[1].def.radius == 0.1f);
    ENSURE(c[2].def.shape == SINEW_SHAPE_CAPSULE && c[2].def.radius == 0.05f &&
           c[2].def.half_height == 0.3f);
    ENSURE(c[3].def.shape == SINEW_SHAPE_BOX && c[3].def.half_extents[0] == 0.5f &&
           c[3].def.half_extents[2] == 0.05f);
    ENSURE(c[4].def.shape == SINEW_SHAPE_HULL && c[4].def.point_count == 4 &&
           c[4].def.points == c[4].points && c[4].points[3] == 1.0f && c[4].points[11] == 1.0f);
    ENSURE(c[5].def.shape == SINEW_SHAPE_MESH && c[5].def.vertex_count == 4 &&
           c[5].def.triangle_count == 4 && c[5].def.vertices == c[5].vertices &&
           c[5].def.indices == c[5].indices);
    ENSURE(c[5].indices[0] == 0 && c[5].indices[1] == 2 && c[5].indices[2] == 1);
    ENSURE(c[5].vertices[9 + 2] == 1.0f);
    for (int i = 0; i < 6; ++i) {
        ENSURE(c[i].nkeys == 0 && c[i].def.stiffness == 0 && c[i].def.friction == 0);
        ENSURE(c[i].def.transform.rotation[0] == 1 && c[i].def.transform.position[1] == 0);
    }
    ENSURE(sw_world_file_last_key_frame(&w) == 0);
    sw_world_file_free(&w);
    ENSURE(w.colliders == NULL && w.ncolliders == 0);
    sw_world_file_free(&w); /* a zeroed struct is a no-op */
}

TEST(optional_fields_defaults_and_normalisation) {
    sw_world_file w;
    sw_error e;
    sinew_result rc = parse(
        "{\"frames\": 40, \"sinew_world\": 1, \"colliders\": ["
        "{\"shape\": \"plane\", \"normal\": [0, 0, -3], \"offset\": 2, \"stiffness\": 1e4, "
        "\"friction\": 0.5},"
        "{\"shape\": \"sphere\", \"radius\": 1, \"motion\": [{\"frame\": 5, \"position\": [1, 2, "
        "3], \"rotation\": [0, 0, 0, 2]}, {\"frame\": 9, \"position\": [0, 0, 0], \"rotation\": "
        "[1, 0, 0, 0]}]}]}",
        NULL, &w, &e);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    ENSURE(w.frames == 40 && w.ncolliders == 2 && !w.rest_pose); /* "pose" defaults to clip */
    ENSURE(!strcmp(w.colliders[0].name, "collider0") && !strcmp(w.colliders[1].name, "collider1"));
    ENSURE(w.colliders[0].def.normal[2] == -1.0f && w.colliders[0].def.offset == 2.0f);
    ENSURE(w.colliders[0].def.stiffness == 1e4f && w.colliders[0].def.friction == 0.5f);
    const sinew_transform *t = &w.colliders[1].def.transform; /* frame 0: held first key */
    ENSURE(t->position[0] == 1 && t->position[2] == 3 && t->rotation[3] == 1 &&
           t->rotation[0] == 0);
    ENSURE(w.colliders[1].keys[0].rotation[3] == 1.0); /* stored normalised */
    ENSURE(sw_world_file_last_key_frame(&w) == 9);
    sw_world_file_free(&w);
    rc = parse("{\"sinew_world\": 1, \"colliders\": []}", NULL, &w, &e);
    ENSUREF(rc == SINEW_OK && w.ncolliders == 0 && w.frames == -1, "%s", e.msg);
    sw_world_file_free(&w);
}

TEST(sample_worlds_parse) {
    static const char *names[] = {"finger_table.json", "capsule_pipe.json", "hand_handle.json",
                                  "finger_props.json"};
    static const int ncoll[] = {2, 1, 1, 2}, frames[] = {30, 30, 60, 30}, rest[] = {1, 0, 0, 0};
    for (int i = 0; i < 4; ++i) {
        char path[1024];
        snprintf(path, sizeof path, "%s/samples/worlds/%s", SINEW_SOURCE_DIR, names[i]);
        sw_world_file w;
        sw_error e;
        sw_error_clear(&e);
        sinew_result rc = sw_world_file_read(path, &w, &e);
        ENSUREF(rc == SINEW_OK, "%s: %s", names[i], e.msg);
        ENSURE(w.ncolliders == ncoll[i] && w.frames == frames[i] && w.rest_pose == rest[i]);
        ENSURE(sw_world_file_last_key_frame(&w) < w.frames);
        ENSURE(!strcmp(w.path, path));
        sw_world_file_free(&w);
    }
}

/* A collider with keys (frame, position x, rotation about z by angle a). */
static sw_world_collider_spec keyed(sw_world_key *k, int n, const int *frames, const double *x,
                                    const double *angle_deg) {
    sw_world_collider_spec c;
    memset(&c, 0, sizeof c);
    for (int i = 0; i < n; ++i) {
        double h = 0.5 * angle_deg[i] * 3.14159265358979323846 / 180.0;
        memset(&k[i], 0, sizeof k[i]);
        k[i].frame = frames[i];
        k[i].position[0] = x[i];
        k[i].position[1] = 2.0 * x[i];
        k[i].rotation[0] = cos(h);
        k[i].rotation[3] = sin(h);
    }
    c.keys = k;
    c.nkeys = n;
    return c;
}

static double angle_z_deg(const sinew_transform *t) {
    return 2.0 * atan2(t->rotation[3], t->rotation[0]) * 180.0 / 3.14159265358979323846;
}

TEST(keyframe_interpolation) {
    sw_world_key k[3];
    const int frames[3] = {10, 20, 40};
    const double x[3] = {1.0, 3.0, -1.0}, a[3] = {0.0, 90.0, 90.0};
    sw_world_collider_spec c = keyed(k, 3, frames, x, a);
    sinew_transform t;
    sw_world_collider_at(&c, 15.0, &t); /* midpoint of the first segment */
    ENSURE_NEAR(t.position[0], 2.0, 1e-6);
    ENSURE_NEAR(t.position[1], 4.0, 1e-6);
    ENSURE_NEAR(angle_z_deg(&t), 45.0, 1e-4);
    double n = 0;
    for (int i = 0; i < 4; ++i)
        n += (double)t.rotation[i] * t.rotation[i];
    ENSURE_NEAR(n, 1.0, 1e-6);
    sw_world_collider_at(&c, 12.5, &t); /* slerp is uniform in angle, not in chord */
    ENSURE_NEAR(angle_z_deg(&t), 22.5, 1e-4);
    ENSURE_NEAR(t.position[0], 1.5, 1e-6);
    sw_world_collider_at(&c, 30.0, &t);
    ENSURE_NEAR(t.position[0], 1.0, 1e-6);
    ENSURE_NEAR(angle_z_deg(&t), 90.0, 1e-4);
    sw_world_collider_at(&c, 20.0, &t); /* exactly on a key */
    ENSURE_NEAR(t.position[0], 3.0, 1e-6);
    sw_world_collider_at(&c, -5.0, &t); /* held before the first key */
    ENSURE(t.position[0] == 1.0f && t.rotation[0] == 1.0f);
    sw_world_collider_at(&c, NAN, &t);
    ENSURE(t.position[0] == 1.0f);
    sw_world_collider_at(&c, 1e9, &t); /* held after the last */
    ENSURE(t.position[0] == -1.0f);
    ENSURE_NEAR(angle_z_deg(&t), 90.0, 1e-4);
    /* no keys: identity at the origin */
    sw_world_collider_spec none;
    memset(&none, 0, sizeof none);
    sw_world_collider_at(&none, 3.0, &t);
    ENSURE(t.position[0] == 0 && t.rotation[0] == 1 && t.rotation[3] == 0);
}

TEST(slerp_takes_the_shortest_arc) {
    /* 170 degrees and -170 degrees about z are 20 degrees apart through 180. The second
     * key's quaternion is stored negated (w < 0) as well, which is the same rotation. */
    sw_world_key k[2];
    const int frames[2] = {0, 10};
    const double x[2] = {0, 0}, a[2] = {170.0, 190.0};
    sw_world_collider_spec c = keyed(k, 2, frames, x, a);
    for (int i = 0; i < 4; ++i)
        k[1].rotation[i] = -k[1].rotation[i];
    sinew_transform t;
    sw_world_collider_at(&c, 5.0, &t);
    double ang = fabs(angle_z_deg(&t));
    ENSUREF(fabs(ang - 180.0) < 1e-3, "midpoint at %g degrees", ang);
    sw_world_collider_at(&c, 2.5, &t);
    ang = angle_z_deg(&t);
    if (ang < 0) ang += 360.0;
    ENSURE_NEAR(ang, 175.0, 1e-3);
}

TEST(world_file_motion_from_text) {
    sw_world_file w;
    sw_error e;
    sinew_result rc =
        parse("{\"sinew_world\": 1, \"colliders\": [{\"name\": \"m\", \"shape\": \"sphere\", "
              "\"radius\": 1, \"motion\": [{\"frame\": 0, \"position\": [0, 0, 0], \"rotation\": "
              "[1, 0, 0, 0]}, {\"frame\": 4, \"position\": [4, 0, 0], \"rotation\": [0, 1, 0, "
              "0]}]}]}",
              NULL, &w, &e);
    ENSUREF(rc == SINEW_OK, "%s", e.msg);
    sinew_transform t;
    sw_world_collider_at(&w.colliders[0], 1.0, &t);
    ENSURE_NEAR(t.position[0], 1.0, 1e-6);
    ENSURE_NEAR(t.rotation[0], cos(3.14159265358979323846 / 8), 1e-6);
    ENSURE_NEAR(t.rotation[1], sin(3.14159265358979323846 / 8), 1e-6);
    sw_world_file_free(&w);
}

/* ---- error paths ----------------------------------------------------------------- */

typedef struct bad_case {
    const char *text;
    sinew_result code;
    const char *needles[4]; /* substrings the message must hold, besides the file name */
} bad_case;

#define HDR "{\"sinew_world\": 1, \"colliders\": ["
#define BALL "{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": 1"
#define K0 "{\"frame\": 0, \"position\": [0,0,0], \"rotation\": [1,0,0,0]}"

static const bad_case bad_cases[] = {
    {"{\"sinew_world\": 1, \"colliders\": [}", SINEW_ERROR_PARSE, {"1:34", "malformed JSON"}},
    {"{\"sinew_world\": 1,\n \"colliders\": [\n  {\"shape\" \"sphere\"}]}",
     SINEW_ERROR_PARSE,
     {"3:12", "malformed"}},
    {"", SINEW_ERROR_PARSE, {"empty"}},
    {"{\"sinew_world\": 1, \"colliders\": []} x", SINEW_ERROR_PARSE, {"1:37", "after"}},
    {"[1, 2]", SINEW_ERROR_INVALID_ARGUMENT, {"object"}},
    {"{\"colliders\": []}", SINEW_ERROR_INVALID_ARGUMENT, {"\"sinew_world\"", "missing"}},
    {"{\"sinew_world\": 2, \"colliders\": []}", SINEW_ERROR_VERSION, {"\"sinew_world\"", "2"}},
    {"{\"sinew_world\": 1.5, \"colliders\": []}", SINEW_ERROR_VERSION, {"\"sinew_world\""}},
    {"{\"sinew_world\": \"1\", \"colliders\": []}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"sinew_world\"", "number"}},
    {"{\"sinew_world\": 1}", SINEW_ERROR_INVALID_ARGUMENT, {"\"colliders\"", "missing"}},
    {"{\"sinew_world\": 1, \"colliders\": {}}", SINEW_ERROR_INVALID_ARGUMENT, {"\"colliders\""}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"colider\": 3}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"colider\"", "unknown key"}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"frames\": 0}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"frames\"", "integer"}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"frames\": 2.5}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"frames\""}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"pose\": \"still\"}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"pose\"", "\"rest\""}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"pose\": 1}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"pose\""}},
    {"{\"sinew_world\": 1, \"colliders\": [], \"colliders\": []}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"\"colliders\"", "repeated"}},
    {HDR "3]}", SINEW_ERROR_INVALID_ARGUMENT, {"collider #0", "object"}},
    {HDR "{\"radius\": 1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider #0", "\"shape\"", "missing"}},
    {HDR "{\"name\": \"x\", \"shape\": \"cube\"}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"x\" (#0)", "\"shape\"", "one of"}},
    {HDR "{\"name\": 7, \"shape\": \"sphere\", \"radius\": 1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider #0", "\"name\"", "string"}},
    {HDR "{\"name\": \"0123456789012345678901234567890123456789012345678901234567890123\", "
         "\"shape\": \"sphere\", \"radius\": 1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider #0", "\"name\"", "at most 63"}},
    {HDR BALL "}, " BALL "}]}", SINEW_ERROR_INVALID_ARGUMENT, {"(#1)", "\"name\"", "#0"}},
    {HDR BALL ", \"radius\": 2}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"radius\"", "repeated"}},
    {HDR BALL ", \"raduis\": 2}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"raduis\"", "unknown key"}},
    {HDR BALL ", \"half_extents\": [1,1,1]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"half_extents\"", "not a field of a sphere"}},
    {HDR "{\"name\": \"ball\", \"shape\": \"sphere\"}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"radius\"", "missing"}},
    {HDR "{\"shape\": \"sphere\", \"radius\": 1}, {\"name\": \"ball\", \"shape\": \"sphere\", "
         "\"radius\": -0.1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#1)", "\"radius\"", "must be a positive finite number"}},
    {HDR "{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": \"big\"}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"radius\"", "number"}},
    {HDR "{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": 1e999}]}",
     SINEW_ERROR_NOT_FINITE,
     {"collider \"ball\" (#0)", "\"radius\"", "finite"}},
    {HDR "{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": 1e300}]}",
     SINEW_ERROR_NOT_FINITE,
     {"collider \"ball\" (#0)", "\"radius\"", "float range"}},
    {HDR "{\"name\": \"bar\", \"shape\": \"capsule\", \"radius\": 1, \"half_height\": -1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"bar\" (#0)", "\"half_height\"", "non-negative"}},
    {HDR "{\"name\": \"wall\", \"shape\": \"box\", \"half_extents\": [1, 0, 1]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"wall\" (#0)", "\"half_extents\"", "positive"}},
    {HDR "{\"name\": \"wall\", \"shape\": \"box\", \"half_extents\": [1, 1]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"wall\" (#0)", "\"half_extents\"", "3 numbers"}},
    {HDR "{\"name\": \"wall\", \"shape\": \"box\", \"half_extents\": [1, -1e999, 1]}]}",
     SINEW_ERROR_NOT_FINITE,
     {"collider \"wall\" (#0)", "\"half_extents\"[1]", "finite"}},
    {HDR "{\"name\": \"floor\", \"shape\": \"plane\", \"normal\": [0, 0, 0], \"offset\": 0}]}",
     SINEW_ERROR_DEGENERATE,
     {"collider \"floor\" (#0)", "\"normal\"", "zero"}},
    {HDR "{\"name\": \"floor\", \"shape\": \"plane\", \"normal\": [0, 1, 0]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"floor\" (#0)", "\"offset\"", "missing"}},
    {HDR "{\"name\": \"rock\", \"shape\": \"hull\", \"points\": [[0,0,0], [1,0,0], [0,1,0]]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"rock\" (#0)", "\"points\"", "3 points"}},
    {HDR "{\"name\": \"rock\", \"shape\": \"hull\", \"points\": [[0,0,0], [1,0,0], [0,1,0], "
         "[1,1,0], [2,3,0]]}]}",
     SINEW_ERROR_DEGENERATE,
     {"collider \"rock\" (#0)", "\"points\"", "coplanar"}},
    {HDR "{\"name\": \"rock\", \"shape\": \"hull\", \"points\": [[0,0,0], [1,0,0], [0,1,0], "
         "[1,1]]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"rock\" (#0)", "\"points\"[3]", "3 numbers"}},
    {HDR "{\"name\": \"pipe\", \"shape\": \"mesh\", \"obj\": \"missing.obj\"}]}",
     SINEW_ERROR_IO,
     {"collider \"pipe\" (#0)", "\"obj\"", "missing.obj"}},
    {HDR "{\"name\": \"pipe\", \"shape\": \"mesh\", \"obj\": \"/abs.obj\"}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"pipe\" (#0)", "\"obj\"", "relative"}},
    {HDR "{\"name\": \"pipe\", \"shape\": \"mesh\", \"obj\": \"flat.obj\"}]}",
     SINEW_ERROR_DEGENERATE,
     {"collider \"pipe\" (#0)", "\"obj\"", "zero area"}},
    {HDR "{\"name\": \"pipe\", \"shape\": \"mesh\", \"obj\": \"broken.obj\"}]}",
     SINEW_ERROR_PARSE,
     {"collider \"pipe\" (#0)", "\"obj\"", "broken.obj:2"}},
    {HDR BALL ", \"stiffness\": -1}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"stiffness\"", "non-negative"}},
    {HDR BALL ", \"friction\": null}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"friction\"", "number"}},
    {HDR BALL ", \"motion\": []}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"", "0 keys"}},
    {HDR BALL ", \"motion\": {}}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"", "array"}},
    {HDR BALL ", \"motion\": [" K0 ", " K0 "]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[1]: \"frame\"", "strictly increase"}},
    {HDR BALL ", \"motion\": [{\"frame\": -1, \"position\": [0,0,0], \"rotation\": [1,0,0,0]}]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"frame\"", "integer"}},
    {HDR BALL ", \"motion\": [{\"frame\": 0.5, \"position\": [0,0,0], \"rotation\": [1,0,0,0]}]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"frame\"", "integer"}},
    {HDR BALL ", \"motion\": [{\"frame\": 0, \"rotation\": [1,0,0,0]}]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"position\"", "missing"}},
    {HDR BALL ", \"motion\": [{\"frame\": 0, \"position\": [0,0,0], \"rotation\": [0,0,0,0]}]}]}",
     SINEW_ERROR_DEGENERATE,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"rotation\"", "zero quaternion"}},
    {HDR BALL
     ", \"motion\": [{\"frame\": 0, \"position\": [0,1e999,0], \"rotation\": [1,0,0,0]}]}]}",
     SINEW_ERROR_NOT_FINITE,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"position\"[1]", "finite"}},
    {HDR BALL ", \"motion\": [{\"frame\": 0, \"position\": [0,0,0], \"rotation\": [1,0,0,0], "
              "\"scale\": 2}]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[0]: \"scale\"", "unknown key"}},
    {HDR BALL ", \"motion\": [3]}]}",
     SINEW_ERROR_INVALID_ARGUMENT,
     {"collider \"ball\" (#0)", "\"motion\"[0]", "object"}},
};

TEST(every_error_path_names_file_collider_and_field) {
    const char *dir = tmp_dir();
    ENSURE(dir && write_file(dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"));
    ENSURE(write_file(dir, "broken.obj", "v 0 0 0\nv 1 0\n"));
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; ++i) {
        const bad_case *b = &bad_cases[i];
        sw_world_file w;
        sw_error e;
        sinew_result rc = parse(b->text, dir, &w, &e);
        ENSUREF(rc == b->code, "case %zu: code %d, expected %d (%s)", i, rc, b->code, e.msg);
        ENSUREF(e.code == rc, "case %zu", i);
        ENSUREF(!strncmp(e.msg, "world.json: ", 12), "case %zu: '%s'", i, e.msg);
        for (int k = 0; k < 4 && b->needles[k]; ++k)
            ENSUREF(strstr(e.msg, b->needles[k]), "case %zu: '%s' lacks '%s'", i, e.msg,
                    b->needles[k]);
        ENSUREF(w.colliders == NULL && w.ncolliders == 0, "case %zu: output not zeroed", i);
    }
}

TEST(mesh_without_folder_is_unsupported) {
    sw_world_file w;
    sw_error e;
    sinew_result rc = parse(
        HDR "{\"name\": \"pipe\", \"shape\": \"mesh\", \"obj\": \"pipe.obj\"}]}", NULL, &w, &e);
    ENSUREF(rc == SINEW_ERROR_UNSUPPORTED && strstr(e.msg, "collider \"pipe\" (#0): \"obj\""),
            "%d %s", rc, e.msg);
}

TEST(size_limits) {
    /* 4097 colliders: rejected naming the limit */
    size_t cap = 64 + 4097 * 48;
    char *t = malloc(cap), *p = t;
    ENSURE(t);
    p += sprintf(p, "%s", HDR);
    for (int i = 0; i < 4097; ++i)
        p += sprintf(p, "%s{\"shape\": \"sphere\", \"radius\": 1}", i ? "," : "");
    sprintf(p, "]}");
    sw_world_file w;
    sw_error e;
    sinew_result rc = parse(t, NULL, &w, &e);
    ENSUREF(rc == SINEW_ERROR_INVALID_ARGUMENT && strstr(e.msg, "\"colliders\"") &&
                strstr(e.msg, "4096"),
            "%d %s", rc, e.msg);
    /* 4096 colliders are fine */
    for (p = t + strlen(t); memcmp(p, ",{", 2) != 0; --p) /* drop the last collider */
        ;
    sprintf(p, "]}");
    rc = parse(t, NULL, &w, &e);
    ENSUREF(rc == SINEW_OK && w.ncolliders == 4096, "%s", e.msg);
    ENSURE(!strcmp(w.colliders[4095].name, "collider4095"));
    sw_world_file_free(&w);
    free(t);
    /* 4097 hull points */
    cap = 128 + 4097 * 24;
    t = malloc(cap);
    ENSURE(t);
    p = t + sprintf(t, "%s{\"name\": \"rock\", \"shape\": \"hull\", \"points\": [", HDR);
    for (int i = 0; i < 4097; ++i)
        p += sprintf(p, "%s[%d,%d,%d]", i ? "," : "", i % 7, i % 11, i % 13);
    sprintf(p, "]}]}");
    rc = parse(t, NULL, &w, &e);
    ENSUREF(rc == SINEW_ERROR_INVALID_ARGUMENT && strstr(e.msg, "collider \"rock\" (#0)") &&
                strstr(e.msg, "\"points\"") && strstr(e.msg, "4097"),
            "%d %s", rc, e.msg);
    free(t);
    /* 100001 keys */
    cap = 128 + 100001 * 64;
    t = malloc(cap);
    ENSURE(t);
    p = t + sprintf(t, "%s%s, \"motion\": [", HDR, BALL);
    for (int i = 0; i < 100001; ++i)
        p += sprintf(p, "%s{\"frame\":%d,\"position\":[0,0,0],\"rotation\":[1,0,0,0]}",
                     i ? "," : "", i);
    sprintf(p, "]}]}");
    rc = parse(t, NULL, &w, &e);
    ENSUREF(rc == SINEW_ERROR_INVALID_ARGUMENT && strstr(e.msg, "\"motion\"") &&
                strstr(e.msg, "100001"),
            "%d %s", rc, e.msg);
    free(t);
}

TEST(read_errors_name_the_path) {
    sw_world_file w;
    sw_error e;
    sw_error_clear(&e);
    sinew_result rc = sw_world_file_read("/nonexistent/world.json", &w, &e);
    ENSUREF(rc == SINEW_ERROR_IO && strstr(e.msg, "/nonexistent/world.json"), "%s", e.msg);
    const char *dir = tmp_dir();
    ENSURE(dir && write_file(dir, "v2.json", "{\"sinew_world\": 2, \"colliders\": []}"));
    char path[1024];
    snprintf(path, sizeof path, "%s/v2.json", dir);
    rc = sw_world_file_read(path, &w, &e);
    ENSUREF(rc == SINEW_ERROR_VERSION && strstr(e.msg, path), "%s", e.msg);
    /* a mesh next to the world file is found through the file's folder */
    ENSURE(write_file(dir, "pipe.obj", pipe_obj));
    ENSURE(write_file(dir, "m.json", HDR "{\"shape\": \"mesh\", \"obj\": \"pipe.obj\"}]}"));
    snprintf(path, sizeof path, "%s/m.json", dir);
    rc = sw_world_file_read(path, &w, &e);
    ENSUREF(rc == SINEW_OK && w.colliders[0].def.triangle_count == 4, "%s", e.msg);
    sw_world_file_free(&w);
}

SW_TEST_MAIN(CASE(example_parses_to_the_right_defs),
             CASE(optional_fields_defaults_and_normalisation), CASE(sample_worlds_parse),
             CASE(keyframe_interpolation), CASE(slerp_takes_the_shortest_arc),
             CASE(world_file_motion_from_text),
             CASE(every_error_path_names_file_collider_and_field),
             CASE(mesh_without_folder_is_unsupported), CASE(size_limits),
             CASE(read_errors_name_the_path))
