/* The sinew blob, format version 1: one baked character, position independent and
 * usable in place from a file mapping or a host buffer (DESIGN.md §6).
 *
 * Layout (all integers and floats little-endian, IEEE-754 doubles):
 *
 *   offset 0    sinew_blob_header (64 bytes)
 *   offset 64   section_count x sinew_blob_section (32 bytes each)
 *   ...         sections, each starting at a multiple of 64 bytes, zero padding between
 *
 * The checksum is FNV-1a 64 over bytes [64, file_size): the section table and every
 * section. A section is one array of `count` elements of `elem_size` bytes. Sections
 * may come in any order but must not overlap each other or the header/table; unknown
 * section ids are skipped (a later minor version may add some); a known id appears at
 * most once.
 *
 * Sections of version 1 (R = rank_total, n = nverts, see sw_blob_view in the runtime
 * for the meaning of every array):
 *
 *   id name            elem  count
 *   1  META            80    1      (sinew_blob_meta)
 *   2  REST            8     3n
 *   3  SKIN_BONE       4     4n
 *   4  SKIN_WEIGHT     8     4n
 *   5  BONE_PARENT     4     nbones
 *   6  BONE_JOINTS     8     6 nbones
 *   7  DOMAINS         48    ndomains (sinew_blob_domain_record)
 *   8  DOMAIN_VERTS    4     ndomain_verts
 *   9  BASIS           8     sum_d vert_count_d * 3 * rank_d
 *   10 CUB_TETS        4     4 ncub
 *   11 CUB_WEIGHT      8     ncub
 *   12 CUB_DMINV       8     9 ncub
 *   13 CUB_VOL         8     ncub
 *   14 SPRING_HESSIAN  8     R*R
 *   15 MASS            8     R*R
 *   16 INERTIA_S       8     3R
 *   17 INERTIA_X       8     9R
 *   18 INERTIA_U       8     sum_d 9 rank_d^2
 *   19 SURF_TRIS       4     3 nsurf_tris
 *   20 SURF_COPY_PTR   4     nsurf_verts + 1
 *   21 SURF_COPIES     4     2 * surf_copy_ptr[nsurf_verts]
 *   22 TRAIN_Q         8     ntrain * R     (reduced solutions of the training poses)
 *   23 TRAIN_POSE      8     ntrain * 4 nbones (pose features: unit quaternions, in the
 *                                               order solved: a pose stored twice is two
 *                                               branches, told apart by pose t - 1)
 *   24 CONTACT_PTR     4     ntrain + 1     (training pose t owns contacts [ptr[t], ptr[t+1]))
 *   25 CONTACT_VERTS   4     8 ncontacts    ((domain, local vertex) of p, t0, t1, t2)
 *   26 CONTACT_DATA    8     7 ncontacts    (barycentrics b0..b2, rest-frame normal, area ka)
 */
#ifndef SINEW_BLOB_FORMAT_H
#define SINEW_BLOB_FORMAT_H

#include <stdint.h>

#define SINEW_BLOB_MAGIC "SINEWBLB" /* 8 bytes, no terminator in the file */
#define SINEW_BLOB_VERSION 1u
#define SINEW_BLOB_ALIGN 64u
#define SINEW_BLOB_ENDIAN_TAG 0x01020304u

/** The fixed header at offset 0. */
typedef struct sinew_blob_header {
    char magic[8];                 /**< SINEW_BLOB_MAGIC */
    uint32_t version;              /**< SINEW_BLOB_VERSION */
    uint32_t header_size;          /**< 64 */
    uint64_t file_size;            /**< total bytes of the blob */
    uint32_t section_count;        /**< entries in the section table */
    uint32_t endian_tag;           /**< SINEW_BLOB_ENDIAN_TAG as written (little-endian) */
    uint64_t checksum;             /**< FNV-1a 64 of bytes [64, file_size) */
    uint64_t section_table_offset; /**< 64 */
    uint8_t reserved[16];          /**< zero */
} sinew_blob_header;

/** One entry of the section table. */
typedef struct sinew_blob_section {
    uint32_t id;        /**< section id (see above) */
    uint32_t elem_size; /**< bytes per element */
    uint64_t offset;    /**< from the start of the blob, a multiple of 64 */
    uint64_t count;     /**< elements */
    uint64_t reserved;  /**< zero */
} sinew_blob_section;

enum sinew_blob_section_id {
    SINEW_SECTION_META = 1,
    SINEW_SECTION_REST = 2,
    SINEW_SECTION_SKIN_BONE = 3,
    SINEW_SECTION_SKIN_WEIGHT = 4,
    SINEW_SECTION_BONE_PARENT = 5,
    SINEW_SECTION_BONE_JOINTS = 6,
    SINEW_SECTION_DOMAINS = 7,
    SINEW_SECTION_DOMAIN_VERTS = 8,
    SINEW_SECTION_BASIS = 9,
    SINEW_SECTION_CUB_TETS = 10,
    SINEW_SECTION_CUB_WEIGHT = 11,
    SINEW_SECTION_CUB_DMINV = 12,
    SINEW_SECTION_CUB_VOL = 13,
    SINEW_SECTION_SPRING_HESSIAN = 14,
    SINEW_SECTION_MASS = 15,
    SINEW_SECTION_INERTIA_S = 16,
    SINEW_SECTION_INERTIA_X = 17,
    SINEW_SECTION_INERTIA_U = 18,
    SINEW_SECTION_SURF_TRIS = 19,
    SINEW_SECTION_SURF_COPY_PTR = 20,
    SINEW_SECTION_SURF_COPIES = 21,
    SINEW_SECTION_TRAIN_Q = 22,
    SINEW_SECTION_TRAIN_POSE = 23,
    SINEW_SECTION_CONTACT_PTR = 24,
    SINEW_SECTION_CONTACT_VERTS = 25,
    SINEW_SECTION_CONTACT_DATA = 26,
    SINEW_SECTION_COUNT_V1 = 26
};

/** Section META: counts and material (80 bytes). */
typedef struct sinew_blob_meta {
    int32_t nverts, nbones, ndomains, rank_total;
    int32_t ndomain_verts, ncub, nsurf_verts, nsurf_tris;
    double mu, lambda, rayleigh_alpha, rayleigh_beta, contact_k;
    int32_t ntrain;    /**< training poses kept for the pose-space warm start (>= 1) */
    int32_t ncontacts; /**< self-contact pairs over all training poses (>= 0) */
} sinew_blob_meta;

/** Section DOMAINS: one record per domain (48 bytes). */
typedef struct sinew_blob_domain_record {
    int32_t bone, vert_begin, vert_count, rank;
    int32_t q_offset, cub_begin, cub_count, reserved;
    int64_t basis_offset, inertia_offset;
} sinew_blob_domain_record;

#endif
