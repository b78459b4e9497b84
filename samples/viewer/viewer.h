/* sinew-view: a windowed real-time host built the way an engine integrates sinew. The
 * viewer imports its character itself (assimp, or a procedural scene's description) and
 * talks to sinew only through the public headers, so everything it needs from the ABI
 * shows here. */
#ifndef SW_VIEWER_H
#define SW_VIEWER_H

#include <sinew/sinew.h>
#include <stdint.h>
#include <stdio.h>

#define VW_MAX_BONES 256
#define VW_MAX_CLIPS 64

/* One node's local transform: translation, rotation (w, x, y, z), scale. */
typedef struct vw_trs {
    double t[3], q[4], s[3];
} vw_trs;

/* What the host imported: the render mesh with its skin weights (4 per vertex), the
 * skeleton's bind transforms and the clips, as an engine's asset pipeline would hold
 * them. Bone b is the blob's bone of the same name, vertex v the blob's output vertex v
 * (found through the blob's output map: see asset.c). */
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
    /* For blending clips (NULL for a procedural scene): the nnodes node-local transforms
     * of `clip` at t seconds (looped), and the bone transforms (as pose's) of such locals. */
    int32_t nnodes;
    int (*sample)(const struct vw_asset *a, int clip, double t, vw_trs *local);
    int (*compose)(const struct vw_asset *a, const vw_trs *local, float *out);
    void (*release)(struct vw_asset *a);
} vw_asset;

/* Imports FILE with assimp and maps it onto `blob`: each blob bone to the file's node of
 * that name, each output vertex to its source mesh's vertex (the blob's output map). 1 on
 * success; otherwise 0, a message in err (a name or a vertex the file lacks) and *out
 * zeroed. */
int vw_asset_import(const char *path, const sinew_blob *blob, vw_asset *out, char *err,
                    size_t errlen);

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

/* Unit quaternions (w, x, y, z) and 3x3 row-major rotations (quat.c). */
void vw_quat_from_matrix(const double *R, double *q);
void vw_quat_matrix(const double *q, double *R);
/* Slerp from a (u = 0) to b (u = 1) along the shorter arc, normalised. */
void vw_quat_slerp(const double *a, const double *b, double u, double *o);

/* 8-bit RGB PNG (zlib-compressed), rows top first. 1 on success, 0 on failure. */
int vw_write_png(const char *path, int w, int h, const uint8_t *rgb);

#endif
