/* sinew-bench's command line: its flags as tables (tool_flags.h), its usage made from
 * them, and the checks of their combinations. */
#ifndef SW_BENCH_CLI_H
#define SW_BENCH_CLI_H

#define SW_TOOL_CHARACTER_ARGS
#define SW_TOOL_REFERENCE_ARGS
#include "tool_common.h"

#include "bench_mode.h"
#include "fullsim.h"

/* The command line. */
typedef struct bench_options {
    sw_character_args ca;
    sw_fullsim_params ref_solver; /* the reference's options */
    const char *blob_path, *out_dir, *world_path;
    int json, full_frames, contract_steps, threads, bake_errors, timing_passes;
    int dynamic, hold_frames, instances, patch_budget;
    int self_mode; /* sinew_self_contact */
    int sc_compare, error_gap, newton_compare, novel, pair, lod;
    int ref_self_contact; /* the reference's self-contact: 1 (default) or 0 */
    sw_cond_bench_params cond;
} bench_options;

/* Parses argv into *o (the flags' defaults first): 0, or the exit status after a message
 * (2 bad arguments, 1 an output folder it cannot create). */
int bench_parse_args(int argc, char **argv, bench_options *o);

#endif
