/* A glTF 2.0 structure check run before assimp sees the bytes (gltf_precheck.h). assimp
 * 5.2.5 (Debian 12) dereferences NULL or reads past arrays on some malformed skins and
 * node graphs instead of rejecting them; fuzz_scene_import found these, and upstream
 * fixed them only in later releases:
 *  - a skin without inverseBindMatrices (optional in glTF 2.0; assimp issue #3465),
 *  - an inverseBindMatrices accessor that is not MAT4 floats, one per joint (#6612),
 *  - a node graph that is not a forest (a node that is a child twice, a child and a scene
 *    root, or its own ancestor).
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
    sinew_result rc = check_skins(root, name, err);
    if (!rc) rc = check_nodes(root, name, err);
    cJSON_Delete(root);
    return rc;
}
