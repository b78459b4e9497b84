/* Small helpers shared by the command-line tools: strict integer arguments, medians, and
 * what every tool does with --help, with an argument it cannot take and with a failure. */
#ifndef SW_TOOL_COMMON_H
#define SW_TOOL_COMMON_H

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sinew/sinew.h"
#include "sw_error.h"

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

/* A step's wall time in ms: the sum of its phases in sinew_step_stats. */
static inline double sw_step_ms(const sinew_step_stats *st) {
    return st->ms_skin + st->ms_contact + st->ms_dynamics + st->ms_world + st->ms_oracle +
           st->ms_solve + st->ms_output;
}

/* The folder of the real assets: $SINEW_DATA_DIR, else the build's shared data folder. */
static inline const char *sw_tool_data_dir(void) {
    return getenv("SINEW_DATA_DIR") ? getenv("SINEW_DATA_DIR") : SINEW_SHARED_DATA_DIR;
}

/* Parses all of s as a base-10 integer in [lo, hi] into *out; 0 when it is not one. */
static inline int sw_parse_int(const char *s, int lo, int hi, int *out) {
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || end == s || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

/* Parses flag's value s as an integer in [lo, hi] into *out; otherwise names the flag, its
 * range and the value on stderr and returns 0. */
static inline int sw_tool_int(const char *tool, const char *flag, const char *s, int lo, int hi,
                              int *out) {
    if (s && sw_parse_int(s, lo, hi, out)) return 1;
    fprintf(stderr, "%s: %s wants an integer in %d..%d, got '%s'\n", tool, flag, lo, hi,
            s ? s : "(nothing)");
    return 0;
}

/* The index of v in the NULL-terminated names, or -1. */
static inline int sw_tool_choice(const char *v, const char *const *names) {
    for (int k = 0; names[k]; ++k)
        if (!strcmp(v, names[k])) return k;
    return -1;
}

/* Parses flag's value s as a finite number with lo < value < hi (open bounds) into *out;
 * otherwise names the flag, its range and the value on stderr and returns 0. */
static inline int sw_tool_real(const char *tool, const char *flag, const char *s, double lo,
                               double hi, const char *range, double *out) {
    char *end = NULL;
    double v = s ? strtod(s, &end) : 0;
    if (s && end != s && !*end && v > lo && v < hi) {
        *out = v;
        return 1;
    }
    fprintf(stderr, "%s: %s wants a number %s, got '%s'\n", tool, flag, range, s ? s : "(nothing)");
    return 0;
}

/* mkdir -p: creates dir and its missing parents; 1 when dir is a writable folder
 * afterwards, else 0 with errno saying why (the tools check an output folder before a long
 * run). */
static inline int sw_tool_make_dirs(const char *dir) {
    char path[4096];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof path) return (errno = ENAMETOOLONG), 0;
    memcpy(path, dir, n + 1);
    for (size_t i = 1; i <= n; ++i)
        if (path[i] == '/' || path[i] == '\0') {
            char c = path[i];
            path[i] = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST) return 0;
            path[i] = c;
        }
    struct stat st;
    if (stat(dir, &st) != 0) return 0;
    if (!S_ISDIR(st.st_mode)) return (errno = ENOTDIR), 0;
    return access(dir, W_OK | X_OK) == 0;
}

/* 1 when path's extension is the first n characters of ext, case-insensitively. */
static inline int sw_tool_ext_is(const char *path, const char *ext, size_t n) {
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strlen(dot + 1) != n || n == 0) return 0;
    for (size_t i = 0; i < n; ++i)
        if ((dot[1 + i] | 0x20) != (ext[i] | 0x20)) return 0;
    return 1;
}

static inline int sw_tool_has_ext(const char *path, const char *ext) {
    return sw_tool_ext_is(path, ext, strlen(ext));
}

/* 1 when path ends (case-insensitively) with one of the space-separated extensions in
 * exts ("mesh node ele"); otherwise names the flag, the file and the accepted formats on
 * stderr and returns 0. */
static inline int sw_tool_format(const char *tool, const char *flag, const char *path,
                                 const char *exts, const char *what) {
    for (const char *e = exts; *e;) {
        size_t k = strcspn(e, " ");
        if (sw_tool_ext_is(path, e, k)) return 1;
        e += k;
        while (*e == ' ')
            ++e;
    }
    fprintf(stderr, "%s: %s '%s': not a format it reads; accepted: %s\n", tool, flag, path, what);
    return 0;
}

/* Prints s to stdout as a JSON string (quotes, backslashes and control characters
 * escaped): names from files (bones, clips) in a tool's --json line. */
static inline void sw_tool_json_string(const char *s) {
    putchar('"');
    for (; *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

static inline int sw_cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n) (sorts v in place); 0 for n <= 0. */
static inline double sw_median(double *v, int n) {
    if (n <= 0) return 0;
    qsort(v, (size_t)n, sizeof *v, sw_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Options that take a string value or set an int flag, as a tool's table. */
typedef struct sw_tool_opt {
    const char *name; /* "--out" */
    const char **str; /* a string option: receives the argument after the name */
    int *flag, value; /* or a flag: *flag = value */
} sw_tool_opt;

/* When argv[*i] names one of the n options (a string option only when its value
 * follows), takes it and its value (advancing *i) and returns 1; 0 otherwise. */
static inline int sw_tool_take(const sw_tool_opt *opts, size_t n, int argc, char **argv, int *i) {
    for (size_t k = 0; k < n; ++k) {
        if (strcmp(argv[*i], opts[k].name)) continue;
        if (!opts[k].str) return (*opts[k].flag = opts[k].value), 1;
        if (*i + 1 >= argc) return 0;
        *opts[k].str = argv[++*i];
        return 1;
    }
    return 0;
}

/* --help or -h prints the usage on stdout and exits with status 0. Returns 0 for any
 * other argument, so that it ends a tool's chain of options. */
static inline int sw_tool_help(const char *a, void (*usage)(FILE *)) {
    if (strcmp(a, "--help") && strcmp(a, "-h")) return 0;
    usage(stdout);
    exit(0);
}

/* sinew-bake and sinew-bench, for an argument they cannot take (unknown, incomplete or
 * a bad value): names it and prints the usage on stderr; returns the exit status 2. */
static inline int sw_tool_bad_arg(const char *tool, const char *a, void (*usage)(FILE *)) {
    fprintf(stderr, "%s: bad or incomplete argument '%s'\n", tool, a);
    usage(stderr);
    return 2;
}

/* sinew-fullsim and sinew-render, for an argument none of their options takes: names it
 * on stderr and returns 0 (their parse_args fails; main prints the usage). */
static inline int sw_tool_unknown_arg(const char *tool, const char *a) {
    fprintf(stderr, "%s: unknown or incomplete argument '%s'\n", tool, a);
    return 0;
}

/* A failed call: prints the printf-formatted prefix (the tool's name and what failed),
 * then "MESSAGE (RESULT)" of err and r, on stderr; returns the exit status 1. */
static inline int sw_tool_failed(sinew_result r, const sw_error *err, const char *prefix, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static inline int sw_tool_failed(sinew_result r, const sw_error *err, const char *prefix, ...) {
    va_list ap;
    va_start(ap, prefix);
    vfprintf(stderr, prefix, ap);
    va_end(ap);
    if (r == SINEW_ERROR_IO) /* its message names the system's reason: "No such file..." */
        fprintf(stderr, "%s\n", err->msg);
    else
        fprintf(stderr, "%s (%s)\n", err->msg, sinew_result_string(r));
    return 1;
}

/* The loader's last error message, kept by sw_tool_log_keep (a sinew_logger hook). */
typedef struct sw_tool_log {
    char msg[512];
} sw_tool_log;

static inline void sw_tool_log_keep(sinew_log_level level, uint32_t id, const char *message,
                                    void *user) {
    (void)id;
    sw_tool_log *l = (sw_tool_log *)user;
    if (level == SINEW_LOG_ERROR && l && message) snprintf(l->msg, sizeof l->msg, "%s", message);
}

/* sinew_blob_load of def with a logger that keeps the loader's reason; on failure prints
 * "TOOL: cannot load the blob WHAT: REASON (RESULT)" on stderr. */
static inline sinew_result sw_tool_blob_load(const char *tool, const char *what, sinew_blob_def def,
                                             sinew_blob **out) {
    sw_tool_log log;
    log.msg[0] = '\0';
    def.logger.log = sw_tool_log_keep;
    def.logger.user = &log;
    def.logger.max_level = SINEW_LOG_WARNING;
    sinew_result r = sinew_blob_load(&def, out);
    if (r != SINEW_OK)
        fprintf(stderr, "%s: cannot load the blob %s: %s (%s)\n", tool, what,
                log.msg[0] ? log.msg : "no reason given", sinew_result_string(r));
    return r;
}
#endif

/* A bake's stage progress (sw_bake_params.on_progress) on stderr: on a terminal a bar
 * redrawn in place with the time left, otherwise a plain line at every tenth; nothing for
 * a stage that ends within two seconds. */
typedef struct sw_tool_progress {
    const char *tool;
    int tty;
    char stage[32];
    int shown, tenth;
} sw_tool_progress;

static inline void sw_tool_progress_init(sw_tool_progress *tp, const char *tool) {
    memset(tp, 0, sizeof *tp);
    tp->tool = tool;
    tp->tty = isatty(STDERR_FILENO);
}

static inline void sw_tool_progress_print(void *user, const char *stage, int64_t done,
                                          int64_t total, double elapsed) {
    sw_tool_progress *tp = user;
    if (strcmp(tp->stage, stage)) {
        snprintf(tp->stage, sizeof tp->stage, "%s", stage);
        tp->shown = tp->tenth = 0;
    }
    if (elapsed < 2.0 && !tp->shown) return;
    double left = done > 0 ? elapsed * (double)(total - done) / (double)done : 0;
    if (tp->tty) {
        static const char bar[] = "##############################";
        static const char dots[] = "..............................";
        int width = 30, fill = total > 0 ? (int)(width * done / total) : width;
        fprintf(stderr, "\r%s: %-9s [%.*s%.*s] %lld/%lld  %.0f s, about %.0f s left   ", tp->tool,
                stage, fill, bar, width - fill, dots, (long long)done, (long long)total, elapsed,
                left);
        if (done >= total) fputc('\n', stderr);
    } else {
        int tenth = total > 0 ? (int)(10 * done / total) : 10;
        if (tenth <= tp->tenth) return;
        tp->tenth = tenth;
        fprintf(stderr, "%s: %-9s %3d%% (%lld/%lld), %.0f s, about %.0f s left\n", tp->tool, stage,
                10 * tenth, (long long)done, (long long)total, elapsed, left);
    }
    tp->shown = 1;
}

#ifdef SW_TOOL_CHARACTER_ARGS
/* The character inputs sinew-bake and sinew-bench share: a named scene, or files. */
#include "character_io.h"
#include "mesh_io.h"
#include "samples.h"
#include "bake.h"
#include "scene_character.h"

typedef struct sw_character_args {
    const char *tool; /* for messages */
    const char *scene, *mesh, *tgf, *weights, *clip, *data_dir;
    const char *joint_range;                 /* --joint-range: a pose or animation */
    const char *file;                        /* a rigged glTF/FBX character (positional) */
    const char *train_clips, *heldout_clips; /* its clips by name */
    double fps, height;                      /* its clip rate and scale (0: defaults) */
    int tets, frames;
    int tets_given, data_given;
    int tetgen, mesher_given; /* --mesher tetgen; --mesher at all (surfaces only) */
} sw_character_args;

/* The least --frames: the fewest clip frames a bake trains on (bake.h). */
#define SW_CHARACTER_MIN_FRAMES 4
#define SW_CHARACTER_USAGE                                                                         \
    "  FILE             a rigged glTF 2.0 (.gltf, .glb) or FBX character: its render surface\n"    \
    "                   filled with about --tets N tets, weights from the artist's, clips by\n"    \
    "                   name (default: the two longest train, the next longest is held out)\n"     \
    "  --train-clips A,B  FILE's clips to train on\n"                                              \
    "  --heldout-clips C  FILE's clips held out (never trained on)\n"                              \
    "  --fps F          FILE's clip sampling rate, 0 < F <= 1000 (default 30)\n"                   \
    "  --height H       scale FILE to H units tall, 0 < H < 1e6 (default: the file's units)\n"     \
    "  --mesher M       what fills FILE's or a surface .obj's render surface with tets:\n"         \
    "                   lattice (default; any surface, a lattice cut by the winding number)\n"     \
    "                   | tetgen (the Debian program; closed surfaces only, the boundary is\n"     \
    "                   the surface)\n"                                                            \
    "  --scene NAME     cylinder | finger | capsule (procedural samples) | elephant-cd |\n"        \
    "                   hand-libigl (real assets under --data DIR, default $SINEW_DATA_DIR or\n"   \
    "                   the build's shared data; --data only with these)\n"                        \
    "  --tets N         simulation tets of a procedural sample, a surface .obj or FILE,\n"         \
    "                   1000..2000000 (default 20000)\n"                                           \
    "  --frames F       clip frames, 4..1000000 (procedural default 30; an asset's or --clip's\n"  \
    "                   own length at most F): the bake trains on the first 60%% and holds out\n"  \
    "                   the rest, and a clip starting at rest needs 2 training frames\n"           \
    "  --mesh FILE      a tet mesh: .mesh (MEDIT) | .node/.ele (TetGen); needs --skeleton\n"       \
    "  --skeleton FILE  a .tgf skeleton (with --mesh only)\n"                                      \
    "  --weights FILE   .dmat skin weights (with --mesh only; default: computed)\n"                \
    "  --clip FILE      a .txt bone animation or a .dmat pose (with --mesh only)\n"                \
    "  --joint-range FILE  each joint's range of motion (with --mesh and no --clip): its\n"        \
    "                   largest turn in a .dmat pose or .txt bone animation bounds the\n"          \
    "                   joint sweeps and random combined poses (default: 90 degrees across\n"      \
    "                   every bone)\n"

static inline void sw_character_args_init(sw_character_args *c, const char *tool) {
    memset(c, 0, sizeof *c);
    c->tool = tool;
    c->data_dir = sw_tool_data_dir();
    c->tets = 20000;
}

/* When argv[*i] is a character option, consumes it and its value and returns 1, with
 * *ok = 0 (and a message naming the flag and its range) for a bad value; returns 0 for
 * any other argument. */
static inline int sw_character_args_take(sw_character_args *c, int argc, char **argv, int *i,
                                         int *ok) {
    const char *a = argv[*i], *next = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (a[0] != '-' && !c->file) return (c->file = a), 1; /* the glTF/FBX file */
    if (!next) return 0;
    if (!strcmp(a, "--fps"))
        return (*ok = sw_tool_real(c->tool, a, argv[++*i], 0, 1000.0000001, "in 0 < F <= 1000",
                                   &c->fps)),
               1;
    if (!strcmp(a, "--height"))
        return (*ok = sw_tool_real(c->tool, a, argv[++*i], 0, 1e6, "in 0 < H < 1e6", &c->height)),
               1;
    const char **s = !strcmp(a, "--scene")           ? &c->scene
                     : !strcmp(a, "--train-clips")   ? &c->train_clips
                     : !strcmp(a, "--heldout-clips") ? &c->heldout_clips
                     : !strcmp(a, "--mesh")          ? &c->mesh
                     : !strcmp(a, "--skeleton")      ? &c->tgf
                     : !strcmp(a, "--weights")       ? &c->weights
                     : !strcmp(a, "--clip")          ? &c->clip
                     : !strcmp(a, "--joint-range")   ? &c->joint_range
                     : !strcmp(a, "--data")          ? &c->data_dir
                                                     : NULL;
    if (s) {
        *s = argv[++*i];
        c->data_given |= s == &c->data_dir;
        return 1;
    }
    if (!strcmp(a, "--mesher")) {
        const char *m = argv[++*i];
        *ok = !strcmp(m, "lattice") || !strcmp(m, "tetgen");
        if (!*ok) fprintf(stderr, "%s: --mesher takes lattice or tetgen, not '%s'\n", c->tool, m);
        c->tetgen = *ok && !strcmp(m, "tetgen");
        c->mesher_given = 1;
        return 1;
    }
    if (!strcmp(a, "--tets")) {
        c->tets_given = 1;
        return (*ok = sw_tool_int(c->tool, a, argv[++*i], 1000, 2000000, &c->tets)), 1;
    }
    if (!strcmp(a, "--frames"))
        return (*ok = sw_tool_int(c->tool, a, argv[++*i], SW_CHARACTER_MIN_FRAMES, 1000000,
                                  &c->frames)),
               1;
    return 0;
}

static inline int sw_character_is_sample(const char *name) {
    for (const char *const *n = sw_sample_names(); *n; ++n)
        if (!strcmp(*n, name)) return 1;
    return 0;
}

/* A glTF/FBX FILE: its format, and no option of the other inputs (each named). */
static inline int sw_scene_file_args_valid(const sw_character_args *c) {
    const char *opts[] = {c->tgf,
                          c->weights,
                          c->clip,
                          c->data_given ? c->data_dir : NULL,
                          c->frames ? "" : NULL,
                          c->joint_range},
               *names[] = {"--skeleton", "--weights", "--clip",
                           "--data",     "--frames",  "--joint-range"};
    for (int k = 0; k < 6; ++k)
        if (opts[k]) {
            fprintf(stderr,
                    "%s: %s does not apply to a glTF/FBX FILE (it brings its skeleton, weights "
                    "and clips; choose clips with --train-clips, --heldout-clips)\n",
                    c->tool, names[k]);
            return 0;
        }
    return sw_tool_format(c->tool, "FILE", c->file, "glb gltf fbx", ".glb, .gltf (glTF 2.0), .fbx");
}

/* Exactly one of FILE, --scene and --mesh, --mesh needs --skeleton, and no option that
 * does not apply to the chosen input (each named on stderr); 1 when valid. */
static inline int sw_character_args_valid(const sw_character_args *c) {
    const char *t = c->tool;
    if (!!c->scene + !!c->mesh + !!c->file != 1) {
        fprintf(stderr,
                "%s: give one character: a glTF/FBX FILE, --scene NAME or --mesh (with "
                "--skeleton)\n",
                t);
        return 0;
    }
    if (c->file) return sw_scene_file_args_valid(c);
    if (c->mesher_given && !(c->mesh && sw_tool_has_ext(c->mesh, "obj"))) {
        fprintf(stderr,
                "%s: --mesher applies only to a render surface to fill: a glTF/FBX FILE or "
                "--mesh FILE.obj\n",
                t);
        return 0;
    }
    if (c->train_clips || c->heldout_clips || c->fps > 0 || c->height > 0) {
        fprintf(stderr,
                "%s: %s applies only to a glTF/FBX FILE (the clips are chosen by name there)\n", t,
                c->train_clips     ? "--train-clips"
                : c->heldout_clips ? "--heldout-clips"
                : c->fps > 0       ? "--fps"
                                   : "--height");
        return 0;
    }
    if (c->scene) {
        const char *files[] = {c->tgf, c->weights, c->clip, c->joint_range},
                   *names[] = {"--skeleton", "--weights", "--clip", "--joint-range"};
        for (int k = 0; k < 4; ++k)
            if (files[k]) {
                fprintf(stderr,
                        "%s: %s does not apply to --scene (the scene brings its own); it "
                        "goes with --mesh\n",
                        t, names[k]);
                return 0;
            }
        int sample = sw_character_is_sample(c->scene);
        if (!sample && c->tets_given) {
            fprintf(stderr,
                    "%s: --tets does not apply to scene '%s' (a real asset with its own mesh); "
                    "it sets a procedural sample's resolution\n",
                    t, c->scene);
            return 0;
        }
        if (sample && c->data_given) {
            fprintf(stderr,
                    "%s: --data does not apply to scene '%s' (a procedural sample); it locates "
                    "the real assets\n",
                    t, c->scene);
            return 0;
        }
        return 1;
    }
    if (!c->tgf) {
        fprintf(stderr, "%s: --mesh needs --skeleton\n", t);
        return 0;
    }
    int surface = sw_tool_has_ext(c->mesh, "obj");
    if ((c->tets_given && !surface) || c->data_given) {
        fprintf(stderr, "%s: %s does not apply to --mesh %s (it goes with --scene%s)\n", t,
                c->tets_given ? "--tets" : "--data", surface ? "FILE.obj" : "with a tet mesh",
                c->tets_given ? " or a surface .obj" : "");
        return 0;
    }
    if (surface && c->weights) {
        fprintf(stderr,
                "%s: --weights does not apply to a surface --mesh (the bake computes "
                "heat-diffusion weights for the tets it generates)\n",
                t);
        return 0;
    }
    if (c->joint_range && c->clip) {
        fprintf(stderr,
                "%s: --joint-range does not apply with --clip (the clip's training frames "
                "bound the joint sweeps)\n",
                t);
        return 0;
    }
    if (c->frames && !c->clip) {
        fprintf(stderr,
                "%s: --frames does not apply to --mesh without --clip (it bounds the clip's "
                "frames)\n",
                t);
        return 0;
    }
    return sw_tool_format(t, "--mesh", c->mesh, "mesh node ele obj",
                          ".mesh (MEDIT), .node or .ele (TetGen), .obj (a render surface)") &&
           sw_tool_format(t, "--skeleton", c->tgf, "tgf", ".tgf") &&
           (!c->weights || sw_tool_format(t, "--weights", c->weights, "dmat", ".dmat")) &&
           (!c->clip || sw_tool_format(t, "--clip", c->clip, "txt dmat",
                                       ".txt (bone animation), .dmat (pose quaternions)")) &&
           (!c->joint_range || sw_tool_format(t, "--joint-range", c->joint_range, "txt dmat",
                                              ".txt (bone animation), .dmat (pose quaternions)"));
}

/* What a glTF/FBX FILE became (the mesher's lattice, the material, the clip split). */
static inline void sw_tool_print_scene(const char *tool, const sw_character *ch,
                                       const sw_clip_split *clips,
                                       const sw_scene_character_info *in, const sw_quality *q) {
    fprintf(stderr, "%s: render mesh %d vertices, %d triangles; ", tool, in->render_verts,
            in->render_tris);
    if (in->mesh.mesher == SW_MESHER_TETGEN)
        fprintf(stderr, "tetgen: %d tets, volume bound %.4g, %d run(s), %.2f s", ch->mesh.ntets,
                in->mesh.tetgen.max_volume, in->mesh.tetgen.runs, in->mesh.tetgen.seconds);
    else
        fprintf(stderr, "lattice spacing %.4g, %d piece(s)", in->mesh.lattice.spacing,
                in->mesh.lattice.components);
    fprintf(stderr,
            " (%d anchored); size %.4g (cube root of the volume), E %.4g, nu %.3g, density %.4g; "
            "%d bone(s) skin no vertex most and drive none\n",
            in->anchored_components, in->size, ch->youngs, ch->poisson, ch->density,
            in->undriven_bones);
    fprintf(stderr,
            "%s: mesh quality: dihedral angles %.1f..%.1f degrees, %d sliver(s) under 5 degrees, "
            "%d inverted, %d degenerate\n",
            tool, q->min_dihedral_deg, q->max_dihedral_deg, q->slivers, q->inverted, q->degenerate);
    fprintf(stderr, "%s: clips: training", tool);
    for (int32_t i = 0; i < clips->ntrain; ++i)
        fprintf(stderr, "%s %s (%d frames)", i ? "," : "", clips->train_names[i],
                clips->train[i].nframes);
    fprintf(stderr, "; held out");
    for (int32_t i = 0; i < clips->nheldout; ++i)
        fprintf(stderr, "%s %s (%d frames)", i ? "," : "", clips->heldout_names[i],
                clips->heldout[i].nframes);
    if (clips->nheldout == 0) fprintf(stderr, " the last part of the training clip");
    fprintf(stderr, "\n");
}

/* A FILE's clips for the bake: its training and held-out clips, each its own path
 * (bake.h). A file of one clip (nothing held out, no --train-clips) is split as a
 * single clip is (the character's clip then): its last part held out. */
static inline void sw_tool_bake_clips(const sw_character_args *c, const sw_clip_split *clips,
                                      sw_bake_params *p) {
    if (clips->ntrain == 0 || (clips->nheldout == 0 && !c->train_clips)) return;
    p->train_clips = clips->train;
    p->ntrain_clips = clips->ntrain;
    p->heldout_clips = clips->heldout;
    p->nheldout_clips = clips->nheldout;
}

/* Builds the character into *ch (zeroed first; err cleared first); a FILE's clip split
 * into *clips and what its import did into *info (both may be NULL; zeroed for the other
 * inputs). When the asset has no
 * skin weights of its own (files without --weights, or an asset folder that ships none)
 * they are dropped, so that the bake computes heat-diffusion weights. */
static inline sinew_result sw_character_args_make(const sw_character_args *c, sw_character *ch,
                                                  sw_clip_split *clips,
                                                  sw_scene_character_info *info, sw_error *err) {
    int computed = 0;
    sw_error_clear(err);
    memset(ch, 0, sizeof *ch);
    if (clips) memset(clips, 0, sizeof *clips);
    if (c->file) {
        sw_scene_character_options o = {
            c->tets,        c->fps,           c->height,
            c->train_clips, c->heldout_clips, c->tetgen ? SW_MESHER_TETGEN : SW_MESHER_LATTICE};
        return sw_character_from_scene(c->file, &o, ch, clips, info, err);
    }
    sinew_result r =
        c->scene ? sw_scene_make(c->scene, c->tets, c->frames, c->data_dir, ch, &computed, err)
        : sw_tool_has_ext(c->mesh, "obj")
            ? sw_character_from_surface(c->mesh, c->tets,
                                        c->tetgen ? SW_MESHER_TETGEN : SW_MESHER_LATTICE, c->tgf,
                                        c->clip, c->frames, ch, NULL, err)
            : sw_character_from_files(c->mesh, c->tgf, c->weights, c->clip, c->frames, ch, err);
    if (r == SINEW_OK && (computed || (c->mesh && !c->weights))) sw_weights_free(&ch->weights);
    if (r == SINEW_OK && c->joint_range && (r = sw_character_read_range(c->joint_range, ch, err)))
        sw_character_free(ch);
    return r;
}
#endif

#ifdef SW_TOOL_REFERENCE_ARGS
/* The full-space reference's solver options, shared by sinew-fullsim, sinew-bench and
 * sinew-bake. */
#include "fullsim.h"

#define SW_REFERENCE_USAGE                                                                         \
    "  --solver S          the reference's linear solver: auto (default) | cholmod | pcg\n"        \
    "  --contact-rounds R  the round cap, 1..100 (default 60)\n"                                   \
    "  --set-check C       on (default) | off: end a round's Newton once its contact set\n"        \
    "                      would change\n"                                                         \
    "  --hessian M         adaptive (default) | projected | exact element Hessians\n"

/* When argv[*i] is a reference option, consumes it and its value and returns 1, with
 * *ok = 0 (and a message) for a bad value; returns 0 for any other argument. */

static inline int sw_reference_args_take(sw_fullsim_params *p, int argc, char **argv, int *i,
                                         int *ok) {
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (!v) return 0;
    /* in enum order, by the names the summaries print (fullsim.h) */
    const char *const solvers[] = {sw_linear_solver_name(SW_SOLVER_AUTO),
                                   sw_linear_solver_name(SW_SOLVER_CHOLMOD),
                                   sw_linear_solver_name(SW_SOLVER_PCG), NULL};
    const char *const hessians[] = {sw_hessian_mode_name(SW_HESSIAN_ADAPTIVE),
                                    sw_hessian_mode_name(SW_HESSIAN_PROJECTED),
                                    sw_hessian_mode_name(SW_HESSIAN_EXACT), NULL};
    static const char *const off_on[] = {"off", "on", NULL};
    int k;
    ++*i;
    if (!strcmp(a, "--solver")) {
        if ((*ok = (k = sw_tool_choice(v, solvers)) >= 0)) p->solver = (sw_linear_solver)k;
    } else if (!strcmp(a, "--hessian")) {
        if ((*ok = (k = sw_tool_choice(v, hessians)) >= 0)) p->hessian = (sw_hessian_mode)k;
    } else if (!strcmp(a, "--set-check")) {
        if ((*ok = (k = sw_tool_choice(v, off_on)) >= 0)) p->contact_set_check = k;
    } else if (!strcmp(a, "--contact-rounds")) {
        *ok = sw_parse_int(v, 1, 100, &p->contact_rounds);
    } else {
        --*i;
        return 0;
    }
    if (!*ok)
        fprintf(stderr, "%s: %s wants %s, got '%s'\n", argv[0], a,
                !strcmp(a, "--solver")      ? "one of auto | cholmod | pcg"
                : !strcmp(a, "--hessian")   ? "one of adaptive | projected | exact"
                : !strcmp(a, "--set-check") ? "on or off"
                                            : "an integer in 1..100",
                v);
    return 1;
}
#endif
