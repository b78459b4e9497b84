/* The reference simulator gives bitwise identical results for any thread count (every
 * reduction has a fixed order); run under TSan by the "threads" label. */
#include <stdint.h>

#include "fullsim.h"
#include "samples.h"
#include "sw_test.h"

/* Folds a small finger into self-contact with `threads` workers; returns positions. */
static double *fold_finger(int threads, size_t *bytes) {
    sw_character c;
    sw_error err;
    if (sw_sample_make("finger", 2000, 5, &c, &err) != SINEW_OK) return NULL;
    sw_fullsim_params p = sw_fullsim_params_default();
    p.threads = threads;
    sw_fullsim *sim;
    double *x = NULL;
    if (sw_fullsim_create(&c, &p, &sim, &err) == SINEW_OK) {
        for (int f = 0; f <= c.clip.nframes / 2; ++f)
            sw_fullsim_step(sim, c.clip.T + (size_t)f * 12 * c.clip.nbones, NULL);
        *bytes = sizeof(double) * 3 * c.mesh.nverts;
        x = malloc(*bytes);
        if (x) memcpy(x, sw_fullsim_positions(sim), *bytes);
        sw_fullsim_destroy(sim);
    }
    sw_character_free(&c);
    return x;
}

TEST(thread_count_does_not_change_results) {
    size_t b1 = 0, b2 = 0, b3 = 0;
    double *x1 = fold_finger(1, &b1), *x2 = fold_finger(2, &b2), *x3 = fold_finger(3, &b3);
    ENSURE(x1 && x2 && x3 && b1 == b2 && b2 == b3);
    ENSUREF(memcmp(x1, x2, b1) == 0, "1 and 2 threads differ");
    ENSUREF(memcmp(x1, x3, b1) == 0, "1 and 3 threads differ");
    free(x1);
    free(x2);
    free(x3);
}

TEST(repeated_runs_are_identical) {
    size_t b1 = 0, b2 = 0;
    double *x1 = fold_finger(2, &b1), *x2 = fold_finger(2, &b2);
    ENSURE(x1 && x2 && b1 == b2);
    ENSURE(memcmp(x1, x2, b1) == 0);
    free(x1);
    free(x2);
}

SW_TEST_MAIN(CASE(thread_count_does_not_change_results), CASE(repeated_runs_are_identical))
