/* The full-space reference simulator: rigid invariance, Newton's quadratic
 * convergence, energy behaviour of the integrators, self-contact and ground
 * penetration, determinism across thread counts, and error paths. */
#include <stdint.h>

#include "fullsim.h"
#include "selfcontact.h"
#include "samples.h"
#include "sw_test.h"

static const double *frame_T(const sw_character *c, int f) {
    return c->clip.T + (size_t)f * 12 * c->clip.nbones;
}

static int all_finite(const double *a, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
        if (!isfinite(a[i])) return 0;
    return 1;
}

/* Every bone at one rigid transform: the solution is the rigidly moved rest shape. */
TEST(rigid_pose_gives_rigid_shape_and_zero_energy) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1500, 3, &c, &err) == SINEW_OK);
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&c, NULL, &sim, &err) == SINEW_OK);
    double th = 0.6, T[12] = {cos(th), -sin(th), 0, sin(th), cos(th), 0, 0, 0, 1, 0.3, -2.0, 5.0};
    double *Tb = malloc(sizeof(double) * 12 * c.skel.nbones);
    for (int b = 0; b < c.skel.nbones; ++b)
        memcpy(Tb + 12 * b, T, sizeof T);
    sw_fullsim_stats st;
    ENSURE(sw_fullsim_step(sim, Tb, &st) == SINEW_OK);
    const double *x = sw_fullsim_positions(sim);
    double err_max = 0;
    for (int v = 0; v < c.mesh.nverts; ++v) {
        double p[3];
        sw_transform_point(T, c.mesh.X + 3 * v, p);
        for (int i = 0; i < 3; ++i)
            err_max = fmax(err_max, fabs(p[i] - x[3 * v + i]));
    }
    ENSUREF(err_max < 1e-9, "max deviation from the rigid motion %g", err_max);
    ENSURE(st.energy_elastic < 1e-12 * c.youngs);
    ENSURE(st.contacts == 0 && st.max_penetration == 0);
    free(Tb);
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

/* Near a solution Newton's error squares each iteration (exact Hessian, tight PCG). */
TEST(newton_converges_quadratically) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1500, 9, &c, &err) == SINEW_OK);
    sw_fullsim_params p = sw_fullsim_params_default();
    p.self_contact = 0;
    p.hessian = SW_HESSIAN_EXACT;
    p.newton_rtol = 1e-13;
    p.pcg_rtol = 1e-13;
    p.pcg_max = 20000;
    p.max_newton = 30;
    p.threads = 1;
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_OK);
    sw_fullsim_stats st;
    sinew_result r = sw_fullsim_step(sim, frame_T(&c, 1), &st); /* a mild bend */
    ENSUREF(r == SINEW_OK || st.grad_norm < 1e-9 * st.grad_norm0, "result %d, |g| %g -> %g", r,
            st.grad_norm0, st.grad_norm);
    ENSURE(st.newton_iters >= 2);
    /* Relative gradients e_k; quadratic: log e_{k+1} ~ 2 log e_k once e_k is small. */
    int checked = 0;
    for (int k = 0; k + 1 <= st.newton_iters && k + 1 < 32; ++k) {
        double ek = st.grad_history[k] / st.grad_norm0,
               ek1 = st.grad_history[k + 1] / st.grad_norm0;
        fprintf(stderr, "    newton %d: |g|/|g0| = %.3e\n", k + 1, ek1);
        if (ek < 1e-2 && ek1 > 1e-12) {
            ENSUREF(log10(ek1) <= 1.6 * log10(ek), "e_k = %.3e -> e_k+1 = %.3e is not quadratic",
                    ek, ek1);
            checked++;
        }
    }
    ENSUREF(checked >= 1, "no iterate in the quadratic regime was observed");
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

/* Starts an undamped free oscillation from a breathing displacement of the flesh. */
static sw_fullsim *oscillating(sw_character *c, sw_integrator integ, double dt, sw_error *err) {
    if (sw_sample_make("cylinder", 1500, 2, c, err) != SINEW_OK) return NULL;
    sw_fullsim_params p = sw_fullsim_params_default();
    p.integrator = integ;
    p.dt = dt;
    p.rayleigh_alpha = p.rayleigh_beta = 0;
    p.self_contact = 0;
    p.newton_rtol = 1e-9;
    p.pcg_rtol = 1e-10;
    p.pcg_max = 5000;
    sw_fullsim *sim;
    if (sw_fullsim_create(c, &p, &sim, err) != SINEW_OK) return NULL;
    int32_t n = c->mesh.nverts;
    double *x = malloc(sizeof(double) * 3 * n);
    for (int32_t v = 0; v < n; ++v) {
        const double *X = c->mesh.X + 3 * v;
        double r = sqrt(X[1] * X[1] + X[2] * X[2]), s = c->bone_of_vertex[v] >= 0 ? 0.0 : 0.04 * r;
        x[3 * v] = X[0];
        x[3 * v + 1] = X[1] * (1 + s);
        x[3 * v + 2] = X[2] * (1 + s);
    }
    sw_fullsim_set_state(sim, NULL, x, NULL);
    free(x);
    return sim;
}

TEST(newmark_keeps_energy_of_undamped_oscillation) {
    sw_character c;
    sw_error err;
    sw_fullsim *sim = oscillating(&c, SW_NEWMARK, 2e-3, &err);
    ENSUREF(sim, "%s", err.msg);
    double *I = calloc((size_t)12 * c.skel.nbones, sizeof(double));
    for (int b = 0; b < c.skel.nbones; ++b)
        I[12 * b] = I[12 * b + 4] = I[12 * b + 8] = 1;
    double e0 = sw_fullsim_elastic_energy(sim), worst = 0, kin_max = 0;
    ENSURE(e0 > 0);
    for (int s = 0; s < 150; ++s) {
        sw_fullsim_stats st;
        sinew_result r = sw_fullsim_step(sim, I, &st);
        ENSUREF(r == SINEW_OK, "step %d: %s, |g| %.3g -> %.3g after %d Newton iterations", s,
                sinew_result_string(r), st.grad_norm0, st.grad_norm, st.newton_iters);
        double e = st.energy_elastic + st.energy_kinetic;
        worst = fmax(worst, fabs(e - e0) / e0);
        kin_max = fmax(kin_max, st.energy_kinetic / e0);
    }
    fprintf(stderr, "    Newmark: max |E - E0|/E0 = %.4f, peak kinetic share %.2f\n", worst,
            kin_max);
    ENSUREF(kin_max > 0.3, "the flesh barely moved (kinetic share %.3f)", kin_max);
    ENSUREF(worst < 0.03, "energy drifted by %.2f%%", 100 * worst);
    free(I);
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

TEST(backward_euler_never_gains_energy) {
    sw_character c;
    sw_error err;
    sw_fullsim *sim = oscillating(&c, SW_BACKWARD_EULER, 2e-3, &err);
    ENSUREF(sim, "%s", err.msg);
    double *I = calloc((size_t)12 * c.skel.nbones, sizeof(double));
    for (int b = 0; b < c.skel.nbones; ++b)
        I[12 * b] = I[12 * b + 4] = I[12 * b + 8] = 1;
    double prev = sw_fullsim_elastic_energy(sim), e0 = prev;
    for (int s = 0; s < 60; ++s) {
        sw_fullsim_stats st;
        ENSURE(sw_fullsim_step(sim, I, &st) == SINEW_OK);
        double e = st.energy_elastic + st.energy_kinetic;
        ENSUREF(e <= prev * (1 + 1e-6), "step %d gained energy: %.9g -> %.9g", s, prev, e);
        prev = e;
    }
    ENSURE(prev < e0);
    free(I);
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

/* Runs the finger's clip to its peak fold; returns the max penetration over frames. */
static int finger_unsettled; /* frames of the last finger_penetration run left unsettled */
static double finger_penetration(int self_contact, int threads, double **x_out, int *ok) {
    sw_character c;
    sw_error err;
    *ok = 0;
    if (sw_sample_make("finger", 3000, 5, &c, &err) != SINEW_OK) return -1;
    sw_fullsim_params p = sw_fullsim_params_default();
    p.self_contact = self_contact;
    p.threads = threads;
    sw_fullsim *sim;
    if (sw_fullsim_create(&c, &p, &sim, &err) != SINEW_OK) {
        sw_character_free(&c);
        return -1;
    }
    double worst = 0;
    int finite = 1;
    finger_unsettled = 0;
    for (int f = 0; f <= c.clip.nframes / 2; ++f) {
        sw_fullsim_stats st;
        sinew_result r = sw_fullsim_step(sim, frame_T(&c, f), &st);
        finite = finite && r != SINEW_ERROR_NOT_FINITE &&
                 all_finite(sw_fullsim_positions(sim), 3 * (int64_t)c.mesh.nverts);
        worst = fmax(worst, st.max_penetration);
        finger_unsettled += st.contacts_unsettled;
        fprintf(stderr, "    frame %d: newton %d, pcg %d, contacts %d, penetration %.4g\n", f,
                st.newton_iters, st.pcg_iters, st.contacts, st.max_penetration);
    }
    if (x_out) {
        *x_out = malloc(sizeof(double) * 3 * c.mesh.nverts);
        memcpy(*x_out, sw_fullsim_positions(sim), sizeof(double) * 3 * c.mesh.nverts);
    }
    *ok = finite;
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
    return worst;
}

TEST(self_contact_removes_most_penetration_of_folded_finger) {
    int ok_off, ok_on;
    double off = finger_penetration(0, 0, NULL, &ok_off);
    double on = finger_penetration(1, 0, NULL, &ok_on);
    ENSUREF(finger_unsettled == 0, "%d frames of the fold stopped at the round cap unsettled",
            finger_unsettled);
    fprintf(stderr, "    max penetration: without self-contact %.4g, with %.4g (ratio %.3f)\n", off,
            on, on / off);
    ENSURE(ok_off && ok_on);
    ENSUREF(off > 0.02, "the fold does not self-intersect (%.4g): the test would prove nothing",
            off);
    ENSUREF(on <= 0.1 * off, "penetration %.4g is more than 10%% of %.4g", on, off);
}

/* The contact set is an active set (fullsim.h): when a step's rounds complete, every
 * pair it converged with still collides or sits within the hysteresis band in front of
 * its surface point (half its detection depth), also while the fold opens again, so no
 * pair holds the flesh open-fold by pulling. */
TEST(contacts_push_and_never_pull) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 9, &c, &err) == SINEW_OK);
    sw_fullsim_params p = sw_fullsim_params_default();
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_OK);
    int with_contacts = 0;
    for (int f = 0; f < c.clip.nframes; ++f) {
        sw_fullsim_stats st;
        ENSURE(sw_fullsim_step(sim, frame_T(&c, f), &st) != SINEW_ERROR_NOT_FINITE);
        int32_t n;
        const sw_contact *k = sw_fullsim_contacts(sim, &n);
        with_contacts += n > 0;
        if (st.contacts_unsettled) continue; /* the round cap stopped it still changing */
        for (int32_t i = 0; i < n; ++i)      /* in front by at most the hysteresis band */
            ENSUREF(sw_contact_gap(&k[i], sw_fullsim_positions(sim)) > -0.5 * k[i].depth,
                    "frame %d: pair %d (vertex %d) is %.3g in front of its surface point (depth "
                    "%.3g)",
                    f, i, k[i].p, -sw_contact_gap(&k[i], sw_fullsim_positions(sim)), k[i].depth);
    }
    ENSUREF(with_contacts >= 2, "only %d frames with contacts: the test would prove little",
            with_contacts);
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

/* contacts_unsettled says whether one more contact round would have changed the
 * result: per frame of the fold, a simulator with a cap of C rounds and one with C + 1
 * start from the same state; where the first reports a settled set they end bitwise
 * equal, where it reports an unsettled one the second used its extra round. */
TEST(unsettled_contact_set_is_one_another_round_changes) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 9, &c, &err) == SINEW_OK);
    const int cap = 2;
    sw_fullsim *sim[2];
    for (int k = 0; k < 2; ++k) {
        sw_fullsim_params p = sw_fullsim_params_default();
        p.contact_rounds = cap + k;
        p.threads = 1;
        ENSURE(sw_fullsim_create(&c, &p, &sim[k], &err) == SINEW_OK);
    }
    size_t n3 = 3 * (size_t)c.mesh.nverts;
    double *x = malloc(n3 * sizeof(double));
    memcpy(x, c.mesh.X, n3 * sizeof(double));
    int seen[2] = {0, 0};
    for (int f = 1; f < c.clip.nframes; ++f) {
        sw_fullsim_stats st[2];
        for (int k = 0; k < 2; ++k) {
            sw_fullsim_set_state(sim[k], frame_T(&c, f - 1), x, NULL);
            ENSURE(sw_fullsim_step(sim[k], frame_T(&c, f), &st[k]) != SINEW_ERROR_NOT_FINITE);
        }
        const double *xa = sw_fullsim_positions(sim[0]), *xb = sw_fullsim_positions(sim[1]);
        ENSURE(!st[1].contacts_unsettled || st[1].contact_rounds == cap + 1);
        if (st[0].contact_rounds < cap) ENSURE(!st[0].contacts_unsettled); /* finished early */
        if (st[0].contact_rounds == cap) {
            seen[st[0].contacts_unsettled]++;
            if (st[0].contacts_unsettled)
                ENSUREF(st[1].contact_rounds == cap + 1,
                        "frame %d: unsettled, yet another round changed nothing", f);
            else
                ENSUREF(memcmp(xa, xb, n3 * sizeof(double)) == 0,
                        "frame %d: settled, yet another round moved the flesh", f);
        }
        memcpy(x, xa, n3 * sizeof(double));
    }
    fprintf(stderr, "    frames at the cap: %d settled, %d unsettled\n", seen[0], seen[1]);
    ENSUREF(seen[1] > 0, "no frame reached the cap unsettled: the test would prove little");
    free(x);
    for (int k = 0; k < 2; ++k)
        sw_fullsim_destroy(sim[k]);
    sw_character_free(&c);
}

/* The set check (fullsim_step.c): a round's Newton ends once its contact set would
 * change, so only the settled set is converged. Per frame of the fold, from the same
 * state, a simulator with the check and one without both end converged and settled,
 * and the check takes fewer Newton iterations over the contact frames. */
TEST(set_check_converges_only_the_settled_set) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 9, &c, &err) == SINEW_OK);
    sw_fullsim *sim[2];
    for (int k = 0; k < 2; ++k) {
        sw_fullsim_params p = sw_fullsim_params_default();
        p.contact_set_check = k == 0; /* sim[0] checks, sim[1] converges every round */
        ENSURE(sw_fullsim_create(&c, &p, &sim[k], &err) == SINEW_OK);
    }
    size_t n3 = 3 * (size_t)c.mesh.nverts;
    double *x = malloc(n3 * sizeof(double));
    memcpy(x, c.mesh.X, n3 * sizeof(double));
    int newton[2] = {0, 0}, rounds[2] = {0, 0}, contact_frames = 0;
    for (int f = 1; f < c.clip.nframes; ++f) {
        sw_fullsim_stats st[2];
        for (int k = 0; k < 2; ++k) {
            sw_fullsim_set_state(sim[k], frame_T(&c, f - 1), x, NULL);
            ENSURE(sw_fullsim_step(sim[k], frame_T(&c, f), &st[k]) == SINEW_OK);
            ENSUREF(st[k].converged && !st[k].contacts_unsettled,
                    "frame %d (%s): converged %d, unsettled %d", f, k ? "no check" : "check",
                    st[k].converged, st[k].contacts_unsettled);
        }
        if (st[1].contact_rounds > 1) { /* a frame whose set changed */
            contact_frames++;
            for (int k = 0; k < 2; ++k) {
                newton[k] += st[k].newton_iters;
                rounds[k] += st[k].contact_rounds;
            }
        }
        memcpy(x, sw_fullsim_positions(sim[1]), n3 * sizeof(double));
    }
    fprintf(stderr,
            "    %d frames with rounds: Newton iterations %d with the check (%d rounds), %d "
            "without (%d rounds)\n",
            contact_frames, newton[0], rounds[0], newton[1], rounds[1]);
    ENSUREF(contact_frames >= 2, "only %d frames with contact rounds: the test would prove little",
            contact_frames);
    ENSURE(newton[0] < newton[1]);
    free(x);
    for (int k = 0; k < 2; ++k)
        sw_fullsim_destroy(sim[k]);
    sw_character_free(&c);
}

TEST(ground_plane_pushes_flesh_out) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("capsule", 2000, 2, &c, &err) == SINEW_OK);
    sw_fullsim_params p = sw_fullsim_params_default();
    p.ground = 1;
    p.ground_height = -0.4; /* the capsule's underside reaches -0.5 at rest */
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_OK);
    sw_fullsim_stats st;
    sinew_result r = sw_fullsim_step(sim, frame_T(&c, 0), &st);
    ENSURE(r == SINEW_OK || r == SINEW_ERROR_NOT_CONVERGED);
    fprintf(stderr, "    ground penetration %.4g (0.1 before), %d Newton iterations\n",
            st.ground_penetration, st.newton_iters);
    ENSUREF(st.ground_penetration < 0.01, "still %.4g below the ground", st.ground_penetration);
    ENSURE(st.energy_elastic > 0); /* the flesh was squashed, not moved rigidly */
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

TEST(bad_input_is_rejected_and_state_kept) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1500, 3, &c, &err) == SINEW_OK);
    sw_fullsim *sim = NULL;
    sw_fullsim_params p = sw_fullsim_params_default();
    p.dt = 0;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_ERROR_INVALID_ARGUMENT && !sim);
    ENSURE(strstr(err.msg, "dt"));
    p = sw_fullsim_params_default();
    p.gravity[1] = NAN;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    p = sw_fullsim_params_default();
    p.contact_alpha = 2;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    /* no bone-driven vertex: singular */
    int32_t *keep = c.bone_of_vertex;
    c.bone_of_vertex = calloc((size_t)c.mesh.nverts, sizeof(int32_t));
    for (int v = 0; v < c.mesh.nverts; ++v)
        c.bone_of_vertex[v] = -1;
    ENSURE(sw_fullsim_create(&c, NULL, &sim, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "singular"));
    free(c.bone_of_vertex);
    c.bone_of_vertex = keep;
    /* a NaN pose: error, and the state stays the last good one */
    ENSURE(sw_fullsim_create(&c, NULL, &sim, &err) == SINEW_OK);
    sw_fullsim_stats st;
    ENSURE(sw_fullsim_step(sim, frame_T(&c, 1), &st) == SINEW_OK);
    size_t bytes = sizeof(double) * 3 * c.mesh.nverts;
    double *before = malloc(bytes);
    memcpy(before, sw_fullsim_positions(sim), bytes);
    double *T = malloc(sizeof(double) * 12 * c.skel.nbones);
    memcpy(T, frame_T(&c, 2), sizeof(double) * 12 * c.skel.nbones);
    T[3] = NAN;
    ENSURE(sw_fullsim_step(sim, T, &st) == SINEW_ERROR_NOT_FINITE);
    ENSURE(memcmp(before, sw_fullsim_positions(sim), bytes) == 0);
    T[3] = INFINITY;
    ENSURE(sw_fullsim_step(sim, T, &st) == SINEW_ERROR_NOT_FINITE);
    ENSURE(sw_fullsim_step(sim, frame_T(&c, 2), &st) == SINEW_OK); /* and it goes on */
    free(T);
    free(before);
    sw_fullsim_destroy(sim);
    sw_character_free(&c);
}

/* The direct solve (CHOLMOD) and PCG reach the same solution: the finger folded into
 * self-contact, each frame's positions within the Newton tolerance of each other, and
 * the direct path really factors (and never iterates PCG). */
TEST(direct_and_pcg_solves_agree) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 5, &c, &err) == SINEW_OK);
    sw_fullsim *sim[2];
    for (int k = 0; k < 2; ++k) {
        sw_fullsim_params p = sw_fullsim_params_default();
        p.solver = k ? SW_SOLVER_CHOLMOD : SW_SOLVER_PCG;
        p.newton_rtol = 1e-8; /* both converge far below the difference tested */
        p.max_newton = 60;
        ENSURE(sw_fullsim_create(&c, &p, &sim[k], &err) == SINEW_OK);
    }
    double scale = 0, worst = 0;
    for (int32_t i = 0; i < 3 * c.mesh.nverts; ++i)
        scale = fmax(scale, fabs(c.mesh.X[i]));
    int contacts = 0;
    for (int f = 0; f <= c.clip.nframes / 2; ++f) {
        sw_fullsim_stats st[2];
        for (int k = 0; k < 2; ++k)
            ENSURE(sw_fullsim_step(sim[k], frame_T(&c, f), &st[k]) != SINEW_ERROR_NOT_FINITE);
        ENSURE(st[0].solver == SW_SOLVER_PCG && st[1].solver == SW_SOLVER_CHOLMOD);
        ENSURE(st[1].pcg_iters == 0 && (f == 0 || st[1].factorizations > 0));
        contacts += st[0].contacts;
        const double *a = sw_fullsim_positions(sim[0]), *b = sw_fullsim_positions(sim[1]);
        for (int32_t i = 0; i < 3 * c.mesh.nverts; ++i)
            worst = fmax(worst, fabs(a[i] - b[i]));
        fprintf(stderr, "    frame %d: newton pcg %d / direct %d (%d factorisations), |dx| %.3g\n",
                f, st[0].newton_iters, st[1].newton_iters, st[1].factorizations, worst);
    }
    ENSUREF(contacts > 0, "the fold never reached self-contact: the test would prove less");
    ENSUREF(worst < 1e-4 * scale, "solutions differ by %.3g (scale %.3g)", worst, scale);
    for (int k = 0; k < 2; ++k)
        sw_fullsim_destroy(sim[k]);
    sw_character_free(&c);
}

/* sw_fullsim_rest_response against the simulator's own quasistatic step: a small
 * gravity g at the rest pose is the load M g, and the step's solution must be the rest
 * shape plus the response to it (linear elasticity: the co-rotational model at rest, up
 * to O(|u|/size) terms, negligible at a displacement of 1e-4 of the size). */
TEST(rest_response_is_the_small_load_solution) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1500, 3, &c, &err) == SINEW_OK);
    int32_t nv = c.mesh.nverts;
    sw_fullsim_params p = sw_fullsim_params_default();
    p.self_contact = 0;
    p.pcg_rtol = 1e-10;
    p.pcg_max = 100000;
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&c, &p, &sim, &err) == SINEW_OK);
    const double *m = sw_fullsim_masses(sim);
    double *f = calloc((size_t)3 * nv, sizeof(double)), *u = malloc(sizeof(double) * 3 * nv);
    const double dir[3] = {0.6, 0.0, 0.8};
    for (int32_t v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i)
            f[3 * v + i] = m[v] * dir[i];
    ENSURE(sw_fullsim_rest_response(sim, 1, f, u, &err) == SINEW_OK);
    double un = 0, lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int32_t v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i) {
            un = fmax(un, fabs(u[3 * v + i]));
            lo[i] = fmin(lo[i], c.mesh.X[3 * v + i]);
            hi[i] = fmax(hi[i], c.mesh.X[3 * v + i]);
        }
    double size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    ENSUREF(un > 0 && isfinite(un), "no response (%g)", un);
    double g = 1e-4 * size / un; /* the gravity that displaces by 1e-4 of the size */
    sw_fullsim_params pg = p;
    pg.newton_rtol = 1e-9;
    for (int i = 0; i < 3; ++i)
        pg.gravity[i] = g * dir[i];
    sw_fullsim *sg;
    ENSURE(sw_fullsim_create(&c, &pg, &sg, &err) == SINEW_OK);
    double *T = malloc(sizeof(double) * 12 * c.skel.nbones);
    for (int32_t b = 0; b < c.skel.nbones; ++b) {
        const double I[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
        memcpy(T + 12 * b, I, sizeof I);
    }
    sw_fullsim_stats st;
    ENSURE(sw_fullsim_step(sg, T, &st) == SINEW_OK);
    const double *x = sw_fullsim_positions(sg);
    double num = 0, den = 0;
    for (int64_t i = 0; i < 3 * (int64_t)nv; ++i) {
        double d = x[i] - c.mesh.X[i], e = d - g * u[i];
        num += e * e;
        den += d * d;
    }
    double rel = sqrt(num / den);
    fprintf(stderr, "    response vs step at g = %.3g: relative difference %.3g\n", g, rel);
    ENSUREF(rel < 1e-3, "the response differs from the small-load solution by %.3g", rel);
    /* a dynamic simulator has no static response to give */
    sw_fullsim_params pd = p;
    pd.integrator = SW_BACKWARD_EULER;
    sw_fullsim *sd;
    ENSURE(sw_fullsim_create(&c, &pd, &sd, &err) == SINEW_OK);
    ENSURE(sw_fullsim_rest_response(sd, 1, f, u, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    sw_fullsim_destroy(sd);
    sw_fullsim_destroy(sg);
    sw_fullsim_destroy(sim);
    free(T);
    free(f);
    free(u);
    sw_character_free(&c);
}

SW_TEST_MAIN(CASE(rigid_pose_gives_rigid_shape_and_zero_energy),
             CASE(rest_response_is_the_small_load_solution), CASE(newton_converges_quadratically),
             CASE(newmark_keeps_energy_of_undamped_oscillation),
             CASE(backward_euler_never_gains_energy),
             CASE(self_contact_removes_most_penetration_of_folded_finger),
             CASE(contacts_push_and_never_pull),
             CASE(unsettled_contact_set_is_one_another_round_changes),
             CASE(set_check_converges_only_the_settled_set), CASE(ground_plane_pushes_flesh_out),
             CASE(bad_input_is_rejected_and_state_kept), CASE(direct_and_pcg_solves_agree))
