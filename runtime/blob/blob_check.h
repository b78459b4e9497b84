/* What the blob loader's files share (blob_load.c, blob_render.c): the message writer and
 * the checks of a "vertex = mean of its domain copies" list, which the tet boundary
 * (SURF_COPY_PTR / SURF_COPIES) and the render nodes (RENDER_NODE_PTR / _COPIES) both are.
 * Private to runtime/blob. */
#ifndef SW_BLOB_CHECK_H
#define SW_BLOB_CHECK_H

#include <stddef.h>
#include <stdint.h>

#include "blob_load.h"

/* Writes the printf-formatted message into msg (may be NULL) and returns code. */
sinew_result sw_blob_fail(char *msg, size_t msg_size, sinew_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Every index of a (n elements of k indices each: triangles, tets, one a vertex) lies in
 * [0, bound); messages name the section, the `elem` (and its corner when k > 1) and the
 * `what` it indexes. */
sinew_result sw_blob_check_indices(uint32_t id, const char *elem, int k, const int32_t *a,
                                   int64_t n, const char *what, int32_t bound, char *msg,
                                   size_t msg_size);

/* A view's array and the section it holds, for sw_blob_check_arrays. */
typedef struct sw_blob_array_ref {
    const void *p;
    uint32_t id;
} sw_blob_array_ref;

/* Every array of the list is non-NULL (SINEW_ERROR_INVALID_ARGUMENT naming the first that
 * is not: a writer's view that lacks one). */
sinew_result sw_blob_check_arrays(const sw_blob_array_ref *a, size_t n, char *msg, size_t msg_size);

/* ptr (n + 1 entries) starts at 0, rises strictly (every `item` has a copy) and ends at
 * ncopies, which is in [1, SW_BLOB_MAX_COPIES]. */
sinew_result sw_blob_check_copy_ptr(uint32_t ptr_id, uint32_t copies_id, const char *item,
                                    const int32_t *ptr, int32_t n, int32_t ncopies, char *msg,
                                    size_t msg_size);

/* Every (domain, local vertex) pair of copies (2 ncopies) names a domain and one of its
 * vertex copies; the domain records must have been checked. */
sinew_result sw_blob_check_copies(uint32_t id, const sw_blob_view *v, const int32_t *copies,
                                  int32_t ncopies, char *msg, size_t msg_size);

/* Layer 1 of the render mesh (blob_render.c): the eight optional sections all present or
 * all absent, RENDER_META's counts and reserved words, every section's count against
 * them; points the view's render fields at them (left 0 / NULL when absent). */
sinew_result sw_blob_render_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                 const int found[], sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2 of the render mesh: counts, indices and values (nothing when nrender_verts is 0). */
sinew_result sw_blob_render_validate(const sw_blob_view *v, char *msg, size_t msg_size);

#endif
