/* A glTF 2.0 structure check run before assimp sees the bytes (gltf_precheck.h). assimp
 * 5.2.5 (Debian 12) dereferences NULL or reads past arrays on some malformed skins and
 * node graphs instead of rejecting them; fuzz_scene_import found these, and upstream
 * fixed them only in later releases:
 *  - a skin without inverseBindMatrices (optional in glTF 2.0; assimp's issue tracker, #3465),
 *  - an inverseBindMatrices accessor that is not MAT4 floats, one per joint (#6612),
 *  - a node graph that is not a forest (a node that is a child twice, a child and a scene
 *    root, or its own ancestor),
 *  - an index that points past its array (a node's mesh or skin, a skin's joint, a
 *    primitive's accessor, an accessor's buffer view, a view's buffer, an animation
 *    channel's sampler or target node, a sampler's accessors), or a channel without a
 *    target (a node's skin naming a skin that is not there crashed it: fuzz_scene_import,
 *    2026-12-03).
 * The bytes must also be what the name says (a .glb starts with "glTF", a .gltf with '{'):
 * otherwise assimp tries its other readers on them, some of which read past the buffer
 * (fuzz_scene_import: strlen over unterminated bytes) or allocate what a header claims.
 * Everything else is left to assimp's own checks. */
#include <cjson/cJSON.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_precheck.h"

static uint32_t le32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The integer item `key` of object o in [0, n), or -1. */
static int index_of(const cJSON *o, const char *key, int n) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble >= n ||
        v->valuedouble != (double)(int)v->valuedouble)
        return -1;
    return (int)v->valuedouble;
}

/* The length of root's array `key` (0 when absent). */
static int count_of(const cJSON *root, const char *key) {
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(root, key);
    return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0;
}

/* Item `key` of o is absent (and not required) or an index in [0, n). */
static int ref_ok(const cJSON *o, const char *key, int n, int required) {
    if (!cJSON_GetObjectItemCaseSensitive(o, key)) return !required;
    return index_of(o, key, n) >= 0;
}

/* Every element of the array `key` of o is an index in [0, n). */
static int refs_ok(const cJSON *o, const char *key, int n) {
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(o, key)) {
        if (!cJSON_IsNumber(e) || e->valuedouble < 0 || e->valuedouble >= n ||
            e->valuedouble != (double)(int)e->valuedouble)
            return 0;
    }
    return 1;
}

#define BAD_REF(what, i)                                                                           \
    sw_error_set(err, SINEW_ERROR_PARSE, "%s: %s %d: an index out of range or missing", name,      \
                 what, (int)(i))

/* Every index the document holds in range of the array it points into. */
static sinew_result check_references(const cJSON *root, const char *name, sw_error *err) {
    const int nnode = count_of(root, "nodes"), nmesh = count_of(root, "meshes"),
              nskin = count_of(root, "skins"), nacc = count_of(root, "accessors"),
              nview = count_of(root, "bufferViews"), nbuf = count_of(root, "buffers"),
              nscene = count_of(root, "scenes"), nmat = count_of(root, "materials");
    const cJSON *o, *p, *a;
    int i = 0;
    if (!ref_ok(root, "scene", nscene, 0)) return BAD_REF("scene", 0);
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "scenes")) {
        if (!refs_ok(o, "nodes", nnode)) return BAD_REF("scene", i);
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "nodes")) {
        if (!ref_ok(o, "mesh", nmesh, 0) || !ref_ok(o, "skin", nskin, 0)) return BAD_REF("node", i);
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "skins")) {
        if (!refs_ok(o, "joints", nnode) || !ref_ok(o, "skeleton", nnode, 0))
            return BAD_REF("skin", i);
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "meshes")) {
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(o, "primitives")) {
            const cJSON *attr = cJSON_GetObjectItemCaseSensitive(p, "attributes");
            if (!cJSON_IsObject(attr) || !ref_ok(p, "indices", nacc, 0) ||
                !ref_ok(p, "material", nmat, 0))
                return BAD_REF("mesh", i);
            cJSON_ArrayForEach(a, attr) {
                if (!cJSON_IsNumber(a) || a->valuedouble < 0 || a->valuedouble >= nacc ||
                    a->valuedouble != (double)(int)a->valuedouble)
                    return BAD_REF("mesh", i);
            }
        }
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "accessors")) {
        if (!ref_ok(o, "bufferView", nview, 0)) return BAD_REF("accessor", i);
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "bufferViews")) {
        if (!ref_ok(o, "buffer", nbuf, 1)) return BAD_REF("buffer view", i);
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(o, cJSON_GetObjectItemCaseSensitive(root, "animations")) {
        int nsamp = count_of(o, "samplers");
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(o, "channels")) {
            const cJSON *target = cJSON_GetObjectItemCaseSensitive(p, "target");
            if (!ref_ok(p, "sampler", nsamp, 1) || !cJSON_IsObject(target) ||
                !ref_ok(target, "node", nnode, 0))
                return BAD_REF("animation", i);
        }
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(o, "samplers")) {
            if (!ref_ok(p, "input", nacc, 1) || !ref_ok(p, "output", nacc, 1))
                return BAD_REF("animation", i);
        }
        i++;
    }
    return SINEW_OK;
}

static sinew_result check_skins(const cJSON *root, const char *name, sw_error *err) {
    const cJSON *skins = cJSON_GetObjectItemCaseSensitive(root, "skins");
    const cJSON *acc = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    int nacc = cJSON_IsArray(acc) ? cJSON_GetArraySize(acc) : 0;
    int s = 0;
    const cJSON *skin;
    cJSON_ArrayForEach(skin, skins) {
        const cJSON *joints = cJSON_GetObjectItemCaseSensitive(skin, "joints");
        int a = index_of(skin, "inverseBindMatrices", nacc);
        if (a < 0)
            return sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                                "%s: skin %d has no valid inverseBindMatrices accessor (assimp "
                                "5.2.5 cannot read such skins)",
                                name, s);
        const cJSON *ac = cJSON_GetArrayItem(acc, a);
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(ac, "type");
        const cJSON *comp = cJSON_GetObjectItemCaseSensitive(ac, "componentType");
        const cJSON *count = cJSON_GetObjectItemCaseSensitive(ac, "count");
        if (!cJSON_IsString(type) || strcmp(type->valuestring, "MAT4") || !cJSON_IsNumber(comp) ||
            comp->valuedouble != 5126 || !cJSON_IsNumber(count) || !cJSON_IsArray(joints) ||
            count->valuedouble < cJSON_GetArraySize(joints))
            return sw_error_set(err, SINEW_ERROR_PARSE,
                                "%s: skin %d: inverseBindMatrices must be MAT4 floats, one per "
                                "joint",
                                name, s);
        s++;
    }
    return SINEW_OK;
}

/* Every child index in range, no node a child twice, and no cycle: with each node having at
 * most one parent, a walk up from any node ends within nnodes steps. */
static sinew_result check_nodes(const cJSON *root, const char *name, sw_error *err) {
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    int n = cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0;
    if (n == 0) return SINEW_OK;
    int *parent = malloc(sizeof(int) * (size_t)n);
    if (!parent) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    for (int i = 0; i < n; ++i)
        parent[i] = -1;
    sinew_result rc = SINEW_OK;
    const cJSON *scene, *r;
    cJSON_ArrayForEach(scene, cJSON_GetObjectItemCaseSensitive(root, "scenes")) {
        cJSON_ArrayForEach(r, cJSON_GetObjectItemCaseSensitive(scene, "nodes")) {
            int k = cJSON_IsNumber(r) && r->valuedouble >= 0 && r->valuedouble < n
                        ? (int)r->valuedouble
                        : -1;
            if (k >= 0) parent[k] = -2; /* a scene's root (several scenes may share it) */
        }
    }
    int i = 0;
    const cJSON *node;
    cJSON_ArrayForEach(node, nodes) {
        const cJSON *c;
        cJSON_ArrayForEach(c, cJSON_GetObjectItemCaseSensitive(node, "children")) {
            int k = cJSON_IsNumber(c) && c->valuedouble >= 0 && c->valuedouble < n
                        ? (int)c->valuedouble
                        : -1;
            if (k < 0 || parent[k] != -1 || k == i) {
                rc = sw_error_set(err, SINEW_ERROR_PARSE,
                                  "%s: node %d: a child out of range, with two parents or a "
                                  "scene root",
                                  name, i);
                goto done;
            }
            parent[k] = i;
        }
        i++;
    }
    for (int k = 0; k < n; ++k) {
        int steps = 0;
        for (int p = parent[k]; p >= 0 && steps <= n; p = parent[p])
            steps++;
        if (steps > n) {
            rc = sw_error_set(err, SINEW_ERROR_PARSE, "%s: node %d is its own ancestor", name, k);
            goto done;
        }
    }
done:
    free(parent);
    return rc;
}

sinew_result sw_gltf_precheck(const void *data, size_t len, int binary, const char *name,
                              sw_error *err) {
    const unsigned char *b = data;
    const char *json = data;
    size_t jlen = len, k = 0;
    while (k < len && (b[k] == ' ' || b[k] == '\t' || b[k] == '\n' || b[k] == '\r'))
        k++;
    if (binary ? len < 4 || memcmp(b, "glTF", 4) : k == len || b[k] != '{')
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: not a glTF %s", name,
                            binary ? "binary (no 'glTF' magic)" : "JSON file (no '{')");
    if (binary) { /* 12-byte header, then the JSON chunk */
        if (len < 20 || le32(b + 4) != 2 || le32(b + 8) > len || le32(b + 16) != 0x4E4F534Au ||
            le32(b + 12) > len - 20)
            return sw_error_set(err, SINEW_ERROR_PARSE,
                                "%s: not a glTF 2.0 binary (bad header or JSON chunk)", name);
        json = (const char *)b + 20;
        jlen = le32(b + 12);
    }
    cJSON *root = cJSON_ParseWithLength(json, jlen);
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: the glTF JSON does not parse", name);
    }
    sinew_result rc = check_references(root, name, err);
    if (!rc) rc = check_skins(root, name, err);
    if (!rc) rc = check_nodes(root, name, err);
    cJSON_Delete(root);
    return rc;
}
