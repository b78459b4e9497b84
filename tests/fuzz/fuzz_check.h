/* Shared checks of the reader harnesses (fuzz_medit.c, fuzz_tetgen.c, ...): the input in a
 * buffer of exactly its size, and the error contract of mesh_io.h / clip_io.h. */
#ifndef SW_FUZZ_CHECK_H
#define SW_FUZZ_CHECK_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sw_error.h"

/* A malloc'd copy of the input with no byte after it (so that ASan reports a read past
 * it), or NULL when out of memory. */
static inline char *sw_fuzz_copy(const uint8_t *data, size_t size) {
    char *copy = malloc(size ? size : 1);
    if (copy && size) memcpy(copy, data, size);
    return copy;
}

/* A failed read must leave its code and a message naming the text ("name:..." or
 * "name: ..."); anything else is a broken promise: abort so libFuzzer keeps the input. */
static inline void sw_fuzz_check_error(sinew_result rc, const sw_error *err, const char *name) {
    size_t n = strlen(name);
    if (rc == SINEW_OK || err->code != rc || strncmp(err->msg, name, n) != 0 || err->msg[n] != ':')
        abort();
}

/* 1 when all `n` bytes at p are zero (a zeroed output struct). */
static inline int sw_fuzz_zeroed(const void *p, size_t n) {
    const unsigned char *b = p;
    for (size_t i = 0; i < n; ++i)
        if (b[i]) return 0;
    return 1;
}

#endif
