/* What a tool does around a run: step times and medians, a failed call's message, the
 * blob loaded with the loader's reason, and a bake's progress on stderr. */
#ifndef SW_TOOL_RUN_H
#define SW_TOOL_RUN_H

#include <stdint.h>

#include "sinew/sinew.h"
#include "sw_error.h"

/* A step's wall time in ms: the sum of its phases in sinew_step_stats. */
double sw_step_ms(const sinew_step_stats *st);

/* Median of v[0..n) (sorts v in place); 0 for n <= 0. */
double sw_median(double *v, int n);

int sw_tool_failed(sinew_result r, const sw_error *err, const char *prefix, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* sinew_blob_load of def with a logger that keeps the loader's reason; on failure prints
 * "TOOL: cannot load the blob WHAT: REASON (RESULT)" on stderr. */
sinew_result sw_tool_blob_load(const char *tool, const char *what, sinew_blob_def def,
                               sinew_blob **out);

/* A bake's stage progress (sw_bake_params.on_progress) on stderr: on a terminal a bar
 * redrawn in place with the time left, otherwise a plain line at every tenth; nothing for
 * a stage that ends within two seconds. */
typedef struct sw_tool_progress {
    const char *tool;
    int tty;
    char stage[32];
    int shown, tenth;
} sw_tool_progress;

void sw_tool_progress_init(sw_tool_progress *tp, const char *tool);

void sw_tool_progress_print(void *user, const char *stage, int64_t done, int64_t total,
                            double elapsed);

#endif
