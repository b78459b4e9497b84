#include "log.h"

#include <stdarg.h>
#include <stdio.h>

void sw_log(const sinew_logger *lg, sinew_log_level level, uint32_t id, const char *fmt, ...) {
    if (!lg || !lg->log || level > lg->max_level) return;
    char text[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    lg->log(level, id, text, lg->user);
}
