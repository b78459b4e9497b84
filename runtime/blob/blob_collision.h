/* The collision surface of a blob (sinew_blob_collision_triangles): the tet boundary a
 * mesh collider of another character's world can take. A tet mesh whose parts touch
 * along an edge or at a vertex (two legs of a coarse mesh, a tail against a thigh) has a
 * boundary edge shared by four triangles or a vertex whose triangles form two cones; a
 * mesh collider needs every edge between two triangles (its edge pseudonormals, Baerentzen
 * and Aanaes). Each such vertex is split into one copy per sheet: the corners of a vertex
 * whose triangles a manifold edge joins are one sheet. A boundary that is manifold
 * already comes back unchanged (vertex i is boundary vertex i). Built once at load. */
#ifndef SW_BLOB_COLLISION_H
#define SW_BLOB_COLLISION_H

#include <stdint.h>

#include "blob_view.h"
#include "sinew/sinew_base.h"

typedef struct sw_coll_surface {
    int32_t nverts, ntris;
    int32_t *vert; /* nverts: each collision vertex's boundary vertex (the first nsurf_verts
                      are the boundary's own) */
    int32_t *tris; /* 3 ntris: the boundary's triangles over the collision vertices */
    void *block;   /* what holds both */
} sw_coll_surface;

/* Builds v's collision surface (allocates through al; OUT_OF_MEMORY leaves it empty). */
sinew_result sw_coll_surface_build(const sw_blob_view *v, const sinew_allocator *al,
                                   sw_coll_surface *out);

void sw_coll_surface_free(const sinew_allocator *al, sw_coll_surface *cs);

#endif
