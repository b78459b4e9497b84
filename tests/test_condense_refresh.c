/* The coupled Newton's law refresh (coupled.c): when the patch's world laws are taken
 * again at an iterate, only they and the pairs the refresh reset are evaluated again;
 * the potential, its gradient and the world's Hessian blocks are those of a whole
 * evaluation at the same iterate, to rounding. The finger of world_fixture.h pressed
 * into a table, off its start so that the refresh moves the laws. */
#include <math.h>

#include "condense.h"
#include "instance.h"
#include "instance_internal.h"
#include "sw_test.h"
#include "world_fixture.h"

static double max_abs_diff(const double *a, const double *b, int64_t n, double *scale) {
    double d = 0;
    for (int64_t i = 0; i < n; ++i) {
        d = fmax(d, fabs(a[i] - b[i]));
        *scale = fmax(*scale, fabs(b[i]));
    }
    return d;
}

TEST(a_refreshed_potential_is_the_whole_evaluation_at_the_iterate) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    ENSURE(w);
    sinew_instance_def d = sinew_instance_def_default();
    d.max_patch_vertices = 2000;
    d.patch_radius = 0.08f;
    sinew_instance *in;
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    ENSURE(sinew_instance_set_world(in, w) == SINEW_OK);
    const int nb = f->ch.skel.nbones;
    float *pose = calloc((size_t)12 * nb, sizeof(float));
    for (int b = 0; b < nb; ++b)
        pose[12 * b] = pose[12 * b + 4] = pose[12 * b + 8] = 1;
    ENSURE(sinew_instance_set_pose(in, pose, (uint32_t)nb) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    sw_instance_step_prepare(in, 1.0f / 30);
    sw_cond *c = &in->cond;
    ENSURE(c->nf > 10);
    const int32_t R = in->red.R, nx = 3 * c->nf;
    sw_step_contacts ct = {&in->ps, &in->wc, NULL, NULL};
    sw_dyn_coef dc = {1.0 / 30, 0, 0, 0, 0, 0};
    sw_cond_weights_apply(c);
    /* an iterate off the start, evaluated whole with its Hessian, as the Newton's is */
    for (int32_t i = 0; i < nx; ++i)
        c->x[i] += 0.02 * sin(1.3 * i) - 0.01;
    const double before =
        sw_cond_potential(c, &in->red, &ct, &in->solver, in->solver.q, c->x, &dc, 1);
    /* the refresh as the solve does it, then the two ways to evaluate */
    sw_cond_detect(c, &in->wc, SW_WC_AT_REPLANE);
    sw_cond_tag_candidates(c, &in->wc);
    for (int32_t j = 0; j < c->np; ++j)
        if (c->pp_active[j] == 0) c->pp_active[j] = -1;
    unsigned char *undecided = malloc((size_t)c->np + 1);
    for (int32_t j = 0; j < c->np; ++j)
        undecided[j] = c->pp_active[j] < 0;
    const double phi_r = sw_cond_potential_refreshed(c, &in->red, &ct, c->x, &dc);
    double *g_r = malloc(sizeof(double) * (R + nx)), *Dw_r = malloc(sizeof(double) * 9 * c->nf);
    memcpy(g_r, in->red.g, sizeof(double) * R);
    memcpy(g_r + R, c->gf, sizeof(double) * nx);
    memcpy(Dw_r, c->Dw, sizeof(double) * 9 * c->nf);
    for (int32_t j = 0; j < c->np; ++j) /* the whole evaluation decides them again */
        if (undecided[j]) c->pp_active[j] = -1;
    const double phi = sw_cond_potential(c, &in->red, &ct, &in->solver, in->solver.q, c->x, &dc, 1);
    double gs = 0, ds = 0;
    double dg = max_abs_diff(g_r, in->red.g, R, &gs);
    dg = fmax(dg, max_abs_diff(g_r + R, c->gf, nx, &gs));
    const double dD = max_abs_diff(Dw_r, c->Dw, 9 * (int64_t)c->nf, &ds);
    fprintf(stderr,
            "    patch %d vertices, %d world candidates; Phi %.12g before the refresh, %.12g "
            "after (refreshed %.12g); gradient %.2e of %.3g, world blocks %.2e of %.3g\n",
            c->nf, in->wc.ncand, before, phi, phi_r, dg, gs, dD, ds);
    ENSUREF(fabs(phi - before) > 1e-9 * fabs(phi), "the refresh changed no law");
    ENSURE_NEAR(phi_r, phi, 1e-12 * fabs(phi));
    ENSUREF(dg <= 1e-11 * gs, "the refreshed gradient is %g from the whole one", dg);
    ENSUREF(dD <= 1e-12 * ds, "the refreshed world blocks are %g from the whole ones", dD);
    sw_cond_weights_restore(c);
    free(g_r), free(Dw_r), free(undecided), free(pose);
    sinew_instance_destroy(in);
    sinew_world_destroy(w);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(a_refreshed_potential_is_the_whole_evaluation_at_the_iterate),
             CASE(release_fixture))
