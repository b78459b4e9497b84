/* TetGen .node/.ele reader and the extension dispatch of tet-mesh files.
 *
 * .node: "npoints 3 nattributes nmarkers", then per point "index x y z [attrs] [marker]".
 * .ele:  "ntets 4|10 nregion", then per tet "index n1 n2 n3 n4 [n5..n10] [region]".
 * TetGen numbers from 0 (-z) or 1; the first point index says which, and the .ele
 * indices use the same base. Lines are entries; '#' starts a comment. */
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "text_reader.h"

/* Reads the header's integers: `need` mandatory, up to `nmax` total (missing optional
 * ones stay 0). */
static sinew_result read_header(sw_text_reader *r, int need, int nmax, const char **names,
                                int64_t *v) {
    if (!sw_text_skip_blank_lines(r))
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE,
                            "unexpected end of file: expected the header line");
    for (int k = 0; k < nmax; ++k)
        v[k] = 0;
    for (int k = 0; k < nmax; ++k) {
        if (k >= need) {
            const char *t;
            size_t save = r->pos;
            if (sw_text_word(r, &t) == 0) break;
            r->pos = save;
        }
        sinew_result rc = sw_text_int(r, 1, names[k], v + k);
        if (rc) return rc;
    }
    return sw_text_expect_eol(r, "the header");
}

/* Positions the cursor at the next entry line and reads its consecutive index. */
static sinew_result entry_start(sw_text_reader *r, const char *what, int64_t i, int64_t n,
                                int64_t *base) {
    if (i > 0) sw_text_next_line(r);
    if (!sw_text_skip_blank_lines(r))
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE,
                            "unexpected end of file: expected %s %lld of %lld", what,
                            (long long)(i + 1), (long long)n);
    int64_t idx;
    sinew_result rc = sw_text_int(r, 1, "index", &idx);
    if (rc) return rc;
    if (i == 0 && idx != 0 && idx != 1)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "first %s index is %lld (must be 0 or 1: it sets 0/1-based numbering)",
                            what, (long long)idx);
    if (i == 0) *base = idx;
    if (idx != *base + i)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "%s index %lld, expected %lld (%lld-based, consecutive)", what,
                            (long long)idx, (long long)(*base + i), (long long)*base);
    return SINEW_OK;
}

static sinew_result read_node(sw_text_reader *r, int64_t *base, int32_t *nverts, double **X) {
    static const char *names[] = {"point count", "dimension", "attribute count", "marker count"};
    int64_t h[4];
    sinew_result rc = read_header(r, 2, 4, names, h);
    if (rc) return rc;
    if (h[1] != 3)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "dimension %lld (must be 3)",
                            (long long)h[1]);
    if (h[2] < 0 || h[2] > 1000 || h[3] < 0 || h[3] > 1)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "bad header: %lld attributes, %lld markers", (long long)h[2],
                            (long long)h[3]);
    if ((rc = sw_text_check_count(r, h[0], 4 + h[2] + h[3], "points"))) return rc;
    *nverts = (int32_t)h[0];
    *X = malloc(3 * (size_t)(h[0] ? h[0] : 1) * sizeof(double));
    if (!*X) return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    sw_text_next_line(r);
    for (int64_t i = 0; i < h[0]; ++i) {
        if ((rc = entry_start(r, "point", i, h[0], base))) return rc;
        for (int k = 0; k < 3; ++k)
            if ((rc = sw_text_double(r, 1, "point coordinate", *X + 3 * i + k))) return rc;
        for (int64_t a = 0; a < h[2]; ++a)
            if ((rc = sw_text_number(r, 1, "point attribute"))) return rc;
        int64_t marker;
        if (h[3] && (rc = sw_text_int(r, 1, "boundary marker", &marker))) return rc;
        if ((rc = sw_text_expect_eol(r, "the point"))) return rc;
    }
    return SINEW_OK;
}

static sinew_result read_ele(sw_text_reader *r, int32_t *ntets, int32_t **tets, int64_t **lines) {
    static const char *names[] = {"tetrahedron count", "nodes per tetrahedron", "region flag"};
    int64_t h[3], base = 0;
    sinew_result rc = read_header(r, 2, 3, names, h);
    if (rc) return rc;
    if ((h[1] != 4 && h[1] != 10) || h[2] < 0 || h[2] > 1)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "bad header: %lld nodes per tetrahedron (4 or 10), region flag %lld",
                            (long long)h[1], (long long)h[2]);
    if ((rc = sw_text_check_count(r, h[0], 1 + h[1] + h[2], "tetrahedra"))) return rc;
    *ntets = (int32_t)h[0];
    *tets = malloc(4 * (size_t)(h[0] ? h[0] : 1) * sizeof(int32_t));
    *lines = malloc((size_t)(h[0] ? h[0] : 1) * sizeof(int64_t));
    if (!*tets || !*lines)
        return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    sw_text_next_line(r);
    for (int64_t t = 0; t < h[0]; ++t) {
        if ((rc = entry_start(r, "tetrahedron", t, h[0], &base))) return rc;
        (*lines)[t] = r->tline;
        for (int64_t k = 0; k < h[1]; ++k) { /* 10-node tets: the 4 corners come first */
            int64_t id;
            if ((rc = sw_text_int(r, 1, "tetrahedron vertex index", &id))) return rc;
            if (id < INT32_MIN || id > INT32_MAX)
                return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                                    "vertex index %lld out of range", (long long)id);
            if (k < 4) (*tets)[4 * t + k] = (int32_t)id;
        }
        if (h[2] && (rc = sw_text_number(r, 1, "region attribute"))) return rc;
        if ((rc = sw_text_expect_eol(r, "the tetrahedron"))) return rc;
    }
    return SINEW_OK;
}

/* Parses the opened .node and .ele readers into *out (zeroed by the caller) and closes
 * both. */
static sinew_result read_tetgen(sw_text_reader *rn, sw_text_reader *re, sw_tetmesh *out) {
    sw_tetmesh m = {0, 0, NULL, NULL};
    int64_t base = 0, *lines = NULL;
    sinew_result rc = read_node(rn, &base, &m.nverts, &m.X);
    if (!rc) rc = read_ele(re, &m.ntets, &m.tets, &lines);
    if (!rc && (m.nverts < 4 || m.ntets < 1))
        rc = sw_text_fail(re, 1, SINEW_ERROR_DEGENERATE, "empty mesh (%d points, %d tetrahedra)",
                          m.nverts, m.ntets);
    if (!rc) rc = sw_text_check_tets(re, "TetGen", base, m.nverts, m.X, m.ntets, m.tets, lines);
    if (!rc) rc = sw_text_validate_tets(re, &m);
    free(lines);
    sw_text_close(rn);
    sw_text_close(re);
    if (rc) {
        sw_tetmesh_free(&m);
        return rc;
    }
    *out = m;
    return SINEW_OK;
}

sinew_result sw_read_tetgen(const char *node_path, const char *ele_path, sw_tetmesh *out,
                            sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_tetgen: no output");
    sw_text_reader rn, re;
    sinew_result rc = sw_text_open(&rn, node_path, '#', err);
    if (rc) return rc;
    if ((rc = sw_text_open(&re, ele_path, '#', err))) {
        sw_text_close(&rn);
        return rc;
    }
    return read_tetgen(&rn, &re, out);
}

sinew_result sw_parse_tetgen(const char *node_text, size_t node_len, const char *node_name,
                             const char *ele_text, size_t ele_len, const char *ele_name,
                             sw_tetmesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_tetgen: no output");
    sw_text_reader rn, re;
    sinew_result rc =
        sw_text_open_mem(&rn, node_name ? node_name : "<node>", node_text, node_len, '#', err);
    if (rc) return rc;
    if ((rc = sw_text_open_mem(&re, ele_name ? ele_name : "<ele>", ele_text, ele_len, '#', err))) {
        sw_text_close(&rn);
        return rc;
    }
    return read_tetgen(&rn, &re, out);
}

static int has_suffix(const char *s, const char *suf) {
    size_t n = strlen(s), k = strlen(suf);
    return n >= k && strcmp(s + n - k, suf) == 0;
}

sinew_result sw_read_tetmesh(const char *path, sw_tetmesh *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!path || !out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_tetmesh: bad arguments");
    if (has_suffix(path, ".mesh")) return sw_read_medit(path, out, err);
    int is_node = has_suffix(path, ".node");
    if (!is_node && !has_suffix(path, ".ele"))
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                            "%s: unknown tet mesh extension (.mesh, .node or .ele)", path);
    size_t stem = strlen(path) - (is_node ? 5 : 4);
    char *node = malloc(stem + 6), *ele = malloc(stem + 5);
    if (!node || !ele) {
        free(node);
        free(ele);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    memcpy(node, path, stem);
    memcpy(node + stem, ".node", 6);
    memcpy(ele, path, stem);
    memcpy(ele + stem, ".ele", 5);
    sinew_result rc = sw_read_tetgen(node, ele, out, err);
    free(node);
    free(ele);
    return rc;
}
