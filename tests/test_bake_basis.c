/* The basis's strain-energy inner product (bake_basis.c, sw_bake_params.pca_strain): the
 * snapshots' Gram matrix in the rest energy equals d_a^T K d_b with K the co-rotational
 * element's own stiffness at rest (fem_corot.c), on a domain that is a part of the mesh;
 * a rigid motion of the domain costs nothing; and a strain share outside 0..1 is an
 * error that names it. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include <lapacke.h>

#include "bake.h"
#include "bake_state.h"
#include "fem_corot.h"
#include "samples.h"
#include "sw_test.h"

/* A unit cube of five tets (the middle one regular), vertices 0..7 at the corners. */
static double cube_X[24];
static int32_t cube_tets[20] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6, 3, 4, 6, 7, 1, 3, 4, 6};

/* A state with two domains: 0 holds tets 0, 1, 4 (its copies: the vertices they touch),
 * 1 holds tets 2, 3. */
typedef struct {
    sw_bake_state s;
    int32_t vert_ptr[3], verts[16], tet_ptr[3], tets[5];
} cube_state;

static void cube_make(cube_state *c) {
    memset(c, 0, sizeof *c);
    for (int v = 0; v < 8; ++v) { /* corners in the order 0 (0,0,0) 1 (1,0,0) 2 (1,1,0)
                                     3 (0,1,0), then the same at z = 1 */
        static const int xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        cube_X[3 * v] = xy[v % 4][0] * 1.3;
        cube_X[3 * v + 1] = xy[v % 4][1] * 0.9;
        cube_X[3 * v + 2] = (v / 4) * 1.1;
    }
    c->s.rig.ch.mesh.X = cube_X;
    c->s.rig.ch.mesh.tets = cube_tets;
    c->s.rig.ch.mesh.nverts = c->s.rig.nv = 8;
    c->s.rig.ch.mesh.ntets = c->s.rig.nt = 5;
    c->s.rig.ch.youngs = 3e4;
    c->s.rig.ch.poisson = 0.3;
    static const int32_t tets0[] = {0, 1, 4}, tets1[] = {2, 3};
    int32_t nt = 0, nvc = 0;
    c->tet_ptr[0] = c->vert_ptr[0] = 0;
    for (int d = 0; d < 2; ++d) {
        const int32_t *list = d == 0 ? tets0 : tets1;
        int n = d == 0 ? 3 : 2, has[8] = {0};
        for (int i = 0; i < n; ++i) {
            c->tets[nt++] = list[i];
            for (int k = 0; k < 4; ++k)
                has[cube_tets[4 * list[i] + k]] = 1;
        }
        for (int v = 0; v < 8; ++v)
            if (has[v]) c->verts[nvc++] = v;
        c->tet_ptr[d + 1] = nt;
        c->vert_ptr[d + 1] = nvc;
    }
    c->s.domains.nd = 2;
    c->s.domains.dom_tet_ptr = c->tet_ptr;
    c->s.domains.dom_tets = c->tets;
    c->s.domains.dom_vert_ptr = c->vert_ptr;
    c->s.domains.dom_verts = c->verts;
}

/* d^T K e over domain dm's tets, K from the co-rotational element's Hessian at rest. */
static double energy_product(const cube_state *c, int dm, const double *d, const double *e) {
    double mu, lambda, sum = 0;
    sw_lame(c->s.rig.ch.youngs, c->s.rig.ch.poisson, &mu, &lambda);
    int32_t base = c->vert_ptr[dm], n = c->vert_ptr[dm + 1] - base;
    for (int32_t i = c->tet_ptr[dm]; i < c->tet_ptr[dm + 1]; ++i) {
        const int32_t *tet = cube_tets + 4 * c->tets[i];
        double X[12], Dm[9], vol, f[12], K[144], de[12], ee[12];
        for (int k = 0; k < 4; ++k) {
            int loc = 0;
            while (loc < n && c->verts[base + loc] != tet[k])
                loc++;
            memcpy(X + 3 * k, cube_X + 3 * tet[k], 24);
            memcpy(de + 3 * k, d + 3 * loc, 24);
            memcpy(ee + 3 * k, e + 3 * loc, 24);
        }
        if (!sw_tet_rest(X, Dm, &vol)) return NAN;
        sw_corot_eval(X, Dm, vol, mu, lambda, f, K, 0);
        for (int a = 0; a < 12; ++a)
            for (int b = 0; b < 12; ++b)
                sum += de[a] * K[12 * a + b] * ee[b];
    }
    return sum;
}

static double uniform(uint64_t *seed) {
    *seed = *seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*seed >> 11) / 9007199254740992.0 * 2 - 1;
}

TEST(strain_gram_is_the_rest_stiffness_of_the_domain) {
    cube_state c;
    cube_make(&c);
    uint64_t seed = 7;
    for (int dm = 0; dm < 2; ++dm) {
        int32_t n = c.vert_ptr[dm + 1] - c.vert_ptr[dm];
        enum { T = 4 };
        double D[T * 24], G[T * T];
        for (int i = 0; i < T * 3 * n; ++i)
            D[i] = 0.01 * uniform(&seed);
        ENSURE(sw_bake_strain_products(&c.s, dm, D, T, NULL, 0, G));
        double scale = 0;
        for (int a = 0; a < T; ++a)
            scale = fmax(scale, fabs(G[a * T + a]));
        ENSUREF(scale > 0, "domain %d: no energy", dm);
        for (int a = 0; a < T; ++a)
            for (int b = 0; b < T; ++b) {
                double ref = energy_product(&c, dm, D + a * 3 * n, D + b * 3 * n);
                ENSUREF(fabs(G[a * T + b] - ref) <= 1e-9 * scale,
                        "domain %d: G[%d][%d] %.12g, d K d %.12g", dm, a, b, G[a * T + b], ref);
            }
        /* rows against other rows: the first one against the last three */
        double G13[3];
        ENSURE(sw_bake_strain_products(&c.s, dm, D, 1, D + 3 * n, 3, G13));
        for (int b = 0; b < 3; ++b)
            ENSUREF(fabs(G13[b] - G[b + 1]) <= 1e-12 * scale,
                    "domain %d: A K B^T %.12g, Gram %.12g", dm, G13[b], G[b + 1]);
    }
}

TEST(a_rigid_motion_of_the_domain_costs_no_strain_energy) {
    cube_state c;
    cube_make(&c);
    int32_t n = c.vert_ptr[1] - c.vert_ptr[0];
    double D[3 * 24], G[9];
    for (int32_t j = 0; j < n; ++j) {
        const double *X = cube_X + 3 * c.verts[j];
        double w[3] = {0.2, -0.5, 0.7}; /* an infinitesimal rotation: w x X */
        double *t = D + 3 * j, *r = D + 3 * n + 3 * j, *s = D + 6 * n + 3 * j;
        t[0] = 0.3, t[1] = -0.1, t[2] = 0.05;
        r[0] = w[1] * X[2] - w[2] * X[1];
        r[1] = w[2] * X[0] - w[0] * X[2];
        r[2] = w[0] * X[1] - w[1] * X[0];
        s[0] = 0.1 * X[0], s[1] = 0, s[2] = 0; /* a stretch along x, for scale */
    }
    ENSURE(sw_bake_strain_products(&c.s, 0, D, 3, NULL, 0, G));
    ENSUREF(G[8] > 0, "the stretch costs %g", G[8]);
    ENSUREF(fabs(G[0]) <= 1e-12 * G[8] && fabs(G[4]) <= 1e-12 * G[8],
            "translation %g, rotation %g against the stretch's %g", G[0], G[4], G[8]);
}

/* The 1K finger, five frames, two poses a sweep, on 2 threads. */
static int bake_finger(sw_bake_params *p, sw_bake_result *r) {
    sw_character ch;
    sw_error err;
    if (sw_sample_make("finger", 1000, 5, &ch, &err) != SINEW_OK) return 0;
    p->sweep_samples = 2;
    p->threads = 2;
    sinew_result res = sw_bake(&ch, p, r, &err);
    if (res != SINEW_OK) fprintf(stderr, "  bake: %s\n", err.msg);
    sw_character_free(&ch);
    return res == SINEW_OK;
}

TEST(galerkin_errors_bound_the_projection_and_vanish_on_a_full_span) {
    sw_bake_params p = sw_bake_params_default();
    sw_bake_result r;
    ENSURE(bake_finger(&p, &r));
    fprintf(stderr, "  default: projection %.4f / %.4f, Galerkin %.4f / %.4f\n", r.train_proj_error,
            r.heldout_proj_error, r.train_galerkin_error, r.heldout_galerkin_error);
    ENSUREF(r.train_galerkin_error >= r.train_proj_error - 1e-12 &&
                r.heldout_galerkin_error >= r.heldout_proj_error - 1e-12,
            "Galerkin %g / %g below the projection %g / %g", r.train_galerkin_error,
            r.heldout_galerkin_error, r.train_proj_error, r.heldout_proj_error);
    ENSUREF(r.heldout_galerkin_error > 0, "held-out Galerkin error %g", r.heldout_galerkin_error);
    sw_bake_result_free(&r);
    p.pca_energy = 1; /* every snapshot in the span */
    p.max_rank = 1024;
    ENSURE(bake_finger(&p, &r));
    fprintf(stderr, "  full span: projection %.2e, Galerkin %.2e (training)\n", r.train_proj_error,
            r.train_galerkin_error);
    ENSUREF(r.train_proj_error < 1e-6 && r.train_galerkin_error < 1e-5,
            "full span: training projection %g, Galerkin %g", r.train_proj_error,
            r.train_galerkin_error);
    sw_bake_result_free(&r);
}

TEST(a_strain_share_outside_0_1_is_an_error) {
    sw_character ch;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &ch, &err) == SINEW_OK);
    sw_bake_params p = sw_bake_params_default();
    const double bad[] = {-0.1, 1.5, NAN};
    for (int i = 0; i < 3; ++i) {
        p.pca_strain = bad[i];
        sw_bake_result r;
        ENSUREF(sw_bake(&ch, &p, &r, &err) == SINEW_ERROR_INVALID_ARGUMENT, "share %g baked",
                bad[i]);
        ENSUREF(strstr(err.msg, "strain share"), "%s", err.msg);
    }
    sw_character_free(&ch);
}

static double lcg(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * 0x1.0p-53 - 0.5;
}

/* The inertia modes' Rayleigh-Ritz step (sw_bake_ritz_modes) against the same step done
 * with K itself: on a random SPD K (30 dofs, 10 vertices of random lumped mass), the
 * responses U = K^-1 F to 6 random loads, plus one response that is the sum of two others
 * and one to a zero load (dependent and empty: B = U M U^T singular). The 3 modes must lie
 * in the responses' span, be M-orthogonal, and have the Rayleigh quotients y^T K y / y^T M
 * y of the 3 lowest eigenvalues of K in that span (computed here from an M-orthonormal
 * basis of the 6 independent responses and K), ascending. Measured: quotients to 1e-13
 * relative, span residual 1e-15, orthogonality 1e-16 (with the mass left out of B: quotients
 * off by 0.1-0.3, the test fails). A response set that spans nothing
 * gives no mode. */
TEST(inertia_ritz_modes_are_the_lowest_vibration_modes_of_the_responses_span) {
    enum { NV = 10, N3 = 30, NL = 8, NI = 6, RITZ = 3 };
    uint64_t seed = 42;
    double K[N3 * N3], L[N3 * N3], m[NV], F[NL * N3], U[NL * N3], Y[NL * N3];
    for (int i = 0; i < N3 * N3; ++i)
        L[i] = lcg(&seed);
    for (int i = 0; i < N3; ++i) /* K = L L^T + N3 I */
        for (int j = 0; j < N3; ++j) {
            double k = i == j ? N3 : 0;
            for (int t = 0; t < N3; ++t)
                k += L[i * N3 + t] * L[j * N3 + t];
            K[i * N3 + j] = k;
        }
    for (int v = 0; v < NV; ++v)
        m[v] = 0.5 + lcg(&seed) + 0.5;
    memset(F, 0, sizeof F);
    for (int l = 0; l < NI; ++l)
        for (int t = 0; t < N3; ++t)
            F[l * N3 + t] = lcg(&seed);
    for (int t = 0; t < N3; ++t)
        F[NI * N3 + t] = F[t] + F[N3 + t]; /* load 7 = loads 0 + 1; load 8 = 0 */
    double Kf[N3 * N3], Ut[N3 * NL];
    memcpy(Kf, K, sizeof K);
    for (int l = 0; l < NL; ++l)
        for (int t = 0; t < N3; ++t)
            Ut[t * NL + l] = F[l * N3 + t];
    ENSURE(LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', N3, NL, Kf, N3, Ut, NL) == 0);
    for (int l = 0; l < NL; ++l)
        for (int t = 0; t < N3; ++t)
            U[l * N3 + t] = Ut[t * NL + l];
    memcpy(Y, U, sizeof U);
    double got_lambda[RITZ];
    ENSURE(sw_bake_ritz_modes(Y, F, m, NL, N3, RITZ, got_lambda) == RITZ);

    /* the expected: Q, an M-orthonormal basis of the independent responses (Gram-Schmidt),
       then the eigenvalues of Q^T K Q */
    double Q[NI * N3], P[NI * NI], lam[NI];
    for (int a = 0; a < NI; ++a) {
        memcpy(Q + a * N3, U + a * N3, N3 * sizeof(double));
        for (int b = 0; b < a; ++b) {
            double d = 0;
            for (int t = 0; t < N3; ++t)
                d += Q[a * N3 + t] * m[t / 3] * Q[b * N3 + t];
            for (int t = 0; t < N3; ++t)
                Q[a * N3 + t] -= d * Q[b * N3 + t];
        }
        double n = 0;
        for (int t = 0; t < N3; ++t)
            n += Q[a * N3 + t] * m[t / 3] * Q[a * N3 + t];
        for (int t = 0; t < N3; ++t)
            Q[a * N3 + t] /= sqrt(n);
    }
    for (int a = 0; a < NI; ++a)
        for (int b = 0; b < NI; ++b) {
            double p = 0;
            for (int i = 0; i < N3; ++i)
                for (int j = 0; j < N3; ++j)
                    p += Q[a * N3 + i] * K[i * N3 + j] * Q[b * N3 + j];
            P[a * NI + b] = p;
        }
    ENSURE(LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', NI, P, NI, lam) == 0);
    double worst_q = 0, worst_span = 0, worst_orth = 0;
    for (int k = 0; k < RITZ; ++k) {
        const double *y = Y + k * N3;
        double yky = 0, ymy = 0, yy = 0, r[N3];
        for (int i = 0; i < N3; ++i) {
            ymy += y[i] * m[i / 3] * y[i];
            yy += y[i] * y[i];
            for (int j = 0; j < N3; ++j)
                yky += y[i] * K[i * N3 + j] * y[j];
        }
        worst_q = fmax(worst_q, fabs(yky / ymy - lam[k]) / lam[k]);
        worst_q = fmax(worst_q, fabs(got_lambda[k] - lam[k]) / lam[k]);
        memcpy(r, y, sizeof r); /* y minus its M-projection on the span */
        for (int a = 0; a < NI; ++a) {
            double d = 0;
            for (int t = 0; t < N3; ++t)
                d += y[t] * m[t / 3] * Q[a * N3 + t];
            for (int t = 0; t < N3; ++t)
                r[t] -= d * Q[a * N3 + t];
        }
        double rr = 0;
        for (int t = 0; t < N3; ++t)
            rr += r[t] * r[t];
        worst_span = fmax(worst_span, sqrt(rr / yy));
        for (int j = 0; j < k; ++j) {
            double d = 0, nj = 0;
            for (int t = 0; t < N3; ++t)
                d += y[t] * m[t / 3] * Y[j * N3 + t],
                    nj += Y[j * N3 + t] * m[t / 3] * Y[j * N3 + t];
            worst_orth = fmax(worst_orth, fabs(d) / sqrt(ymy * nj));
        }
    }
    fprintf(stderr, "  Rayleigh quotients %.2e, span %.2e, M-orthogonality %.2e\n", worst_q,
            worst_span, worst_orth);
    ENSUREF(worst_q < 1e-9, "Rayleigh quotient off the span's eigenvalue by %.3g", worst_q);
    ENSUREF(worst_span < 1e-9, "a mode leaves the responses' span by %.3g", worst_span);
    ENSUREF(worst_orth < 1e-9, "modes not M-orthogonal: %.3g", worst_orth);

    double Z[2 * N3], FZ[2 * N3];
    memset(Z, 0, sizeof Z);
    memset(FZ, 0, sizeof FZ);
    ENSURE(sw_bake_ritz_modes(Z, FZ, m, 2, N3, 1, NULL) == 0);
}

/* Which vibration modes swing at a time step (sw_bake_ritz_swinging): the leading modes up
 * to omega h = SW_INERTIA_MAX_OMEGA_H and up to SW_INERTIA_OMEGA_SPREAD times the lowest
 * frequency, whichever stops first; frequencies as the hand's, the Fox's and the
 * elephant's spectra put them (docs/notes/jiggle.md, Modes that swing). */
TEST(only_the_modes_that_swing_at_the_time_step_join) {
    const double h = 1.0 / 30, w = SW_INERTIA_MAX_OMEGA_H / h, s = SW_INERTIA_OMEGA_SPREAD;
    double stiff[3] = {1.5 * w * w, 2 * w * w, 4 * w * w}; /* all past omega h: none */
    ENSURE(sw_bake_ritz_swinging(stiff, 3, h) == 0);
    double fox[4] = {0.2 * w * w, 0.9 * w * w, 1.01 * w * w, 0.5 * w * w}; /* the third stops it */
    ENSURE(sw_bake_ritz_swinging(fox, 4, h) == 2);
    double l0 = 1e-4 * w * w; /* soft: the spread stops it, far below omega h */
    double soft[4] = {l0, 4 * l0, 0.99 * s * s * l0, 1.01 * s * s * l0};
    ENSURE(sw_bake_ritz_swinging(soft, 4, h) == 3);
    ENSURE(sw_bake_ritz_swinging(soft, 2, h) == 2);
    ENSURE(sw_bake_ritz_swinging(soft, 0, h) == 0);
    /* the same spectrum at 10 times the step: omega h now stops it after the first */
    ENSURE(sw_bake_ritz_swinging(fox, 4, 10 * h) == 0);
    double mid[2] = {0.2 * w * w / 100, 1.5 * w * w / 100};
    ENSURE(sw_bake_ritz_swinging(mid, 2, 10 * h) == 1);
}

SW_TEST_MAIN(CASE(strain_gram_is_the_rest_stiffness_of_the_domain),
             CASE(a_rigid_motion_of_the_domain_costs_no_strain_energy),
             CASE(galerkin_errors_bound_the_projection_and_vanish_on_a_full_span),
             CASE(a_strain_share_outside_0_1_is_an_error),
             CASE(inertia_ritz_modes_are_the_lowest_vibration_modes_of_the_responses_span),
             CASE(only_the_modes_that_swing_at_the_time_step_join))
