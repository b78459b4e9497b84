/* Flags as data: each tool describes its flags in tables (name, kind, range, target,
 * help) and one parser takes argv against them. The usage text is printed from the same
 * tables, so --help, the parser and docs/tools.md (checked by tests/tools_flags.sh)
 * cannot drift apart. */
#ifndef SW_TOOL_FLAGS_H
#define SW_TOOL_FLAGS_H

#include <stddef.h>
#include <stdio.h>

typedef enum sw_flag_kind {
    SW_FLAG_SET,    /* a switch: *(int *)target = value */
    SW_FLAG_STR,    /* *(const char **)target = the argument after the name */
    SW_FLAG_INT,    /* *(int *)target = an integer in [lo, hi] */
    SW_FLAG_REAL,   /* *(double *)target = a finite number with lo < v < hi ("range" says so) */
    SW_FLAG_CHOICE, /* *(int *)target = the index of the argument among choices */
    SW_FLAG_CALL,   /* take(tool, name, argument, target) parses it: 1, or 0 with a message */
} sw_flag_kind;

typedef struct sw_flag {
    const char *name; /* "--tets" */
    sw_flag_kind kind;
    void *target;
    const char *arg;   /* the argument's name in the usage ("N"); NULL for a switch */
    const char *help;  /* the usage text; each '\n' starts a line under the first */
    double lo, hi;     /* SW_FLAG_INT: closed range; SW_FLAG_REAL: open range */
    const char *range; /* messages say the range so (SW_FLAG_REAL), or the choices (SW_FLAG_CHOICE;
                        * default "one of a | b | c") */
    const char *const *choices; /* SW_FLAG_CHOICE: NULL-terminated */
    int value;                  /* SW_FLAG_SET */
    int (*take)(const char *tool, const char *flag, const char *arg, void *target);
    int *given; /* set to 1 when the flag is given (may be NULL) */
} sw_flag;

/* A titled list of flags (a tool's own, or a set shared by several tools). */
typedef struct sw_flag_group {
    const char *title; /* a line before the group's flags in the usage (may be NULL) */
    const sw_flag *flags;
    size_t n;
} sw_flag_group;

/* A tool's command line: its synopsis, its flag groups, the text after them. */
typedef struct sw_tool_cli {
    const char *tool;     /* "sinew-bake" */
    const char *synopsis; /* the usage lines after "usage: " (with their '\n') */
    const sw_flag_group *groups;
    size_t ngroups;
    const char *notes; /* after the flags: what the positional arguments are, exit status */
    /* receives the bare arguments in order (NULL: none taken); a positional that does not
     * fit is an error */
    const char **positional;
    int npositional;
} sw_tool_cli;

/* A table's rows, as designated fields (a row may add .given = &seen):
 *   {SW_INT("--tets", &o->tets, 1000, 2000000, "N", "the tets")}, */
#define SW_SET(n, t, v, h) .name = n, .kind = SW_FLAG_SET, .target = t, .value = v, .help = h
#define SW_STR(n, t, a, h) .name = n, .kind = SW_FLAG_STR, .target = t, .arg = a, .help = h
#define SW_INT(n, t, l, u, a, h)                                                                   \
    .name = n, .kind = SW_FLAG_INT, .target = t, .lo = l, .hi = u, .arg = a, .help = h
#define SW_REAL(n, t, l, u, r, a, h)                                                               \
    .name = n, .kind = SW_FLAG_REAL, .target = t, .lo = l, .hi = u, .range = r, .arg = a, .help = h
#define SW_CHOICE(n, t, c, a, h)                                                                   \
    .name = n, .kind = SW_FLAG_CHOICE, .target = t, .choices = c, .arg = a, .help = h
#define SW_CALL(n, f, t, a, h)                                                                     \
    .name = n, .kind = SW_FLAG_CALL, .take = f, .target = t, .arg = a, .help = h

#define SW_FLAGS_N(a) (sizeof(a) / sizeof((a)[0]))

/* The usage: "usage: SYNOPSIS", each group's flags with their help, the notes. */
void sw_flags_usage(const sw_tool_cli *cli, FILE *f);

/* Takes argv[1..argc) against cli's groups. --help or -h prints the usage on stdout and
 * exits with status 0. Returns 0 when every argument was taken; otherwise names the
 * argument (an unknown flag, one without its value, or a bad value, with its range) on
 * stderr and returns the exit status 2. */
int sw_flags_parse(const sw_tool_cli *cli, int argc, char **argv);

/* The index of v among the NULL-terminated choices; otherwise names the flag and its
 * choices on stderr and returns -1. */
int sw_flags_choice(const char *tool, const char *flag, const char *v, const char *const *choices);

#endif
