/* The bake: a character (mesh, skeleton, weights, bone-driven vertices, clip) in, a
 * blob view out (DESIGN.md §5), as a pipeline: sw_bake runs the stages of sw_bake_stages
 * (bake.c) in order, each a file of its own that reads the state earlier stages wrote and
 * writes its own part (bake_state.h). The stages include bake_state.h, never this header:
 * it is the orchestrator's, above them. */
#ifndef SW_BAKE_H
#define SW_BAKE_H

#include "bake_eval.h"
#include "bake_params.h"

struct sw_bake_state;

/* One stage of the bake: its name (the log, the report, --json), the function that runs
 * it, its line in the log (0: none, e.g. no render mesh), whether sw_bake_solutions runs
 * it, and what it reads and writes of the state (bake_state.h's groups) and the result. */
typedef struct sw_bake_stage {
    const char *name;
    sinew_result (*run)(struct sw_bake_state *s, sw_bake_result *out, sw_error *err);
    int (*summary)(const struct sw_bake_state *s, const sw_bake_result *out, char *msg, size_t n);
    int solutions;
    const char *reads, *writes;
} sw_bake_stage;

/* The bake's stages in the order sw_bake runs them (SW_BAKE_NSTAGES). */
extern const sw_bake_stage sw_bake_stages[SW_BAKE_NSTAGES];

sinew_result sw_bake(const sw_character *c, const sw_bake_params *p, sw_bake_result *out,
                     sw_error *err);

/* Only the bake's evaluation data: the stages prepare, domains, poses and simulate of sw_bake with
 * the same parameters, filling out's ntrain, nheldout, *_unsettled, mass, train_T/x and
 * heldout_T/x exactly as sw_bake does (no view). For a blob baked elsewhere with the
 * same parameters (sinew-bench --blob), so that sw_bake_errors measures it on the very
 * poses and reference solutions its bake measured it on. */
sinew_result sw_bake_solutions(const sw_character *c, const sw_bake_params *p, sw_bake_result *out,
                               sw_error *err);

/* Whether the blob to ship is baked again on all the motion given (sw_bake_whole_clip):
 * when the bake's motion is the character's own clip, split by heldout_fraction into the
 * frames it trains on and those its held-out figures are measured on, and ship_split is
 * 0. The split measures how the blob does on motion it has not seen; the blob a game
 * ships has then no reason to leave the clip's last part out. Training clips of their
 * own (train_clips), a joint range and random poses are not split: their blob ships as
 * baked. */
int sw_bake_ships_whole_clip(const sw_character *c, const sw_bake_params *p);

/* The bake of the whole clip: sw_bake with p's parameters, but every frame of the
 * character's clip a training frame (heldout_fraction 0), the way home trained as the
 * split's default trains it (return_path), and no held-out poses to solve (its figures
 * are the split's). */
sinew_result sw_bake_whole_clip(const sw_character *c, const sw_bake_params *p, sw_bake_result *out,
                                sw_error *err);

#endif
