/* sinew-bench --pair: two copies of the character pressed together side by side (contact
 * between characters), the runtime against the two-body reference.
 *
 * The scene: the second copy stands beside the first along the axis across the clip's
 * bending plane (the rest bounding box's axis, other than the longest, along which the
 * clip moves the flesh least), both play the clip, and the second's root moves from
 * 1.15 to 0.85 of the thickness away, so that the two would overlap by 15% of the
 * thickness without contact. The reference solves both as one character
 * (sw_character_pair): its self-contact is the contact between them. The runtime steps
 * two instances of the blob in one world where each one's surface is a mesh collider of
 * the other (sinew_world_set_mesh_vertices after every frame, each ignoring its own),
 * without and with condensation patches (a budget of 10% of the vertices), and two lone
 * instances for the cost.
 *
 * Figures (lengths in the character's units; JSON keys as the issue names them):
 *   pen_pair_full, pen_pair_sub, pen_pair_cond  the deepest penetration of one copy into
 *       the other over the clip, by the reference's detector on every tet vertex
 *   err_pair_sub, err_pair_cond  correction error of both copies against the reference
 *   pair_cost_vs_lone  a touching pair's frame (two steps and the two surface copies, with
 *       patches) over two lone steps, medians over the frames the pair touches (either
 *       instance in contact with the other: pair_touch_frames), same run
 *   force_balance  over the frames both exert a force on the other (force_frames; with
 *       patches), the mean |F_a + F_b| / (|F_a| + |F_b|) (0: equal and opposite, 1: the same
 *       direction; each side answers the other's surface of the frame before)
 *   patch_frac_max  the largest patch as a share of the vertices */
#ifndef SW_PAIR_BENCH_H
#define SW_PAIR_BENCH_H

#include <stdio.h>

#include "fullsim.h"
#include "sinew/sinew.h"

typedef struct sw_pair_bench {
    int frames, contact_frames_full, contact_frames_sub, contact_frames_cond;
    double thickness, size;
    double pen_pair_full, pen_pair_sub, pen_pair_cond;
    double err_pair_sub, err_pair_cond;
    double full_ms, pair_ms, lone_ms, pair_cost_vs_lone;
    int touch_frames;  /* frames the pair touches (with patches): pair_ms's and lone_ms's */
    double publish_ms; /* of pair_ms: the two surface copies into the colliders */
    /* the touching pair's mean step (with patches): world detection, oracle, solve and
       output ms (sinew_step_stats), and conjugate-gradient iterations */
    double phase_ms[4], pcg_iterations;
    double force_balance, patch_frac_max;
    int force_frames; /* frames (with patches) both exerted a force on the other */
    int ref_failed, sub_failed;
} sw_pair_bench;

/* Runs the scene over the character's clip T (nf frames, 12 per bone). */
sinew_result sw_pair_bench_run(const sinew_blob *blob, const sw_character *ch, const double *T,
                               int nf, const sw_fullsim_params *fp, sw_pair_bench *out,
                               sw_error *err);

/* Its summary on f (json 0) or its JSON members, each with a leading comma. */
void sw_pair_bench_print(const sw_pair_bench *b, FILE *f, int json);

#endif
