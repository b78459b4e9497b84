/* The optional asset description of a blob (sinew_blob_format.h, ids 52..56): bone names,
 * bind poses, the output vertices' sources and what the blob was baked from. Its sections'
 * presence and counts (layer 1, sw_blob_asset_fill) and its values (layer 2,
 * sw_blob_asset_validate, shared with the writer), in the manner of blob_pair.c. One pass
 * over each array, no allocation. */
#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_asset_meta) == 64, "ASSET_META is 64 bytes");

/* The counts bound every later index product (names: at most 256 bytes a bone). */
static sinew_result check_counts(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->nname_bytes < 2 * (int64_t)v->nbones || v->nname_bytes > 256 * (int64_t)v->nbones)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section ASSET_META: nname_bytes = %d outside [2 nbones, 256 nbones] "
                    "(nbones %d)",
                    v->nname_bytes, v->nbones);
    if (v->nsource_meshes < 0 || v->nsource_meshes > SW_BLOB_MAX_COUNT)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section ASSET_META: nsource_meshes = %d outside [0, %d]",
                    v->nsource_meshes, SW_BLOB_MAX_COUNT);
    if (v->noutput_verts < 1 || v->noutput_verts > SW_BLOB_MAX_COUNT)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section ASSET_META: noutput_verts = %d outside [1, %d]", v->noutput_verts,
                    SW_BLOB_MAX_COUNT);
    return SINEW_OK;
}

sinew_result sw_blob_asset_fill(const uint8_t *bytes, const sinew_blob_section *s,
                                const int found[], sw_blob_view *v, char *msg, size_t ms) {
    sinew_blob_asset_meta m;
    int present;
    sinew_result r =
        sw_blob_group_meta(bytes, s, found, SINEW_SECTION_ASSET_FIRST, SINEW_SECTION_ASSET_LAST,
                           "the asset description's", &m, sizeof m,
                           sizeof m.reserved / sizeof m.reserved[0], &present, msg, ms);
    if (r != SINEW_OK || !present) return r; /* none: the view's fields stay 0 / NULL */
#define FROM_META(name) v->name = m.name;
    SINEW_BLOB_ASSET_COUNTS(FROM_META)
#undef FROM_META
    v->sinew_version = m.sinew_version;
    v->source_hash = m.source_hash;
    v->options_hash = m.options_hash;
    if ((r = check_counts(v, msg, ms)) != SINEW_OK) return r;
    SW_BLOB_COUNT_LOCALS(v); /* nbones */
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_ASSET_COUNTS);
    const sw_blob_count_expect expect[] = {SINEW_BLOB_ASSET_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
    if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0],
                                  "ASSET_META and META", msg, ms)) != SINEW_OK)
        return r;
    SINEW_BLOB_ASSET_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
    return SINEW_OK;
}

/* nbones names of 1..255 bytes, each ended by a zero, filling the section exactly. */
static sinew_result check_names(const sw_blob_view *v, char *msg, size_t ms) {
    int64_t at = 0;
    for (int32_t b = 0; b < v->nbones; ++b) {
        int64_t len = 0;
        while (at + len < v->nname_bytes && v->bone_names[at + len] != '\0' && len < 256)
            ++len;
        if (at + len >= v->nname_bytes)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section BONE_NAMES: bone %d's name runs past the section's %d bytes",
                        b, v->nname_bytes);
        if (len < 1 || len > 255)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section BONE_NAMES: bone %d's name has %lld bytes, not 1..255", b,
                        (long long)len);
        at += len + 1;
    }
    if (at != v->nname_bytes)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section BONE_NAMES: %d names end at byte %lld of %d", v->nbones,
                    (long long)at, v->nname_bytes);
    return SINEW_OK;
}

/* Each output vertex's (mesh, vertex): both -1, or a mesh and one of its vertices. */
static sinew_result check_sources(const sw_blob_view *v, char *msg, size_t ms) {
    for (int32_t m = 0; m < v->nsource_meshes; ++m)
        if (v->source_mesh_verts[m] < 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section SOURCE_MESH_VERTS: mesh %d has %d vertices", m,
                        v->source_mesh_verts[m]);
    for (int32_t i = 0; i < v->noutput_verts; ++i) {
        const int32_t m = v->output_source[2 * (int64_t)i],
                      k = v->output_source[2 * (int64_t)i + 1];
        if (m == -1 && k == -1) continue;
        if (m < 0 || m >= v->nsource_meshes)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section OUTPUT_SOURCE: output vertex %d: mesh %d outside [0, %d) "
                        "(or -1 with vertex -1)",
                        i, m, v->nsource_meshes);
        if (k < 0 || k >= v->source_mesh_verts[m])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section OUTPUT_SOURCE: output vertex %d: vertex %d outside [0, %d) "
                        "of mesh %d",
                        i, k, v->source_mesh_verts[m], m);
    }
    return SINEW_OK;
}

sinew_result sw_blob_asset_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (!v->bone_names) return SINEW_OK;
    sinew_result r = check_counts(v, msg, ms);
    if (r != SINEW_OK) return r;
    const sw_blob_array_ref arrays[] = {SINEW_BLOB_ASSET_ARRAY_SECTIONS(SW_BLOB_ARRAY_REF_ROW)};
    if ((r = sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms)) ||
        (r = check_names(v, msg, ms)) ||
        (r = sw_blob_check_finite(SINEW_SECTION_BONE_BIND, v->bone_bind, 12 * (int64_t)v->nbones,
                                  msg, ms)))
        return r;
    if (v->noutput_verts != sw_blob_output_verts(v))
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section ASSET_META: noutput_verts %d, the output surface has %d",
                    v->noutput_verts, sw_blob_output_verts(v));
    return check_sources(v, msg, ms);
}
