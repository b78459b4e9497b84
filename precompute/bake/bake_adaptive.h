/* The adaptive training loop: a bake, then rounds that add the poses
 * the current subspace represents worst, until a held-out target or a pose budget.
 *
 * A round: `candidates` random combined poses (sw_bake_random_poses over the joints'
 * sweeps, from a seed stream of their own, so never the held-out poses) are each stepped
 * by the round's blob, quasistatic from rest as the bake's evaluation steps, and scored
 * by a proxy that needs no reference solve: the full-space elastic force left at the
 * runtime's state, over the force at plain skinning (the free vertices' |f| over the
 * same at the DQS positions; 0: the runtime reached a full-space equilibrium, 1: it
 * corrected nothing). The `add` highest are added to the training poses
 * (sw_bake_params.extra_poses, in paths from rest of about add / 2 poses, one per core)
 * and the bake runs again; its simulate stage reads every other chain from the cache (a
 * temporary one when sw_bake_params.cache_dir is NULL), so a round solves only its new
 * poses. The round after verifies the pick: the old blob's correction error on the
 * picked poses against their reference solutions (`picks_error`, next to the held-out
 * error: a proxy that finds the worst poses picks poses worse than the held-out mean).
 *
 * Stops after `rounds` rounds, when the next round would add more than `budget` poses in
 * all, or once the held-out error is at most `target` (> 0). The last bake is the result. */
#ifndef SW_BAKE_ADAPTIVE_H
#define SW_BAKE_ADAPTIVE_H

#include "bake.h"

#define SW_ADAPTIVE_MAX_ROUNDS 32

typedef struct sw_adaptive_params {
    int32_t rounds;     /* rounds of additions at most (default 4; 0: the plain bake) */
    int32_t candidates; /* candidate poses scored a round (default 64) */
    int32_t add;        /* poses added a round (default 8) */
    int32_t budget;     /* poses added in all at most (default 32) */
    double target;      /* stop once the held-out error is at most this (default 0: none) */
} sw_adaptive_params;

sw_adaptive_params sw_adaptive_params_default(void);

/* One bake of the loop and what it measured. */
typedef struct sw_adaptive_round {
    int32_t ntrain, added, rank_total; /* training poses, of them the loop's, total rank */
    double err_train, err_heldout;     /* sw_bake_errors (pose-space self-contact) */
    double proj_train, proj_heldout;   /* the basis's projection errors */
    double score_mean, score_max;      /* the proxy over this round's candidates */
    double picks_score;                /* its mean over the poses picked */
    double picks_error;                /* this blob's correction error on them (verified by
                                          the next round's reference solves; -1: none) */
    int32_t solved;                    /* poses the round's simulate stage solved */
    double seconds;                    /* the round's wall time */
} sw_adaptive_round;

typedef struct sw_adaptive_report {
    int32_t nrounds; /* bakes made: the first is the plain bake */
    sw_adaptive_round round[SW_ADAPTIVE_MAX_ROUNDS + 1];
    /* with p->plan_only or p->shard_count > 0: the round whose items `out` lists (the
       first whose items the cache did not all hold), or -1 when the cache held every
       round's (`out` then the last round's whole bake) */
    int32_t farm_round;
} sw_adaptive_report;

/* sw_bake with the loop above: `out` is the last round's bake (its training poses
 * include the loop's), `rep` every round's figures. p->progress prints a line a round.
 * A farm runs the rounds as rounds of work items (sw_bake_params.shard_count): a round's
 * items depend on the blob of the round before, so a shard reduces the rounds whose
 * items the cache holds (their bakes read every solution from it) and then plans or
 * solves its items of the first round it lacks, and stops there; the next round's
 * shards run after every shard of this one. */
sinew_result sw_bake_adaptive(const sw_character *c, const sw_bake_params *p,
                              const sw_adaptive_params *a, sw_bake_result *out,
                              sw_adaptive_report *rep, sw_error *err);

#endif
