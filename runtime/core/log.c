#include "log.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* The default hook: one write(2) of "sinew: <level>: <message>\n" to stderr, so a message
 * neither allocates nor takes stdio's lock, and lines from several threads do not mix. */
static void log_stderr(sinew_log_level level, const char *text) {
    static const char *const names[] = {"error", "warning", "info", "debug"};
    char line[800];
    int n = snprintf(line, sizeof line - 1, "sinew: %s: %s",
                     names[level >= SINEW_LOG_ERROR && level <= SINEW_LOG_DEBUG ? level : 0], text);
    if (n < 0) return;
    size_t len = (size_t)n < sizeof line - 1 ? (size_t)n : sizeof line - 2;
    line[len++] = '\n';
    ssize_t w = write(STDERR_FILENO, line, len);
    (void)w; /* nowhere to report a failed report */
}

void sw_log(const sinew_logger *lg, sinew_log_level level, uint32_t id, const char *fmt, ...) {
    if (!lg || level > lg->max_level) return;
    /* Without a hook only errors and warnings are printed (sinew_logger_default). */
    if (!lg->log && level > SINEW_LOG_WARNING) return;
    char text[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (lg->log)
        lg->log(level, id, text, lg->user);
    else
        log_stderr(level, text);
}
