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
 * Sections of version 1: the table SINEW_BLOB_SECTIONS below, one row a section; the
 * section ids, the loader's section names, element sizes, count checks and view, and the
 * writer's section list are all generated from it. Notes on its rows (see sw_blob_view
 * in the runtime for the meaning of every array):
 *   META          one sinew_blob_meta, the counts and material (the view copies them:
 *                 `meta` names no view field); every other section is an array, a row
 *                 of SINEW_BLOB_ARRAY_SECTIONS
 *   DOMAINS       one sinew_blob_domain_record a domain
 *   SPRING_HESSIAN, MASS  the constant reduced matrices: their nonzero domain blocks in
 *                 version 4 (placed by REDUCED_BLOCKS, below), dense before
 *   TRAIN_Q       reduced solutions of the training poses
 *   TRAIN_POSE    pose features (unit quaternions), in the order solved: a pose stored
 *                 twice is two branches, told apart by pose t - 1
 *   CONTACT_PTR   training pose t owns contacts [ptr[t], ptr[t+1])
 *   CONTACT_VERTS (domain, local vertex) of p, t0, t1, t2
 *   CONTACT_DATA  barycentrics b0..b2, rest-frame normal, area ka
 *
 * Optional sections (SINEW_BLOB_RENDER_SECTIONS, ids 27..34): a render mesh embedded in
 * the tets, all eight present or none. A blob without them is byte for byte what it was
 * before they existed (its output surface is the tet mesh's boundary); a blob with them
 * outputs the render mesh, in its own vertex order, instead. A runtime that predates
 * them skips them as unknown ids and outputs the boundary. Their counts are in
 * RENDER_META (sinew_blob_render_meta), their rows:
 *   RENDER_TRIS        the render mesh's triangles, in its own order
 *   RENDER_TET         per render vertex, its embedding tet (a row of RENDER_TETS)
 *   RENDER_BARY        per render vertex, 4 barycentrics summing to 1 that reproduce its
 *                      rest position from the tet's corners (negative outside the tets)
 *   RENDER_WELD        per render vertex, the render vertex standing for every vertex at
 *                      its rest position (a UV seam's duplicates share one): weld[weld[i]]
 *                      = weld[i]; duplicates get the representative's position and normal
 *   RENDER_TETS        4 render nodes a tet: the simulation tets the mesh is embedded in
 *   RENDER_NODE_PTR    render node n (a simulation vertex) owns copies [ptr[n], ptr[n+1])
 *   RENDER_NODE_COPIES (domain, local vertex) of each copy; a node is the mean of them
 *
 * Optional sections (SINEW_BLOB_COND_SECTIONS, ids 35..44): the whole simulation tet mesh,
 * for subspace condensation's full-space patches, all ten present or none, but for
 * COND_TET_DMINV, which may be left out (the bake leaves it out: a runtime derives each
 * tet's rest Dm^-1 from its REST corners, and a runtime that predates this refuses the
 * group without it). A
 * blob without them is byte for byte what it was before they existed; a runtime that
 * predates them skips them as unknown ids. Every tet lies in one domain (the domain the
 * bake gave it: all four corners have copies there), as a cubature tet does. Their counts
 * are in COND_META (sinew_blob_cond_meta) and META (nverts, ncub), their rows:
 *   COND_TETS         4 global simulation vertex ids a tet, all distinct
 *   COND_TET_DOMAIN   per tet, the domain whose copies are its corners
 *   COND_TET_LOCAL    4 a tet: its corners' local vertex indices in that domain
 *                     (domain_verts[vert_begin + local] is the COND_TETS corner)
 *   COND_TET_DMINV    9 a tet: rest Dm^-1, row-major (as CUB_DMINV); when left out, every
 *                     tet's REST corners must be invertible and give its COND_TET_VOL
 *                     exactly, with the rest data a cubature tet's must equal (below)
 *   COND_TET_VOL      per tet, its rest volume > 0 (as CUB_VOL)
 *   COND_VERT_TET_PTR vertex v's incident tets are COND_VERT_TETS [ptr[v], ptr[v+1])
 *   COND_VERT_TETS    tet ids, ascending per vertex: every (vertex, tet) incidence once
 *   COND_VERT_MASS    per vertex, its lumped mass (> 0; 0 only for a vertex in no tet)
 *   COND_CUB_TET_ID   per cubature tet (ncub), its tet id: the tet's domain, corners,
 *                     Dm^-1 and volume are the cubature tet's
 *
 * Optional sections (SINEW_BLOB_PAIR_SECTIONS, ids 45..50): pose-space self-contact per
 * pair of domains (thesis §3.2.3), all six present or none. A blob without them is byte for
 * byte what it was before they existed; a runtime that predates them skips them. A group
 * is an ordered pair of domains (a, b): the contacts whose vertex p is in a (its CONTACT_VERTS
 * domain) and whose triangle's first corner t0 is in b. Its pose feature is 6 uncentred PCA
 * coordinates of b's surface in a's frame, a linear map of the two bones' relative rigid
 * transform. Counts in PAIR_META (sinew_blob_pair_meta) and META (ntrain, ncontacts), rows:
 *   PAIR_DOMAINS  per group, a and b (a == b: a domain against itself)
 *   PAIR_MAP      per group, 6 x 12 row-major: feature = MAP [vec(R) ; t], R (row-major)
 *                 and t the relative transform T_bone(a)^-1 T_bone(b)
 *   PAIR_FEATURE  per group, per training pose, its 6 feature coordinates ([g][t][6])
 *   PAIR_PTR      pose t's contacts of group g are [ptr[t G + g], ptr[t G + g + 1]), G groups;
 *                 ptr[t G] = CONTACT_PTR[t], ptr[ntrain G] = ncontacts (a pose's contacts
 *                 sorted by group)
 *   PAIR_WEIGHT   per contact, its cubature weight >= 0 (eqs. 3.9-3.13; 0: left out)
 *
 * Optional section (SINEW_BLOB_FORCE_SECTIONS, id 51): the pose-space equilibrium force.
 * A blob without it is byte for byte what it was before it existed; a runtime that
 * predates it skips it (and steps as such a blob steps). Count from META:
 *   TRAIN_FORCE   per training pose t, the reduced force b_t (rank_total doubles, finite)
 *                 that makes TRAIN_Q's solution of t the quasistatic step's equilibrium at
 *                 pose t: minus the gradient of the step's potential there, with t's
 *                 pose-space self-contact ([t][rank_total])
 *
 * Optional sections (SINEW_BLOB_ASSET_SECTIONS, ids 52..56): what a host that imports the
 * source asset itself needs to drive the blob, all five present or none. A blob without
 * them is byte for byte what it was before they existed; a runtime that predates them skips
 * them (they change nothing in a step). Counts in ASSET_META (sinew_blob_asset_meta) and
 * META (nbones), rows:
 *   BONE_NAMES     nbones names, each 1..255 bytes and its terminating zero, in bone order
 *                  (the file's node names: glTF joint names; "bone N" when the source had
 *                  none)
 *   BONE_BIND      per bone, its bind-pose global transform in the bake's rest space: 3x3
 *                  row-major, then the translation (12 doubles, finite)
 *   SOURCE_MESH_VERTS per mesh of the source file (as imported), its vertex count (>= 0)
 *   OUTPUT_SOURCE  per output vertex (the render mesh's when embedded, else the tet
 *                  boundary's), the source mesh and the vertex within it, or (-1, -1) for
 *                  a vertex that has none (a tet boundary's)
 *
 * Optional sections (SINEW_BLOB_STIFFNESS_SECTIONS, ids 57, 58): painted material, only in
 * a blob of version 3 (a runtime that predates them refuses the
 * blob rather than step it unpainted). Each tet's elastic energy is its multiplier times
 * the energy at META's mu and lambda (the Poisson ratio is the character's):
 *   CUB_STIFFNESS  per cubature tet, its multiplier (finite, > 0)
 *   TET_STIFFNESS  per tet of the condensation mesh (ntets of COND_META; absent, with
 *                  CUB_STIFFNESS still present, when the blob has no such mesh), its
 *                  multiplier; a cubature tet's equals its COND_CUB_TET_ID tet's
 *
 * Optional sections (SINEW_BLOB_LOD_SECTIONS, ids 59..64): the pose-space level of detail
 * (SINEW_LOD_POSE_SPACE), all six present or none; a runtime that predates them skips them.
 * Each output vertex s is skinned on its own, x_s = DQS_s(X_s + d_s), its rest-frame
 * displacement d_s = V_s c, c = W f linear in the pose's joint rotations (f: each bone's
 * rotation relative to its parent's, less the identity, 9 entries row-major a bone, zero
 * for a root; then 1), no solve:
 *   LOD_REST       per output vertex, X_s (3 doubles, finite)
 *   LOD_BONE       per output vertex, 4 bone ids in [0, nbones)
 *   LOD_WEIGHT     per output vertex, 4 weights (finite, >= 0, summing to 1 within 1e-6)
 *   LOD_BASIS      lod_rank modes, each 3 floats per output vertex (in [-1, 1]: the
 *                  modes are orthonormal)
 *   LOD_MAP        W, lod_rank rows of 9 nbones + 1 (finite)
 *
 * The reduced matrices by domain blocks (SINEW_BLOB_BLOCKS_SECTIONS, id 65; in every blob
 * of version 4 and in none before). Block (a, b) of MASS or SPRING_HESSIAN is the rank_a x
 * rank_b block at rows q_offset_a, columns q_offset_b. In version 4 each section holds
 * only its stored blocks, back to back in (a, b) row-major order, each rank_a x rank_b
 * row-major; a block not stored is zero. In versions 2 and 3 each is the dense rank_total
 * x rank_total matrix, row-major, and REDUCED_BLOCKS is absent.
 *   REDUCED_BLOCKS  [m][a][b], m 0 for MASS and 1 for SPRING_HESSIAN: the block's first
 *                   element in its section, or -1 for a zero block; every diagonal block
 *                   is stored, and the stored blocks' offsets run on without gaps (the
 *                   first at 0, each next one where the one before ends, the section's
 *                   count where the last ends)
 */
#ifndef SINEW_BLOB_FORMAT_H
#define SINEW_BLOB_FORMAT_H

#include <stdint.h>

#define SINEW_BLOB_MAGIC "SINEWBLB" /* 8 bytes, no terminator in the file */
/* 2: pose features measure roots from the first root; 3: the blob has painted material
 * (SINEW_BLOB_STIFFNESS_SECTIONS), which a version-2 runtime would skip and step the
 * character as if unpainted. A blob without painted material is written as version 2.
 * 4: MASS and SPRING_HESSIAN hold only their nonzero domain blocks, placed by
 * REDUCED_BLOCKS (SINEW_BLOB_BLOCKS_SECTIONS), which a version-3 runtime would read as
 * dense matrices; painted material is optional in version 4. A blob whose reduced
 * matrices are dense is written as version 2 or 3, as before. */
#define SINEW_BLOB_VERSION 4u
#define SINEW_BLOB_VERSION_MIN 2u
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

/* The names a section's count is written in: META's counts (sinew_blob_meta), and five
 * counts that the sections' own sizes give and the domain records, the copy pointers and
 * the block placement must match:
 *   nbasis       = sum_d vert_count_d * 3 * rank_d  (doubles in BASIS)
 *   ninertia_u   = sum_d 9 rank_d^2                  (doubles in INERTIA_U)
 *   nsurf_copies = surf_copy_ptr[nsurf_verts]        ((domain, vertex) pairs in SURF_COPIES)
 *   nspring_hessian, nmass  = the stored blocks' sizes summed (version 4), rank_total^2
 *                             (versions 2 and 3) */
/* clang-format off */
#define SINEW_BLOB_META_COUNTS(X)                                                                  \
    X(nverts) X(nbones) X(ndomains) X(rank_total) X(ndomain_verts) X(ncub) X(nsurf_verts)          \
    X(nsurf_tris) X(ntrain) X(ncontacts)
#define SINEW_BLOB_COUNTS(X)                                                                       \
    SINEW_BLOB_META_COUNTS(X) X(nbasis) X(ninertia_u) X(nsurf_copies) X(nspring_hessian) X(nmass)

/* The sections, one row each: X(id, NAME, elem_size, type, field, by_meta, count, formula)
 *   id         section id (SINEW_SECTION_<NAME>); rows in id order, ids 1, 2, ... no gaps
 *   NAME       the section's name, as messages spell it
 *   elem_size  bytes per element in the file; type: the C type of one element (that size)
 *   field      the array's name (the sw_blob_view field the runtime points at it)
 *   by_meta    1 when META's counts alone fix the count: the loader checks it against them;
 *              0 when the section's count gives nbasis, ninertia_u, nsurf_copies,
 *              nspring_hessian or nmass
 *   count      elements: a C expression in the names of SINEW_BLOB_COUNTS
 *   formula    the count as messages write it */
#define SINEW_BLOB_SECTIONS(X)                                                                     \
    X( 1, META,           80, sinew_blob_meta, meta, 1, 1, "1")                                    \
    SINEW_BLOB_ARRAY_SECTIONS(X)

#define SINEW_BLOB_ARRAY_SECTIONS(X)                                                               \
    X( 2, REST,            8, double,  rest,           1, 3 * nverts,          "3 nverts")         \
    X( 3, SKIN_BONE,       4, int32_t, skin_bone,      1, 4 * nverts,          "4 nverts")         \
    X( 4, SKIN_WEIGHT,     8, double,  skin_weight,    1, 4 * nverts,          "4 nverts")         \
    X( 5, BONE_PARENT,     4, int32_t, bone_parent,    1, nbones,              "nbones")           \
    X( 6, BONE_JOINTS,     8, double,  bone_joints,    1, 6 * nbones,          "6 nbones")         \
    X( 7, DOMAINS,        48, sinew_blob_domain_record, domains, 1, ndomains, "ndomains")          \
    X( 8, DOMAIN_VERTS,    4, int32_t, domain_verts,   1, ndomain_verts,       "ndomain_verts")    \
    X( 9, BASIS,           8, double,  basis,          0, nbasis,              "nbasis")           \
    X(10, CUB_TETS,        4, int32_t, cub_tets,       1, 4 * ncub,            "4 ncub")           \
    X(11, CUB_WEIGHT,      8, double,  cub_weight,     1, ncub,                "ncub")             \
    X(12, CUB_DMINV,       8, double,  cub_dminv,      1, 9 * ncub,            "9 ncub")           \
    X(13, CUB_VOL,         8, double,  cub_vol,        1, ncub,                "ncub")             \
    X(14, SPRING_HESSIAN,  8, double,  spring_hessian, 0, nspring_hessian,     "nspring_hessian")  \
    X(15, MASS,            8, double,  mass,           0, nmass,               "nmass")            \
    X(16, INERTIA_S,       8, double,  inertia_s,      1, 3 * rank_total,      "3 rank_total")     \
    X(17, INERTIA_X,       8, double,  inertia_x,      1, 9 * rank_total,      "9 rank_total")     \
    X(18, INERTIA_U,       8, double,  inertia_u,      0, ninertia_u,          "ninertia_u")       \
    X(19, SURF_TRIS,       4, int32_t, surf_tris,      1, 3 * nsurf_tris,      "3 nsurf_tris")     \
    X(20, SURF_COPY_PTR,   4, int32_t, surf_copy_ptr,  1, nsurf_verts + 1,     "nsurf_verts + 1")  \
    X(21, SURF_COPIES,     4, int32_t, surf_copies,    0, 2 * nsurf_copies,    "2 nsurf_copies")   \
    X(22, TRAIN_Q,         8, double,  train_q, 1, ntrain * rank_total, "ntrain rank_total")       \
    X(23, TRAIN_POSE,      8, double,  train_pose,     1, 4 * ntrain * nbones, "4 ntrain nbones")  \
    X(24, CONTACT_PTR,     4, int32_t, contact_ptr,    1, ntrain + 1,          "ntrain + 1")       \
    X(25, CONTACT_VERTS,   4, int32_t, contact_verts,  1, 8 * ncontacts,       "8 ncontacts")      \
    X(26, CONTACT_DATA,    8, double,  contact_data,   1, 7 * ncontacts,       "7 ncontacts")

/* The optional render mesh (see above): counts named by SINEW_BLOB_RENDER_COUNTS, all from
 * RENDER_META; rows as in SINEW_BLOB_SECTIONS (by_meta 1: RENDER_META fixes every count). */
#define SINEW_BLOB_RENDER_COUNTS(X)                                                                \
    X(nrender_verts) X(nrender_tris) X(nembed_tets) X(nrender_nodes) X(nrender_copies)
#define SINEW_BLOB_RENDER_SECTIONS(X)                                                              \
    X(27, RENDER_META,     32, sinew_blob_render_meta, render_meta, 1, 1, "1")                    \
    SINEW_BLOB_RENDER_ARRAY_SECTIONS(X)
#define SINEW_BLOB_RENDER_ARRAY_SECTIONS(X)                                                        \
    X(28, RENDER_TRIS,      4, int32_t, render_tris,   1, 3 * nrender_tris,  "3 nrender_tris")    \
    X(29, RENDER_TET,       4, int32_t, render_tet,    1, nrender_verts,     "nrender_verts")     \
    X(30, RENDER_BARY,      8, double,  render_bary,   1, 4 * nrender_verts, "4 nrender_verts")   \
    X(31, RENDER_WELD,      4, int32_t, render_weld,   1, nrender_verts,     "nrender_verts")     \
    X(32, RENDER_TETS,      4, int32_t, render_tets,   1, 4 * nembed_tets,   "4 nembed_tets")     \
    X(33, RENDER_NODE_PTR,  4, int32_t, render_node_ptr, 1, nrender_nodes + 1, "nrender_nodes + 1") \
    X(34, RENDER_NODE_COPIES, 4, int32_t, render_node_copies, 1, 2 * nrender_copies,               \
      "2 nrender_copies")

/* The optional tet mesh for condensation (see above): counts named by SINEW_BLOB_COND_COUNTS
 * from COND_META, with META's nverts and ncub; rows as in SINEW_BLOB_SECTIONS. */
#define SINEW_BLOB_COND_COUNTS(X) X(ntets) X(nvert_tets)
#define SINEW_BLOB_COND_SECTIONS(X)                                                                \
    X(35, COND_META,         32, sinew_blob_cond_meta, cond_meta, 1, 1, "1")                       \
    SINEW_BLOB_COND_ARRAY_SECTIONS(X)
#define SINEW_BLOB_COND_ARRAY_SECTIONS(X)                                                          \
    X(36, COND_TETS,          4, int32_t, tets,         1, 4 * ntets,  "4 ntets")                  \
    X(37, COND_TET_DOMAIN,    4, int32_t, tet_domain,   1, ntets,      "ntets")                    \
    X(38, COND_TET_LOCAL,     4, int32_t, tet_local,    1, 4 * ntets,  "4 ntets")                  \
    X(39, COND_TET_DMINV,     8, double,  tet_dminv,    1, 9 * ntets,  "9 ntets")                  \
    X(40, COND_TET_VOL,       8, double,  tet_vol,      1, ntets,      "ntets")                    \
    X(41, COND_VERT_TET_PTR,  4, int32_t, vert_tet_ptr, 1, nverts + 1, "nverts + 1")               \
    X(42, COND_VERT_TETS,     4, int32_t, vert_tets,    1, nvert_tets, "nvert_tets")               \
    X(43, COND_VERT_MASS,     8, double,  vert_mass,    1, nverts,     "nverts")                   \
    X(44, COND_CUB_TET_ID,    4, int32_t, cub_tet_id,   1, ncub,       "ncub")

/* The optional per-pair self-contact (see above): counts named by SINEW_BLOB_PAIR_COUNTS
 * from PAIR_META, with META's ntrain and ncontacts; rows as in SINEW_BLOB_SECTIONS. */
#define SINEW_BLOB_PAIR_COUNTS(X) X(npair_groups)
#define SINEW_BLOB_PAIR_SECTIONS(X)                                                                \
    X(45, PAIR_META,         32, sinew_blob_pair_meta, pair_meta, 1, 1, "1")                       \
    SINEW_BLOB_PAIR_ARRAY_SECTIONS(X)
#define SINEW_BLOB_PAIR_ARRAY_SECTIONS(X)                                                          \
    X(46, PAIR_DOMAINS,  4, int32_t, pair_domains, 1, 2 * npair_groups,  "2 npair_groups")         \
    X(47, PAIR_MAP,      8, double,  pair_map,     1, 72 * npair_groups, "72 npair_groups")        \
    X(48, PAIR_FEATURE,  8, double,  pair_feature, 1, 6 * npair_groups * ntrain,                   \
      "6 npair_groups ntrain")                                                                     \
    X(49, PAIR_PTR,      4, int32_t, pair_ptr,     1, npair_groups * ntrain + 1,                   \
      "npair_groups ntrain + 1")                                                                   \
    X(50, PAIR_WEIGHT,   8, double,  pair_weight,  1, ncontacts,         "ncontacts")

/* The optional pose-space equilibrium force (id 51): one section, its count from META. */
#define SINEW_BLOB_FORCE_SECTIONS(X)                                                               \
    X(51, TRAIN_FORCE,   8, double,  train_force,  1, ntrain * rank_total, "ntrain rank_total")

/* The optional asset description (id 52..56): counts named by SINEW_BLOB_ASSET_COUNTS from
 * ASSET_META, with META's nbones; rows as in SINEW_BLOB_SECTIONS. */
#define SINEW_BLOB_ASSET_COUNTS(X) X(nname_bytes) X(nsource_meshes) X(noutput_verts)
#define SINEW_BLOB_ASSET_SECTIONS(X)                                                               \
    X(52, ASSET_META,        64, sinew_blob_asset_meta, asset_meta, 1, 1, "1")                     \
    SINEW_BLOB_ASSET_ARRAY_SECTIONS(X)
#define SINEW_BLOB_ASSET_ARRAY_SECTIONS(X)                                                         \
    X(53, BONE_NAMES,         1, char,    bone_names,   1, nname_bytes,      "nname_bytes")        \
    X(54, BONE_BIND,          8, double,  bone_bind,    1, 12 * nbones,      "12 nbones")          \
    X(55, SOURCE_MESH_VERTS,  4, int32_t, source_mesh_verts, 1, nsource_meshes, "nsource_meshes") \
    X(56, OUTPUT_SOURCE,      4, int32_t, output_source, 1, 2 * noutput_verts, "2 noutput_verts")

/* The optional painted material (ids 57, 58; blob version 3): each tet's multiplier of
 * META's mu and lambda. TET_STIFFNESS (count: COND_META's ntets) is present exactly when
 * CUB_STIFFNESS and the condensation tet mesh both are. */
#define SINEW_BLOB_STIFFNESS_SECTIONS(X)                                                           \
    X(57, CUB_STIFFNESS,      8, double,  cub_stiffness, 1, ncub,        "ncub")                   \
    X(58, TET_STIFFNESS,      8, double,  tet_stiffness, 1, ntets,       "ntets")

/* The optional pose-space level of detail (ids 59..64): counts named by
 * SINEW_BLOB_LOD_COUNTS from LOD_META, with META's ntrain; rows as in SINEW_BLOB_SECTIONS. */
#define SINEW_BLOB_LOD_COUNTS(X) X(nlod_verts) X(lod_rank)
#define SINEW_BLOB_LOD_SECTIONS(X)                                                                 \
    X(59, LOD_META,          32, sinew_blob_lod_meta, lod_meta, 1, 1, "1")                         \
    SINEW_BLOB_LOD_ARRAY_SECTIONS(X)
#define SINEW_BLOB_LOD_ARRAY_SECTIONS(X)                                                           \
    X(60, LOD_REST,           8, double,  lod_rest,   1, 3 * nlod_verts,  "3 nlod_verts")          \
    X(61, LOD_BONE,           4, int32_t, lod_bone,   1, 4 * nlod_verts,  "4 nlod_verts")          \
    X(62, LOD_WEIGHT,         8, double,  lod_weight, 1, 4 * nlod_verts,  "4 nlod_verts")          \
    X(63, LOD_BASIS,          4, float,   lod_basis,  1, lod_rank * 3 * nlod_verts,                \
      "lod_rank 3 nlod_verts")                                                                     \
    X(64, LOD_MAP,            8, double,  lod_map,    1, lod_rank * (9 * nbones + 1),          \
      "lod_rank (9 nbones + 1)")

/* The reduced matrices' block placement (id 65; version 4, where it is required): its count
 * from META. */
#define SINEW_BLOB_BLOCKS_SECTIONS(X)                                                              \
    X(65, REDUCED_BLOCKS,     4, int32_t, reduced_blocks, 1, 2 * ndomains * ndomains,             \
      "2 ndomains^2")

/* Not variadic: C++98 hosts compile this header without warnings. */
#define SINEW_BLOB_ENUM_ROW_(id, NAME, elem_size, type, field, by_meta, count, formula)           \
    SINEW_SECTION_##NAME = id,
#define SINEW_BLOB_PLUS_ONE_(id, NAME, elem_size, type, field, by_meta, count, formula) +1
/** Section ids; SINEW_SECTION_COUNT_V1 (26) is the number of sections every version-1 blob
 * has; SINEW_SECTION_RENDER_FIRST .. _RENDER_LAST are the optional render mesh's,
 * SINEW_SECTION_COND_FIRST .. _COND_LAST the optional condensation tet mesh's,
 * SINEW_SECTION_PAIR_FIRST .. _PAIR_LAST the optional per-pair self-contact's,
 * SINEW_SECTION_TRAIN_FORCE the optional pose-space equilibrium force,
 * SINEW_SECTION_ASSET_FIRST .. _ASSET_LAST the optional asset description,
 * SINEW_SECTION_CUB_STIFFNESS and _TET_STIFFNESS the optional painted material,
 * SINEW_SECTION_LOD_FIRST .. _LOD_LAST the optional pose-space level of detail,
 * SINEW_SECTION_REDUCED_BLOCKS the reduced matrices' block placement (version 4);
 * SINEW_SECTION_ID_MAX is the largest known id. */
enum sinew_blob_section_id {
    SINEW_BLOB_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_COUNT_V1 = 0 SINEW_BLOB_SECTIONS(SINEW_BLOB_PLUS_ONE_),
    SINEW_BLOB_RENDER_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_RENDER_FIRST = SINEW_SECTION_RENDER_META,
    SINEW_SECTION_RENDER_LAST =
        SINEW_SECTION_COUNT_V1 SINEW_BLOB_RENDER_SECTIONS(SINEW_BLOB_PLUS_ONE_),
    SINEW_BLOB_COND_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_COND_FIRST = SINEW_SECTION_COND_META,
    SINEW_SECTION_COND_LAST =
        SINEW_SECTION_RENDER_LAST SINEW_BLOB_COND_SECTIONS(SINEW_BLOB_PLUS_ONE_),
    SINEW_BLOB_PAIR_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_PAIR_FIRST = SINEW_SECTION_PAIR_META,
    SINEW_SECTION_PAIR_LAST =
        SINEW_SECTION_COND_LAST SINEW_BLOB_PAIR_SECTIONS(SINEW_BLOB_PLUS_ONE_),
    SINEW_BLOB_FORCE_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_BLOB_ASSET_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_ASSET_FIRST = SINEW_SECTION_ASSET_META,
    SINEW_SECTION_ASSET_LAST = SINEW_SECTION_OUTPUT_SOURCE,
    SINEW_BLOB_STIFFNESS_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_BLOB_LOD_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_LOD_FIRST = SINEW_SECTION_LOD_META,
    SINEW_SECTION_LOD_LAST = SINEW_SECTION_LOD_MAP,
    SINEW_BLOB_BLOCKS_SECTIONS(SINEW_BLOB_ENUM_ROW_)
    SINEW_SECTION_ID_MAX = SINEW_SECTION_REDUCED_BLOCKS
};
#undef SINEW_BLOB_ENUM_ROW_
#undef SINEW_BLOB_PLUS_ONE_
/* clang-format on */

/** Section META: counts and material (80 bytes). */
typedef struct sinew_blob_meta {
    int32_t nverts, nbones, ndomains, rank_total;
    int32_t ndomain_verts, ncub, nsurf_verts, nsurf_tris;
    double mu, lambda, rayleigh_alpha, rayleigh_beta, contact_k;
    int32_t ntrain;    /**< training poses kept for the pose-space warm start (>= 1) */
    int32_t ncontacts; /**< self-contact pairs over all training poses (>= 0) */
} sinew_blob_meta;

/** Section RENDER_META: the render mesh's counts (32 bytes), each >= 1. */
typedef struct sinew_blob_render_meta {
    int32_t nrender_verts;  /**< render vertices */
    int32_t nrender_tris;   /**< render triangles */
    int32_t nembed_tets;    /**< simulation tets holding a render vertex */
    int32_t nrender_nodes;  /**< simulation vertices at those tets' corners */
    int32_t nrender_copies; /**< domain copies of those vertices */
    int32_t reserved[3];    /**< zero */
} sinew_blob_render_meta;

/** Section COND_META: the condensation tet mesh's counts (32 bytes). */
typedef struct sinew_blob_cond_meta {
    int32_t ntets;       /**< simulation tets (>= 1) */
    int32_t nvert_tets;  /**< (vertex, incident tet) pairs: 4 ntets */
    int32_t reserved[6]; /**< zero */
} sinew_blob_cond_meta;

/** Section PAIR_META: the per-pair self-contact's counts (32 bytes). */
typedef struct sinew_blob_pair_meta {
    int32_t npair_groups; /**< domain pairs with contacts (1 .. ndomains^2) */
    int32_t reserved[7];  /**< zero */
} sinew_blob_pair_meta;

/** Section ASSET_META: what the blob was baked from and the asset sections' counts (64
 * bytes). A hash is FNV-1a 64 (0: not known). */
typedef struct sinew_blob_asset_meta {
    int32_t nname_bytes;    /**< bytes of BONE_NAMES, every name's zero included */
    int32_t nsource_meshes; /**< meshes of the source file (0: no file, or none kept) */
    int32_t noutput_verts;  /**< output surface vertices (OUTPUT_SOURCE holds 2 each) */
    uint32_t sinew_version; /**< SINEW_VERSION of the bake that wrote the blob */
    uint64_t source_hash;   /**< of the source asset file's bytes */
    uint64_t options_hash;  /**< of the bake's options that shape the blob */
    int32_t reserved[8];    /**< zero */
} sinew_blob_asset_meta;

/** Section LOD_META: the pose-space level of detail's counts (32 bytes). */
typedef struct sinew_blob_lod_meta {
    int32_t nlod_verts;  /**< output surface vertices (the render mesh's or the boundary's) */
    int32_t lod_rank;    /**< displacement modes, 1 .. SINEW_BLOB_LOD_MAX_RANK */
    int32_t reserved[6]; /**< zero */
} sinew_blob_lod_meta;

/** The most displacement modes the pose-space level holds. */
#define SINEW_BLOB_LOD_MAX_RANK 64

/** Section DOMAINS: one record per domain (48 bytes). inertia_count (0 ..= rank) is how
 * many of the domain's last basis columns are inertia modes (a bake with them): a
 * quasistatic step holds those coordinates at the pose-space prediction unless contact
 * nobody trained (the world, detected self-contact) touches the domain; a dynamic step
 * leaves them free. It was a reserved field that had to be 0 (a runtime that predates it
 * refuses a blob with inertia modes rather than step them free), so the format version
 * does not change. */
typedef struct sinew_blob_domain_record {
    int32_t bone, vert_begin, vert_count, rank;
    int32_t q_offset, cub_begin, cub_count, inertia_count;
    int64_t basis_offset, inertia_offset;
} sinew_blob_domain_record;

#endif
