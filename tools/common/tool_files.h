/* Files a tool reads and writes: the data folder, output folders, extensions, JSON
 * strings. */
#ifndef SW_TOOL_FILES_H
#define SW_TOOL_FILES_H

#include <stddef.h>

/* The folder of the real assets: $SINEW_DATA_DIR, else the build's shared data folder. */
const char *sw_tool_data_dir(void);

/* mkdir -p: creates dir and its missing parents; 1 when dir is a writable folder
 * afterwards, else 0 with errno saying why (the tools check an output folder before a long
 * run). */
int sw_tool_make_dirs(const char *dir);

int sw_tool_has_ext(const char *path, const char *ext);

/* 1 when path ends (case-insensitively) with one of the space-separated extensions in
 * exts ("mesh node ele"); otherwise names the flag, the file and the accepted formats on
 * stderr and returns 0. */
int sw_tool_format(const char *tool, const char *flag, const char *path, const char *exts,
                   const char *what);

/* Prints s to stdout as a JSON string (quotes, backslashes and control characters
 * escaped): names from files (bones, clips) in a tool's --json line. */
void sw_tool_json_string(const char *s);

#endif
