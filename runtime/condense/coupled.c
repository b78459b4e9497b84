/* The coupled solve of subspace condensation (condense.h; thesis eqs. 4.9-4.12,
 * Algorithm 4): the potential in (q, x_f), its gradient and Hessian, and Newton whose
 * updates solve eq. 4.11 by PCG. The Hessian is never assembled: the reduced block is
 * red->H (the reduced potential's, plus the ring copies' J^T K J), the patch block and
 * the coupling are applied tet by tet from each full tet's 12x12 K. */
#include <math.h>
#include <string.h>

#include "condense.h"
#include "dense.h"
#include "fem_corot.h"
#include "pcg.h"
#include "penalty.h"

/* ---- the cubature weights of eq. 4.12 --------------------------------------------- */

/* Eq. 4.12's subspace part: each domain the patch reaches keeps its whole cubature,
 * evaluated at the subspace's positions, scaled to the domain's volume outside the
 * patch, s_d = (V_d - V_fd) / V_d. Dropping the cubature tets inside the patch and
 * renormalising the rest (the first rule tried) fails once the patch holds the place
 * the cubature was fitted for: the patch may hold most of a bent domain's cubature weight
 * but less of its volume, and the few tets left, scaled up, stand for the rest
 * (docs/notes/world.md).
 * A domain keeps at least SW_COND_MIN_SHARE of it, even one the patch holds whole or whose
 * other tets are exact (exact_domains): the patch's vertices no longer depend on q, so
 * without it the modes that move them are stiff only through the ring, and the
 * pose-space force or the ring's pull runs q to its bound (docs/notes/novel-contact.md).
 * The cached cubature Jacobians of those domains are refilled by the next gradient pass. */
void sw_cond_weights_apply(sw_cond *c) {
    const sw_blob_view *v = c->v;
    for (int32_t k = 0; k < v->ndomains; ++k) { /* dom_fv: the oracle's (exact_domains) */
        if (c->dom_fv[k] == 0) continue;
        const sw_blob_domain *D = &v->domains[k];
        double s = c->dom_vol[k] > 0 ? (c->dom_vol[k] - c->dom_fv[k]) / c->dom_vol[k] : 0;
        if (!(s > SW_COND_MIN_SHARE)) s = SW_COND_MIN_SHARE;
        for (int32_t i = D->cub_begin; i < D->cub_begin + D->cub_count; ++i)
            c->cub_w[i] = s * v->cub_weight[i];
    }
}

void sw_cond_weights_restore(sw_cond *c) {
    const sw_blob_view *v = c->v;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        if (c->dom_fv[k] == 0) continue;
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t i = D->cub_begin; i < D->cub_begin + D->cub_count; ++i)
            c->cub_w[i] = v->cub_weight[i];
    }
}

/* ---- the potential ---------------------------------------------------------------- */

static const double *ring_J(const sw_cond *c, int32_t k) {
    return c->ring_J + (int64_t)3 * c->z.rmax * k;
}

/* The 12 corner positions of full tet e. */
static void tet_positions(const sw_cond *c, const double *x, int32_t e, double x12[12]) {
    const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
    for (int k = 0; k < 4; ++k) {
        const double *p = slot[k] >= 0 ? x + 3 * (int64_t)slot[k] : c->ring_x + 3 * (-1 - slot[k]);
        memcpy(x12 + 3 * k, p, 3 * sizeof(double));
    }
}

/* The full tets' ring blocks, J^T K_rr J summed over their ring corners' pairs, gathered
 * per ring copy a: M_a += sum_b K_ab J_b over the tet's ring corners b (3 x r_d), then
 * H_dd += J_a^T M_a once per copy. Tet by tet, J_a^T (K J) cost 12 r^2 a tet; per copy it
 * costs 3 r^2, and a copy has about five tets (the rest of a domain is all ring copies). */
static void ring_blocks_gather(sw_cond *c, int32_t e, const double *K) {
    const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
    for (int a = 0; a < 4; ++a) {
        if (slot[a] >= 0) continue;
        int32_t ka = -1 - slot[a];
        int32_t r = c->v->domains[c->ring_d[ka]].rank;
        double *M = c->ring_M + (int64_t)3 * c->z.rmax * ka;
        for (int b = 0; b < 4; ++b) {
            if (slot[b] >= 0) continue;
            const double *Jb = ring_J(c, -1 - slot[b]);
            for (int i = 0; i < 3; ++i) {
                const double *Krow = K + (3 * a + i) * 12 + 3 * b;
                double *Mi = M + i * r;
                for (int l = 0; l < 3; ++l) {
                    double kv = Krow[l];
                    const double *Jl = Jb + l * r;
                    for (int32_t j = 0; j < r; ++j)
                        Mi[j] += kv * Jl[j];
                }
            }
        }
    }
}

/* red->H's domain blocks += J_a^T M_a for the ring copies a in [k0, k1), their M cleared
 * for the next gathering. */
static void ring_blocks_flush(sw_cond *c, sw_reduced *red, int32_t k0, int32_t k1) {
    for (int32_t ka = k0; ka < k1; ++ka) {
        const sw_blob_domain *D = &c->v->domains[c->ring_d[ka]];
        int32_t r = D->rank, o = D->q_offset;
        const double *Ja = ring_J(c, ka);
        double *M = c->ring_M + (int64_t)3 * c->z.rmax * ka;
        for (int i = 0; i < 3; ++i) {
            const double *Jai = Ja + i * r, *Mi = M + i * r;
            for (int32_t p = 0; p < r; ++p) {
                double jp = Jai[p], *Hp = red->H + (int64_t)(o + p) * red->R + o;
                for (int32_t j = 0; j < r; ++j)
                    Hp[j] += jp * Mi[j];
            }
        }
        memset(M, 0, 3 * (size_t)r * sizeof(double));
    }
}

/* Contact pair j of the patch (a trained or detected pair with a corner in the patch, the
 * law of pose_contact.c at the corners' patch or subspace positions x12: p, t0, t1, t2):
 * E = 1/2 kk d^T N d, d = sum b_m x_tm - x_p, for a pair that collides at the solve's
 * start, or at one of the solve's law refreshes (sw_cond_solve). Between those the set is
 * frozen (as within one of the reference's contact rounds): the law
 * jumps where a pair starts to collide (E = 1/2 kk alpha |d_t|^2 there, eq. 3.12's
 * Heaviside), and a set re-decided at every iterate left the energy guard no decrease:
 * contact frames stopped early, far from the minimum (docs/notes/world.md). Its forces
 * into f, its Hessian
 * kk (c c^T kron N) into K (12 x 12) when not NULL. */
static double patch_pair(sw_cond *c, int32_t j, const double x12[12], double f[12], double *K) {
    const sw_blob_view *v = c->v;
    const sw_pair_set *set = &c->pp_sets[c->pp_src[j]];
    int32_t id = c->pp_id[j];
    const double *cd = set->data + 7 * (int64_t)id;
    const double coef[4] = {-1.0, cd[0], cd[1], cd[2]};
    const double *Rp = set->act_R + 9 * set->act[4 * id];
    double d[3] = {0, 0, 0}, n[3], Nd[3], N[9];
    for (int m = 0; m < 4; ++m)
        for (int i = 0; i < 3; ++i)
            d[i] += coef[m] * x12[3 * m + i];
    for (int i = 0; i < 3; ++i)
        n[i] = Rp[3 * i] * cd[3] + Rp[3 * i + 1] * cd[4] + Rp[3 * i + 2] * cd[5];
    memset(f, 0, 12 * sizeof(double));
    if (K) memset(K, 0, 144 * sizeof(double));
    if (c->pp_active[j] < 0) c->pp_active[j] = sw_penalty_gap(n, d) > 0; /* the solve's start */
    if (!c->pp_active[j]) return 0;
    double kk = c->pp_w[j] * v->contact_k * cd[6];
    sw_penalty_apply_N(n, c->pp_alpha[j], d, Nd);
    for (int m = 0; m < 4; ++m)
        for (int i = 0; i < 3; ++i)
            f[3 * m + i] = -kk * coef[m] * Nd[i];
    if (K) {
        sw_penalty_N(n, c->pp_alpha[j], N);
        for (int m = 0; m < 4; ++m)
            for (int l = 0; l < 4; ++l)
                for (int i = 0; i < 3; ++i)
                    for (int k = 0; k < 3; ++k)
                        K[(3 * m + i) * 12 + 3 * l + k] = kk * coef[m] * coef[l] * N[3 * i + k];
    }
    return sw_penalty_energy(kk, d, Nd);
}

/* red->H += J_a^T K_ab J_b over a pair element's ring corners a, b (their domains may
 * differ: the block the pose-space pair couples, in the step's pattern already). */
static void add_pair_ring_blocks(sw_cond *c, sw_reduced *red, int32_t e, const double *K) {
    const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            if (slot[a] >= 0 || slot[b] >= 0) continue;
            int32_t ka = -1 - slot[a], kb = -1 - slot[b];
            const sw_blob_domain *Da = &c->v->domains[c->ring_d[ka]],
                                 *Db = &c->v->domains[c->ring_d[kb]];
            const double *Ja = ring_J(c, ka), *Jb = ring_J(c, kb);
            sw_reduced_mark(red, Da, Db);
            for (int32_t p = 0; p < Da->rank; ++p)
                for (int32_t q = 0; q < Db->rank; ++q) {
                    double acc = 0;
                    for (int i = 0; i < 3; ++i)
                        for (int k = 0; k < 3; ++k)
                            acc += Ja[i * Da->rank + p] * K[(3 * a + i) * 12 + 3 * b + k] *
                                   Jb[k * Db->rank + q];
                    red->H[(int64_t)(Da->q_offset + p) * red->R + Db->q_offset + q] += acc;
                }
        }
}

/* Element e's energy (a full tet's, or a pose-space pair's); its forces into c->gf and,
 * through its ring corners' rows, red->g; with want_hess its Hessian into Kt and its ring
 * blocks into red->H (a tet's gathered, for ring_blocks_flush). */
static double add_element(sw_cond *c, sw_reduced *red, const double *x, int32_t e, int want_hess) {
    const sw_blob_view *v = c->v;
    const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
    int is_pair = e >= c->nt && e < c->nt + c->np;
    double x12[12], f[12], *K = c->Kt + 144 * (int64_t)e, phi;
    tet_positions(c, x, e, x12);
    if (!is_pair) {
        int32_t t = c->ft[e];
        const double st = sw_blob_stiffness(v->tet_stiffness, t); /* painted multiplier */
        double dm[9];
        phi = sw_corot_eval(x12, sw_blob_tet_dminv(v, t, dm), v->tet_vol[t], st * v->mu,
                            st * v->lambda, f, want_hess ? K : NULL, SW_COROT_PROJECT_PSD);
    } else {
        phi = patch_pair(c, e - c->nt, x12, f, want_hess ? K : NULL);
    }
    for (int k = 0; k < 4; ++k) {
        if (slot[k] >= 0) {
            for (int i = 0; i < 3; ++i)
                c->gf[3 * (int64_t)slot[k] + i] -= f[3 * k + i];
            continue;
        }
        int32_t a = -1 - slot[k];
        const sw_blob_domain *D = &v->domains[c->ring_d[a]];
        const double *J = ring_J(c, a);
        for (int32_t j = 0; j < D->rank; ++j)
            red->g[D->q_offset + j] -=
                J[j] * f[3 * k] + J[D->rank + j] * f[3 * k + 1] + J[2 * D->rank + j] * f[3 * k + 2];
    }
    if (want_hess && !is_pair) ring_blocks_gather(c, e, K);
    if (want_hess && is_pair) add_pair_ring_blocks(c, red, e, K);
    return phi;
}

/* The patch vertices' world contact and, in a dynamic step, their inertia: the terms a
 * refresh of the world's laws changes, into c->gf and, with want_hess, c->Dw. */
static double patch_world(sw_cond *c, const sw_step_contacts *ct, const double *x,
                          const sw_dyn_coef *dc, int want_hess) {
    double phi = 0;
    const sw_world_contacts *wc = ct->wc;
    for (int32_t j = 0; wc && j < wc->ncand; ++j) {
        const sw_world_cand *cd = &wc->cand[j];
        if (cd->patch < 0) continue;
        double f[3], H3[9];
        phi += sw_world_penalty(&cd->law, x + 3 * (int64_t)cd->patch, f, want_hess ? H3 : NULL);
        for (int i = 0; i < 3; ++i)
            c->gf[3 * (int64_t)cd->patch + i] -= f[i];
        for (int i = 0; want_hess && i < 9; ++i)
            c->Dw[9 * (int64_t)cd->patch + i] += H3[i];
    }
    if (dc->dynamic) phi += sw_cond_inertia(c, dc, x, want_hess);
    return phi;
}

/* Phi(q, x) (condense.h): the gradient into (red->g, c->gf), the Hessian's parts (red->H
 * with the ring blocks, Kt, Dw) with want_hess. */
double sw_cond_potential(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                         const sw_solver *s, const double *q, const double *x,
                         const sw_dyn_coef *dc, int want_hess) {
    double phi = sw_potential(red, ct, s, q, dc, 1, want_hess);
    for (int32_t k = 0; k < c->nring; ++k) {
        const sw_blob_domain *D = &c->v->domains[c->ring_d[k]];
        int32_t r = D->rank;
        const double *J = ring_J(c, k), *qd = q + D->q_offset;
        for (int i = 0; i < 3; ++i) {
            double acc = c->ring_x0[3 * k + i];
            for (int32_t j = 0; j < r; ++j)
                acc += J[i * r + j] * qd[j];
            c->ring_x[3 * k + i] = acc;
        }
    }
    memset(c->gf, 0, 3 * (size_t)c->nf * sizeof(double));
    if (want_hess) memset(c->Dw, 0, 9 * (size_t)c->nf * sizeof(double));
    /* the rest of the domains the patch mostly covers first: wholly at q, their J^T K J
       belong to the reduced block the matrix-vector product applies as a whole (Hq) */
    int32_t ne = c->nt + c->np;
    for (int32_t e = ne; e < ne + c->nrest; ++e)
        phi += add_element(c, red, x, e, want_hess);
    if (want_hess) {
        if (c->nrest > 0) ring_blocks_flush(c, red, 0, c->nring);
        sw_reduced_blocks_copy(c->v, c->Hq, c->Hq_nz, SW_DENSE_BLOCKS(red->H), red->H_nz);
    }
    for (int32_t e = 0; e < ne; ++e)
        phi += add_element(c, red, x, e, want_hess);
    if (want_hess) ring_blocks_flush(c, red, 0, c->nring_patch);
    c->phi_el = phi;
    memcpy(c->gf_el, c->gf, 3 * (size_t)c->nf * sizeof(double));
    /* a quasistatic step's inertia modes stay at their prediction (solver.h): their
       gradient is no force on the iterate, and sw_cond_solve drops their update */
    if (s->hold_inertia) sw_solver_hold_zero(s, c->v, red->g);
    return phi + patch_world(c, ct, x, dc, want_hess);
}

double sw_cond_potential_refreshed(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                                   const double *x, const sw_dyn_coef *dc) {
    double phi = c->phi_el;
    memcpy(c->gf, c->gf_el, 3 * (size_t)c->nf * sizeof(double));
    memset(c->Dw, 0, 9 * (size_t)c->nf * sizeof(double));
    for (int32_t j = 0; j < c->np; ++j) /* a pair the refresh reset decides here */
        if (c->pp_active[j] < 0) phi += add_element(c, red, x, c->nt + j, 1);
    c->phi_el = phi;
    memcpy(c->gf_el, c->gf, 3 * (size_t)c->nf * sizeof(double));
    return phi + patch_world(c, ct, x, dc, 1);
}

/* ---- the linear system of eq. 4.11 ------------------------------------------------- */

/* y = H z, z = (dq, dx): the reduced potential's block Hq, the world's 3x3 blocks, and
 * each full tet's K on its corners (ring corners at J dq, their rows back through J^T). */
void sw_cond_hessian_apply(void *ctx, const double *z, double *y) {
    const sw_cond_system *S = ctx;
    sw_cond *c = S->c;
    const sw_blob_view *v = c->v;
    int32_t R = S->red->R;
    const double *dq = z, *dx = z + R;
    double *yq = y, *yx = y + R;
    sw_reduced_blocks_matvec(v, SW_DENSE_BLOCKS(c->Hq), c->Hq_nz, dq, yq);
    for (int32_t i = 0; i < c->nf; ++i) {
        const double *D = c->Dw + 9 * (int64_t)i, *a = dx + 3 * (int64_t)i;
        for (int k = 0; k < 3; ++k)
            yx[3 * i + k] = D[3 * k] * a[0] + D[3 * k + 1] * a[1] + D[3 * k + 2] * a[2];
    }
    for (int32_t k = 0; k < c->nring_patch; ++k) { /* the rest's elements are in Hq */
        const sw_blob_domain *D = &v->domains[c->ring_d[k]];
        const double *J = ring_J(c, k), *qd = dq + D->q_offset;
        for (int i = 0; i < 3; ++i) {
            double acc = 0;
            for (int32_t j = 0; j < D->rank; ++j)
                acc += J[i * D->rank + j] * qd[j];
            c->ring_dx[3 * k + i] = acc;
        }
    }
    for (int32_t e = 0; e < c->nt + c->np; ++e) {
        const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
        const double *K = c->Kt + 144 * (int64_t)e;
        double z12[12], y12[12];
        for (int k = 0; k < 4; ++k) {
            const double *src =
                slot[k] >= 0 ? dx + 3 * (int64_t)slot[k] : c->ring_dx + 3 * (-1 - slot[k]);
            z12[3 * k] = src[0];
            z12[3 * k + 1] = src[1];
            z12[3 * k + 2] = src[2];
        }
        for (int i = 0; i < 12; ++i) {
            const double *Ki = K + 12 * i;
            double acc = 0;
            for (int l = 0; l < 12; ++l)
                acc += Ki[l] * z12[l];
            y12[i] = acc;
        }
        for (int k = 0; k < 4; ++k) {
            if (slot[k] >= 0) {
                for (int i = 0; i < 3; ++i)
                    yx[3 * (int64_t)slot[k] + i] += y12[3 * k + i];
                continue;
            }
            int32_t a = -1 - slot[k];
            const sw_blob_domain *D = &v->domains[c->ring_d[a]];
            const double *J = ring_J(c, a);
            for (int32_t j = 0; j < D->rank; ++j)
                yq[D->q_offset + j] += J[j] * y12[3 * k] + J[D->rank + j] * y12[3 * k + 1] +
                                       J[2 * D->rank + j] * y12[3 * k + 2];
        }
    }
}

/* z = P^-1 r: the factored reduced block on q, the inverted 3x3 diagonal blocks on x_f. */
static void sys_prec(void *ctx, const double *r, double *z) {
    const sw_cond_system *S = ctx;
    const sw_cond *c = S->c;
    int32_t R = S->red->R;
    memcpy(z, r, (size_t)R * sizeof(double));
    sw_solver_factor_solve(S->red, S->s, z);
    for (int32_t i = 0; i < c->nf; ++i) {
        const double *P = c->Pf + 9 * (int64_t)i, *a = r + R + 3 * (int64_t)i;
        for (int k = 0; k < 3; ++k)
            z[R + 3 * i + k] = P[3 * k] * a[0] + P[3 * k + 1] * a[1] + P[3 * k + 2] * a[2];
    }
}

/* The patch block's 3x3 diagonal blocks (tets and world) inverted into Pf. */
static void patch_preconditioner(sw_cond *c) {
    double *Dg = c->Pf; /* assembled in place of their inverses, then inverted */
    memcpy(Dg, c->Dw, 9 * (size_t)c->nf * sizeof(double));
    for (int32_t e = 0; e < c->nt + c->np; ++e) {
        const int32_t *slot = c->ft_slot + 4 * (int64_t)e;
        const double *K = c->Kt + 144 * (int64_t)e;
        for (int k = 0; k < 4; ++k)
            if (slot[k] >= 0)
                for (int i = 0; i < 3; ++i)
                    for (int l = 0; l < 3; ++l)
                        Dg[9 * (int64_t)slot[k] + 3 * i + l] += K[(3 * k + i) * 12 + 3 * k + l];
    }
    /* inverted in place: each block is read before its inverse is written */
    for (int32_t i = 0; i < c->nf; ++i) {
        double blk[9];
        memcpy(blk, Dg + 9 * (int64_t)i, sizeof blk);
        sw_block_jacobi_invert(1, blk, NULL, Dg + 9 * (int64_t)i);
    }
}

/* ---- Newton ------------------------------------------------------------------------ */

/* Coupled solves take at least this many Newton updates (a patch starts far from its
 * solution: the flesh inside a collider). */
#define SW_COND_MIN_NEWTON 8
/* PCG's relative tolerance and iteration cap for one update (thesis: "typically fewer
 * than 100 iterations"). */
#define SW_COND_GTOL 1e-4
#define SW_COND_PCG_TOL 1e-3
#define SW_COND_PCG_TOL_FAR 1e-1
#define SW_COND_PCG_MAX 200
/* Updates after which the patch's world contact laws are taken again. */
#define SW_COND_LAW_REFRESHES 2

static double grad_norm(const sw_cond *c, const sw_reduced *red) {
    return sqrt(sw_dot(red->g, red->g, red->R) + sw_dot(c->gf, c->gf, 3 * c->nf));
}

/* A patch candidate's gap along the ray x + t dx (world_penalty.h's g = n . (a - x)):
 * g + t s. */
static void gap_along(const sw_cond *c, const sw_world_cand *cd, int32_t R, double *g, double *s) {
    const double *x = c->x + 3 * (int64_t)cd->patch, *dx = c->sol + R + 3 * (int64_t)cd->patch;
    *g = *s = 0;
    for (int i = 0; i < 3; ++i) {
        *g += cd->law.n[i] * (cd->law.a[i] - x[i]);
        *s -= cd->law.n[i] * dx[i];
    }
}

/* The first step of a line search along c->sol from the patch positions c->x: the
 * minimiser in (0, 1] of the update's quadratic model, phi0 + t d0 + t^2 |d0| / 2 (PCG's
 * solve of H sol = -g gives sol^T H sol = -d0), plus the world laws of the patch's
 * candidates that are not in contact now, 1/2 k max(0, g + t s)^2 along the ray: their
 * Hessian is 0 where the update starts, so Newton's full step relaxes flesh straight into
 * a collider (the 100K capsule as the pipe leaves: a full step's energy +240 against a
 * predicted -30, then steps of 0.1 for 8 updates). 1 when no such law is crossed. */
static double contact_step(const sw_cond *c, const sw_world_contacts *wc, int32_t R, double d0) {
    if (!wc || !(d0 < 0)) return 1.0;
    int crossed = 0;
    for (int32_t j = 0; j < wc->ncand && !crossed; ++j) {
        const sw_world_cand *cd = &wc->cand[j];
        if (cd->patch < 0 || !(cd->law.k > 0)) continue;
        double g, sl;
        gap_along(c, cd, R, &g, &sl);
        crossed = g <= 0 && g + sl > 0;
    }
    if (!crossed) return 1.0;
    /* the model's slope is increasing in t (a convex model): bisect its root */
    double lo = 0, hi = 1;
    for (int it = 0; it < 40; ++it) {
        double t = 0.5 * (lo + hi), slope = d0 - t * d0;
        for (int32_t j = 0; j < wc->ncand; ++j) {
            const sw_world_cand *cd = &wc->cand[j];
            if (cd->patch < 0) continue;
            double g, sl;
            gap_along(c, cd, R, &g, &sl);
            if (g <= 0 && g + t * sl > 0) slope += cd->law.k * sl * (g + t * sl);
        }
        if (slope > 0)
            hi = t;
        else
            lo = t;
    }
    return hi > 1e-3 ? hi : 1e-3;
}

/* The energy guard along c->sol from (qtrial, xt): the first of up to `trials` steps
 * whose energy is not above phi0 is taken (q, x and the evaluation are its); 0 when none
 * is. Steps start at contact_step's; after a rejected step t the next is the minimiser of the
 * quadratic through phi0, the slope d0 = g . sol and phi(t), kept within [0.1 t, 0.5 t]
 * (plain halving when sol is no descent): a step the contact's stiffening rejected
 * usually needs one shorter trial, not two or three halvings. */
static int line_search(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                       const sw_dyn_coef *dc, double phi0, double d0, int trials, double *phi,
                       sinew_step_stats *st) {
    int32_t R = red->R, nx = 3 * c->nf;
    double step = contact_step(c, ct->wc, R, d0);
    for (int ls = 0; ls < trials; ++ls) {
        for (int32_t i = 0; i < R; ++i)
            s->q[i] = s->qtrial[i] + step * c->sol[i];
        for (int32_t i = 0; i < nx; ++i)
            c->x[i] = c->xt[i] + step * c->sol[R + i];
        /* the full step usually passes: evaluated with the Hessian the next update
           needs; shorter ones without it, and again with it once one passes */
        *phi = sw_cond_potential(c, red, ct, s, s->q, c->x, dc, ls == 0);
        st->potential_evals++;
        if (isfinite(*phi) && *phi <= phi0 + 1e-12 * fabs(phi0)) {
            if (ls > 0) {
                *phi = sw_cond_potential(c, red, ct, s, s->q, c->x, dc, 1);
                st->potential_evals++;
            }
            return 1;
        }
        double next = 0.5 * step;
        if (d0 < 0 && isfinite(*phi)) {
            double curv = *phi - phi0 - d0 * step; /* > 0: phi(t) is above the tangent */
            if (curv > 0) next = fmin(0.5 * step, fmax(0.1 * step, -d0 * step * step / (2 * curv)));
        }
        step = next;
    }
    return 0;
}

sinew_result sw_cond_solve(sw_cond *c, sw_reduced *red, const sw_step_contacts *ct,
                           sw_world_contacts *wc, sw_solver *s, const sw_dyn_coef *dc,
                           sinew_step_stats *st) {
    int32_t R = red->R, nx = 3 * c->nf;
    int64_t m = R + nx;
    sw_cond_weights_apply(c);
    for (int32_t j = 0; j < c->np; ++j) /* undecided: the first evaluation decides */
        c->pp_active[j] = -1;
    sw_cond_system S = {c, red, s};
    sw_pcg_vectors vec = {c->cg_r, c->cg_z, c->cg_p, c->cg_Ap};
    s->hold_inertia = sw_solver_hold_decide(s, c->v, dc, ct);
    if (s->hold_inertia) sw_solver_hold_start(s, c->v);
    double phi = sw_cond_potential(c, red, ct, s, s->q, c->x, dc, 1);
    st->potential_evals++;
    /* a later round of the step (its contact laws refreshed) is converged to the first
       round's gradient tolerance: it starts near its solution */
    double gn = grad_norm(c, red), g0 = c->g0_step > 0 ? c->g0_step : gn;
    c->g0_step = g0;
    uint32_t max_it = s->max_newton > SW_COND_MIN_NEWTON ? s->max_newton : SW_COND_MIN_NEWTON;
    sinew_result res = SINEW_OK;
    for (uint32_t it = 0;; ++it) {
        if (!isfinite(phi) || !isfinite(gn)) {
            memcpy(s->q, s->qn, (size_t)R * sizeof(double));
            st->status |= SINEW_STEP_FAILED;
            res = SINEW_ERROR_NOT_FINITE;
            break;
        }
        if (gn <= SW_COND_GTOL * g0 || gn == 0) {
            st->status |= SINEW_STEP_CONVERGED;
            break;
        }
        if (it == max_it) break;
        if (!sw_solver_factor(red, s)) break;
        st->factorizations++;
        patch_preconditioner(c);
        for (int32_t i = 0; i < R; ++i)
            c->rhs[i] = -red->g[i];
        for (int32_t i = 0; i < nx; ++i)
            c->rhs[R + i] = -c->gf[i];
        memset(c->sol, 0, (size_t)m * sizeof(double));
        /* inexact Newton (Eisenstat-Walker's choice 2 in its simplest form): far from the
           solution a rough direction serves as well as an exact one */
        double eta = fmin(SW_COND_PCG_TOL_FAR, fmax(SW_COND_PCG_TOL, gn / g0));
        sw_pcg_stats ps = sw_pcg_run(m, sw_cond_hessian_apply, &S, sys_prec, &S, c->rhs, eta,
                                     SW_COND_PCG_MAX, &vec, c->sol);
        c->pcg_iters += (uint32_t)ps.iters;
        /* the held coordinates' update dropped: with their gradient 0 the direction still
           descends as much (rhs . sol is unchanged), and they stay where they are held */
        if (s->hold_inertia) sw_solver_hold_zero(s, c->v, c->sol);
        /* the update: q and x from the iterate kept in qtrial and xt */
        memcpy(s->qtrial, s->q, (size_t)R * sizeof(double));
        memcpy(c->xt, c->x, (size_t)nx * sizeof(double));
        double phi0 = phi, gn0 = gn;
        int accepted =
            line_search(c, red, ct, s, dc, phi0, -sw_dot(c->rhs, c->sol, (int32_t)m), 5, &phi, st);
        if (!accepted) {
            /* The penalty laws' kinks (a pose-space pair's energy jumps where it starts
               to collide, eq. 3.12's Heaviside) can leave the Newton direction no
               decrease: the preconditioned gradient, P^-1 (-g) at the iterate (rhs holds
               -g, the preconditioner is still its), is tried before giving up. */
            sys_prec(&S, c->rhs, c->sol);
            if (s->hold_inertia) sw_solver_hold_zero(s, c->v, c->sol);
            accepted = line_search(c, red, ct, s, dc, phi0, -sw_dot(c->rhs, c->sol, (int32_t)m), 10,
                                   &phi, st);
        }
        if (!accepted) { /* keep the best iterate */
            memcpy(s->q, s->qtrial, (size_t)R * sizeof(double));
            memcpy(c->x, c->xt, (size_t)nx * sizeof(double));
            phi = phi0;
            gn = gn0;
            st->status |= SINEW_STEP_GUARD;
            break;
        }
        st->newton_iterations++;
        if (it < SW_COND_LAW_REFRESHES) {
            /* the patch's world contact laws again at the iterate: taken at the start
               state, where the subspace went deep into the collider (the reference takes
               its own at its last solution, near the surface), their friction caps held
               the flesh (world_contact.c, refresh_candidate); no extra update. The
               pose-space pairs' set grows as the reference's does between rounds, with a
               world or without one (a patch novel self-contact seeded). */
            if (wc) sw_cond_detect(c, wc, SW_WC_AT_REPLANE);
            if (wc) sw_cond_tag_candidates(c, wc);
            for (int32_t j = 0; j < c->np; ++j) /* and a pair now colliding joins */
                if (c->pp_active[j] == 0) c->pp_active[j] = -1;
            /* only those terms changed: the elastic ones stay the last evaluation's */
            phi = sw_cond_potential_refreshed(c, red, ct, c->x, dc);
        }
        gn = grad_norm(c, red);
    }
    sw_cond_weights_restore(c);
    st->residual = g0 > 0 ? gn / g0 : 0;
    st->energy = phi;
    return res;
}
