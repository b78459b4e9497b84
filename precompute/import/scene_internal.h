/* Private to scene_read.c, scene_import.c and scene_clip.c: the character built from
 * assimp's scene, the scene's node table and 4x4 affine helpers (row-major doubles,
 * translation in the last column, as assimp's aiMatrix4x4). */
#ifndef SW_SCENE_INTERNAL_H
#define SW_SCENE_INTERNAL_H

#include <assimp/scene.h>

#include "scene_import.h"

/* Every node of the scene in depth-first (pre-)order: a parent comes before its children. */
typedef struct sw_scene_nodes {
    int32_t n;
    const struct aiNode **node;
    int32_t *parent;          /* index in this table, -1 for the root */
    double *G;                /* 16*n global transforms of the file's node pose */
    const int32_t *node_bone; /* n: the node's bone, or -1 (channels prefer joint nodes) */
} sw_scene_nodes;

/* The character in `sc` (assimp's import of the file `name`, NULL when assimp failed; its
 * scene is released here) into `out` with the checked options `o`. `bytes`: the glTF file
 * read again for what assimp drops (NULL for other formats; `binary` when it is a .glb);
 * `dir`: its folder when it was read from a path. Messages start "name: "; on failure
 * `out` is left zeroed. */
sinew_result sw_scene_build(const struct aiScene *sc, const char *name, const void *bytes,
                            size_t nbytes, int binary, const char *dir, const sw_import_options *o,
                            sw_imported_character *out, sw_error *err);

/* out = a * b (out may not alias a or b). */
void sw_m4_mul(const double *a, const double *b, double *out);

/* Inverse of an affine 4x4 (bottom row 0 0 0 1); 0 when the 3x3 part is singular. */
int sw_m4_affine_inverse(const double *m, double *out);

/* aiMatrix4x4 -> 16 doubles; 0 when an entry is not finite. */
int sw_m4_from_ai(const struct aiMatrix4x4 *m, double *out);

/* Samples animation `a` at `fps` into `out`: for bone b (joint node bone_node[b]) the
 * transform G(t) * Binv[b], with translations times `scale`. Messages start "name: ". */
sinew_result sw_scene_sample_clip(const struct aiAnimation *a, const sw_scene_nodes *nodes,
                                  int32_t nbones, const int32_t *bone_node, const double *Binv,
                                  double scale, double fps, const char *name, sw_imported_clip *out,
                                  sw_error *err);

#endif
