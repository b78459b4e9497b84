/* Geometry and rig types of the bake side: tet meshes, surfaces, skeletons, weights,
 * clips, and a whole character (what the reference simulator and the bake consume).
 *
 * Conventions:
 *  - Indices are 0-based int32; coordinates are double, xyz interleaved.
 *  - Tets are positively oriented: det[x1-x0, x2-x0, x3-x0] > 0.
 *  - Surface triangles are counter-clockwise seen from outside (outward normals).
 *  - A rigid transform is 12 doubles: R row-major (9) then t (3); it maps a rest-space
 *    point p to R p + t. A bone's transform maps rest space to world space (the
 *    skinning transform), so the rest pose is the identity for every bone.
 *  - Every owned pointer is malloc'd; the *_free functions release it and zero the
 *    struct; freeing a zeroed struct is a no-op.
 */
#ifndef SW_MESH_H
#define SW_MESH_H

#include <stdint.h>

#include "clock.h"
#include "sw_error.h"

typedef struct sw_tetmesh {
    int32_t nverts, ntets;
    double *X;     /* 3*nverts rest positions */
    int32_t *tets; /* 4*ntets vertex ids */
} sw_tetmesh;

typedef struct sw_trimesh {
    int32_t nverts, ntris;
    double *X;     /* 3*nverts */
    int32_t *tris; /* 3*ntris */
} sw_trimesh;

/* Boundary of a tet mesh: triangles over the tet mesh's own vertex ids. */
typedef struct sw_surface {
    int32_t ntris;
    int32_t *tris;  /* 3*ntris tet-mesh vertex ids, outward CCW */
    int32_t nverts; /* distinct vertices on the surface */
    int32_t *verts; /* nverts tet-mesh vertex ids, ascending */
} sw_surface;

typedef struct sw_skeleton {
    int32_t njoints;
    double *joints; /* 3*njoints rest positions */
    int32_t nbones;
    int32_t *bones;  /* 2*nbones: (head joint, tail joint) */
    int32_t *parent; /* nbones: parent bone (whose tail is this bone's head) or -1 */
    /* Bones keep their file order (weights columns follow it); parents may come after
     * children, but the hierarchy has no cycles (sw_skeleton_validate checks). */
} sw_skeleton;

/* Skin weights: w[v*nbones + b], each row non-negative and summing to 1. */
typedef struct sw_weights {
    int32_t nverts, nbones;
    double *w;
} sw_weights;

/* An animation as per-frame bone transforms (rest -> world). */
typedef struct sw_clip {
    int32_t nbones, nframes;
    double fps;
    double *T; /* nframes * nbones * 12 */
} sw_clip;

/* Everything the reference simulator needs for one character. */
typedef struct sw_character {
    char name[64];
    sw_tetmesh mesh;
    sw_skeleton skel;
    sw_weights weights;
    int32_t *bone_of_vertex; /* nverts: bone driving this vertex rigidly, or -1 (free flesh) */
    sw_clip clip;
    /* Each joint's range of motion (nframes 0: none given): its largest turn over these
     * frames bounds the bake's joint sweeps and random combined poses where the bake has
     * no clip to train on; without it they turn every joint 90 degrees across its bone,
     * the palm's metacarpals too (docs/notes/generalisation.md, "Joint ranges"). */
    sw_clip range;
    double youngs;  /* Young's modulus E */
    double poisson; /* Poisson ratio nu */
    double density; /* mass per unit rest volume */
    /* Painted material (NULL: uniform). A multiplier of E (mu and lambda alike, so nu is
     * kept) per render vertex as the artist painted it, and per tet as the simulation
     * uses it (sw_character_paint carries the first onto the second). */
    double *render_stiffness; /* render.nverts, > 0, or NULL */
    double *tet_stiffness;    /* mesh.ntets, > 0, or NULL */
    /* Optional render mesh (render.nverts 0: none). When set, the bake embeds it in the
     * tets and the runtime's output surface is this mesh in its own vertex order;
     * otherwise the output surface is the tet mesh's boundary. */
    sw_trimesh render;
    char (*bone_names)[64]; /* skel.nbones names from the file (glTF/FBX nodes), or NULL */
    /* What the file was, for the blob's asset description (NULL / 0: not from a file): */
    double *bone_bind;          /* 12 skel.nbones: bind global transforms, or NULL (identity) */
    int32_t *render_source;     /* 2 render.nverts: (file mesh, vertex in it), or NULL */
    int32_t nsource_meshes;     /* the file's meshes as imported */
    int32_t *source_mesh_verts; /* nsource_meshes vertex counts */
    uint64_t source_hash;       /* FNV-1a 64 of the file's bytes (0: none) */
} sw_character;

/* Tet t's multiplier of the character's E (1 where nothing is painted). */
static inline double sw_character_stiffness(const sw_character *c, int64_t t) {
    return c->tet_stiffness ? c->tet_stiffness[t] : 1.0;
}

void sw_tetmesh_free(sw_tetmesh *m);
void sw_trimesh_free(sw_trimesh *m);
void sw_surface_free(sw_surface *s);
void sw_skeleton_free(sw_skeleton *s);
void sw_weights_free(sw_weights *w);
void sw_clip_free(sw_clip *c);
void sw_character_free(sw_character *c);

/* Validates a triangle surface for `who` (the messages' prefix): at least 3 vertices and
 * one triangle, coordinates finite, indices in range; SINEW_ERROR_INVALID_ARGUMENT naming
 * the first offending item. */
sinew_result sw_trimesh_validate(const sw_trimesh *m, const char *who, sw_error *err);

/* Signed volume of tet (a,b,c,d): det[b-a, c-a, d-a] / 6. */
double sw_tet_signed_volume(const double *a, const double *b, const double *c, const double *d);
/* A tet mesh's volume (its tets' signed volumes summed). */
double sw_tetmesh_volume(const sw_tetmesh *m);
/* The volume a triangle surface encloses, by the divergence theorem: exact when it is
 * closed, positive when it is oriented outward. */
double sw_trimesh_signed_volume(const sw_trimesh *m);

/* Validates a tet mesh: counts positive, indices in range, coordinates finite, no
 * tet with a repeated vertex, every tet of positive volume above `min_volume`
 * (pass 0 for "strictly positive"). The message names the first offending item. */
sinew_result sw_tetmesh_validate(const sw_tetmesh *m, double min_volume, sw_error *err);

/* Forward kinematics. `local` holds per bone a rotation (9, row-major) about the
 * bone's head joint, expressed in rest space and applied after the parent's
 * transform: T_b(x) = T_parent(h_b + L_b (x - h_b)); every root bone also gets
 * `root_translation` (3, may be NULL). The skeleton must pass sw_skeleton_validate
 * (at most SW_MAX_BONES bones). Writes 12*nbones to T. */
void sw_forward_kinematics(const sw_skeleton *s, const double *local,
                           const double *root_translation, double *T);

#define SW_MAX_BONES 1024

/* Checks joints finite, bone joint ids in range, parents in range, no cycles, and at
 * most SW_MAX_BONES bones. */
sinew_result sw_skeleton_validate(const sw_skeleton *s, sw_error *err);

/* A motion of nbones bones: at least one frame, every value finite. Errors: PARSE (the
 * shape, or no frames), NOT_FINITE (naming the frame); the message names "motion". */
sinew_result sw_clip_validate(const sw_clip *c, int32_t nbones, sw_error *err);

/* Depth of bone b: 0 for a root, its parent's plus 1 otherwise (a validated skeleton). */
int32_t sw_bone_depth(const sw_skeleton *s, int32_t b);

/* Linear blend skinning of rest positions X (3*n) with weights W (n x nbones) and
 * bone transforms T (12*nbones) into x (3*n). */
void sw_lbs(int32_t n, const double *X, const sw_weights *W, const double *T, double *x);

/* Distance from point p to the segment a-b (a point when a == b). */
double sw_point_segment_distance(const double *p, const double *a, const double *b);

/* Applies rigid transform T (12) to p (3) into out (3); out may alias p. */
void sw_transform_point(const double *T, const double *p, double *out);

#endif
