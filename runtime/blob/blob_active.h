/* The subspace map's tables (reduced_map.h): which vertices the step skins, and where each
 * cubature tet corner, boundary surface copy, render node copy and pose-space contact
 * vertex finds its skinning transform among them. They depend on the blob alone, so they
 * are derived once when it loads (sinew_blob_load) and shared read-only by all its
 * instances, as the pose index is (blob_pose_index.h): held per instance, every instance of a
 * crowd kept the same copy. */
#ifndef SW_BLOB_ACTIVE_H
#define SW_BLOB_ACTIVE_H

#include <stddef.h>
#include <stdint.h>

#include "blob_view.h"

typedef struct sw_active_map {
    int32_t nact;      /* active vertices */
    int32_t nact_step; /* the first nact_step: those every step reads (ACT_STEP below) */
    int32_t *act_vert; /* nact: the global vertex of each, ascending in both parts */
    int32_t *cub_act;  /* 4 ncub: active index of each cubature tet corner */
    /* The cubature tets' corners, each (domain, local vertex) once: a pass places each once
     * and sums the forces of its tets on it (cubature.c). Domain k's are corner_begin[k] ..
     * corner_begin[k + 1] - 1, in local vertex order. */
    int32_t ncorner;
    int32_t *corner_begin;           /* ndomains + 1 */
    int32_t *corner_lv, *corner_act; /* ncorner: local vertex and active index */
    int32_t *cub_corner;             /* 4 ncub: the corner of each cubature tet corner */
    int32_t *copy_act;               /* nsurf_copies: active index of each surface copy */
    int32_t *contact_act;            /* 4 ncontacts: active index of p, t0, t1, t2 */
    int32_t *node_copy_act;          /* nrender_copies: active index of each render node copy */
} sw_active_map;

/* Bytes sw_active_map_build needs for v (a multiple of 8). Needs no memory itself: the
 * vertices are marked a chunk of the mesh at a time in a bit set on the stack. */
size_t sw_active_map_bytes(const sw_blob_view *v);

/* Fills *a in mem (sw_active_map_bytes(v) bytes, 4-byte aligned). */
void sw_active_map_build(const sw_blob_view *v, void *mem, sw_active_map *a);

#endif
