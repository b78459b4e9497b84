/* For scene_read.c and the viewer's asset import (samples/viewer/asset.c): assimp read in
 * a child process first, so that a file it dies on is refused instead of taking the bake or
 * the host with it.
 *
 * Debian's assimp 5.2.5 aborts on some damaged files that it does not reject: one flipped
 * bit in a small binary FBX trips an ai_assert in its FBX converter (tests/fuzz, the
 * corpus entry fbx_assert.fbx), and a glTF structure check (gltf_precheck.h) can only name
 * the crashes it knows. A child that returns, with a scene or without one, says the parent
 * can read the same bytes with the same flags safely: assimp's import is a pure function
 * of them. */
#ifndef SW_ASSIMP_TRIAL_H
#define SW_ASSIMP_TRIAL_H

#include <stddef.h>

#include "sw_error.h"

/* The time a trial read may take (seconds): a file assimp loops on is refused too. Ten
 * minutes: far beyond what a character of any size takes to import. */
#define SW_ASSIMP_TRIAL_SECONDS 600.0

/* Reads the file at `path` (data NULL), or the `len` bytes at `data` as a `hint` file
 * (path NULL; the bytes followed by a zero, as aiImportFileFromMemory wants them), with
 * assimp's post-processing `flags`, in a child process given `seconds` (> 0). SINEW_OK
 * when the child returned; SINEW_ERROR_PARSE when it died or ran out of time (the signal
 * and assimp's last line on stderr in the message, which starts "name: "); SINEW_ERROR_IO
 * when no child could be started. */
sinew_result sw_assimp_trial(const char *path, const void *data, size_t len, const char *hint,
                             unsigned flags, double seconds, const char *name, sw_error *err);

#endif
