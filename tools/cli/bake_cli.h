/* sinew-bake's command line: its flags as tables (tool_flags.h), its usage made from them,
 * and the checks of their combinations. */
#ifndef SW_BAKE_CLI_H
#define SW_BAKE_CLI_H

#define SW_TOOL_CHARACTER_ARGS
#define SW_TOOL_REFERENCE_ARGS
#include "tool_common.h"

#include "bake.h"
#include "bake_adaptive.h"

/* The command line. */
typedef struct bake_options {
    sw_character_args ca;
    const char *out_path, *report_dir, *plan_path; /* --plan: the farm's manifest */
    int json, force, spread_every, seed, seed_given, eval_pairs;
    sw_bake_params p;
    sw_fullsim_params reference; /* its solver options */
    sw_adaptive_params ad;
} bake_options;

/* Parses argv into *o (the flags' defaults first): 0, or the exit status after a message
 * (2 bad arguments, 1 an output folder it cannot create). */
int bake_parse_args(int argc, char **argv, bake_options *o);

/* --plan FILE (the manifest of the bake's work items) or --shard I/N (shard I's items
 * solved into --cache) for the character ch: the exit status (bake_farm.c). */
int bake_farm(const bake_options *o, const sw_character *ch);

#endif
