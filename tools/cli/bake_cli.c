#include "bake_cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "blob_write.h"

static const char *const tool = "sinew-bake";

enum { BAKE_NFLAGS = 16, RESEARCH_NFLAGS = 40 }; /* room in the groups' arrays */

#define TEXT_(x) #x
#define TEXT(x) TEXT_(x)

static const char *const SYNOPSIS =
    "sinew-bake FILE --out FILE.blob [--report DIR] [--tets N]\n"
    "                  [--train-clips A,B] [--heldout-clips C]\n"
    "       sinew-bake (FILE | --scene NAME | --mesh FILE --skeleton FILE.tgf)\n"
    "                  --out FILE.blob [bake options] [character options]\n"
    "                  [research options] [reference options]\n"
    "An artist's bake needs the rigged glTF 2.0 / FBX FILE, --out, and often --report,\n"
    "--tets and the clips (--train-clips, --heldout-clips); the rest has defaults that\n"
    "suit a character. A character's only clip is split: the figures are measured on its\n"
    "last 40%, then the blob ships trained on all of it (--ship-split: the split's).\n";

/* --selector greedy | importance | nnhtp */
static int take_selector(const char *tool, const char *flag, const char *v, void *target) {
    static const char *const names[] = {"greedy", "importance", "nnhtp", NULL};
    static const sw_cubature_selector selectors[] = {SW_CUBATURE_GREEDY, SW_CUBATURE_IMPORTANCE,
                                                     SW_CUBATURE_NNHTP};
    int k = sw_tool_choice(v, names);
    if (k < 0) {
        fprintf(stderr, "%s: %s wants greedy | importance | nnhtp, got '%s'\n", tool, flag, v);
        return 0;
    }
    *(sw_cubature_selector *)target = selectors[k];
    return 1;
}

/* --fold-share S, 0 <= S < 0.5 */
static int take_fold_share(const char *tool, const char *flag, const char *v, void *target) {
    double *s = target;
    int ok = sw_tool_real(tool, flag, v, -1, 0.5, "in 0..0.5", s);
    if (ok && *s < 0) {
        fprintf(stderr, "%s: %s wants a number in 0..0.5, got '%s'\n", tool, flag, v);
        ok = 0;
    }
    return ok;
}

/* --shard I/N, 0 <= I < N <= 100000 */
static int take_shard(const char *tool, const char *flag, const char *v, void *target) {
    sw_bake_params *p = target;
    int i = -1, n = 0, used = 0;
    if (sscanf(v, "%d/%d%n", &i, &n, &used) != 2 || v[used] != 0 || n < 1 || n > 100000 || i < 0 ||
        i >= n) {
        fprintf(stderr, "%s: %s wants I/N with 0 <= I < N <= 100000 (shard I of N), got '%s'\n",
                tool, flag, v);
        return 0;
    }
    p->shard_index = i;
    p->shard_count = n;
    return 1;
}

/* --damping ALPHA,BETA: the dynamic step's Rayleigh damping. */
static int take_damping(const char *tool, const char *flag, const char *v, void *target) {
    sw_bake_params *p = target;
    double a = NAN, b = NAN;
    int used = 0;
    if (sscanf(v, "%lf,%lf%n", &a, &b, &used) != 2 || v[used] != 0 || !(a >= 0 && a <= 1e3) ||
        !(b >= 0 && b <= 1e3)) {
        fprintf(stderr,
                "%s: %s wants ALPHA,BETA, each in 0..1000 (C = ALPHA M + BETA K), got '%s'\n", tool,
                flag, v);
        return 0;
    }
    p->rayleigh_alpha = a;
    p->rayleigh_beta = b;
    return 1;
}

/* The bake's own flags (what every bake may want), bound to o, into f; returns their
 * count. */
static size_t bake_flags(bake_options *o, sw_flag *f) {
    sw_bake_params *p = &o->p;
    const sw_flag flags[] = {
        {SW_STR("--out", &o->out_path, "FILE",
                "the blob to write (atomically: FILE.tmp, then renamed)")},
        {SW_STR("--report", &o->report_dir, "DIR",
                "write the bake report: DIR/report.html (plots of every clip\n"
                "frame's error, ranks, cubature, stage times, a contact sheet of\n"
                "held-out frames) and DIR/report.json (the same figures)")},
        {SW_STR("--cache", &p->cache_dir, "DIR",
                "keep the full-space solutions in DIR and reuse them when a\n"
                "later bake solves the same poses of the same character (a\n"
                "re-bake that changes the cubature, rank or report only)")},
        {SW_STR("--plan", &o->plan_path, "FILE",
                "write the bake's work items (each chain of full-space solves,\n"
                "named by the hash of its inputs) as a JSON manifest and exit;\n"
                "with --shard, check that FILE is this character's")},
        {SW_CALL("--shard", take_shard, p, "I/N",
                 "solve only shard I's work items (of N, 0 <= I < N) into the\n"
                 "--cache folder and exit; the plain bake with the same --cache\n"
                 "then only reduces (docs/baking.md, Baking on a farm)")},
        {SW_SET("--ship-split", &p->ship_split, 1,
                "ship the blob trained on the split of a character's only\n"
                "clip, the one the held-out figures measure (default: baked\n"
                "again on the whole clip once measured)")},
        {SW_CALL("--damping", take_damping, p, "A,B",
                 "the dynamic step's Rayleigh damping C = A M + B K, each 0..1000\n"
                 "(default 0.01,0.001); B K follows painted material")},
        {SW_INT("--threads", &p->threads, 0, 256, "T", "0..256 (default 0: all cores)")},
        {SW_SET("--force", &o->force, 1,
                "write the blob even when its training error is " TEXT(
                    SW_BAKE_MAX_TRAIN_ERROR) " or more\n"
                                             "(the share of the physics correction it misses "
                                             "on its own\n"
                                             "training poses; without --force that is an error)")},
        {SW_SET("--json", &o->json, 1, "one JSON object with the figures as the last stdout line")},
    };
    _Static_assert(SW_FLAGS_N(flags) <= BAKE_NFLAGS, "room for the flags");
    memcpy(f, flags, sizeof flags);
    return SW_FLAGS_N(flags);
}

/* The model's knobs, for studying the method, bound to o, into f; returns their count. */
static size_t research_flags(bake_options *o, sw_flag *f) {
    static const char *const eval_modes[] = {"pose-space", "pose-pairs", NULL};
    sw_bake_params *p = &o->p;
    sw_adaptive_params *ad = &o->ad;
    const sw_flag flags[] = {
        {SW_CALL("--selector", take_selector, &p->selector, "S",
                 "cubature selector: greedy | importance | nnhtp (default)")},
        {SW_REAL("--tol", &p->cubature_tol, 0, 1, "in the open range 0..1", "T",
                 "cubature fit tolerance, 0 < T < 1 (default 0.05)")},
        {SW_INT("--max-rank", &p->max_rank, 1, 1024, "R",
                "basis rank per domain, 1..1024 (default 30)")},
        {SW_REAL("--pca-strain", &p->pca_strain, -1e-300, nextafter(1.0, 2.0), "in 0..1", "S",
                 "the basis's PCA in an inner product that is the share S of the\n"
                 "snapshots' rest strain energy, 0..1 (default 0: the plain PCA)")},
        {SW_CALL("--fold-share", take_fold_share, &p->fold_share, "S",
                 "a bone whose tets hold less than S of the mesh's volume\n"
                 "joins its parent's domain, 0..0.5 (default 0: off; 0.03\n"
                 "folds the elephant's 24 bones into 11 domains)")},
        {SW_REAL("--spring-k", &p->spring_k, 0, INFINITY, "above 0", "K",
                 "interface spring stiffness, K > 0 (default: of 20, 10, 5 and\n"
                 "2.5 E h the one with the lowest training error)")},
        {SW_SET("--compare-cubature", &p->compare_selectors, 1,
                "also train the other two selectors on the same data and\n"
                "report each one's tets, seconds and worst fit")},
        {SW_SET("--no-self-contact", &p->self_contact, 0,
                "no self-contact in the training simulations")},
        {SW_SET("--return-path", &p->return_path, 1,
                "also train on the way home: from the first training clip's\n"
                "last frame, its earlier frames backwards, each bent less than\n"
                "the one before (a fold keeps its branch on the way out); by\n"
                "default on where the held-out frames continue the training\n"
                "clip (a --clip or a file's one clip split 60/40), off for\n"
                "--train-clips")},
        {SW_SET("--no-return-path", &p->return_path, 0, "never train on the way home")},
        {SW_SET("--pair-sweeps", &p->pair_sweeps, 1,
                "also train on every joint swept together with its parent\n"
                "joint (combinations the single-joint sweeps never show); by\n"
                "default on with --joint-range")},
        {SW_SET("--no-pair-sweeps", &p->pair_sweeps, 0, "never the pair sweeps")},
        {SW_SET("--no-sibling-sweeps", &p->sibling_sweeps, 0,
                "do not train on two sibling joints whose flesh meets\n"
                "swept together (by default each such pair is: the flesh\n"
                "between them shears with the difference of their bends)")},
        {SW_INT("--adaptive", &ad->rounds, 0, SW_ADAPTIVE_MAX_ROUNDS, "R",
                "then up to R rounds that each add the K (default 8) of C\n"
                "(default 64) random combined poses the blob steps worst (the\n"
                "full-space force its state leaves over plain skinning's) to\n"
                "the training poses and bake again, until B poses (default 32)\n"
                "are added or the held-out error is at most E")},
        {SW_INT("--adaptive-add", &ad->add, 1, 100000, "K", "poses added a round, 1..100000")},
        {SW_INT("--adaptive-candidates", &ad->candidates, 1, 100000, "C",
                "candidate poses scored a round, 1..100000")},
        {SW_INT("--adaptive-budget", &ad->budget, 0, 1000000, "B",
                "poses added in all at most, 0..1000000")},
        {SW_REAL("--adaptive-target", &ad->target, 0, 1, "in 0..1", "E",
                 "stop once the held-out error is at most E, 0 < E < 1")},
        {SW_INT("--heldout-steps", &p->heldout_steps, 1, 64, "S",
                "without a clip, the 10 random held-out poses are each\n"
                "reached from the one before in S held-out poses, 1..64\n"
                "(default 4; the reference depends on the path)")},
        {SW_INT("--random-poses", &p->random_poses, 1, 10000, "N",
                "without a clip, N random held-out poses, 1..10000\n"
                "(default 10; more define the held-out figure better)")},
        {SW_INT("--seed", &o->seed, 0, 2147483647, "S",
                "the bake's random draws (held-out poses, adaptive candidates,\n"
                "cubature candidates), 0..2147483647 (default 1592614637)"),
         .given = &o->seed_given},
        {SW_SET("--contact-modes", &p->contact_modes, 1,
                "also the static responses to the training poses' self-contact\n"
                "forces in the basis (thesis 3.3.1; a higher rank)")},
        {SW_REAL("--contact-tol", &p->contact_cubature_tol, -1e-300, 1, "in 0 <= T < 1", "T",
                 "per pair of domains, each training pose's contact pairs are\n"
                 "cut to a cubature that keeps their reduced force to T,\n"
                 "0 <= T < 1 (default 0.05; 0: every pair kept)")},
        {SW_SET("--no-pose-force", &p->pose_force, 0,
                "no pose-space equilibrium force in the blob (by default each\n"
                "training pose carries the reduced force that makes its\n"
                "projected solution the runtime's equilibrium there,\n"
                "interpolated between poses)")},
        {SW_CHOICE("--eval-self-contact", &o->eval_pairs, eval_modes, "M",
                   "the runtime's self-contact mode the bake's errors are\n"
                   "measured in: pose-space (default) or pose-pairs")},
        {SW_INT("--reference-spread", &o->spread_every, 1, 1000000, "K",
                "at every K-th held-out pose, three more full-space\n"
                "solves: from plain skinning, from the reference and from the\n"
                "runtime's state; how far they land from the reference says\n"
                "how well the reference is defined, and whether the runtime\n"
                "sits by another equilibrium")},
        {SW_SET("--inertia-modes", &p->inertia_modes, 1,
                "for the dynamic step: basis modes for the inertia of the\n"
                "bones' accelerations (the lowest vibration modes of the static\n"
                "responses to them that swing at the clips' frame rate, at most\n"
                "3 a domain), so that the flesh lags and overshoots as the\n"
                "reference does; a stiff character gets none")},
    };
    _Static_assert(SW_FLAGS_N(flags) <= RESEARCH_NFLAGS, "room for the flags");
    memcpy(f, flags, sizeof flags);
    return SW_FLAGS_N(flags);
}

int bake_parse_args(int argc, char **argv, bake_options *o) {
    memset(o, 0, sizeof *o);
    sw_character_args_init(&o->ca, tool);
    o->p = sw_bake_params_default();
    o->reference = sw_fullsim_params_default();
    o->p.reference = &o->reference;
    o->ad = sw_adaptive_params_default();
    o->ad.rounds = 0;
    o->p.progress = 1;
    sw_flag character[SW_CHARACTER_NFLAGS], bake[BAKE_NFLAGS], research[RESEARCH_NFLAGS],
        reference[SW_REFERENCE_NFLAGS];
    const sw_flag_group groups[] = {
        {"bake:", bake, bake_flags(o, bake)},
        {"character:\n" SW_CHARACTER_FILE_USAGE, character, sw_character_flags(&o->ca, character)},
        {"research (the model's knobs, for studying the method):", research,
         research_flags(o, research)},
        {"reference options (every full-space solve of the bake; a change of them\n"
         "solves the poses again instead of reading the cache):",
         reference, sw_reference_flags(&o->reference, reference)}};
    const sw_tool_cli cli = {tool,
                             SYNOPSIS,
                             groups,
                             SW_FLAGS_N(groups),
                             "exit status: 0 blob written, 1 failed, 2 bad arguments\n",
                             &o->ca.file,
                             1};
    int status = sw_flags_parse(&cli, argc, argv);
    if (status) return status;
    if (o->seed_given) o->p.seed = (uint64_t)o->seed;
    if (o->p.shard_count > 0 && !o->p.cache_dir) {
        fprintf(stderr, "%s: --shard puts its work in the shared cache: give --cache DIR\n", tool);
        return 2;
    }
    const int farm = o->plan_path || o->p.shard_count > 0;
    o->p.plan_only = o->plan_path && o->p.shard_count == 0;
    if (farm && (o->out_path || o->report_dir)) {
        fprintf(stderr, "%s: --plan and --shard write no blob or report: drop --out, --report\n",
                tool);
        return 2;
    }
    if (!o->out_path && !farm) {
        fprintf(stderr, "%s: give --out FILE.blob\n", tool);
        sw_flags_usage(&cli, stderr);
        return 2;
    }
    if (!sw_character_args_valid(&o->ca)) return 2;
    /* the report's folder before the long run: an unwritable one is an error now */
    const char *dirs[2][2] = {{"--report", o->report_dir}, {"--cache", o->p.cache_dir}};
    for (int k = 0; k < 2; ++k)
        if (dirs[k][1] && !sw_tool_make_dirs(dirs[k][1])) {
            fprintf(stderr, "%s: %s '%s': cannot create or write the folder: %s\n", tool,
                    dirs[k][0], dirs[k][1], strerror(errno ? errno : EACCES));
            return 1;
        }
    /* the blob's path too: a folder that is missing, or a path that is a folder */
    sw_error err;
    const int plan_out = o->plan_path && o->p.shard_count == 0;
    sinew_result r = sw_write_file_check(plan_out      ? o->plan_path
                                         : o->out_path ? o->out_path
                                                       : "",
                                         &err);
    if (r != SINEW_OK && (plan_out || o->out_path))
        return sw_tool_failed(r, &err, "%s: %s: ", tool, plan_out ? "--plan" : "--out");
    return 0;
}
