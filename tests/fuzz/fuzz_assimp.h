/* For the harnesses that read through assimp (fuzz_scene_import.c, fuzz_view_asset.c),
 * included by each once.
 *
 * Debian's assimp 5.2.5 leaks a few objects of its own (allocated by operator new inside
 * libassimp) on some malformed glTF inputs. Only leaks whose allocation stack passes through
 * libassimp are suppressed; a leak of the importer's own malloc calls is still found. assimp
 * is built without frame pointers, so the fast unwinder stops at operator new and the stack
 * never shows libassimp (CI found such a leak reported as ours): unwind slowly instead. Both
 * live here, not in the environment, so ctest and tools/scripts/run-fuzz.sh run the
 * harnesses alike. */
#ifndef SW_FUZZ_ASSIMP_H
#define SW_FUZZ_ASSIMP_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

const char *__asan_default_options(void);
const char *__lsan_default_suppressions(void);

const char *__asan_default_options(void) {
    return "fast_unwind_on_malloc=0";
}
const char *__lsan_default_suppressions(void) {
    return "leak:libassimp.so\n";
}

/* The format the input claims, for assimp's hint and the file's extension: FBX (binary,
 * or ASCII with its header comment) or else glTF's binary container. The seeds of both
 * formats sit in one corpus, and their mutations keep their first bytes most of the time. */
static inline const char *sw_fuzz_assimp_hint(const uint8_t *data, size_t size) {
    static const char bin[] = "Kaydara FBX Binary", text[] = "; FBX";
    if ((size >= sizeof bin - 1 && !memcmp(data, bin, sizeof bin - 1)) ||
        (size >= sizeof text - 1 && !memcmp(data, text, sizeof text - 1)))
        return "fbx";
    return "glb";
}

#endif
