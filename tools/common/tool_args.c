#include "tool_args.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

int sw_tool_parse_int(const char *s, int lo, int hi, int *out) {
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || end == s || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

int sw_tool_int(const char *tool, const char *flag, const char *s, int lo, int hi, int *out) {
    if (s && sw_tool_parse_int(s, lo, hi, out)) return 1;
    fprintf(stderr, "%s: %s wants an integer in %d..%d, got '%s'\n", tool, flag, lo, hi,
            s ? s : "(nothing)");
    return 0;
}

int sw_tool_choice(const char *v, const char *const *names) {
    for (int k = 0; names[k]; ++k)
        if (!strcmp(v, names[k])) return k;
    return -1;
}

int sw_tool_real(const char *tool, const char *flag, const char *s, double lo, double hi,
                 const char *range, double *out) {
    char *end = NULL;
    double v = s ? strtod(s, &end) : 0;
    if (s && end != s && !*end && v > lo && v < hi) {
        *out = v;
        return 1;
    }
    fprintf(stderr, "%s: %s wants a number %s, got '%s'\n", tool, flag, range, s ? s : "(nothing)");
    return 0;
}
