/* The derivatives of the step's whole potential against central differences:
 * the potential a dynamic step minimises (runtime/solver/potential.c) with every term
 * engaged at once, evaluated through the step's own preparation and coefficients
 * (sw_instance_step_prepare / sw_instance_step_potential, instance.h):
 *   cubature material energy, interface springs, pose-space self-contact pairs (a folded
 *   pose), a world collider the finger is pressed into (a table), and the backward-Euler
 *   terms cm/2 |q - q_n - h qdot_n|_M^2 + cd/2 |q - q_n|_(alpha M + beta H(q_s))^2 - q.f_in
 *   with a real velocity and real inertial forces (the finger stepped along its clip).
 * The inertial forces f_in are explicit (evaluated at q_n, qdot_n and the bones' motion)
 * and H(q_s) (at the step's predicted start; the reference Hessian there for a rest-first
 * instance) is frozen for the step, so neither depends on q: they enter Phi as a linear
 * and a quadratic term whose derivatives the differences check like any other. Both
 * kinds of instance are checked.
 *
 * At random q around the step's start state (and around a deeper fold):
 *   gradient  g_i against (Phi(q + h e_i) - Phi(q - h e_i)) / 2h,
 *   Hessian   the exact Hessian's column j against (g(q + h e_j) - g(q - h e_j)) / 2h,
 *   Newton    the step's matrix (material part projected to PSD) is symmetric, and it
 *             differs from the exact Hessian by a PSD matrix (the projection only clamps
 *             negative element eigenvalues).
 * h = 1e-6 |q|_inf (3e-7 .. 9e-7 here). Central differences err by h^2/6 |Phi'''|
 * (truncation) plus about eps |Phi| / h (rounding): with |Phi| ~ 1e3 and |g|_inf ~ 1e2
 * that is ~2e-9 of |g|_inf for the gradient, ~1e-11 of |H|_inf (~2e4) for the Hessian.
 * Measured (Release, the 8 states checked here): worst gradient error 1.1e-8 of |g|_inf,
 * Hessian 1.5e-10 of |H|_inf, Hp - He >= -4.3e-17 |H| (20 states on frames 2-11: 1.6e-8,
 * 2.7e-10, -4.7e-17); bounds 1e-7, 1e-8 and -1e-12
 * (the rounding estimate with a margin, far below a wrong term: measured, f_in scaled by
 * 0.99 in the gradient gives a gradient error of 1.6e-3, beta H(q_s) scaled by 0.9 in
 * the Hessian a Hessian error of 2.9e-3). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bake_fixture.h"
#include "instance.h"
#include "instance_internal.h"
#include "pose_contact.h"
#include "sw_test.h"
#include "world_contact.h"
#include "world_fixture.h"

static double urand(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * 0x1.0p-53;
}

static double inf_norm(const double *x, int64_t n) {
    double m = 0;
    for (int64_t i = 0; i < n; ++i)
        m = fmax(m, fabs(x[i]));
    return m;
}

/* The step's first Newton evaluation, at its predicted start q_s from the material part
 * the damping Hessian's pass left (no cubature pass of its own), against a fresh
 * evaluation of the prepared step's potential at q_s: the same value, gradient and (when
 * the part's Hessian is the current one, not the rest-first reference) Newton matrix (to
 * the rounding of a second SVD warm-started at the same point: measured 0 for Phi, up to
 * 8.4e-16 of |g|_inf and 9.3e-17 of |H|_inf; bounds 1e-12), and only once. */
static void check_start(sinew_instance *inst, float dt, int *reused) {
    int32_t R = inst->red.R;
    double *g = malloc(sizeof(double) * R), *H = malloc(sizeof(double) * R * R),
           *g1 = malloc(sizeof(double) * R), *H1 = malloc(sizeof(double) * R * R),
           *qs = malloc(sizeof(double) * R);
    memcpy(qs, inst->solver.q, sizeof(double) * R);
    /* pose-space pairs that came apart at q_s were dropped after the part was evaluated
       (phase_self): then the part is stale and the start must make its own pass */
    int pass = -1, current = inst->solver.mat_hess == 1, valid = inst->solver.mat_at_start;
    double e = sw_instance_step_start_potential(inst, dt, g, H, &pass);
    ENSUREF(pass == !valid, "the start made %d cubature passes, its part %s", pass,
            valid ? "valid" : "stale");
    *reused += valid;
    double e1 = sw_instance_step_potential(inst, dt, qs, g1, H1, 0), gd = 0, hd = 0;
    for (int32_t i = 0; i < R; ++i)
        gd = fmax(gd, fabs(g[i] - g1[i]));
    for (int64_t i = 0; i < (int64_t)R * R && current; ++i)
        hd = fmax(hd, fabs(H[i] - H1[i]));
    fprintf(stderr,
            "  start from the damping pass (%s Hessian): |dPhi| %.2e, |dg| %.2e, |dH| %.2e\n",
            current ? "current" : "reference", fabs(e - e1) / fabs(e1), gd / inf_norm(g1, R),
            hd / inf_norm(H1, (int64_t)R * R));
    ENSUREF(fabs(e - e1) <= 1e-12 * fabs(e1), "Phi %.17g against %.17g", e, e1);
    ENSUREF(gd <= 1e-12 * inf_norm(g1, R), "gradient differs by %.3g", gd);
    ENSUREF(hd <= 1e-12 * inf_norm(H1, (int64_t)R * R), "Newton matrix differs by %.3g", hd);
    sw_instance_step_start_potential(inst, dt, g, H, &pass);
    ENSUREF(pass == 1, "the part was used twice");
    free(g), free(H), free(g1), free(H1), free(qs);
}

/* Checks the prepared step's potential at q (R coordinates); prints and returns the
 * worst relative errors through gerr and herr. */
static void check_at(sinew_instance *inst, float dt, double *q, double *gerr, double *herr,
                     double *psd_min) {
    int32_t R = inst->red.R;
    double *g = malloc(sizeof(double) * R), *He = malloc(sizeof(double) * R * R),
           *Hp = malloc(sizeof(double) * R * R), *gp = malloc(sizeof(double) * R),
           *gm = malloc(sizeof(double) * R);
    sw_instance_step_potential(inst, dt, q, g, He, 1);
    sw_instance_step_potential(inst, dt, q, NULL, Hp, 0);
    double gmax = inf_norm(g, R), hmax = inf_norm(He, (int64_t)R * R);
    const double h = 1e-6 * inf_norm(q, R);
    *gerr = *herr = 0;
    for (int32_t j = 0; j < R; ++j) {
        double qj = q[j];
        q[j] = qj + h;
        double ep = sw_instance_step_potential(inst, dt, q, gp, NULL, 0);
        q[j] = qj - h;
        double em = sw_instance_step_potential(inst, dt, q, gm, NULL, 0);
        q[j] = qj;
        *gerr = fmax(*gerr, fabs((ep - em) / (2 * h) - g[j]) / gmax);
        for (int32_t i = 0; i < R; ++i)
            *herr = fmax(*herr, fabs((gp[i] - gm[i]) / (2 * h) - He[(int64_t)i * R + j]) / hmax);
    }
    /* the Newton matrix: symmetric, and Hp - He PSD (min of v^T (Hp - He) v / v^T He v
     * over random v, relative to |H|) */
    *psd_min = INFINITY;
    for (int32_t i = 0; i < R; ++i)
        for (int32_t j = 0; j < i; ++j)
            *psd_min =
                fmin(*psd_min, -fabs(Hp[(int64_t)i * R + j] - Hp[(int64_t)j * R + i]) / hmax);
    uint64_t seed = 99;
    for (int k = 0; k < 32; ++k) {
        double vDv = 0, vv = 0;
        for (int32_t i = 0; i < R; ++i)
            gp[i] = urand(&seed) - 0.5, vv += gp[i] * gp[i];
        for (int32_t i = 0; i < R; ++i)
            for (int32_t j = 0; j < R; ++j)
                vDv += gp[i] * (Hp[(int64_t)i * R + j] - He[(int64_t)i * R + j]) * gp[j];
        *psd_min = fmin(*psd_min, vDv / (vv * hmax));
    }
    fprintf(stderr,
            "    |g|_inf %.3g |H|_inf %.3g, h %.2g: gradient error %.2e, Hessian error %.2e, "
            "Newton matrix min(v^T (Hp - He) v / |v|^2 |H|) %.2e\n",
            gmax, hmax, h, *gerr, *herr, *psd_min);
    free(g), free(He), free(Hp), free(gp), free(gm);
}

static void check_dynamic_potential(sinew_newton_hessian kind) {
    const bake_fixture *f = fixture(); /* finger, 2,000 tets (world_fixture.h) */
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    ENSUREF(v->ncontacts > 0, "the fixture's fold has no contact pairs: the test would prove less");
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.5f, &id); /* pressed 0.08 into a table */
    ENSURE(w);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    d.newton_hessian = kind;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_world(inst, w) == SINEW_OK);
    int32_t R = inst->red.R, nb = f->ch.skel.nbones;
    const float dt = 1.0f / 30;
    float *pose = malloc(sizeof(float) * 12 * nb);
    double *q = malloc(sizeof(double) * R);
    uint64_t seed = 7;
    int checked = 0, with_pairs = 0, reused = 0;
    double gworst = 0, hworst = 0, psd_worst = INFINITY;
    /* along the clip into its fold (frames 6 and 7: pose-space pairs; 6 in contact) and
       out (11: the most world candidates); the table under it all the way */
    for (int frame = 0; frame < 12; ++frame) {
        bake_fixture_pose(f, frame, pose);
        ENSURE(sinew_instance_set_pose(inst, pose, (uint32_t)nb) == SINEW_OK);
        if (frame == 3 || frame == 6 || frame == 7 || frame == 11) {
            sw_instance_step_prepare(inst, dt);
            const sw_solver *s = &inst->solver;
            ENSURE(inst->pose.history == 2);
            ENSUREF(inf_norm(s->qdot, R) > 0 && inf_norm(s->fin, R) > 0,
                    "frame %d: no velocity or no inertial forces to check", frame);
            check_start(inst, dt, &reused);
            for (int rep = 0; rep < 2; ++rep) {
                /* rep 0: near the start state; rep 1: 5% deeper into the correction */
                for (int32_t i = 0; i < R; ++i)
                    q[i] = s->qn[i] * (1 + 0.05 * rep + 0.02 * (urand(&seed) - 0.5)) +
                           1e-3 * inf_norm(s->qn, R) * (urand(&seed) - 0.5);
                double e_pair = sw_pose_contact_eval(&inst->red, &inst->ps, q, 0, 0);
                double e_world = sw_world_contact_eval(&inst->red, &inst->wc, q, 0, 0);
                fprintf(stderr,
                        "  frame %d q %d: %d pose-space pairs (energy %.3g), %d world candidates "
                        "(energy %.3g)\n",
                        frame, rep, inst->ps.npairs, e_pair, inst->wc.ncand, e_world);
                ENSUREF(e_world > 0, "frame %d: the table does not touch the finger", frame);
                with_pairs += e_pair > 0;
                double ge, he, pm;
                check_at(inst, dt, q, &ge, &he, &pm);
                gworst = fmax(gworst, ge);
                hworst = fmax(hworst, he);
                psd_worst = fmin(psd_worst, pm);
                checked++;
            }
            /* the prepared step left the instance mid-step: replay this pose as a step */
            ENSURE(sinew_instance_set_pose(inst, pose, (uint32_t)nb) == SINEW_OK);
        }
        ENSURE(sinew_instance_step(inst, dt) == SINEW_OK);
    }
    fprintf(stderr,
            "  %d states (%d with pose-space pairs in contact): worst gradient error %.2e, "
            "Hessian %.2e, Newton matrix %.2e\n",
            checked, with_pairs, gworst, hworst, psd_worst);
    ENSUREF(with_pairs >= 2, "only %d states with pose-space pairs in contact", with_pairs);
    ENSUREF(reused >= 3, "the damping pass's part started only %d of 4 steps", reused);
    ENSUREF(gworst <= 1e-7, "gradient error %.3g of |g|_inf", gworst);
    ENSUREF(hworst <= 1e-8, "Hessian error %.3g of |H|_inf", hworst);
    ENSUREF(psd_worst >= -1e-12, "the Newton matrix is below the exact Hessian: %.3g", psd_worst);
    free(pose), free(q);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(dynamic_step_potential_matches_finite_differences) {
    check_dynamic_potential(SINEW_NEWTON_HESSIAN_CURRENT);
}

TEST(rest_first_dynamic_step_potential_matches_finite_differences) {
    check_dynamic_potential(SINEW_NEWTON_HESSIAN_REST_FIRST);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(dynamic_step_potential_matches_finite_differences),
             CASE(rest_first_dynamic_step_potential_matches_finite_differences),
             CASE(release_fixture))
