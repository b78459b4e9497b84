/* The motion formats of ../shared/data, read into bone-transform clips. */
#ifndef SW_CLIP_IO_H
#define SW_CLIP_IO_H

#include <stddef.h>

#include "sw_mesh.h"

/* Complementary-dynamics bone animation (elephant-cd/elephant_anim.txt; format in its
 * SOURCE.md): per-frame Euler angles per bone -> per-frame bone transforms (rest ->
 * world) for skeleton `s`. */
sinew_result sw_read_cd_anim(const char *path, const sw_skeleton *s, double fps, sw_clip *out,
                             sw_error *err);
/* The same from `len` bytes in memory (copied; no NUL needed), named `name_for_errors` in
 * messages (NULL: "<text>"). */
sinew_result sw_parse_cd_anim(const char *text, size_t len, const char *name_for_errors,
                              const sw_skeleton *s, double fps, sw_clip *out, sw_error *err);

#endif
