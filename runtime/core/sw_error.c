#include "sw_error.h"

#include <stdarg.h>
#include <stdio.h>

sinew_result sw_error_set(sw_error *err, sinew_result code, const char *fmt, ...) {
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->code = code;
    }
    return code;
}

void sw_error_clear(sw_error *err) {
    if (err) {
        err->code = SINEW_OK;
        err->msg[0] = '\0';
    }
}
