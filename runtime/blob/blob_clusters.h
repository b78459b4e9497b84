/* The output surface's clusters for the world's broad phase and the novel self-contact's
 * (world_contact.h, novel_contact.h): the boundary's vertex copies grouped into clusters of
 * at most SW_WORLD_CLUSTER copies (median splits of each domain's copies in rest space),
 * the bones that skin each cluster, and each copy's rest area. They depend on the blob
 * alone, so they are derived once when it loads (sinew_blob_load) and shared read-only by
 * all its instances, as the active map is (blob_active.h). */
#ifndef SW_BLOB_CLUSTERS_H
#define SW_BLOB_CLUSTERS_H

#include <stddef.h>
#include <stdint.h>

#include "blob_view.h"

/* Copies per cluster at most. */
#define SW_WORLD_CLUSTER 16

typedef struct sw_surface_clusters {
    int32_t ncl;        /* clusters */
    int32_t *cl_begin;  /* ncl + 1: cluster c holds cl_copy[cl_begin[c] .. cl_begin[c+1]) */
    int32_t *cl_copy;   /* nsurf_copies, in cluster order */
    uint64_t *cl_bones; /* ncl: bits of the bones skinning the cluster (all when > 64) */
    int32_t *cl_bone0;  /* ncl: the bone with the most of the cluster's skinning weight */
    double *copy_area;  /* nsurf_copies: rest area per copy (the area weight of eqs. 3.4-3.6) */
    double *dom_umax;   /* ndomains: the largest |U rows|_F of a surface copy */
} sw_surface_clusters;

/* Upper bound of the cluster count for a blob. */
int32_t sw_surface_cluster_bound(const sw_blob_view *v);

/* Bytes sw_surface_clusters_build needs for v (a multiple of 8). */
size_t sw_surface_clusters_bytes(const sw_blob_view *v);

/* Fills *cl in mem (sw_surface_clusters_bytes(v) bytes, 8-byte aligned). */
void sw_surface_clusters_build(const sw_blob_view *v, void *mem, sw_surface_clusters *cl);

#endif
