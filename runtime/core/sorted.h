/* The index of a value in an ascending int32 array: the one binary search of the
 * project (self-contact's boundary vertices, the instance's active vertices, the
 * cubature corners). */
#ifndef SW_SORTED_H
#define SW_SORTED_H

#include <stdint.h>

/* The index of v in a[0, n) (ascending), or -1 when it is not there. */
static inline int32_t sw_sorted_index(const int32_t *a, int32_t n, int32_t v) {
    int32_t lo = 0, hi = n;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (a[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (lo < n && a[lo] == v) ? lo : -1;
}

#endif
