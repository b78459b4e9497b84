/* The baked character as the runtime reads it: typed pointers into the blob (zero
 * copy) plus counts. The bake fills one from its own arrays and hands it to the blob
 * writer; the loader fills one from validated bytes. Every index named below has been
 * range-checked by the loader (blob_load.c) before any runtime code sees it.
 *
 * Model (thesis §4.4.1, DESIGN.md §4): simulation vertex v has rest position
 * rest[v]; its world position in domain d is
 *     x = R_v (rest[v] + U_d[v] q_d) + t_v,
 * with (R_v, t_v) the dual-quaternion skinning transform of v (its 4 influences) and
 * U_d[v] the 3 x r_d rows of domain d's skinning-correction basis. Vertices shared by
 * two domains have one copy in each, tied by springs whose reduced Hessian is the
 * constant matrix `spring_hessian` (eqs. 4.17-4.20). */
#ifndef SW_BLOB_VIEW_H
#define SW_BLOB_VIEW_H

#include <stdint.h>

#include "sinew/sinew_blob_format.h"
#include "tet_rest.h"

#define SW_BLOB_INFLUENCES 4 /* skin influences per vertex */

/* The fields of META (sinew_blob_meta), which the view copies under the same names. */
#define SW_BLOB_META_FIELDS(X)                                                                     \
    SINEW_BLOB_META_COUNTS(X) X(mu) X(lambda) X(rayleigh_alpha) X(rayleigh_beta) X(contact_k)

/* Declares a `const uint64_t` local for every name of SINEW_BLOB_COUNTS, holding that count
 * of the view `view`, so that the sections' count expressions (SINEW_BLOB_SECTIONS) can be
 * evaluated in the scope that follows. */
#define SW_BLOB_COUNT_LOCALS(view)                                                                 \
    const sw_blob_view *const sw_blob_counts_of_ = (view);                                         \
    SINEW_BLOB_COUNTS(SW_BLOB_COUNT_LOCAL_)
#define SW_BLOB_COUNT_LOCAL_(name)                                                                 \
    const uint64_t name = (uint64_t)sw_blob_counts_of_->name;                                      \
    (void)name;

/* The same for the counts of an optional group of sections (COUNTS: e.g.
 * SINEW_BLOB_RENDER_COUNTS), which may share a scope with SW_BLOB_COUNT_LOCALS. */
#define SW_BLOB_GROUP_COUNT_LOCALS(view, COUNTS)                                                   \
    const sw_blob_view *const sw_blob_group_counts_of_ = (view);                                   \
    COUNTS(SW_BLOB_GROUP_COUNT_LOCAL_)
#define SW_BLOB_GROUP_COUNT_LOCAL_(name)                                                           \
    const uint64_t name = (uint64_t)sw_blob_group_counts_of_->name;                                \
    (void)name;

/* One domain (the on-disk record itself, used in place):
 *   bone            the bone this domain rides with (inertial frame)
 *   vert_begin/count  its vertex copies are domain_verts[vert_begin .. +vert_count)
 *   rank            r_d;  q_offset: offset of q_d in the stacked reduced vector q
 *   cub_begin/count its cubature tets
 *   basis_offset    into basis: vert_count * 3 * rank doubles, row-major, local
 *                   vertex k owns rows 3k..3k+2
 *   inertia_offset  into inertia_u: 9 * rank * rank doubles */
typedef sinew_blob_domain_record sw_blob_domain;

typedef struct sw_blob_view {
    /* META */
    int32_t nverts; /* simulation vertices */
    int32_t nbones;
    int32_t ndomains;
    int32_t rank_total;    /* sum of ranks = length of q */
    int32_t ndomain_verts; /* sum of vert_count (vertex copies) */
    int32_t ncub;          /* cubature tets over all domains */
    int32_t nsurf_verts;   /* output (render) surface vertices */
    int32_t nsurf_tris;
    double mu, lambda; /* Lamé parameters of the co-rotational material */
    double rayleigh_alpha, rayleigh_beta;
    double contact_k; /* run-time penalty stiffness (reserved for self-contact) */

    /* per simulation vertex */
    const double *rest;        /* 3 * nverts */
    const int32_t *skin_bone;  /* SW_BLOB_INFLUENCES * nverts, bone ids; unused slots 0 */
    const double *skin_weight; /* SW_BLOB_INFLUENCES * nverts, >= 0, sum 1 */

    /* skeleton (for tools and inertial frames) */
    const int32_t *bone_parent; /* nbones, -1 for roots */
    const double *bone_joints;  /* 6 * nbones: head xyz, tail xyz at rest */

    /* domains */
    const sw_blob_domain *domains; /* ndomains */
    const int32_t *domain_verts;   /* ndomain_verts simulation vertex ids */
    const double *basis;           /* sum over domains of vert_count*3*rank */
    int64_t nbasis;                /* doubles in basis */

    /* cubature, grouped by domain (domain d owns [cub_begin, cub_begin+cub_count)) */
    const int32_t *cub_tets;  /* 4 * ncub: domain-LOCAL vertex indices (< vert_count) */
    const double *cub_weight; /* ncub, > 0 */
    const double *cub_dminv;  /* 9 * ncub: rest Dm^-1 */
    const double *cub_vol;    /* ncub: rest volume */

    /* constant reduced matrices, rank_total x rank_total, by domain blocks: read them with
     * sw_blob_block. With reduced_blocks (blob version 4) each array holds its stored
     * blocks back to back, reduced_blocks[m nd^2 + a nd + b] the offset of block (a, b)
     * (-1: zero), m SW_BLOB_MASS or SW_BLOB_SPRINGS; without (NULL), each is dense and
     * row-major. nspring_hessian and nmass count their doubles. */
    const double *spring_hessian; /* interface springs (eq. 4.20), symmetric PSD */
    const double *mass;           /* reduced lumped mass U^T M U, block diagonal */
    const int32_t *reduced_blocks;
    int64_t nspring_hessian, nmass;
    /* Inertial projections per domain (Kim & James 2011) for the domain's bone frame,
     * m_v the lumped masses, U_v the domain's 3 x r rows of vertex v:
     *   inertia_s: rank_total x 3, row i of domain d: sum_v m_v U_v[:, i]^T
     *   inertia_x: rank_total x 9, entry (i, 3a+b): sum_v m_v U_v[a, i] rest_v[b]
     *   inertia_u: per domain 9 blocks r x r, block 3a+b entry (i, j):
     *              sum_v m_v U_v[a, i] U_v[b, j]  (at domains[d].inertia_offset) */
    const double *inertia_s;
    const double *inertia_x;
    const double *inertia_u;
    int64_t ninertia_u;

    /* output surface: vertex i is the mean of its copies (domain, local vertex) */
    const int32_t *surf_tris;     /* 3 * nsurf_tris, indices < nsurf_verts */
    const int32_t *surf_copy_ptr; /* nsurf_verts + 1, non-decreasing, starts at 0 */
    const int32_t *surf_copies;   /* 2 * surf_copy_ptr[nsurf_verts]: (domain, local vertex) */
    int32_t nsurf_copies;

    /* pose-space warm start: training pose t has feature train_pose[4 nbones t ..]
     * (each bone's rotation relative to its parent as a unit quaternion w, x, y, z with
     * w >= 0) and reduced solution train_q[R t ..]. Stored in the order the bake solved
     * them, each from the one before (pose t - 1 is t's predecessor on its path where t
     * has a twin: a pose stored twice is one pose on two branches of the reference's
     * path, and the runtime tells them apart by how each was arrived at) */
    int32_t ntrain;
    const double *train_q;
    const double *train_pose;

    /* pose-space self-contact (thesis §3.2.3): the reference simulator's contact set at
     * training pose t is contacts [contact_ptr[t], contact_ptr[t+1]); contact c: vertex p and
     * triangle (t0, t1, t2) as (domain, local vertex) pairs in contact_verts[8c..],
     * and in contact_data[7c..] the triangle barycentrics b0..b2, the contact normal in
     * p's un-skinned frame (R_p^T n) and the area weight ka. The penalty stiffness is
     * contact_k, the anisotropy SW_CONTACT_ALPHA (contact/penalty.h, eq. 3.5). */
    int32_t ncontacts;
    const int32_t *contact_ptr;
    const int32_t *contact_verts;
    const double *contact_data;

    /* the optional render mesh embedded in the tets (nrender_verts 0: none, and
     * every field below is 0 / NULL). Render vertex i sits at
     *     sum_k render_bary[4i+k] node(render_tets[4 render_tet[i] + k]),
     * a node the mean of its copies render_node_copies[render_node_ptr[n] ..] (domain,
     * local vertex), like a surface vertex; render_weld[i] is the vertex whose position and
     * normal i takes (itself for a representative). When present it is the output surface
     * (sw_blob_output_*); the tet boundary (surf_*) still carries the world's contact. */
    int32_t nrender_verts, nrender_tris, nembed_tets, nrender_nodes, nrender_copies;
    const int32_t *render_tris;        /* 3 * nrender_tris, indices < nrender_verts */
    const int32_t *render_tet;         /* nrender_verts, < nembed_tets */
    const double *render_bary;         /* 4 * nrender_verts, each vertex's sum 1 */
    const int32_t *render_weld;        /* nrender_verts, idempotent */
    const int32_t *render_tets;        /* 4 * nembed_tets render nodes */
    const int32_t *render_node_ptr;    /* nrender_nodes + 1, increasing, starts at 0 */
    const int32_t *render_node_copies; /* 2 * nrender_copies: (domain, local vertex) */

    /* the whole tet mesh for condensation's full-space patches (ntets 0: none,
     * every field below 0 / NULL). Tet t lies in domain tet_domain[t]: its corner k is
     * domain_verts[domains[tet_domain[t]].vert_begin + tet_local[4t+k]] == tets[4t+k]. */
    int32_t ntets, nvert_tets;
    const int32_t *tets;       /* 4 ntets: global simulation vertex ids */
    const int32_t *tet_domain; /* ntets: the domain whose copies are the tet's corners */
    const int32_t *tet_local;  /* 4 ntets: the corners' domain-local indices (see above) */
    /* 9 ntets: rest Dm^-1, row-major (as cub_dminv); NULL when the blob leaves it out (the
     * bake does): read it with sw_blob_tet_dminv */
    const double *tet_dminv;
    const double *tet_vol; /* ntets: rest volume > 0 (as cub_vol) */
    /* nverts + 1: vertex v's incident tets are vert_tets[ptr[v] .. ptr[v+1]) */
    const int32_t *vert_tet_ptr;
    const int32_t *vert_tets; /* nvert_tets (= 4 ntets): tet ids, ascending per vertex */
    /* nverts: lumped mass, the same masses the bake's reduced mass/inertia used (> 0; 0
     * only for a vertex in no tet, which no patch reaches) */
    const double *vert_mass;
    const int32_t *cub_tet_id; /* ncub: the global tet id of each cubature tet */

    /* the optional per-pair self-contact (thesis §3.2.3; npair_groups 0: none, every field
     * below NULL). Group g pairs domain pair_domains[2g] (the contacts' vertex p) with
     * pair_domains[2g+1] (their triangle); its feature is pair_map[72 g ..] (6 x 12) times
     * the relative transform [vec(R); t] of the second domain's bone in the first's frame,
     * pair_feature[6 (g ntrain + t) ..] at training pose t, whose contacts of the group are
     * [pair_ptr[t npair_groups + g], pair_ptr[t npair_groups + g + 1]), each with its
     * cubature weight pair_weight[c] (>= 0) */
    int32_t npair_groups;
    const int32_t *pair_domains;
    const double *pair_map;
    const double *pair_feature;
    const int32_t *pair_ptr;
    const double *pair_weight;

    /* the optional pose-space equilibrium force (NULL: none): per training pose t, the
     * reduced force train_force[R t ..] that makes train_q[R t ..] the quasistatic step's
     * equilibrium at pose t (pose_space.h, sw_pose_space_force) */
    const double *train_force;

    /* the optional asset description (bone_names NULL: none, every field below 0 / NULL):
     * nbones zero-terminated names back to back (nname_bytes in all), each bone's bind-pose
     * global transform (12 doubles), the source file's meshes' vertex counts and each output
     * vertex's (source mesh, vertex in it) or (-1, -1); what the blob was baked from */
    int32_t nname_bytes, nsource_meshes, noutput_verts;
    uint32_t sinew_version;
    uint64_t source_hash, options_hash;
    const char *bone_names;
    const double *bone_bind;
    const int32_t *source_mesh_verts;
    const int32_t *output_source;

    /* the optional painted material (cub_stiffness NULL: uniform, tet_stiffness NULL too):
     * each cubature tet's and each condensation tet's multiplier of mu and lambda */
    const double *cub_stiffness; /* ncub */
    const double *tet_stiffness; /* ntets, or NULL when ntets is 0 */

    /* the optional pose-space level of detail (lod_rank 0: none; SINEW_LOD_POSE_SPACE):
     * output vertex s (of nlod_verts, the output surface's) skinned on its own from rest
     * position lod_rest[3 s ..] by bones lod_bone[4 s ..] with weights lod_weight[4 s ..],
     * displaced in its rest frame by d_s[i] = sum_j lod_basis[(3 s + i) lod_rank + j] c_j,
     * c = W f of the pose's joint rotations f (sw_pose_rotation_feature), W = lod_map
     * (lod_rank rows of 9 nbones + 1) */
    int32_t nlod_verts, lod_rank;
    const double *lod_rest;
    const int32_t *lod_bone;
    const double *lod_weight;
    const float *lod_basis;
    const double *lod_map;
} sw_blob_view;

/* The painted multipliers a blob may hold (the bake refuses the same range): one further
 * from 1 is no painting but a broken file, whose Newton matrices would mix stiffnesses
 * 10^12 apart. */
#define SW_STIFFNESS_MIN 1e-6
#define SW_STIFFNESS_MAX 1e6

/* Tet t's multiplier of the material (1 where nothing is painted). */
static inline double sw_blob_stiffness(const double *stiffness, int64_t t) {
    return stiffness ? stiffness[t] : 1.0;
}

/* The constant reduced matrices (sw_blob_view.mass and .spring_hessian), as sw_blob_block
 * names them. */
enum { SW_BLOB_MASS = 0, SW_BLOB_SPRINGS = 1 };

/* Block (a, b) of reduced matrix m (SW_BLOB_MASS or SW_BLOB_SPRINGS): its entry (0, 0),
 * with *ld the step from one of its rows to the next; NULL for a block the blob does not
 * store (all zeros). A dense matrix (a blob before version 4) stores every block. */
static inline const double *sw_blob_block(const sw_blob_view *v, int m, int32_t a, int32_t b,
                                          int64_t *ld) {
    const double *A = m == SW_BLOB_MASS ? v->mass : v->spring_hessian;
    if (!v->reduced_blocks) {
        *ld = v->rank_total;
        return A + (int64_t)v->domains[a].q_offset * v->rank_total + v->domains[b].q_offset;
    }
    int32_t off = v->reduced_blocks[((int64_t)m * v->ndomains + a) * v->ndomains + b];
    *ld = v->domains[b].rank;
    return off < 0 ? (const double *)0 : A + off;
}

/* Entry (i, j) of reduced matrix m, i and j in [0, rank_total): for tools and tests (it
 * searches the domains of i and j). */
double sw_blob_reduced_entry(const sw_blob_view *v, int m, int32_t i, int32_t j);

/* Whether block (a, b) of reduced matrix m holds a nonzero entry. */
int sw_blob_block_nonzero(const sw_blob_view *v, int m, int32_t a, int32_t b);

/* Tet t's rest Dm^-1 (of the condensation mesh): the blob's, or when it stores none, its
 * rest corners' into buf (the same function as the bake's: the same bits; the loader
 * proved every tet's invertible). */
static inline const double *sw_blob_tet_dminv(const sw_blob_view *v, int32_t t, double buf[9]) {
    if (v->tet_dminv) return v->tet_dminv + 9 * (int64_t)t;
    double X[12], vol;
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 3; ++i)
            X[3 * k + i] = v->rest[3 * (int64_t)v->tets[4 * (int64_t)t + k] + i];
    sw_tet_rest(X, buf, &vol);
    return buf;
}

/* The simulation vertex of surface copy i (a (domain, local vertex) pair). */
static inline int32_t sw_blob_surf_copy_vertex(const sw_blob_view *v, int32_t i) {
    const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
    return v->domain_verts[D->vert_begin + v->surf_copies[2 * i + 1]];
}

/* The output surface a host reads (sinew_instance_read_surface): the render mesh when the
 * blob has one, else the tet mesh's boundary. */

static inline int32_t sw_blob_output_verts(const sw_blob_view *v) {
    return v->nrender_verts > 0 ? v->nrender_verts : v->nsurf_verts;
}
static inline int32_t sw_blob_output_ntris(const sw_blob_view *v) {
    return v->nrender_verts > 0 ? v->nrender_tris : v->nsurf_tris;
}
static inline const int32_t *sw_blob_output_tris(const sw_blob_view *v) {
    return v->nrender_verts > 0 ? v->render_tris : v->surf_tris;
}

#endif
