/* Stage "contacts" (bake.c, sw_bake_stages): reads s->rig, s->poses, s->basis; writes s->contacts.
 */
/* Pose-space self-contact data (thesis §3.2.3): the self-contact set the reference
 * simulator converged with at every training pose (every pair its contact rounds
 * gathered, eqs. 3.4-3.6 with n and beta frozen), so that at a training pose the
 * runtime's contact forces are the reference's. The runtime applies the pairs of the
 * nearest training pose, so its contact cost scales with the pairs kept, not with the
 * mesh. Vertices are referenced through their first domain copy; the normal is stored
 * in the vertex's un-skinned frame (R_p^T n) so that it follows the pose. */
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"

sinew_result sw_bake_contacts(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    (void)out;
    int32_t *first = malloc((size_t)s->rig.nv * 2 * sizeof(int32_t));
    double *R = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->rig.nv * 3 * sizeof(double));
    s->contacts.contact_ptr = calloc((size_t)s->basis.ntrain + 1, sizeof(int32_t));
    int32_t total = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        total += s->poses.train[i].ncontacts;
    s->contacts.ncontacts = 0;
    s->contacts.contact_verts = malloc(((size_t)total + 1) * 8 * sizeof(int32_t));
    s->contacts.contact_data = malloc(((size_t)total + 1) * 7 * sizeof(double));
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!first || !R || !t || !s->contacts.contact_ptr || !s->contacts.contact_verts ||
        !s->contacts.contact_data) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for contacts");
        goto done;
    }
    for (int32_t v = 0; v < s->rig.nv; ++v)
        first[2 * v] = -1;
    for (int32_t d = s->domains.nd - 1; d >= 0; --d) /* the lowest domain holding the vertex wins */
        for (int32_t k = s->domains.dom_vert_ptr[d]; k < s->domains.dom_vert_ptr[d + 1]; ++k) {
            first[2 * s->domains.dom_verts[k]] = d;
            first[2 * s->domains.dom_verts[k] + 1] = k - s->domains.dom_vert_ptr[d];
        }
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j, ++k) {
            const sw_pose_seq *q = &s->poses.train[i];
            const double *T = q->T + (size_t)j * 12 * s->rig.nb;
            const sw_contact *c = q->contacts ? q->contacts + q->contact_ptr[j] : NULL;
            int32_t n = q->contact_ptr[j + 1] - q->contact_ptr[j];
            if (n > 0) sw_bake_skin_transforms(s, T, R, t);
            for (int32_t m = 0; m < n; ++m) {
                int32_t ids[4] = {c[m].p, c[m].tri[0], c[m].tri[1], c[m].tri[2]}, ok = 1;
                for (int a = 0; a < 4; ++a)
                    ok = ok && first[2 * ids[a]] >= 0;
                if (!ok) continue; /* a vertex in no domain cannot carry a force */
                int32_t *cv = s->contacts.contact_verts + 8 * (size_t)s->contacts.ncontacts;
                double *cd = s->contacts.contact_data + 7 * (size_t)s->contacts.ncontacts;
                for (int a = 0; a < 4; ++a) {
                    cv[2 * a] = first[2 * ids[a]];
                    cv[2 * a + 1] = first[2 * ids[a] + 1];
                }
                const double *Rp = R + 9 * (size_t)c[m].p;
                for (int a = 0; a < 3; ++a)
                    cd[a] = c[m].beta[a];
                for (int a = 0; a < 3; ++a)
                    cd[3 + a] = Rp[a] * c[m].n[0] + Rp[3 + a] * c[m].n[1] + Rp[6 + a] * c[m].n[2];
                cd[6] = c[m].ka;
                s->contacts.ncontacts++;
            }
            s->contacts.contact_ptr[k + 1] = s->contacts.ncontacts;
        }
    r = SINEW_OK;
done:
    free(first);
    free(R);
    free(t);
    return r;
}
