/* Private to scene_import.c: a custom glTF vertex attribute (one a painted material uses,
 * _SINEW_STIFFNESS) read from the file's own bytes, since assimp 5.2.5 drops attributes it
 * does not know. gltf_attribute.c says how its primitives are matched to assimp's meshes. */
#ifndef SW_GLTF_ATTRIBUTE_H
#define SW_GLTF_ATTRIBUTE_H

#include <stddef.h>
#include <stdint.h>

#include "sw_error.h"

/* Reads the SCALAR attribute `attr` of every glTF primitive of the .glb (`binary` 1) or
 * .gltf (0) in `len` bytes, in the order assimp 5.2.5 makes its aiMeshes from them. The
 * caller passes what assimp made: `nprims` meshes, prim_verts[k] vertices in mesh k and,
 * when prim_xyz is not NULL, prim_xyz[k] their 3 float coordinates, which the primitive's
 * POSITION must equal (a check that the order is right). On success *out is NULL when no
 * primitive has the attribute, else sum(prim_verts) doubles (malloc; the caller frees):
 * mesh 0's vertices, then mesh 1's..., 1 where a primitive lacks the attribute. A value
 * must be finite, > 0 and <= 1e6 (SINEW_ERROR_INVALID_ARGUMENT naming mesh, primitive and
 * vertex). The accessor is FLOAT, or normalized UNSIGNED_BYTE/SHORT, in the GLB's BIN
 * chunk, a base64 data: URI or, when `dir` is not NULL, a file named by a relative uri in
 * the folder `dir` (the .gltf's); SINEW_ERROR_UNSUPPORTED for a sparse accessor, another
 * uri, or primitives that do not match assimp's meshes; SINEW_ERROR_IO for a buffer file
 * that cannot be read; SINEW_ERROR_PARSE for a reference, offset, count or type out of
 * place. Every read is bounds-checked (the bytes are outside data). Messages start
 * "name: ". */
sinew_result sw_gltf_float_attribute(const void *data, size_t len, int binary, const char *dir,
                                     const char *attr, const char *name, int32_t nprims,
                                     const int32_t *prim_verts, const float *const *prim_xyz,
                                     double **out, sw_error *err);

#endif
