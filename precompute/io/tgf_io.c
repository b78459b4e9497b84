/* libigl .tgf skeleton reader. Layout (libigl readTGF): joint lines "index x y z
 * [extra numbers...]" with 1-based consecutive indices, a line starting with '#', edge
 * lines "a b [flag columns...]" (1-based joint ids; libigl's flags mark bone/pseudo/cage
 * edges; every edge here is a bone, as in the libigl tutorials that read E as BE), then
 * optionally another '#' and a section libigl ignores (so do we). Real files carry
 * extra columns on both kinds of line (hand.tgf joints, elephant.tgf edges). */
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "text_reader.h"

typedef struct tgf_state {
    double *joints;
    int32_t *bones, *parent;
    int64_t *bone_line;
    size_t nj, cap_j, nb, cap_b, cap_l;
} tgf_state;

static sinew_result joint_line(sw_text_reader *r, tgf_state *s) {
    int64_t idx;
    sinew_result rc = sw_text_int(r, 1, "joint index", &idx);
    if (rc) return rc;
    if (idx != (int64_t)s->nj + 1)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "joint index %lld, expected %lld (TGF joints are 1-based and "
                            "consecutive)",
                            (long long)idx, (long long)s->nj + 1);
    if (s->nj >= INT32_MAX / 4)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "too many joints");
    if (!sw_grow((void **)&s->joints, &s->cap_j, 3 * (s->nj + 1), sizeof(double)))
        return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int k = 0; k < 3; ++k)
        if ((rc = sw_text_double(r, 1, "joint coordinate", s->joints + 3 * s->nj + k))) return rc;
    const char *t;
    for (;;) { /* extra columns (libigl ignores them; hand.tgf has 16) must be numbers */
        size_t save = r->pos;
        if (sw_text_word(r, &t) == 0) break;
        r->pos = save;
        if ((rc = sw_text_number(r, 1, "extra joint column"))) return rc;
    }
    s->nj++;
    return SINEW_OK;
}

static sinew_result edge_line(sw_text_reader *r, tgf_state *s) {
    int64_t ab[2], flag;
    sinew_result rc;
    for (int k = 0; k < 2; ++k) {
        if ((rc = sw_text_int(r, 1, "edge joint index", ab + k))) return rc;
        if (ab[k] < 1 || ab[k] > (int64_t)s->nj)
            return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                                "joint index %lld outside 1..%lld (TGF indices are 1-based)",
                                (long long)ab[k], (long long)s->nj);
    }
    if (ab[0] == ab[1])
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "edge from joint %lld to itself",
                            (long long)ab[0]);
    const char *t;
    for (;;) { /* bone/pseudo/cage flag columns */
        size_t save = r->pos;
        if (sw_text_word(r, &t) == 0) break;
        r->pos = save;
        if ((rc = sw_text_int(r, 1, "edge flag", &flag))) return rc;
    }
    if (s->nb >= INT32_MAX / 4)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "too many edges");
    if (!sw_grow((void **)&s->bones, &s->cap_b, 2 * (s->nb + 1), sizeof(int32_t)) ||
        !sw_grow((void **)&s->bone_line, &s->cap_l, s->nb + 1, sizeof(int64_t)))
        return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    s->bones[2 * s->nb] = (int32_t)(ab[0] - 1);
    s->bones[2 * s->nb + 1] = (int32_t)(ab[1] - 1);
    s->bone_line[s->nb++] = r->tline;
    return SINEW_OK;
}

/* parent(b) = the bone whose tail is b's head (libigl directed_edge_parents). A joint
 * that ends two bones would make that ambiguous, and a parent chain longer than the
 * bone count is a cycle: both are errors naming the line. */
static sinew_result derive_parents(sw_text_reader *r, tgf_state *s) {
    int32_t nb = (int32_t)s->nb;
    int32_t *into = malloc((s->nj ? s->nj : 1) * sizeof(int32_t));
    s->parent = malloc((size_t)(nb ? nb : 1) * sizeof(int32_t));
    if (!into || !s->parent) {
        free(into);
        return sw_text_fail(r, 1, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    for (size_t j = 0; j < s->nj; ++j)
        into[j] = -1;
    for (int32_t b = 0; b < nb; ++b) {
        int32_t tail = s->bones[2 * b + 1];
        if (into[tail] >= 0) {
            sinew_result rc = sw_text_fail(
                r, s->bone_line[b], SINEW_ERROR_PARSE,
                "joint %d already ends the bone on line %lld (a joint can end only one bone)",
                tail + 1, (long long)s->bone_line[into[tail]]);
            free(into);
            return rc;
        }
        into[tail] = b;
    }
    for (int32_t b = 0; b < nb; ++b)
        s->parent[b] = into[s->bones[2 * b]];
    free(into);
    for (int32_t b = 0; b < nb; ++b) {
        int32_t depth = 0;
        for (int32_t p = s->parent[b]; p >= 0; p = s->parent[p])
            if (++depth > nb)
                return sw_text_fail(r, s->bone_line[b], SINEW_ERROR_PARSE,
                                    "the bone on this line is in a parent cycle");
    }
    return SINEW_OK;
}

static sinew_result parse(sw_text_reader *r, tgf_state *s) {
    int section = 0; /* 0 joints, 1 edges, 2 ignored */
    sinew_result rc = SINEW_OK;
    while (!rc && section < 2 && sw_text_skip_blank_lines(r)) {
        const char *t;
        size_t save = r->pos;
        size_t n = sw_text_word(r, &t);
        if (n > 0 && t[0] == '#') {
            section++;
        } else {
            r->pos = save;
            rc = section == 0 ? joint_line(r, s) : edge_line(r, s);
        }
        if (!sw_text_next_line(r)) break;
    }
    if (rc) return rc;
    if (s->nj == 0)
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE, "no joints in the file");
    return derive_parents(r, s);
}

/* Parses the opened reader `r` into *out (zeroed by the caller) and closes it. */
static sinew_result read_tgf(sw_text_reader *r, sw_skeleton *out) {
    tgf_state s;
    memset(&s, 0, sizeof s);
    sinew_result rc = parse(r, &s);
    sw_text_close(r);
    free(s.bone_line);
    if (rc) {
        free(s.joints);
        free(s.bones);
        free(s.parent);
        return rc;
    }
    out->njoints = (int32_t)s.nj;
    out->joints = s.joints;
    out->nbones = (int32_t)s.nb;
    out->bones = s.bones;
    out->parent = s.parent;
    return SINEW_OK;
}

sinew_result sw_read_tgf(const char *path, sw_skeleton *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_tgf: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open(&r, path, 0, err);
    return rc ? rc : read_tgf(&r, out);
}

sinew_result sw_parse_tgf(const char *text, size_t len, const char *name_for_errors,
                          sw_skeleton *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_tgf: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open_mem(&r, name_for_errors, text, len, 0, err);
    return rc ? rc : read_tgf(&r, out);
}
