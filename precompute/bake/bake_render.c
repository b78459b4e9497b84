/* Stage "render" (bake.c, sw_bake_stages): reads s->embed, s->domains, s->basis, the rig's
 * character; writes the view's render sections and its asset description (bake_asset.c). */
/* The render mesh's blob sections (bake.h "embed" and "reduce"): the embedding computed in
 * prepare (precompute/import/embed.h) turned into the runtime's terms. Only the tets that
 * hold a render vertex are stored (RENDER_TETS), over the simulation vertices at their
 * corners (render nodes), each with its domain copies, so the runtime evaluates those
 * vertices alone and as the mean of their copies, as it does the tet boundary's. */
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"

#define OWN(ptr, n, type)                                                                          \
    ((ptr) = sw_bake_own(out, calloc((size_t)(n) > 0 ? (size_t)(n) : 1, sizeof(type))))

/* The embedding tets in order of first use, their corners as render nodes in order of
 * first use: tet_slot (nt) and node_of (nv) map the simulation's ids to them (-1: unused). */
static void number_tets_and_nodes(const sw_bake_state *s, int32_t *tet_slot, int32_t *node_of,
                                  int32_t *nembed, int32_t *nnodes) {
    const sw_embedding *e = &s->embed;
    *nembed = *nnodes = 0;
    for (int32_t i = 0; i < e->nverts; ++i) {
        int32_t t = e->tet[i];
        if (tet_slot[t] >= 0) continue;
        tet_slot[t] = (*nembed)++;
        for (int k = 0; k < 4; ++k) {
            int32_t gv = s->rig.ch.mesh.tets[4 * (int64_t)t + k];
            if (node_of[gv] < 0) node_of[gv] = (*nnodes)++;
        }
    }
}

static sinew_result render_sections(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    const sw_trimesh *rm = &s->rig.ch.render;
    const sw_embedding *e = &s->embed;
    if (rm->nverts == 0) return SINEW_OK;
    sw_blob_view *v = &out->view;
    int32_t nd = s->domains.nd, *tet_slot = malloc((size_t)s->rig.nt * sizeof(int32_t)),
            *node_of = malloc((size_t)s->rig.nv * sizeof(int32_t));
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    int32_t *tris, *tet, *weld, *tets, *ptr, *copies = NULL, nembed, nnodes;
    double *bary;
    if (!tet_slot || !node_of) goto done;
    memset(tet_slot, 0xff, (size_t)s->rig.nt * sizeof(int32_t)); /* -1 */
    memset(node_of, 0xff, (size_t)s->rig.nv * sizeof(int32_t));
    number_tets_and_nodes(s, tet_slot, node_of, &nembed, &nnodes);
    OWN(tris, 3 * (int64_t)rm->ntris, int32_t);
    OWN(tet, rm->nverts, int32_t);
    OWN(bary, 4 * (int64_t)rm->nverts, double);
    OWN(weld, rm->nverts, int32_t);
    OWN(tets, 4 * (int64_t)nembed, int32_t);
    OWN(ptr, nnodes + 1, int32_t);
    if (!tris || !tet || !bary || !weld || !tets || !ptr) goto done;
    memcpy(tris, rm->tris, 3 * (size_t)rm->ntris * sizeof(int32_t));
    memcpy(bary, e->bary, 4 * (size_t)rm->nverts * sizeof(double));
    memcpy(weld, e->weld, (size_t)rm->nverts * sizeof(int32_t));
    for (int32_t i = 0; i < rm->nverts; ++i)
        tet[i] = tet_slot[e->tet[i]];
    for (int32_t t = 0; t < s->rig.nt; ++t)
        if (tet_slot[t] >= 0)
            for (int k = 0; k < 4; ++k)
                tets[4 * tet_slot[t] + k] = node_of[s->rig.ch.mesh.tets[4 * (int64_t)t + k]];
    /* each node's copies, domain by domain: counted, then filled */
    for (int32_t k = 0; k < s->domains.dom_vert_ptr[nd]; ++k)
        if (node_of[s->domains.dom_verts[k]] >= 0) ptr[node_of[s->domains.dom_verts[k]] + 1]++;
    for (int32_t n = 0; n < nnodes; ++n)
        ptr[n + 1] += ptr[n];
    OWN(copies, 2 * (int64_t)ptr[nnodes], int32_t);
    if (!copies) goto done;
    for (int32_t d = 0; d < nd; ++d)
        for (int32_t k = s->domains.dom_vert_ptr[d]; k < s->domains.dom_vert_ptr[d + 1]; ++k) {
            int32_t n = node_of[s->domains.dom_verts[k]];
            if (n < 0) continue;
            int32_t at = ptr[n]++;
            copies[2 * at] = d;
            copies[2 * at + 1] = k - s->domains.dom_vert_ptr[d];
        }
    for (int32_t n = nnodes; n > 0; --n) /* the fill advanced ptr[n] to ptr[n+1]: back */
        ptr[n] = ptr[n - 1];
    ptr[0] = 0;
    v->nrender_verts = rm->nverts;
    v->nrender_tris = rm->ntris;
    v->nembed_tets = nembed;
    v->nrender_nodes = nnodes;
    v->nrender_copies = ptr[nnodes];
    v->render_tris = tris;
    v->render_tet = tet;
    v->render_bary = bary;
    v->render_weld = weld;
    v->render_tets = tets;
    v->render_node_ptr = ptr;
    v->render_node_copies = copies;
    r = SINEW_OK;
done:
    if (r != SINEW_OK) sw_error_set(err, r, "out of memory for the render mesh's sections");
    free(tet_slot);
    free(node_of);
    return r;
}

/* The render mesh's sections, then the asset description, which maps the output vertices
 * (the render mesh's when there is one). */
sinew_result sw_bake_render(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sinew_result r = render_sections(s, out, err);
    return r != SINEW_OK ? r : sw_bake_asset(s, out, err);
}
