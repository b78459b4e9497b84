/* A simulation character from a glTF/FBX file (precompute/import/scene_character.h): the
 * clip split (default, by name, disjoint, unknown and repeated names rejected naming the
 * file's clips), the material relative to the size, weights transferred from a render
 * surface, and the Fox built at a small tet count (counts, weight rows, driven vertices
 * of every bone that skins flesh, none for a bone that skins nothing, every mesh piece
 * anchored, the render mesh kept, the held-out clip as the character's clip). */
#include <math.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "embed.h"
#include "mesh_io.h"
#include "rig.h"
#include "scene_character.h"
#include "sw_test.h"

static const char names[5][64] = {"Idle", "Walk", "Run", "Jump", "Wave"};
static const int32_t frames[5] = {100, 29, 35, 22, 56};

TEST(split_default_takes_the_longest) {
    int32_t ti[5], hi[5], nt, nh;
    sw_error e;
    ENSURE(sw_clip_split_choose(names, frames, 5, NULL, NULL, ti, &nt, hi, &nh, &e) == SINEW_OK);
    ENSURE(nt == 2 && ti[0] == 0 && ti[1] == 4); /* Idle 100, Wave 56 */
    ENSURE(nh == 1 && hi[0] == 2);               /* Run 35 */
    /* one clip alone trains (the bake then holds out its last part) */
    ENSURE(sw_clip_split_choose(names, frames, 1, NULL, NULL, ti, &nt, hi, &nh, &e) == SINEW_OK);
    ENSURE(nt == 1 && ti[0] == 0 && nh == 0);
    /* no clip: nothing to split */
    ENSURE(sw_clip_split_choose(names, frames, 0, NULL, NULL, ti, &nt, hi, &nh, &e) == SINEW_OK);
    ENSURE(nt == 0 && nh == 0);
}

TEST(split_honours_names_and_is_disjoint) {
    int32_t ti[5], hi[5], nt, nh;
    sw_error e;
    ENSURE(sw_clip_split_choose(names, frames, 5, "Walk, Jump", "Run", ti, &nt, hi, &nh, &e) ==
           SINEW_OK);
    ENSURE(nt == 2 && ti[0] == 1 && ti[1] == 3);
    ENSURE(nh == 1 && hi[0] == 2);
    /* a held-out list alone: training defaults to the longest clips it leaves */
    ENSURE(sw_clip_split_choose(names, frames, 5, NULL, "Idle", ti, &nt, hi, &nh, &e) == SINEW_OK);
    ENSURE(nh == 1 && hi[0] == 0);
    ENSURE(nt == 2 && ti[0] == 4 && ti[1] == 2);
    for (int32_t a = 0; a < nt; ++a)
        for (int32_t b = 0; b < nh; ++b)
            ENSURE(ti[a] != hi[b]);
    /* a training list alone: the longest clip it leaves is held out */
    ENSURE(sw_clip_split_choose(names, frames, 5, "Run", NULL, ti, &nt, hi, &nh, &e) == SINEW_OK);
    ENSURE(nt == 1 && ti[0] == 2 && nh == 1 && hi[0] == 0);
}

TEST(split_rejects_bad_names) {
    int32_t ti[5], hi[5], nt, nh;
    sw_error e;
    sw_error_clear(&e);
    ENSURE(sw_clip_split_choose(names, frames, 5, "Walk,Sprint", NULL, ti, &nt, hi, &nh, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "'Sprint'") && strstr(e.msg, "Idle, Walk, Run, Jump, Wave"), "%s", e.msg);
    ENSURE(nt == 0 && nh == 0);
    ENSURE(sw_clip_split_choose(names, frames, 5, "Walk", "Walk", ti, &nt, hi, &nh, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "'Walk' is given twice"), "%s", e.msg);
    ENSURE(sw_clip_split_choose(names, frames, 5, "Walk,,Run", NULL, ti, &nt, hi, &nh, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "empty clip name"), "%s", e.msg);
    ENSURE(sw_clip_split_choose(names, frames, 0, "Walk", NULL, ti, &nt, hi, &nh, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_clip_split_choose(names, frames, 2, NULL, "Idle,Walk", ti, &nt, hi, &nh, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "none is left to train on"), "%s", e.msg);
}

/* Every dimensionless group of the bake stays the finger's: E / L and rho L constant. */
TEST(material_scales_with_size) {
    double e1, n1, r1, e2, n2, r2;
    sw_scene_material(1.5, &e1, &n1, &r1);
    sw_scene_material(155.0, &e2, &n2, &r2);
    ENSURE_NEAR(e2 / e1, 155.0 / 1.5, 1e-9);
    ENSURE_NEAR(r2 * 155.0, r1 * 1.5, 1e-12);
    ENSURE(n1 == n2 && n1 > 0 && n1 < 0.5);
}

/* A cube surface weighted by x (bone 0 at x = 0, bone 1 at x = 1): the tets' vertices
 * take the interpolated weights, rows sum to 1, and a vertex on a face keeps the face's. */
TEST(weights_follow_the_render_surface) {
    static double X[24];
    static int32_t tris[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                               2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    static double w[16];
    for (int v = 0; v < 8; ++v) {
        X[3 * v] = (v == 1 || v == 2 || v == 5 || v == 6);
        X[3 * v + 1] = (v == 2 || v == 3 || v == 6 || v == 7);
        X[3 * v + 2] = v >= 4;
        w[2 * v] = 1 - X[3 * v];
        w[2 * v + 1] = X[3 * v];
    }
    sw_trimesh surf = {8, 12, X, tris};
    sw_weights sw = {8, 2, w}, out;
    sw_tetmesh m;
    sw_error e;
    ENSURE(sw_tetmesh_from_surface(&surf, 500, NULL, &m, NULL, &e) == SINEW_OK);
    ENSURE(sw_weights_from_surface(&m, &surf, &sw, &out, &e) == SINEW_OK);
    ENSURE(out.nverts == m.nverts && out.nbones == 2);
    for (int32_t v = 0; v < m.nverts; ++v) {
        const double *r = out.w + 2 * v;
        ENSURE_NEAR(r[0] + r[1], 1.0, 1e-12);
        if (m.X[3 * v] < 1e-9) ENSURE_NEAR(r[0], 1.0, 1e-9);
        if (m.X[3 * v] > 1 - 1e-9) ENSURE_NEAR(r[1], 1.0, 1e-9);
    }
    sw_weights_free(&out);
    sw_tetmesh_free(&m);
}

/* Union-find over tet vertices: the piece (root) of every vertex. */
static int32_t root_of(int32_t *up, int32_t v) {
    while (up[v] != v)
        v = up[v] = up[up[v]];
    return v;
}

/* Every piece of the tet mesh has a driven vertex. */
static int every_piece_anchored(const sw_character *c) {
    int32_t n = c->mesh.nverts, *up = malloc(sizeof(int32_t) * (size_t)n);
    unsigned char *held = calloc((size_t)n, 1), *used = calloc((size_t)n, 1);
    for (int32_t v = 0; v < n; ++v)
        up[v] = v;
    for (int32_t t = 0; t < c->mesh.ntets; ++t)
        for (int k = 0; k < 4; ++k) {
            int32_t a = root_of(up, c->mesh.tets[4 * t]), b = root_of(up, c->mesh.tets[4 * t + k]);
            up[b] = a;
            used[c->mesh.tets[4 * t + k]] = 1;
        }
    for (int32_t v = 0; v < n; ++v)
        if (c->bone_of_vertex[v] >= 0) held[root_of(up, v)] = 1;
    int ok = 1;
    for (int32_t v = 0; v < n; ++v)
        if (used[v] && !held[root_of(up, v)]) ok = 0;
    free(up);
    free(held);
    free(used);
    return ok;
}

/* The Fox at 2,000 tets by `mesher`, Survey and Walk training, Run held out (a failure
 * is counted and *rc says it). */
static void fox(sw_mesher mesher, sw_character *c, sw_clip_split *clips,
                sw_scene_character_info *info, sinew_result *rc_out) {
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf-fox/Fox.glb", SINEW_SHARED_DATA_DIR);
    sw_scene_character_options o = {2000, 0, 0, "Survey,Walk", "Run", mesher};
    sw_error e;
    *rc_out = sw_character_from_scene(path, &o, c, clips, info, &e);
    ENSUREF(*rc_out == SINEW_OK, "%s", e.msg);
}

TEST(fox_character) {
    NEED_DATA("gltf-fox/Fox.glb");
    sw_character c;
    sw_clip_split clips;
    sw_scene_character_info info;
    sinew_result rc;
    fox(SW_MESHER_LATTICE, &c, &clips, &info, &rc);
    if (rc) return;
    ENSURE(c.mesh.ntets > 1000 && c.mesh.ntets < 3000);
    ENSURE(c.skel.nbones == 24 && c.weights.nverts == c.mesh.nverts && c.weights.nbones == 24);
    ENSURE(c.render.nverts == 1728 && c.render.ntris == 576);
    ENSURE(clips.ntrain == 2 && clips.nheldout == 1);
    ENSURE(!strcmp(clips.train_names[0], "Survey") && !strcmp(clips.heldout_names[0], "Run"));
    ENSURE(c.clip.nframes == clips.heldout[0].nframes && c.clip.nframes == 35);
    ENSURE(c.youngs > 0 && c.density > 0 && info.size > 10); /* file units: ~155 long */
    int32_t *driven = calloc(24, sizeof(int32_t)), *dominates = calloc(24, sizeof(int32_t));
    for (int32_t v = 0; v < c.mesh.nverts; ++v) {
        const double *r = c.weights.w + (size_t)v * 24;
        double sum = 0;
        int32_t best = 0;
        for (int32_t b = 0; b < 24; ++b) {
            ENSURE(r[b] >= 0);
            sum += r[b];
            if (r[b] > r[best]) best = b;
        }
        ENSURE_NEAR(sum, 1.0, 1e-9);
        dominates[best]++;
        if (c.bone_of_vertex[v] >= 0) driven[c.bone_of_vertex[v]]++;
    }
    int32_t undriven = 0;
    for (int32_t b = 0; b < 24; ++b) {
        /* a bone that is some vertex's strongest drives at least 4; one that skins nothing
           most drives none, except a tet's corners when it anchors a loose piece */
        if (dominates[b]) ENSUREF(driven[b] >= 4, "bone %d drives %d", b, driven[b]);
        undriven += !dominates[b];
    }
    ENSURE(undriven == info.undriven_bones && undriven >= 1); /* the root joints */
    ENSURE(every_piece_anchored(&c));
    free(driven);
    free(dominates);
    sw_clip_split_free(&clips);
    sw_character_free(&c);
}

/* TetGen fills the Fox's closed render surface: the tet mesh holds
 * exactly the volume the surface encloses and its boundary is that surface, so every render
 * vertex embeds inside a tet (none outside, no barycentric beyond [0, 1]); the robot's
 * render mesh (19 open primitives) is refused, naming the file and the open edges. */
TEST(tetgen_fills_the_fox_and_refuses_the_robot) {
    NEED_DATA("gltf-fox/Fox.glb");
    sw_character c;
    sw_scene_character_info info;
    sw_error e;
    sinew_result rc;
    fox(SW_MESHER_TETGEN, &c, NULL, &info, &rc);
    if (rc) return;
    double vs = fabs(sw_trimesh_signed_volume(&c.render)), vt = sw_tetmesh_volume(&c.mesh);
    fprintf(stderr, "    Fox by tetgen: %d tets (floor of its sharp features), %d run(s), %.2f s\n",
            c.mesh.ntets, info.mesh.tetgen.runs, info.mesh.tetgen.seconds);
    ENSURE(info.mesh.mesher == SW_MESHER_TETGEN && info.mesh.tetgen.welded_verts == 290);
    /* (TetGen writes its points with 16 significant digits) */
    ENSUREF(fabs(vt - vs) < 1e-6 * vs, "tets %.17g against the surface's %.17g", vt, vs);
    sw_embedding emb;
    ENSUREF(sw_embed_render(&c.mesh, &c.render, &emb, &e) == SINEW_OK, "%s", e.msg);
    ENSUREF(emb.outside == 0 && emb.max_bary <= 1 + 1e-6, "%d outside, |b| %g", emb.outside,
            emb.max_bary);
    sw_embedding_free(&emb);
    sw_character_free(&c);
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf-robot-quaternius/robot.glb", SINEW_SHARED_DATA_DIR);
    if (access(path, R_OK) != 0) return;
    sw_scene_character_options o = {2000, 0, 0, NULL, NULL, SW_MESHER_TETGEN};
    ENSURE(sw_character_from_scene(path, &o, &c, NULL, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "robot.glb") && strstr(e.msg, "not closed"), "%s", e.msg);
    o.mesher = (sw_mesher)7;
    ENSURE(sw_character_from_scene(path, &o, &c, NULL, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "unknown mesher"), "%s", e.msg);
}

TEST(bad_inputs_name_the_file) {
    sw_character c;
    sw_error e;
    sw_scene_character_options o = {50, 0, 0, NULL, NULL, SW_MESHER_LATTICE};
    ENSURE(sw_character_from_scene("x.glb", &o, &c, NULL, NULL, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "x.glb") && strstr(e.msg, "100..5000000"), "%s", e.msg);
    ENSURE(sw_character_from_scene("/nonexistent/a.glb", NULL, &c, NULL, NULL, &e) != SINEW_OK);
    ENSUREF(strstr(e.msg, "/nonexistent/a.glb"), "%s", e.msg);
    NEED_DATA("gltf-fox/Fox.glb");
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf-fox/Fox.glb", SINEW_SHARED_DATA_DIR);
    sw_scene_character_options bad = {2000, 0, 0, "Survey", "Gallop", SW_MESHER_LATTICE};
    ENSURE(sw_character_from_scene(path, &bad, &c, NULL, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "Fox.glb") && strstr(e.msg, "'Gallop'") &&
                strstr(e.msg, "Survey, Walk, Run"),
            "%s", e.msg);
}

SW_TEST_MAIN(CASE(split_default_takes_the_longest), CASE(split_honours_names_and_is_disjoint),
             CASE(split_rejects_bad_names), CASE(material_scales_with_size),
             CASE(weights_follow_the_render_surface), CASE(fox_character),
             CASE(tetgen_fills_the_fox_and_refuses_the_robot), CASE(bad_inputs_name_the_file))
