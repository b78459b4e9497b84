/* Medit .mesh reader and writer (ASCII, 3D). The format is a stream of keywords, each
 * followed by a count and that many fixed-width entries; indices are 1-based and every
 * entry ends with an integer reference (region/boundary label) that we ignore. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "text_reader.h"

/* Case-insensitive keyword match (Medit writers differ in capitalisation). */
static int keyword_is(const char *tok, size_t n, const char *kw) {
    if (strlen(kw) != n) return 0;
    for (size_t i = 0; i < n; ++i) {
        char a = tok[i], b = kw[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (b >= 'A' && b <= 'Z') b = (char)(b - 'A' + 'a');
        if (a != b) return 0;
    }
    return 1;
}

/* Blocks we skip, with the number of tokens per entry (reference column included). */
static const struct {
    const char *name;
    int width;
} skipped_blocks[] = {
    {"Triangles", 4},        {"Edges", 3},
    {"Corners", 1},          {"Ridges", 1},
    {"Quadrilaterals", 5},   {"Hexahedra", 9},
    {"Prisms", 7},           {"RequiredVertices", 1},
    {"RequiredEdges", 1},    {"RequiredTriangles", 1},
    {"Normals", 3},          {"Tangents", 3},
    {"NormalAtVertices", 2}, {"TangentAtVertices", 2},
    {"TangentAtEdges", 3},
};

typedef struct medit_state {
    int32_t nverts, ntets;
    double *X;
    int32_t *tets;
    int64_t *lines;
    int have_verts, have_tets;
} medit_state;

static sinew_result read_vertices(sw_text_reader *r, medit_state *s, int64_t kw_line) {
    int64_t n;
    sinew_result rc = sw_text_int(r, 0, "vertex count", &n);
    if (rc) return rc;
    if (s->have_verts) return sw_text_fail(r, kw_line, SINEW_ERROR_PARSE, "second Vertices block");
    if ((rc = sw_text_check_count(r, n, 4, "vertices"))) return rc;
    s->have_verts = 1;
    s->nverts = (int32_t)n;
    s->X = malloc(3 * (size_t)(n ? n : 1) * sizeof(double));
    if (!s->X) return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int64_t v = 0; v < n; ++v) {
        int64_t ref;
        for (int k = 0; k < 3; ++k)
            if ((rc = sw_text_double(r, 0, "vertex coordinate", s->X + 3 * v + k))) return rc;
        if ((rc = sw_text_int(r, 0, "vertex reference", &ref))) return rc;
    }
    return SINEW_OK;
}

static sinew_result read_tets(sw_text_reader *r, medit_state *s, int64_t kw_line) {
    int64_t n;
    sinew_result rc = sw_text_int(r, 0, "tetrahedron count", &n);
    if (rc) return rc;
    if (s->have_tets) return sw_text_fail(r, kw_line, SINEW_ERROR_PARSE, "second Tetrahedra block");
    if ((rc = sw_text_check_count(r, n, 5, "tetrahedra"))) return rc;
    s->have_tets = 1;
    s->ntets = (int32_t)n;
    s->tets = malloc(4 * (size_t)(n ? n : 1) * sizeof(int32_t));
    s->lines = malloc((size_t)(n ? n : 1) * sizeof(int64_t));
    if (!s->tets || !s->lines)
        return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int64_t t = 0; t < n; ++t) {
        int64_t id, ref;
        for (int k = 0; k < 4; ++k) {
            if ((rc = sw_text_int(r, 0, "tetrahedron vertex index", &id))) return rc;
            if (k == 0) s->lines[t] = r->tline;
            if (id < INT32_MIN || id > INT32_MAX)
                return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                                    "vertex index %lld out of range (Medit indices are 1-based)",
                                    (long long)id);
            s->tets[4 * t + k] = (int32_t)id;
        }
        if ((rc = sw_text_int(r, 0, "tetrahedron reference", &ref))) return rc;
    }
    return SINEW_OK;
}

/* Skips `width` numeric tokens per entry of a block we do not use. */
static sinew_result skip_block(sw_text_reader *r, const char *name, int width) {
    int64_t n;
    sinew_result rc = sw_text_int(r, 0, "block count", &n);
    if (rc) return rc;
    if ((rc = sw_text_check_count(r, n, width, name))) return rc;
    for (int64_t i = 0; i < n * width; ++i)
        if ((rc = sw_text_number(r, 0, name))) return rc;
    return SINEW_OK;
}

static sinew_result parse(sw_text_reader *r, medit_state *s) {
    sinew_result rc;
    const char *t;
    size_t n;
    while ((n = sw_text_token(r, &t)) > 0) {
        int64_t line = r->tline, v;
        if (keyword_is(t, n, "End")) break;
        if (keyword_is(t, n, "MeshVersionFormatted")) {
            if ((rc = sw_text_int(r, 0, "mesh version", &v))) return rc;
            if (v < 1 || v > 4)
                return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "unknown mesh version %lld",
                                    (long long)v);
        } else if (keyword_is(t, n, "Dimension")) {
            if ((rc = sw_text_int(r, 0, "dimension", &v))) return rc;
            if (v != 3)
                return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                                    "dimension %lld (only 3D meshes are supported)", (long long)v);
        } else if (keyword_is(t, n, "Vertices")) {
            if ((rc = read_vertices(r, s, line))) return rc;
        } else if (keyword_is(t, n, "Tetrahedra")) {
            if ((rc = read_tets(r, s, line))) return rc;
        } else {
            size_t b = 0, nb = sizeof skipped_blocks / sizeof skipped_blocks[0];
            while (b < nb && !keyword_is(t, n, skipped_blocks[b].name))
                ++b;
            if (b == nb) {
                char q[32];
                size_t k = n < 24 ? n : 24;
                for (size_t i = 0; i < k; ++i)
                    q[i] = (t[i] >= 32 && t[i] < 127) ? t[i] : '?';
                q[k] = '\0';
                return sw_text_fail(r, line, SINEW_ERROR_PARSE, "unknown Medit keyword '%s'", q);
            }
            if ((rc = skip_block(r, skipped_blocks[b].name, skipped_blocks[b].width))) return rc;
        }
    }
    if (!s->have_verts)
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE, "no Vertices block");
    if (!s->have_tets)
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE, "no Tetrahedra block");
    if (s->nverts < 4 || s->ntets < 1)
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_DEGENERATE,
                            "empty mesh (%d vertices, %d tetrahedra)", s->nverts, s->ntets);
    return sw_text_check_tets(r, "Medit", 1, s->nverts, s->X, s->ntets, s->tets, s->lines);
}

/* Parses the opened reader `r` into *out (zeroed by the caller) and closes it. */
static sinew_result read_medit(sw_text_reader *r, sw_tetmesh *out) {
    medit_state s;
    memset(&s, 0, sizeof s);
    sinew_result rc = parse(r, &s);
    sw_tetmesh m = {s.nverts, s.ntets, s.X, s.tets};
    if (!rc) rc = sw_text_validate_tets(r, &m);
    free(s.lines);
    sw_text_close(r);
    if (rc) {
        free(s.X);
        free(s.tets);
        return rc;
    }
    *out = m;
    return SINEW_OK;
}

sinew_result sw_read_medit(const char *path, sw_tetmesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_medit: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open(&r, path, '#', err);
    return rc ? rc : read_medit(&r, out);
}

sinew_result sw_parse_medit(const char *text, size_t len, const char *name_for_errors,
                            sw_tetmesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_medit: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open_mem(&r, name_for_errors, text, len, '#', err);
    return rc ? rc : read_medit(&r, out);
}

sinew_result sw_write_medit(const char *path, const sw_tetmesh *m, sw_error *err) {
    if (!path || !m || m->nverts < 0 || m->ntets < 0 || (m->nverts && !m->X) ||
        (m->ntets && !m->tets))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_write_medit: bad arguments");
    FILE *f = fopen(path, "w");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open for writing", path);
    /* version 2 = double precision; %.17g round-trips every double exactly */
    fprintf(f, "MeshVersionFormatted 2\nDimension 3\nVertices\n%d\n", m->nverts);
    for (int32_t v = 0; v < m->nverts; ++v)
        fprintf(f, "%.17g %.17g %.17g 0\n", m->X[3 * v], m->X[3 * v + 1], m->X[3 * v + 2]);
    fprintf(f, "Tetrahedra\n%d\n", m->ntets);
    for (int32_t t = 0; t < m->ntets; ++t)
        fprintf(f, "%d %d %d %d 0\n", m->tets[4 * t] + 1, m->tets[4 * t + 1] + 1,
                m->tets[4 * t + 2] + 1, m->tets[4 * t + 3] + 1);
    fprintf(f, "End\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) return sw_error_set(err, SINEW_ERROR_IO, "%s: write failed", path);
    return SINEW_OK;
}
