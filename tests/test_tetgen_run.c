/* TetGen as a separate program (io/tetgen_run.h): a closed surface filled to its exact
 * volume with its own vertices on the boundary, seams welded, the count steered to the
 * target, and the errors: open and non-manifold surfaces, a self-intersecting one (TetGen's
 * own diagnosis quoted), a missing or failing program, bad arguments. Needs the Debian
 * `tetgen` program (tools/setup-debian.sh installs it). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_io.h"
#include "surface_fixture.h"
#include "sw_test.h"
#include "tetgen_run.h"

/* TetGen's files go to a folder of the bake's own under $TMPDIR: point TMPDIR at a fresh
 * folder, and `tmpdir_entries` tells afterwards whether anything was left behind. */
static char tmp_base[64];
static void private_tmpdir(void) {
    snprintf(tmp_base, sizeof tmp_base, "/tmp/test_tetgen_run-XXXXXX");
    if (!mkdtemp(tmp_base)) abort();
    setenv("TMPDIR", tmp_base, 1);
}
static int tmpdir_entries(void) {
    DIR *d = opendir(tmp_base);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));)
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d) closedir(d);
    return n;
}
static void end_private_tmpdir(void) {
    rmdir(tmp_base);
    unsetenv("TMPDIR");
}

/* A valid mesh (positive tets, indices in range), every vertex used, and every vertex of
 * `surf` a vertex of the mesh at the very same coordinates. */
static void check_conforming(const sw_tetmesh *t, const sw_trimesh *surf) {
    sw_error e;
    ENSUREF(sw_tetmesh_validate(t, 0, &e) == SINEW_OK, "%s", e.msg);
    unsigned char *used = calloc((size_t)t->nverts, 1);
    for (int64_t i = 0; i < 4 * (int64_t)t->ntets; ++i)
        used[t->tets[i]] = 1;
    int32_t unused = 0, missing = 0;
    for (int32_t v = 0; v < t->nverts; ++v)
        unused += !used[v];
    for (int32_t s = 0; s < surf->nverts; ++s) {
        int found = 0;
        for (int32_t v = 0; v < t->nverts && !found; ++v)
            found = !memcmp(t->X + 3 * (int64_t)v, surf->X + 3 * (int64_t)s, 3 * sizeof(double));
        missing += !found;
    }
    ENSUREF(unused == 0 && missing == 0, "%d unused vertices, %d surface vertices missing", unused,
            missing);
    free(used);
}

TEST(a_sphere_is_filled_to_its_exact_volume) {
    sw_trimesh s = sphere(1.0, 12, 24);
    sw_tetmesh t;
    sw_tetgen_report rep;
    sw_error e;
    private_tmpdir();
    ENSUREF(sw_tetmesh_by_tetgen(&s, 4000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    ENSUREF(tmpdir_entries() == 0, "TetGen's folder left in %s", tmp_base);
    sw_quality q;
    sw_tetmesh_quality(&t, 0, &q);
    fprintf(stderr,
            "    sphere (%d triangles): %d tets in %d run(s), bound %.4g, dihedral %.1f..%.1f, "
            "%d slivers, %.2f s\n",
            s.ntris, t.ntets, rep.runs, rep.max_volume, q.min_dihedral_deg, q.max_dihedral_deg,
            q.slivers, rep.seconds);
    check_conforming(&t, &s);
    double exact = sw_trimesh_signed_volume(&s); /* the polyhedron's, not the ball's */
    ENSUREF(fabs(rep.volume - exact) < 1e-12 * exact &&
                fabs(sw_tetmesh_volume(&t) - exact) < 1e-12 * exact,
            "volume %.17g against the surface's %.17g", rep.volume, exact);
    ENSUREF(t.ntets > 4000 / 1.25 && t.ntets < 4000 * 1.25, "%d tets for 4000", t.ntets);
    ENSURE(rep.welded_verts == s.nverts && q.inverted == 0 && q.degenerate == 0);
    sw_tetmesh_free(&t);
    /* a finer request gives more tets */
    ENSUREF(sw_tetmesh_by_tetgen(&s, 16000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    ENSUREF(t.ntets > 16000 / 1.25 && t.ntets < 16000 * 1.25, "%d tets for 16000", t.ntets);
    sw_tetmesh_free(&t);
    sw_trimesh_free(&s);
    end_private_tmpdir();
}

/* Render meshes split vertices at UV seams: a box whose every triangle has corners of its
 * own is one closed surface after welding. */
TEST(seams_are_welded) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh b = boxes(1, lo, 2.0, -1), split = {0};
    split.nverts = 3 * b.ntris;
    split.ntris = b.ntris;
    split.X = malloc(sizeof(double) * 3 * split.nverts);
    split.tris = malloc(sizeof(int32_t) * 3 * split.ntris);
    for (int32_t i = 0; i < 3 * b.ntris; ++i) {
        memcpy(split.X + 3 * i, b.X + 3 * b.tris[i], 3 * sizeof(double));
        split.tris[i] = i;
    }
    int32_t *w, n, open, nonmanifold, degenerate;
    sw_error e;
    ENSURE(sw_surface_closure(&split, &w, &n, &open, &nonmanifold, &degenerate, &e) == SINEW_OK);
    ENSUREF(n == 8 && open == 0 && nonmanifold == 0 && degenerate == 0, "%d %d %d %d", n, open,
            nonmanifold, degenerate);
    free(w);
    sw_tetmesh t;
    sw_tetgen_report rep;
    ENSUREF(sw_tetmesh_by_tetgen(&split, 1000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    check_conforming(&t, &split);
    ENSUREF(fabs(rep.volume - 8.0) < 1e-12 && rep.welded_verts == 8, "volume %.17g, %d welded",
            rep.volume, rep.welded_verts);
    sw_tetmesh_free(&t);
    sw_trimesh_free(&split);
    sw_trimesh_free(&b);
}

TEST(open_and_non_manifold_surfaces_are_refused) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh open_box = boxes(1, lo, 1.0, 5); /* no +z face: its 4 edges are open */
    sw_tetmesh t;
    sw_error e;
    ENSURE(sw_tetmesh_by_tetgen(&open_box, 1000, NULL, &t, NULL, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "not closed") && strstr(e.msg, "4 open") && strstr(e.msg, "lattice"),
            "%s", e.msg);
    ENSURE(t.ntets == 0 && t.X == NULL);
    /* a fin on one of a closed box's edges: that edge is shared by three triangles */
    sw_trimesh fin = boxes(1, lo, 1.0, -1);
    fin.X = realloc(fin.X, sizeof(double) * 3 * 9);
    fin.tris = realloc(fin.tris, sizeof(int32_t) * 3 * 13);
    fin.X[24] = 0.5, fin.X[25] = -1, fin.X[26] = 0.5;
    fin.tris[36] = 0, fin.tris[37] = 1, fin.tris[38] = 8; /* on edge 0-1 */
    fin.nverts = 9, fin.ntris = 13;
    int32_t *w, n, open, nonmanifold, degenerate;
    ENSURE(sw_surface_closure(&fin, &w, &n, &open, &nonmanifold, &degenerate, &e) == SINEW_OK);
    ENSUREF(open == 2 && nonmanifold == 1 && degenerate == 0, "%d open, %d non-manifold", open,
            nonmanifold);
    free(w);
    ENSURE(sw_tetmesh_by_tetgen(&fin, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "1 non-manifold"), "%s", e.msg);
    sw_trimesh_free(&fin);
    sw_trimesh_free(&open_box);
}

/* Two overlapping closed boxes as one surface: TetGen refuses it, and the message quotes
 * its diagnosis of the intersecting faces. */
TEST(a_self_intersecting_surface_is_refused_with_tetgens_reason) {
    double lo[2][3] = {{0, 0, 0}, {0.5, 0.5, 0.5}};
    sw_trimesh two = boxes(2, lo, 1.0, -1);
    sw_tetmesh t;
    sw_error e;
    private_tmpdir();
    ENSURE(sw_tetmesh_by_tetgen(&two, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_IO);
    ENSUREF(strstr(e.msg, "failed") && strstr(e.msg, "intersect"), "%s", e.msg);
    /* the diagnosing run writes files of its own (surface.1.smesh): they go too */
    ENSUREF(tmpdir_entries() == 0, "TetGen's folder left in %s", tmp_base);
    end_private_tmpdir();
    ENSURE(t.ntets == 0 && t.X == NULL);
    sw_trimesh_free(&two);
}

TEST(a_missing_or_failing_program_and_bad_arguments) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh b = boxes(1, lo, 1.0, -1);
    sw_tetmesh t;
    sw_error e;
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, "/nonexistent/tetgen", &t, NULL, &e) == SINEW_ERROR_IO);
    ENSUREF(strstr(e.msg, "cannot run") && strstr(e.msg, "/nonexistent/tetgen"), "%s", e.msg);
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, "false", &t, NULL, &e) == SINEW_ERROR_IO);
    ENSUREF(strstr(e.msg, "'false' failed (exit 1)"), "%s", e.msg);
    ENSURE(sw_tetmesh_by_tetgen(&b, 99, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, NULL, NULL, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    b.X[4] = NAN;
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    b.X[4] = 0;
    b.tris[7] = 8;
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    b.tris[7] = 1;
    for (int32_t i = 0; i < 3 * b.nverts; ++i) /* every vertex at one point: no volume */
        b.X[i] = 1;
    ENSURE(sw_tetmesh_by_tetgen(&b, 1000, NULL, &t, NULL, &e) != SINEW_OK);
    ENSURE(t.ntets == 0 && t.X == NULL);
    sw_trimesh_free(&b);
}

SW_TEST_MAIN(CASE(a_sphere_is_filled_to_its_exact_volume), CASE(seams_are_welded),
             CASE(open_and_non_manifold_surfaces_are_refused),
             CASE(a_self_intersecting_surface_is_refused_with_tetgens_reason),
             CASE(a_missing_or_failing_program_and_bad_arguments))
