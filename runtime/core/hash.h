/* FNV-1a 64: the one byte hash of the project (the blob checksum, the bake's simulate
 * cache and its key, the tests' bitwise fingerprints). Continued from h, so a caller can
 * hash several pieces in turn: start with SW_FNV_START. */
#ifndef SW_HASH_H
#define SW_HASH_H

#include <stddef.h>
#include <stdint.h>

#define SW_FNV_START 0xcbf29ce484222325ull /* the offset basis */

static inline uint64_t sw_fnv1a(uint64_t h, const void *data, size_t n) {
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ p[i]) * 0x100000001b3ull; /* the FNV 64 prime */
    return h;
}

#endif
