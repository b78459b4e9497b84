/* The adaptive training loop (precompute/bake/bake_adaptive.h): each
 * round adds the candidates its proxy scores worst, and the reference confirms they are
 * poses the blob gets wrong (worse than the held-out poses); a round solves only its new
 * poses (the other chains come from the cache), and a re-bake with another cubature none;
 * the added poses are never held-out ones;
 * the budget and the target stop the loop; the caller's extra poses are checked. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake_adaptive.h"
#include "samples.h"
#include "sw_test.h"

static sw_bake_params quick(void) {
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3;
    p.threads = 2;
    return p;
}

TEST(rounds_add_the_poses_the_blob_gets_wrong_and_solve_only_those) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 2000, 10, &c, &err) == SINEW_OK);
    sw_bake_params p = quick();
    sw_adaptive_params a = sw_adaptive_params_default();
    a.rounds = 2;
    a.add = 4;
    a.candidates = 16;
    sw_bake_result res;
    sw_adaptive_report rep;
    ENSUREF(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rep.nrounds == 3);
    int32_t base = rep.round[0].ntrain, nb = c.skel.nbones;
    ENSURE(res.ntrain == base + 8 && rep.round[2].added == 8);
    for (int k = 0; k < 2; ++k) {
        const sw_adaptive_round *r = &rep.round[k];
        fprintf(stderr, "    round %d: held-out %.4f, picks %.4f (proxy %.3f, mean %.3f)\n", k,
                r->err_heldout, r->picks_error, r->picks_score, r->score_mean);
        /* the reference confirms the proxy: the picked poses are ones the blob misses more
           of than it misses of the held-out poses */
        ENSURE(r->picks_error > r->err_heldout);
        ENSURE(rep.round[k + 1].solved == 4); /* the new poses only */
    }
    ENSURE(rep.round[0].solved == base + res.nheldout && rep.round[2].picks_error == -1);
    /* the added poses (the last 8 training poses) are no held-out pose */
    for (int32_t i = base; i < res.ntrain; ++i)
        for (int32_t j = 0; j < res.nheldout; ++j)
            ENSURE(memcmp(res.train_T + (size_t)i * 12 * nb, res.heldout_T + (size_t)j * 12 * nb,
                          12 * nb * sizeof(double)) != 0);
    ENSURE(rep.round[2].err_train < 0.5 && isfinite(rep.round[2].err_heldout));
    sw_bake_result_free(&res);
    /* the budget stops it: 4 poses at most */
    a.budget = 4;
    ENSUREF(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rep.nrounds == 2 && res.ntrain == base + 4);
    sw_bake_result_free(&res);
    /* so does a held-out target already met: the plain bake */
    a.budget = 32;
    a.target = 0.99;
    ENSUREF(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rep.nrounds == 1 && res.ntrain == base);
    sw_bake_result_free(&res);
    sw_character_free(&c);
}

/* Every candidate picked, so a re-bake picks the same poses whatever its scores: with only
 * the cubature changed, its rounds read every chain back from the cache (the picks go in
 * as paths in the candidates' order; in the scores' order a changed blob renamed them). */
TEST(an_adaptive_rebake_that_changes_only_the_cubature_solves_nothing) {
    char dir[] = "/tmp/sinew-adaptive-XXXXXX";
    ENSURE(mkdtemp(dir));
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    sw_bake_params p = quick();
    p.cache_dir = dir;
    sw_adaptive_params a = sw_adaptive_params_default();
    a.rounds = 1;
    a.add = a.candidates = 6;
    sw_bake_result res;
    sw_adaptive_report rep;
    ENSUREF(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rep.nrounds == 2 && rep.round[1].added == 6 && rep.round[1].solved == 6);
    sw_bake_result_free(&res);
    p.cubature_tol = 0.2;
    ENSUREF(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_OK, "%s", err.msg);
    fprintf(stderr, "    re-bake: solved %d, %d\n", rep.round[0].solved, rep.round[1].solved);
    ENSURE(rep.nrounds == 2 && rep.round[0].solved == 0 && rep.round[1].solved == 0);
    sw_bake_result_free(&res);
    sw_character_free(&c);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    ENSURE(system(cmd) == 0);
}

TEST(bad_loop_parameters_and_extra_poses_are_named) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    sw_bake_params p = quick();
    sw_adaptive_params a = sw_adaptive_params_default();
    sw_bake_result res;
    sw_adaptive_report rep;
    a.add = a.candidates + 1;
    ENSURE(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_ERROR_INVALID_ARGUMENT &&
           strstr(err.msg, "add"));
    a = sw_adaptive_params_default();
    a.target = NAN;
    ENSURE(sw_bake_adaptive(&c, &p, &a, &res, &rep, &err) == SINEW_ERROR_INVALID_ARGUMENT &&
           strstr(err.msg, "target"));
    /* the caller's poses: a NaN in the second is named; NULL with a count is refused */
    int32_t nb = c.skel.nbones;
    double *T = malloc(sizeof(double) * 24 * nb);
    ENSURE(T);
    memcpy(T, c.clip.T + (size_t)12 * nb * 2, sizeof(double) * 12 * nb);
    memcpy(T + 12 * nb, c.clip.T + (size_t)12 * nb * 3, sizeof(double) * 12 * nb);
    T[12 * nb + 5] = NAN;
    p.extra_poses = T;
    p.nextra_poses = 2;
    ENSURE(sw_bake(&c, &p, &res, &err) == SINEW_ERROR_NOT_FINITE && strstr(err.msg, "pose 1"));
    p.extra_poses = NULL;
    ENSURE(sw_bake(&c, &p, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT &&
           strstr(err.msg, "extra poses"));
    /* the loop does not take them: it adds poses of its own there */
    sw_adaptive_params a2 = sw_adaptive_params_default();
    ENSURE(sw_bake_adaptive(&c, &p, &a2, &res, &rep, &err) == SINEW_ERROR_INVALID_ARGUMENT &&
           strstr(err.msg, "extra poses"));
    /* and two good ones train: two more training poses on a path of their own */
    T[12 * nb + 5] = c.clip.T[(size_t)12 * nb * 3 + 5];
    p.extra_poses = T;
    sw_bake_result plain;
    sw_bake_params q = quick();
    ENSUREF(sw_bake(&c, &q, &plain, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_bake(&c, &p, &res, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(res.ntrain == plain.ntrain + 2 &&
           !memcmp(res.train_T + (size_t)plain.ntrain * 12 * nb, T, sizeof(double) * 24 * nb));
    sw_bake_result_free(&res);
    sw_bake_result_free(&plain);
    free(T);
    sw_character_free(&c);
}

SW_TEST_MAIN(CASE(rounds_add_the_poses_the_blob_gets_wrong_and_solve_only_those),
             CASE(an_adaptive_rebake_that_changes_only_the_cubature_solves_nothing),
             CASE(bad_loop_parameters_and_extra_poses_are_named))
