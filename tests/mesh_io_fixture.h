/* The mesh I/O tests' shared fixtures (test_mesh_io.c, test_mesh_io_real.c): a per-run
 * temp folder and the files written into it, error-message checks, the small Medit,
 * TetGen, OBJ and TGF texts (their line numbers matter), a xorshift generator, and the
 * closed-surface and enclosed-volume checks. Everything is static inline or a static
 * const array (a test uses what it needs). Define _POSIX_C_SOURCE 200809L (mkdtemp)
 * before including it. */
#ifndef SW_MESH_IO_FIXTURE_H
#define SW_MESH_IO_FIXTURE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_io.h"

/* ---- temp files ---------------------------------------------------------------- */

static char g_dir[64];
static char g_names[256][32];
static int g_nnames;

static inline void cleanup(void) {
    char p[128];
    for (int i = 0; i < g_nnames; ++i) {
        snprintf(p, sizeof p, "%s/%.31s", g_dir, g_names[i]);
        remove(p);
    }
    if (g_dir[0]) rmdir(g_dir);
}

/* Path of `name` in this run's temp dir (created on first use, removed at exit). */
static inline const char *tmp_path(const char *name) {
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

static inline const char *write_bytes(const char *name, const void *data, size_t n) {
    const char *p = tmp_path(name);
    FILE *f = fopen(p, "wb");
    if (!f) return p;
    fwrite(data, 1, n, f);
    fclose(f);
    return p;
}

static inline const char *write_text(const char *name, const char *text) {
    return write_bytes(name, text, strlen(text));
}

/* Returns a malloc'd copy of `s` with the first `from` replaced by `to`. */
static inline char *replace(const char *s, const char *from, const char *to) {
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

static inline int all_zero(const void *p, size_t n) {
    const unsigned char *b = p;
    for (size_t i = 0; i < n; ++i)
        if (b[i]) return 0;
    return 1;
}

/* The error carries `code`, names the file's base name and (line > 0) ":line:". */
static inline int err_is(sinew_result rc, const sw_error *e, sinew_result code, const char *path,
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

static inline int has(const sw_error *e, const char *word) {
    if (strstr(e->msg, word)) return 1;
    fprintf(stderr, "  message '%s' lacks '%s'\n", e->msg, word);
    return 0;
}

/* ---- a two-tet Medit file ------------------------------------------------------ */

/* Tets (1,2,3,4) and (2,3,4,5) share face 2-3-4; both positive. Line numbers matter. */
static const char k_medit[] = "MeshVersionFormatted 1\n"       /* 1 */
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

static inline double total_volume(const sw_tetmesh *m) {
    double v = 0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *q = m->tets + 4 * t;
        v += sw_tet_signed_volume(m->X + 3 * q[0], m->X + 3 * q[1], m->X + 3 * q[2],
                                  m->X + 3 * q[3]);
    }
    return v;
}

/* ---- TetGen -------------------------------------------------------------------- */

static const char k_node1[] = "# five points, one attribute, markers\n" /* 1 */
                              "5 3 1 1\n"                               /* 2 */
                              "1 0 0 0 7.5 1\n"                         /* 3 */
                              "2 1 0 0 7.5 1\n"                         /* 4 */
                              "\n"                                      /* 5 */
                              "3 0 1 0 7.5 0   # inline comment\n"      /* 6 */
                              "4 0 0 1 7.5 1\n"                         /* 7 */
                              "5 1 1 1 7.5 1\n";                        /* 8 */
static const char k_ele1[] = "2 4 1\n"                                  /* 1 */
                             "1 1 2 3 4 -1\n"                           /* 2 */
                             "2 3 2 4 5 2\n"; /* 3: negative, gets reoriented */

/* ---- OBJ ----------------------------------------------------------------------- */

static const char k_obj[] = "# quad and triangle\n"       /* 1 */
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

/* ---- TGF ----------------------------------------------------------------------- */

static const char k_tgf[] = "1\t0 0 0\n"         /* 1 */
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

/* ---- random numbers ------------------------------------------------------------ */

static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static inline uint64_t rnd(void) { /* xorshift64* */
    g_rng ^= g_rng >> 12;
    g_rng ^= g_rng << 25;
    g_rng ^= g_rng >> 27;
    return g_rng * 2685821657736338717ull;
}
static inline double rnd_unit(void) {
    return (double)(rnd() >> 11) / 9007199254740992.0;
}

/* ---- surface checks ------------------------------------------------------------ */

static inline int cmp_i64(const void *a, const void *b) {
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Every directed edge appears once and its reverse once: closed, consistently oriented,
 * each edge in exactly two triangles. */
static inline int surface_closed(const sw_surface *s, int32_t nverts) {
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
static inline double enclosed_volume(const sw_surface *s, const double *X) {
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

#endif
