/* How well the held-out references are defined (sw_bake_reference_spread, bake_spread.c):
 * on a finger without self-contact the flesh has one equilibrium a pose, so full-space
 * solves from plain skinning, from the reference and from the runtime's state all land on
 * the reference, and the one from the runtime's state moves it by the runtime's own
 * error; the runtime's figure is the bake's held-out error; every K-th pose is every
 * K-th; bad arguments are refused with a message. */
#include <math.h>

#include "bake_fixture.h"
#include "sw_test.h"

static int bake_without_contact(bake_fixture *f) {
    sw_bake_params p = bake_fixture_params(0, 2);
    p.self_contact = 0;
    return bake_fixture_make_params(f, "finger", 1000, 8, &p);
}

TEST(one_equilibrium_is_found_from_every_start) {
    bake_fixture f;
    ENSURE(bake_without_contact(&f));
    sw_bake_params p = bake_fixture_params(0, 2);
    p.self_contact = 0;
    sw_error e;
    sw_eval_result et, eh;
    ENSURE(sw_bake_errors(f.blob, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, &et, &eh, &e) == SINEW_OK);
    sw_bake_spread s;
    ENSUREF(sw_bake_reference_spread(&f.ch, &p, f.blob, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, 1,
                                     &s, &e) == SINEW_OK,
            "%s", e.msg);
    fprintf(stderr,
            "%d poses: runtime %.6f, from skinning %.3e, from the reference %.3e, polished "
            "%.3e, moved %.6f\n",
            s.poses, s.runtime, s.from_skin, s.from_reference, s.polished, s.polish_move);
    ENSURE(f.res.nheldout > 1 && s.poses == f.res.nheldout && s.failed == 0);
    /* the runtime's figure is the bake's, summed in another order */
    ENSUREF(fabs(s.runtime - eh.correction_error) <= 1e-9 * eh.correction_error, "%.12g vs %.12g",
            s.runtime, eh.correction_error);
    ENSURE(s.runtime > 0.01); /* the subspace misses some: the polish has a way to go */
    /* one equilibrium: all three starts end on the reference, to Newton's tolerance */
    ENSUREF(s.from_skin < 1e-3 && s.from_reference < 1e-3 && s.polished < 1e-3, "%g %g %g",
            s.from_skin, s.from_reference, s.polished);
    /* so the polish moved the runtime's state by its error (triangle inequality) */
    ENSURE(fabs(s.polish_move - s.runtime) <= s.polished + 1e-12);
    /* per pose: every held-out pose in order, each with a correction landing on its
       reference (a pose back near rest has almost none: its shares are of rounding); the
       whole figure a weighted mean of the poses' own (between the least and the most) */
    double lo = INFINITY, hi = 0, cmax = 0;
    for (int32_t k = 0; k < s.poses; ++k)
        cmax = fmax(cmax, s.per_pose[k].correction);
    for (int32_t k = 0; k < s.poses; ++k) {
        const sw_bake_spread_pose *q = &s.per_pose[k];
        ENSURE(q->heldout == k && q->correction >= 0);
        lo = fmin(lo, q->runtime);
        hi = fmax(hi, q->runtime);
        if (q->correction < 1e-3 * cmax) continue;
        ENSUREF(q->from_skin < 1e-3 && q->from_reference < 1e-3 && q->polished < 1e-3,
                "pose %d: %g %g %g", k, q->from_skin, q->from_reference, q->polished);
    }
    ENSUREF(lo <= s.runtime && s.runtime <= hi, "%g in [%g, %g]", s.runtime, lo, hi);
    /* every second pose: poses 1, 3, 5, ... */
    sw_bake_spread s2;
    ENSURE(sw_bake_reference_spread(&f.ch, &p, f.blob, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, 2,
                                    &s2, &e) == SINEW_OK);
    ENSURE(s2.poses == f.res.nheldout / 2 && s2.failed == 0);
    ENSURE(s2.from_skin < 1e-3 && s2.polished < 1e-3 && s2.runtime > 0);
    for (int32_t k = 0; k < s2.poses; ++k) { /* the same poses' own figures as before, */
        const sw_bake_spread_pose *a = &s2.per_pose[k], *b = &s.per_pose[2 * k + 1];
        ENSURE(a->heldout == 2 * k + 1 && a->runtime == b->runtime); /* the solves' bitwise: */
        ENSURE(a->from_skin == b->from_skin && a->from_reference == b->from_reference &&
               a->polished == b->polished); /* none depends on the poses measured before */
    }
    sw_bake_spread_free(&s2);
    sw_bake_spread_free(&s);
    bake_fixture_free(&f);
}

TEST(bad_arguments_are_refused) {
    bake_fixture f;
    ENSURE(bake_without_contact(&f));
    sw_bake_params p = bake_fixture_params(0, 2);
    sw_error e;
    sw_bake_spread s;
    ENSURE(sw_bake_reference_spread(&f.ch, &p, f.blob, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, 0, &s,
                                    &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "every 0-th") != NULL, "%s", e.msg);
    ENSURE(sw_bake_reference_spread(&f.ch, &p, NULL, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, 1, &s,
                                    &e) == SINEW_ERROR_INVALID_ARGUMENT);
    /* a character the blob was not baked from */
    sw_character other;
    ENSURE(sw_sample_make("finger", 2000, 8, &other, &e) == SINEW_OK);
    ENSURE(sw_bake_reference_spread(&other, &p, f.blob, &f.res, SINEW_SELF_CONTACT_POSE_SPACE, 1,
                                    &s, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "vertices") != NULL, "%s", e.msg);
    sw_character_free(&other);
    bake_fixture_free(&f);
}

SW_TEST_MAIN(CASE(one_equilibrium_is_found_from_every_start), CASE(bad_arguments_are_refused))
