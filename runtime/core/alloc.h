/* The runtime's one allocator path: the host's hooks (sinew_allocator) or the C
 * library, always aligned and zeroed. Called only outside the step (DESIGN.md §3). */
#ifndef SW_ALLOC_H
#define SW_ALLOC_H

#include <stddef.h>

#include "sinew/sinew_base.h"

/* The alignment of every runtime allocation: a cache line, and the blob's own. */
#define SW_ALLOC_ALIGN 64u

/* `size` bytes (rounded up to a multiple of `align`, a power of two >= sizeof(void *)),
 * zeroed, through `a` (its functions NULL: the C library). NULL when out of memory. */
void *sw_alloc(const sinew_allocator *a, size_t size, size_t align);

/* Releases memory from sw_alloc with the same allocator (NULL is allowed). */
void sw_free(const sinew_allocator *a, void *p);

/* SINEW_OK when the allocator's alloc and free are both set or both NULL. */
sinew_result sw_allocator_check(const sinew_allocator *a);

#endif
