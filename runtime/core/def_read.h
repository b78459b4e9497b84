/* The one reader of the public def structs (sinew.h): each starts with its
 * struct_size, and the library reads only the bytes the caller's size covers, so a
 * host built against older headers keeps working (STYLE.md §2). */
#ifndef SW_DEF_READ_H
#define SW_DEF_READ_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sinew/sinew_base.h"

/* The largest struct_size taken as real (a larger one is garbage, not a newer header). */
#define SW_DEF_MAX_SIZE 4096u

/* Overwrites the defaults in `dst` (dst_size bytes) with the caller's def `src`, whose
 * first field is its uint32_t struct_size: the first min(struct_size, dst_size) bytes,
 * then struct_size set to dst_size. INVALID_ARGUMENT (dst untouched) when src is NULL
 * or its size is below `min_size` (the fields every caller must set) or above
 * SW_DEF_MAX_SIZE. */
static inline sinew_result sw_def_read(void *dst, size_t dst_size, const void *src,
                                       size_t min_size) {
    uint32_t size;
    if (!src) return SINEW_ERROR_INVALID_ARGUMENT;
    memcpy(&size, src, sizeof size);
    if (size < min_size || size > SW_DEF_MAX_SIZE) return SINEW_ERROR_INVALID_ARGUMENT;
    memcpy(dst, src, size < dst_size ? size : dst_size);
    size = (uint32_t)dst_size;
    memcpy(dst, &size, sizeof size);
    return SINEW_OK;
}

#endif
