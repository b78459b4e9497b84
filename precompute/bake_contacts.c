/* Pose-space self-contact data (thesis §3.2.3, simplified): the penetrating (vertex,
 * triangle) pairs of every training pose's full-space solution, found by the same
 * detection the reference simulator uses. The runtime applies a penalty to the pairs of
 * the nearest training pose, so its contact cost scales with the pairs kept, not with
 * the mesh. Vertices are referenced through their first domain copy; the normal is
 * stored in the vertex's un-skinned frame (R_p^T n) so that it follows the pose. */
#include <stdlib.h>
#include <string.h>

#include "bake_internal.h"
#include "mesh_io.h"
#include "selfcontact.h"

sinew_result sw_bake_contacts(sw_bake_state *s, sw_error *err) {
    sw_surface surf;
    memset(&surf, 0, sizeof surf);
    sw_selfcontact *sc = NULL;
    int32_t *first = malloc((size_t)s->nv * 2 * sizeof(int32_t));
    double *R = malloc((size_t)s->nv * 9 * sizeof(double)), *t = malloc((size_t)s->nv * 3 * sizeof(double));
    s->contact_ptr = calloc((size_t)s->ntrain + 1, sizeof(int32_t));
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!first || !R || !t || !s->contact_ptr) goto done;
    if ((r = sw_tetmesh_surface(&s->ch.mesh, &surf, err)) != SINEW_OK ||
        (r = sw_selfcontact_create(&s->ch.mesh, &surf, 1.8, 0, &sc, err)) != SINEW_OK)
        goto done;
    for (int32_t v = 0; v < s->nv; ++v) first[2 * v] = -1;
    for (int32_t d = s->nd - 1; d >= 0; --d) /* the lowest domain holding the vertex wins */
        for (int32_t k = s->dom_vert_ptr[d]; k < s->dom_vert_ptr[d + 1]; ++k) {
            first[2 * s->dom_verts[k]] = d;
            first[2 * s->dom_verts[k] + 1] = k - s->dom_vert_ptr[d];
        }
    int32_t cap = 0, k = 0;
    for (int32_t i = 0; i < s->ntrain_seq; ++i)
        for (int32_t j = 0; j < s->train[i].npose; ++j, ++k) {
            const double *T = s->train[i].T + (size_t)j * 12 * s->nb, *x = s->train[i].x + (size_t)j * 3 * s->nv;
            int32_t n = s->p->self_contact ? sw_selfcontact_detect(sc, x, s->pool) : 0;
            const sw_contact *c = sw_selfcontact_list(sc, &n);
            if (!s->p->self_contact) n = 0;
            if (s->ncontacts + n > cap) {
                cap = 2 * (s->ncontacts + n) + 64;
                int32_t *cv = realloc(s->contact_verts, (size_t)cap * 8 * sizeof(int32_t));
                if (cv) s->contact_verts = cv;
                double *cd = realloc(s->contact_data, (size_t)cap * 7 * sizeof(double));
                if (cd) s->contact_data = cd;
                if (!cv || !cd) {
                    r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for contacts");
                    goto done;
                }
            }
            if (n > 0) sw_bake_skin_transforms(s, T, R, t);
            for (int32_t q = 0; q < n; ++q) {
                int32_t ids[4] = {c[q].p, c[q].tri[0], c[q].tri[1], c[q].tri[2]}, ok = 1;
                for (int m = 0; m < 4; ++m) ok = ok && first[2 * ids[m]] >= 0;
                if (!ok) continue; /* a vertex in no domain cannot carry a force */
                int32_t *cv = s->contact_verts + 8 * (size_t)s->ncontacts;
                double *cd = s->contact_data + 7 * (size_t)s->ncontacts;
                for (int m = 0; m < 4; ++m) {
                    cv[2 * m] = first[2 * ids[m]];
                    cv[2 * m + 1] = first[2 * ids[m] + 1];
                }
                const double *Rp = R + 9 * (size_t)c[q].p;
                for (int m = 0; m < 3; ++m) cd[m] = c[q].beta[m];
                for (int m = 0; m < 3; ++m) cd[3 + m] = Rp[m] * c[q].n[0] + Rp[3 + m] * c[q].n[1] + Rp[6 + m] * c[q].n[2];
                cd[6] = c[q].ka;
                s->ncontacts++;
            }
            s->contact_ptr[k + 1] = s->ncontacts;
        }
    if (!s->contact_verts) s->contact_verts = malloc(8 * sizeof(int32_t));
    if (!s->contact_data) s->contact_data = malloc(7 * sizeof(double));
    r = s->contact_verts && s->contact_data ? SINEW_OK
                                            : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
done:
    if (r == SINEW_ERROR_OUT_OF_MEMORY && err && err->code != r) sw_error_set(err, r, "out of memory for contacts");
    sw_selfcontact_destroy(sc);
    sw_surface_free(&surf);
    free(first);
    free(R);
    free(t);
    return r;
}
