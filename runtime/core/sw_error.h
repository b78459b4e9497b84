/* Error reports of the bake side: a result code plus one message that names the file
 * and line (for readers) or the object and value (for everything else). */
#ifndef SW_ERROR_H
#define SW_ERROR_H

#include "sinew/sinew_base.h"

typedef struct sw_error {
    sinew_result code;
    char msg[512];
} sw_error;

/* Records `code` and a printf-formatted message in `err` (which may be NULL) and
 * returns `code`, so that a failing path reads `return sw_error_set(err, ...);`. */
sinew_result sw_error_set(sw_error *err, sinew_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Clears `err` to SINEW_OK with an empty message. */
void sw_error_clear(sw_error *err);

#endif
