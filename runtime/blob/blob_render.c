/* The optional render mesh of a blob (sinew_blob_format.h, ids 27..34): its sections'
 * presence and counts (layer 1, sw_blob_render_fill) and its indices and values (layer 2,
 * sw_blob_render_validate, shared with the writer), in the manner of blob_load.c. */
#include <math.h>
#include <string.h>

#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_render_meta) == 32, "RENDER_META is 32 bytes");

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
    sinew_blob_render_meta m;
    int present;
    sinew_result r = sw_blob_group_meta(
        bytes, s, found, SINEW_SECTION_RENDER_FIRST, SINEW_SECTION_RENDER_LAST, "the render mesh's",
        &m, sizeof m, sizeof m.reserved / sizeof m.reserved[0], &present, msg, ms);
    if (r != SINEW_OK || !present) return r; /* none: the view's fields stay 0 / NULL */
#define FROM_META(name) v->name = m.name;
    SINEW_BLOB_RENDER_COUNTS(FROM_META)
#undef FROM_META
    if ((r = check_counts(v, msg, ms)) != SINEW_OK) return r;
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_RENDER_COUNTS);
    const sw_blob_count_expect expect[] = {SINEW_BLOB_RENDER_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
    if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0], "RENDER_META",
                                  msg, ms)) != SINEW_OK)
        return r;
    SINEW_BLOB_RENDER_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
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
    const sw_blob_array_ref arrays[] = {SINEW_BLOB_RENDER_ARRAY_SECTIONS(SW_BLOB_ARRAY_REF_ROW)};
    if ((r = sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms)) ||
        (r = sw_blob_check_indices(SINEW_SECTION_RENDER_TRIS, "triangle", 3, v->render_tris,
                                   v->nrender_tris, "vertex", v->nrender_verts, msg, ms)) ||
        (r = check_nodes(v, msg, ms)) || (r = check_embedding(v, msg, ms)))
        return r;
    return check_weld(v, msg, ms);
}
