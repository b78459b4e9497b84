/* Inertia modes held in quasistatic steps where nothing untrained touches (solver.h). */
#include "solver.h"
#include "self_contact.h"
#include "world_contact.h"

/* Domain d's held coordinates: [first, end) of q. */
static int32_t held_first(const sw_blob_domain *D) {
    return D->q_offset + D->rank - D->inertia_count;
}

int sw_solver_hold_decide(sw_solver *s, const sw_blob_view *v, const sw_dyn_coef *dc,
                          const sw_step_contacts *ct) {
    int any = 0;
    for (int32_t d = 0; d < v->ndomains; ++d)
        any |= s->hold[d] = !dc->dynamic && v->domains[d].inertia_count > 0;
    if (!any) return 0;
    if (ct->wc) /* the world near a copy: its domain gives way through its modes */
        for (int32_t i = 0; i < ct->wc->ncand; ++i)
            s->hold[v->surf_copies[2 * ct->wc->cand[i].copy]] = 0;
    if (ct->sc) /* the domains of a detected pair's four copies */
        for (int32_t p = 0; p < ct->sc->npairs; ++p)
            for (int k = 0; k < 4; ++k)
                s->hold[ct->sc->verts[8 * (int64_t)p + 2 * k]] = 0;
    any = 0;
    for (int32_t d = 0; d < v->ndomains; ++d)
        any |= s->hold[d];
    return any;
}

void sw_solver_hold_start(sw_solver *s, const sw_blob_view *v) {
    for (int32_t d = 0; d < v->ndomains; ++d) {
        if (!s->hold[d]) continue;
        const sw_blob_domain *D = &v->domains[d];
        for (int32_t i = held_first(D); i < D->q_offset + D->rank; ++i)
            s->q[i] = s->q_pred[i];
    }
}

void sw_solver_hold_zero(const sw_solver *s, const sw_blob_view *v, double *x) {
    for (int32_t d = 0; d < v->ndomains; ++d) {
        if (!s->hold[d]) continue;
        const sw_blob_domain *D = &v->domains[d];
        for (int32_t i = held_first(D); i < D->q_offset + D->rank; ++i)
            x[i] = 0;
    }
}

void sw_solver_hold_rows(const sw_solver *s, sw_reduced *red, int want_hess) {
    const sw_blob_view *v = red->v;
    const int64_t R = red->R;
    sw_solver_hold_zero(s, v, red->g);
    if (!want_hess) return;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        if (!s->hold[d]) continue;
        const sw_blob_domain *D = &v->domains[d];
        for (int64_t i = held_first(D); i < D->q_offset + D->rank; ++i) {
            double hii = red->H[i * R + i];
            for (int64_t j = 0; j < R; ++j)
                red->H[i * R + j] = red->H[j * R + i] = 0;
            red->H[i * R + i] = hii > 0 ? hii : 1;
        }
    }
}
