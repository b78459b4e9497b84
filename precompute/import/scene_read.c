/* A rigged character file read (scene_import.h's entry points): the options checked, a
 * glTF's structure checked before assimp sees it (gltf_precheck.h), assimp's trial read in
 * a child process (assimp_trial.h), then assimp's import, which scene_import.c turns into
 * the character (sw_scene_build). */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "assimp_trial.h"
#include "gltf_precheck.h"
#include "scene_internal.h"

/* 1 when `ext` is "glb" (any case). */
static int is_glb(const char *ext) {
    return ext && strlen(ext) == 3 && tolower((unsigned char)ext[0]) == 'g' &&
           tolower((unsigned char)ext[1]) == 'l' && tolower((unsigned char)ext[2]) == 'b';
}

/* 1 when `ext` names glTF ("gltf" or "glb", any case). */
static int is_gltf_ext(const char *ext) {
    char e[8] = {0};
    for (size_t i = 0; ext && ext[i] && i < sizeof e - 1; ++i)
        e[i] = (char)tolower((unsigned char)ext[i]);
    return !strcmp(e, "gltf") || !strcmp(e, "glb");
}

/* Triangulate; ValidateDataStructure rejects out-of-range indices and broken trees. glTF
 * keeps its own vertices (the file's counts); FBX, which assimp unrolls into one vertex
 * per face corner, gets them welded back (a connected surface for the simulation). */
static unsigned ai_flags(int gltf) {
    unsigned f = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
    return gltf ? f : f | aiProcess_JoinIdenticalVertices;
}

static sinew_result check_options(const sw_import_options *o, const char *name,
                                  sw_import_options *use, sw_error *err) {
    sw_import_options d = {0};
    if (o) d = *o;
    if (d.fps == 0) d.fps = 30;
    if (!(d.fps > 0 && d.fps <= 10000) || !(d.target_height >= 0 && d.target_height < 1e6))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: fps %g (0 or (0, 10000]) or target_height %g (>= 0) out of range",
                            name, d.fps, d.target_height);
    *use = d;
    return SINEW_OK;
}

/* sw_gltf_precheck over a whole glTF file (at most 1 GiB), read into *bytes (the caller
 * frees it) for what assimp drops. */
static sinew_result precheck_file(FILE *f, int binary, const char *name, char **bytes,
                                  size_t *nbytes, sw_error *err) {
    if (fseek(f, 0, SEEK_END) != 0)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot seek", name);
    long n = ftell(f);
    if (n < 0 || n > (1L << 30) || fseek(f, 0, SEEK_SET) != 0)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot size (or larger than 1 GiB)", name);
    char *buf = malloc(n ? (size_t)n : 1);
    if (!buf) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    sinew_result rc = fread(buf, 1, (size_t)n, f) == (size_t)n
                          ? sw_gltf_precheck(buf, (size_t)n, binary, name, err)
                          : sw_error_set(err, SINEW_ERROR_IO, "%s: cannot read", name);
    if (rc) {
        free(buf);
        return rc;
    }
    *bytes = buf, *nbytes = (size_t)n;
    return SINEW_OK;
}

sinew_result sw_scene_import(const char *path, const sw_import_options *o,
                             sw_imported_character *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    sw_import_options use;
    const char *name = path ? path : "(null)";
    sinew_result rc = check_options(o, name, &use, err);
    if (rc) return rc;
    FILE *f = path ? fopen(path, "rb") : NULL;
    if (!f) /* the system's reason (a missing file: "No such file or directory") */
        return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open: %s", name,
                            strerror(path ? errno : EINVAL));
    const char *dot = strrchr(path, '.');
    int gltf = is_gltf_ext(dot ? dot + 1 : NULL), binary = gltf && is_glb(dot + 1);
    char *bytes = NULL;
    size_t nbytes = 0;
    rc = gltf ? precheck_file(f, binary, name, &bytes, &nbytes, err) : SINEW_OK;
    fclose(f);
    if (rc) return rc;
    const char *slash = strrchr(path, '/');
    char *dir = slash ? strndup(path, (size_t)(slash - path + (slash == path))) : strdup(".");
    if (!dir) {
        free(bytes);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    rc = sw_assimp_trial(path, NULL, 0, NULL, ai_flags(gltf), SW_ASSIMP_TRIAL_SECONDS, name, err);
    if (rc == SINEW_OK)
        rc = sw_scene_build(aiImportFile(path, ai_flags(gltf)), name, bytes, nbytes, binary, dir,
                            &use, out, err);
    free(bytes);
    free(dir);
    return rc;
}

sinew_result sw_scene_import_memory(const void *data, size_t len, const char *hint,
                                    const sw_import_options *o, sw_imported_character *out,
                                    sw_error *err) {
    memset(out, 0, sizeof *out);
    char name[32];
    snprintf(name, sizeof name, "memory.%s", hint ? hint : "");
    sw_import_options use;
    sinew_result rc = check_options(o, name, &use, err);
    if (rc) return rc;
    if (!data || len == 0 || len > 0xffffffffu)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: %zu bytes: nothing to read", name, len);
    int gltf = is_gltf_ext(hint);
    if (gltf && (rc = sw_gltf_precheck(data, len, is_glb(hint), name, err))) return rc;
    /* A copy with zero bytes after it: some assimp 5.2.5 readers strlen the buffer. */
    char *copy = malloc(len + 16);
    if (!copy) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    memcpy(copy, data, len);
    memset(copy + len, 0, 16);
    rc = sw_assimp_trial(NULL, copy, len, hint, ai_flags(gltf), SW_ASSIMP_TRIAL_SECONDS, name, err);
    if (rc == SINEW_OK)
        rc = sw_scene_build(
            aiImportFileFromMemory(copy, (unsigned)len, ai_flags(gltf), hint ? hint : ""), name,
            gltf ? data : NULL, len, is_glb(hint), NULL, &use, out, err);
    free(copy);
    return rc;
}
