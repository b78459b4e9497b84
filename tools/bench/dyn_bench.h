/* sinew-bench --dynamic: the runtime in dynamic mode (SINEW_STEP_DYNAMIC) against the
 * reference's backward-Euler run of the same clip, with the same time step, damping and
 * masses, and the figures the dynamics issue asks of them (definitions in
 * sinew-bench.c's header comment).
 *
 * Both runs start settled at the clip's first frame: the reference from its quasistatic
 * solution there at zero velocity, the runtime from its quasistatic q there with two
 * dynamic steps at that pose (the second fills the pose history with T_0 twice, so the
 * next step sees the bone start from rest, as the reference's driven vertices do). Then
 * both step frames 1 .. F-1 and hold the last pose for H more frames at h = 1 / fps. */
#ifndef SW_DYN_BENCH_H
#define SW_DYN_BENCH_H

#include "fullsim.h"
#include "sinew/sinew.h"

typedef struct sw_dyn_bench {
    int frames, hold_frames;
    double dt, rayleigh_alpha, rayleigh_beta; /* what both runs used */
    double err_dynamic;                       /* correction error over the clip's frames */
    double err_dynamic_hold;                  /* the same over the hold frames */
    /* the reference's own spread, by the same formula: a reference solved to Newton and PCG
       tolerances 100 times tighter, from the same start, against the reference (over the
       clip, over the hold): how well the reference's trajectory is defined, a floor under
       err_dynamic that no runtime can go below */
    double err_dynamic_ref[2];
    double err_dynamic_tight; /* err_dynamic against that tighter reference */
    double overshoot_sub, overshoot_full, overshoot_ratio;
    /* the hold frame at which the surface first swings back through its rest at the held
       pose (interpolated; NaN: it never does), about a quarter of its period after the stop */
    double swing_sub, swing_full;
    double settle_sub, settle_full; /* the surface's mass-weighted RMS motion over the last
                                       hold step: how far from settled the end still is */
    double err_increment;           /* with the reference's quasistatic clip: |d_sub - d_full|_M /
                                       |d_full|_M over frames 1 .. F+H-1, d = dynamic - quasistatic
                                       shape (the runtime's d against a quasistatic instance): the
                                       error of the dynamics alone, without the subspace's static
                                       error (NaN without it) */
    double increment_rms;           /* |d_full|_M RMS a frame per unit mass: how dynamic it is */
    /* |d_sub|_M / |d_full|_M and the cosine between them (M inner product, NaN without the
       quasistatic clip): how much of the reference's dynamics the runtime makes, and whether
       in its direction (err_increment mixes the two) */
    double increment_ratio, increment_cos;
    double full_ms, sub_ms; /* median ms a dynamic step, beside the reference's */
    int ref_failed, ref_unconverged, ref_unsettled, sub_failed;
    /* the runtime's steps with each status flag: the bounds limited the state, a pose
       jump, the energy guard, Newton converged */
    int sub_limited, sub_teleport, sub_guard, sub_converged;
} sw_dyn_bench;

/* Runs both over the character's clip plus hold_frames (>= 2) held frames. fp gives the
 * reference's solver options (threads, solver, Hessian, contact rounds); its integrator,
 * dt and Rayleigh coefficients are set here: backward Euler, 1 / clip fps, the blob's. */
sinew_result sw_dyn_bench_run(const sw_character *ch, const sinew_blob *blob,
                              const sw_fullsim_params *fp, int hold_frames, const double *full_qs,
                              sw_dyn_bench *out, sw_error *err);

/* The cost of a dynamic step against a quasistatic one of the same blob, in the same run:
 * two instances, one in each mode, take turns playing the clip's first `frames` poses (a
 * first play each untimed, then `passes` timed); each mode's median over the frames of
 * each frame's least ms (pose and step), and its cubature passes and factorisations a
 * step over the first timed play. */
typedef struct sw_dyn_cost {
    double qs_ms, dyn_ms;
    double qs_evals, dyn_evals, qs_factors, dyn_factors;
    long failed; /* steps of either instance that did not return SINEW_OK */
} sw_dyn_cost;

sinew_result sw_dyn_bench_cost(const sinew_blob *blob, const sw_clip *clip, int frames, int passes,
                               sw_dyn_cost *out, sw_error *err);

#endif
