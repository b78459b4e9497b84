/* Asset readers and writers on small synthetic files (Medit, TetGen, OBJ, TGF, DMAT),
 * surface extraction and the quality report: every error path with its code and
 * "path:line:" message, the from-memory parsers, and round trips of every writer. The
 * real assets of ../shared/data, a truncation sweep over one and random byte flips are in
 * test_mesh_io_real.c; the shared fixtures in mesh_io_fixture.h. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>

#include "mesh_io.h"
#include "sw_test.h"

#include "mesh_io_fixture.h"

#define SW_PI 3.14159265358979323846

/* ---- Medit --------------------------------------------------------------------- */

TEST(medit_reads_small_mesh) {
    sw_tetmesh m;
    sw_error e;
    sw_error_clear(&e);
    ENSURE(sw_read_medit(write_text("ok.mesh", k_medit), &m, &e) == SINEW_OK);
    ENSURE(m.nverts == 5 && m.ntets == 2);
    ENSURE(m.X[3 * 4] == 1.0 && m.X[3 * 4 + 2] == 1.0);
    const int32_t want[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    ENSURE(memcmp(m.tets, want, sizeof want) == 0);
    ENSURE_NEAR(total_volume(&m), 1.0 / 6 + 2.0 / 6, 1e-15);
    sw_tetmesh_free(&m);
    /* the dispatcher picks Medit by extension */
    ENSURE(sw_read_tetmesh(tmp_path("ok.mesh"), &m, &e) == SINEW_OK && m.ntets == 2);
    sw_tetmesh_free(&m);
    ENSURE(sw_read_tetmesh(tmp_path("ok.stl"), &m, &e) == SINEW_ERROR_UNSUPPORTED);
}

TEST(medit_reorients_negative_tets) {
    char *s = replace(k_medit, "2 3 4 5 1\n", "3 2 4 5 1\n");
    sw_tetmesh m;
    sw_error e;
    sinew_result rc = sw_read_medit(write_text("neg.mesh", s), &m, &e);
    free(s);
    ENSURE(rc == SINEW_OK);
    const int32_t *q = m.tets + 4;
    /* file (3,2,4,5) = 0-based (2,1,3,4), negative; 2nd and 3rd swapped */
    ENSUREF(q[0] == 2 && q[1] == 3 && q[2] == 1 && q[3] == 4, "got %d %d %d %d", q[0], q[1], q[2],
            q[3]);
    ENSURE(sw_tet_signed_volume(m.X + 3 * q[0], m.X + 3 * q[1], m.X + 3 * q[2], m.X + 3 * q[3]) >
           0);
    ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
    sw_tetmesh_free(&m);
}

/* One malformed variant of the Medit file: the replacement, the expected code, line
 * and an extra word the message must contain. */
typedef struct bad_case {
    const char *from, *to;
    sinew_result code;
    int line;
    const char *word;
} bad_case;

TEST(medit_rejects_malformed) {
    static const bad_case cases[] = {
        {"0.000000 1.000000 0.000000 0", "0.000000 abc 0.000000 0", SINEW_ERROR_PARSE, 7, "abc"},
        {"1.000000 0.000000 0.000000 0", "1.000000 nan 0.000000 0", SINEW_ERROR_NOT_FINITE, 6,
         "finite"},
        {"0.000000 0.000000 1.000000 0", "0.000000 0.000000 -inf 0", SINEW_ERROR_NOT_FINITE, 8,
         "finite"},
        {"0.000000 0.000000 1.000000 0", "0.000000 0.000000 1e999 0", SINEW_ERROR_NOT_FINITE, 8,
         "finite"},
        {"Vertices\n5\n", "Vertices\n-5\n", SINEW_ERROR_PARSE, 4, "negative"},
        {"Vertices\n5\n", "Vertices\n2000000000\n", SINEW_ERROR_PARSE, 4, "absurd"},
        {"Vertices\n5\n", "Vertices\n500000\n", SINEW_ERROR_PARSE, 4, "bytes"},
        {"Vertices\n5\n", "Vertices\n5x\n", SINEW_ERROR_PARSE, 4, "5x"},
        {"Tetrahedra\n2\n", "Tetrahedra\n99999999999\n", SINEW_ERROR_PARSE, 15, "absurd"},
        {"2 3 4 5 1\n", "2 3 4 0 1\n", SINEW_ERROR_PARSE, 17, "1-based"},
        {"2 3 4 5 1\n", "2 3 4 6 1\n", SINEW_ERROR_PARSE, 17, "1-based"},
        {"1 2 3 4 1\n", "1 2 -3 4 1\n", SINEW_ERROR_PARSE, 16, "1-based"},
        {"2 3 4 5 1\n", "2 3 3 5 1\n", SINEW_ERROR_DEGENERATE, 17, "repeats"},
        {"1.000000 1.000000 1.000000 0", "0.5 0.5 0 0", SINEW_ERROR_DEGENERATE, 17, "volume"},
        {"2 3 4 5 1\n", "2 3 4 5.0 1\n", SINEW_ERROR_PARSE, 17, "5.0"},
        {"Triangles\n1\n1 2 3 0\n", "Triangles\n1\n1 2 zz 0\n", SINEW_ERROR_PARSE, 12, "zz"},
        {"Edges\n", "Bogus\n", SINEW_ERROR_PARSE, 18, "Bogus"},
        {"Dimension 3", "Dimension 2", SINEW_ERROR_PARSE, 2, "3D"},
        /* finite coordinates whose volume overflows (it was accepted as +inf) */
        {"1.000000 0.000000 0.000000 0\n0.000000 1.000000 0.000000 0\n0.000000 0.000000 "
         "1.000000 0",
         "1e200 0 0 0\n0 1e200 0 0\n0 0 1e200 0", SINEW_ERROR_NOT_FINITE, 16, "overflows"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char *s = replace(k_medit, cases[i].from, cases[i].to);
        const char *p = write_text("bad.mesh", s);
        free(s);
        sw_tetmesh m;
        sw_error e;
        sw_error_clear(&e);
        sinew_result rc = sw_read_medit(p, &m, &e);
        ENSUREF(err_is(rc, &e, cases[i].code, p, cases[i].line), "case %zu", i);
        ENSUREF(has(&e, cases[i].word), "case %zu", i);
        ENSURE(all_zero(&m, sizeof m));
    }
}

TEST(medit_rejects_truncated_and_missing) {
    sw_tetmesh m;
    sw_error e;
    const char *p = tmp_path("does_not_exist.mesh");
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_IO, p, 0));
    ENSURE(all_zero(&m, sizeof m));
    /* cut before the 5th vertex: 4 of 5 present, the file ends on line 8 */
    const char *cut = strstr(k_medit, "1.000000 1.000000 1.000000 0");
    p = write_bytes("trunc.mesh", k_medit, (size_t)(cut - k_medit));
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 8));
    ENSURE(has(&e, "end of file") && all_zero(&m, sizeof m));
    /* cut inside the 5th vertex line */
    p = write_bytes("trunc2.mesh", k_medit, (size_t)(cut - k_medit) + 9);
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 9));
    ENSURE(has(&e, "end of file"));
    /* cut after the first tet: 2 declared, 1 present, and too few bytes for the 2nd */
    cut = strstr(k_medit, "2 3 4 5 1\n");
    p = write_bytes("trunc3.mesh", k_medit, (size_t)(cut - k_medit));
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 15));
    /* no Tetrahedra block at all */
    cut = strstr(k_medit, "Tetrahedra");
    p = write_bytes("notets.mesh", k_medit, (size_t)(cut - k_medit));
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 13));
    ENSURE(has(&e, "Tetrahedra"));
    p = write_text("empty.mesh", "");
    ENSURE(err_is(sw_read_medit(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 1));
}

/* ---- TetGen -------------------------------------------------------------------- */

static sinew_result read_tg(const char *node, const char *ele, sw_tetmesh *m, sw_error *e,
                            const char **np, const char **ep) {
    *np = write_text("t.node", node);
    *ep = write_text("t.ele", ele);
    return sw_read_tetgen(*np, *ep, m, e);
}

TEST(tetgen_reads_both_bases) {
    sw_tetmesh m;
    sw_error e;
    const char *np, *ep;
    ENSURE(read_tg(k_node1, k_ele1, &m, &e, &np, &ep) == SINEW_OK);
    ENSURE(m.nverts == 5 && m.ntets == 2 && m.X[3 * 4 + 1] == 1.0);
    ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
    ENSURE(m.tets[4] == 2 && m.tets[5] == 3 && m.tets[6] == 1 && m.tets[7] == 4); /* reoriented */
    ENSURE_NEAR(total_volume(&m), 0.5, 1e-15);
    sw_tetmesh_free(&m);
    /* dispatch from either sibling */
    ENSURE(sw_read_tetmesh(np, &m, &e) == SINEW_OK && m.ntets == 2);
    sw_tetmesh_free(&m);
    ENSURE(sw_read_tetmesh(ep, &m, &e) == SINEW_OK && m.ntets == 2);
    sw_tetmesh_free(&m);
    /* 0-based (tetgen -z), no attributes, 10-node tets (corners first) */
    const char *node0 = "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n";
    const char *ele0 = "2 10\n0 0 1 2 3 0 0 0 0 0 0\n1 1 2 3 4 1 1 1 1 1 1\n";
    ENSURE(read_tg(node0, ele0, &m, &e, &np, &ep) == SINEW_OK);
    ENSURE(m.tets[0] == 0 && m.tets[3] == 3 && m.tets[7] == 4);
    sw_tetmesh_free(&m);
}

TEST(tetgen_rejects_malformed) {
    sw_tetmesh m;
    sw_error e;
    const char *np, *ep;
    struct {
        const char *node, *ele;
        sinew_result code;
        int in_ele, line;
        const char *word;
    } cases[] = {
        {"4 0 0 1 7.5 1\n", NULL, SINEW_ERROR_PARSE, 0, 6, "end of file"},
        {"2 1 0 0 7.5 1\n", "3 1 0 0 7.5 1\n", SINEW_ERROR_PARSE, 0, 4, "consecutive"},
        {"1 0 0 0 7.5 1\n", "2 0 0 0 7.5 1\n", SINEW_ERROR_PARSE, 0, 3, "0 or 1"},
        {"4 0 0 1 7.5 1\n", "4 0 0 nan 7.5 1\n", SINEW_ERROR_NOT_FINITE, 0, 7, "finite"},
        {"4 0 0 1 7.5 1\n", "4 0 0 1 7.5\n", SINEW_ERROR_PARSE, 0, 7, "boundary marker"},
        {"4 0 0 1 7.5 1\n", "4 0 0 1 7.5 1 9\n", SINEW_ERROR_PARSE, 0, 7, "'9'"},
        {"5 3 1 1\n", "5 2 1 1\n", SINEW_ERROR_PARSE, 0, 2, "dimension"},
        {"5 3 1 1\n", "-5 3 1 1\n", SINEW_ERROR_PARSE, 0, 2, "negative"},
        {"5 3 1 1\n", "1500000000 3 1 1\n", SINEW_ERROR_PARSE, 0, 2, "absurd"},
        {"1 1 2 3 4 -1\n", "1 0 2 3 4 -1\n", SINEW_ERROR_PARSE, 1, 2, "1-based"},
        {"2 3 2 4 5 2\n", "2 3 2 4 6 2\n", SINEW_ERROR_PARSE, 1, 3, "1-based"},
        {"2 3 2 4 5 2\n", "2 3 2 4 4 2\n", SINEW_ERROR_DEGENERATE, 1, 3, "repeats"},
        {"2 3 2 4 5 2\n", "2 3 2 4 q 2\n", SINEW_ERROR_PARSE, 1, 3, "'q'"},
        {"2 4 1\n", "3 4 1\n", SINEW_ERROR_PARSE, 1, 1, "bytes"},
        {"2 4 1\n", "2 5 1\n", SINEW_ERROR_PARSE, 1, 1, "nodes per"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char *node, *ele;
        if (cases[i].in_ele) {
            node = replace(k_node1, "", "");
            ele = replace(k_ele1, cases[i].node, cases[i].ele);
        } else if (cases[i].ele) {
            node = replace(k_node1, cases[i].node, cases[i].ele);
            ele = replace(k_ele1, "", "");
        } else { /* truncate the node file before the given line */
            node = replace(k_node1, "", "");
            strstr(node, cases[i].node)[0] = '\0';
            ele = replace(k_ele1, "", "");
        }
        sinew_result rc = read_tg(node, ele, &m, &e, &np, &ep);
        free(node);
        free(ele);
        ENSUREF(err_is(rc, &e, cases[i].code, cases[i].in_ele ? ep : np, cases[i].line), "case %zu",
                i);
        ENSUREF(has(&e, cases[i].word), "case %zu", i);
        ENSURE(all_zero(&m, sizeof m));
    }
    /* 0-based file: index n is one past the end */
    const char *node0 = "5 3\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n";
    ENSURE(
        err_is(read_tg(node0, "1 4\n0 1 2 3 5\n", &m, &e, &np, &ep), &e, SINEW_ERROR_PARSE, ep, 2));
    ENSURE(has(&e, "0-based"));
    ENSURE(err_is(sw_read_tetgen(np, tmp_path("none.ele"), &m, &e), &e, SINEW_ERROR_IO, "none.ele",
                  0));
}

/* ---- OBJ ----------------------------------------------------------------------- */

TEST(obj_reads_polygons_and_relative_indices) {
    sw_trimesh m;
    sw_error e;
    ENSURE(sw_read_obj(write_text("ok.obj", k_obj), &m, &e) == SINEW_OK);
    ENSURE(m.nverts == 5 && m.ntris == 3);
    const int32_t want[9] = {0, 1, 2, 0, 2, 3, 4, 1, 0};
    ENSURE(memcmp(m.tris, want, sizeof want) == 0);
    ENSURE(m.X[3 * 4 + 2] == 1.0);
    sw_trimesh_free(&m);
}

TEST(obj_vertex_colours_round_trip) {
    const double X[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, C[9] = {1, 0, 0, 0.5, 0.25, 0, 0, 0, 1};
    const int32_t tri[3] = {0, 1, 2};
    sw_error e;
    ENSURE(sw_write_obj_colors(tmp_path("c.obj"), 3, X, C, 1, tri, &e) == SINEW_OK);
    sw_trimesh m;
    double *col = NULL;
    ENSURE(sw_read_obj_colors(tmp_path("c.obj"), &m, &col, &e) == SINEW_OK);
    ENSURE(col && m.nverts == 3);
    for (int i = 0; i < 9; ++i)
        ENSURE(col[i] == C[i] && m.X[i] == X[i]);
    free(col);
    sw_trimesh_free(&m);
    /* a vertex without a colour: none; a colour outside [0, 1]: clamped */
    ENSURE(sw_read_obj_colors(write_text("c2.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\n"
                                                   "f 1 2 3\n"),
                              &m, &col, &e) == SINEW_OK);
    ENSURE(col == NULL);
    sw_trimesh_free(&m);
    ENSURE(sw_read_obj_colors(write_text("c3.obj", "v 0 0 0 2 -1 0.5\nv 1 0 0 0 0 0\n"
                                                   "v 0 1 0 0 0 1\nf 1 2 3\n"),
                              &m, &col, &e) == SINEW_OK);
    ENSURE(col && col[0] == 1 && col[1] == 0 && col[2] == 0.5);
    free(col);
    sw_trimesh_free(&m);
    /* plain reading ignores them */
    ENSURE(sw_read_obj(tmp_path("c.obj"), &m, &e) == SINEW_OK && m.nverts == 3);
    sw_trimesh_free(&m);
}

TEST(obj_rejects_malformed) {
    static const bad_case cases[] = {
        {"f 1/1/1 2/1/1 3/1/1 4/1/1", "f 1 2 0", SINEW_ERROR_PARSE, 13, "1-based"},
        {"f 1/1/1 2/1/1 3/1/1 4/1/1", "f 1 2 5", SINEW_ERROR_PARSE, 13, "1-based"},
        {"f -1 -4//1 -5/1", "f -1 -4//1 -6/1", SINEW_ERROR_PARSE, 15, "relative"},
        {"f 1/1/1 2/1/1 3/1/1 4/1/1", "f 1 2", SINEW_ERROR_PARSE, 13, "corners"},
        {"f 1/1/1 2/1/1 3/1/1 4/1/1", "f 1 2/x 3", SINEW_ERROR_PARSE, 13, "2/x"},
        {"f 1/1/1 2/1/1 3/1/1 4/1/1", "f 1 2/1/1/1 3", SINEW_ERROR_PARSE, 13, "corner"},
        {"v 1 1 0\n", "v 1 nan 0\n", SINEW_ERROR_NOT_FINITE, 6, "finite"},
        {"v 1 1 0\n", "v 1 1\n", SINEW_ERROR_PARSE, 6, "ends early"},
        {"v 1 1 0\n", "v 1 1 0 1 2 3 4 5\n", SINEW_ERROR_PARSE, 6, "'5'"},
        {"v 1 1 0\n", "v 1 1 0 w\n", SINEW_ERROR_PARSE, 6, "'w'"},
        {"s off\n", "zz top\n", SINEW_ERROR_PARSE, 11, "zz"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char *s = replace(k_obj, cases[i].from, cases[i].to);
        const char *p = write_text("bad.obj", s);
        free(s);
        sw_trimesh m;
        sw_error e;
        sinew_result rc = sw_read_obj(p, &m, &e);
        ENSUREF(err_is(rc, &e, cases[i].code, p, cases[i].line), "case %zu", i);
        ENSUREF(has(&e, cases[i].word), "case %zu", i);
        ENSURE(all_zero(&m, sizeof m));
    }
    sw_trimesh m;
    sw_error e;
    const char *p = write_text("nofaces.obj", "v 0 0 0\nv 1 0 0\n");
    ENSURE(err_is(sw_read_obj(p, &m, &e), &e, SINEW_ERROR_PARSE, p, 2));
    p = tmp_path("missing.obj");
    ENSURE(err_is(sw_read_obj(p, &m, &e), &e, SINEW_ERROR_IO, p, 0));
}

/* ---- TGF ----------------------------------------------------------------------- */

TEST(tgf_reads_and_derives_parents) {
    sw_skeleton s;
    sw_error e;
    ENSURE(sw_read_tgf(write_text("ok.tgf", k_tgf), &s, &e) == SINEW_OK);
    ENSURE(s.njoints == 5 && s.nbones == 3);
    const int32_t bones[6] = {1, 2, 0, 1, 1, 3}, parent[3] = {1, -1, 1};
    ENSURE(memcmp(s.bones, bones, sizeof bones) == 0);
    ENSURE(memcmp(s.parent, parent, sizeof parent) == 0);
    ENSURE(s.joints[3 * 1 + 1] == 1.0 && s.joints[3 * 4 + 2] == 5.0);
    ENSURE(sw_skeleton_validate(&s, &e) == SINEW_OK);
    sw_skeleton_free(&s);
}

TEST(tgf_rejects_malformed) {
    static const bad_case cases[] = {
        {"2 3 1 0 0 0\n", "0 3 1 0 0 0\n", SINEW_ERROR_PARSE, 7, "1-based"},
        {"2 3 1 0 0 0\n", "2 6 1 0 0 0\n", SINEW_ERROR_PARSE, 7, "1-based"},
        {"2 3 1 0 0 0\n", "2 3 1 0 x 0\n", SINEW_ERROR_PARSE, 7, "'x'"},
        {"2 3 1 0 0 0\n", "2 2\n", SINEW_ERROR_PARSE, 7, "itself"},
        {"2 3 1 0 0 0\n", "2\n", SINEW_ERROR_PARSE, 7, "ends early"},
        {"2\t4\n", "3\t2\n", SINEW_ERROR_PARSE, 9, "line 8"}, /* joint 2 ends two bones */
        {"2\t4\n", "3\t1\n", SINEW_ERROR_PARSE, 7, "cycle"},
        {"3\t0 2 0\n", "4\t0 2 0\n", SINEW_ERROR_PARSE, 3, "1-based"},
        {"3\t0 2 0\n", "3\t0 inf 0\n", SINEW_ERROR_NOT_FINITE, 3, "finite"},
        {"3\t0 2 0\n", "3\t0 2\n", SINEW_ERROR_PARSE, 3, "ends early"},
        {"2\t0 1 0 0 1 2.5\n", "2\t0 1 0 0 one 2.5\n", SINEW_ERROR_PARSE, 2, "one"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char *s = replace(k_tgf, cases[i].from, cases[i].to);
        const char *p = write_text("bad.tgf", s);
        free(s);
        sw_skeleton sk;
        sw_error e;
        sinew_result rc = sw_read_tgf(p, &sk, &e);
        ENSUREF(err_is(rc, &e, cases[i].code, p, cases[i].line), "case %zu", i);
        ENSUREF(has(&e, cases[i].word), "case %zu", i);
        ENSURE(all_zero(&sk, sizeof sk));
    }
    sw_skeleton sk;
    sw_error e;
    const char *p = write_text("nojoints.tgf", "#\n1 2\n");
    ENSURE(err_is(sw_read_tgf(p, &sk, &e), &e, SINEW_ERROR_PARSE, p, 2));
    p = tmp_path("missing.tgf");
    ENSURE(err_is(sw_read_tgf(p, &sk, &e), &e, SINEW_ERROR_IO, p, 0));
}

/* ---- DMAT ---------------------------------------------------------------------- */

TEST(dmat_round_trips_ascii_and_binary) {
    const int32_t shapes[][2] = {{7, 3}, {1, 5}, {4, 1}, {0, 0}};
    for (int s = 0; s < 4; ++s) {
        int32_t R = shapes[s][0], C = shapes[s][1];
        double *A = malloc(sizeof(double) * (size_t)(R * C + 1));
        for (int i = 0; i < R * C; ++i)
            A[i] = (rnd_unit() - 0.5) * pow(10.0, (int)(rnd() % 40) - 20);
        if (R * C > 2) A[1] = -0.0, A[2] = 4.9406564584124654e-324; /* signed zero, denormal */
        for (int binary = 0; binary < 2; ++binary) {
            sw_error e;
            const char *p = tmp_path(binary ? "rt_b.dmat" : "rt_a.dmat");
            ENSURE(sw_write_dmat(p, R, C, A, binary, &e) == SINEW_OK);
            int32_t r, c;
            double *B;
            ENSUREF(sw_read_dmat(p, &r, &c, &B, &e) == SINEW_OK, "%s", e.msg);
            ENSURE(r == R && c == C);
            ENSURE(R * C == 0 || memcmp(A, B, sizeof(double) * (size_t)(R * C)) == 0);
            free(B);
        }
        free(A);
    }
    /* column-major on disk, row-major in memory */
    int32_t r, c;
    double *B;
    sw_error e;
    ENSURE(sw_read_dmat(write_text("cm.dmat", "3 2\n1 4\n2 5\n3 6\n"), &r, &c, &B, &e) == SINEW_OK);
    ENSURE(r == 2 && c == 3);
    for (int i = 0; i < 6; ++i)
        ENSURE(B[i] == i + 1);
    free(B);
    /* binary layout is exactly "0 0\n" "cols rows\n" + LE doubles, column-major */
    const double A[2] = {1.5, -2.0};
    const char *p = tmp_path("lay.dmat");
    ENSURE(sw_write_dmat(p, 1, 2, A, 1, &e) == SINEW_OK);
    size_t n;
    char *raw = sw_test_read_file(p, &n);
    ENSURE(n == 8 + 16 && memcmp(raw, "0 0\n2 1\n", 8) == 0);
    ENSURE(raw[8 + 6] == (char)0xF8 && raw[8 + 7] == (char)0x3F); /* 1.5 = 0x3FF8... */
    free(raw);
}

/* a byte-string literal with embedded NULs and its exact length */
#define BIN(s) s, sizeof(s) - 1

TEST(dmat_rejects_malformed) {
    struct {
        const char *text;
        size_t len; /* 0: strlen */
        sinew_result code;
        int line;
        const char *word;
    } cases[] = {
        {"2 2\n1.5 2.5\n3.5\n", 0, SINEW_ERROR_PARSE, 3, "end of file"},
        {"2 2\n1 2\n3\n", 0, SINEW_ERROR_PARSE, 1, "bytes"},
        {"2 2\n1 2\n3 4 5\n", 0, SINEW_ERROR_PARSE, 3, "more values"},
        {"2 2\n1 2\n3 nan\n", 0, SINEW_ERROR_NOT_FINITE, 3, "finite"},
        {"2 2\n1 2\n3 4x\n", 0, SINEW_ERROR_PARSE, 3, "4x"},
        {"-2 2\n1 2\n", 0, SINEW_ERROR_PARSE, 1, "size"},
        {"2 3000000000\n", 0, SINEW_ERROR_PARSE, 1, "size"},
        {"100000 100000\n1\n", 0, SINEW_ERROR_PARSE, 1, "large"},
        {"1000 1000\n1 2 3\n", 0, SINEW_ERROR_PARSE, 1, "bytes"},
        {"2 two\n1 2\n", 0, SINEW_ERROR_PARSE, 1, "two"},
        {"2 2 2\n1 2 3 4\n", 0, SINEW_ERROR_PARSE, 1, "header"},
        {"", 0, SINEW_ERROR_PARSE, 1, "empty"},
        {BIN("0 0\n2 1\n\0\0\0\0\0\0\xf8\x3f\0\0\0\0\0\0"), SINEW_ERROR_PARSE, 3, "truncated"},
        {BIN("0 0\n2 1\n\0\0\0\0\0\0\xf8\x3f\0\0\0\0\0\0\0\0\1"), SINEW_ERROR_PARSE, 3, "after"},
        {BIN("0 0\n2 1\n\0\0\0\0\0\0\xf8\x7f\0\0\0\0\0\0\0\0"), SINEW_ERROR_NOT_FINITE, 3,
         "finite"},
        {BIN("0 0\n2 1 \n\0\0\0\0\0\0\xf8\x3f\0\0\0\0\0\0\0\0"), SINEW_ERROR_PARSE, 2, "newline"},
        {"0 0\n2 x\n", 0, SINEW_ERROR_PARSE, 2, "x"},
        /* an empty matrix declared with one nonzero size is not followed by values */
        {"0 2\n1 2\n", 0, SINEW_ERROR_PARSE, 2, "empty"},
        {"3 0\n\n7\n", 0, SINEW_ERROR_PARSE, 3, "empty"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        size_t len = cases[i].len ? cases[i].len : strlen(cases[i].text);
        const char *p = write_bytes("bad.dmat", cases[i].text, len);
        int32_t r = 5, c = 5;
        double *d = (double *)&r;
        sw_error e;
        sinew_result rc = sw_read_dmat(p, &r, &c, &d, &e);
        ENSUREF(err_is(rc, &e, cases[i].code, p, cases[i].line), "case %zu", i);
        ENSUREF(has(&e, cases[i].word), "case %zu", i);
        ENSURE(r == 0 && c == 0 && d == NULL);
    }
}

TEST(weights_are_checked_and_normalised) {
    sw_weights w;
    sw_error e;
    const char *p = write_text("w.dmat", "2 3\n1 0 -1e-9\n3 1 2\n");
    ENSURE(sw_read_weights(p, 3, 2, &w, &e) == SINEW_OK);
    ENSURE(w.nverts == 3 && w.nbones == 2);
    ENSURE_NEAR(w.w[0], 0.25, 1e-15);
    ENSURE_NEAR(w.w[1], 0.75, 1e-15);
    ENSURE(w.w[2] == 0.0 && w.w[3] == 1.0 && w.w[4] == 0.0 && w.w[5] == 1.0);
    sw_weights_free(&w);
    ENSURE(err_is(sw_read_weights(p, 4, 2, &w, &e), &e, SINEW_ERROR_PARSE, p, 1));
    ENSURE(all_zero(&w, sizeof w));
    p = write_text("wneg.dmat", "2 2\n1 -0.5\n0 1\n");
    ENSURE(err_is(sw_read_weights(p, 2, 2, &w, &e), &e, SINEW_ERROR_PARSE, p, 0));
    ENSURE(has(&e, "vertex 1"));
    p = write_text("wzero.dmat", "2 2\n1 0\n0 0\n");
    ENSURE(err_is(sw_read_weights(p, 2, 2, &w, &e), &e, SINEW_ERROR_DEGENERATE, p, 0));
    ENSURE(all_zero(&w, sizeof w));
    /* finite weights whose sum overflows still sum to 1 (fuzz_dmat: were all 0) */
    p = write_text("whuge.dmat", "2 1\n1e308\n1.5e308\n");
    ENSURE(sw_read_weights(p, 1, 2, &w, &e) == SINEW_OK);
    ENSURE_NEAR(w.w[0], 0.4, 1e-15);
    ENSURE_NEAR(w.w[1], 0.6, 1e-15);
    sw_weights_free(&w);
    p = write_text("wnobone.dmat", "0 2\n"); /* 2 vertices, no bone column (fuzz_dmat) */
    ENSURE(err_is(sw_read_weights(p, 2, 0, &w, &e), &e, SINEW_ERROR_DEGENERATE, p, 1));
    ENSURE(all_zero(&w, sizeof w));
    int32_t r, c;
    double *d = (double *)&r; /* an empty binary matrix has no data, as an ASCII one */
    ENSURE(sw_read_dmat(write_bytes("bempty.dmat", "0 0\n3 0\n", 8), &r, &c, &d, &e) == SINEW_OK);
    ENSURE(r == 0 && c == 3 && d == NULL);
    /* 1e9 empty columns (fuzz_dmat: took a minute looping over them) */
    ENSURE(sw_read_dmat(write_bytes("bwide.dmat", "0 0\n1000000000 0\n", 17), &r, &c, &d, &e) ==
           SINEW_OK);
    ENSURE(r == 0 && c == 1000000000 && d == NULL);
}

/* The from-memory readers (the fuzz harnesses' entries) give what the path readers give,
 * and name the text as told in their messages. */
TEST(parse_from_memory_matches_files) {
    static const char mesh[] = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n"
                               "1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra\n1\n1 3 2 4 0\nEnd\n";
    static const char node[] = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    static const char ele[] = "1 4 0\n0 0 1 2 3\n";
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    static const char tgf[] = "1 0 0 0\n2 0 1 0\n#\n1 2\n";
    static const char dmat[] = "2 2\n1 3\n2 4\n";
    sw_error e;
    sw_tetmesh a, b;
    ENSURE(sw_read_medit(write_text("m.mesh", mesh), &a, &e) == SINEW_OK);
    ENSURE(sw_parse_medit(mesh, strlen(mesh), "mem.mesh", &b, &e) == SINEW_OK);
    ENSURE(a.nverts == b.nverts && a.ntets == b.ntets);
    ENSURE(!memcmp(a.X, b.X, 12 * sizeof(double)) && !memcmp(a.tets, b.tets, 4 * sizeof(int32_t)));
    sw_tetmesh_free(&a);
    sw_tetmesh_free(&b);
    ENSURE(sw_parse_tetgen(node, strlen(node), NULL, ele, strlen(ele), NULL, &b, &e) == SINEW_OK);
    ENSURE(b.nverts == 4 && b.ntets == 1);
    sw_tetmesh_free(&b);
    ENSURE(sw_parse_tetgen(node, strlen(node), "n.node", ele, 5, "e.ele", &b, &e) ==
           SINEW_ERROR_PARSE);
    ENSUREF(!strncmp(e.msg, "e.ele:", 6) && all_zero(&b, sizeof b), "%s", e.msg);
    sw_trimesh t;
    ENSURE(sw_parse_obj(obj, strlen(obj), "mem.obj", &t, &e) == SINEW_OK);
    ENSURE(t.nverts == 3 && t.ntris == 1 && t.tris[2] == 2);
    sw_trimesh_free(&t);
    ENSURE(sw_parse_obj(obj, strlen(obj) - 2, "mem.obj", &t, &e) == SINEW_ERROR_PARSE);
    ENSUREF(!strncmp(e.msg, "mem.obj:4:", 10), "%s", e.msg);
    sw_skeleton s;
    ENSURE(sw_parse_tgf(tgf, strlen(tgf), NULL, &s, &e) == SINEW_OK);
    ENSURE(s.njoints == 2 && s.nbones == 1 && s.parent[0] == -1);
    sw_skeleton_free(&s);
    int32_t r, c;
    double *d;
    ENSURE(sw_parse_dmat(dmat, strlen(dmat), NULL, &r, &c, &d, &e) == SINEW_OK);
    ENSURE(r == 2 && c == 2 && d[0] == 1 && d[1] == 2 && d[2] == 3 && d[3] == 4);
    free(d);
    ENSURE(sw_parse_dmat(dmat, 6, NULL, &r, &c, &d, &e) == SINEW_ERROR_PARSE);
    ENSUREF(!strncmp(e.msg, "<text>:", 7) && d == NULL, "%s", e.msg);
    sw_weights w;
    ENSURE(sw_parse_weights(dmat, strlen(dmat), "w", 2, 2, &w, &e) == SINEW_OK);
    ENSURE_NEAR(w.w[0], 1.0 / 3.0, 1e-15);
    sw_weights_free(&w);
}

/* ---- writers round trip -------------------------------------------------------- */

TEST(medit_and_obj_round_trip) {
    sw_tetmesh m, m2;
    sw_error e;
    ENSURE(sw_read_medit(write_text("src.mesh", k_medit), &m, &e) == SINEW_OK);
    for (int i = 0; i < 3 * m.nverts; ++i)
        m.X[i] += (rnd_unit() - 0.5) * 1e-3; /* ugly digits */
    const char *p = tmp_path("rt.mesh");
    ENSURE(sw_write_medit(p, &m, &e) == SINEW_OK);
    ENSURE(sw_read_medit(p, &m2, &e) == SINEW_OK);
    ENSURE(m2.nverts == m.nverts && m2.ntets == m.ntets);
    ENSURE(memcmp(m.X, m2.X, sizeof(double) * 3 * (size_t)m.nverts) == 0);
    ENSURE(memcmp(m.tets, m2.tets, sizeof(int32_t) * 4 * (size_t)m.ntets) == 0);
    sw_tetmesh_free(&m2);
    sw_surface s;
    ENSURE(sw_tetmesh_surface(&m, &s, &e) == SINEW_OK);
    p = tmp_path("rt.obj");
    ENSURE(sw_write_obj(p, m.nverts, m.X, s.ntris, s.tris, &e) == SINEW_OK);
    sw_trimesh t;
    ENSURE(sw_read_obj(p, &t, &e) == SINEW_OK);
    ENSURE(t.nverts == m.nverts && t.ntris == s.ntris);
    ENSURE(memcmp(t.X, m.X, sizeof(double) * 3 * (size_t)m.nverts) == 0);
    ENSURE(memcmp(t.tris, s.tris, sizeof(int32_t) * 3 * (size_t)s.ntris) == 0);
    sw_trimesh_free(&t);
    sw_surface_free(&s);
    ENSURE(sw_write_medit("/nonexistent_dir/x.mesh", &m, &e) == SINEW_ERROR_IO);
    ENSURE(sw_write_obj("/nonexistent_dir/x.obj", 0, NULL, 0, NULL, &e) == SINEW_ERROR_IO);
    ENSURE(sw_write_dmat("/nonexistent_dir/x.dmat", 0, 0, NULL, 1, &e) == SINEW_ERROR_IO);
    sw_tetmesh_free(&m);
}

/* ---- surface and quality ------------------------------------------------------- */

TEST(surface_of_small_meshes) {
    sw_tetmesh m;
    sw_error e;
    sw_surface s;
    ENSURE(sw_read_medit(write_text("s.mesh", k_medit), &m, &e) == SINEW_OK);
    ENSURE(sw_tetmesh_surface(&m, &s, &e) == SINEW_OK);
    ENSURE(s.ntris == 6 && s.nverts == 5);
    for (int i = 0; i < 5; ++i)
        ENSURE(s.verts[i] == i);
    ENSURE(surface_closed(&s, m.nverts));
    ENSURE_NEAR(enclosed_volume(&s, m.X), total_volume(&m), 1e-15);
    /* the two tets form a convex bipyramid: every outward normal points away from its
     * centroid (0.4, 0.4, 0.4) */
    for (int32_t t = 0; t < s.ntris; ++t) {
        const double *a = m.X + 3 * s.tris[3 * t], *b = m.X + 3 * s.tris[3 * t + 1],
                     *c = m.X + 3 * s.tris[3 * t + 2];
        double u[3], v[3], n[3], d = 0;
        for (int i = 0; i < 3; ++i)
            u[i] = b[i] - a[i], v[i] = c[i] - a[i];
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        for (int i = 0; i < 3; ++i)
            d += n[i] * ((a[i] + b[i] + c[i]) / 3 - 0.4);
        ENSUREF(d > 0, "triangle %d faces inward", t);
    }
    sw_surface_free(&s);
    /* single tet: 4 faces */
    sw_tetmesh one = {4, 1, m.X, m.tets};
    ENSURE(sw_tetmesh_surface(&one, &s, &e) == SINEW_OK);
    ENSURE(s.ntris == 4 && s.nverts == 4 && surface_closed(&s, 4));
    ENSURE_NEAR(enclosed_volume(&s, m.X), 1.0 / 6, 1e-15);
    sw_surface_free(&s);
    /* three tets on one face: non-manifold */
    double X[3 * 6] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 1, 1};
    int32_t T[12] = {0, 1, 2, 3, 0, 2, 1, 4, 0, 1, 2, 5}; /* three tets on face 0-1-2 */
    sw_tetmesh nm = {6, 3, X, T};
    ENSURE(sw_tetmesh_surface(&nm, &s, &e) == SINEW_ERROR_DEGENERATE);
    ENSURE(has(&e, "non-manifold") && all_zero(&s, sizeof s));
    sw_tetmesh_free(&m);
}

TEST(quality_of_known_tets) {
    /* regular tet: all dihedrals acos(1/3) = 70.53 deg */
    double X[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
    int32_t T[4] = {0, 1, 2, 3};
    if (sw_tet_signed_volume(X, X + 3, X + 6, X + 9) < 0) T[1] = 2, T[2] = 1;
    sw_tetmesh m = {4, 1, X, T};
    sw_quality q;
    sw_tetmesh_quality(&m, 0, &q);
    ENSURE(q.ntets == 1 && q.inverted == 0 && q.degenerate == 0 && q.slivers == 0);
    ENSURE_NEAR(q.min_dihedral_deg, acos(1.0 / 3) * 180 / SW_PI, 1e-9);
    ENSURE_NEAR(q.max_dihedral_deg, acos(1.0 / 3) * 180 / SW_PI, 1e-9);
    ENSURE_NEAR(q.min_volume, 8.0 / 3, 1e-12);
    /* corner tet: dihedrals 90 (x3) and acos(1/sqrt3) = 54.7 (x3) */
    double Y[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.X = Y;
    T[0] = 0, T[1] = 1, T[2] = 2, T[3] = 3;
    sw_tetmesh_quality(&m, 0, &q);
    ENSURE_NEAR(q.max_dihedral_deg, 90, 1e-9);
    ENSURE_NEAR(q.min_dihedral_deg, acos(1 / sqrt(3.0)) * 180 / SW_PI, 1e-9);
    /* inverted and flattened (sliver) */
    T[1] = 2, T[2] = 1;
    sw_tetmesh_quality(&m, 0, &q);
    ENSURE(q.inverted == 1 && q.min_volume < 0 && q.slivers == 0);
    Y[11] = 1e-3; /* apex nearly in the base plane: tiny dihedral at the base */
    T[1] = 1, T[2] = 2;
    sw_tetmesh_quality(&m, 0, &q);
    ENSURE(q.slivers == 1 && q.min_dihedral_deg < 5 && q.inverted == 0);
    Y[11] = 0;
    sw_tetmesh_quality(&m, 0, &q);
    ENSURE(q.degenerate == 1 && q.inverted == 0 && q.min_dihedral_deg == 0);
}

SW_TEST_MAIN(CASE(medit_reads_small_mesh), CASE(medit_reorients_negative_tets),
             CASE(medit_rejects_malformed), CASE(medit_rejects_truncated_and_missing),
             CASE(tetgen_reads_both_bases), CASE(tetgen_rejects_malformed),
             CASE(obj_reads_polygons_and_relative_indices), CASE(obj_vertex_colours_round_trip),
             CASE(obj_rejects_malformed), CASE(tgf_reads_and_derives_parents),
             CASE(tgf_rejects_malformed), CASE(dmat_round_trips_ascii_and_binary),
             CASE(dmat_rejects_malformed), CASE(weights_are_checked_and_normalised),
             CASE(parse_from_memory_matches_files), CASE(medit_and_obj_round_trip),
             CASE(surface_of_small_meshes), CASE(quality_of_known_tets))
