/* The lattice mesher (io/tet_lattice.h): the generalised winding number of known
 * surfaces, the volume a closed, an open and an inside-out surface enclose, the tet
 * count against the target, orientation and quality of every tet, components, a real
 * render surface, and the error paths. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <unistd.h>

#include "mesh_io.h"
#include "surface_fixture.h"
#include "sw_test.h"
#include "tet_lattice.h"

/* Every tet positively oriented and not degenerate, every vertex used; *vol = the
 * volume. */
static void check_tets(const sw_tetmesh *t, double *vol_out) {
    *vol_out = 0;
    sw_quality q;
    sw_tetmesh_quality(t, 0, &q);
    ENSUREF(q.inverted == 0 && q.degenerate == 0, "%d inverted, %d degenerate", q.inverted,
            q.degenerate);
    /* Freudenthal tets of a cube: dihedral angles of 45, 60 and 90 degrees only */
    ENSUREF(q.min_dihedral_deg > 44.9 && q.max_dihedral_deg < 90.1, "dihedral %g..%g",
            q.min_dihedral_deg, q.max_dihedral_deg);
    unsigned char *used = calloc((size_t)t->nverts, 1);
    for (int64_t i = 0; i < 4 * (int64_t)t->ntets; ++i)
        used[t->tets[i]] = 1;
    for (int32_t v = 0; v < t->nverts; ++v)
        ENSUREF(used[v], "vertex %d is in no tet", v);
    free(used);
    double vol = 0;
    for (int32_t e = 0; e < t->ntets; ++e) {
        const int32_t *k = t->tets + 4 * e;
        double a[3], b[3], c[3], n[3];
        for (int i = 0; i < 3; ++i) {
            a[i] = t->X[3 * k[1] + i] - t->X[3 * k[0] + i];
            b[i] = t->X[3 * k[2] + i] - t->X[3 * k[0] + i];
            c[i] = t->X[3 * k[3] + i] - t->X[3 * k[0] + i];
        }
        n[0] = b[1] * c[2] - b[2] * c[1], n[1] = b[2] * c[0] - b[0] * c[2],
        n[2] = b[0] * c[1] - b[1] * c[0];
        vol += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6;
    }
    *vol_out = vol;
}

TEST(winding_number_of_a_closed_and_an_open_box) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh closed = boxes(1, lo, 1, -1), open = boxes(1, lo, 1, 5);
    double in[3] = {0.5, 0.5, 0.5}, out[3] = {2, 0.5, 0.5}, corner[3] = {0.1, 0.2, 0.3};
    ENSURE(fabs(sw_winding_number(&closed, in) - 1) < 1e-12);
    ENSURE(fabs(sw_winding_number(&closed, corner) - 1) < 1e-12);
    ENSURE(fabs(sw_winding_number(&closed, out)) < 1e-12);
    /* the missing top face takes its solid angle away: 1 - 1/6 seen from the centre */
    ENSUREF(fabs(sw_winding_number(&open, in) - 5.0 / 6) < 1e-9, "%.12f",
            sw_winding_number(&open, in));
    sw_trimesh_free(&closed);
    sw_trimesh_free(&open);
}

/* The dipole tree against the exact sum: a sphere and the arm's render surface, at
 * points inside, outside and near the surface: within 0.05 (first order at beta 4), and
 * the inside test (|w| >= 1/2) agrees wherever the exact value is not within 0.05 of
 * 1/2. */
TEST(winding_tree_matches_the_exact_sum) {
    sw_trimesh s = sphere(1.0, 24, 48), arm = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/arm-libigl/arm.obj", SINEW_SHARED_DATA_DIR);
    sw_error e;
    int have_arm = access(path, R_OK) == 0 && sw_read_obj(path, &arm, &e) == SINEW_OK;
    const sw_trimesh *cases[2] = {&s, &arm};
    for (int c = 0; c < 1 + have_arm; ++c) {
        const sw_trimesh *m = cases[c];
        sw_winding_tree *t = sw_winding_tree_create(m);
        ENSURE(t != NULL);
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int32_t v = 0; v < m->nverts; ++v)
            for (int a = 0; a < 3; ++a) {
                lo[a] = fmin(lo[a], m->X[3 * v + a]);
                hi[a] = fmax(hi[a], m->X[3 * v + a]);
            }
        uint64_t rng = 12345;
        double worst = 0;
        int disagree = 0, inside = 0;
        for (int i = 0; i < 2000; ++i) {
            double p[3];
            for (int a = 0; a < 3; ++a) { /* the box grown by a fifth each side */
                rng = rng * 6364136223846793005ull + 1442695040888963407ull;
                double u = (double)(rng >> 11) / 9007199254740992.0;
                p[a] = lo[a] + (hi[a] - lo[a]) * (1.4 * u - 0.2);
            }
            if (i % 4 == 0) { /* near a surface vertex */
                const double *x = m->X + 3 * (size_t)((rng >> 20) % (uint64_t)m->nverts);
                for (int a = 0; a < 3; ++a)
                    p[a] = x[a] +
                           0.01 * (hi[a] - lo[a]) * ((double)((rng >> (a * 8)) & 255) / 255 - 0.5);
            }
            double w = sw_winding_number(m, p), wt = sw_winding_tree_eval(t, p);
            worst = fmax(worst, fabs(w - wt));
            inside += fabs(w) >= 0.5;
            if (fabs(fabs(w) - 0.5) > 0.05) disagree += (fabs(w) >= 0.5) != (fabs(wt) >= 0.5);
        }
        fprintf(stderr,
                "    %s: %d triangles, tree error at most %.2e over 2000 points (%d inside)\n",
                c ? "arm" : "sphere", m->ntris, worst, inside);
        ENSUREF(worst < 0.05, "tree error %g", worst);
        ENSURE(disagree == 0);
        ENSURE(inside > 100);
        sw_winding_tree_destroy(t);
    }
    sw_trimesh_free(&arm);
    sw_trimesh_free(&s);
}

TEST(sphere_fills_to_its_volume_at_the_target_count) {
    sw_trimesh s = sphere(1.0, 24, 48);
    sw_pool *pool = sw_pool_create(2);
    const int32_t targets[] = {2000, 20000};
    for (int i = 0; i < 2; ++i) {
        sw_tetmesh t;
        sw_lattice_report rep;
        sw_error e;
        ENSUREF(sw_tetmesh_from_surface(&s, targets[i], pool, &t, &rep, &e) == SINEW_OK, "%s",
                e.msg);
        double vol, exact = 4.0 / 3 * SW_PI;
        check_tets(&t, &vol);
        fprintf(stderr,
                "    target %d: %d tets, %d vertices, spacing %.4g, volume %.4f (sphere %.4f, "
                "surface %.4f), %d component(s), %.3f s\n",
                targets[i], t.ntets, t.nverts, rep.spacing, vol, exact, rep.surface_volume,
                rep.components, rep.seconds);
        ENSURE(t.ntets <= 1.5 * targets[i] && t.ntets >= targets[i] / 1.5);
        ENSURE(fabs(vol - rep.volume) < 1e-9 * exact);
        /* the staircase's error shrinks with the spacing: a shell of a spacing's depth */
        ENSUREF(fabs(vol - exact) < 4 * SW_PI * rep.spacing, "volume %g against %g", vol, exact);
        ENSURE(rep.components == 1);
        ENSURE(fabs(rep.surface_volume - exact) < 0.01 * exact);
        sw_tetmesh_free(&t);
    }
    sw_pool_destroy(pool);
    sw_trimesh_free(&s);
}

TEST(open_and_inside_out_surfaces_are_filled) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh open = boxes(1, lo, 1, 3), flipped = boxes(1, lo, 1, -1);
    for (int32_t i = 0; i < flipped.ntris; ++i) { /* inside out */
        int32_t s = flipped.tris[3 * i + 1];
        flipped.tris[3 * i + 1] = flipped.tris[3 * i + 2];
        flipped.tris[3 * i + 2] = s;
    }
    const sw_trimesh *cases[2] = {&open, &flipped};
    for (int c = 0; c < 2; ++c) {
        sw_tetmesh t;
        sw_lattice_report rep;
        sw_error e;
        ENSUREF(sw_tetmesh_from_surface(cases[c], 6000, NULL, &t, &rep, &e) == SINEW_OK, "%s",
                e.msg);
        double vol;
        check_tets(&t, &vol);
        fprintf(stderr, "    %s box: %d tets, volume %.4f, surface volume %.4f\n",
                c ? "inside-out" : "open", t.ntets, vol, rep.surface_volume);
        ENSUREF(fabs(vol - 1) < 6 * rep.spacing, "volume %g", vol);
        ENSURE(rep.components == 1);
        sw_tetmesh_free(&t);
    }
    sw_trimesh_free(&open);
    sw_trimesh_free(&flipped);
}

TEST(separate_pieces_stay_separate) {
    double lo[2][3] = {{0, 0, 0}, {3, 0, 0}};
    sw_trimesh two = boxes(2, lo, 1, -1);
    sw_tetmesh t;
    sw_lattice_report rep;
    sw_error e;
    ENSUREF(sw_tetmesh_from_surface(&two, 4000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    double vol;
    check_tets(&t, &vol);
    ENSUREF(rep.components == 2, "%d components", rep.components);
    ENSUREF(fabs(vol - 2) < 12 * rep.spacing, "volume %g", vol);
    sw_tetmesh_free(&t);
    sw_trimesh_free(&two);
}

/* A thin shape (a tube one unit across, forty long) fills in steps as the spacing falls
 * (one cube across, then four): the cube rule alone jumped back and forth over such
 * targets and gave up, or kept the last count rather than the nearest. Every target gets
 * the nearest count, within a factor of 2 where it falls between the steps. */
TEST(a_thin_tube_fills_near_its_targets) {
    double lo[40][3];
    for (int i = 0; i < 40; ++i)
        lo[i][0] = i, lo[i][1] = lo[i][2] = 0;
    sw_trimesh tube = boxes(40, lo, 1.0, -1);
    sw_pool *pool = sw_pool_create(2);
    int filled = 0, tried = 0;
    for (int32_t target = 400; target <= 4000; target += 200, ++tried) {
        sw_tetmesh t;
        sw_lattice_report rep;
        sw_error e;
        if (sw_tetmesh_from_surface(&tube, target, pool, &t, &rep, &e) != SINEW_OK) {
            fprintf(stderr, "    %d: %s\n", target, e.msg);
            continue;
        }
        filled++;
        ENSURE(t.ntets <= 2 * target && t.ntets >= target / 2);
        sw_tetmesh_free(&t);
    }
    sw_pool_destroy(pool);
    sw_trimesh_free(&tube);
    fprintf(stderr, "    filled %d of %d targets\n", filled, tried);
    ENSURE(filled == tried);
}

TEST(real_render_surface) {
    char path[512];
    snprintf(path, sizeof path, "%s/arm-libigl/arm.obj", SINEW_SHARED_DATA_DIR);
    if (access(path, R_OK) != 0) {
        fprintf(stderr, "    skipped: %s not found\n", path);
        return;
    }
    sw_trimesh arm;
    sw_error e;
    ENSUREF(sw_read_obj(path, &arm, &e) == SINEW_OK, "%s", e.msg);
    sw_tetmesh t;
    sw_lattice_report rep;
    sw_pool *pool = sw_pool_create(2);
    ENSUREF(sw_tetmesh_from_surface(&arm, 3000, pool, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    sw_pool_destroy(pool);
    double vol;
    check_tets(&t, &vol);
    fprintf(stderr,
            "    arm (%d vertices, %d triangles): %d tets, volume %.4g, surface volume %.4g, %d "
            "component(s), %.2f s\n",
            arm.nverts, arm.ntris, t.ntets, vol, rep.surface_volume, rep.components, rep.seconds);
    ENSURE(t.ntets <= 4500 && t.ntets >= 2000);
    ENSUREF(fabs(vol - fabs(rep.surface_volume)) < 0.25 * fabs(rep.surface_volume),
            "volume %g against the surface's %g", vol, rep.surface_volume);
    sw_tetmesh_free(&t);
    sw_trimesh_free(&arm);
}

TEST(bad_surfaces_are_rejected) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh box = boxes(1, lo, 1, -1);
    sw_tetmesh t;
    sw_error e;
    ENSURE(sw_tetmesh_from_surface(&box, 99, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(t.ntets == 0 && t.tets == NULL);
    ENSURE(sw_tetmesh_from_surface(&box, 5000001, NULL, &t, NULL, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    sw_trimesh empty = {0};
    ENSURE(sw_tetmesh_from_surface(&empty, 1000, NULL, &t, NULL, &e) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    box.tris[4] = 8; /* out of range */
    ENSURE(sw_tetmesh_from_surface(&box, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(e.msg, "triangle 1") != NULL);
    box.tris[4] = 2;
    box.X[5] = NAN;
    ENSURE(sw_tetmesh_from_surface(&box, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    box.X[5] = 0;
    /* no area at all: every vertex at one point */
    sw_trimesh dot = boxes(1, lo, 1, -1);
    for (int32_t i = 0; i < 3 * dot.nverts; ++i)
        dot.X[i] = 0;
    ENSURE(sw_tetmesh_from_surface(&dot, 1000, NULL, &t, NULL, &e) == SINEW_ERROR_DEGENERATE);
    ENSURE(t.ntets == 0 && t.tets == NULL && t.X == NULL && strstr(e.msg, "no area"));
    sw_trimesh_free(&dot);
    sw_trimesh_free(&box);
}

/* Every tet's centre within the shell's half-thickness (plus a cube's half diagonal) of
 * the plane z = 0, and the volume near the sheet's area times the thickness. */
static void check_shell(const sw_tetmesh *t, const sw_lattice_report *rep, double area) {
    double vol = 0;
    for (int32_t k = 0; k < t->ntets; ++k) {
        const int32_t *v = t->tets + 4 * k;
        double z = 0;
        for (int c = 0; c < 4; ++c)
            z += 0.25 * t->X[3 * v[c] + 2];
        ENSURE(fabs(z) <= 0.5 * rep->shell + 0.87 * rep->spacing);
        vol += sw_tet_signed_volume(t->X + 3 * v[0], t->X + 3 * v[1], t->X + 3 * v[2],
                                    t->X + 3 * v[3]);
    }
    ENSUREF(vol > 0.5 * area * rep->shell && vol < 2.5 * area * rep->shell,
            "shell volume %g for area %g and thickness %g", vol, area, rep->shell);
}

/* A surface with no inside (SimpleSkin is a flat strip) is meshed as a shell:
 * a flat sheet (the unit box squashed to z = 0), the same flat but for rounding, and one
 * tilted triangle. */
TEST(a_surface_without_inside_becomes_a_shell) {
    double lo[1][3] = {{0, 0, 0}};
    sw_trimesh box = boxes(1, lo, 1, -1);
    for (int32_t v = 0; v < box.nverts; ++v) /* flat: every z = 0 (both faces coincide) */
        box.X[3 * v + 2] = 0;
    sw_tetmesh t;
    sw_lattice_report rep;
    sw_error e;
    ENSUREF(sw_tetmesh_from_surface(&box, 20000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    fprintf(stderr, "    flat sheet: %d tets, shell %.4f, spacing %.4f, %d piece(s)\n", t.ntets,
            rep.shell, rep.spacing, rep.components);
    ENSURE(rep.shell > 0 && fabs(rep.shell - 0.04 * sqrt(2.0)) < 1e-12);
    ENSURE(t.ntets >= 20000 / 1.5 && t.ntets <= 1.5 * 20000 && rep.components == 1);
    check_shell(&t, &rep, 1.0);
    sw_tetmesh_free(&t);
    for (int32_t v = 0; v < box.nverts; v += 2) /* flat to rounding: Blender's round trip */
        box.X[3 * v + 2] = 2.4e-7;
    ENSUREF(sw_tetmesh_from_surface(&box, 20000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    ENSURE(rep.shell > 0 && t.ntets >= 20000 / 1.5 && t.ntets <= 1.5 * 20000);
    check_shell(&t, &rep, 1.0);
    sw_tetmesh_free(&t);
    sw_trimesh tri = boxes(1, lo, 1, -1);
    tri.ntris = 1;
    tri.tris[0] = 0, tri.tris[1] = 3, tri.tris[2] = 5; /* (0,0,0), (1,1,0), (1,0,1) */
    ENSUREF(sw_tetmesh_from_surface(&tri, 1000, NULL, &t, &rep, &e) == SINEW_OK, "%s", e.msg);
    ENSURE(rep.shell > 0 && t.ntets >= 1000 / 1.5 && rep.components == 1);
    sw_tetmesh_free(&t);
    sw_trimesh_free(&tri);
    sw_trimesh_free(&box);
}

SW_TEST_MAIN(CASE(winding_number_of_a_closed_and_an_open_box),
             CASE(winding_tree_matches_the_exact_sum),
             CASE(sphere_fills_to_its_volume_at_the_target_count),
             CASE(open_and_inside_out_surfaces_are_filled), CASE(separate_pieces_stay_separate),
             CASE(a_thin_tube_fills_near_its_targets), CASE(real_render_surface),
             CASE(bad_surfaces_are_rejected), CASE(a_surface_without_inside_becomes_a_shell))
