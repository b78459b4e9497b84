#include "tool_flags.h"

#include <stdlib.h>
#include <string.h>

#include "tool_args.h"

/* The column the help text starts at; a longer name and argument push it to the next
 * line. */
enum { HELP_COLUMN = 19 };

static void usage_flag(const sw_flag *g, FILE *f) {
    char left[96];
    int n =
        snprintf(left, sizeof left, "  %s%s%s", g->name, g->arg ? " " : "", g->arg ? g->arg : "");
    const char *h = g->help ? g->help : "";
    if (n + 1 > HELP_COLUMN)
        fprintf(f, "%s\n%*s", left, HELP_COLUMN, "");
    else
        fprintf(f, "%-*s", HELP_COLUMN, left);
    for (;;) {
        size_t k = strcspn(h, "\n");
        fprintf(f, "%.*s\n", (int)k, h);
        if (!h[k] || !h[k + 1]) break;
        h += k + 1;
        fprintf(f, "%*s", HELP_COLUMN, "");
    }
}

void sw_flags_usage(const sw_tool_cli *cli, FILE *f) {
    fprintf(f, "usage: %s", cli->synopsis);
    for (size_t k = 0; k < cli->ngroups; ++k) {
        const sw_flag_group *gr = &cli->groups[k];
        if (gr->title) fprintf(f, "%s\n", gr->title);
        for (size_t j = 0; j < gr->n; ++j)
            usage_flag(&gr->flags[j], f);
    }
    if (cli->notes) fputs(cli->notes, f);
}

static const sw_flag *find(const sw_tool_cli *cli, const char *name) {
    for (size_t k = 0; k < cli->ngroups; ++k)
        for (size_t j = 0; j < cli->groups[k].n; ++j)
            if (!strcmp(cli->groups[k].flags[j].name, name)) return &cli->groups[k].flags[j];
    return NULL;
}

/* "one of a | b | c", or "a or b" for two. */
static void choices_text(const char *const *c, char *out, size_t size) {
    int n = 0;
    while (c[n])
        ++n;
    if (n == 2) {
        snprintf(out, size, "%s or %s", c[0], c[1]);
        return;
    }
    size_t used = (size_t)snprintf(out, size, "one of");
    for (int k = 0; k < n && used < size; ++k)
        used += (size_t)snprintf(out + used, size - used, "%s %s", k ? " |" : "", c[k]);
}

int sw_flags_choice(const char *tool, const char *flag, const char *v, const char *const *choices) {
    int k = sw_tool_choice(v, choices);
    if (k >= 0) return k;
    char want[256];
    choices_text(choices, want, sizeof want);
    fprintf(stderr, "%s: %s wants %s, got '%s'\n", tool, flag, want, v);
    return -1;
}

/* Takes flag g's argument v: 1, or 0 after a message naming the flag and its range. */
static int take_value(const char *tool, const sw_flag *g, const char *v) {
    switch (g->kind) {
    case SW_FLAG_STR:
        *(const char **)g->target = v;
        return 1;
    case SW_FLAG_INT:
        return sw_tool_int(tool, g->name, v, (int)g->lo, (int)g->hi, (int *)g->target);
    case SW_FLAG_REAL:
        return sw_tool_real(tool, g->name, v, g->lo, g->hi, g->range, (double *)g->target);
    case SW_FLAG_CHOICE: {
        int k = sw_tool_choice(v, g->choices);
        if (k >= 0) return (*(int *)g->target = k), 1;
        if (g->range)
            return fprintf(stderr, "%s: %s wants %s, got '%s'\n", tool, g->name, g->range, v), 0;
        return sw_flags_choice(tool, g->name, v, g->choices) >= 0;
    }
    case SW_FLAG_CALL:
        return g->take(tool, g->name, v, g->target);
    case SW_FLAG_SET:
        break;
    }
    return 0;
}

static int bad_arg(const sw_tool_cli *cli, const char *a) {
    fprintf(stderr, "%s: unknown or incomplete argument '%s' (%s --help lists the flags)\n",
            cli->tool, a, cli->tool);
    return 2;
}

int sw_flags_parse(const sw_tool_cli *cli, int argc, char **argv) {
    int npos = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            sw_flags_usage(cli, stdout);
            exit(0);
        }
        const sw_flag *g = a[0] == '-' && a[1] ? find(cli, a) : NULL;
        if (!g) {
            if (a[0] == '-' || npos >= cli->npositional) return bad_arg(cli, a);
            cli->positional[npos++] = a;
            continue;
        }
        if (g->given) *g->given = 1;
        if (g->kind == SW_FLAG_SET) {
            *(int *)g->target = g->value;
            continue;
        }
        if (i + 1 >= argc) return bad_arg(cli, a);
        if (!take_value(cli->tool, g, argv[++i])) return 2;
    }
    return 0;
}
