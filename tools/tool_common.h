/* Small helpers shared by the command-line tools: strict integer arguments, medians, and
 * what every tool does with --help, with an argument it cannot take and with a failure. */
#ifndef SW_TOOL_COMMON_H
#define SW_TOOL_COMMON_H

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sw_error.h"

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

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
    fprintf(stderr, "%s (%s)\n", err->msg, sinew_result_string(r));
    return 1;
}
#endif

#ifdef SW_TOOL_CHARACTER_ARGS
/* The character inputs sinew-bake and sinew-bench share: a named scene, or files. */
#include "character_io.h"
#include "samples.h"

typedef struct sw_character_args {
    const char *scene, *mesh, *tgf, *weights, *clip, *data_dir;
    int tets, frames;
} sw_character_args;

static inline void sw_character_args_init(sw_character_args *c) {
    memset(c, 0, sizeof *c);
    c->data_dir = sw_tool_data_dir();
    c->tets = 20000;
}

/* When argv[*i] is a character option, consumes it and its value and returns 1, with
 * *ok = 0 for a bad value; returns 0 for any other argument. */
static inline int sw_character_args_take(sw_character_args *c, int argc, char **argv, int *i,
                                         int *ok) {
    const char *a = argv[*i], *next = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (!next) return 0;
    const char **s = !strcmp(a, "--scene")      ? &c->scene
                     : !strcmp(a, "--mesh")     ? &c->mesh
                     : !strcmp(a, "--skeleton") ? &c->tgf
                     : !strcmp(a, "--weights")  ? &c->weights
                     : !strcmp(a, "--clip")     ? &c->clip
                     : !strcmp(a, "--data")     ? &c->data_dir
                                                : NULL;
    if (s) {
        *s = argv[++*i];
        return 1;
    }
    if (!strcmp(a, "--tets")) return (*ok = sw_parse_int(argv[++*i], 1000, 2000000, &c->tets)), 1;
    if (!strcmp(a, "--frames")) return (*ok = sw_parse_int(argv[++*i], 2, 1000000, &c->frames)), 1;
    return 0;
}

/* Exactly one of --scene and --mesh, and --mesh needs --skeleton. */
static inline int sw_character_args_valid(const sw_character_args *c) {
    return !c->scene != !c->mesh && (!c->mesh || c->tgf);
}

/* Builds the character into *ch (zeroed first; err cleared first). When the asset has no
 * skin weights of its own (files without --weights, or an asset folder that ships none)
 * they are dropped, so that the bake computes heat-diffusion weights. */
static inline sinew_result sw_character_args_make(const sw_character_args *c, sw_character *ch,
                                                  sw_error *err) {
    int computed = 0;
    sw_error_clear(err);
    memset(ch, 0, sizeof *ch);
    sinew_result r =
        c->scene
            ? sw_scene_make(c->scene, c->tets, c->frames, c->data_dir, ch, &computed, err)
            : sw_character_from_files(c->mesh, c->tgf, c->weights, c->clip, c->frames, ch, err);
    if (r == SINEW_OK && (computed || (c->mesh && !c->weights))) sw_weights_free(&ch->weights);
    return r;
}
#endif

#ifdef SW_TOOL_REFERENCE_ARGS
/* The full-space reference's solver options, shared by sinew-fullsim, sinew-bench and
 * sinew-bake. */
#include "fullsim.h"

#define SW_REFERENCE_USAGE                                                                         \
    "  --solver S          the reference's linear solver: auto (default) | cholmod | pcg\n"        \
    "  --contact-rounds R  the round cap (default 30)\n"                                           \
    "  --hessian M         adaptive (default) | projected | exact element Hessians\n"

/* When argv[*i] is a reference option, consumes it and its value and returns 1, with
 * *ok = 0 (and a message) for a bad value; returns 0 for any other argument. */
/* The index of v in the NULL-terminated names, or -1. */
static inline int sw_tool_choice(const char *v, const char *const *names) {
    for (int k = 0; names[k]; ++k)
        if (!strcmp(v, names[k])) return k;
    return -1;
}

static inline int sw_reference_args_take(sw_fullsim_params *p, int argc, char **argv, int *i,
                                         int *ok) {
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (!v) return 0;
    /* names in enum order: sw_linear_solver, sw_hessian_mode */
    static const char *const solvers[] = {"auto", "cholmod", "pcg", NULL};
    static const char *const hessians[] = {"adaptive", "projected", "exact", NULL};
    int k;
    ++*i;
    if (!strcmp(a, "--solver")) {
        if ((*ok = (k = sw_tool_choice(v, solvers)) >= 0)) p->solver = (sw_linear_solver)k;
    } else if (!strcmp(a, "--hessian")) {
        if ((*ok = (k = sw_tool_choice(v, hessians)) >= 0)) p->hessian = (sw_hessian_mode)k;
    } else if (!strcmp(a, "--contact-rounds")) {
        *ok = sw_parse_int(v, 1, 100, &p->contact_rounds);
    } else {
        --*i;
        return 0;
    }
    if (!*ok) fprintf(stderr, "%s: %s: bad value '%s' (see --help)\n", argv[0], a, v);
    return 1;
}
#endif
