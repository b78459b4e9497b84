/* The interface springs' stiffness the bake chooses (bake_springs.c): the blob it keeps
 * is the one baked with that stiffness given, byte for byte; every training error it
 * recorded is the training error of the blob baked with that choice given (without its
 * equilibrium force, which lowers it); and it kept
 * the stiffest choice that no softer one beat by the required share. */
#include <math.h>

#include "bake_fixture.h"
#include "sw_test.h"

/* Bakes the fixture's finger with spring stiffness k (0: chosen) into f. */
static int bake_with(bake_fixture *f, double k) {
    sw_bake_params p = bake_fixture_params(1, 2); /* return path: a fold with contact pairs */
    p.spring_k = k;
    return bake_fixture_make_params(f, "finger", 3000, 12, &p);
}

TEST(chosen_stiffness_is_the_blob_and_its_errors_are_measured) {
    bake_fixture a;
    ENSURE(bake_with(&a, 0));
    const sw_bake_result *r = &a.res;
    ENSUREF(r->nspring_tried >= 2 && r->nspring_tried <= SW_SPRING_CHOICES, "%d stiffnesses tried",
            r->nspring_tried);
    /* the rule: stiffest first, a softer one taken below 0.98 of the best so far, the
     * search over at the first that is no lower than the best */
    int best = 0, stop = 0;
    for (int c = 0; c < r->nspring_tried; ++c) {
        ENSURE(r->spring_tried_mult[c] == sw_bake_spring_mult(c));
        ENSURE(r->spring_tried_err[c] > 0 && r->spring_tried_err[c] < 0.5);
        ENSUREF(!stop, "choice %d tried after the search was over", c);
        if (c == 0) continue;
        if (r->spring_tried_err[c] < 0.98 * r->spring_tried_err[best])
            best = c;
        else if (r->spring_tried_err[c] >= r->spring_tried_err[best])
            stop = 1;
    }
    ENSURE(stop || r->nspring_tried == SW_SPRING_CHOICES);
    double eh = r->spring_eh; /* E h of the fixture's mesh */
    ENSURE(r->spring_k == sw_bake_spring_mult(best) * eh);
    fprintf(stderr, "  chose %g E h (E h = %.6g) of %d tried\n", sw_bake_spring_mult(best), eh,
            r->nspring_tried);
    for (int c = 0; c < r->nspring_tried; ++c) {
        bake_fixture b;
        ENSURE(bake_with(&b, sw_bake_spring_mult(c) * eh));
        ENSURE(b.res.nspring_tried == 0 && b.res.spring_k == sw_bake_spring_mult(c) * eh);
        if (c == best)
            ENSUREF(b.size == a.size && memcmp(b.data, a.data, a.size) == 0,
                    "the chosen stiffness given: a blob of %zu bytes, not the chosen %zu bytes",
                    b.size, a.size);
        /* the choice measures the blob without its equilibrium force: the model's own
           error, which the given-stiffness bake measures once more (bake_equilibrium.c) */
        ENSUREF(b.res.model_train_error == r->spring_tried_err[c],
                "%g E h: training error %.17g, recorded %.17g", sw_bake_spring_mult(c),
                b.res.model_train_error, r->spring_tried_err[c]);
        sw_eval_result e;
        sw_error err;
        ENSURE(sw_bake_train_error(b.blob, &b.res, SINEW_SELF_CONTACT_POSE_SPACE, &e, NULL, &err) ==
               SINEW_OK);
        fprintf(stderr, "  %g E h: training error %.4f, %.4f with the equilibrium force\n",
                sw_bake_spring_mult(c), b.res.model_train_error, e.correction_error);
        ENSURE(b.res.force_poses == b.res.ntrain && e.correction_error < b.res.model_train_error);
        bake_fixture_free(&b);
    }
    bake_fixture_free(&a);
}

SW_TEST_MAIN(CASE(chosen_stiffness_is_the_blob_and_its_errors_are_measured))
