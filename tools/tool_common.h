/* Small helpers shared by the command-line tools: strict integer arguments and medians. */
#ifndef SW_TOOL_COMMON_H
#define SW_TOOL_COMMON_H

#include <errno.h>
#include <stdlib.h>

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
#endif

#ifdef SW_TOOL_CHARACTER_ARGS
/* The character inputs sinew-bake and sinew-bench share: a named scene, or files. */
#include <string.h>

#include "character_io.h"
#include "samples.h"

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

typedef struct sw_character_args {
    const char *scene, *mesh, *tgf, *weights, *clip, *data_dir;
    int tets, frames;
} sw_character_args;

static inline void sw_character_args_init(sw_character_args *c) {
    memset(c, 0, sizeof *c);
    c->data_dir = getenv("SINEW_DATA_DIR") ? getenv("SINEW_DATA_DIR") : SINEW_SHARED_DATA_DIR;
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

/* Builds the character. When the asset has no skin weights of its own (files without
 * --weights, or an asset folder that ships none) they are dropped, so that the bake
 * computes heat-diffusion weights. */
static inline sinew_result sw_character_args_make(const sw_character_args *c, sw_character *ch,
                                                  sw_error *err) {
    int computed = 0;
    memset(ch, 0, sizeof *ch);
    sinew_result r =
        c->scene
            ? sw_scene_make(c->scene, c->tets, c->frames, c->data_dir, ch, &computed, err)
            : sw_character_from_files(c->mesh, c->tgf, c->weights, c->clip, c->frames, ch, err);
    if (r == SINEW_OK && (computed || (c->mesh && !c->weights))) sw_weights_free(&ch->weights);
    return r;
}
#endif
