/* The collision surface (blob_collision.h): the tet boundary with its non-manifold
 * vertices split, one copy per sheet. */
#include "blob_collision.h"

#include <stdlib.h>
#include <string.h>

#include "alloc.h"

/* One triangle corner's directed edge (corner e to corner e + 1), keyed by its vertices. */
typedef struct edge_use {
    int32_t lo, hi, corner; /* corner: 3 t + e */
    int32_t forward;        /* runs lo -> hi */
} edge_use;

static int edge_cmp(const void *pa, const void *pb) {
    const edge_use *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->corner < b->corner ? -1 : a->corner > b->corner;
}

static int32_t find(int32_t *parent, int32_t c) {
    while (parent[c] != c)
        c = parent[c] = parent[parent[c]];
    return c;
}

static void unite(int32_t *parent, int32_t a, int32_t b) {
    a = find(parent, a), b = find(parent, b);
    if (a != b) parent[a > b ? a : b] = a < b ? a : b; /* the smaller corner is the root */
}

/* The next corner of corner c's triangle. */
static int32_t next_corner(int32_t c) {
    return c - c % 3 + (c % 3 + 1) % 3;
}

/* Corners of one vertex belong to one sheet where a manifold edge (two uses, opposite
 * ways) joins their triangles: the two corners at each end of the edge are united. */
static void unite_across_edges(const int32_t *tris, int32_t ntris, edge_use *u, int32_t *parent) {
    const int32_t ne = 3 * ntris;
    for (int32_t c = 0; c < ne; ++c) {
        int32_t a = tris[c], b = tris[next_corner(c)];
        u[c] = (edge_use){a < b ? a : b, a < b ? b : a, c, a < b};
        parent[c] = c;
    }
    qsort(u, (size_t)ne, sizeof *u, edge_cmp);
    for (int32_t i = 0, j; i < ne; i = j) {
        for (j = i + 1; j < ne && u[j].lo == u[i].lo && u[j].hi == u[i].hi;)
            ++j;
        if (j - i != 2 || u[i].forward == u[i + 1].forward) continue;
        const int32_t c1 = u[i].corner, c2 = u[i + 1].corner;
        /* c1 runs x -> y, c2 runs y -> x: c1's start meets c2's end and the reverse */
        unite(parent, c1, next_corner(c2));
        unite(parent, next_corner(c1), c2);
    }
}

sinew_result sw_coll_surface_build(const sw_blob_view *v, const sinew_allocator *al,
                                   sw_coll_surface *out) {
    memset(out, 0, sizeof *out);
    const int32_t nt = v->nsurf_tris, nv = v->nsurf_verts, ne = 3 * nt;
    edge_use *u = sw_alloc(al, sizeof(edge_use) * (size_t)ne + 1, SW_ALLOC_ALIGN);
    int32_t *parent = sw_alloc(al, sizeof(int32_t) * (size_t)ne + 1, SW_ALLOC_ALIGN);
    int32_t *first = sw_alloc(al, sizeof(int32_t) * (size_t)nv + 1, SW_ALLOC_ALIGN);
    /* one block: vert (at most nv + ne) then tris */
    int32_t *block =
        sw_alloc(al, sizeof(int32_t) * ((size_t)nv + 2 * (size_t)ne) + 1, SW_ALLOC_ALIGN);
    sinew_result r = u && parent && first && block ? SINEW_OK : SINEW_ERROR_OUT_OF_MEMORY;
    if (r == SINEW_OK) {
        unite_across_edges(v->surf_tris, nt, u, parent);
        int32_t *vert = block, *tris = block + nv + ne, n = nv;
        for (int32_t s = 0; s < nv; ++s) {
            first[s] = -1;
            vert[s] = s;
        }
        /* the sheet of a vertex's first corner keeps the vertex's index; each further
           sheet is a new vertex after the boundary's, in corner order */
        for (int32_t c = 0; c < ne; ++c) {
            const int32_t s = v->surf_tris[c], root = find(parent, c);
            if (root != c) {
                tris[c] = tris[root];
                continue;
            }
            if (first[s] < 0) {
                first[s] = c;
                tris[c] = s;
            } else {
                vert[n] = s;
                tris[c] = n++;
            }
        }
        out->vert = vert;
        out->tris = tris;
        out->nverts = n;
        out->ntris = nt;
        out->block = block;
        block = NULL;
    }
    sw_free(al, u);
    sw_free(al, parent);
    sw_free(al, first);
    sw_free(al, block);
    return r;
}

void sw_coll_surface_free(const sinew_allocator *al, sw_coll_surface *cs) {
    sw_free(al, cs->block);
    memset(cs, 0, sizeof *cs);
}
