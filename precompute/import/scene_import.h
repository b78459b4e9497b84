/* A rigged character from a glTF 2.0 (.gltf/.glb) or FBX file, read through assimp's C API
 * (DESIGN.md §5): the skinned meshes merged into one render mesh in bind pose, the skin's
 * joints as a skeleton, weights cut to 4 influences, and every animation sampled into a
 * clip of rest -> world bone transforms (sw_mesh.h conventions).
 *
 * Conventions of the result:
 *  - World units are metres, +Y up (glTF's convention; FBX gets assimp's unit conversion).
 *  - Rest space is the bind pose in world units: a bone's clip transform is
 *    G_j(t) * B_j^-1, with G_j(t) the joint node's animated global transform and B_j its
 *    bind global transform (the inverse of the skin's inverse bind matrix, placed by the
 *    skinned mesh's bind space), so the bind pose is the identity for every bone.
 *  - Bones are the union of every skin's joints, in node traversal (depth-first) order.
 *
 * Not thread-safe: assimp's C API keeps its last error in a global. */
#ifndef SW_SCENE_IMPORT_H
#define SW_SCENE_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "sw_mesh.h"

/* Zero in a field means its default. */
typedef struct sw_import_options {
    double fps;           /* clip sampling rate in frames per second; 0: 30 */
    double target_height; /* > 0: scale so the render mesh is this tall (metres); 0: file units */
} sw_import_options;

typedef struct sw_imported_clip {
    char name[64];     /* the animation's name, cut to 63 bytes ("clipN" when it has none) */
    sw_clip clip;      /* nframes = floor(duration * fps) + 1, frame 0 at t = 0 */
    double duration_s; /* the animation's length in seconds */
} sw_imported_clip;

typedef struct sw_imported_character {
    sw_trimesh render;             /* every skinned mesh and rigid prop merged, bind pose, metres */
    int32_t *render_source;        /* render.nverts: index of the aiMesh the vertex came from */
    int32_t *render_source_vertex; /* render.nverts: its index within that aiMesh */
    int32_t nsource_meshes;        /* the aiScene's meshes */
    int32_t *source_mesh_verts;    /* nsource_meshes: each one's vertex count */
    /* render.nverts: the painted stiffness multiplier (a glTF primitive's _SINEW_STIFFNESS
     * attribute, 1 where a primitive has none), or NULL when no primitive has one */
    double *render_stiffness;
    double *bone_bind;      /* 12 skel.nbones: bind global transforms (3x3 row-major, t), scaled */
    sw_skeleton skel;       /* joints 0..nb-1 are bone heads, nb..2nb-1 their tails */
    char (*bone_names)[64]; /* skel.nbones node names, cut to 63 bytes */
    sw_weights weights;     /* render.nverts x skel.nbones, <= 4 non-zero per row, rows sum 1 */
    double weight_dropped_max; /* largest share of a vertex's weight cut by the 4-influence limit */
    double weight_dropped_mean; /* mean of that share over the skinned vertices */
    int32_t nskinned;           /* meshes with bones merged */
    int32_t nrigid;   /* boneless meshes shown by a node at or below a joint: weight 1 to it */
    int32_t nignored; /* boneless meshes shown by a node outside the skeleton (not imported) */
    int32_t nclips;
    sw_imported_clip *clips;
    double unit_scale; /* scale applied to the file's coordinates */
} sw_imported_character;

/* Imports the file at `path` (format from its contents and extension). `o` may be NULL
 * (defaults). On failure `out` is zeroed and `err` names the file: SINEW_ERROR_IO (cannot
 * read), SINEW_ERROR_PARSE (assimp rejected it), SINEW_ERROR_INVALID_ARGUMENT (no skin,
 * unweighted vertices, a bone without a node, bad options), SINEW_ERROR_NOT_FINITE (a NaN
 * or infinity in the data), SINEW_ERROR_CAPACITY (too big), SINEW_ERROR_OUT_OF_MEMORY. A
 * glTF's painted stiffness (gltf_attribute.h) adds SINEW_ERROR_INVALID_ARGUMENT (a value
 * not finite in (0, 1e6]), SINEW_ERROR_PARSE (its accessor out of place) and
 * SINEW_ERROR_UNSUPPORTED (sparse, or primitives that cannot be matched to assimp's). */
sinew_result sw_scene_import(const char *path, const sw_import_options *o,
                             sw_imported_character *out, sw_error *err);

/* The same from `len` bytes in memory; `hint` is the format's extension ("glb", "gltf",
 * "fbx"). A .gltf in memory can only use embedded (data URI) buffers. */
sinew_result sw_scene_import_memory(const void *data, size_t len, const char *hint,
                                    const sw_import_options *o, sw_imported_character *out,
                                    sw_error *err);

/* Releases everything and zeroes `c`; a zeroed struct is a no-op. */
void sw_imported_character_free(sw_imported_character *c);

#endif
