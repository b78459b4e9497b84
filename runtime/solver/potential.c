/* The potential of one step (thesis eqs. 2.11, 4.20 and the backward-Euler terms):
 *   Phi(q) = E_cub(q) + E_contact(q) + E_world(q) + 1/2 q^T H_s q
 *          [ + cm/2 |q - q_n - h qdot_n|_M^2 + cd/2 |q - q_n|_D^2 - q^T f_in ],
 * D = alpha M + beta H(q_s) (the material Hessian at the step's start, frozen), H_s the
 * constant interface-spring Hessian, M the constant reduced mass, f_in the inertial forces
 * of the domains riding their bones. */
#include <string.h>

#include "cubature.h"
#include "dense.h"
#include "clock.h"
#include "pose_contact.h"
#include "solver.h"
#include <stdlib.h>

/* Whether domain block (a, b) is in the step's factor pattern (springs, contact pairs,
 * fill): where H(q_s) may be nonzero. */
static int step_block(const sw_solver *s, int32_t nd, int32_t a, int32_t b) {
    if (a == b) return 1;
    int32_t pa = s->blk_pos[a], pb = s->blk_pos[b];
    return pa > pb ? s->blk_nz[pa * nd + pb] : s->blk_nz[pb * nd + pa];
}

/* y = M x: over the diagonal blocks when the blob's mass is block diagonal (the bake's
 * always is), else over its nonzero blocks as well. */
static void mass_matvec(const sw_blob_view *v, const sw_solver *s, const double *x, double *y) {
    sw_reduced_blocks_matvec(v, SW_BLOB_BLOCKS(SW_BLOB_MASS), s->mass_adj, x, y);
}

/* H += cm M + cd (alpha M + beta H(q_s)) over the blocks where M or H(q_s) may be nonzero
 * (elsewhere both are exact zeros, and so is what the dense sum would add). */
static void add_dynamic_hessian(sw_reduced *red, const sw_solver *s, const sw_dyn_coef *dc) {
    const sw_blob_view *v = red->v;
    int32_t R = v->rank_total, nd = v->ndomains;
    double *H = red->H;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < nd; ++b) {
            if (s->mass_blockdiag && !step_block(s, nd, a, b)) continue;
            sw_reduced_mark(red, &v->domains[a], &v->domains[b]);
            int64_t ld;
            const double *M = sw_blob_block(v, SW_BLOB_MASS, a, b, &ld);
            for (int32_t i = 0; i < s->blk_size[a]; ++i)
                for (int32_t j = 0; j < s->blk_size[b]; ++j) {
                    int64_t k = (int64_t)(s->blk_off[a] + i) * R + s->blk_off[b] + j;
                    double m = M ? M[i * ld + j] : 0.0;
                    H[k] += dc->cm * m + dc->cd * (dc->alpha * m + dc->beta * s->Hn[k]);
                }
        }
}

double sw_potential_material(sw_reduced *red, const sw_pose_space *ps, const double *q,
                             int want_grad, int want_hess, double *self_seconds) {
    int32_t R = red->R;
    const sw_blob_view *v = red->v;
    if (want_grad) memset(red->g, 0, (size_t)R * sizeof(double));
    if (want_hess)
        sw_reduced_blocks_copy(v, red->H, red->H_nz, SW_BLOB_BLOCKS(SW_BLOB_SPRINGS),
                               red->spring_adj);
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
        phi += sw_contact_pairs_eval(red, &set, NULL, ct->sc->in_patch, ct->sc->npairs, ct->sc->w,
                                     ct->sc->tan, q, want_grad, want_hess);
        if (ct->self_seconds) *ct->self_seconds += sw_now_seconds() - t0;
    }
    if (ct->wc) phi += sw_world_contact_eval(red, ct->wc, q, want_grad, want_hess);
    phi += sw_pose_space_force(ct->ps, R, q, want_grad ? red->g : NULL);
    sw_reduced_blocks_matvec(v, SW_BLOB_BLOCKS(SW_BLOB_SPRINGS), s->blk_adj, q, s->tmp);
    phi += 0.5 * sw_dot(q, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += s->tmp[i];
    if (!dc->dynamic) return phi;
    /* inertia: cm/2 |q - qhat|_M^2 with qhat = qn + h qdot */
    double *e = s->tmp2;
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - s->qn[i] - dc->h * s->qdot[i];
    mass_matvec(v, s, e, s->tmp);
    phi += 0.5 * dc->cm * sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cm * s->tmp[i];
    /* damping: cd/2 |q - qn|_D^2, D = alpha M + beta Hn */
    for (int32_t i = 0; i < R; ++i)
        e[i] = q[i] - s->qn[i];
    mass_matvec(v, s, e, s->tmp);
    double dm = sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cd * dc->alpha * s->tmp[i];
    sw_reduced_blocks_matvec(v, SW_DENSE_BLOCKS(s->Hn), s->Hn_nz, e, s->tmp);
    double dk = sw_dot(e, s->tmp, R);
    if (want_grad)
        for (int32_t i = 0; i < R; ++i)
            red->g[i] += dc->cd * dc->beta * s->tmp[i] - s->fin[i];
    phi += 0.5 * dc->cd * (dc->alpha * dm + dc->beta * dk) - sw_dot(q, s->fin, R);
    if (want_hess) add_dynamic_hessian(red, s, dc);
    return phi;
}

double sw_potential(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                    const double *q, const sw_dyn_coef *dc, int want_grad, int want_hess) {
    double phi = sw_potential_material(red, ct->ps, q, want_grad, want_hess, ct->self_seconds);
    return sw_potential_rest(red, ct, s, q, dc, phi, want_grad, want_hess);
}

double sw_potential_start(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                          const sw_dyn_coef *dc, int want_hess, int *cubature_pass) {
    int32_t R = red->R;
    int at = s->mat_at_start && s->mat_hess == want_hess &&
             !memcmp(s->q, s->q_mat, (size_t)R * sizeof(double));
    s->mat_at_start = 0;
    *cubature_pass = !at;
    if (!at) return sw_potential(red, ct, s, s->q, dc, 1, want_hess);
    sw_reduced_blocks_copy(red->v, red->H, red->H_nz, SW_DENSE_BLOCKS(s->Hn), s->Hn_nz);
    memcpy(red->g, s->g_mat, (size_t)R * sizeof(double));
    return sw_potential_rest(red, ct, s, s->q, dc, s->phi_mat, 1, want_hess);
}
