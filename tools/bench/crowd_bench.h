/* sinew-bench --instances N: a crowd of N quasistatic instances of one blob stepped each
 * frame over the character's clip, as a host's worker model steps them: plain pthreads
 * created once, each taking the frame's instances one at a time from a shared atomic
 * counter until none is left, then a barrier. Instance i plays the clip offset by
 * i * (clip frames) / N frames, so the crowd is not in lockstep (fixed shares left one
 * worker with more of the clip's costly contact frames than the other). The
 * crowd runs twice, on 1 thread and on T; a lone instance (instance 0's motion, alone)
 * is timed in the same run for comparison. The instances keep no scratch of their own
 * (def.shared_workspace): each thread steps those it takes in its workspace. */
#ifndef SW_CROWD_BENCH_H
#define SW_CROWD_BENCH_H

#include "sinew/sinew.h"
#include "sw_error.h"
#include "sw_mesh.h"

typedef struct sw_crowd_bench {
    int instances, threads;    /* N and T (T resolved: 0 asked for all cores) */
    int warmup_frames, frames; /* untimed then timed frames of each run */
    double ms;                 /* median wall ms a frame, all N on T threads */
    double ms_1thread;         /* the same on 1 thread */
    double lone_ms;            /* mean ms of a lone instance's frame (pose, step, read) over
                                  the timed frames: a crowd frame holds one frame of every
                                  part of the clip, so the mean, not the median, compares */
    double lone_median_ms;     /* the median of the same frames */
    double us_per_instance;    /* 1000 ms / N */
    double scaling;            /* ms_1thread / ms */
    double vs_lone;            /* (ms T / N) / lone_ms: an instance's time in the crowd */
    long failed;               /* steps that did not return SINEW_OK */
    int lod_auto;              /* levels by distance from a walking camera */
    double at_level[3];        /* instances at each level (sinew_lod), a frame's mean */
    size_t instance_bytes;     /* an instance without scratch (def.shared_workspace) */
    size_t workspace_bytes;    /* a thread's workspace */
    double crowd_bytes;        /* N instances and T workspaces */
} sw_crowd_bench;

/* Runs the crowd of `instances` (1..4096) instances of `blob` over ch's clip on 1 thread
 * and on `threads` (0: all cores). Each instance's frame is the work the bench times for
 * sub_ms: set the pose, step (dt = 1 / clip fps), read the surface's positions and
 * normals; with lod_auto, first its level of detail from its screen size
 * (sinew_lod_for_screen_size), the instances standing 1 to 40 character sizes from a
 * camera that walks a quarter of a size a frame through them. */
sinew_result sw_crowd_bench_run(const sw_character *ch, const sinew_blob *blob, int instances,
                                int threads, int lod_auto, sw_crowd_bench *out, sw_error *err);

#endif
