/* What the blob loader's files share (blob_load.c, blob_render.c, blob_cond.c, blob_pair.c,
 * blob_force.c): the message
 * writer, the layer-1 reading of an optional group of sections (its meta section, presence
 * all or none, counts), the value checks, and the checks of a "vertex = mean of its domain
 * copies" list, which the tet boundary (SURF_COPY_PTR / SURF_COPIES) and the render nodes
 * (RENDER_NODE_PTR / _COPIES) both are. Private to runtime/blob. */
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

/* A section's expected count for sw_blob_check_counts: a row of a section table
 * (sinew_blob_format.h) expands to one with SW_BLOB_EXPECT_ROW, in a scope that holds its
 * count names (SW_BLOB_COUNT_LOCALS, SW_BLOB_GROUP_COUNT_LOCALS). */
typedef struct sw_blob_count_expect {
    uint32_t id;
    int by_meta; /* 0: not checked (a count the section's own size gives) */
    uint64_t count;
    const char *formula;
} sw_blob_count_expect;
#define SW_BLOB_EXPECT_ROW(id, NAME, elem_size, type, field, by_meta, count, formula)              \
    {id, by_meta, count, formula},

/* Every section of e (by_meta) present in the table s (at found[id]) with its expected
 * count; messages say which meta section (`meta`, e.g. "META") needs it. */
sinew_result sw_blob_check_counts(const sinew_blob_section *s, const int found[],
                                  const sw_blob_count_expect *e, size_t n, const char *meta,
                                  char *msg, size_t msg_size);

/* Points the view `v`'s field at its section: a table row expanded in a scope holding
 * `bytes`, the table `s` and `found` (every row's section present). */
#define SW_BLOB_POINT_ROW(id, NAME, elem_size, type, field, ...)                                   \
    v->field = (const type *)(const void *)(bytes + s[found[id]].offset);

/* The optional group of sections with ids first .. last, the first its meta section of one
 * element (meta_size bytes, its last nreserved int32 words reserved, zero): *present is 0
 * when none of them is in the table, and 1, with the meta section read into `meta`, when
 * all are. Errors: some present but not all (the first missing one named, with `what`,
 * e.g. "the render mesh's"), the meta section's count, a reserved word. */
sinew_result sw_blob_group_meta(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], uint32_t first, uint32_t last, const char *what,
                                void *meta, size_t meta_size, size_t nreserved, int *present,
                                char *msg, size_t msg_size);

/* Every element of a (n doubles) finite (SINEW_ERROR_NOT_FINITE naming the section `id`). */
sinew_result sw_blob_check_finite(uint32_t id, const double *a, int64_t n, char *msg,
                                  size_t msg_size);

/* a[i * stride] > 0 for i < n (stride > 1: a matrix's diagonal). */
sinew_result sw_blob_check_positive(uint32_t id, const double *a, int64_t n, int64_t stride,
                                    char *msg, size_t msg_size);

/* A view's array and the section it holds, for sw_blob_check_arrays. */
typedef struct sw_blob_array_ref {
    const void *p;
    uint32_t id;
} sw_blob_array_ref;
/* A table row's sw_blob_array_ref in a scope holding the view `v`. */
#define SW_BLOB_ARRAY_REF_ROW(id, NAME, elem_size, type, field, ...) {v->field, id},

/* Every array of the list is non-NULL (SINEW_ERROR_INVALID_ARGUMENT naming the first that
 * is not: a writer's view that lacks one). */
sinew_result sw_blob_check_arrays(const sw_blob_array_ref *a, size_t n, char *msg, size_t msg_size);

/* Every index of a (n elements of k indices each: triangles, tets, one a vertex) lies in
 * [0, bound); messages name the section, the `elem` (and its corner when k > 1) and the
 * `what` it indexes. */
sinew_result sw_blob_check_indices(uint32_t id, const char *elem, int k, const int32_t *a,
                                   int64_t n, const char *what, int32_t bound, char *msg,
                                   size_t msg_size);

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

/* Layer 1 of the condensation tet mesh (blob_cond.c): the ten optional sections all present
 * or all absent, COND_META's counts (ntets in [1, SW_BLOB_MAX_COUNT], nvert_tets = 4 ntets)
 * and reserved words, every section's count against them and META's; points the view's
 * fields at them (left 0 / NULL when absent). After META has been read into v. */
sinew_result sw_blob_cond_fill(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                               sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2 of the condensation tet mesh: counts, indices, incidences, the cubature tets'
 * agreement and values (nothing when ntets is 0); after the domains and cubature tets have
 * been checked. */
sinew_result sw_blob_cond_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 1 of the per-pair self-contact (blob_pair.c): the six optional sections all present
 * or all absent, PAIR_META's count (npair_groups in [1, ndomains^2], npair_groups ntrain <=
 * SW_BLOB_MAX_COUNT) and reserved words, every section's count against them and META's;
 * points the view's fields at them (left 0 / NULL when absent). After META. */
sinew_result sw_blob_pair_fill(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                               sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2 of the per-pair self-contact: domains, ascending groups, the pointer table against
 * CONTACT_PTR and every contact's domains, finite maps and features, weights >= 0 (nothing
 * when npair_groups is 0); after the contacts have been checked. */
sinew_result sw_blob_pair_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 1 of the pose-space equilibrium force (blob_force.c): TRAIN_FORCE absent, or of
 * META's ntrain rank_total doubles; points v->train_force at it (NULL when absent). */
sinew_result sw_blob_force_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2: every force finite (nothing when train_force is NULL). */
sinew_result sw_blob_force_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 1 of the painted material (blob_stiffness.c): CUB_STIFFNESS absent (and
 * TET_STIFFNESS with it) or of META's ncub doubles, TET_STIFFNESS then present exactly when
 * the condensation mesh is, with its ntets; present in every blob of format `version` 3,
 * in none of version 2, and as painted in version 4.
 * Points the view's fields at them (NULL when absent). After the condensation mesh's fill. */
sinew_result sw_blob_stiffness_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                    const int found[], uint32_t version, sw_blob_view *v, char *msg,
                                    size_t msg_size);

/* Layer 2: every multiplier in [1e-6, 1e6] and each cubature tet's equal to its tet's
 * (nothing when cub_stiffness is NULL); after the condensation mesh's checks. */
sinew_result sw_blob_stiffness_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 1 of the asset description (blob_asset.c): the five optional sections all present or
 * all absent, ASSET_META's counts and reserved words, every section's count against them and
 * META's; points the view's fields at them (left 0 / NULL when absent). After META. */
sinew_result sw_blob_asset_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2: nbones names of 1..255 bytes filling BONE_NAMES exactly, finite bind transforms,
 * mesh vertex counts >= 0, noutput_verts the output surface's and every source pair in range
 * (nothing when bone_names is NULL); after the render mesh has been checked. */
sinew_result sw_blob_asset_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Every vertex's SW_BLOB_INFLUENCES (bone, weight) pairs (4 n each): bones in [0, nbones),
 * weights >= 0 summing to 1 within SW_BLOB_WEIGHT_SUM_TOL; messages name the sections. */
sinew_result sw_blob_check_influences(uint32_t bone_id, uint32_t weight_id, const int32_t *bone,
                                      const double *weight, int32_t n, int32_t nbones, char *msg,
                                      size_t msg_size);

/* Layer 1 of the pose-space level of detail (blob_lod.c): the six optional sections all
 * present or all absent, LOD_META's counts (nlod_verts the output surface's, lod_rank in
 * [1, SINEW_BLOB_LOD_MAX_RANK]) and reserved words, every section's count against them and
 * META's; points the view's fields at them (left 0 / NULL when absent). After the render
 * mesh's fill. */
sinew_result sw_blob_lod_fill(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                              sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 2: finite rest positions and coefficients, influences as SKIN_BONE/SKIN_WEIGHT's,
 * basis entries in [-1, 1] (nothing when lod_rank is 0). */
sinew_result sw_blob_lod_validate(const sw_blob_view *v, char *msg, size_t msg_size);

/* Layer 1 of the reduced matrices' blocks (blob_blocks.c): REDUCED_BLOCKS present exactly in
 * a blob of format `version` 4, of META's 2 ndomains^2; points the view at it (NULL when
 * absent) and records MASS's and SPRING_HESSIAN's counts. */
sinew_result sw_blob_blocks_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                 const int found[], uint32_t version, sw_blob_view *v, char *msg,
                                 size_t msg_size);

/* Layer 2: dense matrices of rank_total^2, or stored blocks packed without gaps with every
 * diagonal block stored; the mass's diagonal > 0. After the domain records' checks. */
sinew_result sw_blob_blocks_validate(const sw_blob_view *v, char *msg, size_t msg_size);

#endif
