/* The bake's least input (issue 15): a clip too short to train on is rejected with the
 * minimum and the reason, not written as a blob with empty cubature or a useless basis;
 * sw_bake_solutions gives the very poses and solutions sw_bake keeps. Small meshes. */
#include "sw_test.h"

#include "bake.h"
#include "samples.h"

TEST(min_frames) {
    ENSURE(sw_bake_min_frames(0.4) == 4); /* floor(0.6 F) >= 2 */
    ENSURE(sw_bake_min_frames(0.0) == 2);
    ENSURE(sw_bake_min_frames(0.5) == 4);
}

TEST(too_few_frames_rejected) {
    for (int frames = 2; frames <= 3; ++frames) {
        sw_character c;
        sw_error err;
        ENSURE(sw_sample_make("finger", 1000, frames, &c, &err) == SINEW_OK);
        sw_bake_result res;
        sinew_result r = sw_bake(&c, NULL, &res, &err);
        sw_character_free(&c);
        ENSUREF(r == SINEW_ERROR_INVALID_ARGUMENT, "%d frames: %s", frames, err.msg);
        ENSUREF(strstr(err.msg, "too few poses to train") && strstr(err.msg, "at least 4 frames"),
                "%s", err.msg);
    }
}

TEST(solutions_match_the_bake) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 2;
    p.threads = 2;
    sw_bake_result a, b;
    ENSUREF(sw_bake(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    int same = a.ntrain == b.ntrain && a.nheldout == b.nheldout;
    size_t pt = (size_t)12 * c.skel.nbones * sizeof(double),
           px = (size_t)3 * c.mesh.nverts * sizeof(double);
    if (same)
        same = !memcmp(a.train_T, b.train_T, a.ntrain * pt) &&
               !memcmp(a.train_x, b.train_x, a.ntrain * px) &&
               !memcmp(a.heldout_T, b.heldout_T, a.nheldout * pt) &&
               !memcmp(a.heldout_x, b.heldout_x, a.nheldout * px) &&
               !memcmp(a.mass, b.mass, (size_t)c.mesh.nverts * sizeof(double));
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
    ENSURE(same);
}

SW_TEST_MAIN(CASE(min_frames), CASE(too_few_frames_rejected), CASE(solutions_match_the_bake))
