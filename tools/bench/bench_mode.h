/* sinew-bench's optional modes behind one interface: each is asked for by its flag, runs
 * on what the bench has made (the character, the blob, the reference's run of the clip),
 * prints its summary on stderr and adds its members to the bench's JSON line. The bench
 * runs the modes it was asked for in the table's order (sw_bench_modes). */
#ifndef SW_BENCH_MODE_H
#define SW_BENCH_MODE_H

#include "bake.h"
#include "crowd_bench.h"
#include "dyn_bench.h"
#include "gap_bench.h"
#include "lod_bench.h"
#include "newton_bench.h"
#include "novel_bench.h"
#include "pair_bench.h"
#include "sc_bench.h"
#include "world_bench.h"

/* --lod: off, every level's figures, and (with --instances) the crowd's levels by
 * distance too. */
enum { SW_BENCH_LOD_OFF, SW_BENCH_LOD_LEVELS, SW_BENCH_LOD_AUTO };

/* What the modes read (set by sinew-bench before they run) and what they found. */
typedef struct sw_bench_ctx {
    const sw_character *ch;
    const sinew_blob *blob;
    const sw_bake_result *res;   /* the bake's poses and solutions (--error-gap) */
    const sw_fullsim_params *fp; /* the reference's parameters */
    const double *full_x;        /* the reference's solutions of the first kf clip frames */
    int nf, kf;                  /* clip frames; frames the reference solved */
    int clip_frames;             /* --frames (0: the asset's own) */
    int threads, contract_steps;
    sinew_self_contact self_mode;
    /* the modes' flags */
    const char *world_path;
    const sw_cond_bench_params *cond;
    int dynamic, hold_frames, instances, sc_compare, newton_compare, error_gap, novel, pair, lod;
    const sw_bake_result *err_res; /* the poses and solutions the errors are of (--lod) */
    int timing_passes;
    /* found */
    long failed; /* the modes' failed steps */
    sw_world_bench wb;
    sw_dyn_bench db;
    sw_dyn_cost dcost;
    sw_crowd_bench cb;
    sw_sc_bench scb;
    sw_newton_bench nwb;
    sw_gap_bench gap;
    sw_novel_bench nvb;
    sw_pair_bench pb;
    sw_lod_bench lb;
} sw_bench_ctx;

typedef struct sw_bench_mode {
    const char *name; /* its flag */
    int (*wanted)(const sw_bench_ctx *c);
    /* runs it, adds its failed steps to c->failed and prints its summary on stderr; on
     * failure err says why, after "sinew-bench: " and fail */
    sinew_result (*run)(sw_bench_ctx *c, sw_error *err);
    void (*json)(const sw_bench_ctx *c); /* its members of the JSON line */
    const char *fail;
} sw_bench_mode;

extern const sw_bench_mode sw_bench_modes[];
extern const int sw_bench_nmodes;

#endif
