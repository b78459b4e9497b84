/* Full-space reference simulator (see fullsim.h for the formulation). */
#include "fullsim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sw_mesh.h"

#include "blob_view.h"
#include "bsr_matrix.h"
#include "fem_corot.h"
#include "mesh_io.h"
#include "pcg.h"
#include "penalty.h"

struct sw_fullsim {
    sw_fullsim_params p;
    const sw_character *c;
    int32_t nv, nt;
    double mu, lambda;
    double *DmInv, *vol; /* 9*nt, nt */
    double *mass;        /* nv lumped masses */
    unsigned char *free_mask;
    int32_t ndriven;
    sw_surface surf;
    double *vert_area; /* nv: rest surface area around each surface vertex (0 inside) */
    sw_selfcontact *sc;
    sw_bsr K;               /* pattern; val holds the Newton system matrix during an iteration */
    double *Kn;             /* 9*nblocks: K(x_n), the Rayleigh stiffness term (dynamics only) */
    double *Ke;             /* 144*nt element Hessians */
    double *fe;             /* 12*nt element forces */
    double *ee;             /* nt element energies */
    int64_t *inc_ptr, *inc; /* vertex -> element entries (4*t + local), for force gathers */
    double *x, *v, *a, *xn, *vn, *an, *xhat, *Dvn;
    double *skin_prev, *skin_now;
    double *g, *dx, *dx_prev, *tmp, *xtrial, *diag, *Pinv, *fint;
    double *rhs, *kdx; /* Newton right-hand side; K_n (x - x_n) scratch */
    sw_pcg_workspace ws;
    sw_pool *pool;
    double c_m, c_d, s; /* integrator coefficients of this step */
    const sw_contact *contacts;
    int32_t ncontacts;
    double gfloor;        /* absolute gradient norm treated as converged */
    uint32_t hess_flags;  /* sw_corot_eval flags of the current evaluation */
    sw_contact *active;   /* the step's contact set: surf.nverts slots, one per vertex */
    int32_t *active_slot; /* nv: slot of a vertex in `active`, or -1 */
};

sw_fullsim_params sw_fullsim_params_default(void) {
    sw_fullsim_params p;
    memset(&p, 0, sizeof p);
    p.integrator = SW_QUASISTATIC;
    p.dt = 1.0 / 30.0;
    p.rayleigh_alpha = 0.01;
    p.rayleigh_beta = 0.001;
    p.self_contact = 1;
    p.contact_k = 1e6;
    p.contact_alpha = SW_CONTACT_ALPHA;
    p.neighbour_factor = 1.8;
    p.ground = 0;
    p.ground_height = 0;
    p.ground_k = 0; /* 0: contact_k */
    p.hessian = SW_HESSIAN_ADAPTIVE;
    p.contact_rounds = 30; /* fullsim.h: 8 left every contact frame of the finger unsettled */
    p.max_newton = 20;
    p.newton_rtol = 1e-4;
    p.pcg_rtol = 1e-3;
    p.pcg_max = 1000;
    p.threads = 0;
    return p;
}

/* ---- element evaluation ------------------------------------------------------ */

enum { EVAL_ENERGY = 0, EVAL_FORCE = 1, EVAL_HESSIAN = 2 };

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
        sim->ee[t] =
            sw_corot_eval(xe, sim->DmInv + 9 * t, sim->vol[t], sim->mu, sim->lambda,
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
static double evaluate(sw_fullsim *sim, const double *x, int want) {
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

static int dynamic(const sw_fullsim *sim) {
    return sim->p.integrator != SW_QUASISTATIC;
}

static double ground_k(const sw_fullsim *sim) {
    return sim->p.ground_k > 0 ? sim->p.ground_k : sim->p.contact_k;
}

/* The incremental potential Phi(x) of fullsim.h, with the elastic part `elastic`
 * already evaluated at x and the contacts frozen. Uses tmp and kdx as scratch. */
static double potential(sw_fullsim *sim, const double *x, double elastic) {
    double phi = elastic;
    if (sim->p.self_contact && sim->ncontacts)
        phi += sw_contact_energy(sim->contacts, sim->ncontacts, x, sim->p.contact_k,
                                 sim->p.contact_alpha);
    for (int32_t v = 0; v < sim->nv; ++v) {
        const double *xv = x + 3 * v;
        if (sim->p.ground && sim->vert_area[v] > 0 && xv[1] < sim->p.ground_height) {
            double d = sim->p.ground_height - xv[1];
            phi += 0.5 * ground_k(sim) * sim->vert_area[v] * d * d;
        }
        const double *gr = sim->p.gravity;
        phi -= sim->mass[v] * (gr[0] * xv[0] + gr[1] * xv[1] + gr[2] * xv[2]);
    }
    if (!dynamic(sim)) return phi;
    int64_t m = 3 * (int64_t)sim->nv;
    for (int64_t i = 0; i < m; ++i)
        sim->tmp[i] = x[i] - sim->xn[i];
    sw_bsr Kn = sim->K;
    Kn.val = sim->Kn;
    sw_bsr_multiply(&Kn, sim->tmp, sim->kdx, sim->pool);
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
static double gradient(sw_fullsim *sim, const double *x) {
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
    for (int32_t v = 0; v < nv; ++v) {
        if (sim->p.ground && sim->vert_area[v] > 0 && x[3 * v + 1] < sim->p.ground_height)
            g[3 * v + 1] -=
                ground_k(sim) * sim->vert_area[v] * (sim->p.ground_height - x[3 * v + 1]);
        for (int i = 0; i < 3; ++i)
            g[3 * v + i] -= sim->mass[v] * sim->p.gravity[i];
    }
    if (dynamic(sim)) {
        for (int64_t k = 0; k < m; ++k)
            sim->tmp[k] = x[k] - sim->xn[k];
        sw_bsr Kn = sim->K;
        Kn.val = sim->Kn;
        sw_bsr_multiply(&Kn, sim->tmp, sim->kdx, sim->pool);
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
    if (dynamic(sim)) {
        double cb = sim->c_d * sim->p.rayleigh_beta;
        for (int64_t i = 0; i < 9 * K->nblocks; ++i)
            K->val[i] += cb * sim->Kn[i];
    }
    double cm = dynamic(sim) ? sim->c_m + sim->c_d * sim->p.rayleigh_alpha : 0.0;
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

/* ---- creation ----------------------------------------------------------------- */

static int all_finite(const double *a, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
        if (!isfinite(a[i])) return 0;
    return 1;
}

static sinew_result check_params(const sw_fullsim_params *p, sw_error *err) {
    if (!(p->dt > 0 && p->dt <= 10) || !isfinite(p->dt))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "dt = %g s (must be in (0, 10])",
                            p->dt);
    if (p->integrator < SW_QUASISTATIC || p->integrator > SW_NEWMARK)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "unknown integrator %d",
                            (int)p->integrator);
    if (!(p->rayleigh_alpha >= 0) || !(p->rayleigh_beta >= 0) || !isfinite(p->rayleigh_alpha) ||
        !isfinite(p->rayleigh_beta))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "Rayleigh damping (%g, %g) must be finite and >= 0", p->rayleigh_alpha,
                            p->rayleigh_beta);
    if (!(p->contact_k >= 0) || !isfinite(p->contact_k) || !(p->contact_alpha >= 0) ||
        !(p->contact_alpha <= 1) || !(p->ground_k >= 0) || !isfinite(p->ground_k))
        return sw_error_set(
            err, SINEW_ERROR_INVALID_ARGUMENT,
            "contact stiffness %g / anisotropy %g / ground stiffness %g out of range", p->contact_k,
            p->contact_alpha, p->ground_k);
    if (!all_finite(p->gravity, 3) || !isfinite(p->ground_height))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "gravity or ground not finite");
    if (p->hessian < SW_HESSIAN_ADAPTIVE || p->hessian > SW_HESSIAN_EXACT ||
        p->contact_rounds < 1 || p->contact_rounds > 100)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "hessian mode %d / contact rounds %d out of range", (int)p->hessian,
                            p->contact_rounds);
    if (p->max_newton < 1 || p->max_newton > 1000 || p->pcg_max < 1 || p->pcg_max > 1000000 ||
        !(p->newton_rtol > 0 && p->newton_rtol < 1) || !(p->pcg_rtol > 0 && p->pcg_rtol < 1))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "solver limits out of range (newton %d, rtol %g, pcg %d, rtol %g)",
                            p->max_newton, p->newton_rtol, p->pcg_max, p->pcg_rtol);
    return SINEW_OK;
}

static sinew_result check_character(const sw_character *c, sw_error *err) {
    sinew_result r = sw_tetmesh_validate(&c->mesh, 0.0, err);
    if (r != SINEW_OK) return r;
    if ((r = sw_skeleton_validate(&c->skel, err)) != SINEW_OK) return r;
    if (!c->bone_of_vertex || c->weights.nverts != c->mesh.nverts ||
        c->weights.nbones != c->skel.nbones || !c->weights.w)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character '%s': weights (%d x %d) do not match mesh (%d vertices) and "
                            "skeleton (%d bones), or no bone-driven vertex list",
                            c->name, c->weights.nverts, c->weights.nbones, c->mesh.nverts,
                            c->skel.nbones);
    if (!(c->youngs > 0) || !isfinite(c->youngs) || !(c->poisson > -1 && c->poisson < 0.5) ||
        !(c->density > 0) || !isfinite(c->density))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character '%s': material E = %g, nu = %g, density = %g out of range",
                            c->name, c->youngs, c->poisson, c->density);
    int32_t driven = 0;
    for (int32_t v = 0; v < c->mesh.nverts; ++v) {
        int32_t b = c->bone_of_vertex[v];
        if (b < -1 || b >= c->skel.nbones)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "vertex %d is driven by bone %d of %d", v, b, c->skel.nbones);
        driven += b >= 0;
    }
    if (driven == 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character '%s' has no bone-driven vertex: the problem is singular",
                            c->name);
    return SINEW_OK;
}

/* The per-vertex 3-vectors the simulator owns, listed once for allocation and release. */
enum { SW_NVECS = 18 };
static void state_vectors(sw_fullsim *sim, double **v[SW_NVECS]) {
    double **all[SW_NVECS] = {
        &sim->x,       &sim->v,   &sim->a,         &sim->xn,       &sim->vn,  &sim->an,
        &sim->xhat,    &sim->Dvn, &sim->skin_prev, &sim->skin_now, &sim->g,   &sim->dx,
        &sim->dx_prev, &sim->tmp, &sim->xtrial,    &sim->fint,     &sim->rhs, &sim->kdx};
    memcpy(v, all, sizeof all);
}

void sw_fullsim_destroy(sw_fullsim *sim) {
    if (!sim) return;
    free(sim->DmInv);
    free(sim->vol);
    free(sim->diag);
    free(sim->Pinv);
    free(sim->mass);
    free(sim->free_mask);
    sw_surface_free(&sim->surf);
    free(sim->vert_area);
    sw_selfcontact_destroy(sim->sc);
    sw_bsr_free(&sim->K);
    free(sim->Kn);
    free(sim->Ke);
    free(sim->fe);
    free(sim->ee);
    free(sim->inc_ptr);
    free(sim->inc);
    free(sim->active);
    free(sim->active_slot);
    double **vecs[SW_NVECS];
    state_vectors(sim, vecs);
    for (int i = 0; i < SW_NVECS; ++i)
        free(*vecs[i]);
    sw_pcg_workspace_free(&sim->ws);
    sw_pool_destroy(sim->pool);
    free(sim);
}

sinew_result sw_fullsim_create(const sw_character *c, const sw_fullsim_params *params,
                               sw_fullsim **out, sw_error *err) {
    *out = NULL;
    sw_fullsim_params p = params ? *params : sw_fullsim_params_default();
    sinew_result r = check_params(&p, err);
    if (r != SINEW_OK) return r;
    if (!c) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "no character");
    if ((r = check_character(c, err)) != SINEW_OK) return r;

    sw_fullsim *sim = calloc(1, sizeof *sim);
    if (!sim) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    sim->p = p;
    sim->c = c;
    int32_t nv = sim->nv = c->mesh.nverts, nt = sim->nt = c->mesh.ntets;
    size_t v3 = (size_t)nv * 3 * sizeof(double);
    sw_lame(c->youngs, c->poisson, &sim->mu, &sim->lambda);
    sim->DmInv = malloc((size_t)nt * 9 * sizeof(double));
    sim->vol = malloc((size_t)nt * sizeof(double));
    sim->mass = calloc((size_t)nv, sizeof(double));
    sim->free_mask = malloc((size_t)nv);
    sim->vert_area = calloc((size_t)nv, sizeof(double));
    sim->Ke = malloc((size_t)nt * 144 * sizeof(double));
    sim->fe = malloc((size_t)nt * 12 * sizeof(double));
    sim->ee = malloc((size_t)nt * sizeof(double));
    sim->inc_ptr = calloc((size_t)nv + 1, sizeof(int64_t));
    sim->inc = malloc((size_t)nt * 4 * sizeof(int64_t));
    double **vecs[SW_NVECS];
    state_vectors(sim, vecs);
    sim->diag = calloc((size_t)nv, 9 * sizeof(double));
    sim->Pinv = calloc((size_t)nv, 9 * sizeof(double));
    int ok = sim->diag && sim->Pinv && sim->DmInv && sim->vol && sim->mass && sim->free_mask &&
             sim->vert_area && sim->Ke && sim->fe && sim->ee && sim->inc_ptr && sim->inc;
    for (int i = 0; i < SW_NVECS; ++i)
        ok = ok && (*vecs[i] = calloc(1, v3));
    ok = ok && sw_pcg_workspace_init(&sim->ws, nv);
    if (!ok) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for %d tets", nt);
    }
    const double *X = c->mesh.X;
    const int32_t *tets = c->mesh.tets;
    for (int32_t t = 0; t < nt; ++t) {
        double Xe[12];
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, X + 3 * (int64_t)tets[4 * t + k], 24);
        if (!sw_tet_rest(Xe, sim->DmInv + 9 * t, sim->vol + t)) {
            sw_fullsim_destroy(sim);
            return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tet %d is degenerate at rest", t);
        }
        sw_lumped_mass_add(tets + 4 * t, c->density, sim->vol[t], sim->mass);
        for (int k = 0; k < 4; ++k)
            sim->inc_ptr[tets[4 * t + k] + 1]++;
    }
    for (int32_t v = 0; v < nv; ++v)
        sim->inc_ptr[v + 1] += sim->inc_ptr[v];
    int64_t *fill = malloc((size_t)nv * sizeof(int64_t));
    if (!fill) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for %d tets", nt);
    }
    memcpy(fill, sim->inc_ptr, (size_t)nv * sizeof(int64_t));
    for (int32_t t = 0; t < nt; ++t) /* element order within each vertex: deterministic */
        for (int k = 0; k < 4; ++k)
            sim->inc[fill[tets[4 * t + k]]++] = 4 * (int64_t)t + k;
    free(fill);
    for (int32_t v = 0; v < nv; ++v) {
        sim->free_mask[v] = c->bone_of_vertex[v] < 0;
        sim->ndriven += c->bone_of_vertex[v] >= 0;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i) {
            lo[i] = fmin(lo[i], X[3 * v + i]);
            hi[i] = fmax(hi[i], X[3 * v + i]);
        }
    double diag2 = 0;
    for (int i = 0; i < 3; ++i)
        diag2 += (hi[i] - lo[i]) * (hi[i] - lo[i]);
    sim->gfloor = 1e-12 * c->youngs * diag2 * sqrt((double)nv);

    if ((r = sw_tetmesh_surface(&c->mesh, &sim->surf, err)) != SINEW_OK ||
        (r = sw_bsr_create_from_tets(nv, nt, tets, &sim->K, err)) != SINEW_OK ||
        (r = sw_selfcontact_create(&c->mesh, &sim->surf, p.neighbour_factor, 0, &sim->sc, err)) !=
            SINEW_OK) {
        sw_fullsim_destroy(sim);
        return r;
    }
    for (int32_t f = 0; f < sim->surf.ntris; ++f) {
        const int32_t *tri = sim->surf.tris + 3 * f;
        const double *a = X + 3 * tri[0], *b = X + 3 * tri[1], *cc = X + 3 * tri[2];
        double e1[3], e2[3];
        for (int i = 0; i < 3; ++i) {
            e1[i] = b[i] - a[i];
            e2[i] = cc[i] - a[i];
        }
        double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
               cz = e1[0] * e2[1] - e1[1] * e2[0];
        double area = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
        for (int k = 0; k < 3; ++k)
            sim->vert_area[tri[k]] += area / 3.0;
    }
    sim->active = malloc(((size_t)sim->surf.nverts + 1) * sizeof(sw_contact));
    sim->active_slot = malloc((size_t)nv * sizeof(int32_t));
    if (!sim->active || !sim->active_slot) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    if (dynamic(sim) && !(sim->Kn = calloc((size_t)sim->K.nblocks * 9, sizeof(double)))) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    if (!(sim->pool = sw_pool_create(p.threads))) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cannot start %d threads", p.threads);
    }
    for (int32_t v = 0; v < nv; ++v)
        sim->active_slot[v] = -1;
    memcpy(sim->x, X, v3);
    memcpy(sim->skin_prev, X, v3);
    *out = sim;
    return SINEW_OK;
}

/* ---- the step ----------------------------------------------------------------- */

static void set_integrator(sw_fullsim *sim) {
    double h = sim->p.dt;
    int32_t nv = sim->nv;
    sim->c_m = sim->c_d = sim->s = 0;
    if (!dynamic(sim)) return;
    int newmark = sim->p.integrator == SW_NEWMARK;
    sim->c_m = newmark ? 4.0 / (h * h) : 1.0 / (h * h);
    sim->c_d = newmark ? 2.0 / h : 1.0 / h;
    sim->s = newmark ? 1.0 : 0.0;
    for (int64_t k = 0; k < 3 * (int64_t)nv; ++k)
        sim->xhat[k] = sim->xn[k] + h * sim->vn[k] + (newmark ? 0.25 * h * h * sim->an[k] : 0.0);
    /* Rayleigh stiffness at x_n, frozen for the step; Dvn = D v_n. Projected to PSD so
     * that damping never adds energy. */
    sim->hess_flags = SW_COROT_PROJECT_PSD;
    evaluate(sim, sim->xn, EVAL_HESSIAN);
    memcpy(sim->Kn, sim->K.val, (size_t)sim->K.nblocks * 9 * sizeof(double));
    sw_bsr Kn = sim->K;
    Kn.val = sim->Kn;
    sw_bsr_multiply(&Kn, sim->vn, sim->Dvn, sim->pool);
    for (int32_t v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i) {
            int64_t k = 3 * (int64_t)v + i;
            sim->Dvn[k] = sim->p.rayleigh_alpha * sim->mass[v] * sim->vn[k] +
                          sim->p.rayleigh_beta * sim->Dvn[k];
        }
}

static void update_dynamics(sw_fullsim *sim) {
    double h = sim->p.dt;
    int newmark = sim->p.integrator == SW_NEWMARK;
    for (int32_t v = 0; v < sim->nv; ++v)
        for (int i = 0; i < 3; ++i) {
            int64_t k = 3 * (int64_t)v + i;
            if (!sim->free_mask[v] || !newmark) { /* backward Euler; driven: finite difference */
                sim->v[k] = (sim->x[k] - sim->xn[k]) / h;
                sim->a[k] = sim->free_mask[v] ? (sim->v[k] - sim->vn[k]) / h : 0.0;
            } else {
                sim->a[k] = sim->c_m * (sim->x[k] - sim->xhat[k]);
                sim->v[k] = sim->vn[k] + 0.5 * h * (sim->an[k] + sim->a[k]);
            }
        }
}

static void restore(sw_fullsim *sim) {
    size_t v3 = (size_t)sim->nv * 3 * sizeof(double);
    memcpy(sim->x, sim->xn, v3);
    memcpy(sim->v, sim->vn, v3);
    memcpy(sim->a, sim->an, v3);
}

/* Empties the step's contact set. */
static void clear_contacts(sw_fullsim *sim) {
    for (int32_t i = 0; i < sim->ncontacts; ++i)
        sim->active_slot[sim->active[i].p] = -1;
    sim->ncontacts = 0;
    sim->contacts = sim->active;
}

/* One contact round, an active-set update of the step's contact set:
 *  - a pair whose vertex is no longer behind its surface point along the frozen normal
 *    (<n, d> <= 0, eq. 3.12's Heaviside off) is dropped: the solve kept it there by
 *    pulling, and a contact never pulls (adhesion would hold a fold shut as it opens);
 *  - penetrations detected at the current positions are added, and a vertex already in
 *    the set gets its fresh contact (triangle, barycentrics, normal).
 * A pair the solve has just resolved sits slightly behind its surface (the penalty
 * balances the flesh pushing it in), so it stays: the set settles instead of dropping
 * resolved contacts and finding them again on alternate rounds. Returns the number of
 * pairs added or dropped (0: the set is complete and the last solve stands). */
static int32_t contact_round(sw_fullsim *sim) {
    int32_t changed = 0, kept = 0;
    for (int32_t i = 0; i < sim->ncontacts; ++i) {
        sw_contact *c = &sim->active[i];
        if (sw_contact_gap(c, sim->x) > 0) {
            sim->active_slot[c->p] = kept;
            sim->active[kept++] = *c;
        } else {
            sim->active_slot[c->p] = -1;
            changed++;
        }
    }
    sim->ncontacts = kept;
    int32_t n;
    const sw_contact *found =
        (sw_selfcontact_detect(sim->sc, sim->x, sim->pool), sw_selfcontact_list(sim->sc, &n));
    for (int32_t i = 0; i < n; ++i) {
        int32_t slot = sim->active_slot[found[i].p];
        if (slot < 0) {
            if (sim->ncontacts > sim->surf.nverts) continue; /* cannot happen: one per vertex */
            slot = sim->active_slot[found[i].p] = sim->ncontacts++;
            changed++;
        }
        sim->active[slot] = found[i];
    }
    sim->contacts = sim->active;
    return changed;
}

/* Whether a contact round at the current positions, whose penetrations are pen[0..n),
 * would add or drop a pair (contact_round's rules, without changing the set). */
static int set_would_change(const sw_fullsim *sim, const sw_contact *pen, int32_t n) {
    for (int32_t i = 0; i < sim->ncontacts; ++i)
        if (!(sw_contact_gap(&sim->active[i], sim->x) > 0)) return 1;
    for (int32_t i = 0; i < n; ++i)
        if (sim->active_slot[pen[i].p] < 0) return 1;
    return 0;
}

/* Solves the Newton system at sim->x into sim->dx with the current Hessian flags;
 * returns the PCG statistics. */
static sw_pcg_stats solve_newton_system(sw_fullsim *sim) {
    size_t v3 = (size_t)sim->nv * 3 * sizeof(double);
    finish_system(sim, sim->x);
    memcpy(sim->dx, sim->dx_prev, v3); /* warm start from the last update */
    return sw_pcg_solve(system_apply, sim, sim->rhs, sim->Pinv, sim->free_mask, sim->p.pcg_rtol,
                        sim->p.pcg_max, &sim->ws, sim->dx);
}

/* Newton with a backtracking (Armijo) line search on Phi, contacts frozen, from
 * sim->x, until |grad| <= rtol * *gref. *gref is the gradient norm of the step's
 * first evaluation (set by it when negative). */
static sinew_result newton_solve(sw_fullsim *sim, sw_fullsim_stats *st, double *gref, double rtol) {
    int32_t nv = sim->nv;
    int64_t m = 3 * (int64_t)nv;
    size_t v3 = (size_t)m * sizeof(double);
    for (int it = 0;; ++it) {
        sim->hess_flags = sim->p.hessian == SW_HESSIAN_PROJECTED ? SW_COROT_PROJECT_PSD : 0u;
        double elastic = evaluate(sim, sim->x, EVAL_HESSIAN);
        double gn = gradient(sim, sim->x);
        if (!isfinite(gn) || !isfinite(elastic)) return SINEW_ERROR_NOT_FINITE;
        if (*gref < 0) *gref = st->grad_norm0 = gn;
        if (st->newton_iters < 32) st->grad_history[st->newton_iters] = gn;
        st->grad_norm = gn;
        if (gn <= rtol * *gref || gn <= sim->gfloor) return SINEW_OK;
        if (it == sim->p.max_newton) return SINEW_ERROR_NOT_CONVERGED;
        for (int64_t k = 0; k < m; ++k)
            sim->rhs[k] = -sim->g[k];
        sw_pcg_stats ps = solve_newton_system(sim);
        st->pcg_iters += ps.iters;
        if (ps.negative_curvature && sim->p.hessian == SW_HESSIAN_ADAPTIVE) {
            sim->hess_flags = SW_COROT_PROJECT_PSD; /* indefinite here: projected, this once */
            evaluate(sim, sim->x, EVAL_HESSIAN);
            ps = solve_newton_system(sim);
            st->pcg_iters += ps.iters;
            st->projected_iters++;
        }
        double slope = 0;
        for (int64_t k = 0; k < m; ++k)
            slope += sim->g[k] * sim->dx[k];
        if (!(slope < 0)) { /* not a descent direction: preconditioned gradient instead */
            for (int32_t v = 0; v < nv; ++v) {
                const double *P = sim->Pinv + 9 * v, *gv = sim->g + 3 * v;
                for (int i = 0; i < 3; ++i)
                    sim->dx[3 * v + i] =
                        -(P[3 * i] * gv[0] + P[3 * i + 1] * gv[1] + P[3 * i + 2] * gv[2]);
            }
            slope = 0;
            for (int64_t k = 0; k < m; ++k)
                slope += sim->g[k] * sim->dx[k];
            if (!(slope < 0)) return SINEW_ERROR_NOT_CONVERGED;
        }
        double phi0 = potential(sim, sim->x, elastic), step = 1.0;
        int accepted = 0;
        for (int ls = 0; ls < 16 && !accepted; ++ls, step *= 0.5) {
            for (int64_t k = 0; k < m; ++k)
                sim->xtrial[k] = sim->x[k] + step * sim->dx[k];
            double phi1 = potential(sim, sim->xtrial, evaluate(sim, sim->xtrial, EVAL_ENERGY));
            /* Near convergence the decrease falls below Phi's round-off: a full Newton
             * step whose change is at that level is accepted. */
            accepted = isfinite(phi1) && (phi1 <= phi0 + 1e-4 * step * slope ||
                                          (ls == 0 && fabs(phi1 - phi0) <= 1e-12 * fabs(phi0)));
            if (accepted) break;
        }
        if (!accepted) return SINEW_ERROR_NOT_CONVERGED; /* stagnation: keep the best iterate */
        memcpy(sim->x, sim->xtrial, v3);
        for (int64_t k = 0; k < m; ++k)
            sim->dx_prev[k] = step * sim->dx[k];
        st->newton_iters++;
    }
}

sinew_result sw_fullsim_step(sw_fullsim *sim, const double *T, sw_fullsim_stats *stats) {
    sw_fullsim_stats st;
    memset(&st, 0, sizeof st);
    double t0 = sw_now_seconds();
    const sw_character *c = sim->c;
    int32_t nv = sim->nv;
    int64_t m = 3 * (int64_t)nv;
    size_t v3 = (size_t)m * sizeof(double);
    if (!T || !all_finite(T, 12 * (int64_t)c->skel.nbones)) {
        if (stats) *stats = st;
        return SINEW_ERROR_NOT_FINITE;
    }
    memcpy(sim->xn, sim->x, v3);
    memcpy(sim->vn, sim->v, v3);
    memcpy(sim->an, sim->a, v3);
    /* Warm start: driven vertices at their bone's pose, free flesh follows the change
     * of the skinned shape since the last step. */
    sw_lbs(nv, c->mesh.X, &c->weights, T, sim->skin_now);
    for (int32_t v = 0; v < nv; ++v) {
        int32_t b = c->bone_of_vertex[v];
        if (b >= 0)
            sw_transform_point(T + 12 * b, c->mesh.X + 3 * v, sim->x + 3 * v);
        else
            for (int i = 0; i < 3; ++i)
                sim->x[3 * v + i] += sim->skin_now[3 * v + i] - sim->skin_prev[3 * v + i];
    }
    set_integrator(sim);

    sinew_result result = SINEW_ERROR_NOT_CONVERGED;
    double gref = -1;
    clear_contacts(sim);
    int capped = 0;
    for (int round = 0;; ++round) {
        if (sim->p.self_contact && contact_round(sim) == 0 && round > 0) break; /* complete */
        st.contact_rounds += sim->p.self_contact;
        result = newton_solve(sim, &st, &gref, sim->p.newton_rtol);
        if (result == SINEW_ERROR_NOT_FINITE || !sim->p.self_contact) break;
        if (round + 1 >= sim->p.contact_rounds) {
            capped = 1;
            break;
        }
    }
    if (result == SINEW_ERROR_NOT_FINITE || !all_finite(sim->x, m)) {
        restore(sim);
        result = SINEW_ERROR_NOT_FINITE;
    } else {
        if (dynamic(sim)) update_dynamics(sim);
        memcpy(sim->skin_prev, sim->skin_now, v3);
    }
    st.converged = result == SINEW_OK;
    /* Measurement at the final positions: self-penetration and ground penetration. */
    int32_t found;
    sw_selfcontact_detect(sim->sc, sim->x, sim->pool);
    st.max_penetration = sw_selfcontact_max_depth(sim->sc);
    const sw_contact *pen = sw_selfcontact_list(sim->sc, &found);
    st.contacts = found;
    if (sim->p.self_contact && capped) /* would one more round have changed the set? */
        st.contacts_unsettled = set_would_change(sim, pen, found);
    if (sim->p.ground)
        for (int32_t v = 0; v < nv; ++v)
            if (sim->vert_area[v] > 0)
                st.ground_penetration =
                    fmax(st.ground_penetration, sim->p.ground_height - sim->x[3 * v + 1]);
    st.energy_elastic = evaluate(sim, sim->x, EVAL_ENERGY);
    if (dynamic(sim))
        for (int32_t v = 0; v < nv; ++v)
            st.energy_kinetic +=
                0.5 * sim->mass[v] *
                (sim->v[3 * v] * sim->v[3 * v] + sim->v[3 * v + 1] * sim->v[3 * v + 1] +
                 sim->v[3 * v + 2] * sim->v[3 * v + 2]);
    st.seconds = sw_now_seconds() - t0;
    if (stats) *stats = st;
    return result;
}

const double *sw_fullsim_positions(const sw_fullsim *sim) {
    return sim->x;
}
double *sw_fullsim_velocities(sw_fullsim *sim) {
    return sim->v;
}
const sw_surface *sw_fullsim_surface(const sw_fullsim *sim) {
    return &sim->surf;
}
const double *sw_fullsim_masses(const sw_fullsim *sim) {
    return sim->mass;
}

const sw_contact *sw_fullsim_contacts(const sw_fullsim *sim, int32_t *count) {
    *count = sim->p.self_contact ? sim->ncontacts : 0;
    return sim->contacts;
}
int32_t sw_fullsim_driven_count(const sw_fullsim *sim) {
    return sim->ndriven;
}

void sw_fullsim_set_state(sw_fullsim *sim, const double *T, const double *x, const double *v) {
    size_t v3 = (size_t)sim->nv * 3 * sizeof(double);
    memcpy(sim->x, x, v3);
    if (T) sw_lbs(sim->nv, sim->c->mesh.X, &sim->c->weights, T, sim->skin_prev);
    if (v)
        memcpy(sim->v, v, v3);
    else
        memset(sim->v, 0, v3);
    /* A consistent acceleration M a = f_elastic(x) + M g for the free vertices: Newmark
     * carries a between steps, and a wrong a_0 shows up as an energy error. */
    evaluate(sim, sim->x, EVAL_FORCE);
    for (int32_t i = 0; i < sim->nv; ++i)
        for (int k = 0; k < 3; ++k)
            sim->a[3 * i + k] = sim->free_mask[i] && sim->mass[i] > 0
                                    ? sim->fint[3 * i + k] / sim->mass[i] + sim->p.gravity[k]
                                    : 0.0;
}

double sw_fullsim_elastic_energy(sw_fullsim *sim) {
    return evaluate(sim, sim->x, EVAL_ENERGY);
}
