#include "tool_run.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The loader's last error message, kept by sw_tool_log_keep (a sinew_logger hook). */
typedef struct sw_tool_log {
    char msg[512];
} sw_tool_log;

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
    (void)id;
    sw_tool_log *l = (sw_tool_log *)user;
    if (level == SINEW_LOG_ERROR && l && message) snprintf(l->msg, sizeof l->msg, "%s", message);
}

sinew_result sw_tool_blob_load(const char *tool, const char *what, sinew_blob_def def,
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
