/* Wavefront OBJ surface reader and writer. Only geometry is kept: "v x y z [w|r g b]"
 * and "f" polygons, whose corners may be "v", "v/vt", "v//vn" or "v/vt/vn", with
 * 1-based or negative (relative to the vertices read so far) indices. Polygons are
 * fan-triangulated from their first corner. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "text_reader.h"

static int word_is(const char *t, size_t n, const char *w) {
    return strlen(w) == n && memcmp(t, w, n) == 0;
}

/* Statements that carry no geometry we need (texture, normals, grouping, materials,
 * free-form geometry): skipped whole. */
static int ignored_statement(const char *t, size_t n) {
    static const char *names[] = {
        "vt",       "vn",        "vp",         "g",      "o",      "s",      "usemtl", "mtllib",
        "l",        "p",         "mg",         "maplib", "usemap", "lod",    "bevel",  "c_interp",
        "d_interp", "trace_obj", "shadow_obj", "ctech",  "stech",  "cstype", "deg",    "bmat",
        "step",     "curv",      "curv2",      "surf",   "parm",   "trim",   "hole",   "scrv",
        "sp",       "end",       "con",        "call",   "csh"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (word_is(t, n, names[i])) return 1;
    return 0;
}

/* Resolves one face corner "v[/vt][/vn]" to a 0-based vertex id. */
static sinew_result corner(sw_text_reader *r, const char *t, size_t n, int64_t nread, int32_t *id) {
    const char *part[3];
    size_t len[3], s = 0;
    int np = 0, ok = 1;
    int64_t v = 0, aux;
    for (;;) {
        size_t e = s;
        while (e < n && t[e] != '/')
            ++e;
        if (np == 3) {
            ok = 0;
            break;
        }
        part[np] = t + s;
        len[np++] = e - s;
        if (e == n) break;
        s = e + 1;
    }
    /* the vt and vn parts are ignored but must be integers ("v//vn" leaves vt empty) */
    if (ok) ok = sw_parse_int(part[0], len[0], &v);
    if (ok && np >= 2) ok = len[1] ? sw_parse_int(part[1], len[1], &aux) : np == 3;
    if (ok && np == 3) ok = sw_parse_int(part[2], len[2], &aux);
    if (!ok)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "bad face corner '%.*s' (expected v, v/vt, v//vn or v/vt/vn)",
                            (int)(n < 24 ? n : 24), t);
    if (v == 0)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "vertex index 0 (OBJ indices are 1-based, or negative = relative)");
    int64_t res = v > 0 ? v - 1 : nread + v;
    if (res < 0 || res >= nread)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "vertex index %lld out of range: %lld vertices defined so far (OBJ "
                            "indices are 1-based, or negative = relative)",
                            (long long)v, (long long)nread);
    *id = (int32_t)res;
    return SINEW_OK;
}

typedef struct obj_state {
    double *X;
    int32_t *tris;
    size_t nv, cap_v, nt, cap_t;
    double *C; /* 3 per vertex: its "v x y z r g b" colour (want_colors only) */
    size_t cap_c;
    int colored; /* every vertex so far had a colour */
    int want_colors;
} obj_state;

static sinew_result read_vertex(sw_text_reader *r, obj_state *s) {
    sinew_result rc;
    if (s->nv >= INT32_MAX / 4)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "too many vertices");
    if (!sw_grow((void **)&s->X, &s->cap_v, 3 * (s->nv + 1), sizeof(double)))
        return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int k = 0; k < 3; ++k)
        if ((rc = sw_text_double(r, 1, "vertex coordinate", s->X + 3 * s->nv + k))) return rc;
    double extra[4];
    int nextra = 0;
    for (int k = 0; k < 4; ++k) { /* optional w or vertex colour */
        const char *t;
        size_t save = r->pos;
        if (sw_text_word(r, &t) == 0) break;
        r->pos = save;
        if ((rc = sw_text_double(r, 1, "vertex weight or colour", extra + nextra))) return rc;
        nextra++;
    }
    s->colored = s->colored && nextra == 3;
    if (s->want_colors && s->colored) {
        if (!sw_grow((void **)&s->C, &s->cap_c, 3 * (s->nv + 1), sizeof(double)))
            return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        for (int k = 0; k < 3; ++k) /* a colour outside [0, 1] is clamped into it */
            s->C[3 * s->nv + k] = extra[k] > 1 ? 1 : extra[k] > 0 ? extra[k] : 0;
    }
    if ((rc = sw_text_expect_eol(r, "the vertex"))) return rc;
    s->nv++;
    return SINEW_OK;
}

static sinew_result read_face(sw_text_reader *r, obj_state *s) {
    int32_t first = -1, prev = -1, id = -1;
    int corners = 0;
    const char *t;
    size_t n;
    sinew_result rc;
    while ((n = sw_text_word(r, &t)) > 0) {
        if ((rc = corner(r, t, n, (int64_t)s->nv, &id))) return rc;
        if (corners == 0) first = id;
        if (corners >= 2) {
            if (s->nt >= INT32_MAX / 4)
                return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "too many faces");
            if (!sw_grow((void **)&s->tris, &s->cap_t, 3 * (s->nt + 1), sizeof(int32_t)))
                return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
            int32_t *tri = s->tris + 3 * s->nt++;
            tri[0] = first;
            tri[1] = prev;
            tri[2] = id;
        }
        prev = id;
        corners++;
    }
    if (corners < 3)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "face with %d corners (at least 3)",
                            corners);
    return SINEW_OK;
}

/* Parses the opened reader `r` into *out (zeroed by the caller) and closes it. */
static sinew_result read_obj(sw_text_reader *r, sw_trimesh *out, double **colors) {
    sinew_result rc = SINEW_OK;
    obj_state s;
    memset(&s, 0, sizeof s);
    s.colored = 1;
    s.want_colors = colors != NULL;
    while (!rc && sw_text_skip_blank_lines(r)) {
        const char *t;
        size_t n = sw_text_word(r, &t);
        if (word_is(t, n, "v")) {
            rc = read_vertex(r, &s);
        } else if (word_is(t, n, "f")) {
            rc = read_face(r, &s);
        } else if (!ignored_statement(t, n)) {
            rc = sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "unknown OBJ statement '%.*s'",
                              (int)(n < 24 ? n : 24), t);
        }
        if (!sw_text_next_line(r)) break;
    }
    if (!rc && (s.nv == 0 || s.nt == 0))
        rc = sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE, "no %s in the file",
                          s.nv == 0 ? "vertices" : "faces");
    sw_text_close(r);
    if (rc || !s.colored || !colors) free(s.C);
    if (rc) {
        free(s.X);
        free(s.tris);
        return rc;
    }
    if (colors) *colors = s.colored ? s.C : NULL;
    out->nverts = (int32_t)s.nv;
    out->ntris = (int32_t)s.nt;
    out->X = s.X;
    out->tris = s.tris;
    return SINEW_OK;
}

sinew_result sw_read_obj(const char *path, sw_trimesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_obj: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open(&r, path, '#', err);
    return rc ? rc : read_obj(&r, out, NULL);
}

sinew_result sw_read_obj_colors(const char *path, sw_trimesh *out, double **colors, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (colors) *colors = NULL;
    if (!out || !colors)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_obj_colors: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open(&r, path, '#', err);
    return rc ? rc : read_obj(&r, out, colors);
}

sinew_result sw_parse_obj(const char *text, size_t len, const char *name_for_errors,
                          sw_trimesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_obj: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open_mem(&r, name_for_errors, text, len, '#', err);
    return rc ? rc : read_obj(&r, out, NULL);
}

sinew_result sw_write_obj(const char *path, int32_t nverts, const double *X, int32_t ntris,
                          const int32_t *tris, sw_error *err) {
    return sw_write_obj_colors(path, nverts, X, NULL, ntris, tris, err);
}

sinew_result sw_write_obj_colors(const char *path, int32_t nverts, const double *X, const double *C,
                                 int32_t ntris, const int32_t *tris, sw_error *err) {
    if (!path || nverts < 0 || ntris < 0 || (nverts && !X) || (ntris && !tris))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_write_obj: bad arguments");
    for (int64_t i = 0; i < 3 * (int64_t)ntris; ++i)
        if (tris[i] < 0 || tris[i] >= nverts)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "sw_write_obj: triangle %lld references vertex %d of %d",
                                (long long)(i / 3), tris[i], nverts);
    FILE *f = fopen(path, "w");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open for writing", path);
    for (int32_t v = 0; v < nverts; ++v) {
        fprintf(f, "v %.17g %.17g %.17g", X[3 * v], X[3 * v + 1], X[3 * v + 2]);
        if (C) fprintf(f, " %.4g %.4g %.4g", C[3 * v], C[3 * v + 1], C[3 * v + 2]);
        fputc('\n', f);
    }
    for (int32_t t = 0; t < ntris; ++t)
        fprintf(f, "f %d %d %d\n", tris[3 * t] + 1, tris[3 * t + 1] + 1, tris[3 * t + 2] + 1);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) return sw_error_set(err, SINEW_ERROR_IO, "%s: write failed", path);
    return SINEW_OK;
}
