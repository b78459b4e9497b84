/* For scene_read.c and the viewer's asset import (samples/viewer/asset.c): the glTF
 * structures that assimp 5.2.5 crashes on, rejected before assimp reads the bytes
 * (gltf_precheck.c says which and why). */
#ifndef SW_GLTF_PRECHECK_H
#define SW_GLTF_PRECHECK_H

#include <stddef.h>

#include "sw_error.h"

/* Checks a .glb (`binary` 1) or .gltf (0) held in `len` bytes: SINEW_ERROR_PARSE when they
 * are not one, or hold a structure assimp 5.2.5 cannot read safely. Messages start
 * "name: ". */
sinew_result sw_gltf_precheck(const void *data, size_t len, int binary, const char *name,
                              sw_error *err);

#endif
