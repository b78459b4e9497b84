/* The subspace map's tables, derived from the blob once at its load (blob_active.h). */
#include <string.h>

#include "blob_active.h"
#include "sorted.h"

/* The vertices the step skins: every cubature tet corner, render node copy and pose-space
 * contact vertex (ACT_STEP), and every boundary surface copy (ACT_SURFACE: read only by
 * the world's contact and by the output of a blob without a render mesh), each once.
 * visit() is called with the global vertex of every such reference of the tiers asked
 * for and the slot that receives its active index (NULL without a map). */
enum { ACT_STEP = 1, ACT_SURFACE = 2 };
typedef void (*visit_fn)(void *ctx, int32_t gv, int32_t *slot);

static void visit_active(const sw_blob_view *v, sw_active_map *a, int tiers, visit_fn visit,
                         void *ctx) {
    for (int32_t k = 0; k < v->ndomains && (tiers & ACT_STEP); ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c)
            for (int j = 0; j < 4; ++j)
                visit(ctx, v->domain_verts[D->vert_begin + v->cub_tets[4 * c + j]],
                      a ? &a->cub_act[4 * c + j] : NULL);
    }
    for (int32_t i = 0; i < v->nsurf_copies && (tiers & ACT_SURFACE); ++i) {
        const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
        visit(ctx, v->domain_verts[D->vert_begin + v->surf_copies[2 * i + 1]],
              a ? &a->copy_act[i] : NULL);
    }
    for (int32_t i = 0; i < v->nrender_copies && (tiers & ACT_STEP); ++i) {
        const sw_blob_domain *D = &v->domains[v->render_node_copies[2 * i]];
        visit(ctx, v->domain_verts[D->vert_begin + v->render_node_copies[2 * i + 1]],
              a ? &a->node_copy_act[i] : NULL);
    }
    for (int32_t c = 0; c < v->ncontacts && (tiers & ACT_STEP); ++c)
        for (int k = 0; k < 4; ++k) {
            const sw_blob_domain *D = &v->domains[v->contact_verts[8 * c + 2 * k]];
            visit(ctx, v->domain_verts[D->vert_begin + v->contact_verts[8 * c + 2 * k + 1]],
                  a ? &a->contact_act[4 * c + k] : NULL);
        }
}

/* Marks are kept a chunk of vertices at a time in bit sets on the stack. */
enum { CHUNK = 1 << 16 };
typedef struct {
    int32_t lo;
    uint64_t bits[CHUNK / 64];
} chunk_marks;

static void mark_in_chunk(void *ctx, int32_t gv, int32_t *slot) {
    chunk_marks *c = ctx;
    (void)slot;
    if (gv >= c->lo && gv - c->lo < CHUNK)
        c->bits[(gv - c->lo) / 64] |= 1ull << ((gv - c->lo) % 64);
}

/* The number of active vertices, and in *nstep those of ACT_STEP. With act_vert (and
 * nstep the count sizing found), also their global ids: ACT_STEP's ascending in
 * [0, nstep), then the surface copies' that are not among them, ascending. */
static int32_t active_vertices(const sw_blob_view *v, int32_t *act_vert, int32_t *nstep) {
    chunk_marks cs, cf;
    int32_t ns = 0, nf = 0, base = act_vert ? *nstep : 0;
    for (cs.lo = 0; cs.lo < v->nverts; cs.lo += CHUNK) {
        cf.lo = cs.lo;
        memset(cs.bits, 0, sizeof cs.bits);
        memset(cf.bits, 0, sizeof cf.bits);
        visit_active(v, NULL, ACT_STEP, mark_in_chunk, &cs);
        visit_active(v, NULL, ACT_SURFACE, mark_in_chunk, &cf);
        for (int32_t i = 0; i < CHUNK && cs.lo + i < v->nverts; ++i) {
            int in_step = cs.bits[i / 64] >> (i % 64) & 1,
                in_surf = cf.bits[i / 64] >> (i % 64) & 1;
            if (in_step) {
                if (act_vert) act_vert[ns] = cs.lo + i;
                ns++;
            } else if (in_surf) {
                if (act_vert) act_vert[base + nf] = cs.lo + i;
                nf++;
            }
        }
    }
    *nstep = ns;
    return ns + nf;
}

/* The active index of global vertex gv: among ACT_STEP's, else among the rest. */
static void assign_active(void *ctx, int32_t gv, int32_t *slot) {
    const sw_active_map *a = ctx;
    int32_t i = sw_sorted_index(a->act_vert, a->nact_step, gv);
    *slot = i >= 0 ? i
                   : a->nact_step +
                         sw_sorted_index(a->act_vert + a->nact_step, a->nact - a->nact_step, gv);
}

/* The cubature tets' corners: their number, and with a (whose cub_act is filled) their
 * lists in a's corner arrays. */
static int32_t cubature_corners(const sw_blob_view *v, sw_active_map *a) {
    uint64_t bits[CHUNK / 64];
    int32_t n = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        if (a) a->corner_begin[k] = n;
        for (int32_t lo = 0; lo < D->vert_count; lo += CHUNK) {
            memset(bits, 0, sizeof bits);
            for (int32_t i = 4 * D->cub_begin; i < 4 * (D->cub_begin + D->cub_count); ++i) {
                int32_t lv = v->cub_tets[i] - lo;
                if (lv >= 0 && lv < CHUNK) bits[lv / 64] |= 1ull << (lv % 64);
            }
            for (int32_t i = 0; i < CHUNK && lo + i < D->vert_count; ++i)
                if (bits[i / 64] >> (i % 64) & 1) {
                    if (a) a->corner_lv[n] = lo + i;
                    n++;
                }
        }
        if (!a) continue;
        for (int32_t i = 4 * D->cub_begin; i < 4 * (D->cub_begin + D->cub_count); ++i) {
            int32_t b = a->corner_begin[k],
                    c = b + sw_sorted_index(a->corner_lv + b, n - b, v->cub_tets[i]);
            a->cub_corner[i] = c;
            a->corner_act[c] = a->cub_act[i]; /* the vertex's, whichever tet names it */
        }
    }
    if (a) a->corner_begin[v->ndomains] = n;
    return n;
}

/* The arrays' lengths, in their order in the block. */
static void part_lengths(const sw_blob_view *v, int32_t nact, int32_t ncorner, size_t len[9]) {
    const size_t ncub = (size_t)v->ncub;
    size_t l[9] = {(size_t)nact,
                   4 * ncub,
                   (size_t)v->ndomains + 1,
                   (size_t)ncorner,
                   (size_t)ncorner,
                   4 * ncub,
                   (size_t)v->nsurf_copies,
                   4 * (size_t)v->ncontacts,
                   (size_t)v->nrender_copies};
    memcpy(len, l, sizeof l);
}

size_t sw_active_map_bytes(const sw_blob_view *v) {
    int32_t nstep, nact = active_vertices(v, NULL, &nstep);
    size_t len[9], n = 0;
    part_lengths(v, nact, cubature_corners(v, NULL), len);
    for (int i = 0; i < 9; ++i)
        n += len[i];
    return (sizeof(int32_t) * n + 7) / 8 * 8;
}

void sw_active_map_build(const sw_blob_view *v, void *mem, sw_active_map *a) {
    a->nact = active_vertices(v, NULL, &a->nact_step);
    a->ncorner = cubature_corners(v, NULL);
    size_t len[9];
    part_lengths(v, a->nact, a->ncorner, len);
    int32_t **part[9] = {&a->act_vert,  &a->cub_act,     &a->corner_begin,
                         &a->corner_lv, &a->corner_act,  &a->cub_corner,
                         &a->copy_act,  &a->contact_act, &a->node_copy_act};
    int32_t *p = mem;
    for (int i = 0; i < 9; ++i) {
        *part[i] = p;
        p += len[i];
    }
    (void)active_vertices(v, a->act_vert, &a->nact_step);
    visit_active(v, a, ACT_STEP | ACT_SURFACE, assign_active, a);
    (void)cubature_corners(v, a);
}
