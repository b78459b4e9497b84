/* Boundary extraction of a tet mesh by sorting faces: every tet contributes its four
 * faces keyed by their sorted vertex triple; after an O(n log n) sort, a key seen once
 * is a boundary face, twice an interior face, more often a non-manifold mesh. */
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"

typedef struct face_key {
    int32_t v[3]; /* sorted vertex ids */
    int32_t id;   /* 4 * tet + local face */
} face_key;

/* Faces of a positive tet (a,b,c,d), each CCW seen from outside: face k is opposite
 * vertex k. det[b-a, c-a, d-a] > 0 puts d on the side (b-a)x(c-a) points to, so the
 * face opposite d is (a,c,b), and likewise for the others. */
static const int face_of_tet[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

static int cmp_face(const void *pa, const void *pb) {
    const face_key *a = pa, *b = pb;
    for (int k = 0; k < 3; ++k)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

static void sort3(int32_t *v) {
    int32_t t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

sinew_result sw_tetmesh_surface(const sw_tetmesh *m, sw_surface *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!m || !out || m->ntets < 1 || m->nverts < 4 || !m->tets || m->ntets > INT32_MAX / 4)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_tetmesh_surface: empty or missing mesh");
    size_t nf = 4 * (size_t)m->ntets;
    face_key *keys = malloc(nf * sizeof *keys);
    unsigned char *boundary = calloc(nf, 1), *on = calloc((size_t)m->nverts, 1);
    sinew_result rc = SINEW_OK;
    if (!keys || !boundary || !on) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "sw_tetmesh_surface: out of memory");
        goto done;
    }
    for (int32_t t = 0; t < m->ntets; ++t)
        for (int k = 0; k < 4; ++k) {
            face_key *f = keys + 4 * (size_t)t + k;
            for (int i = 0; i < 3; ++i) {
                f->v[i] = m->tets[4 * (size_t)t + face_of_tet[k][i]];
                if (f->v[i] < 0 || f->v[i] >= m->nverts) {
                    rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                      "tet %d references vertex %d (mesh has %d)", t, f->v[i],
                                      m->nverts);
                    goto done;
                }
            }
            sort3(f->v);
            f->id = 4 * t + k;
        }
    qsort(keys, nf, sizeof *keys, cmp_face);
    int32_t ntris = 0;
    for (size_t i = 0; i < nf;) {
        size_t j = i + 1;
        while (j < nf && memcmp(keys[j].v, keys[i].v, sizeof keys[i].v) == 0)
            ++j;
        if (j - i > 2) {
            rc = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                              "face (%d, %d, %d) is shared by %zu tets (%d, %d, %d, ...): "
                              "non-manifold mesh",
                              keys[i].v[0], keys[i].v[1], keys[i].v[2], j - i, keys[i].id / 4,
                              keys[i + 1].id / 4, keys[i + 2].id / 4);
            goto done;
        }
        if (j - i == 1) {
            boundary[keys[i].id] = 1;
            ntris++;
        }
        i = j;
    }
    /* emit in tet order, so the result does not depend on the sort's tie order */
    out->tris = malloc(3 * (size_t)(ntris ? ntris : 1) * sizeof(int32_t));
    if (!out->tris) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "sw_tetmesh_surface: out of memory");
        goto done;
    }
    int32_t *tri = out->tris;
    for (size_t f = 0; f < nf; ++f) {
        if (!boundary[f]) continue;
        const int32_t *q = m->tets + 4 * (f / 4);
        for (int i = 0; i < 3; ++i) {
            tri[i] = q[face_of_tet[f % 4][i]];
            on[tri[i]] = 1;
        }
        tri += 3;
    }
    out->ntris = ntris;
    int32_t nv = 0;
    for (int32_t v = 0; v < m->nverts; ++v)
        nv += on[v];
    out->verts = malloc((size_t)(nv ? nv : 1) * sizeof(int32_t));
    if (!out->verts) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "sw_tetmesh_surface: out of memory");
        goto done;
    }
    out->nverts = nv;
    for (int32_t v = 0, k = 0; v < m->nverts; ++v)
        if (on[v]) out->verts[k++] = v;
done:
    free(keys);
    free(boundary);
    free(on);
    if (rc) sw_surface_free(out);
    return rc;
}
