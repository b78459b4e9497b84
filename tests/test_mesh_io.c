/* Asset readers and writers (Medit, TetGen, OBJ, TGF, DMAT), surface extraction and the
 * quality report: every error path with its code and "path:line:" message, round trips
 * of every writer, the real assets of ../shared/data with the counts their SOURCE.md
 * states, a truncation sweep over a real file, and random byte flips. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <unistd.h>

#include "mesh_io.h"
#include "sw_test.h"

#define SW_PI 3.14159265358979323846

/* ---- temp files ---------------------------------------------------------------- */

static char g_dir[64];
static char g_names[256][32];
static int g_nnames;

static void cleanup(void) {
    char p[128];
    for (int i = 0; i < g_nnames; ++i) {
        snprintf(p, sizeof p, "%s/%.31s", g_dir, g_names[i]);
        remove(p);
    }
    if (g_dir[0]) rmdir(g_dir);
}

/* Path of `name` in this run's temp dir (created on first use, removed at exit). */
static const char *tmp_path(const char *name) {
    static char buf[4][160];
    static int slot;
    if (!g_dir[0]) {
        strcpy(g_dir, "/tmp/sinew_mesh_io_XXXXXX");
        if (!mkdtemp(g_dir)) {
            perror("mkdtemp");
            exit(1);
        }
        atexit(cleanup);
    }
    int known = 0;
    for (int i = 0; i < g_nnames; ++i)
        known |= strcmp(g_names[i], name) == 0;
    if (!known && g_nnames < 256) snprintf(g_names[g_nnames++], 32, "%s", name);
    char *p = buf[slot++ % 4];
    snprintf(p, 160, "%s/%s", g_dir, name);
    return p;
}

static const char *write_bytes(const char *name, const void *data, size_t n) {
    const char *p = tmp_path(name);
    FILE *f = fopen(p, "wb");
    if (!f) return p;
    fwrite(data, 1, n, f);
    fclose(f);
    return p;
}

static const char *write_text(const char *name, const char *text) {
    return write_bytes(name, text, strlen(text));
}

/* Returns a malloc'd copy of `s` with the first `from` replaced by `to`. */
static char *replace(const char *s, const char *from, const char *to) {
    const char *at = strstr(s, from);
    if (!at) {
        fprintf(stderr, "  replace: '%s' not found\n", from);
        exit(1);
    }
    size_t n = strlen(s) + strlen(to) + 1;
    char *r = malloc(n);
    size_t k = (size_t)(at - s);
    memcpy(r, s, k);
    strcpy(r + k, to);
    strcat(r, at + strlen(from));
    return r;
}

static int all_zero(const void *p, size_t n) {
    const unsigned char *b = p;
    for (size_t i = 0; i < n; ++i)
        if (b[i]) return 0;
    return 1;
}

/* The error carries `code`, names the file's base name and (line > 0) ":line:". */
static int err_is(sinew_result rc, const sw_error *e, sinew_result code, const char *path,
                  int line) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char tag[32];
    snprintf(tag, sizeof tag, ":%d:", line);
    int ok =
        rc == code && e->code == code && strstr(e->msg, base) && (line <= 0 || strstr(e->msg, tag));
    if (!ok)
        fprintf(stderr, "  got rc %d (want %d), message '%s' (want %s and line %d)\n", rc, code,
                e->msg, base, line);
    return ok;
}

static int has(const sw_error *e, const char *word) {
    if (strstr(e->msg, word)) return 1;
    fprintf(stderr, "  message '%s' lacks '%s'\n", e->msg, word);
    return 0;
}

/* ---- a two-tet Medit file ------------------------------------------------------ */

/* Tets (1,2,3,4) and (2,3,4,5) share face 2-3-4; both positive. Line numbers matter. */
static const char *k_medit = "MeshVersionFormatted 1\n"       /* 1 */
                             "Dimension 3\n"                  /* 2 */
                             "Vertices\n"                     /* 3 */
                             "5\n"                            /* 4 */
                             "0.000000 0.000000 0.000000 0\n" /* 5 */
                             "1.000000 0.000000 0.000000 0\n" /* 6 */
                             "0.000000 1.000000 0.000000 0\n" /* 7 */
                             "0.000000 0.000000 1.000000 0\n" /* 8 */
                             "1.000000 1.000000 1.000000 0\n" /* 9 */
                             "Triangles\n"                    /* 10 */
                             "1\n"                            /* 11 */
                             "1 2 3 0\n"                      /* 12 */
                             "# a comment line\n"             /* 13 */
                             "Tetrahedra\n"                   /* 14 */
                             "2\n"                            /* 15 */
                             "1 2 3 4 1\n"                    /* 16 */
                             "2 3 4 5 1\n"                    /* 17 */
                             "Edges\n"                        /* 18 */
                             "1\n"                            /* 19 */
                             "1 2 0\n"                        /* 20 */
                             "End\n";                         /* 21 */

static double total_volume(const sw_tetmesh *m) {
    double v = 0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *q = m->tets + 4 * t;
        v += sw_tet_signed_volume(m->X + 3 * q[0], m->X + 3 * q[1], m->X + 3 * q[2],
                                  m->X + 3 * q[3]);
    }
    return v;
}

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

static const char *k_node1 = "# five points, one attribute, markers\n" /* 1 */
                             "5 3 1 1\n"                               /* 2 */
                             "1 0 0 0 7.5 1\n"                         /* 3 */
                             "2 1 0 0 7.5 1\n"                         /* 4 */
                             "\n"                                      /* 5 */
                             "3 0 1 0 7.5 0   # inline comment\n"      /* 6 */
                             "4 0 0 1 7.5 1\n"                         /* 7 */
                             "5 1 1 1 7.5 1\n";                        /* 8 */
static const char *k_ele1 = "2 4 1\n"                                  /* 1 */
                            "1 1 2 3 4 -1\n"                           /* 2 */
                            "2 3 2 4 5 2\n"; /* 3: negative, gets reoriented */

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

static const char *k_obj = "# quad and triangle\n"       /* 1 */
                           "mtllib x.mtl\n"              /* 2 */
                           "o thing\n"                   /* 3 */
                           "v 0 0 0\n"                   /* 4 */
                           "v 1 0 0 1.0\n"               /* 5 */
                           "v 1 1 0\n"                   /* 6 */
                           "v 0 1 0\n"                   /* 7 */
                           "vt 0 0\n"                    /* 8 */
                           "vn 0 0 1\n"                  /* 9 */
                           "g grp\n"                     /* 10 */
                           "s off\n"                     /* 11 */
                           "usemtl m\n"                  /* 12 */
                           "f 1/1/1 2/1/1 3/1/1 4/1/1\n" /* 13: quad -> 2 tris */
                           "v 0 0 1\n"                   /* 14 */
                           "f -1 -4//1 -5/1\n";          /* 15: 5, 2, 1 */

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

static const char *k_tgf = "1\t0 0 0\n"         /* 1 */
                           "2\t0 1 0 0 1 2.5\n" /* 2: extra columns ignored */
                           "3\t0 2 0\n"         /* 3 */
                           "4\t1 1 0\n"         /* 4 */
                           "5\t5 5 5\n"         /* 5: a lone joint */
                           "#\n"                /* 6 */
                           "2 3 1 0 0 0\n"      /* 7: child listed before its parent */
                           "1 2 1 0 0 0\n"      /* 8 */
                           "2\t4\n"             /* 9 */
                           "#\n"                /* 10 */
                           "whatever 1 2 3\n";  /* 11: ignored section */

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

static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static uint64_t rnd(void) { /* xorshift64* */
    g_rng ^= g_rng >> 12;
    g_rng ^= g_rng << 25;
    g_rng ^= g_rng >> 27;
    return g_rng * 2685821657736338717ull;
}
static double rnd_unit(void) {
    return (double)(rnd() >> 11) / 9007199254740992.0;
}

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

static int cmp_i64(const void *a, const void *b) {
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Every directed edge appears once and its reverse once: closed, consistently oriented,
 * each edge in exactly two triangles. */
static int surface_closed(const sw_surface *s, int32_t nverts) {
    size_t ne = 3 * (size_t)s->ntris;
    int64_t *k = malloc(ne * sizeof *k);
    for (int32_t t = 0; t < s->ntris; ++t)
        for (int i = 0; i < 3; ++i)
            k[3 * t + i] = (int64_t)s->tris[3 * t + i] * nverts + s->tris[3 * t + (i + 1) % 3];
    qsort(k, ne, sizeof *k, cmp_i64);
    int ok = 1;
    for (size_t i = 0; i < ne && ok; ++i) {
        if (i + 1 < ne && k[i] == k[i + 1]) ok = 0;
        int64_t rev = (k[i] % nverts) * nverts + k[i] / nverts;
        if (!bsearch(&rev, k, ne, sizeof *k, cmp_i64)) ok = 0;
    }
    free(k);
    return ok;
}

/* Divergence theorem: sum over outward triangles of p0 . (p1 x p2) / 6. */
static double enclosed_volume(const sw_surface *s, const double *X) {
    double v = 0;
    for (int32_t t = 0; t < s->ntris; ++t) {
        const double *a = X + 3 * s->tris[3 * t], *b = X + 3 * s->tris[3 * t + 1],
                     *c = X + 3 * s->tris[3 * t + 2];
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) /
             6.0;
    }
    return v;
}

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

/* ---- real assets --------------------------------------------------------------- */

static const char *data_path(const char *rel) {
    static char buf[4][512];
    static int slot;
    char *p = buf[slot++ % 4];
    snprintf(p, 512, "%s/%s", SINEW_SHARED_DATA_DIR, rel);
    return p;
}

static const struct {
    const char *rel;
    int32_t nverts, ntets, nsurf;
} k_meshes[] = {
    {"elephant-cd/elephant.mesh", 494, 1502, 790},
    {"hand-libigl/hand.mesh", 7234, 29998, 9556},
    {"fish-cd/fish.mesh", 6142, 21708, 8914},
};

TEST(real_tet_meshes) {
    NEED_DATA("elephant-cd/elephant.mesh");
    for (size_t i = 0; i < sizeof k_meshes / sizeof k_meshes[0]; ++i) {
        sw_tetmesh m;
        sw_error e;
        sw_surface s;
        ENSUREF(sw_read_tetmesh(data_path(k_meshes[i].rel), &m, &e) == SINEW_OK, "%s", e.msg);
        ENSURE(m.nverts == k_meshes[i].nverts && m.ntets == k_meshes[i].ntets);
        ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
        ENSURE(sw_tetmesh_surface(&m, &s, &e) == SINEW_OK);
        ENSUREF(s.ntris == k_meshes[i].nsurf, "%s: %d boundary faces", k_meshes[i].rel, s.ntris);
        ENSUREF(surface_closed(&s, m.nverts), "%s surface not closed", k_meshes[i].rel);
        double vt = total_volume(&m), vs = enclosed_volume(&s, m.X);
        ENSUREF(fabs(vt - vs) <= 1e-9 * fabs(vt), "%s: tets %.17g, surface %.17g", k_meshes[i].rel,
                vt, vs);
        for (int32_t k = 1; k < s.nverts; ++k)
            ENSURE(s.verts[k - 1] < s.verts[k]);
        sw_quality q;
        sw_tetmesh_quality(&m, 0, &q);
        fprintf(stderr,
                "  %s: %d v, %d tets, %d surface tris / %d surface v; dihedral %.3f..%.3f deg, "
                "volume %.3g..%.3g, %d slivers (<5 deg), %d degenerate, %d inverted\n",
                k_meshes[i].rel, m.nverts, m.ntets, s.ntris, s.nverts, q.min_dihedral_deg,
                q.max_dihedral_deg, q.min_volume, q.max_volume, q.slivers, q.degenerate,
                q.inverted);
        ENSURE(q.ntets == m.ntets && q.inverted == 0 && q.min_volume > 0);
        ENSURE(q.min_dihedral_deg > 0 && q.max_dihedral_deg < 180);
        sw_surface_free(&s);
        sw_tetmesh_free(&m);
    }
}

static const struct {
    const char *rel;
    int32_t a, b; /* obj: verts, tris; tgf: joints, bones; dmat: rows, cols */
} k_assets[] = {
    {"arm-libigl/arm.obj", 8311, 16618},
    {"elephant-cd/elephant.obj", 635, 1266},
    {"elephant-libigl/elephant.obj", 6034, 12064},
    {"fish-cd/fish.obj", 3200, 6396},
    {"arm-libigl/arm.tgf", 5, 4},
    {"elephant-cd/elephant.tgf", 25, 24},
    {"elephant-libigl/elephant.tgf", 25, 24},
    {"fish-cd/fish.tgf", 2, 0},
    {"hand-libigl/hand.tgf", 21, 20},
    {"arm-libigl/arm-weights.dmat", 8311, 4},
    {"elephant-cd/elephant.dmat", 494, 24},
    {"elephant-libigl/elephant-weights.dmat", 6034, 24},
    {"elephant-libigl/elephant-anim.dmat", 288, 457},
    {"fish-cd/fish.dmat", 6142, 2},
    {"hand-libigl/hand-pose.dmat", 80, 1},
};

static int ends_with(const char *s, const char *suf) {
    size_t n = strlen(s), k = strlen(suf);
    return n >= k && strcmp(s + n - k, suf) == 0;
}

TEST(real_surfaces_skeletons_and_matrices) {
    NEED_DATA("elephant-cd/elephant.mesh");
    for (size_t i = 0; i < sizeof k_assets / sizeof k_assets[0]; ++i) {
        const char *p = data_path(k_assets[i].rel);
        sw_error e;
        int32_t a = -1, b = -1;
        if (ends_with(p, ".obj")) {
            sw_trimesh m;
            ENSUREF(sw_read_obj(p, &m, &e) == SINEW_OK, "%s", e.msg);
            a = m.nverts, b = m.ntris;
            sw_trimesh_free(&m);
        } else if (ends_with(p, ".tgf")) {
            sw_skeleton s;
            ENSUREF(sw_read_tgf(p, &s, &e) == SINEW_OK, "%s", e.msg);
            a = s.njoints, b = s.nbones;
            if (s.nbones) ENSUREF(sw_skeleton_validate(&s, &e) == SINEW_OK, "%s", e.msg);
            int roots = 0;
            for (int32_t k = 0; k < s.nbones; ++k)
                roots += s.parent[k] < 0;
            ENSURE(s.nbones == 0 || roots >= 1);
            sw_skeleton_free(&s);
        } else {
            double *d;
            ENSUREF(sw_read_dmat(p, &a, &b, &d, &e) == SINEW_OK, "%s", e.msg);
            if (strstr(p, "weights") || ends_with(p, "elephant.dmat") ||
                ends_with(p, "fish.dmat")) {
                double worst = 0;
                for (int32_t r = 0; r < a; ++r) {
                    double sum = 0;
                    for (int32_t c = 0; c < b; ++c)
                        sum += d[(size_t)r * b + c];
                    worst = fmax(worst, fabs(sum - 1));
                }
                ENSUREF(worst < 1e-3, "%s: weight rows sum off by %g", p, worst);
                sw_weights w;
                ENSUREF(sw_read_weights(p, a, b, &w, &e) == SINEW_OK, "%s", e.msg);
                sw_weights_free(&w);
            }
            free(d);
        }
        ENSUREF(a == k_assets[i].a && b == k_assets[i].b, "%s: %d x %d", k_assets[i].rel, a, b);
    }
}

/* Every .mesh/.obj/.tgf/.dmat under the data folder reads, and is one we check above. */
TEST(real_every_asset_reads) {
    NEED_DATA("elephant-cd/elephant.mesh");
    DIR *top = opendir(SINEW_SHARED_DATA_DIR);
    ENSURE(top);
    struct dirent *de;
    int seen = 0, fail = 0;
    while ((de = readdir(top)) != NULL && !fail) {
        if (de->d_name[0] == '.') continue;
        char sub[600];
        snprintf(sub, sizeof sub, "%s/%s", SINEW_SHARED_DATA_DIR, de->d_name);
        DIR *d = opendir(sub);
        if (!d) continue;
        struct dirent *fe;
        while ((fe = readdir(d)) != NULL && !fail) {
            char rel[520], full[900];
            snprintf(rel, sizeof rel, "%s/%s", de->d_name, fe->d_name);
            snprintf(full, sizeof full, "%s/%s", sub, fe->d_name);
            sw_error e;
            sinew_result rc = SINEW_OK;
            int known = 0;
            if (ends_with(rel, ".mesh")) {
                sw_tetmesh m;
                rc = sw_read_medit(full, &m, &e);
                sw_tetmesh_free(&m);
                for (size_t i = 0; i < sizeof k_meshes / sizeof k_meshes[0]; ++i)
                    known |= strcmp(rel, k_meshes[i].rel) == 0;
            } else if (ends_with(rel, ".obj") || ends_with(rel, ".tgf") ||
                       ends_with(rel, ".dmat")) {
                if (ends_with(rel, ".obj")) {
                    sw_trimesh m;
                    rc = sw_read_obj(full, &m, &e);
                    sw_trimesh_free(&m);
                } else if (ends_with(rel, ".tgf")) {
                    sw_skeleton s;
                    rc = sw_read_tgf(full, &s, &e);
                    sw_skeleton_free(&s);
                } else {
                    int32_t r, c;
                    double *x = NULL;
                    rc = sw_read_dmat(full, &r, &c, &x, &e);
                    free(x);
                }
                for (size_t i = 0; i < sizeof k_assets / sizeof k_assets[0]; ++i)
                    known |= strcmp(rel, k_assets[i].rel) == 0;
            } else {
                continue;
            }
            seen++;
            if (rc != SINEW_OK) fprintf(stderr, "  %s: %s\n", rel, e.msg);
            if (!known) fprintf(stderr, "  %s: not in the expected-count tables\n", rel);
            fail = rc != SINEW_OK || !known;
        }
        closedir(d);
    }
    closedir(top);
    ENSURE(!fail);
    ENSUREF(seen == 18, "saw %d assets", seen);
}

/* Cut elephant.mesh at ~200 offsets: every prefix fails cleanly with PARSE, except the
 * ones that keep all the data (then it must read the whole mesh). */
TEST(real_truncation_sweep) {
    NEED_DATA("elephant-cd/elephant.mesh");
    size_t n;
    char *full = sw_test_read_file(data_path("elephant-cd/elephant.mesh"), &n);
    ENSURE(full && n > 1000);
    size_t data_end = n;
    while (data_end > 0 && (full[data_end - 1] == '\n' || full[data_end - 1] == ' '))
        data_end--;
    for (int k = 0; k <= 201; ++k) {
        size_t cut =
            k <= 199 ? (size_t)((double)n * k / 199.0 + (k % 7)) : (k == 200 ? data_end : n);
        if (cut > n) cut = n;
        const char *p = write_bytes("cut.mesh", full, cut);
        sw_tetmesh m;
        sw_error e;
        sinew_result rc = sw_read_medit(p, &m, &e);
        if (cut >= data_end) {
            ENSUREF(rc == SINEW_OK && m.ntets == 1502, "cut %zu/%zu: %s", cut, n, e.msg);
        } else {
            ENSUREF(rc == SINEW_ERROR_PARSE && strstr(e.msg, "cut.mesh:"), "cut %zu/%zu: rc %d %s",
                    cut, n, rc, e.msg);
            ENSURE(all_zero(&m, sizeof m));
        }
        sw_tetmesh_free(&m);
    }
    free(full);
}

/* Random byte flips in small files of every format: any outcome but a crash, a leak or
 * a half-filled output; successes must still be valid. */
TEST(byte_flips_never_crash) {
    char dm[64];
    double A[6] = {1, 2, 3, 4, 5, 6};
    sw_error e;
    ENSURE(sw_write_dmat(tmp_path("flip_src.dmat"), 2, 3, A, 1, &e) == SINEW_OK);
    size_t dn;
    char *dsrc = sw_test_read_file(tmp_path("flip_src.dmat"), &dn);
    ENSURE(dsrc && dn < sizeof dm);
    memcpy(dm, dsrc, dn);
    free(dsrc);
    const struct {
        const char *name, *text;
        size_t len;
    } src[] = {
        {"flip.mesh", k_medit, strlen(k_medit)}, {"flip.obj", k_obj, strlen(k_obj)},
        {"flip.tgf", k_tgf, strlen(k_tgf)},      {"flip.dmat", dm, dn},
        {"flip.node", k_node1, strlen(k_node1)},
    };
    int outcomes[16] = {0};
    for (size_t f = 0; f < sizeof src / sizeof src[0]; ++f) {
        char buf[1024];
        for (int it = 0; it < 400; ++it) {
            memcpy(buf, src[f].text, src[f].len);
            int flips = 1 + (int)(rnd() % 3);
            for (int j = 0; j < flips; ++j) {
                size_t at = rnd() % src[f].len;
                buf[at] = (it & 1) ? (char)(rnd() & 0xff) : (char)(buf[at] ^ (1 << (rnd() % 8)));
            }
            const char *p = write_bytes(src[f].name, buf, src[f].len);
            sinew_result rc;
            sw_error_clear(&e);
            if (f == 0 || f == 4) {
                sw_tetmesh m;
                rc = f == 0 ? sw_read_medit(p, &m, &e)
                            : sw_read_tetgen(p, write_text("flip.ele", k_ele1), &m, &e);
                if (rc == SINEW_OK)
                    ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
                else
                    ENSURE(all_zero(&m, sizeof m));
                sw_tetmesh_free(&m);
            } else if (f == 1) {
                sw_trimesh m;
                rc = sw_read_obj(p, &m, &e);
                if (rc == SINEW_OK)
                    for (int32_t i = 0; i < 3 * m.ntris; ++i)
                        ENSURE(m.tris[i] >= 0 && m.tris[i] < m.nverts);
                else
                    ENSURE(all_zero(&m, sizeof m));
                sw_trimesh_free(&m);
            } else if (f == 2) {
                sw_skeleton s;
                rc = sw_read_tgf(p, &s, &e);
                if (rc == SINEW_OK && s.nbones) ENSURE(sw_skeleton_validate(&s, &e) == SINEW_OK);
                if (rc != SINEW_OK) ENSURE(all_zero(&s, sizeof s));
                sw_skeleton_free(&s);
            } else {
                int32_t r, c;
                double *d;
                rc = sw_read_dmat(p, &r, &c, &d, &e);
                if (rc == SINEW_OK)
                    for (int32_t i = 0; i < r * c; ++i)
                        ENSURE(isfinite(d[i]));
                free(d);
            }
            ENSURE(rc >= 0 && rc < 16);
            outcomes[rc]++;
            /* (a flipped .node may surface as an index error in the .ele) */
            if (rc != SINEW_OK)
                ENSUREF(strstr(e.msg, f == 4 ? "/flip." : src[f].name), "%s", e.msg);
            ENSURE(rc == SINEW_OK || rc == SINEW_ERROR_PARSE || rc == SINEW_ERROR_NOT_FINITE ||
                   rc == SINEW_ERROR_DEGENERATE);
        }
    }
    fprintf(stderr, "  byte flips: %d ok, %d parse, %d not finite, %d degenerate\n", outcomes[0],
            outcomes[SINEW_ERROR_PARSE], outcomes[SINEW_ERROR_NOT_FINITE],
            outcomes[SINEW_ERROR_DEGENERATE]);
    ENSURE(outcomes[SINEW_ERROR_PARSE] > 0 && outcomes[SINEW_OK] > 0);
}

SW_TEST_MAIN(CASE(medit_reads_small_mesh), CASE(medit_reorients_negative_tets),
             CASE(medit_rejects_malformed), CASE(medit_rejects_truncated_and_missing),
             CASE(tetgen_reads_both_bases), CASE(tetgen_rejects_malformed),
             CASE(obj_reads_polygons_and_relative_indices), CASE(obj_vertex_colours_round_trip),
             CASE(obj_rejects_malformed), CASE(tgf_reads_and_derives_parents),
             CASE(tgf_rejects_malformed), CASE(dmat_round_trips_ascii_and_binary),
             CASE(dmat_rejects_malformed), CASE(weights_are_checked_and_normalised),
             CASE(parse_from_memory_matches_files), CASE(medit_and_obj_round_trip),
             CASE(surface_of_small_meshes), CASE(quality_of_known_tets), CASE(real_tet_meshes),
             CASE(real_surfaces_skeletons_and_matrices), CASE(real_every_asset_reads),
             CASE(real_truncation_sweep), CASE(byte_flips_never_crash))
