/* The render mesh as output surface (blob_view.h): each representative render
 * vertex the barycentric sum of its tet's render nodes, each duplicate a copy of its
 * representative; normals area-weighted over the welded triangles, so a UV seam's
 * duplicates shade as one vertex. Used by the step's output (output.c) and, over other
 * node positions, by the evaluation helpers of tools. */
#include <string.h>

#include "instance.h"
#include "instance_internal.h"
#include "surface_normals.h"

/* Representative i from its tet's node positions (3 per render node); the sum in corner
 * order, as the bake reproduced the rest position (precompute/import/embed.c). */
static void embed_one(const sw_blob_view *v, int32_t i, const double *node_x, double x[3]) {
    const int32_t *c = v->render_tets + 4 * (int64_t)v->render_tet[i];
    const double *b = v->render_bary + 4 * (int64_t)i;
    const double *p0 = node_x + 3 * (int64_t)c[0], *p1 = node_x + 3 * (int64_t)c[1],
                 *p2 = node_x + 3 * (int64_t)c[2], *p3 = node_x + 3 * (int64_t)c[3];
    for (int k = 0; k < 3; ++k)
        x[k] = b[0] * p0[k] + b[1] * p1[k] + b[2] * p2[k] + b[3] * p3[k];
}

void sw_render_positions(const sw_blob_view *v, const double *node_x, double *x) {
    /* a duplicate's representative may come after it: representatives first */
    for (int32_t i = 0; i < v->nrender_verts; ++i)
        if (v->render_weld[i] == i) embed_one(v, i, node_x, x + 3 * (int64_t)i);
    for (int32_t i = 0; i < v->nrender_verts; ++i)
        if (v->render_weld[i] != i)
            memcpy(x + 3 * (int64_t)i, x + 3 * (int64_t)v->render_weld[i], 3 * sizeof(double));
}

void sw_render_normals(const sw_blob_view *v, const int32_t *weld_tris, const double *x,
                       double *n) {
    sw_surface_normals(v->nrender_verts, x, v->nrender_tris, weld_tris, n);
    for (int32_t i = 0; i < v->nrender_verts; ++i)
        if (v->render_weld[i] != i)
            memcpy(n + 3 * (int64_t)i, n + 3 * (int64_t)v->render_weld[i], 3 * sizeof(double));
}

void sw_render_weld_tris(const sw_blob_view *v, int32_t *weld_tris) {
    for (int64_t k = 0; k < 3 * (int64_t)v->nrender_tris; ++k)
        weld_tris[k] = v->render_weld[v->render_tris[k]];
}

int32_t sw_render_node_vertex(const sw_blob_view *v, int32_t n) {
    const int32_t *c = v->render_node_copies + 2 * (int64_t)v->render_node_ptr[n];
    return v->domain_verts[v->domains[c[0]].vert_begin + c[1]];
}

void sw_output_from_full(const sw_blob_view *v, const double *x_full, double *out) {
    if (v->nrender_verts == 0) {
        for (int32_t s = 0; s < v->nsurf_verts; ++s) {
            const int32_t *c = v->surf_copies + 2 * (int64_t)v->surf_copy_ptr[s];
            int32_t gv = v->domain_verts[v->domains[c[0]].vert_begin + c[1]];
            memcpy(out + 3 * (int64_t)s, x_full + 3 * (int64_t)gv, 3 * sizeof(double));
        }
        return;
    }
    for (int32_t i = 0; i < v->nrender_verts; ++i) {
        const int32_t *c = v->render_tets + 4 * (int64_t)v->render_tet[v->render_weld[i]];
        const double *b = v->render_bary + 4 * (int64_t)v->render_weld[i];
        const double *p[4];
        for (int k = 0; k < 4; ++k)
            p[k] = x_full + 3 * (int64_t)sw_render_node_vertex(v, c[k]);
        for (int k = 0; k < 3; ++k)
            out[3 * (int64_t)i + k] =
                b[0] * p[0][k] + b[1] * p[1][k] + b[2] * p[2][k] + b[3] * p[3][k];
    }
}
