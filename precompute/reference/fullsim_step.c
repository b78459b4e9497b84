/* The reference's step: warm start, contact, Newton with a line search on Phi. */
#include "fullsim_internal.h"

#include <math.h>
#include <string.h>

#include "clock.h"
#include "collision.h"
#include "fem_corot.h"
#include "penalty.h"
#include "sw_mesh.h"

/* ---- the step ----------------------------------------------------------------- */

static void set_integrator(sw_fullsim *sim) {
    double h = sim->p.dt;
    int32_t nv = sim->nv;
    sim->c_m = sim->c_d = sim->s = 0;
    if (!sw_fullsim_dynamic(sim)) return;
    int newmark = sim->p.integrator == SW_NEWMARK;
    sim->c_m = newmark ? 4.0 / (h * h) : 1.0 / (h * h);
    sim->c_d = newmark ? 2.0 / h : 1.0 / h;
    sim->s = newmark ? 1.0 : 0.0;
    for (int64_t k = 0; k < 3 * (int64_t)nv; ++k)
        sim->xhat[k] = sim->xn[k] + h * sim->vn[k] + (newmark ? 0.25 * h * h * sim->an[k] : 0.0);
    /* Rayleigh stiffness at x_n, frozen for the step; Dvn = D v_n. Projected to PSD so
     * that damping never adds energy. */
    sim->hess_flags = SW_COROT_PROJECT_PSD;
    sw_fullsim_evaluate(sim, sim->xn, EVAL_HESSIAN);
    memcpy(sim->Kn, sim->K.val, (size_t)sim->K.nblocks * 9 * sizeof(double));
    sw_fullsim_apply_Kn(sim, sim->vn, sim->Dvn);
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

/* A pair leaves the set only once its vertex is in front of its surface point by more
 * than this share of the depth it was detected at (hysteresis). Dropping it as soon as
 * the gap reached 0 made the set cycle: the solve pushed a vertex just out, the round
 * dropped its pair, the next solve let it back in, until the round cap (the finger's
 * fold; docs/notes/outside-the-harness.md has the figures). */
#define SW_CONTACT_HYSTERESIS 0.5

/* Whether pair c stays in the set at positions x. */
static int pair_stays(const sw_contact *c, const double *x) {
    return sw_contact_gap(c, x) > -SW_CONTACT_HYSTERESIS * c->depth;
}

/* One contact round, an active-set update of the step's contact set:
 *  - a pair whose vertex has left its surface point along the frozen normal by more
 *    than the hysteresis band (eq. 3.12's Heaviside off, with a margin) is dropped: the
 *    solve kept it there by pulling, and a contact must not glue a fold shut as it
 *    opens; inside the band it stays, and may pull by at most half its detection depth;
 *  - penetrations detected at the current positions are added, and a vertex already in
 *    the set gets its fresh contact (triangle, barycentrics, normal).
 * A pair the solve has just resolved sits near its surface (the penalty balances the
 * flesh pushing it in), so it stays: the set settles instead of dropping resolved
 * contacts and finding them again on alternate rounds. Returns the number of pairs
 * added or dropped (0: the set is complete and the last solve stands). */
static int32_t contact_round(sw_fullsim *sim) {
    int32_t changed = 0, kept = 0;
    for (int32_t i = 0; i < sim->ncontacts; ++i) {
        sw_contact *c = &sim->active[i];
        if (pair_stays(c, sim->x)) {
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
        if (!pair_stays(&sim->active[i], sim->x)) return 1;
    for (int32_t i = 0; i < n; ++i)
        if (sim->active_slot[pen[i].p] < 0) return 1;
    return 0;
}

/* Whether the contact set would change at the current positions (a detection, then
 * contact_round's rules). */
static int set_changes_now(sw_fullsim *sim) {
    int32_t n;
    sw_selfcontact_detect(sim->sc, sim->x, sim->pool);
    const sw_contact *pen = sw_selfcontact_list(sim->sc, &n);
    return set_would_change(sim, pen, n);
}

/* Newton steps this round takes before each check of its contact set. */
#define SW_SET_CHECK_AFTER 2

/* Newton with a backtracking (Armijo) line search on Phi, contacts frozen, from
 * sim->x, until |grad| <= rtol * *gref. *gref is the gradient norm of the step's
 * first evaluation (set by it when negative).
 *
 * With self-contact, after SW_SET_CHECK_AFTER accepted steps and after every one that
 * follows, the contact set is checked at the iterate: once it would change, converging
 * this frozen set further is wasted work, since the next round solves another
 * problem; the solve stops with SINEW_ERROR_NOT_CONVERGED. Only
 * the last round, with a set that no longer changes, is converged to the tolerance.
 * Measured on the finger's 40-frame fold (quasistatic, PCG, the default Hessian): at
 * 20K tets 331-378 ms a frame on average instead of 1,610 ms, at 50K 1.2-1.5 s instead
 * of 20 s, every frame settled; rounds had run to 20 Newton iterations each, most of them
 * crawling along the fold's soft modes for a set the next round replaced. */
static sinew_result newton_solve(sw_fullsim *sim, sw_fullsim_stats *st, double *gref, double rtol) {
    int check = sim->p.self_contact && sim->p.contact_set_check && sim->p.contact_rounds > 1;
    int32_t nv = sim->nv;
    int64_t m = 3 * (int64_t)nv;
    size_t v3 = (size_t)m * sizeof(double);
    for (int it = 0;; ++it) {
        sim->hess_flags = sim->p.hessian == SW_HESSIAN_PROJECTED ? SW_COROT_PROJECT_PSD : 0u;
        double elastic = sw_fullsim_evaluate(sim, sim->x, EVAL_HESSIAN);
        double gn = sw_fullsim_gradient(sim, sim->x);
        if (!isfinite(gn) || !isfinite(elastic)) return SINEW_ERROR_NOT_FINITE;
        if (*gref < 0) *gref = st->grad_norm0 = gn;
        if (st->newton_iters < 32) st->grad_history[st->newton_iters] = gn;
        st->grad_norm = gn;
        if (gn <= rtol * *gref || gn <= sim->gfloor) return SINEW_OK;
        if (it == sim->p.max_newton) return SINEW_ERROR_NOT_CONVERGED;
        for (int64_t k = 0; k < m; ++k)
            sim->rhs[k] = -sim->g[k];
        sinew_result sr = sw_fullsim_solve_system(sim, st);
        if (sr == SINEW_ERROR_NOT_FINITE) return sr;
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
        double phi0 = sw_fullsim_potential(sim, sim->x, elastic), step = 1.0;
        int accepted = 0;
        for (int ls = 0; ls < 16 && !accepted; ++ls, step *= 0.5) {
            for (int64_t k = 0; k < m; ++k)
                sim->xtrial[k] = sim->x[k] + step * sim->dx[k];
            double phi1 = sw_fullsim_potential(sim, sim->xtrial,
                                               sw_fullsim_evaluate(sim, sim->xtrial, EVAL_ENERGY));
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
        if (check && it + 1 >= SW_SET_CHECK_AFTER && set_changes_now(sim))
            return SINEW_ERROR_NOT_CONVERGED; /* the next round takes the new set */
    }
}

/* Warm start: driven vertices at their bone's pose, free flesh follows the change of the
 * skinned shape since the last step. The last state is kept for a refused step. */
static void warm_start(sw_fullsim *sim, const double *T) {
    const sw_character *c = sim->c;
    const int32_t nv = sim->nv;
    const size_t v3 = 3 * (size_t)nv * sizeof(double);
    memcpy(sim->xn, sim->x, v3);
    memcpy(sim->vn, sim->v, v3);
    memcpy(sim->an, sim->a, v3);
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
}

/* Newton solves in rounds of contact detection until the contact set stops changing
 * (thesis §3.3.1: contacts found at the solution, solved again), at most contact_rounds;
 * *capped when the cap ended them. */
static sinew_result solve_in_contact_rounds(sw_fullsim *sim, sw_fullsim_stats *st, int *capped) {
    sinew_result result = SINEW_ERROR_NOT_CONVERGED;
    double gref = -1;
    clear_contacts(sim);
    const int rounds = sim->p.self_contact || sim->world.world;
    *capped = 0;
    sim->world.ncand = 0;
    for (int round = 0;; ++round) {
        int32_t changed = sim->p.self_contact ? contact_round(sim) : 0;
        if (sim->world.world) { /* world candidates at the current positions */
            int32_t fresh = sw_ref_world_detect(&sim->world, sim->nv, sim->x, sim->vert_area);
            if (fresh < 0) return SINEW_ERROR_OUT_OF_MEMORY;
            changed += fresh;
        }
        if (round > 0 && changed == 0) break; /* complete */
        st->contact_rounds += rounds;
        result = newton_solve(sim, st, &gref, sim->p.newton_rtol);
        if (result == SINEW_ERROR_NOT_FINITE || !rounds) break;
        if (round + 1 >= sim->p.contact_rounds) {
            *capped = 1;
            break;
        }
    }
    return result;
}

/* The world's side of the measurement: its deepest penetration, candidates and contacts
 * pressing; capped with vertices inside colliders that are no candidates: unsettled. */
static void measure_world(const sw_fullsim *sim, int capped, sw_fullsim_stats *st) {
    int32_t fresh;
    st->world_penetration = sw_world_max_penetration(sim->world.world, sim->nv, sim->x,
                                                     sim->vert_area, sim->world.is_cand, &fresh);
    st->world_candidates = sim->world.ncand;
    for (int32_t i = 0; i < sim->world.ncand; ++i) {
        const sw_ref_world_cand *wc = &sim->world.cand[i];
        double d[3];
        for (int k = 0; k < 3; ++k)
            d[k] = wc->law.a[k] - sim->x[3 * wc->v + k];
        st->world_contacts += sw_penalty_gap(wc->law.n, d) > 0;
    }
    if (capped && fresh > 0) st->contacts_unsettled = 1;
}

/* Measurement at the final positions: self-penetration, the world's and the ground's,
 * the elastic and kinetic energies. */
static void measure(sw_fullsim *sim, int capped, sw_fullsim_stats *st) {
    const int32_t nv = sim->nv;
    int32_t found;
    sw_selfcontact_detect(sim->sc, sim->x, sim->pool);
    st->max_penetration = sw_selfcontact_max_depth(sim->sc);
    const sw_contact *pen = sw_selfcontact_list(sim->sc, &found);
    st->contacts = found;
    if (sim->p.self_contact && capped) /* would one more round have changed the set? */
        st->contacts_unsettled = set_would_change(sim, pen, found);
    if (sim->world.world) measure_world(sim, capped, st);
    if (sim->p.ground)
        for (int32_t v = 0; v < nv; ++v)
            if (sim->vert_area[v] > 0)
                st->ground_penetration =
                    fmax(st->ground_penetration, sim->p.ground_height - sim->x[3 * v + 1]);
    st->energy_elastic = sw_fullsim_evaluate(sim, sim->x, EVAL_ENERGY);
    if (sw_fullsim_dynamic(sim))
        for (int32_t v = 0; v < nv; ++v)
            st->energy_kinetic +=
                0.5 * sim->mass[v] *
                (sim->v[3 * v] * sim->v[3 * v] + sim->v[3 * v + 1] * sim->v[3 * v + 1] +
                 sim->v[3 * v + 2] * sim->v[3 * v + 2]);
}

sinew_result sw_fullsim_step(sw_fullsim *sim, const double *T, sw_fullsim_stats *stats) {
    sw_fullsim_stats st;
    memset(&st, 0, sizeof st);
    double t0 = sw_now_seconds();
    int fac0 = sim->chol ? sw_sparse_chol_get_stats(sim->chol).factorizations : 0;
    const int64_t m = 3 * (int64_t)sim->nv;
    if (!T || !sw_fullsim_all_finite(T, 12 * (int64_t)sim->c->skel.nbones)) {
        if (stats) *stats = st;
        return SINEW_ERROR_NOT_FINITE;
    }
    warm_start(sim, T);
    int capped;
    sinew_result result = solve_in_contact_rounds(sim, &st, &capped);
    if (result == SINEW_ERROR_NOT_FINITE || !sw_fullsim_all_finite(sim->x, m)) {
        restore(sim);
        result = SINEW_ERROR_NOT_FINITE;
    } else {
        if (sw_fullsim_dynamic(sim)) update_dynamics(sim);
        memcpy(sim->skin_prev, sim->skin_now, (size_t)m * sizeof(double));
    }
    st.converged = result == SINEW_OK;
    measure(sim, capped, &st);
    st.solver = sim->chol ? SW_SOLVER_CHOLMOD : SW_SOLVER_PCG;
    if (sim->chol) st.factorizations = sw_sparse_chol_get_stats(sim->chol).factorizations - fac0;
    st.seconds = sw_now_seconds() - t0;
    if (stats) *stats = st;
    return result;
}
