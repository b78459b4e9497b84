#include "cubature.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "blob_load.h"
#include "fem_corot.h"
#include "sorted.h"

/* A cubature tet's corners in the subspace map (reduced_map.h): corner n's rows of the
 * domain's basis U_n (3 x r) and its skinning rotation R_n, so that its Jacobian is
 * J_n = R_n U_n without being formed. (A per-step cache of x0 and J = R U, 12 (r + 1)
 * doubles a tet, costs more to fill than it saves: W_n = U^T R_n costs a pass what J costs
 * a column, and most steps make one or two passes; see docs/notes/runtime-constants.md.) */
typedef struct {
    const double *U[4];
    const double *R[4];
} tet_map;

/* The upper triangle of the domain block H (row stride R) += sum_k (a_k h_k)(h_k)^T over
 * the n projections h_k (at hm + k r), a_k their weights: each entry adds its terms in k
 * order, as n separate rank-1 updates would (bitwise the same), in passes of up to four
 * modes so that an entry is loaded and stored once a pass. */
static void add_mode_products(double *H, int32_t R, int32_t r, const double *hm, const double *a,
                              int n) {
    for (int k0 = 0; k0 < n; k0 += 4) {
        int m = n - k0 < 4 ? n - k0 : 4;
        const double *h0 = hm + (int64_t)k0 * r, *h1 = h0 + r, *h2 = h1 + r, *h3 = h2 + r;
        for (int32_t i = 0; i < r; ++i) {
            double *Hi = H + (int64_t)i * R;
            double c0 = a[k0] * h0[i];
            if (m == 4) {
                double c1 = a[k0 + 1] * h1[i], c2 = a[k0 + 2] * h2[i], c3 = a[k0 + 3] * h3[i];
                for (int32_t j = i; j < r; ++j)
                    Hi[j] = Hi[j] + c0 * h0[j] + c1 * h1[j] + c2 * h2[j] + c3 * h3[j];
            } else if (m == 3) {
                double c1 = a[k0 + 1] * h1[i], c2 = a[k0 + 2] * h2[i];
                for (int32_t j = i; j < r; ++j)
                    Hi[j] = Hi[j] + c0 * h0[j] + c1 * h1[j] + c2 * h2[j];
            } else if (m == 2) {
                double c1 = a[k0 + 1] * h1[i];
                for (int32_t j = i; j < r; ++j)
                    Hi[j] = Hi[j] + c0 * h0[j] + c1 * h1[j];
            } else {
                for (int32_t j = i; j < r; ++j)
                    Hi[j] += c0 * h0[j];
            }
        }
    }
}

/* Columns j0 .. j0 + nl - 1 (nl <= SW_CUB_COLS) of singular_frame_projections side by
 * side: each column's sums in the order of a one-column loop, the columns in lanes that
 * a vectorising compiler fills when nl is the constant SW_CUB_COLS (SSE2 pairs). The sums
 * are bitwise those of the one-column loop. (An AVX2 clone of the pass was slower.) */
#define SW_CUB_COLS 4
static void column_projections(const tet_map *tm, int32_t r, int32_t j0, int nl, double W[4][9],
                               const double b[12], const double dpsi[3], double fscale,
                               const int *mode, int n, double *out) {
    double Gs[9][SW_CUB_COLS] = {{0}}, h[9][SW_CUB_COLS];
    for (int c = 0; c < 4; ++c) {
        const double *u0 = tm->U[c] + j0, *u1 = u0 + r, *u2 = u1 + r;
        for (int i = 0; i < 3; ++i) {
            const double *Wi = W[c] + 3 * i;
            for (int l = 0; l < nl; ++l) {
                double ai = Wi[0] * u0[l] + Wi[1] * u1[l] + Wi[2] * u2[l]; /* (U^T R_n U_n,j)_i */
                Gs[3 * i][l] += ai * b[3 * c];
                Gs[3 * i + 1][l] += ai * b[3 * c + 1];
                Gs[3 * i + 2][l] += ai * b[3 * c + 2];
            }
        }
    }
    for (int l = 0; l < nl; ++l) {
        out[j0 + l] = fscale * (dpsi[0] * Gs[0][l] + dpsi[1] * Gs[4][l] + dpsi[2] * Gs[8][l]);
        double As[9], hl[9];
        for (int k = 0; k < 9; ++k)
            As[k] = Gs[k][l];
        sw_corot_modes_dot(As, hl);
        for (int k = 0; k < 9; ++k)
            h[k][l] = hl[k];
    }
    for (int i = 0; i < n; ++i)
        for (int l = 0; l < nl; ++l)
            out[(int64_t)(1 + i) * r + j0 + l] = h[mode[i]][l];
}

/* The projections of one tet evaluated with its Hessian, through the singular frame of
 * its SVD F = U diag(s) V^T: column j of J moves F by G_j = sum_n J_n,j D_n^T (corner n's
 * Jacobian J_n = R_n U_n, shape gradient D_n), and in that frame Gs_j = U^T G_j V =
 * sum_n (W_n U_n,j)(V^T D_n)^T with W_n = U^T R_n formed once a tet, against which the nine modes U
 * M_k V^T and the stress U diag(dpsi) V^T are sparse (sw_corot_modes_dot): out[j] = fscale <Gs_j,
 * diag(dpsi)> (J^T f with fscale = -vol), then out[(1 + i) r + j] = <Gs_j, M_mode[i]> for the n
 * modes listed. About 100 products a column instead of 12 for each of ten 12-vectors, and no mode
 * directions or pulls to the nodes. */
static void singular_frame_projections(const tet_map *tm, int32_t r, const double DmInv[9],
                                       const double U[9], const double V[9], const double dpsi[3],
                                       double fscale, const int *mode, int n, double *out) {
    double D[12], b[12], W[4][9];
    sw_tet_shape_gradients(DmInv, D);
    for (int c = 0; c < 4; ++c) /* W_n = U^T R_n */
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k)
                W[c][3 * i + k] =
                    U[i] * tm->R[c][k] + U[3 + i] * tm->R[c][3 + k] + U[6 + i] * tm->R[c][6 + k];
    for (int c = 0; c < 4; ++c) /* b_n = V^T D_n */
        for (int i = 0; i < 3; ++i)
            b[3 * c + i] = V[i] * D[3 * c] + V[3 + i] * D[3 * c + 1] + V[6 + i] * D[3 * c + 2];
    /* blocks of SW_CUB_COLS columns, then the rest */
    int32_t j = 0;
    for (; j + SW_CUB_COLS <= r; j += SW_CUB_COLS)
        column_projections(tm, r, j, SW_CUB_COLS, W, b, dpsi, fscale, mode, n, out);
    if (j < r) column_projections(tm, r, j, r - j, W, b, dpsi, fscale, mode, n, out);
}

/* One cubature tet with its Hessian: returns w E and leaves J^T f in hm[0, r) (f = -dE/dx),
 * and adds w J^T K J to the upper triangle of the domain block H (row stride ld) through
 * the element's nonzero modes in the singular frame (eq. 2.12 through the modes, J^T K J =
 * sum_k w_k (J^T g_k) (J^T g_k)^T). V_cache warm-starts the SVD and keeps its V. */
static double tet_with_hessian(const tet_map *tm, int32_t r, const double x[12],
                               const double dminv[9], double vol, const sw_blob_view *v,
                               double *V_cache, uint32_t project, double w, double *H, int32_t ld,
                               double *hm) {
    double U[9], sv[3], V[9], dpsi[3], wm[9], a[9];
    double e = w * sw_corot_eval_svd(x, dminv, vol, v->mu, v->lambda, V_cache, project, U, sv, V,
                                     dpsi, wm);
    int mode[9], n = 0;
    for (int mk = 0; mk < 9; ++mk)
        if (wm[mk] != 0.0) {
            a[n] = w * wm[mk];
            mode[n++] = mk;
        }
    singular_frame_projections(tm, r, dminv, U, V, dpsi, -vol, mode, n, hm);
    if (n > 0) add_mode_products(H, ld, r, hm + r, a, n);
    return e;
}

/* A domain block filled in its upper triangle (row stride ld): mirror it. */
static void mirror_upper(double *H, int32_t ld, int32_t r) {
    for (int32_t i = 0; i < r; ++i)
        for (int32_t j = i + 1; j < r; ++j)
            H[(int64_t)j * ld + i] = H[(int64_t)i * ld + j];
}

/* H (row stride ld) += B (r x r, row-major). */
static void add_block(double *H, int32_t ld, const double *B, int32_t r) {
    for (int32_t i = 0; i < r; ++i)
        for (int32_t j = 0; j < r; ++j)
            H[(int64_t)i * ld + j] += B[(int64_t)i * r + j];
}

/* Domain k's block of m->h_ref, after those of the domains before it. */
static double *ref_block(const sw_reduced *m, int32_t k) {
    int64_t off = 0;
    for (int32_t j = 0; j < k; ++j)
        off += (int64_t)m->v->domains[j].rank * m->v->domains[j].rank;
    return m->h_ref + off;
}

/* Domain k's corners placed at its coordinates qd (corner_x), their summed forces zeroed. */
static void place_corners(sw_reduced *m, int32_t k, const double *qd) {
    const sw_blob_domain *D = &m->v->domains[k];
    const int32_t end = m->corner_begin[k + 1];
    int32_t i = m->corner_begin[k];
    for (; i + 1 < end; i += 2)
        sw_reduced_position_pair(m, D, m->corner_lv + i, m->corner_act + i, qd, m->corner_x + 3 * i,
                                 m->corner_x + 3 * (i + 1));
    if (i < end)
        sw_reduced_position(m, D, m->corner_lv[i], m->corner_act[i], qd, m->corner_x + 3 * i, NULL);
    for (i = m->corner_begin[k]; i < end; ++i)
        m->corner_f[3 * i] = m->corner_f[3 * i + 1] = m->corner_f[3 * i + 2] = 0;
}

/* Cubature tet c of domain D: its corners' positions x from corner_x, and with tm its map. */
static void tet_corners(const sw_reduced *m, const sw_blob_domain *D, int32_t c, double x[12],
                        tet_map *tm) {
    const int32_t *cc = m->cub_corner + 4 * c;
    for (int n = 0; n < 4; ++n) {
        for (int i = 0; i < 3; ++i)
            x[3 * n + i] = m->corner_x[3 * cc[n] + i];
        if (!tm) continue;
        tm->U[n] = m->v->basis + D->basis_offset + (int64_t)3 * m->v->cub_tets[4 * c + n] * D->rank;
        tm->R[n] = m->act_R + 9 * m->cub_act[4 * c + n];
    }
}

/* g_d -= sum over domain k's corners of U_i^T R_i^T f_i, the forces its tets summed on
 * them (J^T f a corner at a time: each basis row read once a pass, not once a tet). */
static void project_corner_forces(sw_reduced *m, int32_t k, double *gd) {
    const sw_blob_domain *D = &m->v->domains[k];
    int32_t r = D->rank;
    for (int32_t i = m->corner_begin[k]; i < m->corner_begin[k + 1]; ++i) {
        const double *Rm = m->act_R + 9 * m->corner_act[i], *f = m->corner_f + 3 * i;
        const double *U0 = m->v->basis + D->basis_offset + (int64_t)3 * m->corner_lv[i] * r,
                     *U1 = U0 + r, *U2 = U1 + r;
        double w0 = Rm[0] * f[0] + Rm[3] * f[1] + Rm[6] * f[2],
               w1 = Rm[1] * f[0] + Rm[4] * f[1] + Rm[7] * f[2],
               w2 = Rm[2] * f[0] + Rm[5] * f[1] + Rm[8] * f[2];
        for (int32_t j = 0; j < r; ++j)
            gd[j] -= U0[j] * w0 + U1[j] * w1 + U2[j] * w2;
    }
}

/* One cubature pass over some domains, by one worker. */
typedef struct {
    sw_reduced *m;
    const double *q;
    int want_grad, want_hess;
} cub_pass;

/* Domains [begin, end) of a pass on worker `worker`: each writes only its own blocks of
 * g and H, its tets' SVD warm starts and weighted energies, and the worker's scratch, so
 * domains run on any workers in any order with bitwise the same result. */
static void cub_domains(uint32_t begin, uint32_t end, uint32_t worker, void *ctx) {
    const cub_pass *p = ctx;
    sw_reduced *m = p->m;
    const sw_blob_view *v = m->v;
    int want_grad = p->want_grad, want_hess = p->want_hess;
    uint32_t project = want_hess == SW_CUB_HESSIAN_EXACT ? 0u : SW_COROT_PROJECT_PSD;
    double *hm = m->hm + (int64_t)10 * m->rmax * worker;
    for (uint32_t k = begin; k < end; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank, o = D->q_offset;
        /* each corner placed once for all its tets */
        place_corners(m, (int32_t)k, p->q + o);
        /* the tets' Hessian goes to the domain's block of H, or first to the reference's
         * (cubature.h) when this pass refreshes it */
        double *Hd = m->H + (int64_t)o * m->R + o, *ref = NULL;
        int32_t ld = m->R;
        if (want_hess == 1 && m->h_ref) {
            ref = ref_block(m, (int32_t)k);
            for (int64_t i = 0; i < (int64_t)r * r; ++i)
                ref[i] = 0;
        }
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c) {
            double x[12], f[12];
            /* the weight of its energy at the character's material, times its painted
               multiplier (the cubature was fitted to the painted energy) */
            double w = m->cub_w[c] * sw_blob_stiffness(v->cub_stiffness, c);
            if (w == 0.0) { /* in a condensation patch: its tet is evaluated in full space */
                m->ecub[c] = 0;
                continue;
            }
            tet_map tm;
            tet_corners(m, D, c, x, want_hess ? &tm : NULL);
            const double *dminv = v->cub_dminv + 9 * c;
            if (!want_hess) { /* energy, and its forces summed on the corners (no SVD) */
                m->ecub[c] = w * sw_corot_eval(x, dminv, v->cub_vol[c], v->mu, v->lambda,
                                               want_grad ? f : NULL, NULL, project);
                if (!want_grad) continue;
                const int32_t *cc = m->cub_corner + 4 * c;
                for (int n = 0; n < 4; ++n)
                    for (int i = 0; i < 3; ++i)
                        m->corner_f[3 * cc[n] + i] += w * f[3 * n + i];
                continue;
            }
            m->ecub[c] =
                tet_with_hessian(&tm, r, x, dminv, v->cub_vol[c], v, m->svd_V + 9 * (int64_t)c,
                                 project, w, ref ? ref : Hd, ref ? r : ld, hm);
            for (int32_t j = 0; j < r; ++j)
                m->g[o + j] -= w * hm[j];
        }
        if (want_grad && !want_hess) project_corner_forces(m, (int32_t)k, m->g + o);
        if (ref) {
            mirror_upper(ref, r, r);
            add_block(Hd, ld, ref, r);
        } else if (want_hess) {
            mirror_upper(Hd, ld, r);
        }
    }
}

void sw_cubature_rest_hessian(sw_reduced *m, double *blocks) {
    static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const sw_blob_view *v = m->v;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank;
        for (int64_t i = 0; i < (int64_t)r * r; ++i)
            blocks[i] = 0;
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c) {
            tet_map tm;
            double x[12], V[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            for (int n = 0; n < 4; ++n) {
                int32_t lv = v->cub_tets[4 * c + n];
                const double *X = v->rest + 3 * (int64_t)v->domain_verts[D->vert_begin + lv];
                tm.U[n] = v->basis + D->basis_offset + (int64_t)3 * lv * r;
                tm.R[n] = I3;
                for (int i = 0; i < 3; ++i)
                    x[3 * n + i] = X[i];
            }
            (void)tet_with_hessian(
                &tm, r, x, v->cub_dminv + 9 * c, v->cub_vol[c], v, V, SW_COROT_PROJECT_PSD,
                v->cub_weight[c] * sw_blob_stiffness(v->cub_stiffness, c), blocks, r, m->hm);
        }
        mirror_upper(blocks, r, r);
        blocks += (int64_t)r * r;
    }
}

int64_t sw_cubature_rest_hessian_size(const sw_blob_view *v) {
    int64_t n = 0;
    for (int32_t k = 0; k < v->ndomains; ++k)
        n += (int64_t)v->domains[k].rank * v->domains[k].rank;
    return n;
}

double sw_cubature_hessian_madds(const sw_blob_view *v) {
    double n = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        double r = v->domains[k].rank;
        n += v->domains[k].cub_count * (4.5 * r * (r + 1) + 88 * r);
    }
    return n;
}

static double cubature_pass(sw_reduced *m, const double *q, int want_grad, int want_hess);

double sw_cubature_eval(sw_reduced *m, const double *q, int want_grad, int want_hess) {
    if (want_hess != SW_CUB_HESSIAN_REF) return cubature_pass(m, q, want_grad, want_hess);
    double E = cubature_pass(m, q, want_grad, 0);
    const sw_blob_view *v = m->v;
    const double *B = m->h_ref;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        int32_t r = v->domains[k].rank, o = v->domains[k].q_offset;
        add_block(m->H + (int64_t)o * m->R + o, m->R, B, r);
        B += (int64_t)r * r;
    }
    return E;
}

/* Every domain's tets at q, on the host's task workers when it gave them. */
static double cubature_pass(sw_reduced *m, const double *q, int want_grad, int want_hess) {
    const sw_blob_view *v = m->v;
    cub_pass p = {m, q, want_grad, want_hess};
    const sinew_task_callbacks *t = m->tasks;
    if (t && v->ndomains > 1) {
        void *h = t->enqueue(cub_domains, (uint32_t)v->ndomains, 1, &p, t->user);
        if (h) t->finish(h, t->user);
    } else {
        cub_domains(0, (uint32_t)v->ndomains, 0, &p);
    }
    /* the energy summed tet by tet in the blob's order, whoever evaluated them */
    double E = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c)
            E += m->ecub[c];
    }
    return E;
}
