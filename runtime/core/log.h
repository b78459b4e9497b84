/* The runtime's one log path: a message goes to the host's sinew_logger, formatted only
 * when its level passes the logger's max_level; a logger without a hook prints errors and
 * warnings to stderr (SINEW_LOG_NONE as max_level silences it). */
#ifndef SW_LOG_H
#define SW_LOG_H

#include <stdint.h>

#include "sinew/sinew_base.h"

/* Formats and sends one message with a stable id (SINEW_MSG_*); a NULL logger, or a
 * message above max_level, costs one comparison. */
void sw_log(const sinew_logger *lg, sinew_log_level level, uint32_t id, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

#endif
