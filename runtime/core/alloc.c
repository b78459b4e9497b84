#include "alloc.h"

#include <stdlib.h>
#include <string.h>

void *sw_alloc(const sinew_allocator *a, size_t size, size_t align) {
    if (size == 0) size = 1;
    if (size > SIZE_MAX - align) return NULL;
    size = (size + align - 1) & ~(size_t)(align - 1);
    void *p = NULL;
    if (a && a->alloc)
        p = a->alloc(size, align, a->user);
    else if (posix_memalign(&p, align, size) != 0)
        p = NULL;
    if (p) memset(p, 0, size);
    return p;
}

void sw_free(const sinew_allocator *a, void *p) {
    if (!p) return;
    if (a && a->free)
        a->free(p, a->user);
    else
        free(p);
}

sinew_result sw_allocator_check(const sinew_allocator *a) {
    return (a->alloc == NULL) == (a->free == NULL) ? SINEW_OK : SINEW_ERROR_INVALID_ARGUMENT;
}
