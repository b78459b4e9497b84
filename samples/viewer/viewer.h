/* sinew-view: a windowed real-time host built the way an engine integrates sinew. The
 * viewer imports its character itself (assimp, or a procedural scene's description) and
 * talks to sinew only through the public headers, so everything it needs from the ABI
 * shows here. */
#ifndef SW_VIEWER_H
#define SW_VIEWER_H

#include <stdint.h>
#include <stdio.h>

#define VW_MAX_BONES 256
#define VW_MAX_CLIPS 64

/* What the host imported: the render mesh with its skin weights (4 per vertex), the
 * skeleton's bind transforms and the clips, as an engine's asset pipeline would hold
 * them. Bone b and vertex v are in the order the bake imported them (see asset.c). */
typedef struct vw_asset {
    int32_t nbones, nverts, ntris;
    float *rest;    /* 3 nverts, bind pose */
    uint32_t *tris; /* 3 ntris */
    int32_t *wbone; /* 4 nverts */
    float *wgt;     /* 4 nverts, summing to 1 */
    int32_t *weld;  /* nverts: the first vertex at the same rest position (a seam's) */
    int32_t nclips;
    char clip_names[VW_MAX_CLIPS][64];
    double clip_duration[VW_MAX_CLIPS]; /* seconds */
    void *impl;                         /* the importer's own state */
    /* Bone transforms (12 floats each: 3x3 row-major, then the translation) mapping the
     * bind pose to the pose of `clip` at `t` seconds (looped). */
    int (*pose)(const struct vw_asset *a, int clip, double t, float *out);
    void (*release)(struct vw_asset *a);
} vw_asset;

/* Imports FILE with assimp. 0 on success; otherwise writes a message into err. */
int vw_asset_import(const char *path, vw_asset *out, char *err, size_t errlen);

/* A procedural sample scene ("finger", "cylinder", "capsule") described as the bake
 * generates it, skinning the blob's own rest surface (rest: 3 nverts floats, tris). */
int vw_scene_asset(const char *name, const float *rest, int32_t nverts, const uint32_t *tris,
                   int32_t ntris, uint32_t nbones, vw_asset *out, char *err, size_t errlen);

void vw_asset_free(vw_asset *a);

/* Plain skinning on the CPU: linear blend (dqs 0) or dual quaternions (dqs 1). */
void vw_skin(const vw_asset *a, const float *T, int dqs, float *pos, float *nrm);

/* Fills a->weld: a UV seam's copies of a vertex share one normal, as the blob's do. */
int vw_asset_weld(vw_asset *a);

/* Area-weighted vertex normals of a triangle mesh, shared across weld (NULL: none). */
void vw_normals(const float *pos, int32_t nverts, const uint32_t *tris, int32_t ntris,
                const int32_t *weld, float *nrm);

/* 8-bit RGB PNG (zlib-compressed), rows top first. 0 on success. */
int vw_write_png(const char *path, int w, int h, const uint8_t *rgb);

#endif
