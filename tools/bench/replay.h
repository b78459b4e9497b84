/* The bench's one replay loop: an instance steps a clip, first untimed (it settles), then
 * timed, optionally reading its surface and counting allocation and lock calls, and hands
 * each timed step's figures to the mode. sinew-bench's timing and contract count, the
 * --sc-compare and --newton-compare modes and the --world mode's timing and contract count
 * replay through it. */
#ifndef SW_BENCH_REPLAY_H
#define SW_BENCH_REPLAY_H

#include <stdint.h>

#include "rt_interpose.h"
#include "sinew/sinew.h"

typedef struct sw_replay {
    sinew_instance *inst;
    const double *T; /* the clip: 12 nbones doubles a frame */
    int nframes, nbones;
    float dt;
    float warmup_dt;  /* the untimed steps' dt (0: dt) */
    int warmup;       /* untimed steps first, at frames 0, 1, ... (mod nframes) */
    int steps;        /* timed steps after them, at frames 0, 1, ... (mod nframes) */
    int count_rt;     /* count allocation and lock calls over the timed steps */
    int post_null;    /* before each timed pose, a rejected empty pose (must not allocate) */
    float *pos, *nrm; /* when pos is set: read ns surface vertices after each timed step */
    uint32_t ns;
    /* before each timed step's pose (outside its wall time, inside the count): e.g. the
     * colliders moved to the frame; a result other than SINEW_OK ends the replay there
     * (NULL: nothing) */
    sinew_result (*before)(void *user, int step, int frame);
    /* each timed step: its index, its clip frame, its wall ms (pose, step and read) and its
     * stats (NULL: the mode needs none; then no stats are read) */
    void (*on_step)(void *user, int step, int frame, double ms, const sinew_step_stats *st);
    void *user;
    /* out */
    long warmup_failed, failed; /* steps that did not return SINEW_OK */
    sw_rt_counts counts;        /* with count_rt */
    sinew_result result;        /* SINEW_OK, or what ended the replay (before) */
} sw_replay;

/* A replay of the clip T (nframes frames of nbones bones) on inst at dt, nothing else
 * set: no untimed and no timed steps yet, no count, no read, no hooks. */
sw_replay sw_replay_clip(sinew_instance *inst, const double *T, int nframes, int nbones, float dt);

/* Runs r's untimed then timed steps. */
void sw_replay_run(sw_replay *r);

#endif
