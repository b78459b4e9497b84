/* A tool's flag values: strict integers, numbers and names, with the message every
 * tool prints for a value out of range. */
#ifndef SW_TOOL_ARGS_H
#define SW_TOOL_ARGS_H

#include <stdio.h>

/* Parses all of s as a base-10 integer in [lo, hi] into *out; 0 when it is not one. */
int sw_tool_parse_int(const char *s, int lo, int hi, int *out);

/* Parses flag's value s as an integer in [lo, hi] into *out; otherwise names the flag, its
 * range and the value on stderr and returns 0. */
int sw_tool_int(const char *tool, const char *flag, const char *s, int lo, int hi, int *out);

/* The index of v in the NULL-terminated names, or -1. */
int sw_tool_choice(const char *v, const char *const *names);

/* Parses flag's value s as a finite number with lo < value < hi (open bounds) into *out;
 * otherwise names the flag, its range and the value on stderr and returns 0. */
int sw_tool_real(const char *tool, const char *flag, const char *s, double lo, double hi,
                 const char *range, double *out);

#endif
