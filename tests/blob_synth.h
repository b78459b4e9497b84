/* The blob tests' synthetic character: a small, complete, consistent view (4 bones, 3
 * domains, 2 training poses with 2 contact pairs; optionally a render mesh and the
 * condensation tet mesh) written by the real writer, and the helpers that forge its bytes
 * (table entries, sections, checksum fix-up) and walk an accepted view along every index
 * chain a runtime follows. Shared by the blob tests; everything is static inline (a test
 * uses what it needs). */
#ifndef SW_BLOB_SYNTH_H
#define SW_BLOB_SYNTH_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "blob_write.h"
#include "sinew/sinew.h"
#include "sw_test.h"

/* ---- a small, complete, consistent synthetic character -------------------------- */

enum {
    NB = 4,       /* bones */
    NV = 12,      /* simulation vertices */
    ND = 3,       /* domains */
    NDV = 17,     /* vertex copies */
    RT = 9,       /* rank_total = 2 + 3 + 4 */
    NCUB = 8,     /* cubature tets: 3 + 2 + 3 */
    NSV = 8,      /* surface vertices */
    NST = 6,      /* surface triangles */
    NBASIS = 150, /* 6*3*2 + 6*3*3 + 5*3*4 */
    NIU = 261,    /* 9 * (4 + 9 + 16) */
    MAXCOP = 16,
    NTR = 2 /* training poses */
};

typedef struct fixture {
    double rest[3 * NV];
    int32_t skin_bone[4 * NV];
    double skin_weight[4 * NV];
    int32_t bone_parent[NB];
    double bone_joints[6 * NB];
    sw_blob_domain domains[ND];
    int32_t domain_verts[NDV];
    double basis[NBASIS];
    int32_t cub_tets[4 * NCUB];
    double cub_weight[NCUB], cub_dminv[9 * NCUB], cub_vol[NCUB];
    double spring_hessian[RT * RT], mass[RT * RT], inertia_s[3 * RT], inertia_x[9 * RT];
    double inertia_u[NIU];
    int32_t surf_tris[3 * NST], surf_copy_ptr[NSV + 1], surf_copies[2 * MAXCOP];
    double train_q[NTR * RT], train_pose[NTR * 4 * NB];
    int32_t contact_ptr[NTR + 1], contact_verts[8 * 2];
    double contact_data[7 * 2];
    sw_blob_view v;
} fixture;

static uint64_t rng_state;
static inline uint32_t rng_next(void) {
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(rng_state >> 33);
}
/* Uniform in [0, 1) and in [-1, 1). */
static inline double rng_unit(void) {
    return rng_next() / 2147483648.0;
}
static inline double rng_sym(void) {
    return 2.0 * rng_unit() - 1.0;
}

/* k distinct values of [0, n) into out. */
static inline void rng_distinct(int32_t *out, int k, int32_t n) {
    int32_t pool[64];
    for (int32_t i = 0; i < n; ++i)
        pool[i] = i;
    for (int i = 0; i < k; ++i) {
        int32_t j = i + (int32_t)(rng_next() % (uint32_t)(n - i));
        int32_t t = pool[i];
        pool[i] = pool[j];
        pool[j] = t;
        out[i] = pool[i];
    }
}

static inline void fixture_init(fixture *f, uint64_t seed) {
    static const int32_t dverts[NDV] = {0, 1, 2, 3, 4, 5, 4, 5, 6, 7, 8, 9, 8, 9, 10, 11, 0};
    static const int32_t vc[ND] = {6, 6, 5}, rank[ND] = {2, 3, 4}, ncub[ND] = {3, 2, 3};
    memset(f, 0, sizeof *f);
    rng_state = seed;
    for (int i = 0; i < 3 * NV; ++i)
        f->rest[i] = rng_sym();
    for (int v = 0; v < NV; ++v) {
        double w[4], sum = 0.0;
        int used = 1 + (int)(rng_next() % 4u); /* 1..4 influences, unused slots bone 0 */
        for (int k = 0; k < 4; ++k) {
            w[k] = k < used ? 0.05 + rng_unit() : 0.0;
            sum += w[k];
            f->skin_bone[4 * v + k] = k < used ? (int32_t)(rng_next() % NB) : 0;
        }
        for (int k = 0; k < 4; ++k)
            f->skin_weight[4 * v + k] = w[k] / sum;
    }
    const int32_t parents[NB] = {-1, 0, 1, 1};
    memcpy(f->bone_parent, parents, sizeof parents);
    for (int i = 0; i < 6 * NB; ++i)
        f->bone_joints[i] = rng_sym();
    memcpy(f->domain_verts, dverts, sizeof dverts);
    int32_t vb = 0, q = 0, cb = 0;
    int64_t bo = 0, io = 0;
    for (int d = 0; d < ND; ++d) {
        sw_blob_domain *dom = &f->domains[d];
        dom->bone = d + 1, dom->vert_begin = vb, dom->vert_count = vc[d], dom->rank = rank[d];
        dom->q_offset = q, dom->cub_begin = cb, dom->cub_count = ncub[d];
        dom->basis_offset = bo, dom->inertia_offset = io;
        for (int c = cb; c < cb + ncub[d]; ++c)
            rng_distinct(&f->cub_tets[4 * c], 4, vc[d]);
        vb += vc[d], q += rank[d], cb += ncub[d];
        bo += (int64_t)vc[d] * 3 * rank[d], io += 9 * rank[d] * rank[d];
    }
    for (int i = 0; i < NBASIS; ++i)
        f->basis[i] = rng_sym();
    for (int c = 0; c < NCUB; ++c) {
        f->cub_weight[c] = 0.1 + rng_unit();
        f->cub_vol[c] = 0.01 + rng_unit();
        for (int k = 0; k < 9; ++k)
            f->cub_dminv[9 * c + k] = rng_sym() * 10.0;
    }
    for (int i = 0; i < RT; ++i)
        for (int j = 0; j <= i; ++j) {
            f->spring_hessian[i * RT + j] = f->spring_hessian[j * RT + i] = rng_sym();
            f->mass[i * RT + j] = f->mass[j * RT + i] = i == j ? 1.0 + rng_unit() : 0.0;
        }
    for (int i = 0; i < 3 * RT; ++i)
        f->inertia_s[i] = rng_sym();
    for (int i = 0; i < 9 * RT; ++i)
        f->inertia_x[i] = rng_sym();
    for (int i = 0; i < NIU; ++i)
        f->inertia_u[i] = rng_sym();
    for (int i = 0; i < NTR * RT; ++i)
        f->train_q[i] = rng_sym();
    for (int i = 0; i < NTR * 4 * NB; ++i)
        f->train_pose[i] = rng_sym();
    f->contact_ptr[0] = 0, f->contact_ptr[1] = 2, f->contact_ptr[2] = 2; /* pose 0: 2 pairs */
    for (int c = 0; c < 2; ++c) {
        for (int k = 0; k < 4; ++k) {
            int32_t d = (int32_t)(rng_next() % ND);
            f->contact_verts[8 * c + 2 * k] = d;
            f->contact_verts[8 * c + 2 * k + 1] = (int32_t)(rng_next() % (uint32_t)vc[d]);
        }
        for (int k = 0; k < 6; ++k)
            f->contact_data[7 * c + k] = rng_sym();
        f->contact_data[7 * c + 6] = 0.5 + rng_unit();
    }
    for (int t = 0; t < NST; ++t)
        rng_distinct(&f->surf_tris[3 * t], 3, NSV);
    int32_t nc = 0;
    for (int s = 0; s < NSV; ++s) {
        f->surf_copy_ptr[s] = nc;
        for (int k = 0; k < (s % 3 == 0 ? 2 : 1); ++k, ++nc) {
            int32_t d = (int32_t)(rng_next() % ND);
            f->surf_copies[2 * nc] = d;
            f->surf_copies[2 * nc + 1] = (int32_t)(rng_next() % (uint32_t)vc[d]);
        }
    }
    f->surf_copy_ptr[NSV] = nc;

    sw_blob_view *v = &f->v;
    v->nverts = NV, v->nbones = NB, v->ndomains = ND, v->rank_total = RT;
    v->ndomain_verts = NDV, v->ncub = NCUB, v->nsurf_verts = NSV, v->nsurf_tris = NST;
    v->mu = 1e5, v->lambda = 4e5, v->rayleigh_alpha = 0.1, v->rayleigh_beta = 0.01;
    v->contact_k = 1e3;
    v->nbasis = NBASIS, v->ninertia_u = NIU, v->nsurf_copies = nc;
    v->nspring_hessian = v->nmass = RT * RT; /* dense: a version-2 blob */
    v->ntrain = NTR, v->ncontacts = 2;
    /* The fixture's arrays carry the view's field names. */
#define POINT(id, NAME, elem_size, type, field, ...) v->field = f->field;
    SINEW_BLOB_ARRAY_SECTIONS(POINT)
#undef POINT
}

/* ---- the optional render mesh (sinew_blob_format.h, ids 27..34) ------------------ */

enum {
    NRV = 5, /* render vertices: 4 and a duplicate of vertex 0 */
    NRT = 3, /* render triangles */
    NET = 2, /* embedding tets */
    NRN = 5, /* render nodes: simulation vertices 0..4 */
    NRC = 7  /* their copies: vertices 0 and 4 have two */
};

typedef struct render_fixture {
    int32_t render_tris[3 * NRT], render_tet[NRV];
    double render_bary[4 * NRV];
    int32_t render_weld[NRV], render_tets[4 * NET], render_node_ptr[NRN + 1];
    int32_t render_node_copies[2 * NRC];
} render_fixture;

/* Gives f's view a render mesh held in r: one vertex extrapolated outside its tet, one a
 * welded duplicate; the nodes' copies are the fixture's (vertex 0 in domains 0 and 2,
 * vertex 4 in domains 0 and 1). */
static inline void fixture_add_render(fixture *f, render_fixture *r) {
    static const render_fixture k = {{0, 1, 2, 1, 3, 2, 4, 2, 3},
                                     {0, 0, 1, 1, 0},
                                     {0.25, 0.25, 0.25, 0.25, 0.1, 0.2, 0.3,  0.4,  1.5,  -0.5,
                                      0,    0,    0.2,  0.2,  0.3, 0.3, 0.25, 0.25, 0.25, 0.25},
                                     {0, 1, 2, 3, 0},
                                     {0, 1, 2, 3, 1, 2, 3, 4},
                                     {0, 2, 3, 4, 5, 7},
                                     {0, 0, 2, 4, 0, 1, 0, 2, 0, 3, 0, 4, 1, 0}};
    *r = k;
    sw_blob_view *v = &f->v;
    v->nrender_verts = NRV, v->nrender_tris = NRT, v->nembed_tets = NET;
    v->nrender_nodes = NRN, v->nrender_copies = NRC;
#define POINT(id, NAME, elem_size, type, field, ...) v->field = r->field;
    SINEW_BLOB_RENDER_ARRAY_SECTIONS(POINT)
#undef POINT
}

/* ---- the optional condensation tet mesh (sinew_blob_format.h, ids 35..44) --------- */

enum {
    NCT = NCUB + 2 /* tets: two of their own, then the cubature tets in reverse order */
};

typedef struct cond_fixture {
    int32_t tets[4 * NCT], tet_domain[NCT], tet_local[4 * NCT];
    double tet_dminv[9 * NCT], tet_vol[NCT];
    int32_t vert_tet_ptr[NV + 1], vert_tets[4 * NCT];
    double vert_mass[NV];
    int32_t cub_tet_id[NCUB];
} cond_fixture;

/* Painted material over a fixture with its tet mesh (fixture_add_cond): tet t's multiplier
 * 0.25 + t / 8, each cubature tet its tet's. */
typedef struct paint_fixture {
    double cub_stiffness[NCUB], tet_stiffness[NCT];
} paint_fixture;
static inline void fixture_add_paint(fixture *f, const cond_fixture *c, paint_fixture *p) {
    for (int32_t t = 0; t < NCT; ++t)
        p->tet_stiffness[t] = 0.25 + t / 8.0;
    for (int32_t k = 0; k < NCUB; ++k)
        p->cub_stiffness[k] = p->tet_stiffness[c->cub_tet_id[k]];
    f->v.cub_stiffness = p->cub_stiffness;
    f->v.tet_stiffness = p->tet_stiffness;
}

/* Gives f's view the tet mesh held in c: tet 0 on domain 0's local vertices 0..3, tet 1 on
 * domain 2's 0, 1, 2, 4 (vertices 8, 9, 10, 0), and cubature tet k as tet NCT - 1 - k; the
 * vertices in no tet have mass 0. */
static inline void fixture_add_cond(fixture *f, cond_fixture *c) {
    static const int32_t own_domain[2] = {0, 2}, own_local[2][4] = {{0, 1, 2, 3}, {0, 1, 2, 4}};
    sw_blob_view *v = &f->v;
    memset(c, 0, sizeof *c);
    for (int32_t t = 0; t < NCT; ++t) {
        const int32_t k = NCT - 1 - t; /* its cubature tet (when t >= 2) */
        int32_t d = 0;
        if (t < 2) {
            d = own_domain[t];
            memcpy(&c->tet_local[4 * t], own_local[t], sizeof own_local[t]);
            for (int i = 0; i < 9; ++i)
                c->tet_dminv[9 * t + i] = i % 4 == 0 ? 2.0 + t : 0.25 * (i - 4);
            c->tet_vol[t] = 0.5 / (1 + t);
        } else {
            while (k >= f->domains[d].cub_begin + f->domains[d].cub_count)
                ++d;
            memcpy(&c->tet_local[4 * t], &f->cub_tets[4 * k], 4 * sizeof(int32_t));
            memcpy(&c->tet_dminv[9 * t], &f->cub_dminv[9 * k], 9 * sizeof(double));
            c->tet_vol[t] = f->cub_vol[k];
            c->cub_tet_id[k] = t;
        }
        c->tet_domain[t] = d;
        for (int i = 0; i < 4; ++i) {
            c->tets[4 * t + i] =
                f->domain_verts[f->domains[d].vert_begin + c->tet_local[4 * t + i]];
            c->vert_tet_ptr[c->tets[4 * t + i] + 1]++;
        }
    }
    for (int32_t x = 0; x < NV; ++x) {
        c->vert_mass[x] = c->vert_tet_ptr[x + 1] > 0 ? 1.0 + 0.125 * x : 0.0;
        c->vert_tet_ptr[x + 1] += c->vert_tet_ptr[x];
    }
    int32_t fill[NV];
    memcpy(fill, c->vert_tet_ptr, sizeof fill);
    for (int32_t t = 0; t < NCT; ++t)
        for (int i = 0; i < 4; ++i)
            c->vert_tets[fill[c->tets[4 * t + i]]++] = t;
    v->ntets = NCT, v->nvert_tets = 4 * NCT;
#define POINT(id, NAME, elem_size, type, field, ...) v->field = c->field;
    SINEW_BLOB_COND_ARRAY_SECTIONS(POINT)
#undef POINT
}

enum { NPG_MAX = 2 /* pair groups: one per contact at most */ };

typedef struct pair_fixture {
    int32_t pair_domains[2 * NPG_MAX];
    double pair_map[72 * NPG_MAX], pair_feature[6 * NPG_MAX * NTR];
    int32_t pair_ptr[NPG_MAX * NTR + 1];
    double pair_weight[2];
} pair_fixture;

/* Gives f's view per-pair sections held in p: a group per distinct (domain of p, domain of
 * t0) of the two contacts of pose 0, which are put in group order; made-up maps and
 * features; the first pair weighted 0.75, the second 0 (left out). */
static inline void fixture_add_pairs(fixture *f, pair_fixture *p) {
    sw_blob_view *v = &f->v;
    memset(p, 0, sizeof *p);
    int32_t *cv = f->contact_verts;
    if (cv[0] > cv[8] || (cv[0] == cv[8] && cv[2] > cv[10])) { /* swap the two contacts */
        int32_t ti[8];
        double td[7];
        memcpy(ti, cv, sizeof ti), memcpy(cv, cv + 8, sizeof ti), memcpy(cv + 8, ti, sizeof ti);
        memcpy(td, f->contact_data, sizeof td);
        memcpy(f->contact_data, f->contact_data + 7, sizeof td);
        memcpy(f->contact_data + 7, td, sizeof td);
    }
    const int32_t G = cv[0] == cv[8] && cv[2] == cv[10] ? 1 : 2;
    for (int32_t g = 0; g < G; ++g)
        p->pair_domains[2 * g] = cv[8 * g], p->pair_domains[2 * g + 1] = cv[8 * g + 2];
    for (int32_t i = 0; i < 72 * G; ++i)
        p->pair_map[i] = 0.125 * ((i * 7) % 11) - 0.5;
    for (int32_t i = 0; i < 6 * G * NTR; ++i)
        p->pair_feature[i] = 0.25 * ((i * 5) % 9) - 1.0;
    /* pose 0: both contacts (one group holds both when G is 1), pose 1: none */
    p->pair_ptr[0] = 0;
    p->pair_ptr[1] = G == 1 ? 2 : 1;
    for (int32_t i = 2; i <= G * NTR; ++i)
        p->pair_ptr[i] = 2;
    p->pair_weight[0] = 0.75;
    p->pair_weight[1] = 0;
    v->npair_groups = G;
#define POINT(id, NAME, elem_size, type, field, ...) v->field = p->field;
    SINEW_BLOB_PAIR_ARRAY_SECTIONS(POINT)
#undef POINT
}

/* The asset description: names (one of the file's, "bone N" for the rest), bind poses,
 * two source meshes of 3 and 4 vertices and each output vertex's source (the first
 * output vertex has none). Added after the render mesh when there is one: the output
 * surface's size is read from the view. */
enum { NSRC = 2, NOUT_MAX = 16 };
typedef struct asset_fixture {
    char bone_names[NB * 16];
    double bone_bind[12 * NB];
    int32_t source_mesh_verts[NSRC];
    int32_t output_source[2 * NOUT_MAX];
} asset_fixture;

static inline void fixture_add_asset(fixture *f, asset_fixture *a) {
    sw_blob_view *v = &f->v;
    memset(a, 0, sizeof *a);
    int32_t at = 0;
    for (int32_t b = 0; b < NB; ++b)
        at += 1 + snprintf(a->bone_names + at, 16, b == 0 ? "Hips" : "bone %d", (int)b);
    for (int32_t b = 0; b < NB; ++b) {
        double *m = a->bone_bind + 12 * b;
        m[0] = m[4] = m[8] = 1;
        m[9] = 0.5 * b, m[10] = 1.0 + b, m[11] = -0.25 * b;
    }
    a->source_mesh_verts[0] = 3, a->source_mesh_verts[1] = 4;
    const int32_t nout = sw_blob_output_verts(v);
    for (int32_t i = 0; i < nout && i < NOUT_MAX; ++i) {
        a->output_source[2 * i] = i == 0 ? -1 : i % NSRC;
        a->output_source[2 * i + 1] = i == 0 ? -1 : i % a->source_mesh_verts[i % NSRC];
    }
    v->nname_bytes = at, v->nsource_meshes = NSRC, v->noutput_verts = nout;
    v->sinew_version = SINEW_VERSION, v->source_hash = 0x0123456789abcdefull;
    v->options_hash = 0xfedcba9876543210ull;
#define POINT(id, NAME, elem_size, type, field, ...) v->field = a->field;
    SINEW_BLOB_ASSET_ARRAY_SECTIONS(POINT)
#undef POINT
}

/* A pose-space level of detail (LOD sections) of rank 2 for at most NOUT_MAX output
 * vertices: each vertex on bone i % NB alone at its rest position, two orthonormal modes
 * (x of every vertex, then y, scaled), a map of small entries. */
enum { LOD_RANK = 2 };
/* ---- the reduced matrices by domain blocks (sinew_blob_format.h, id 65; version 4) ----- */

typedef struct blocks_fixture {
    double mass[RT * RT], spring_hessian[RT * RT];
    int32_t blocks[2 * ND * ND];
} blocks_fixture;

/* The fixture's mass and springs stored by blocks, as the bake stores them: the springs'
 * block between the first and the last domain zeroed first (both ways), so that an
 * off-diagonal block is left out. */
static inline void fixture_add_blocks(fixture *f, blocks_fixture *k) {
    sw_blob_view *v = &f->v;
    const sw_blob_domain *first = &v->domains[0], *last = &v->domains[ND - 1];
    for (int32_t i = 0; i < first->rank; ++i)
        for (int32_t j = 0; j < last->rank; ++j)
            f->spring_hessian[(first->q_offset + i) * RT + last->q_offset + j] =
                f->spring_hessian[(last->q_offset + j) * RT + first->q_offset + i] = 0.0;
    v->nmass = sw_blob_pack_blocks(v->domains, ND, RT, f->mass, k->blocks, k->mass);
    v->nspring_hessian = sw_blob_pack_blocks(v->domains, ND, RT, f->spring_hessian,
                                             k->blocks + ND * ND, k->spring_hessian);
    v->mass = k->mass, v->spring_hessian = k->spring_hessian, v->reduced_blocks = k->blocks;
}

typedef struct lod_fixture {
    double rest[3 * NOUT_MAX], weight[4 * NOUT_MAX], map[LOD_RANK * (9 * NB + 1)];
    int32_t bone[4 * NOUT_MAX];
    float basis[LOD_RANK * 3 * NOUT_MAX];
} lod_fixture;

static inline void fixture_add_lod(fixture *f, lod_fixture *l) {
    sw_blob_view *v = &f->v;
    memset(l, 0, sizeof *l);
    const int32_t n = sw_blob_output_verts(v);
    const float e = (float)(1.0 / sqrt((double)(n > 0 ? n : 1)));
    for (int32_t s = 0; s < n && s < NOUT_MAX; ++s) {
        for (int k = 0; k < 3; ++k)
            l->rest[3 * s + k] = 0.1 * (s + k);
        for (int k = 0; k < 4; ++k)
            l->bone[4 * s + k] = (s + k) % NB;
        l->weight[4 * s] = 1;
        l->basis[3 * s] = e;
        l->basis[3 * n + 3 * s + 1] = e;
    }
    for (int32_t i = 0; i < LOD_RANK * (9 * NB + 1); ++i)
        l->map[i] = 0.01 * (double)(i % 5) - 0.02;
    v->nlod_verts = n, v->lod_rank = LOD_RANK;
    v->lod_rest = l->rest, v->lod_bone = l->bone, v->lod_weight = l->weight;
    v->lod_basis = l->basis, v->lod_map = l->map;
}

/* ---- helpers --------------------------------------------------------------------- */

/* First field in which two views differ (counts, scalars bitwise, arrays bitwise, the
 * optional groups' too), or NULL when they are identical. */
static inline const char *view_diff(const sw_blob_view *a, const sw_blob_view *b) {
#define SAME_BITS(f)                                                                               \
    if (memcmp(&a->f, &b->f, sizeof a->f) != 0) return #f;
    SW_BLOB_META_FIELDS(SAME_BITS)
    SAME_BITS(nbasis)
    SAME_BITS(ninertia_u)
    SAME_BITS(nsurf_copies)
    SAME_BITS(nspring_hessian)
    SAME_BITS(nmass)
    SINEW_BLOB_RENDER_COUNTS(SAME_BITS)
    SINEW_BLOB_COND_COUNTS(SAME_BITS)
    SINEW_BLOB_PAIR_COUNTS(SAME_BITS)
    SINEW_BLOB_ASSET_COUNTS(SAME_BITS)
    SAME_BITS(sinew_version)
    SAME_BITS(source_hash)
    SAME_BITS(options_hash)
#undef SAME_BITS
    SW_BLOB_COUNT_LOCALS(a);
#define SAME_ARRAY(id, NAME, elem_size, type, field, by_meta, count, formula)                      \
    if (!a->field != !b->field ||                                                                  \
        (a->field && memcmp(a->field, b->field, (size_t)(count) * sizeof a->field[0]) != 0))       \
        return #field; /* (COND_TET_DMINV may be left out) */
    SINEW_BLOB_ARRAY_SECTIONS(SAME_ARRAY)
    if (a->nrender_verts > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(a, SINEW_BLOB_RENDER_COUNTS);
        SINEW_BLOB_RENDER_ARRAY_SECTIONS(SAME_ARRAY)
    }
    if (a->ntets > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(a, SINEW_BLOB_COND_COUNTS);
        SINEW_BLOB_COND_ARRAY_SECTIONS(SAME_ARRAY)
    }
    if (a->npair_groups > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(a, SINEW_BLOB_PAIR_COUNTS);
        SINEW_BLOB_PAIR_ARRAY_SECTIONS(SAME_ARRAY)
    }
    if (a->bone_names) {
        SW_BLOB_GROUP_COUNT_LOCALS(a, SINEW_BLOB_ASSET_COUNTS);
        SINEW_BLOB_ASSET_ARRAY_SECTIONS(SAME_ARRAY)
    }
    if (!a->cub_stiffness != !b->cub_stiffness || !a->tet_stiffness != !b->tet_stiffness)
        return "painted material";
    if (a->cub_stiffness &&
        memcmp(a->cub_stiffness, b->cub_stiffness, (size_t)a->ncub * sizeof(double)))
        return "cub_stiffness";
    if (a->tet_stiffness &&
        memcmp(a->tet_stiffness, b->tet_stiffness, (size_t)a->ntets * sizeof(double)))
        return "tet_stiffness";
    if (!a->reduced_blocks != !b->reduced_blocks ||
        (a->reduced_blocks &&
         memcmp(a->reduced_blocks, b->reduced_blocks,
                2 * (size_t)a->ndomains * (size_t)a->ndomains * sizeof(int32_t))))
        return "reduced_blocks";
    if (a->lod_rank != b->lod_rank || a->nlod_verts != b->nlod_verts) return "lod counts";
    if (a->lod_rank > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(a, SINEW_BLOB_LOD_COUNTS);
        SINEW_BLOB_LOD_ARRAY_SECTIONS(SAME_ARRAY)
    }
#undef SAME_ARRAY
    return NULL;
}

/* A copy of n bytes in a 64-byte aligned allocation of exactly n bytes (so that ASan
 * catches a read past the end). */
static inline uint8_t *copy_exact(const void *src, size_t n) {
    void *p = NULL;
    if (posix_memalign(&p, 64, n ? n : 1) != 0) return NULL;
    if (n) memcpy(p, src, n);
    return p;
}

static inline sinew_blob_header *hdr(uint8_t *blob) {
    return (sinew_blob_header *)(void *)blob;
}

static inline sinew_blob_section *entry(uint8_t *blob, uint32_t id) {
    sinew_blob_section *t = (sinew_blob_section *)(void *)(blob + 64);
    for (uint32_t i = 0; i < hdr(blob)->section_count; ++i)
        if (t[i].id == id) return &t[i];
    return NULL;
}

static inline void *section(uint8_t *blob, uint32_t id) {
    return blob + entry(blob, id)->offset;
}

static inline void fix_checksum(uint8_t *blob, size_t size) {
    hdr(blob)->checksum = sw_blob_checksum(blob + 64, size - 64);
}

/* Cubature tet 3's second local index out of its domain (a forged case of
 * test_blob_hostile.c, and the damaged blob test_blob.c's loader must log). */
static inline void f_cub_index(uint8_t *b) {
    ((int32_t *)section(b, SINEW_SECTION_CUB_TETS))[4 * 3 + 1] = 6;
}

/* The whole range [p, p + bytes) lies inside [base, base + size). */
static inline int inside(const void *p, int64_t bytes, const uint8_t *base, size_t size) {
    const uint8_t *q = p;
    return q >= base && bytes >= 0 && (uint64_t)(q - base) + (uint64_t)bytes <= size;
}

/* The training poses and their contacts, as the pose-space code follows them: each
 * pose's reduced solution and feature, the pairs of its range [contact_ptr[t],
 * contact_ptr[t+1]), each pair's four (domain, local vertex) references on to a vertex
 * copy and a simulation vertex, its barycentrics, normal and area weight. 0 when an index
 * would leave its array or an area weight is not positive (the loader must have
 * rejected that blob): bounds are checked here, not left to ASan, because a wrong index
 * into one buffer mostly lands in another section. */
static inline int walk_training(const sw_blob_view *v, double *acc) {
    const int64_t R = v->rank_total, F = 4 * (int64_t)v->nbones;
    double s = 0.0;
    if (v->contact_ptr[0] != 0 || v->contact_ptr[v->ntrain] != v->ncontacts) return 0;
    for (int32_t t = 0; t < v->ntrain; ++t) {
        for (int64_t i = 0; i < R; ++i)
            s += v->train_q[R * t + i];
        for (int64_t i = 0; i < F; ++i)
            s += v->train_pose[F * t + i];
        const int32_t c0 = v->contact_ptr[t], c1 = v->contact_ptr[t + 1];
        if (c0 < 0 || c1 < c0 || c1 > v->ncontacts) return 0;
        for (int32_t c = c0; c < c1; ++c) {
            for (int k = 0; k < 4; ++k) {
                const int32_t d = v->contact_verts[8 * (int64_t)c + 2 * k];
                const int32_t l = v->contact_verts[8 * (int64_t)c + 2 * k + 1];
                if (d < 0 || d >= v->ndomains) return 0;
                const sw_blob_domain *dom = &v->domains[d];
                if (l < 0 || l >= dom->vert_count) return 0;
                s += v->rest[3 * (int64_t)v->domain_verts[dom->vert_begin + l]];
            }
            for (int k = 0; k < 7; ++k)
                s += v->contact_data[7 * (int64_t)c + k];
            if (!(v->contact_data[7 * (int64_t)c + 6] > 0.0)) return 0;
        }
    }
    *acc += s;
    return 1;
}

/* Everything a runtime would dereference, from an accepted view: every array inside the
 * buffer, and every index chain followed. Under ASan an out-of-range index aborts. */
static inline int walk_view(const sw_blob_view *v, const uint8_t *base, size_t size, double *acc) {
    const int64_t R = v->rank_total;
    SW_BLOB_COUNT_LOCALS(v);
    const struct {
        const void *p;
        int64_t bytes;
    } arrays[] = {
#define EXTENT(id, NAME, elem_size, type, field, by_meta, count, formula)                          \
    {v->field, (int64_t)(elem_size * (count))},
        SINEW_BLOB_ARRAY_SECTIONS(EXTENT)
#undef EXTENT
    };
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i)
        if (!inside(arrays[i].p, arrays[i].bytes, base, size)) return 0;
    if (v->reduced_blocks &&
        !inside(v->reduced_blocks, 8 * (int64_t)v->ndomains * v->ndomains, base, size))
        return 0;
    double s = 0.0;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        s += v->bone_joints[6 * dom->bone];
        for (int32_t k = 0; k < dom->vert_count; ++k) {
            int32_t x = v->domain_verts[dom->vert_begin + k];
            s += v->rest[3 * x + 2];
            for (int j = 0; j < 4; ++j) {
                int32_t b = v->skin_bone[4 * x + j];
                s += v->skin_weight[4 * x + j] * v->bone_joints[6 * b + 5];
                for (int32_t p = v->bone_parent[b]; p >= 0; p = v->bone_parent[p])
                    s += 1.0;
            }
            for (int32_t a = 0; a < 3; ++a)
                for (int32_t i = 0; i < dom->rank; ++i)
                    s += v->basis[dom->basis_offset + (3 * k + a) * dom->rank + i];
        }
        for (int32_t i = 0; i < dom->rank; ++i) {
            s += sw_blob_reduced_entry(v, SW_BLOB_MASS, dom->q_offset + i, dom->q_offset + i);
            s += sw_blob_reduced_entry(v, SW_BLOB_SPRINGS, dom->q_offset + i, R - 1);
            s += v->inertia_s[3 * (dom->q_offset + i) + 2] +
                 v->inertia_x[9 * (dom->q_offset + i) + 8];
        }
        s += v->inertia_u[dom->inertia_offset + 9 * dom->rank * dom->rank - 1];
        for (int32_t c = dom->cub_begin; c < dom->cub_begin + dom->cub_count; ++c) {
            s += v->cub_weight[c] * v->cub_vol[c] + v->cub_dminv[9 * c + 8];
            for (int k = 0; k < 4; ++k)
                s += v->rest[3 * v->domain_verts[dom->vert_begin + v->cub_tets[4 * c + k]]];
        }
    }
    for (int32_t t = 0; t < 3 * v->nsurf_tris; ++t) {
        int32_t sv = v->surf_tris[t];
        for (int32_t c = v->surf_copy_ptr[sv]; c < v->surf_copy_ptr[sv + 1]; ++c) {
            const sw_blob_domain *dom = &v->domains[v->surf_copies[2 * c]];
            s += v->rest[3 * v->domain_verts[dom->vert_begin + v->surf_copies[2 * c + 1]]];
        }
    }
    *acc += s;
    return walk_training(v, acc);
}

static inline int contains(const char *haystack, const char *needle) {
    return strstr(haystack, needle) != NULL;
}

/* Parses the forged blob b (size bytes) after fixing its checksum up: 1 when sw_blob_parse
 * refuses it with `code` and a message (printed) holding a and, unless NULL, c. */
static inline int parse_refuses(uint8_t *b, size_t size, sinew_result code, const char *a,
                                const char *c) {
    fix_checksum(b, size);
    sw_blob_view v;
    char msg[512];
    sinew_result r = sw_blob_parse(b, size, &v, msg, sizeof msg);
    fprintf(stderr, "    %s\n", msg);
    return r == code && strstr(msg, a) && (!c || strstr(msg, c));
}

/* Whether the fuzz seed tests/fuzz/corpus/blob_fixed/<name> holds exactly the n bytes b
 * (1), or not (0, saying so); SINEW_WRITE_SEEDS=1 in the environment (re)writes it first. */
static inline int seed_is(const char *name, const uint8_t *b, size_t n) {
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/fuzz/corpus/blob_fixed/%s", SINEW_SOURCE_DIR, name);
    const char *write = getenv("SINEW_WRITE_SEEDS");
    if (write && strcmp(write, "1") == 0) {
        FILE *o = fopen(path, "wb");
        int ok = o && fwrite(b, 1, n, o) == n;
        if (o && fclose(o) != 0) ok = 0;
        if (!ok) fprintf(stderr, "  cannot write %s\n", path);
    }
    size_t got = 0;
    char *seed = sw_test_read_file(path, &got);
    const int same = seed && got == n && memcmp(seed, b, n) == 0;
    if (!same)
        fprintf(stderr, "  %s %s the blob written (SINEW_WRITE_SEEDS=1 rewrites it)\n", path,
                seed ? "is not" : "is missing, not");
    free(seed);
    return same;
}

/* The fixture written to memory (64-aligned buffer, caller frees). */
static inline uint8_t *write_fixture(const fixture *f, size_t *size) {
    void *data = NULL;
    sw_error err;
    sw_error_clear(&err);
    if (sw_blob_write_memory(&f->v, &data, size, &err) != SINEW_OK) {
        fprintf(stderr, "  write failed: %s\n", err.msg);
        return NULL;
    }
    return data;
}

/* write_fixture, parsed back into *v: NULL (the message printed) unless the parse accepts
 * the bytes. */
static inline uint8_t *write_parsed(const fixture *f, size_t *size, sw_blob_view *v) {
    uint8_t *b = write_fixture(f, size);
    char msg[512];
    if (b && sw_blob_parse(b, *size, v, msg, sizeof msg) != SINEW_OK) {
        fprintf(stderr, "  parse failed: %s\n", msg);
        free(b);
        b = NULL;
    }
    return b;
}

#endif
