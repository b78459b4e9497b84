#include "tool_files.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

const char *sw_tool_data_dir(void) {
    return getenv("SINEW_DATA_DIR") ? getenv("SINEW_DATA_DIR") : SINEW_SHARED_DATA_DIR;
}

int sw_tool_make_dirs(const char *dir) {
    char path[4096];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof path) return (errno = ENAMETOOLONG), 0;
    memcpy(path, dir, n + 1);
    for (size_t i = 1; i <= n; ++i)
        if (path[i] == '/' || path[i] == '\0') {
            char c = path[i];
            path[i] = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST) return 0;
            path[i] = c;
        }
    struct stat st;
    if (stat(dir, &st) != 0) return 0;
    if (!S_ISDIR(st.st_mode)) return (errno = ENOTDIR), 0;
    return access(dir, W_OK | X_OK) == 0;
}

/* 1 when path's extension is the first n characters of ext, case-insensitively. */
static int sw_tool_ext_is(const char *path, const char *ext, size_t n) {
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strlen(dot + 1) != n || n == 0) return 0;
    for (size_t i = 0; i < n; ++i)
        if ((dot[1 + i] | 0x20) != (ext[i] | 0x20)) return 0;
    return 1;
}

int sw_tool_has_ext(const char *path, const char *ext) {
    return sw_tool_ext_is(path, ext, strlen(ext));
}

int sw_tool_format(const char *tool, const char *flag, const char *path, const char *exts,
                   const char *what) {
    for (const char *e = exts; *e;) {
        size_t k = strcspn(e, " ");
        if (sw_tool_ext_is(path, e, k)) return 1;
        e += k;
        while (*e == ' ')
            ++e;
    }
    fprintf(stderr, "%s: %s '%s': not a format it reads; accepted: %s\n", tool, flag, path, what);
    return 0;
}

void sw_tool_json_string(const char *s) {
    putchar('"');
    for (; *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}
