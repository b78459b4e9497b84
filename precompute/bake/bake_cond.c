/* The condensation tet mesh's blob sections (issue 12): the whole simulation tet mesh, for
 * the runtime's full-space patches. Each tet is stored with the domain the bake gave it
 * (bake_domains.c: its corners all have copies there) and its corners' local indices in
 * that domain, as the cubature tets are (bake_reduce.c); its rest Dm^-1 and volume come from
 * sw_tet_rest on the same corners, so a cubature tet's equal its own bit for bit; the
 * vertex masses are the lumped masses of prepare (sw_lumped_mass_add, the character's
 * density), whose split over each vertex's domain copies the reduced mass and inertia
 * use (sw_bake_state.copy_mass). */
#include <stdlib.h>
#include <string.h>

#include "bake_internal.h"
#include "fem_corot.h"

#define OWN(ptr, n, type)                                                                          \
    ((ptr) = sw_bake_own(out, calloc((size_t)(n) > 0 ? (size_t)(n) : 1, sizeof(type))))

/* tet_local of every tet, domain by domain: local_of maps a global vertex to its copy in
 * the domain at hand (scratch of nv). */
static void local_corners(const sw_bake_state *s, int32_t *local_of, int32_t *tet_local) {
    const int32_t *tets = s->ch.mesh.tets;
    for (int32_t d = 0; d < s->nd; ++d) {
        const int32_t base = s->dom_vert_ptr[d];
        for (int32_t k = base; k < s->dom_vert_ptr[d + 1]; ++k)
            local_of[s->dom_verts[k]] = k - base;
        for (int32_t i = s->dom_tet_ptr[d]; i < s->dom_tet_ptr[d + 1]; ++i) {
            const int64_t t = s->dom_tets[i];
            for (int k = 0; k < 4; ++k)
                tet_local[4 * t + k] = local_of[tets[4 * t + k]];
        }
    }
}

/* Each vertex's incident tets, ascending: counted, then filled in tet order. */
static void incidence(const sw_bake_state *s, int32_t *ptr, int32_t *vert_tets) {
    const int32_t *tets = s->ch.mesh.tets;
    for (int64_t i = 0; i < 4 * (int64_t)s->nt; ++i)
        ptr[tets[i] + 1]++;
    for (int32_t x = 0; x < s->nv; ++x)
        ptr[x + 1] += ptr[x];
    for (int32_t t = 0; t < s->nt; ++t)
        for (int k = 0; k < 4; ++k)
            vert_tets[ptr[tets[4 * (int64_t)t + k]]++] = t;
    for (int32_t x = s->nv; x > 0; --x) /* the fill advanced ptr[x] to ptr[x+1]: back */
        ptr[x] = ptr[x - 1];
    ptr[0] = 0;
}

sinew_result sw_bake_cond(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    const int32_t nt = s->nt, nv = s->nv;
    int32_t *tets, *tet_domain, *tet_local, *ptr, *vert_tets, *cub_tet_id;
    double *dminv, *vol, *mass;
    int32_t *local_of = malloc((size_t)nv * sizeof(int32_t));
    OWN(tets, 4 * (int64_t)nt, int32_t);
    OWN(tet_domain, nt, int32_t);
    OWN(tet_local, 4 * (int64_t)nt, int32_t);
    OWN(dminv, 9 * (int64_t)nt, double);
    OWN(vol, nt, double);
    OWN(ptr, (int64_t)nv + 1, int32_t);
    OWN(vert_tets, 4 * (int64_t)nt, int32_t);
    OWN(mass, nv, double);
    OWN(cub_tet_id, v->ncub, int32_t);
    if (!local_of || !tets || !tet_domain || !tet_local || !dminv || !vol || !ptr || !vert_tets ||
        !mass || !cub_tet_id ||
        out->nstorage >= (int)(sizeof out->storage / sizeof out->storage[0])) {
        free(local_of);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "out of memory for the condensation tet mesh's sections");
    }
    memcpy(tets, s->ch.mesh.tets, 4 * (size_t)nt * sizeof(int32_t));
    memcpy(tet_domain, s->tet_domain, (size_t)nt * sizeof(int32_t));
    memcpy(mass, s->mass, (size_t)nv * sizeof(double));
    for (int32_t t = 0; t < nt; ++t) {
        double Xe[12];
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, s->ch.mesh.X + 3 * (int64_t)tets[4 * (int64_t)t + k], 24);
        sw_tet_rest(Xe, dminv + 9 * (int64_t)t, vol + t); /* not degenerate: prepare checked */
    }
    local_corners(s, local_of, tet_local);
    incidence(s, ptr, vert_tets);
    /* the cubature tets in the blob's order (bake_reduce.c): domain by domain */
    for (int32_t d = 0, c = 0; d < s->nd; ++d)
        for (int32_t i = 0; i < s->cub_n[d]; ++i)
            cub_tet_id[c++] = s->dom_tets[s->dom_tet_ptr[d] + s->cub_local[d][i]];
    free(local_of);
    v->ntets = nt;
    v->nvert_tets = 4 * nt;
    v->tets = tets;
    v->tet_domain = tet_domain;
    v->tet_local = tet_local;
    v->tet_dminv = dminv;
    v->tet_vol = vol;
    v->vert_tet_ptr = ptr;
    v->vert_tets = vert_tets;
    v->vert_mass = mass;
    v->cub_tet_id = cub_tet_id;
    return SINEW_OK;
}
