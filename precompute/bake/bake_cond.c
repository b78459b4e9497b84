/* Stage "cond" (bake.c, sw_bake_stages): reads s->rig, s->domains, s->cubature, the view; writes
 * the view's tet mesh sections. */
/* The condensation tet mesh's blob sections : the whole simulation tet mesh, for
 * the runtime's full-space patches. Each tet is stored with the domain the bake gave it
 * (bake_domains.c: its corners all have copies there) and its corners' local indices in
 * that domain, as the cubature tets are (bake_reduce.c); its rest volume comes from
 * sw_tet_rest on the same corners, so a cubature tet's equals its own bit for bit, and its
 * rest Dm^-1 is left out (COND_TET_DMINV: the runtime derives it from REST with the same
 * function, sw_blob_tet_dminv, so 9 doubles a tet buy nothing); the
 * vertex masses are the lumped masses of prepare (sw_lumped_mass_add, the character's
 * density), whose split over each vertex's domain copies the reduced mass and inertia
 * use (sw_bake_state.copy_mass). */
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"

#define OWN(ptr, n, type)                                                                          \
    ((ptr) = sw_bake_own(out, calloc((size_t)(n) > 0 ? (size_t)(n) : 1, sizeof(type))))

/* tet_local of every tet, domain by domain: local_of maps a global vertex to its copy in
 * the domain at hand (scratch of nv). */
static void local_corners(const sw_bake_state *s, int32_t *local_of, int32_t *tet_local) {
    const int32_t *tets = s->rig.ch.mesh.tets;
    for (int32_t d = 0; d < s->domains.nd; ++d) {
        const int32_t base = s->domains.dom_vert_ptr[d];
        for (int32_t k = base; k < s->domains.dom_vert_ptr[d + 1]; ++k)
            local_of[s->domains.dom_verts[k]] = k - base;
        for (int32_t i = s->domains.dom_tet_ptr[d]; i < s->domains.dom_tet_ptr[d + 1]; ++i) {
            const int64_t t = s->domains.dom_tets[i];
            for (int k = 0; k < 4; ++k)
                tet_local[4 * t + k] = local_of[tets[4 * t + k]];
        }
    }
}

/* Each vertex's incident tets, ascending: counted, then filled in tet order. */
static void incidence(const sw_bake_state *s, int32_t *ptr, int32_t *vert_tets) {
    const int32_t *tets = s->rig.ch.mesh.tets;
    for (int64_t i = 0; i < 4 * (int64_t)s->rig.nt; ++i)
        ptr[tets[i] + 1]++;
    for (int32_t x = 0; x < s->rig.nv; ++x)
        ptr[x + 1] += ptr[x];
    for (int32_t t = 0; t < s->rig.nt; ++t)
        for (int k = 0; k < 4; ++k)
            vert_tets[ptr[tets[4 * (int64_t)t + k]]++] = t;
    for (int32_t x = s->rig.nv; x > 0; --x) /* the fill advanced ptr[x] to ptr[x+1]: back */
        ptr[x] = ptr[x - 1];
    ptr[0] = 0;
}

sinew_result sw_bake_cond(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    const int32_t nt = s->rig.nt, nv = s->rig.nv;
    int32_t *tets, *tet_domain, *tet_local, *ptr, *vert_tets, *cub_tet_id;
    double *vol, *mass;
    int32_t *local_of = malloc((size_t)nv * sizeof(int32_t));
    OWN(tets, 4 * (int64_t)nt, int32_t);
    OWN(tet_domain, nt, int32_t);
    OWN(tet_local, 4 * (int64_t)nt, int32_t);
    OWN(vol, nt, double);
    OWN(ptr, (int64_t)nv + 1, int32_t);
    OWN(vert_tets, 4 * (int64_t)nt, int32_t);
    OWN(mass, nv, double);
    OWN(cub_tet_id, v->ncub, int32_t);
    if (!local_of || !tets || !tet_domain || !tet_local || !vol || !ptr || !vert_tets || !mass ||
        !cub_tet_id) {
        free(local_of);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "out of memory for the condensation tet mesh's sections");
    }
    memcpy(tets, s->rig.ch.mesh.tets, 4 * (size_t)nt * sizeof(int32_t));
    memcpy(tet_domain, s->domains.tet_domain, (size_t)nt * sizeof(int32_t));
    memcpy(mass, s->rig.mass, (size_t)nv * sizeof(double));
    for (int32_t t = 0; t < nt; ++t) {
        double Xe[12], dminv[9]; /* the runtime derives Dm^-1 from REST as here: not stored */
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, s->rig.ch.mesh.X + 3 * (int64_t)tets[4 * (int64_t)t + k], 24);
        sw_tet_rest(Xe, dminv, vol + t); /* not degenerate: prepare checked */
    }
    local_corners(s, local_of, tet_local);
    incidence(s, ptr, vert_tets);
    /* the cubature tets in the blob's order (bake_reduce.c): domain by domain */
    for (int32_t d = 0, c = 0; d < s->domains.nd; ++d)
        for (int32_t i = 0; i < s->cubature.n[d]; ++i)
            cub_tet_id[c++] =
                s->domains.dom_tets[s->domains.dom_tet_ptr[d] + s->cubature.local[d][i]];
    free(local_of);
    v->ntets = nt;
    v->nvert_tets = 4 * nt;
    v->tets = tets;
    v->tet_domain = tet_domain;
    v->tet_local = tet_local;
    v->tet_dminv = NULL;
    v->tet_vol = vol;
    if (s->rig.ch.tet_stiffness) { /* painted: the patches' full tets carry it too */
        double *stiff;
        if (!OWN(stiff, nt, double))
            return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                                "out of memory for the painted material's section");
        memcpy(stiff, s->rig.ch.tet_stiffness, (size_t)nt * sizeof(double));
        v->tet_stiffness = stiff;
    }
    v->vert_tet_ptr = ptr;
    v->vert_tets = vert_tets;
    v->vert_mass = mass;
    v->cub_tet_id = cub_tet_id;
    return SINEW_OK;
}
