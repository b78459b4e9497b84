/* One memory plan (STYLE.md §4, DESIGN.md §3): an object's memory is laid out once, as
 * regions at 64-byte boundaries of a single block whose size is known before it is
 * allocated, so that a size query and the allocation share one layout and nothing is
 * allocated afterwards. Walk the same layout twice: with base NULL to learn the size,
 * then with the allocated block to place every region. */
#ifndef SW_MEM_PLAN_H
#define SW_MEM_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "alloc.h"

typedef struct sw_mem_plan {
    unsigned char *base; /* the block, or NULL while sizing */
    size_t size;         /* bytes laid out so far */
    int overflow;        /* a size did not fit in size_t */
} sw_mem_plan;

/* The next region of count elements of elem bytes, 64-byte aligned: its address in the
 * block (NULL while sizing, or for an empty region). */
static inline void *sw_plan_take(sw_mem_plan *p, uint64_t count, size_t elem) {
    size_t at = (p->size + SW_ALLOC_ALIGN - 1) & ~(size_t)(SW_ALLOC_ALIGN - 1);
    if (at < p->size || (elem && count > (SIZE_MAX - at) / elem)) {
        p->overflow = 1;
        return NULL;
    }
    p->size = at + (size_t)count * elem;
    return p->base && count ? p->base + at : NULL;
}

/* Places `ptr` (a typed pointer) as a region of `count` of what it points to. */
#define SW_PLAN_TAKE(p, ptr, count) ((ptr) = sw_plan_take((p), (count), sizeof *(ptr)))

/* The block's size: everything laid out, rounded up to the alignment (what sw_alloc
 * reserves). */
static inline size_t sw_plan_size(const sw_mem_plan *p) {
    return (p->size + SW_ALLOC_ALIGN - 1) & ~(size_t)(SW_ALLOC_ALIGN - 1);
}

#endif
