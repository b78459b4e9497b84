#include "tool_run.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The tools' logger (sw_tool_log_keep). A blob keeps its logger for its life, and the
 * instances created from it without a logger of their own log through it too, from any
 * thread: so the hook writes no caller's memory (it kept every message in the loader's
 * stack frame, and an instance refused after the load wrote over sinew-invariance's
 * stack). An error logged while this thread loads a blob is kept for the load's own
 * message; any later message is printed as the default logger prints it. */
static _Thread_local struct {
    int loading;
    char msg[512];
} tool_log;

double sw_step_ms(const sinew_step_stats *st) {
    return st->ms_skin + st->ms_contact + st->ms_dynamics + st->ms_world + st->ms_oracle +
           st->ms_solve + st->ms_output;
}

static int sw_cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double sw_median(double *v, int n) {
    if (n <= 0) return 0;
    qsort(v, (size_t)n, sizeof *v, sw_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int sw_tool_failed(sinew_result r, const sw_error *err, const char *prefix, ...) {
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

static void sw_tool_log_keep(sinew_log_level level, uint32_t id, const char *message, void *user) {
    (void)id, (void)user;
    if (!message) return;
    if (!tool_log.loading)
        fprintf(stderr, "sinew: %s: %s\n", level == SINEW_LOG_ERROR ? "error" : "warning", message);
    else if (level == SINEW_LOG_ERROR)
        snprintf(tool_log.msg, sizeof tool_log.msg, "%s", message);
}

sinew_result sw_tool_blob_load(const char *tool, const char *what, sinew_blob_def def,
                               sinew_blob **out) {
    tool_log.msg[0] = '\0';
    def.logger.log = sw_tool_log_keep;
    def.logger.user = NULL;
    def.logger.max_level = SINEW_LOG_WARNING;
    tool_log.loading = 1;
    sinew_result r = sinew_blob_load(&def, out);
    tool_log.loading = 0;
    if (r != SINEW_OK)
        fprintf(stderr, "%s: cannot load the blob %s: %s (%s)\n", tool, what,
                tool_log.msg[0] ? tool_log.msg : "no reason given", sinew_result_string(r));
    return r;
}

void sw_tool_progress_init(sw_tool_progress *tp, const char *tool) {
    memset(tp, 0, sizeof *tp);
    tp->tool = tool;
    tp->tty = isatty(STDERR_FILENO);
}

void sw_tool_progress_print(void *user, const char *stage, int64_t done, int64_t total,
                            double elapsed) {
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
