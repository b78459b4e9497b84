/* Blob parser and validator. Two layers, run in this order so that no check ever reads
 * past what an earlier check proved to exist:
 *   1. bytes: header, section table, section bounds/alignment/overlap, checksum, and the
 *      count of every section against META (sw_blob_parse);
 *   2. view: domain records, derived counts, every index and every value
 *      (sw_blob_validate_view, shared with the writer).
 * All arithmetic on file-supplied numbers is done in uint64/int64 after range checks
 * that keep it from overflowing. */
#include "blob_load.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "blob_check.h"
#include "hash.h"

_Static_assert(sizeof(sinew_blob_header) == 64, "blob header is 64 bytes");
_Static_assert(sizeof(sinew_blob_section) == 32, "section entry is 32 bytes");
/* Each section's C type has the element size of the format. */
#define SIZE_MATCHES(id, NAME, elem_size, type, ...)                                               \
    _Static_assert(sizeof(type) == elem_size, #NAME " elements are " #elem_size " bytes");
SINEW_BLOB_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_RENDER_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_COND_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_PAIR_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_FORCE_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_ASSET_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_STIFFNESS_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_LOD_SECTIONS(SIZE_MATCHES)
SINEW_BLOB_BLOCKS_SECTIONS(SIZE_MATCHES)
#undef SIZE_MATCHES
/* The optional groups follow the version-1 sections with no gap (the all-or-none loops). */
_Static_assert(SINEW_SECTION_RENDER_FIRST == SINEW_SECTION_COUNT_V1 + 1 &&
                   SINEW_SECTION_COND_FIRST == SINEW_SECTION_RENDER_LAST + 1 &&
                   SINEW_SECTION_PAIR_FIRST == SINEW_SECTION_COND_LAST + 1 &&
                   SINEW_SECTION_TRAIN_FORCE == SINEW_SECTION_PAIR_LAST + 1 &&
                   SINEW_SECTION_ASSET_FIRST == SINEW_SECTION_TRAIN_FORCE + 1 &&
                   SINEW_SECTION_CUB_STIFFNESS == SINEW_SECTION_ASSET_LAST + 1 &&
                   SINEW_SECTION_REDUCED_BLOCKS == SINEW_SECTION_LOD_LAST + 1,
               "section ids run on without gaps");
/* SW_BLOB_META_FIELDS covers every byte of META: no field is left uncopied. */
#define META_FIELD_SIZE(field) +sizeof(((sinew_blob_meta *)0)->field)
_Static_assert(0 SW_BLOB_META_FIELDS(META_FIELD_SIZE) == sizeof(sinew_blob_meta),
               "SW_BLOB_META_FIELDS lists every META field");
#undef META_FIELD_SIZE
_Static_assert(SW_BLOB_INFLUENCES == 4, "the format stores 4 influences per vertex");

#define HEADER_SIZE ((uint64_t)sizeof(sinew_blob_header))
#define ENTRY_SIZE ((uint64_t)sizeof(sinew_blob_section))

/* Name and element size of every known section, by id; entry 0 names the unknown ones.
 * The designated initializers make a repeated id a compile error (-Werror). */
#define SECTION_INFO(id, NAME, elem_size, ...) [id] = {#NAME, elem_size},
static const struct {
    const char *name;
    uint32_t elem_size;
} k_sections[SINEW_SECTION_ID_MAX + 1] = {
    [0] = {"unknown", 0},
    SINEW_BLOB_SECTIONS(SECTION_INFO) SINEW_BLOB_RENDER_SECTIONS(SECTION_INFO)
        SINEW_BLOB_COND_SECTIONS(SECTION_INFO) SINEW_BLOB_PAIR_SECTIONS(SECTION_INFO)
            SINEW_BLOB_FORCE_SECTIONS(SECTION_INFO) SINEW_BLOB_ASSET_SECTIONS(SECTION_INFO)
                SINEW_BLOB_STIFFNESS_SECTIONS(SECTION_INFO) SINEW_BLOB_LOD_SECTIONS(SECTION_INFO)
                    SINEW_BLOB_BLOCKS_SECTIONS(SECTION_INFO)};
#undef SECTION_INFO

/* Not instrumented for fuzzing coverage: its loop has no branch worth a fuzzer's
 * attention, and tracing its compare per byte was 60% of the fuzz_blob_fixed harness's
 * time (perf). */
#if defined(__clang__) && __clang_major__ >= 13
#define SW_NO_FUZZ_COVERAGE __attribute__((no_sanitize("coverage")))
#else
#define SW_NO_FUZZ_COVERAGE
#endif
SW_NO_FUZZ_COVERAGE uint64_t sw_blob_checksum(const void *data, size_t n) {
    return sw_fnv1a(SW_FNV_START, data, n);
}

const char *sw_blob_section_name(uint32_t id) {
    return k_sections[id >= 1 && id <= SINEW_SECTION_ID_MAX ? id : 0].name;
}

sinew_result sw_blob_fail(char *msg, size_t msg_size, sinew_result code, const char *fmt, ...) {
    if (msg && msg_size) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
    }
    return code;
}

#define fail sw_blob_fail

/* ---- layer 2: the view ----------------------------------------------------------- */

static sinew_result check_count(const char *field, int64_t value, int64_t lo, int64_t hi, char *msg,
                                size_t msg_size) {
    if (value < lo || value > hi)
        return fail(msg, msg_size, SINEW_ERROR_CORRUPT,
                    "blob section META: %s = %lld outside [%lld, %lld]", field, (long long)value,
                    (long long)lo, (long long)hi);
    return SINEW_OK;
}

static sinew_result check_meta(const sw_blob_view *v, char *msg, size_t ms) {
    const struct {
        const char *name;
        int64_t value, lo, hi;
    } counts[] = {
        {"nverts", v->nverts, 1, SW_BLOB_MAX_COUNT},
        {"nbones", v->nbones, 1, SW_BLOB_MAX_BONES},
        {"ndomains", v->ndomains, 1, v->nbones},
        {"rank_total", v->rank_total, 1, SW_BLOB_MAX_RANK_TOTAL},
        {"ndomain_verts", v->ndomain_verts, 1, SW_BLOB_MAX_COUNT},
        {"ncub", v->ncub, 1, SW_BLOB_MAX_COUNT},
        {"nsurf_verts", v->nsurf_verts, 1, SW_BLOB_MAX_COUNT},
        {"nsurf_tris", v->nsurf_tris, 1, SW_BLOB_MAX_COUNT},
        {"ntrain", v->ntrain, 1, 1000000},
        {"ncontacts", v->ncontacts, 0, SW_BLOB_MAX_COUNT},
    };
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; ++i) {
        sinew_result r =
            check_count(counts[i].name, counts[i].value, counts[i].lo, counts[i].hi, msg, ms);
        if (r != SINEW_OK) return r;
    }
    const struct {
        const char *name;
        double value;
    } mat[] = {{"mu", v->mu},
               {"lambda", v->lambda},
               {"rayleigh_alpha", v->rayleigh_alpha},
               {"rayleigh_beta", v->rayleigh_beta},
               {"contact_k", v->contact_k}};
    for (size_t i = 0; i < sizeof mat / sizeof mat[0]; ++i) {
        if (!isfinite(mat[i].value))
            return fail(msg, ms, SINEW_ERROR_NOT_FINITE, "blob section META: %s is %g", mat[i].name,
                        mat[i].value);
        /* Damping and contact stiffness below zero would inject energy. */
        if (i >= 2 && mat[i].value < 0.0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section META: %s = %g is negative",
                        mat[i].name, mat[i].value);
    }
    /* A stable isotropic material: shear modulus and bulk modulus (lambda + 2/3 mu)
     * positive. */
    if (!(v->mu > 0.0) || !(3.0 * v->lambda + 2.0 * v->mu > 0.0))
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section META: unstable material mu = %g, lambda = %g (need mu > 0 "
                    "and 3 lambda + 2 mu > 0)",
                    v->mu, v->lambda);
    return SINEW_OK;
}

sinew_result sw_blob_check_arrays(const sw_blob_array_ref *a, size_t n, char *msg, size_t ms) {
    for (size_t i = 0; i < n; ++i)
        if (!a[i].p)
            return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT,
                        "blob section %s: the view's array is NULL", sw_blob_section_name(a[i].id));
    return SINEW_OK;
}

sinew_result sw_blob_check_indices(uint32_t id, const char *elem, int k, const int32_t *a,
                                   int64_t n, const char *what, int32_t bound, char *msg,
                                   size_t ms) {
    for (int64_t i = 0; i < k * n; ++i) {
        if (a[i] >= 0 && a[i] < bound) continue;
        char corner[32] = "";
        if (k > 1) snprintf(corner, sizeof corner, " corner %d", (int)(i % k));
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section %s: %s %lld%s: %s %d outside [0, %d)", sw_blob_section_name(id),
                    elem, (long long)(i / k), corner, what, a[i], bound);
    }
    return SINEW_OK;
}

static sinew_result check_pointers(const sw_blob_view *v, char *msg, size_t ms) {
    const sw_blob_array_ref arrays[] = {SINEW_BLOB_ARRAY_SECTIONS(SW_BLOB_ARRAY_REF_ROW)};
    return sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms);
}

/* One domain record against the running prefix sums of the domains before it. */
static sinew_result check_domain(const sw_blob_view *v, int32_t d, const int64_t sum[5], char *msg,
                                 size_t ms) {
    const sw_blob_domain *dom = &v->domains[d];
#define DFAIL(...)                                                                                 \
    fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section DOMAINS: domain %d: " __VA_ARGS__)
    if (dom->bone < 0 || dom->bone >= v->nbones)
        return DFAIL("bone %d outside [0, %d)", d, dom->bone, v->nbones);
    if (dom->rank < 1 || dom->rank > SW_BLOB_MAX_RANK)
        return DFAIL("rank %d outside [1, %d]", d, dom->rank, SW_BLOB_MAX_RANK);
    if (dom->vert_begin != sum[0])
        return DFAIL("vert_begin %d, expected %lld (after the previous domains' copies)", d,
                     dom->vert_begin, (long long)sum[0]);
    if (dom->vert_count < 1 || dom->vert_count > v->ndomain_verts - sum[0])
        return DFAIL("vert_count %d outside [1, %lld] (DOMAIN_VERTS holds %d copies)", d,
                     dom->vert_count, (long long)(v->ndomain_verts - sum[0]), v->ndomain_verts);
    if (dom->q_offset != sum[1])
        return DFAIL("q_offset %d, expected %lld (sum of the previous ranks)", d, dom->q_offset,
                     (long long)sum[1]);
    if (dom->rank > v->rank_total - sum[1])
        return DFAIL("rank %d runs past rank_total %d", d, dom->rank, v->rank_total);
    if (dom->cub_begin != sum[2])
        return DFAIL("cub_begin %d, expected %lld", d, dom->cub_begin, (long long)sum[2]);
    if (dom->cub_count < 1 || dom->cub_count > v->ncub - sum[2])
        return DFAIL("cub_count %d outside [1, %lld] (ncub %d)", d, dom->cub_count,
                     (long long)(v->ncub - sum[2]), v->ncub);
    if (dom->basis_offset != sum[3])
        return DFAIL("basis_offset %lld, expected %lld", d, (long long)dom->basis_offset,
                     (long long)sum[3]);
    if (dom->inertia_offset != sum[4])
        return DFAIL("inertia_offset %lld, expected %lld", d, (long long)dom->inertia_offset,
                     (long long)sum[4]);
    if (dom->inertia_count < 0 || dom->inertia_count > dom->rank)
        return DFAIL("inertia_count %d outside [0, rank %d]", d, dom->inertia_count, dom->rank);
#undef DFAIL
    return SINEW_OK;
}

static sinew_result check_domains(const sw_blob_view *v, char *msg, size_t ms) {
    /* Prefix sums: vertex copies, q, cubature, basis doubles, inertia_u doubles. The
     * per-domain bounds checked first keep them far from overflow. */
    int64_t sum[5] = {0, 0, 0, 0, 0};
    for (int32_t d = 0; d < v->ndomains; ++d) {
        sinew_result r = check_domain(v, d, sum, msg, ms);
        if (r != SINEW_OK) return r;
        const sw_blob_domain *dom = &v->domains[d];
        sum[0] += dom->vert_count;
        sum[1] += dom->rank;
        sum[2] += dom->cub_count;
        sum[3] += (int64_t)dom->vert_count * 3 * dom->rank;
        sum[4] += (int64_t)9 * dom->rank * dom->rank;
    }
    if (sum[0] != v->ndomain_verts)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section DOMAINS: domains hold %lld vertex copies, META ndomain_verts "
                    "is %d",
                    (long long)sum[0], v->ndomain_verts);
    if (sum[1] != v->rank_total)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section DOMAINS: ranks sum to %lld, META rank_total is %d",
                    (long long)sum[1], v->rank_total);
    if (sum[2] != v->ncub)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section DOMAINS: domains own %lld cubature tets, META ncub is %d",
                    (long long)sum[2], v->ncub);
    if (sum[3] != v->nbasis)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section BASIS: holds %lld doubles, the domains need %lld",
                    (long long)v->nbasis, (long long)sum[3]);
    if (sum[4] != v->ninertia_u)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section INERTIA_U: holds %lld doubles, the domains need %lld",
                    (long long)v->ninertia_u, (long long)sum[4]);
    return SINEW_OK;
}

sinew_result sw_blob_check_copy_ptr(uint32_t ptr_id, uint32_t copies_id, const char *item,
                                    const int32_t *ptr, int32_t n, int32_t ncopies, char *msg,
                                    size_t ms) {
    const char *ptr_name = sw_blob_section_name(ptr_id),
               *copies_name = sw_blob_section_name(copies_id);
    if (ncopies < 1 || ncopies > SW_BLOB_MAX_COPIES)
        return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section %s: %d copies outside [1, %d]",
                    copies_name, ncopies, SW_BLOB_MAX_COPIES);
    if (ptr[0] != 0)
        return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section %s: element 0 is %d, not 0",
                    ptr_name, ptr[0]);
    /* Strictly increasing: a vertex is the mean of its copies, so it needs one. */
    for (int32_t i = 0; i < n; ++i)
        if (ptr[i + 1] <= ptr[i])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: %s %d has %lld copies (ptr %d -> %d); every %s needs "
                        "at least one",
                        ptr_name, item, i, (long long)ptr[i + 1] - ptr[i], ptr[i], ptr[i + 1],
                        item);
    if (ptr[n] != ncopies)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section %s: last element %d, but %s holds %d copies", ptr_name, ptr[n],
                    copies_name, ncopies);
    return SINEW_OK;
}

sinew_result sw_blob_check_copies(uint32_t id, const sw_blob_view *v, const int32_t *copies,
                                  int32_t ncopies, char *msg, size_t ms) {
    for (int32_t c = 0; c < ncopies; ++c) {
        int32_t d = copies[2 * (int64_t)c], l = copies[2 * (int64_t)c + 1];
        if (d < 0 || d >= v->ndomains)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: copy %d: domain %d outside [0, %d)",
                        sw_blob_section_name(id), c, d, v->ndomains);
        if (l < 0 || l >= v->domains[d].vert_count)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: copy %d: local vertex %d outside [0, %d) of domain %d",
                        sw_blob_section_name(id), c, l, v->domains[d].vert_count, d);
    }
    return SINEW_OK;
}

sinew_result sw_blob_check_finite(uint32_t id, const double *a, int64_t n, char *msg, size_t ms) {
    for (int64_t i = 0; i < n; ++i)
        if (!isfinite(a[i]))
            return fail(msg, ms, SINEW_ERROR_NOT_FINITE, "blob section %s: element %lld is %g",
                        sw_blob_section_name(id), (long long)i, a[i]);
    return SINEW_OK;
}

/* Every double of the view: the sections of element type double. (_Generic picks, per
 * row, the array and its count for doubles and NULL otherwise.) */
static sinew_result check_all_finite(const sw_blob_view *v, char *msg, size_t ms) {
    SW_BLOB_COUNT_LOCALS(v);
    const struct {
        uint32_t id;
        const double *a;
        uint64_t n;
    } arrays[] = {
#define DOUBLES(id, NAME, elem_size, type, field, by_meta, count, formula)                         \
    {id, _Generic((type *)0, double * : v->field, default : NULL), count},
        SINEW_BLOB_ARRAY_SECTIONS(DOUBLES)
#undef DOUBLES
    };
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) {
        if (!arrays[i].a) continue;
        sinew_result r =
            sw_blob_check_finite(arrays[i].id, arrays[i].a, (int64_t)arrays[i].n, msg, ms);
        if (r != SINEW_OK) return r;
    }
    return SINEW_OK;
}

/* Parent links must end at a root (-1) from every bone. A walk from each bone stops at a
 * root or at a bone already proven acyclic, then marks its path: O(nbones) in all. */
static sinew_result check_bone_tree(const sw_blob_view *v, char *msg, size_t ms) {
    const int32_t nb = v->nbones;
    for (int32_t b = 0; b < nb; ++b)
        if (v->bone_parent[b] < -1 || v->bone_parent[b] >= nb)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section BONE_PARENT: bone %d: parent %d outside [-1, %d)", b,
                        v->bone_parent[b], nb);
    uint64_t done[SW_BLOB_MAX_BONES / 64];
    memset(done, 0, ((size_t)nb + 63) / 64 * sizeof done[0]);
#define DONE(c) ((done[(c) >> 6] >> ((c)&63)) & 1u)
    for (int32_t b = 0; b < nb; ++b) {
        int32_t steps = 0;
        for (int32_t c = b; c >= 0 && !DONE(c); c = v->bone_parent[c])
            if (++steps > nb)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section BONE_PARENT: bone %d: its parent chain has a cycle", b);
        for (int32_t c = b; c >= 0 && !DONE(c); c = v->bone_parent[c])
            done[c >> 6] |= (uint64_t)1 << (c & 63);
    }
#undef DONE
    return SINEW_OK;
}

sinew_result sw_blob_check_influences(uint32_t bone_id, uint32_t weight_id, const int32_t *bone,
                                      const double *weight, int32_t n, int32_t nbones, char *msg,
                                      size_t ms) {
    for (int32_t i = 0; i < n; ++i) {
        double sum = 0.0;
        for (int k = 0; k < SW_BLOB_INFLUENCES; ++k) {
            int32_t b = bone[4 * (int64_t)i + k];
            double w = weight[4 * (int64_t)i + k];
            if (b < 0 || b >= nbones)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section %s: vertex %d influence %d: bone %d outside [0, %d)",
                            sw_blob_section_name(bone_id), i, k, b, nbones);
            if (!(w >= 0.0))
                return fail(msg, ms, isnan(w) ? SINEW_ERROR_NOT_FINITE : SINEW_ERROR_CORRUPT,
                            "blob section %s: vertex %d influence %d: weight %g < 0",
                            sw_blob_section_name(weight_id), i, k, w);
            sum += w;
        }
        if (!(fabs(sum - 1.0) <= SW_BLOB_WEIGHT_SUM_TOL))
            return fail(msg, ms, isfinite(sum) ? SINEW_ERROR_CORRUPT : SINEW_ERROR_NOT_FINITE,
                        "blob section %s: vertex %d: weights sum to %.9g, not 1 (tol %g)",
                        sw_blob_section_name(weight_id), i, sum, SW_BLOB_WEIGHT_SUM_TOL);
    }
    return SINEW_OK;
}

static sinew_result check_domain_indices(const sw_blob_view *v, char *msg, size_t ms) {
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        for (int32_t k = 0; k < dom->vert_count; ++k) {
            int32_t s = v->domain_verts[(int64_t)dom->vert_begin + k];
            if (s < 0 || s >= v->nverts)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section DOMAIN_VERTS: domain %d local vertex %d: vertex %d "
                            "outside [0, %d)",
                            d, k, s, v->nverts);
        }
        for (int32_t c = dom->cub_begin; c < dom->cub_begin + dom->cub_count; ++c)
            for (int k = 0; k < 4; ++k) {
                int32_t l = v->cub_tets[4 * (int64_t)c + k];
                if (l < 0 || l >= dom->vert_count)
                    return fail(msg, ms, SINEW_ERROR_CORRUPT,
                                "blob section CUB_TETS: tet %d corner %d (domain %d): local "
                                "vertex %d outside [0, %d)",
                                c, k, d, l, dom->vert_count);
            }
    }
    return SINEW_OK;
}

static sinew_result check_surface(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r = sw_blob_check_indices(SINEW_SECTION_SURF_TRIS, "triangle", 3, v->surf_tris,
                                           v->nsurf_tris, "vertex", v->nsurf_verts, msg, ms);
    if (r != SINEW_OK) return r;
    return sw_blob_check_copies(SINEW_SECTION_SURF_COPIES, v, v->surf_copies, v->nsurf_copies, msg,
                                ms);
}

sinew_result sw_blob_check_positive(uint32_t id, const double *a, int64_t n, int64_t stride,
                                    char *msg, size_t ms) {
    for (int64_t i = 0; i < n; ++i)
        if (!(a[i * stride] > 0.0))
            return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section %s: %s %lld is %g, must be > 0",
                        sw_blob_section_name(id), stride > 1 ? "diagonal entry" : "element",
                        (long long)i, a[i * stride]);
    return SINEW_OK;
}

/* Pose-space contacts: pointers from 0 to ncontacts without decreasing, every vertex
 * reference a valid (domain, local vertex), area weights positive. */
static sinew_result check_contacts(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->contact_ptr[0] != 0 || v->contact_ptr[v->ntrain] != v->ncontacts)
        return fail(
            msg, ms, SINEW_ERROR_CORRUPT,
            "blob section CONTACT_PTR: runs from %d to %d, must run from 0 to ncontacts = %d",
            v->contact_ptr[0], v->contact_ptr[v->ntrain], v->ncontacts);
    for (int32_t t = 0; t < v->ntrain; ++t)
        if (v->contact_ptr[t + 1] < v->contact_ptr[t])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section CONTACT_PTR: entry %d (%d) below entry %d (%d)", t + 1,
                        v->contact_ptr[t + 1], t, v->contact_ptr[t]);
    for (int32_t c = 0; c < v->ncontacts; ++c) {
        for (int k = 0; k < 4; ++k) {
            int32_t d = v->contact_verts[8 * c + 2 * k], l = v->contact_verts[8 * c + 2 * k + 1];
            if (d < 0 || d >= v->ndomains || l < 0 || l >= v->domains[d].vert_count)
                return fail(
                    msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section CONTACT_VERTS: contact %d vertex %d: (domain %d, local %d) "
                    "out of range",
                    c, k, d, l);
        }
        if (!(v->contact_data[7 * c + 6] > 0))
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section CONTACT_DATA: contact %d has area weight %g (must be > 0)", c,
                        v->contact_data[7 * c + 6]);
    }
    return SINEW_OK;
}

sinew_result sw_blob_validate_view(const sw_blob_view *v, char *msg, size_t ms) {
    if (msg && ms) msg[0] = '\0';
    if (!v) return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT, "blob: view is NULL");
    sinew_result r;
    if ((r = check_meta(v, msg, ms)) != SINEW_OK) return r;
    if ((r = check_pointers(v, msg, ms)) != SINEW_OK) return r;
    if ((r = check_domains(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_check_copy_ptr(SINEW_SECTION_SURF_COPY_PTR, SINEW_SECTION_SURF_COPIES,
                                    "surface vertex", v->surf_copy_ptr, v->nsurf_verts,
                                    v->nsurf_copies, msg, ms)) != SINEW_OK)
        return r;
    if ((r = check_all_finite(v, msg, ms)) != SINEW_OK) return r;
    if ((r = check_bone_tree(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_check_influences(SINEW_SECTION_SKIN_BONE, SINEW_SECTION_SKIN_WEIGHT,
                                      v->skin_bone, v->skin_weight, v->nverts, v->nbones, msg,
                                      ms)) != SINEW_OK)
        return r;
    if ((r = check_domain_indices(v, msg, ms)) != SINEW_OK) return r;
    if ((r = check_surface(v, msg, ms)) != SINEW_OK) return r;
    if ((r = check_contacts(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_render_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_check_positive(SINEW_SECTION_CUB_WEIGHT, v->cub_weight, v->ncub, 1, msg,
                                    ms)) ||
        (r = sw_blob_check_positive(SINEW_SECTION_CUB_VOL, v->cub_vol, v->ncub, 1, msg, ms)))
        return r;
    if ((r = sw_blob_blocks_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_cond_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_pair_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_force_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_stiffness_validate(v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_lod_validate(v, msg, ms)) != SINEW_OK) return r;
    return sw_blob_asset_validate(v, msg, ms);
}

/* ---- layer 1: bytes --------------------------------------------------------------- */

static sinew_result check_header(const sinew_blob_header *h, size_t size, char *msg, size_t ms) {
    if (memcmp(h->magic, SINEW_BLOB_MAGIC, sizeof h->magic) != 0)
        return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob header: bad magic, not a sinew blob");
    if (h->version < SINEW_BLOB_VERSION_MIN || h->version > SINEW_BLOB_VERSION)
        return fail(msg, ms, SINEW_ERROR_VERSION,
                    "blob header: format version %u, this runtime reads versions %u to %u",
                    (unsigned)h->version, SINEW_BLOB_VERSION_MIN, SINEW_BLOB_VERSION);
    if (h->endian_tag != SINEW_BLOB_ENDIAN_TAG)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: endian tag 0x%08x, expected 0x%08x (little-endian blob on a "
                    "little-endian host)",
                    (unsigned)h->endian_tag, SINEW_BLOB_ENDIAN_TAG);
    if (h->header_size != HEADER_SIZE || h->section_table_offset != HEADER_SIZE)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: header_size %u / section_table_offset %llu, expected 64",
                    (unsigned)h->header_size, (unsigned long long)h->section_table_offset);
    for (size_t i = 0; i < sizeof h->reserved; ++i)
        if (h->reserved[i] != 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob header: reserved byte %zu is not 0", i);
    if (h->file_size != (uint64_t)size)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: file_size %llu, but %zu bytes given (truncated or padded)",
                    (unsigned long long)h->file_size, size);
    if (h->section_count > SW_BLOB_MAX_SECTIONS ||
        h->section_count > (size - HEADER_SIZE) / ENTRY_SIZE)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section table: %u entries do not fit (limit %d, %zu bytes)",
                    (unsigned)h->section_count, SW_BLOB_MAX_SECTIONS, size);
    return SINEW_OK;
}

/* Section names in messages: known name, or the unknown id. */
static const char *entry_name(const sinew_blob_section *s, char buf[32]) {
    if (s->id >= 1 && s->id <= SINEW_SECTION_ID_MAX) return sw_blob_section_name(s->id);
    snprintf(buf, 32, "with unknown id %u", (unsigned)s->id);
    return buf;
}

/* Bounds, alignment and size of every entry; fills end[] and found[] (index of each
 * known id, -1 when absent). */
static sinew_result check_entries(const sinew_blob_section *s, uint32_t n, size_t size,
                                  uint64_t *end, int found[], char *msg, size_t ms) {
    const uint64_t table_end = HEADER_SIZE + (uint64_t)n * ENTRY_SIZE;
    char buf[32];
    for (uint32_t i = 0; i < n; ++i) {
        const char *name = entry_name(&s[i], buf);
        const int known = s[i].id >= 1 && s[i].id <= SINEW_SECTION_ID_MAX;
        if (s[i].offset % SINEW_BLOB_ALIGN != 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s (table entry %u): offset %llu is not a multiple of %u",
                        name, i, (unsigned long long)s[i].offset, SINEW_BLOB_ALIGN);
        if (s[i].offset < table_end || s[i].offset > size)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s (table entry %u): offset %llu outside [%llu, %zu] "
                        "(header and table end at %llu)",
                        name, i, (unsigned long long)s[i].offset, (unsigned long long)table_end,
                        size, (unsigned long long)table_end);
        if (known) {
            if (found[s[i].id] >= 0)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section %s: appears twice (table entries %d and %u)", name,
                            found[s[i].id], i);
            if (s[i].elem_size != k_sections[s[i].id].elem_size)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section %s (table entry %u): elem_size %u, expected %u", name, i,
                            (unsigned)s[i].elem_size, (unsigned)k_sections[s[i].id].elem_size);
            if (s[i].reserved != 0)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section %s (table entry %u): reserved field is not 0", name, i);
            found[s[i].id] = (int)i;
        }
        const uint64_t room = (uint64_t)size - s[i].offset;
        if (s[i].elem_size != 0 && s[i].count > room / s[i].elem_size)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s (table entry %u): %llu elements of %u bytes at offset "
                        "%llu run past the end (%zu bytes)",
                        name, i, (unsigned long long)s[i].count, (unsigned)s[i].elem_size,
                        (unsigned long long)s[i].offset, size);
        end[i] = s[i].offset + s[i].count * s[i].elem_size;
    }
    return SINEW_OK;
}

static sinew_result check_overlaps(const sinew_blob_section *s, uint32_t n, const uint64_t *end,
                                   char *msg, size_t ms) {
    /* n <= SW_BLOB_MAX_SECTIONS, so the quadratic scan is bounded (4560 pairs). */
    char b1[32], b2[32];
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = i + 1; j < n; ++j)
            if (end[i] > s[i].offset && end[j] > s[j].offset && s[i].offset < end[j] &&
                s[j].offset < end[i])
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section %s [%llu, %llu) overlaps section %s [%llu, %llu)",
                            entry_name(&s[i], b1), (unsigned long long)s[i].offset,
                            (unsigned long long)end[i], entry_name(&s[j], b2),
                            (unsigned long long)s[j].offset, (unsigned long long)end[j]);
    return SINEW_OK;
}

sinew_result sw_blob_check_counts(const sinew_blob_section *s, const int found[],
                                  const sw_blob_count_expect *e, size_t n, const char *meta,
                                  char *msg, size_t ms) {
    for (size_t i = 0; i < n; ++i) {
        const sinew_blob_section *at = &s[found[e[i].id]];
        if (e[i].by_meta && at->count != e[i].count)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: %llu elements, %s needs %s = %llu",
                        sw_blob_section_name(e[i].id), (unsigned long long)at->count, meta,
                        e[i].formula, (unsigned long long)e[i].count);
    }
    return SINEW_OK;
}

sinew_result sw_blob_group_meta(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], uint32_t first, uint32_t last, const char *what,
                                void *meta, size_t meta_size, size_t nreserved, int *present,
                                char *msg, size_t ms) {
    uint32_t n = 0;
    for (uint32_t id = first; id <= last; ++id)
        n += found[id] >= 0;
    *present = n > 0;
    if (n == 0) return SINEW_OK;
    for (uint32_t id = first; id <= last; ++id)
        if (found[id] < 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: missing (%s sections come all or none)",
                        sw_blob_section_name(id), what);
    const sinew_blob_section *m = &s[found[first]];
    if (m->count != 1)
        return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section %s: %llu elements, expected 1",
                    sw_blob_section_name(first), (unsigned long long)m->count);
    memcpy(meta, bytes + m->offset, meta_size);
    for (size_t i = 0; i < nreserved; ++i) {
        int32_t w;
        memcpy(&w, (const uint8_t *)meta + meta_size - 4 * (nreserved - i), sizeof w);
        if (w != 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section %s: reserved word %zu is %d, not 0",
                        sw_blob_section_name(first), i, w);
    }
    return SINEW_OK;
}

/* Reads META into the view's counts; checks the counts of every section; points the
 * view's arrays at the sections. */
static sinew_result fill_view(const uint8_t *bytes, const sinew_blob_section *s, const int found[],
                              sw_blob_view *v, char *msg, size_t ms) {
    const sinew_blob_section *meta = &s[found[SINEW_SECTION_META]];
    if (meta->count != 1)
        return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section META: %llu elements, expected 1",
                    (unsigned long long)meta->count);
    sinew_blob_meta m;
    memcpy(&m, bytes + meta->offset, sizeof m);
    memset(v, 0, sizeof *v);
#define FROM_META(field) v->field = m.field;
    SW_BLOB_META_FIELDS(FROM_META)
#undef FROM_META
    sinew_result r = check_meta(v, msg, ms);
    if (r != SINEW_OK) return r;
    {
        /* The sections whose size follows from META alone (by_meta); the other rows' counts
         * read nbasis, ninertia_u, nsurf_copies, nspring_hessian and nmass, still 0 here,
         * and go unused. */
        SW_BLOB_COUNT_LOCALS(v);
        const sw_blob_count_expect expect[] = {SINEW_BLOB_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
        if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0], "META",
                                      msg, ms)) != SINEW_OK)
            return r;
    }

    /* Sizes that depend on the domain records: recorded here, checked against the
     * records by the view validator. Each count is bounded by the file size. */
    const sinew_blob_section *copies = &s[found[SINEW_SECTION_SURF_COPIES]];
    if (copies->count % 2 != 0 || copies->count / 2 > (uint64_t)SW_BLOB_MAX_COPIES)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section SURF_COPIES: %llu elements, expected an even number <= %d",
                    (unsigned long long)copies->count, 2 * SW_BLOB_MAX_COPIES);
    v->nbasis = (int64_t)s[found[SINEW_SECTION_BASIS]].count;
    v->ninertia_u = (int64_t)s[found[SINEW_SECTION_INERTIA_U]].count;
    v->nsurf_copies = (int32_t)(copies->count / 2);

    SINEW_BLOB_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

sinew_result sw_blob_parse(const void *data, size_t size, sw_blob_view *view, char *msg,
                           size_t ms) {
    if (msg && ms) msg[0] = '\0';
    if (!data || !view)
        return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT, "blob: %s is NULL",
                    data ? "view" : "data");
    /* Sections are used in place as double/int64 arrays. */
    if ((uintptr_t)data % 8 != 0)
        return fail(msg, ms, SINEW_ERROR_INVALID_ARGUMENT,
                    "blob: data at %p is not 8-byte aligned (64 recommended)", data);
    const uint8_t *bytes = data;
    if (size < HEADER_SIZE)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: %zu bytes given, shorter than the 64-byte header", size);
    sinew_blob_header h;
    memcpy(&h, bytes, sizeof h);
    sinew_result r = check_header(&h, size, msg, ms);
    if (r != SINEW_OK) return r;
    /* Checksum before any payload check: a damaged file is reported as damaged, not as
     * whatever its first damaged field happens to look like. */
    const uint64_t sum = sw_blob_checksum(bytes + HEADER_SIZE, size - HEADER_SIZE);
    if (sum != h.checksum)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob header: checksum mismatch (stored %016llx, computed %016llx): the "
                    "blob is damaged",
                    (unsigned long long)h.checksum, (unsigned long long)sum);

    sinew_blob_section s[SW_BLOB_MAX_SECTIONS];
    uint64_t end[SW_BLOB_MAX_SECTIONS];
    const uint32_t n = h.section_count;
    memcpy(s, bytes + HEADER_SIZE, (size_t)n * sizeof s[0]);
    int found[SINEW_SECTION_ID_MAX + 1];
    for (int i = 0; i <= SINEW_SECTION_ID_MAX; ++i)
        found[i] = -1;
    if ((r = check_entries(s, n, size, end, found, msg, ms)) != SINEW_OK) return r;
    if ((r = check_overlaps(s, n, end, msg, ms)) != SINEW_OK) return r;
    for (uint32_t id = 1; id <= SINEW_SECTION_COUNT_V1; ++id)
        if (found[id] < 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT, "blob section %s: missing",
                        sw_blob_section_name(id));

    sw_blob_view v;
    if ((r = fill_view(bytes, s, found, &v, msg, ms)) != SINEW_OK) return r;
    if ((r = sw_blob_render_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_cond_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_pair_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_force_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_asset_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_stiffness_fill(bytes, s, found, h.version, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_blocks_fill(bytes, s, found, h.version, &v, msg, ms)) != SINEW_OK ||
        (r = sw_blob_lod_fill(bytes, s, found, &v, msg, ms)) != SINEW_OK)
        return r;
    if ((r = sw_blob_validate_view(&v, msg, ms)) != SINEW_OK) return r;
    *view = v;
    return SINEW_OK;
}
