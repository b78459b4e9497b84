/* The reference's incremental potential Phi (fullsim.h), its gradient and the Newton
 * system. */
#include "fullsim_internal.h"

#include <math.h>
#include <string.h>

#include "fem_corot.h"
#include "penalty.h"

/* ---- element evaluation ------------------------------------------------------ */

typedef struct {
    sw_fullsim *sim;
    const double *x;
    int want;
} elem_ctx;

static void eval_elements(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    elem_ctx *ctx = vctx;
    sw_fullsim *sim = ctx->sim;
    const int32_t *tets = sim->c->mesh.tets;
    for (int64_t t = begin; t < end; ++t) {
        double xe[12];
        for (int k = 0; k < 4; ++k)
            memcpy(xe + 3 * k, ctx->x + 3 * (int64_t)tets[4 * t + k], 24);
        const double st = sw_character_stiffness(sim->c, t); /* painted multiplier */
        sim->ee[t] =
            sw_corot_eval(xe, sim->DmInv + 9 * t, sim->vol[t], st * sim->mu, st * sim->lambda,
                          ctx->want >= EVAL_FORCE ? sim->fe + 12 * t : NULL,
                          ctx->want >= EVAL_HESSIAN ? sim->Ke + 144 * t : NULL, sim->hess_flags);
    }
}

static void gather_forces(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    sw_fullsim *sim = vctx;
    for (int64_t v = begin; v < end; ++v) {
        double f[3] = {0, 0, 0};
        for (int64_t i = sim->inc_ptr[v]; i < sim->inc_ptr[v + 1]; ++i) {
            const double *fe = sim->fe + 3 * sim->inc[i]; /* inc = 4*t + local */
            f[0] += fe[0];
            f[1] += fe[1];
            f[2] += fe[2];
        }
        memcpy(sim->fint + 3 * v, f, sizeof f);
    }
}

/* Evaluates all elements at x; returns the elastic energy (summed in element order). */
double sw_fullsim_evaluate(sw_fullsim *sim, const double *x, int want) {
    elem_ctx ctx = {sim, x, want};
    sw_pool_parallel_for(sim->pool, sim->nt, eval_elements, &ctx);
    if (want >= EVAL_FORCE) sw_pool_parallel_for(sim->pool, sim->nv, gather_forces, sim);
    if (want >= EVAL_HESSIAN) sw_bsr_assemble(&sim->K, sim->Ke, sim->pool);
    double e = 0;
    for (int32_t t = 0; t < sim->nt; ++t)
        e += sim->ee[t];
    return e;
}

/* ---- potential, gradient, operator ------------------------------------------ */

int sw_fullsim_dynamic(const sw_fullsim *sim) {
    return sim->p.integrator != SW_QUASISTATIC;
}

static double ground_k(const sw_fullsim *sim) {
    return sim->p.ground_k > 0 ? sim->p.ground_k : sim->p.contact_k;
}

void sw_fullsim_apply_Kn(sw_fullsim *sim, const double *u, double *y) {
    sw_bsr Kn = sim->K; /* K's pattern, the frozen values */
    Kn.val = sim->Kn;
    sw_bsr_multiply(&Kn, u, y, sim->pool);
}

/* The incremental potential Phi(x) of fullsim.h, with the elastic part `elastic`
 * already evaluated at x and the contacts frozen. Uses tmp and kdx as scratch. */
double sw_fullsim_potential(sw_fullsim *sim, const double *x, double elastic) {
    double phi = elastic;
    if (sim->p.self_contact && sim->ncontacts)
        phi += sw_contact_energy(sim->contacts, sim->ncontacts, x, sim->p.contact_k,
                                 sim->p.contact_alpha);
    phi += sw_ref_world_eval(&sim->world, x, NULL);
    for (int32_t v = 0; v < sim->nv; ++v) {
        const double *xv = x + 3 * v;
        if (sim->p.ground && sim->vert_area[v] > 0 && xv[1] < sim->p.ground_height) {
            double d = sim->p.ground_height - xv[1];
            phi += 0.5 * ground_k(sim) * sim->vert_area[v] * d * d;
        }
        const double *gr = sim->p.gravity;
        phi -= sim->mass[v] * (gr[0] * xv[0] + gr[1] * xv[1] + gr[2] * xv[2]);
    }
    if (!sw_fullsim_dynamic(sim)) return phi;
    int64_t m = 3 * (int64_t)sim->nv;
    for (int64_t i = 0; i < m; ++i)
        sim->tmp[i] = x[i] - sim->xn[i];
    sw_fullsim_apply_Kn(sim, sim->tmp, sim->kdx);
    double inertia = 0, damp_m = 0, damp_k = 0, lin = 0;
    for (int32_t v = 0; v < sim->nv; ++v)
        for (int i = 0; i < 3; ++i) {
            int64_t k = 3 * (int64_t)v + i;
            double dh = x[k] - sim->xhat[k], dn = sim->tmp[k];
            inertia += sim->mass[v] * dh * dh;
            damp_m += sim->mass[v] * dn * dn;
            lin += dn * sim->Dvn[k];
        }
    for (int64_t k = 0; k < m; ++k)
        damp_k += sim->tmp[k] * sim->kdx[k];
    phi += 0.5 * sim->c_m * inertia +
           0.5 * sim->c_d * (sim->p.rayleigh_alpha * damp_m + sim->p.rayleigh_beta * damp_k) -
           sim->s * lin;
    return phi;
}

/* g = grad Phi at x (forces fint and contacts of x already evaluated), masked. */
double sw_fullsim_gradient(sw_fullsim *sim, const double *x) {
    int32_t nv = sim->nv;
    int64_t m = 3 * (int64_t)nv;
    double *g = sim->g;
    for (int64_t k = 0; k < m; ++k)
        g[k] = -sim->fint[k];
    if (sim->p.self_contact && sim->ncontacts) {
        /* contact forces into tmp, then subtract */
        memset(sim->tmp, 0, (size_t)m * sizeof(double));
        sw_contact_add_forces(sim->contacts, sim->ncontacts, x, sim->p.contact_k,
                              sim->p.contact_alpha, sim->tmp);
        for (int64_t k = 0; k < m; ++k)
            g[k] -= sim->tmp[k];
    }
    if (sim->world.ncand) {
        memset(sim->tmp, 0, (size_t)m * sizeof(double));
        sw_ref_world_eval(&sim->world, x, sim->tmp);
        for (int64_t k = 0; k < m; ++k)
            g[k] -= sim->tmp[k];
    }
    for (int32_t v = 0; v < nv; ++v) {
        if (sim->p.ground && sim->vert_area[v] > 0 && x[3 * v + 1] < sim->p.ground_height)
            g[3 * v + 1] -=
                ground_k(sim) * sim->vert_area[v] * (sim->p.ground_height - x[3 * v + 1]);
        for (int i = 0; i < 3; ++i)
            g[3 * v + i] -= sim->mass[v] * sim->p.gravity[i];
    }
    if (sw_fullsim_dynamic(sim)) {
        for (int64_t k = 0; k < m; ++k)
            sim->tmp[k] = x[k] - sim->xn[k];
        sw_fullsim_apply_Kn(sim, sim->tmp, sim->kdx);
        for (int32_t v = 0; v < nv; ++v)
            for (int i = 0; i < 3; ++i) {
                int64_t k = 3 * (int64_t)v + i;
                g[k] += sim->c_m * sim->mass[v] * (x[k] - sim->xhat[k]) +
                        sim->c_d * (sim->p.rayleigh_alpha * sim->mass[v] * sim->tmp[k] +
                                    sim->p.rayleigh_beta * sim->kdx[k]) -
                        sim->s * sim->Dvn[k];
            }
    }
    double n2 = 0;
    for (int32_t v = 0; v < nv; ++v) {
        if (!sim->free_mask[v]) {
            g[3 * v] = g[3 * v + 1] = g[3 * v + 2] = 0;
            continue;
        }
        n2 += g[3 * v] * g[3 * v] + g[3 * v + 1] * g[3 * v + 1] + g[3 * v + 2] * g[3 * v + 2];
    }
    return sqrt(n2);
}

/* K.val (elastic Hessian) += c_d beta Kn + (c_m + c_d alpha) M + ground terms; the
 * diagonal blocks (plus contact diagonals) go to sim->diag for the preconditioner. */
static void finish_system(sw_fullsim *sim, const double *x) {
    sw_bsr *K = &sim->K;
    if (sw_fullsim_dynamic(sim)) {
        double cb = sim->c_d * sim->p.rayleigh_beta;
        for (int64_t i = 0; i < 9 * K->nblocks; ++i)
            K->val[i] += cb * sim->Kn[i];
    }
    double cm = sw_fullsim_dynamic(sim) ? sim->c_m + sim->c_d * sim->p.rayleigh_alpha : 0.0;
    for (int32_t i = 0; i < sim->world.ncand; ++i) { /* world contact: diagonal blocks */
        const sw_ref_world_cand *c = &sim->world.cand[i];
        double f[3], H[9];
        if (K->diag[c->v] < 0) continue;
        sw_world_penalty(&c->law, x + 3 * c->v, f, H);
        double *B = K->val + 9 * K->diag[c->v];
        for (int k = 0; k < 9; ++k)
            B[k] += H[k];
    }
    for (int32_t v = 0; v < sim->nv; ++v) {
        if (K->diag[v] < 0) continue;
        double *B = K->val + 9 * K->diag[v];
        for (int i = 0; i < 3; ++i)
            B[4 * i] += cm * sim->mass[v];
        if (sim->p.ground && sim->vert_area[v] > 0 && x[3 * v + 1] < sim->p.ground_height)
            B[4] += ground_k(sim) * sim->vert_area[v];
        memcpy(sim->diag + 9 * v, B, 9 * sizeof(double));
    }
    if (sim->p.self_contact && sim->ncontacts)
        sw_contact_add_diag(sim->contacts, sim->ncontacts, sim->p.contact_k, sim->p.contact_alpha,
                            sim->diag);
    sw_block_jacobi_invert(sim->nv, sim->diag, sim->free_mask, sim->Pinv);
}

static void system_apply(void *vctx, const double *xin, double *y) {
    sw_fullsim *sim = vctx;
    sw_bsr_multiply(&sim->K, xin, y, sim->pool);
    if (sim->p.self_contact && sim->ncontacts)
        sw_contact_apply_hessian(sim->contacts, sim->ncontacts, sim->p.contact_k,
                                 sim->p.contact_alpha, xin, y);
}

static sw_pcg_stats solve_pcg(sw_fullsim *sim) {
    size_t v3 = (size_t)sim->nv * 3 * sizeof(double);
    memcpy(sim->dx, sim->dx_prev, v3); /* warm start from the last update */
    return sw_pcg_solve(system_apply, sim, sim->rhs, sim->Pinv, sim->free_mask, sim->p.pcg_rtol,
                        sim->p.pcg_max, &sim->ws, sim->dx);
}

/* The direct path: factor and solve; SINEW_ERROR_DEGENERATE when indefinite. */
static sinew_result solve_direct(sw_fullsim *sim) {
    sw_error e;
    int32_t n = sim->p.self_contact ? sim->ncontacts : 0;
    sinew_result r = sw_sparse_chol_factor(sim->chol, &sim->K, sim->contacts, n, sim->p.contact_k,
                                           sim->p.contact_alpha, &e);
    if (r == SINEW_OK) r = sw_sparse_chol_solve(sim->chol, sim->rhs, sim->dx, &e);
    return r;
}

/* Adaptive mode keeps a truncated PCG answer (Newton-CG: the iterate before the
 * direction of negative curvature, a descent direction of the quadratic model) when
 * it has brought the relative residual below this; one truncated at once is re-solved
 * with projected element Hessians. On a fold whose compressed crease makes the exact
 * Hessian indefinite in most iterations, projecting every truncated iteration (the
 * threshold 0) leaves Newton crawling along the crease's soft modes, and keeping every
 * truncated answer (always exact) leaves some of the elephant's frames unconverged; 0.9
 * converged both (docs/notes/outside-the-harness.md has the figures). */
#define SW_TRUNCATED_PROGRESS 0.9

sinew_result sw_fullsim_solve_system(sw_fullsim *sim, sw_fullsim_stats *st) {
    finish_system(sim, sim->x);
    int indefinite;
    sinew_result r = SINEW_OK;
    if (sim->chol) {
        r = solve_direct(sim);
        indefinite = r == SINEW_ERROR_DEGENERATE;
    } else {
        sw_pcg_stats ps = solve_pcg(sim);
        st->pcg_iters += ps.iters;
        indefinite = ps.negative_curvature && ps.rel_residual > SW_TRUNCATED_PROGRESS;
    }
    /* Indefinite: the projected element Hessians, this once (always for the direct
     * solve, which has no truncated answer; PCG in adaptive mode). A diagonal shift
     * (Levenberg-Marquardt) instead was measured worse: the finger's exact Hessian in
     * a fold needed a shift of the whole diagonal's size, which is gradient descent. */
    if (indefinite && (sim->chol ? sim->p.hessian != SW_HESSIAN_PROJECTED
                                 : sim->p.hessian == SW_HESSIAN_ADAPTIVE)) {
        sim->hess_flags = SW_COROT_PROJECT_PSD;
        sw_fullsim_evaluate(sim, sim->x, EVAL_HESSIAN);
        finish_system(sim, sim->x);
        st->projected_iters++;
        if (sim->chol)
            r = solve_direct(sim);
        else
            st->pcg_iters += solve_pcg(sim).iters;
    }
    if (sim->chol && r != SINEW_OK) {
        if (r == SINEW_ERROR_NOT_FINITE) return r;
        st->pcg_iters += solve_pcg(sim).iters; /* no factor: the iterative solve */
    }
    return SINEW_OK;
}

sinew_result sw_fullsim_rest_response(sw_fullsim *sim, int32_t n, const double *f, double *u,
                                      sw_error *err) {
    if (sw_fullsim_dynamic(sim))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "rest response: a quasistatic simulator is needed");
    int64_t m = 3 * (int64_t)sim->nv;
    size_t v3 = (size_t)m * sizeof(double);
    const double *X = sim->c->mesh.X;
    memcpy(sim->x, X, v3);
    sim->ncontacts = 0;
    sim->world.ncand = 0;
    /* at rest the co-rotational Hessian is the linear-elastic stiffness, positive definite
       over the free vertices; the projection only guards a degenerate element */
    sim->hess_flags = SW_COROT_PROJECT_PSD;
    sw_fullsim_evaluate(sim, sim->x, EVAL_HESSIAN);
    sw_fullsim_stats st;
    memset(&st, 0, sizeof st);
    for (int32_t j = 0; j < n; ++j) {
        const double *fj = f + (size_t)j * m;
        for (int32_t v = 0; v < sim->nv; ++v)
            for (int i = 0; i < 3; ++i)
                sim->rhs[3 * v + i] = sim->free_mask[v] ? fj[3 * v + i] : 0.0;
        memset(sim->dx_prev, 0, v3);
        sinew_result r = sw_fullsim_solve_system(sim, &st);
        if (r != SINEW_OK) return sw_error_set(err, r, "rest response %d: the solve failed", j);
        if (!sw_fullsim_all_finite(sim->dx, m))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "rest response %d: not finite", j);
        memcpy(u + (size_t)j * m, sim->dx, v3);
    }
    return SINEW_OK;
}
