/* Full-space reference simulator: creation and state access (see fullsim.h for the
 * formulation, fullsim_internal.h for how the files divide it). */
#include "fullsim_internal.h"

#include "blob_view.h" /* SW_STIFFNESS_MIN, _MAX */

#include "bbox.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sw_mesh.h"

#include "fem_corot.h"
#include "mesh_io.h"
#include "penalty.h"

const char *sw_linear_solver_name(sw_linear_solver s) {
    return s == SW_SOLVER_CHOLMOD ? "cholmod" : s == SW_SOLVER_PCG ? "pcg" : "auto";
}

const char *sw_hessian_mode_name(sw_hessian_mode m) {
    return m == SW_HESSIAN_PROJECTED ? "projected" : m == SW_HESSIAN_EXACT ? "exact" : "adaptive";
}

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
    p.solver = SW_SOLVER_AUTO;
    p.contact_rounds = 60; /* fullsim.h: 8 left every contact frame of the finger unsettled */
    p.contact_set_check = 1;
    p.max_newton = 20;
    p.newton_rtol = 1e-4;
    p.pcg_rtol = 1e-3;
    p.pcg_max = 1000;
    p.threads = 0;
    p.world = NULL;
    p.world_radius = 0;
    return p;
}

void sw_fullsim_params_take_solver(sw_fullsim_params *to, const sw_fullsim_params *from) {
    to->solver = from->solver;
    to->hessian = from->hessian;
    to->contact_rounds = from->contact_rounds;
    to->contact_set_check = from->contact_set_check;
}

/* ---- creation ----------------------------------------------------------------- */

int sw_fullsim_all_finite(const double *a, int64_t n) {
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
    if (!sw_fullsim_all_finite(p->gravity, 3) || !isfinite(p->ground_height))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "gravity or ground not finite");
    if (!(p->world_radius >= 0) || !isfinite(p->world_radius))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "world detection radius %g is not a finite length >= 0",
                            p->world_radius);
    if (p->hessian < SW_HESSIAN_ADAPTIVE || p->hessian > SW_HESSIAN_EXACT ||
        p->contact_rounds < 1 || p->contact_rounds > 100 ||
        (p->contact_set_check != 0 && p->contact_set_check != 1))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "hessian mode %d / contact rounds %d / set check %d out of range",
                            (int)p->hessian, p->contact_rounds, p->contact_set_check);
    if (p->solver < SW_SOLVER_AUTO || p->solver > SW_SOLVER_PCG)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "linear solver %d unknown",
                            (int)p->solver);
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
    for (int32_t t = 0; c->tet_stiffness && t < c->mesh.ntets; ++t)
        if (!(c->tet_stiffness[t] >= SW_STIFFNESS_MIN && c->tet_stiffness[t] <= SW_STIFFNESS_MAX))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "character '%s': tet %d's painted stiffness multiplier %g is "
                                "outside [%g, %g]",
                                c->name, t, c->tet_stiffness[t], SW_STIFFNESS_MIN,
                                SW_STIFFNESS_MAX);
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
    sw_ref_world_free(&sim->world);
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
    sw_sparse_chol_destroy(sim->chol);
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
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, nv, X);
    double size = sw_bbox_diagonal(lo, hi);
    sim->gfloor = 1e-12 * c->youngs * size * size * sqrt((double)nv);
    sim->world.world = p.world;
    sim->world.blob_k = p.contact_k;
    sim->world.radius = p.world_radius > 0 ? p.world_radius : 0.02 * size;

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
    if (sw_fullsim_dynamic(sim) &&
        !(sim->Kn = calloc((size_t)sim->K.nblocks * 9, sizeof(double)))) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    if (!(sim->pool = sw_pool_create(p.threads))) {
        sw_fullsim_destroy(sim);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cannot start %d threads", p.threads);
    }
    if (p.solver == SW_SOLVER_CHOLMOD &&
        (r = sw_sparse_chol_create(nv, sim->free_mask, &sim->chol, err)) != SINEW_OK) {
        sw_fullsim_destroy(sim);
        return r;
    }
    for (int32_t v = 0; v < nv; ++v)
        sim->active_slot[v] = -1;
    memcpy(sim->x, X, v3);
    memcpy(sim->skin_prev, X, v3);
    *out = sim;
    return SINEW_OK;
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
    sw_fullsim_evaluate(sim, sim->x, EVAL_FORCE);
    for (int32_t i = 0; i < sim->nv; ++i)
        for (int k = 0; k < 3; ++k)
            sim->a[3 * i + k] = sim->free_mask[i] && sim->mass[i] > 0
                                    ? sim->fint[3 * i + k] / sim->mass[i] + sim->p.gravity[k]
                                    : 0.0;
}

double sw_fullsim_elastic_energy(sw_fullsim *sim) {
    return sw_fullsim_evaluate(sim, sim->x, EVAL_ENERGY);
}
