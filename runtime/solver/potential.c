/* The potential of one step (thesis eqs. 2.11, 4.20 and the backward-Euler terms):
 *   Phi(q) = E_cub(q) + E_contact(q) + E_world(q) + 1/2 q^T H_s q
 *          [ + cm/2 |q - q_n - h qdot_n|_M^2 + cd/2 |q - q_n|_D^2 - q^T f_in ],
 * D = alpha M + beta H(q_n), H_s the constant interface-spring Hessian, M the constant
 * reduced mass, f_in the inertial forces of the domains riding their bones. */
#include <string.h>

#include "cubature.h"
#include "dense.h"
#include "clock.h"
#include "pose_contact.h"
#include "solver.h"

/* y = H_s q over the spring-coupled blocks only (and the diagonal ones): each row sums
 * its nonzero terms in the same column order as the dense product, and the terms it skips
 * are exact zeros times finite entries, so the result is bitwise the dense one. */
static void spring_matvec(const sw_blob_view *v, const sw_solver *s, const double *q, double *y) {
    int32_t R = v->rank_total, nd = v->ndomains;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t i = s->blk_off[a]; i < s->blk_off[a] + s->blk_size[a]; ++i) {
            const double *Ai = v->spring_hessian + (int64_t)i * R;
            double acc = 0;
            for (int32_t b = 0; b < nd; ++b) {
                if (b != a && !s->blk_adj[a * nd + b]) continue;
                for (int32_t j = s->blk_off[b]; j < s->blk_off[b] + s->blk_size[b]; ++j)
                    acc += Ai[j] * q[j];
            }
            y[i] = acc;
        }
}

double sw_potential_material(sw_reduced *red, const sw_pose_space *ps, const double *q,
                             int want_grad, int want_hess, double *self_seconds) {
    int32_t R = red->R;
    const sw_blob_view *v = red->v;
    if (want_grad) memset(red->g, 0, (size_t)R * sizeof(double));
    if (want_hess) memcpy(red->H, v->spring_hessian, (size_t)R * R * sizeof(double));
    double phi = sw_cubature_eval(red, q, want_grad, want_hess);
    double t0 = self_seconds ? sw_now_seconds() : 0;
    phi += sw_pose_contact_eval(red, ps, q, want_grad, want_hess);
    if (self_seconds) *self_seconds += sw_now_seconds() - t0;
    return phi;
}

double sw_potential_rest(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                         const double *q, const sw_dyn_coef *dc, double phi, int want_grad,
                         int want_hess) {
    int32_t R = red->R;
    const sw_blob_view *v = red->v;
    if (ct->sc) {
        double t0 = ct->self_seconds ? sw_now_seconds() : 0;
        sw_pair_set set = sw_self_contacts_pairs(ct->sc);
        phi += sw_contact_pairs_eval(red, &set, NULL, ct->sc->npairs, NULL, NULL, q, want_grad,
                                     want_hess);
        if (ct->self_seconds) *ct->self_seconds += sw_now_seconds() - t0;
    }
    if (ct->wc) phi += sw_world_contact_eval(red, ct->wc, q, want_grad, want_hess);
    spring_matvec(v, s, q, s->tmp);
    phi += 0.5 * sw_dot(q, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += s->tmp[i];
    if (!dc->dynamic) return phi;
    /* inertia: cm/2 |q - qhat|_M^2 with qhat = qn + h qdot */
    double *e = s->tmp2;
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - s->qn[i] - dc->h * s->qdot[i];
    sw_matvec(v->mass, R, e, s->tmp);
    phi += 0.5 * dc->cm * sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cm * s->tmp[i];
    /* damping: cd/2 |q - qn|_D^2, D = alpha M + beta Hn */
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - s->qn[i];
    sw_matvec(v->mass, R, e, s->tmp);
    double dm = sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cd * dc->alpha * s->tmp[i];
    sw_matvec(s->Hn, R, e, s->tmp);
    double dk = sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cd * dc->beta * s->tmp[i] - s->fin[i];
    phi += 0.5 * dc->cd * (dc->alpha * dm + dc->beta * dk) - sw_dot(q, s->fin, R);
    if (want_hess)
        for (int64_t i = 0; i < (int64_t)R * R; ++i)
            red->H[i] +=
                dc->cm * v->mass[i] + dc->cd * (dc->alpha * v->mass[i] + dc->beta * s->Hn[i]);
    return phi;
}

double sw_potential(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                    const double *q, const sw_dyn_coef *dc, int want_grad, int want_hess) {
    double phi = sw_potential_material(red, ct->ps, q, want_grad, want_hess, ct->self_seconds);
    return sw_potential_rest(red, ct, s, q, dc, phi, want_grad, want_hess);
}

double sw_potential_start(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                          const sw_dyn_coef *dc, int *cubature_pass) {
    int32_t R = red->R;
    int at_qn = s->mat_at_qn && !memcmp(s->q, s->qn, (size_t)R * sizeof(double));
    s->mat_at_qn = 0;
    *cubature_pass = !at_qn;
    if (!at_qn) return sw_potential(red, ct, s, s->q, dc, 1, 1);
    memcpy(red->H, s->Hn, (size_t)R * R * sizeof(double));
    memcpy(red->g, s->g_mat, (size_t)R * sizeof(double));
    return sw_potential_rest(red, ct, s, s->q, dc, s->phi_mat, 1, 1);
}
