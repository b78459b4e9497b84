/* The two-body reference (character_pair.h): two copies of the 1,000-tet finger solved as
 * one character.
 *  - apart, each copy's solution is the lone finger's, moved by the rest offset (the
 *    merge adds nothing between them);
 *  - pushed into each other by their roots, the reference's self-contact finds vertices
 *    of one inside the other and holds them out: the overlap left is a small share of
 *    the overlap the roots asked for;
 *  - the transforms: the second body's are its own composed with the rest offset. */
#include <math.h>

#include "bbox.h"
#include "character_pair.h"
#include "fullsim.h"
#include "mesh_io.h"
#include "samples.h"
#include "selfcontact.h"
#include "sw_test.h"

#define TETS 1000
#define FRAMES 6

static sw_character g_ch;
static int g_ok;

static int fixture(void) {
    sw_error err;
    if (!g_ok) g_ok = sw_sample_make("finger", TETS, FRAMES, &g_ch, &err) == SINEW_OK ? 1 : -1;
    return g_ok > 0;
}

static sw_fullsim_params params(void) {
    sw_fullsim_params p = sw_fullsim_params_default();
    p.threads = 2;
    return p;
}

/* The thinnest rest extent and its axis. */
static double thickness(const sw_character *c, int *axis) {
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, c->mesh.nverts, c->mesh.X);
    *axis = 0;
    for (int i = 1; i < 3; ++i)
        if (hi[i] - lo[i] < hi[*axis] - lo[*axis]) *axis = i;
    return hi[*axis] - lo[*axis];
}

/* The finger and a copy `apart` thicknesses away along its thinnest axis *ax (*w thick,
 * offset off). */
static int make_pair(double apart, sw_character *pair, int *ax, double *w, double off[3]) {
    sw_error err;
    if (!fixture()) return 0;
    *w = thickness(&g_ch, ax);
    off[0] = off[1] = off[2] = 0;
    off[*ax] = apart * *w;
    return sw_character_pair(&g_ch, off, pair, &err) == SINEW_OK;
}

TEST(two_copies_apart_are_each_the_lone_character) {
    int ax;
    double w, off[3];
    sw_character pair;
    sw_error err;
    ENSURE(make_pair(4, &pair, &ax, &w, off));
    ENSURE(pair.mesh.nverts == 2 * g_ch.mesh.nverts && pair.skel.nbones == 2 * g_ch.skel.nbones);
    sw_fullsim_params p = params();
    sw_fullsim *one, *two;
    ENSURE(sw_fullsim_create(&g_ch, &p, &one, &err) == SINEW_OK);
    ENSURE(sw_fullsim_create(&pair, &p, &two, &err) == SINEW_OK);
    const int32_t nb = g_ch.skel.nbones, nv = g_ch.mesh.nverts;
    double *Tp = malloc(sizeof(double) * 24 * nb), *Tb = malloc(sizeof(double) * 12 * nb);
    ENSURE(Tp && Tb);
    double worst = 0, scale = 0;
    for (int f = 0; f < g_ch.clip.nframes; ++f) {
        const double *T = g_ch.clip.T + (size_t)f * 12 * nb;
        memcpy(Tb, T, sizeof(double) * 12 * nb); /* the second moved by the offset too */
        for (int32_t b = 0; b < nb; ++b)
            Tb[12 * b + 9 + ax] += off[ax];
        sw_character_pair_transforms(nb, T, Tb, off, Tp);
        sw_fullsim_stats s1, s2;
        ENSURE(sw_fullsim_step(one, T, &s1) == SINEW_OK);
        ENSURE(sw_fullsim_step(two, Tp, &s2) == SINEW_OK);
        const double *x1 = sw_fullsim_positions(one), *x2 = sw_fullsim_positions(two);
        for (int32_t v = 0; v < nv; ++v)
            for (int k = 0; k < 3; ++k) {
                const double a = x1[3 * v + k], b = x2[3 * v + k],
                             c = x2[3 * (nv + v) + k] - (k == ax ? off[ax] : 0.0);
                worst = fmax(worst, fmax(fabs(a - b), fabs(a - c)));
                scale = fmax(scale, fabs(a));
            }
    }
    fprintf(stderr, "  apart: largest distance from the lone finger %.3g (of %.3g)\n", worst,
            scale);
    ENSUREF(worst <= 1e-6 * scale, "the pair apart is off the lone finger by %.3g", worst);
    free(Tp), free(Tb);
    sw_fullsim_destroy(one);
    sw_fullsim_destroy(two);
    sw_character_free(&pair);
}

TEST(two_copies_pushed_together_hold_each_other_out) {
    int ax;
    double w, off[3];
    sw_character pair;
    sw_error err;
    ENSURE(make_pair(3, &pair, &ax, &w, off));
    sw_fullsim_params p = params();
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&pair, &p, &sim, &err) == SINEW_OK);
    sw_surface surf = {0};
    sw_selfcontact *sc = NULL;
    ENSURE(sw_tetmesh_surface(&pair.mesh, &surf, &err) == SINEW_OK);
    ENSURE(sw_selfcontact_create(&pair.mesh, &surf, 1.8, 0, &sc, &err) == SINEW_OK);
    const int32_t nb = g_ch.skel.nbones, nv = g_ch.mesh.nverts;
    double *Tp = malloc(sizeof(double) * 24 * nb), *Tb = malloc(sizeof(double) * 12 * nb);
    ENSURE(Tp && Tb);
    /* the rest pose, the second copy's root from 1.1 to 0.8 thicknesses away */
    double *I = calloc(12 * (size_t)nb, sizeof(double));
    ENSURE(I != NULL);
    for (int32_t b = 0; b < nb; ++b)
        I[12 * b] = I[12 * b + 4] = I[12 * b + 8] = 1;
    double depth = 0;
    int32_t between = 0;
    for (int f = 0; f < 4; ++f) {
        memcpy(Tb, I, sizeof(double) * 12 * nb);
        for (int32_t b = 0; b < nb; ++b)
            Tb[12 * b + 9 + ax] = (1.1 - 0.1 * f) * w;
        sw_character_pair_transforms(nb, I, Tb, off, Tp);
        sw_fullsim_stats st;
        sinew_result r = sw_fullsim_step(sim, Tp, &st);
        ENSURE(r == SINEW_OK || r == SINEW_ERROR_NOT_CONVERGED);
        sw_selfcontact_detect(sc, sw_fullsim_positions(sim), NULL);
        int32_t n;
        const sw_contact *c = sw_selfcontact_list(sc, &n);
        depth = 0;
        between = 0;
        for (int32_t i = 0; i < n; ++i)
            if ((c[i].p < nv) != (c[i].tri[0] < nv)) {
                ++between;
                depth = fmax(depth, c[i].depth);
            }
    }
    fprintf(stderr,
            "  pushed 0.2 thicknesses into each other: %d vertices inside the other, "
            "deepest %.3g (%.3f of the overlap asked)\n",
            between, depth, depth / (0.2 * w));
    ENSUREF(between > 0, "no contact between the copies (%d)", between);
    ENSUREF(depth < 0.25 * 0.2 * w, "the copies overlap %.3g of the %.3g asked", depth, 0.2 * w);
    free(Tp), free(Tb), free(I);
    sw_selfcontact_destroy(sc);
    sw_surface_free(&surf);
    sw_fullsim_destroy(sim);
    sw_character_free(&pair);
}

TEST(release_fixture) {
    if (g_ok > 0) sw_character_free(&g_ch);
}

SW_TEST_MAIN(CASE(two_copies_apart_are_each_the_lone_character),
             CASE(two_copies_pushed_together_hold_each_other_out), CASE(release_fixture))
