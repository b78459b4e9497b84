/* The optional render mesh of a blob (sinew_blob_format.h, ids 27..34): its sections'
 * presence and counts (layer 1, sw_blob_render_fill) and its indices and values (layer 2,
 * sw_blob_render_validate, shared with the writer), in the manner of blob_load.c. */
#include <math.h>
#include <string.h>

#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_render_meta) == 32, "RENDER_META is 32 bytes");

/* Declares a `const uint64_t` local for every render count of the view `v`, for the count
 * expressions of SINEW_BLOB_RENDER_SECTIONS. */
#define RENDER_COUNT_LOCAL(name)                                                                   \
    const uint64_t name = (uint64_t)v->name;                                                       \
    (void)name;

static sinew_result check_counts(const sw_blob_view *v, char *msg, size_t ms) {
    const struct {
        const char *name;
        int64_t value, hi;
    } counts[] = {
#define COUNT(name) {#name, v->name, SW_BLOB_MAX_COUNT},
        SINEW_BLOB_RENDER_COUNTS(COUNT)
#undef COUNT
    };
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; ++i)
        if (counts[i].value < 1 || counts[i].value > counts[i].hi)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section RENDER_META: %s = %lld outside [1, %lld]", counts[i].name,
                        (long long)counts[i].value, (long long)counts[i].hi);
    return SINEW_OK;
}

sinew_result sw_blob_render_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                 const int found[], sw_blob_view *v, char *msg, size_t ms) {
    int present = 0;
    for (uint32_t id = SINEW_SECTION_RENDER_FIRST; id <= SINEW_SECTION_ID_MAX; ++id)
        present += found[id] >= 0;
    if (present == 0) return SINEW_OK; /* no render mesh: the view's fields stay 0 / NULL */
    for (uint32_t id = SINEW_SECTION_RENDER_FIRST; id <= SINEW_SECTION_ID_MAX; ++id)
        if (found[id] < 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: missing (the render mesh's sections come all or none)",
                        sw_blob_section_name(id));
    const sinew_blob_section *meta = &s[found[SINEW_SECTION_RENDER_META]];
    if (meta->count != 1)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section RENDER_META: %llu elements, expected 1",
                    (unsigned long long)meta->count);
    sinew_blob_render_meta m;
    memcpy(&m, bytes + meta->offset, sizeof m);
    for (size_t i = 0; i < sizeof m.reserved / sizeof m.reserved[0]; ++i)
        if (m.reserved[i] != 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section RENDER_META: reserved word %zu is %d, not 0", i,
                        m.reserved[i]);
#define FROM_META(name) v->name = m.name;
    SINEW_BLOB_RENDER_COUNTS(FROM_META)
#undef FROM_META
    sinew_result r = check_counts(v, msg, ms);
    if (r != SINEW_OK) return r;
    SINEW_BLOB_RENDER_COUNTS(RENDER_COUNT_LOCAL)
    const struct {
        uint32_t id;
        uint64_t count;
        const char *formula;
    } expect[] = {
#define EXPECT(id, NAME, elem_size, type, field, by_meta, count, formula) {id, count, formula},
        SINEW_BLOB_RENDER_ARRAY_SECTIONS(EXPECT)
#undef EXPECT
    };
    for (size_t i = 0; i < sizeof expect / sizeof expect[0]; ++i) {
        const sinew_blob_section *e = &s[found[expect[i].id]];
        if (e->count != expect[i].count)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: %llu elements, RENDER_META needs %s = %llu",
                        sw_blob_section_name(expect[i].id), (unsigned long long)e->count,
                        expect[i].formula, (unsigned long long)expect[i].count);
    }
#define AT(id, NAME, elem_size, type, field, ...)                                                  \
    v->field = (const type *)(const void *)(bytes + s[found[id]].offset);
    SINEW_BLOB_RENDER_ARRAY_SECTIONS(AT)
#undef AT
    return SINEW_OK;
}

/* A render node is one simulation vertex: all its copies are copies of the same one. */
static sinew_result check_nodes(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r = sw_blob_check_copy_ptr(
        SINEW_SECTION_RENDER_NODE_PTR, SINEW_SECTION_RENDER_NODE_COPIES, "render node",
        v->render_node_ptr, v->nrender_nodes, v->nrender_copies, msg, ms);
    if (r != SINEW_OK) return r;
    const int32_t *c = v->render_node_copies;
    if ((r = sw_blob_check_copies(SINEW_SECTION_RENDER_NODE_COPIES, v, c, v->nrender_copies, msg,
                                  ms)) != SINEW_OK)
        return r;
    for (int32_t n = 0; n < v->nrender_nodes; ++n) {
        int32_t b = v->render_node_ptr[n];
        int32_t gv = v->domain_verts[v->domains[c[2 * b]].vert_begin + c[2 * b + 1]];
        for (int32_t k = b + 1; k < v->render_node_ptr[n + 1]; ++k) {
            int32_t other = v->domain_verts[v->domains[c[2 * k]].vert_begin + c[2 * k + 1]];
            if (other != gv)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section RENDER_NODE_COPIES: render node %d: copy %d is of "
                            "vertex %d, its first copy of vertex %d",
                            n, k, other, gv);
        }
    }
    return SINEW_OK;
}

/* Each render vertex: a tet in range, and barycentrics that are finite, bounded (an
 * extrapolation the bake would have refused amplifies every motion of the tet) and sum to
 * 1 (so a rigid motion of the tet moves the vertex rigidly). */
static sinew_result check_embedding(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r;
    if ((r = sw_blob_check_indices(SINEW_SECTION_RENDER_TETS, "tet", 4, v->render_tets,
                                   v->nembed_tets, "render node", v->nrender_nodes, msg, ms)) ||
        (r = sw_blob_check_indices(SINEW_SECTION_RENDER_TET, "render vertex", 1, v->render_tet,
                                   v->nrender_verts, "tet", v->nembed_tets, msg, ms)))
        return r;
    for (int32_t i = 0; i < v->nrender_verts; ++i) {
        const double *b = v->render_bary + 4 * (int64_t)i;
        double sum = 0;
        for (int k = 0; k < 4; ++k) {
            if (!isfinite(b[k]))
                return fail(msg, ms, SINEW_ERROR_NOT_FINITE,
                            "blob section RENDER_BARY: render vertex %d: barycentric %d is %g", i,
                            k, b[k]);
            if (fabs(b[k]) > SW_BLOB_MAX_BARY)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section RENDER_BARY: render vertex %d: barycentric %d is %g, "
                            "beyond +-%g",
                            i, k, b[k], SW_BLOB_MAX_BARY);
            sum += b[k];
        }
        if (fabs(sum - 1.0) > SW_BLOB_WEIGHT_SUM_TOL)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section RENDER_BARY: render vertex %d: barycentrics sum to %.9g, "
                        "not 1 (tol %g)",
                        i, sum, SW_BLOB_WEIGHT_SUM_TOL);
    }
    return SINEW_OK;
}

/* The weld map names a representative that stands for itself: duplicates are copied from
 * a vertex the runtime computes, never from another duplicate. */
static sinew_result check_weld(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r =
        sw_blob_check_indices(SINEW_SECTION_RENDER_WELD, "render vertex", 1, v->render_weld,
                              v->nrender_verts, "representative", v->nrender_verts, msg, ms);
    if (r != SINEW_OK) return r;
    for (int32_t i = 0; i < v->nrender_verts; ++i) {
        int32_t w = v->render_weld[i];
        if (v->render_weld[w] != w)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section RENDER_WELD: render vertex %d: representative %d is "
                        "welded to %d in turn (the map must be idempotent)",
                        i, w, v->render_weld[w]);
    }
    return SINEW_OK;
}

sinew_result sw_blob_render_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->nrender_verts == 0) {
        if (v->nrender_tris || v->nembed_tets || v->nrender_nodes || v->nrender_copies)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section RENDER_META: no render vertices, but %d triangles, %d "
                        "tets, %d nodes, %d copies",
                        v->nrender_tris, v->nembed_tets, v->nrender_nodes, v->nrender_copies);
        return SINEW_OK;
    }
    sinew_result r = check_counts(v, msg, ms);
    if (r != SINEW_OK) return r;
    const sw_blob_array_ref arrays[] = {
#define ARRAY(id, NAME, elem_size, type, field, ...) {v->field, id},
        SINEW_BLOB_RENDER_ARRAY_SECTIONS(ARRAY)
#undef ARRAY
    };
    if ((r = sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms)) ||
        (r = sw_blob_check_indices(SINEW_SECTION_RENDER_TRIS, "triangle", 3, v->render_tris,
                                   v->nrender_tris, "vertex", v->nrender_verts, msg, ms)) ||
        (r = check_nodes(v, msg, ms)) || (r = check_embedding(v, msg, ms)))
        return r;
    return check_weld(v, msg, ms);
}
