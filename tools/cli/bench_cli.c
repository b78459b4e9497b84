/* sinew-bench's command line (bench_cli.h). */
#include "bench_cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"

static const char *const tool = "sinew-bench";

/* --rho R[,R...]: patch radii in (0, 1], at most SW_COND_MAX_RHO. */
static int parse_rhos(const char *tool, const char *flag, const char *s, void *target) {
    (void)flag;
    sw_cond_bench_params *cp = target;
    char buf[256];
    if (strlen(s) >= sizeof buf) return sw_tool_real(tool, "--rho", "", 0, 1, "in (0, 1]", NULL);
    strcpy(buf, s);
    cp->nrho = 0;
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (cp->nrho == SW_COND_MAX_RHO) {
            fprintf(stderr, "%s: --rho takes at most %d radii\n", tool, SW_COND_MAX_RHO);
            return 0;
        }
        if (!sw_tool_real(tool, "--rho", tok, 0, 1.0000001, "in (0, 1]", &cp->rho[cp->nrho]))
            return 0;
        cp->nrho++;
    }
    return cp->nrho > 0 || sw_tool_real(tool, "--rho", s, 0, 1, "in (0, 1]", NULL);
}

/* --lod's values (SW_BENCH_LOD_*, after "off", which is no flag). */
static const char *const lod_names[] = {"off", "levels", "auto", NULL};

static const char *const SYNOPSIS =
    "sinew-bench (FILE [--tets N] [--train-clips A,B] [--heldout-clips C] |\n"
    "                    --scene NAME [--tets N] [--frames F] [--data DIR] |\n"
    "                    --mesh FILE --skeleton FILE.tgf [--weights FILE.dmat]\n"
    "                    [--clip FILE [--frames F] | --joint-range FILE])\n"
    "                   [--blob FILE [--bake-errors]]\n"
    "                   [--full-frames K] [--contract-steps S] [--threads T]\n"
    "                   [--timing-passes P]\n"
    "                   [reference options] [--out DIR]\n"
    "                   [--world FILE.json [--rho R] [--patch-budget N]]\n"
    "                   [--dynamic [--hold-frames H]] [--instances N]\n"
    "                   [--self-contact pose-space|exhaustive] [--sc-compare]\n"
    "                   [--newton-compare] [--novel] [--pair]\n"
    "                   [--error-gap] [--json]\n";

/* The bench's own flags, bound to o, into f; returns their count. */
static size_t bench_flags(bench_options *o, sw_flag *f) {
    static const char *const off_on[] = {"off", "on", NULL};
    const sw_flag flags[] = {
        {SW_STR("--blob", &o->blob_path, "FILE",
                "a blob sinew-bake wrote for this character (default: bake,\n"
                "and report the bake's err_train/err_heldout). The errors are\n"
                "then measured on the clip frames the reference solved, split\n"
                "as the bake splits a clip: err_clip_train, err_clip_heldout\n"
                "(err_source \"clip\"), not the bake's figures")},
        {SW_SET("--bake-errors", &o->bake_errors, 1,
                "with --blob: re-solve the bake's training and held-out poses\n"
                "(default bake parameters, the reference options below; as\n"
                "slow as the bake's simulate stage) and report the bake's\n"
                "err_train/err_heldout (err_source \"bake_default_poses\")")},
        {SW_INT("--full-frames", &o->full_frames, 1, 100000, "K",
                "time the reference over the first K clip frames, 1..100000\n"
                "(default: the whole clip)")},
        {SW_INT("--contract-steps", &o->contract_steps, 0, 100000000, "S",
                "steps counted for allocations and locks, 0..100000000\n(default 10000)")},
        {SW_INT("--threads", &o->threads, 0, 256, "T",
                "0..256 (default 0: all cores); also the crowd's threads")},
        {SW_INT("--timing-passes", &o->timing_passes, 1, 1000, "P",
                "play the clip P times for sub_ms and dqs_ms, each frame's\n"
                "least time of the P, 1..1000 (default 1; the errors and\n"
                "counts: the first play's; failed_steps: every play's)")},
        {SW_STR("--out", &o->out_dir, "DIR",
                "write the subspace surface of every clip frame as\n"
                "DIR/frame_NNNN.obj; with --world, the condensed run's\n"
                "(the first radius) as DIR/condensed/frame_NNNN.obj, the\n"
                "patch in red (sinew-render --frames DIR/condensed)")},
        {SW_STR("--world", &o->world_path, "F",
                "also run reference and runtime against world file F (.json,\n"
                "schema 1, samples/worlds/README.md) and report its figures;\n"
                "with a blob holding the tet mesh, also a condensed runtime\n"
                "(full-space patches at novel contact) and its figures")},
        {SW_CALL("--rho", parse_rhos, &o->cond, "R[,R...]",
                 "with --world: the patch radius in units of the rest\n"
                 "bounding-box diagonal, 0 < R <= 1 (default 0.05); several\n"
                 "(at most 8) run one condensed instance each against the\n"
                 "same reference run (the first in the top-level figures,\n"
                 "the others in cond_sweep)")},
        {SW_INT("--patch-budget", &o->patch_budget, 1, 100000000, "N",
                "with --world: max_patch_vertices (default a quarter of\nthe vertices)")},
        {SW_CHOICE("--self-contact", &o->self_mode, sw_self_contact_names, "M",
                   "pose-space (default) or exhaustive: the runtime's mode\n"
                   "(sinew_instance_def.self_contact) for the timing and errors"),
         .range = "pose-space, exhaustive or pose-pairs"},
        {SW_CHOICE("--ref-self-contact", &o->ref_self_contact, off_on, "C",
                   "on (default) | off: the full-space reference's self-contact\n"
                   "(off: what the reference does without it, e.g. how much of its\n"
                   "dynamics is contact)"),
         .range = "on or off"},
        {SW_SET("--sc-compare", &o->sc_compare, 1,
                "also time self-contact in both modes over the clip: sc_*")},
        {SW_SET("--novel", &o->novel, 1,
                "also the clip with novel self-contact (through the\n"
                "subspace, and seeding patches): pen_self_*, err_clip_*")},
        {SW_SET("--pair", &o->pair, 1,
                "also two copies pressed together side by side over the clip,\n"
                "against the two-body reference: pen_pair_*, err_pair_*,\n"
                "pair_cost_vs_lone (the tet boundary as the output surface)")},
        {SW_CHOICE("--lod", &o->lod, lod_names, "L",
                   "levels: also every level of detail the blob holds over the\n"
                   "clip, each one's step against DQS and its held-out surface\n"
                   "error (the errors' poses as err_heldout's): lod_*; auto:\n"
                   "that, and the crowd (--instances) picks each instance's\n"
                   "level from its screen size, 1 to 40 character sizes from a\n"
                   "walking camera: crowd_at_level"),
         .range = "levels or auto"},
        {SW_SET("--newton-compare", &o->newton_compare, 1,
                "also time the quasistatic step with Newton on the current\n"
                "and starting on the rest Hessian over the clip: newton_*")},
        {SW_SET("--error-gap", &o->error_gap, 1,
                "also the runtime against its basis's projection on the\n"
                "bake's held-out poses (not with --blob alone): gap_*")},
        {SW_SET("--dynamic", &o->dynamic, 1,
                "also run the runtime in dynamic mode against the reference's\n"
                "backward-Euler run of the clip (same dt, damping, masses)\n"
                "and report err_dynamic and the overshoot after the clip")},
        {SW_INT("--hold-frames", &o->hold_frames, 2, 100000, "H",
                "with --dynamic: frames holding the last pose, 2..100000\n(default 30)")},
        {SW_INT("--instances", &o->instances, 1, 4096, "N",
                "also step a crowd of N instances of the blob over the clip,\n"
                "1..4096, each offset in time, on 1 thread and on T\n"
                "(--threads) host pthreads, and report crowd_ms,\n"
                "crowd_us_per_instance, crowd_scaling, crowd_vs_lone")},
        {SW_SET("--json", &o->json, 1, "one JSON object with the figures as the last stdout line")},
    };
    memcpy(f, flags, sizeof flags);
    return SW_FLAGS_N(flags);
}

/* The flags' combinations: 0, or the exit status after a message. */
static int check_args(const bench_options *o) {
    if (!sw_character_args_valid(&o->ca)) return 2;
    if (o->error_gap && o->blob_path && !o->bake_errors) {
        fprintf(stderr,
                "%s: --error-gap needs the bake's poses: without --blob, or with "
                "--bake-errors\n",
                tool);
        return 2;
    }
    if (o->bake_errors && !o->blob_path) {
        fprintf(stderr,
                "%s: --bake-errors applies only with --blob (without --blob the bench bakes and "
                "reports the bake's own err_train/err_heldout already)\n",
                tool);
        return 2;
    }
    if (o->hold_frames && !o->dynamic) {
        fprintf(stderr, "%s: --hold-frames applies only with --dynamic\n", tool);
        return 2;
    }
    if ((o->cond.nrho > 0 || o->patch_budget > 0) && !o->world_path) {
        fprintf(stderr, "%s: --rho and --patch-budget apply only with --world\n", tool);
        return 2;
    }
    if (o->world_path &&
        !sw_tool_format(tool, "--world", o->world_path, "json", ".json (world file)"))
        return 2;
    /* the output folder before the long run: an unwritable one is an error now */
    if (o->out_dir && !sw_tool_make_dirs(o->out_dir)) {
        fprintf(stderr, "%s: --out '%s': cannot create or write the folder: %s\n", tool, o->out_dir,
                strerror(errno ? errno : EACCES));
        return 1;
    }
    return 0;
}

int bench_parse_args(int argc, char **argv, bench_options *o) {
    memset(o, 0, sizeof *o);
    sw_character_args_init(&o->ca, tool);
    o->ref_solver = sw_fullsim_params_default();
    o->contract_steps = 10000;
    o->timing_passes = 1;
    o->self_mode = SINEW_SELF_CONTACT_POSE_SPACE;
    o->ref_self_contact = 1;
    sw_flag character[SW_CHARACTER_NFLAGS], bench[32], reference[SW_REFERENCE_NFLAGS];
    const sw_flag_group groups[] = {
        {"character:\n" SW_CHARACTER_FILE_USAGE, character, sw_character_flags(&o->ca, character)},
        {"bench:", bench, bench_flags(o, bench)},
        {"reference options (the full-space run the bench times, and the full-space solves\n"
         "of a bake it runs or of --bake-errors):",
         reference, sw_reference_flags(&o->ref_solver, reference)}};
    const sw_tool_cli cli = {tool,
                             SYNOPSIS,
                             groups,
                             SW_FLAGS_N(groups),
                             "exit status: 0 done, 1 failed, 2 bad arguments\n",
                             &o->ca.file,
                             1};
    int status = sw_flags_parse(&cli, argc, argv);
    if (status) return status;
    o->cond.budget = (uint32_t)o->patch_budget;
    o->cond.out_dir = o->out_dir;
    return check_args(o);
}
