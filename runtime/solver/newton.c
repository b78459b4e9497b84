/* Newton on the step's potential (thesis §4.4; DESIGN.md §4.3) with a block-sparse
 * Cholesky of the reduced Hessian, whose blocks are the domains', eliminated in a
 * minimum-degree order of the spring couplings (plus the fill and the contact pairs of
 * the step), chord updates on an earlier factor once the iterate converges fast, and an
 * energy guard: a trial point whose energy grows is halved, up to five times, and the
 * best iterate is kept. A step may start with updates on a reference Hessian
 * (rest_first_updates: the rest one, then the last one evaluated) before the current
 * Hessian's. */
#include <math.h>
#include <string.h>

#include "cubature.h"
#include "dense.h"
#include "solver.h"

void sw_solver_order_blocks(sw_solver *s, const sw_blob_view *v) {
    for (int32_t k = 0; k < v->ndomains; ++k) {
        s->blk_off[k] = v->domains[k].q_offset;
        s->blk_size[k] = v->domains[k].rank;
    }
    /* the block graph of the interface springs (with the fill it creates); springs follow
     * the skeleton, but vertices shared by three or more domains couple siblings too */
    const int32_t nd = v->ndomains;
    s->mass_blockdiag = 1;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < nd; ++b) {
            s->blk_adj[a * nd + b] = a != b && sw_blob_block_nonzero(v, SW_BLOB_SPRINGS, a, b);
            /* the bake's mass is U^T M U per domain; a blob whose is not gets its products
             * over the blocks where it is not zero */
            s->mass_adj[a * nd + b] = a != b && sw_blob_block_nonzero(v, SW_BLOB_MASS, a, b);
            s->mass_blockdiag &= !s->mass_adj[a * nd + b];
        }
    sw_block_order_min_degree(nd, s->blk_adj, s->blk_nz, s->blk_order);
    for (int32_t e = 0; e < nd; ++e)
        s->blk_pos[s->blk_order[e]] = e;
}

void sw_solver_take(sw_mem_plan *p, const sw_blob_view *v, int dynamic, sw_solver *s) {
    const uint64_t R = (uint64_t)v->rank_total, nd = (uint64_t)v->ndomains;
#define TAKE(ptr, count) SW_PLAN_TAKE(p, ptr, count)
    TAKE(s->q, R);
    TAKE(s->qn, R);
    TAKE(s->qdot, R);
    TAKE(s->fin, R);
    TAKE(s->g_mat, R);
    TAKE(s->q_mat, dynamic ? R : 0);
    TAKE(s->dq, R);
    TAKE(s->qtrial, R);
    TAKE(s->q_pred, R);
    TAKE(s->tmp, R);
    TAKE(s->tmp2, R);
    TAKE(s->blk_off, nd);
    TAKE(s->blk_size, nd);
    TAKE(s->blk_order, nd);
    TAKE(s->blk_pos, nd);
    TAKE(s->blk_nz, nd * nd);
    TAKE(s->blk_adj, nd * nd);
    TAKE(s->mass_adj, nd * nd);
    TAKE(s->hold, nd);
#undef TAKE
}

/* The blocks a contact pair's four copies (cv: (domain, local) each) couple. */
static void couple_pair(sw_solver *s, int32_t nd, const int32_t *cv) {
    for (int m = 0; m < 4; ++m)
        for (int k = 0; k < 4; ++k) {
            int32_t a = s->blk_pos[cv[2 * m]], b = s->blk_pos[cv[2 * k]];
            if (a > b) s->blk_nz[a * nd + b] = 1;
        }
}

void sw_solver_block_pattern(sw_solver *s, const sw_blob_view *v, const sw_step_contacts *ct) {
    int32_t nd = v->ndomains;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < a; ++b)
            s->blk_nz[a * nd + b] = s->blk_adj[s->blk_order[a] * nd + s->blk_order[b]];
    for (int32_t p = 0; p < ct->ps->npairs; ++p)
        couple_pair(s, nd, v->contact_verts + 8 * (int64_t)ct->ps->pairs[p]);
    if (ct->sc)
        for (int32_t p = 0; p < ct->sc->npairs; ++p)
            couple_pair(s, nd, ct->sc->verts + 8 * (int64_t)p);
}

int sw_solver_factor(sw_reduced *red, sw_solver *s) {
    int32_t R = red->R, nd = red->v->ndomains;
    double tr = 0;
    for (int32_t i = 0; i < R; ++i)
        tr += fabs(red->H[(int64_t)i * R + i]);
    double shift = 0;
    for (int attempt = 0; attempt < 8; ++attempt) {
        if (sw_block_cholesky(red->H, R, nd, s->blk_off, s->blk_size, s->blk_order, s->blk_nz, s->L,
                              s->pack))
            return 1;
        double next = shift == 0 ? 1e-10 * tr / R + 1e-300 : shift * 100;
        for (int32_t i = 0; i < R; ++i)
            red->H[(int64_t)i * R + i] += next - shift; /* H is rebuilt next pass */
        shift = next;
    }
    return 0;
}

void sw_solver_factor_solve(const sw_reduced *red, const sw_solver *s, double *x) {
    sw_block_cholesky_solve(s->L, red->R, red->v->ndomains, s->blk_off, s->blk_size, s->blk_order,
                            s->blk_nz, x);
}

/* dq = -L^-T L^-1 g with the factor in s->L. */
static void factored_direction(const sw_reduced *red, sw_solver *s) {
    for (int32_t i = 0; i < red->R; ++i)
        s->dq[i] = -red->g[i];
    sw_solver_factor_solve(red, s, s->dq);
}

double sw_solver_factor_madds(sw_solver *s, const sw_blob_view *v) {
    int32_t nd = v->ndomains;
    sw_pose_space none;
    memset(&none, 0, sizeof none);
    sw_step_contacts ct = {&none, NULL, NULL, NULL};
    sw_solver_block_pattern(s, v, &ct);
    unsigned char *nz = s->blk_nz;
    double n = 0;
    for (int32_t e = 0; e < nd; ++e) { /* eliminate position e, symbolically */
        double re = s->blk_size[s->blk_order[e]];
        n += re * re * re / 6;
        for (int32_t i = e + 1; i < nd; ++i) {
            if (!nz[i * nd + e]) continue;
            double ri = s->blk_size[s->blk_order[i]];
            n += ri * re * re / 2 + ri * ri * re / 2; /* its solve and its own update */
            for (int32_t j = e + 1; j < i; ++j)
                if (nz[j * nd + e]) {
                    n += ri * s->blk_size[s->blk_order[j]] * re;
                    nz[i * nd + j] = 1; /* fill */
                }
        }
    }
    return n;
}

/* Phi at q with its gradient, and its Hessian with want_hess; counted. */
static double evaluate(sw_reduced *red, const sw_step_contacts *ct, const sw_solver *s,
                       const double *q, const sw_dyn_coef *dc, int want_hess,
                       sinew_step_stats *st) {
    st->potential_evals++;
    double phi = sw_potential(red, ct, s, q, dc, 1, want_hess);
    if (s->hold_inertia) sw_solver_hold_rows(s, red, want_hess);
    return phi;
}

/* Phi, g and H (of kind want_hess) at the step's start, counted when it makes a cubature
 * pass. */
static double evaluate_start(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                             const sw_dyn_coef *dc, int want_hess, sinew_step_stats *st) {
    int pass = 0;
    if (s->hold_inertia) sw_solver_hold_start(s, red->v);
    double phi = sw_potential_start(red, ct, s, dc, want_hess, &pass);
    if (s->hold_inertia) sw_solver_hold_rows(s, red, want_hess);
    st->potential_evals += (uint32_t)pass;
    return phi;
}

/* Chord updates (on the factor of an earlier iterate's Hessian) follow a Newton update
 * that shrank the gradient to SW_CHORD_ENTER of its value or less, and go on while each
 * shrinks it to SW_CHORD_KEEP or less; a slower one is followed by a fresh factorisation.
 * Near the stationary point Newton converges quadratically and the Hessian changes
 * little, so a chord update costs a solve where Newton costs a Hessian pass and a
 * factorisation. A looser entry saves more but takes a slower path through the several
 * minima of a buckled fold (§3.2.3). Figures: docs/notes/runtime-constants.md. */
#define SW_CHORD_ENTER 0.1
#define SW_CHORD_KEEP 0.5
/* A Newton update of at most this share of |q| is near the stationary point: its end
 * point is evaluated without H, and when the gradient there is too large for chord
 * updates, the factor at hand first tells whether the update from there is the last one
 * (SW_NEWTON_LAST_UPDATE), taken then without a new Hessian. Newton's next update is
 * quadratically smaller, so the Hessian pass and factorisation that would only confirm
 * the last update are saved. A larger share saves more factorisations but lets a step
 * settle in another of a buckled fold's minima. Figures: docs/notes/runtime-constants.md. */
#define SW_NEWTON_NEAR 0.2

/* Rest-first updates (SINEW_NEWTON_HESSIAN_REST_FIRST) go on while each shrinks the
 * gradient to this share of its value or less; a slower one hands the step to the current
 * Hessian. Much looser, a step spends its whole update cap on slow reference updates and
 * ends at the cap instead of at its last-update test. */
#define SW_REST_KEEP 0.3
/* A reference update's error is not quadratic in its length, as a Newton update's is: the
 * step's first must be shorter to be its last (at SW_NEWTON_LAST_UPDATE itself a step can
 * end farther from its stationary point than test_reduced_model's bound). After an update
 * that shrank the gradient to SW_REST_KEEP or less, the factor at hand models the
 * potential as well as Newton's last ones do, and Newton's SW_NEWTON_LAST_UPDATE holds. */
#define SW_REST_LAST_UPDATE (0.5 * SW_NEWTON_LAST_UPDATE)

/* After a fast reference update the factor at hand is the last iterate's, whose matrix
 * differs from the new one only in the contact pairs' Hessian (the reference and the
 * springs do not change within the updates): it first tells whether the update from
 * here is the last (SW_NEWTON_LAST_UPDATE), taken then without a new factorisation; if
 * not, the iterate's own factor gives the update as before, so no pass is added. (Taking
 * the chord update and evaluating its end point instead takes more passes.) */

/* An update s->dq shorter than `share` of |q| (or than dq_tiny) is the step's last: taken
 * without evaluating its end point, counted, the step CONVERGED; returns 1 then. */
static int took_last_update(sw_solver *s, int32_t R, double share, sinew_step_stats *st) {
    double dqn = sqrt(sw_dot(s->dq, s->dq, R));
    if (!(dqn <= share * sqrt(sw_dot(s->q, s->q, R)) || dqn <= s->dq_tiny)) return 0; /* NaN too */
    for (int32_t i = 0; i < R; ++i)
        s->q[i] += s->dq[i];
    st->newton_iterations++;
    st->status |= SINEW_STEP_CONVERGED;
    return 1;
}

/* A non-finite potential: the state back to q_n, the step FAILED. */
static sinew_result step_failed(sw_solver *s, int32_t R, sinew_step_stats *st) {
    memcpy(s->q, s->qn, (size_t)R * sizeof(double));
    st->status |= SINEW_STEP_FAILED;
    return SINEW_ERROR_NOT_FINITE;
}

/* What rest_first_updates left: the step done, or its iteration to go on from s->q. */
enum rest_outcome { REST_DONE, REST_HAND_OVER, REST_NOT_FINITE };

/* Newton updates on the reference Hessian (SW_CUB_HESSIAN_REF: the cubature's
 * Hessian kept in red->h_ref, with the contact pairs' and springs' Hessians at the
 * iterate), each factored at its iterate, each trial a gradient pass accepted when the
 * energy does not rise. The minimum is the same as the current Hessian's; only the path
 * changes. After a reset the reference is the rest Hessian: a tet that turns with its
 * bones without deforming has that very Hessian (cubature.h), so where the flesh follows
 * the skeleton an update costs a gradient pass and a factorisation instead of a Hessian
 * pass and a factorisation, several times cheaper on the Fox. Where it
 * does not (stretched elements stiffen in their rotation modes), the first rejected
 * update or one that shrinks the gradient by less than SW_REST_KEEP hands the step to the
 * current Hessian's iteration at the best iterate, whose Hessian passes then become the
 * reference of the next steps: the pose of the last hand-over is nearer than the rest
 * pose. The reference is factored at each iterate, not once a step: a factor kept for the
 * whole step misses the contact pairs that start to touch during it. On entry phi,
 * red->g and red->H are the start point's; *gn is |g| there, g0 the step's first. */
static enum rest_outcome rest_first_updates(sw_reduced *red, const sw_step_contacts *ct,
                                            sw_solver *s, const sw_dyn_coef *dc,
                                            sinew_step_stats *st, double *phi, double *gn,
                                            double g0, uint32_t *it) {
    int32_t R = red->R;
    double last = SW_REST_LAST_UPDATE; /* SW_NEWTON_LAST_UPDATE after a fast update */
    int probe = 0; /* the factor at hand is the last iterate's, after a fast update */
    for (;; ++*it) {
        if (!isfinite(*phi) || !isfinite(*gn)) return REST_NOT_FINITE;
        if (*gn <= 1e-5 * g0 || *gn == 0) { /* as sw_newton_solve's own test */
            st->status |= SINEW_STEP_CONVERGED;
            return REST_DONE;
        }
        if (*it == s->max_newton) return REST_DONE;
        if (probe) { /* the factor at hand may show that this update is the last */
            probe = 0;
            factored_direction(red, s);
            if (took_last_update(s, R, last, st)) {
                st->rest_updates++;
                return REST_DONE;
            }
        }
        if (!sw_solver_factor(red, s)) return REST_HAND_OVER;
        st->factorizations++;
        factored_direction(red, s);
        if (took_last_update(s, R, last, st)) {
            st->rest_updates++;
            return REST_DONE;
        }
        memcpy(s->qtrial, s->q, (size_t)R * sizeof(double));
        double phi0 = *phi;
        for (int32_t i = 0; i < R; ++i)
            s->q[i] += s->dq[i];
        *phi = evaluate(red, ct, s, s->q, dc, SW_CUB_HESSIAN_REF, st);
        if (!(isfinite(*phi) && *phi <= phi0 + 1e-12 * fabs(phi0))) {
            memcpy(s->q, s->qtrial, (size_t)R * sizeof(double));
            *phi = phi0;
            return REST_HAND_OVER;
        }
        double gnew = sqrt(sw_dot(red->g, red->g, R));
        st->newton_iterations++;
        st->rest_updates++;
        int slow = gnew > SW_REST_KEEP * *gn;
        *gn = gnew;
        if (slow) {
            ++*it;
            return REST_HAND_OVER;
        }
        last = SW_NEWTON_LAST_UPDATE;
        probe = 1;
    }
}

/* The chord-Newton iteration's state between updates. */
typedef struct newton_iter {
    double phi, gn, g0; /* the energy and |g| at s->q; |g| at the step's start */
    int have_h;         /* red->H is the Hessian at s->q, not yet factored */
    int fresh;          /* s->L was factored at s->q */
    int trust;          /* trial points are evaluated without H (chord updates may follow) */
    int probe;          /* the next update, from the factor at hand, is taken only if the last */
} newton_iter;

/* The energy, gradient and Hessian at s->q, the Hessian to be factored next. */
static void evaluate_with_hessian(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                                  const sw_dyn_coef *dc, sinew_step_stats *st, newton_iter *n) {
    n->phi = evaluate(red, ct, s, s->q, dc, 1, st);
    n->have_h = 1;
    n->trust = 0;
}

/* The step's start: rest-first updates when the step has a reference Hessian (which may
 * end the step: returns 1, or fails it: *failed), else the Hessian at the start. */
static int newton_start(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                        const sw_dyn_coef *dc, sinew_step_stats *st, newton_iter *n, uint32_t *it0,
                        int *failed) {
    int32_t R = red->R;
    *n = (newton_iter){.have_h = 1, .trust = 1};
    *it0 = 0;
    *failed = 0;
    if (!(s->rest_first && red->h_ref)) {
        n->phi = evaluate_start(red, ct, s, dc, 1, st);
        n->gn = n->g0 = sqrt(sw_dot(red->g, red->g, R));
        return 0;
    }
    n->phi = evaluate_start(red, ct, s, dc, SW_CUB_HESSIAN_REF, st);
    n->gn = n->g0 = sqrt(sw_dot(red->g, red->g, R));
    enum rest_outcome o = rest_first_updates(red, ct, s, dc, st, &n->phi, &n->gn, n->g0, it0);
    if (o == REST_NOT_FINITE) *failed = 1;
    if (o != REST_HAND_OVER) return 1;
    n->phi = evaluate(red, ct, s, s->q, dc, 1, st); /* hand over: the Hessian at q */
    n->gn = sqrt(sw_dot(red->g, red->g, R));
    return 0;
}

/* The trial points q_k + step dq (q_k in s->qtrial), the step halved up to five times
 * while the factor is fresh (a stale direction is refactored rather than halved): 1 when
 * one's energy does not rise (n->phi is its), 0 with s->q somewhere on the way. */
static int line_search(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                       const sw_dyn_coef *dc, sinew_step_stats *st, newton_iter *n, int with_h,
                       double phi0) {
    double step = 1.0;
    for (int ls = 0; ls < 5; ++ls, step *= 0.5) {
        for (int32_t i = 0; i < red->R; ++i)
            s->q[i] = s->qtrial[i] + step * s->dq[i];
        n->phi = evaluate(red, ct, s, s->q, dc, with_h, st);
        if (isfinite(n->phi) && n->phi <= phi0 + 1e-12 * fabs(phi0)) return 1;
        if (!n->fresh) return 0; /* a stale direction: refactor rather than halve */
    }
    return 0;
}

/* After no trial point was accepted, s->q back at q_k (energy phi0, |g| gn0): 1 to go on
 * from a fresh evaluation, 0 when the step ends at q_k, GUARD. */
static int rejected_update(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                           const sw_dyn_coef *dc, sinew_step_stats *st, newton_iter *n, double phi0,
                           double gn0) {
    int32_t R = red->R;
    memcpy(s->q, s->qtrial, (size_t)R * sizeof(double));
    if (!n->fresh) { /* back to q_k, with its Hessian this time */
        evaluate_with_hessian(red, ct, s, dc, st, n);
        n->gn = gn0;
        return 1;
    }
    if (s->fallback_qn) {
        /* from a predicted start (step.c, dynamic_start) the path met a region where the
           potential curves far more than its Hessian says (a stiff contact engaging): a
           pose-space blend that switched training poses had moved the start off the
           motion's path. Newton starts again from q_n, the last state, as a step that
           starts there does. */
        s->fallback_qn = 0;
        memcpy(s->q, s->qn, (size_t)R * sizeof(double));
        if (s->hold_inertia) sw_solver_hold_start(s, red->v);
        n->phi = evaluate(red, ct, s, s->q, dc, 1, st);
        n->gn = n->g0 = sqrt(sw_dot(red->g, red->g, R));
        n->have_h = 1;
        n->trust = 1;
        return 1;
    }
    /* keep the best iterate (its energy and gradient norm are known) */
    n->phi = phi0;
    n->gn = gn0;
    st->status |= SINEW_STEP_GUARD;
    return 0;
}

/* After an accepted update (|g| was gn0 before it): what the next one is. A Newton
 * update's end point had its Hessian: Newton next, chord updates after it when it shrank
 * the gradient fast. A chord update that shrank it too slowly: the Hessian at the point
 * (or, near the stationary point, first the factor at hand's probe). */
static void after_update(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                         const sw_dyn_coef *dc, sinew_step_stats *st, newton_iter *n, int with_h,
                         double gn0) {
    n->gn = sqrt(sw_dot(red->g, red->g, red->R));
    st->newton_iterations++;
    if (with_h) {
        n->have_h = 1;
        n->trust = n->gn <= SW_CHORD_ENTER * gn0;
    } else if (n->gn > (n->fresh ? SW_CHORD_ENTER : SW_CHORD_KEEP) * gn0 && n->gn > 1e-5 * n->g0) {
        if (!n->trust) /* near: the factor at hand may show the next update is the last */
            n->probe = 1;
        else
            evaluate_with_hessian(red, ct, s, dc, st, n); /* the same phi and g, with H */
    }
    n->fresh = 0;
}

sinew_result sw_newton_solve(sw_reduced *red, const sw_step_contacts *ct, sw_solver *s,
                             const sw_dyn_coef *dc, sinew_step_stats *st) {
    int32_t R = red->R;
    /* Chord Newton: a trial point is first evaluated without the Hessian (a
     * gradient-only cubature pass skips the element modes and their products, and the
     * factorisation is skipped too). Once an update has shrunk the gradient fast (the
     * iterate is where Newton converges quadratically), the next updates reuse the
     * factor; otherwise H is evaluated at the accepted point and the iteration is plain
     * Newton (its trial points evaluated with H, as a rejected or slow chord update does)
     * until an update is near the stationary point (SW_NEWTON_NEAR). The stationary point
     * is the same: only the path to it changes, and it is still a function of the step's
     * start alone. */
    newton_iter n;
    uint32_t it0;
    int failed;
    s->hold_inertia = sw_solver_hold_decide(s, red->v, dc, ct);
    int done = newton_start(red, ct, s, dc, st, &n, &it0, &failed);
    if (failed) return step_failed(s, R, st);
    for (uint32_t it = it0; !done; ++it) {
        if (!isfinite(n.phi) || !isfinite(n.gn)) return step_failed(s, R, st);
        /* 1e-5 of the step's first gradient: the position error it leaves is far below
         * the subspace's own (measured: tighter costs iterations, not accuracy) */
        if (n.gn <= 1e-5 * n.g0 || n.gn == 0) {
            st->status |= SINEW_STEP_CONVERGED;
            break;
        }
        if (it == s->max_newton) break;
        if (n.have_h) {
            if (!sw_solver_factor(red, s)) break;
            st->factorizations++;
            n.have_h = 0;
            n.fresh = 1;
        }
        factored_direction(red, s);
        /* An update that moves the shape by less than 5% of its correction (the basis
         * columns are orthonormal, so |dq| is the displacement's norm) is the last one,
         * taken without evaluating its end point (a cubature pass). A Newton update's own
         * error is quadratic in its length, so the last one leaves far less than the 5% it
         * moves, and the subspace's own error is larger still (figures:
         * docs/notes/runtime-constants.md).
         * An update below dq_tiny (a billionth of the character's size: no vertex moves by
         * more, the basis columns being orthonormal; the float output cannot show it) is
         * convergence too: at rest the gradient is rounding noise that no line search can
         * lower, and |q| ~ 0 leaves the relative test nothing to compare with. Where
         * |q| > dq_tiny / SW_NEWTON_LAST_UPDATE it implies the relative test, so it changes nothing
         * else. */
        if (took_last_update(s, R, SW_NEWTON_LAST_UPDATE, st)) break;
        if (n.probe) { /* not the last: a Newton update from here, with its Hessian */
            n.probe = 0;
            evaluate_with_hessian(red, ct, s, dc, st, &n);
            continue;
        }
        /* the end point's Hessian is wanted unless chord updates may follow, or the update
         * is near the stationary point */
        double dqn = sqrt(sw_dot(s->dq, s->dq, R));
        int with_h = !n.trust && dqn > SW_NEWTON_NEAR * sqrt(sw_dot(s->q, s->q, R));
        memcpy(s->qtrial, s->q, (size_t)R * sizeof(double)); /* keep q_k */
        double phi0 = n.phi, gn0 = n.gn;
        if (line_search(red, ct, s, dc, st, &n, with_h, phi0))
            after_update(red, ct, s, dc, st, &n, with_h, gn0);
        else
            done = !rejected_update(red, ct, s, dc, st, &n, phi0, gn0);
    }
    st->residual = n.g0 > 0 ? n.gn / n.g0 : 0;
    st->energy = n.phi;
    return SINEW_OK;
}
