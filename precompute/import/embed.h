/* The render mesh embedded in the simulation tets (DESIGN.md §4): every render
 * vertex gets a tet and 4 barycentrics that reproduce its rest position exactly, so the
 * runtime can carry the render mesh on the deformed tets; and a weld map that joins the
 * render vertices at one rest position (UV seams, hard edges) so they move and shade as
 * one. */
#ifndef SW_EMBED_H
#define SW_EMBED_H

#include <stdint.h>

#include "sw_mesh.h"

/* The largest |barycentric| the embedding accepts. A vertex outside the tets extrapolates
 * its tet's affine map, and every motion of the tet comes out multiplied by up to that
 * much: beyond it the render mesh does not fit the simulation mesh (other units, another
 * pose, far too coarse a tet mesh) and the bake says so instead of amplifying. Kept below
 * the loader's bound SW_BLOB_MAX_BARY. */
#define SW_EMBED_MAX_BARY 16.0

typedef struct sw_embedding {
    int32_t nverts; /* render vertices */
    int32_t *tet;   /* nverts: the simulation tet of each */
    double *bary;   /* 4 nverts: sum 1, sum_k bary_k X(tet corner k) = the rest position */
    int32_t *weld;  /* nverts: the lowest-numbered render vertex at the same rest position */
    /* report */
    int32_t outside;    /* representatives outside every tet */
    double max_outside; /* the largest distance of a render vertex from the tet mesh */
    int32_t worst;      /* the render vertex at max_outside (-1: all inside) */
    double max_bary;    /* the largest |barycentric| */
    int32_t nwelded;    /* render vertices that are another's duplicate */
    double seconds;
} sw_embedding;

/* Embeds `render` in the tets of `mesh` (which must pass sw_tetmesh_validate): a vertex in a
 * tet gets that tet (the one it is deepest in when on a shared face); one outside gets,
 * among the tets within a quarter of a cell of the nearest one, the tet whose affine map
 * extrapolates least to reach it, with barycentrics that still reproduce it exactly
 * (negative ones, |b| <= SW_EMBED_MAX_BARY, else SINEW_ERROR_UNSUPPORTED naming the
 * vertex and its distance). Duplicates (equal rest positions) share their
 * representative's embedding. A uniform grid over the tets' boxes keeps it about linear:
 * 100K tets and 50K render vertices in well under a second. Errors: INVALID_ARGUMENT
 * (empty or non-finite render mesh, a triangle index out of range), OUT_OF_MEMORY. */
sinew_result sw_embed_render(const sw_tetmesh *mesh, const sw_trimesh *render, sw_embedding *out,
                             sw_error *err);

/* Releases the arrays and zeroes the struct; a zeroed struct is a no-op. */
void sw_embedding_free(sw_embedding *e);

#endif
