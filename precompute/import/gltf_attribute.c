/* A custom glTF vertex attribute read from the file's bytes (gltf_attribute.h).
 *
 * Which aiMesh is which primitive. assimp 5.2.5 makes one aiMesh per primitive, mesh by
 * mesh, but its meshes come in the order its lazy dictionary first *loads* them, not the
 * file's order: the default scene's root nodes depth-first with a node's children read
 * before its own mesh, then every skin's joints (a node only names its skin, to avoid a
 * recursion), then every animation channel's target node; a mesh no node reaches is not
 * imported. (Checked against assimp 5.2.5 on hand-written files where the file order and
 * that order differ, a skin's joints reaching a mesh first, and on the robot's 14 meshes
 * of 1 to 3 primitives.) load_order()
 * replays this; the vertex counts, and the positions when given, confirm it.
 * A primitive's vertices are the POSITION accessor's, in its order (5.2.5 keeps unused
 * vertices and does not reorder by the indices).
 *
 * Everything here is outside data: every index is checked against its array, every
 * offset, stride and count against the bytes that hold them. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_attribute.h"

#define GLTF_MAX_BYTES ((uint64_t)1 << 40) /* any offset or length larger is refused */
#define GLTF_VALUE_MAX 1e6

typedef struct gltf_doc {
    const cJSON *root;
    const unsigned char *bin; /* the GLB's BIN chunk, or NULL */
    size_t nbin;
    int binary;
    const char *dir; /* the folder of a .gltf's buffer files, or NULL (bytes in memory) */
    int nbuf;
    unsigned char **decoded; /* per buffer: its data: URI decoded or its file read, once */
    size_t *ndecoded;
    const char *name;
    sw_error *err;
} gltf_doc;

static uint32_t le32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The integer v in [0, n), or -1. */
static int index_in(const cJSON *v, int n) {
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0) || v->valuedouble >= n ||
        v->valuedouble != floor(v->valuedouble))
        return -1;
    return (int)v->valuedouble;
}

static int index_of(const cJSON *o, const char *key, int n) {
    return index_in(cJSON_GetObjectItemCaseSensitive(o, key), n);
}

static int count_of(const cJSON *o, const char *key) {
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0;
}

/* Item `key` of o as a byte count or offset: `dflt` when absent, -1 when not an integer in
 * [0, GLTF_MAX_BYTES]. */
static int64_t bytes_of(const cJSON *o, const char *key, int64_t dflt) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return dflt;
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0) || v->valuedouble > (double)GLTF_MAX_BYTES ||
        v->valuedouble != floor(v->valuedouble))
        return -1;
    return (int64_t)v->valuedouble;
}

/* The JSON and, for a GLB, its BIN chunk (chunk layout as gltf_precheck.c reads it). */
static int split_glb(const unsigned char *b, size_t len, const char **json, size_t *jlen,
                     const unsigned char **bin, size_t *nbin) {
    *bin = NULL, *nbin = 0;
    if (len < 20 || memcmp(b, "glTF", 4) || le32(b + 16) != 0x4E4F534Au || le32(b + 12) > len - 20)
        return 0;
    *json = (const char *)b + 20;
    *jlen = le32(b + 12);
    size_t at = 20 + (size_t)*jlen;
    at += (4 - at % 4) % 4; /* chunks are 4-byte aligned */
    if (at <= len && len - at >= 8 && le32(b + at + 4) == 0x004E4942u &&
        le32(b + at) <= len - at - 8) {
        *bin = b + at + 8;
        *nbin = le32(b + at);
    }
    return 1;
}

static int b64_value(unsigned char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
}

/* Decodes base64 text (padding optional) into a new buffer; NULL on a bad character or
 * no memory (*bad tells which). */
static unsigned char *b64_decode(const char *s, size_t n, size_t *out_n, int *bad) {
    while (n > 0 && s[n - 1] == '=')
        n--;
    unsigned char *o = malloc(n / 4 * 3 + 3);
    *bad = 0;
    if (!o) return NULL;
    size_t k = 0;
    uint32_t acc = 0;
    for (size_t i = 0; i < n; ++i) {
        int v = b64_value((unsigned char)s[i]);
        if (v < 0) {
            free(o);
            *bad = 1;
            return NULL;
        }
        acc = acc << 6 | (uint32_t)v;
        if (i % 4 == 3) {
            o[k++] = (unsigned char)(acc >> 16), o[k++] = (unsigned char)(acc >> 8);
            o[k++] = (unsigned char)acc, acc = 0;
        }
    }
    if (n % 4 == 1) {
        free(o);
        *bad = 1;
        return NULL;
    }
    if (n % 4 == 2) o[k++] = (unsigned char)(acc >> 4);
    if (n % 4 == 3) o[k++] = (unsigned char)(acc >> 10), o[k++] = (unsigned char)(acc >> 2);
    *out_n = k;
    return o;
}

/* The file `uri` in the folder `dir`, whole, into a new buffer. The uri is taken as it is,
 * as assimp 5.2.5 takes it (it does not decode percent-escapes): the same file. */
static sinew_result read_buffer_file(gltf_doc *d, int b, const char *uri, unsigned char **out,
                                     size_t *n) {
    const size_t np = strlen(d->dir) + strlen(uri) + 2;
    char *path = malloc(np);
    if (!path) return sw_error_set(d->err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", d->name);
    snprintf(path, np, "%s/%s", d->dir, uri);
    FILE *f = fopen(path, "rb");
    long len = -1;
    if (f && fseek(f, 0, SEEK_END) == 0) len = ftell(f);
    *out = f && len >= 0 && len <= (1L << 30) && fseek(f, 0, SEEK_SET) == 0
               ? malloc(len ? (size_t)len : 1)
               : NULL;
    sinew_result rc = SINEW_OK;
    if (!*out || fread(*out, 1, (size_t)len, f) != (size_t)len) {
        rc =
            sw_error_set(d->err, SINEW_ERROR_IO, "%s: buffer %d: cannot read %s", d->name, b, path);
        free(*out);
        *out = NULL;
    }
    *n = (size_t)(len > 0 ? len : 0);
    if (f) fclose(f);
    free(path);
    return rc;
}

/* Buffer b's bytes: the BIN chunk (a GLB's buffer 0 without uri), its base64 data: URI, or
 * the file its relative uri names beside the .gltf. */
static sinew_result buffer_bytes(gltf_doc *d, int b, const unsigned char **p, size_t *n) {
    const cJSON *buf = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(d->root, "buffers"), b);
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(buf, "uri");
    if (!uri) {
        if (!d->binary || b != 0 || !d->bin)
            return sw_error_set(d->err, SINEW_ERROR_PARSE,
                                "%s: buffer %d has no uri and is not a GLB's BIN chunk", d->name,
                                b);
        *p = d->bin, *n = d->nbin;
        return SINEW_OK;
    }
    if (d->decoded[b]) {
        *p = d->decoded[b], *n = d->ndecoded[b];
        return SINEW_OK;
    }
    const char *s = cJSON_IsString(uri) ? uri->valuestring : NULL;
    if (s && d->dir && strncmp(s, "data:", 5) && !strchr(s, ':') && s[0] != '/' && s[0]) {
        sinew_result rc = read_buffer_file(d, b, s, &d->decoded[b], &d->ndecoded[b]);
        if (!rc) *p = d->decoded[b], *n = d->ndecoded[b];
        return rc;
    }
    const char *comma = s && !strncmp(s, "data:", 5) ? strchr(s, ',') : NULL;
    if (!comma || comma - s < 12 || memcmp(comma - 7, ";base64", 7))
        return sw_error_set(d->err, SINEW_ERROR_UNSUPPORTED,
                            "%s: buffer %d: a vertex attribute is read from the GLB's BIN chunk, "
                            "a base64 data: URI or a file beside a .gltf read from a path",
                            d->name, b);
    int bad = 0;
    d->decoded[b] = b64_decode(comma + 1, strlen(comma + 1), &d->ndecoded[b], &bad);
    if (!d->decoded[b])
        return bad ? sw_error_set(d->err, SINEW_ERROR_PARSE, "%s: buffer %d: bad base64", d->name,
                                  b)
                   : sw_error_set(d->err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", d->name);
    *p = d->decoded[b], *n = d->ndecoded[b];
    return SINEW_OK;
}

#define BAD_ACCESSOR(code, ...) sw_error_set(d->err, code, "%s: accessor %d (%s): " __VA_ARGS__)

/* Accessor a as `count` elements of `type` (ncomp components), converted to doubles in dst;
 * FLOAT, or (norm) normalized UNSIGNED_BYTE/SHORT. `what` names it in messages. */
static sinew_result read_accessor(gltf_doc *d, int a, int64_t count, const char *type, int ncomp,
                                  int norm, const char *what, double *dst) {
    const cJSON *acc =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(d->root, "accessors"), a);
    const cJSON *ty = cJSON_GetObjectItemCaseSensitive(acc, "type");
    const cJSON *ct = cJSON_GetObjectItemCaseSensitive(acc, "componentType");
    const cJSON *nm = cJSON_GetObjectItemCaseSensitive(acc, "normalized");
    const double c = cJSON_IsNumber(ct) ? ct->valuedouble : 0;
    const int csize = c == 5126                    ? 4
                      : !norm || !cJSON_IsTrue(nm) ? 0
                      : c == 5121                  ? 1
                      : c == 5123                  ? 2
                                                   : 0;
    if (cJSON_GetObjectItemCaseSensitive(acc, "sparse"))
        return BAD_ACCESSOR(SINEW_ERROR_UNSUPPORTED, "a sparse accessor is not read", d->name, a,
                            what);
    if (!cJSON_IsString(ty) || strcmp(ty->valuestring, type) || !csize)
        return BAD_ACCESSOR(SINEW_ERROR_PARSE, "must be %s FLOAT%s", d->name, a, what, type,
                            norm ? " (or normalized UNSIGNED_BYTE/SHORT)" : "");
    if (bytes_of(acc, "count", -1) != count)
        return BAD_ACCESSOR(SINEW_ERROR_PARSE, "count must be %lld, the primitive's vertices",
                            d->name, a, what, (long long)count);
    const int v = index_of(acc, "bufferView", count_of(d->root, "bufferViews"));
    const cJSON *view =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(d->root, "bufferViews"), v);
    const int b = index_of(view, "buffer", count_of(d->root, "buffers"));
    const int64_t elem = (int64_t)ncomp * csize, aoff = bytes_of(acc, "byteOffset", 0),
                  voff = bytes_of(view, "byteOffset", 0), vlen = bytes_of(view, "byteLength", -1),
                  stride = bytes_of(view, "byteStride", elem);
    if (v < 0 || b < 0 || aoff < 0 || voff < 0 || vlen < 0 || stride < elem || stride > 252)
        return BAD_ACCESSOR(SINEW_ERROR_PARSE,
                            "its buffer view, buffer, offset, length or stride is missing or out "
                            "of range",
                            d->name, a, what);
    if (count > 0 && aoff + stride * (count - 1) + elem > vlen)
        return BAD_ACCESSOR(SINEW_ERROR_PARSE,
                            "%lld elements from byte %lld overrun its view of %lld", d->name, a,
                            what, (long long)count, (long long)aoff, (long long)vlen);
    const unsigned char *p = NULL;
    size_t n = 0;
    sinew_result rc = buffer_bytes(d, b, &p, &n);
    if (rc) return rc;
    if ((uint64_t)(voff + vlen) > n)
        return BAD_ACCESSOR(SINEW_ERROR_PARSE,
                            "buffer view %d (bytes %lld..%lld) overruns buffer %d "
                            "(%zu bytes)",
                            d->name, a, what, v, (long long)voff, (long long)(voff + vlen), b, n);
    for (int64_t i = 0; i < count; ++i)
        for (int k = 0; k < ncomp; ++k) {
            const unsigned char *e = p + voff + aoff + stride * i + (int64_t)csize * k;
            double x;
            if (csize == 4) {
                uint32_t u = le32(e);
                float f;
                memcpy(&f, &u, sizeof f);
                x = f;
            } else {
                x = csize == 1 ? e[0] / 255.0 : (double)(e[0] | e[1] << 8) / 65535.0;
            }
            dst[ncomp * i + k] = x;
        }
    return SINEW_OK;
}

/* A node or skin being read, and where in its children or joints. */
typedef struct load_frame {
    int skin; /* 0: a node, 1: a skin */
    int idx, i;
} load_frame;

/* Pushes node/skin idx when it has not been read (state 0); state 1: being read, 2: read. */
static void load_push(load_frame *st, int *sp, unsigned char *state, int skin, int idx) {
    if (idx < 0 || state[idx]) return;
    state[idx] = 1;
    st[(*sp)++] = (load_frame){skin, idx, 0};
}

/* Runs the stack down: assimp's Node::Read (its children, then its mesh; its skin only
 * named, read later) and Skin::Read (its joints), appending each mesh to `order` the first
 * time one is read. */
static void load_run(const cJSON *root, load_frame *st, int *sp, unsigned char *nstate,
                     unsigned char *mseen, int *order, int *norder) {
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    const cJSON *skins = cJSON_GetObjectItemCaseSensitive(root, "skins");
    const int nnode = count_of(root, "nodes"), nmesh = count_of(root, "meshes");
    while (*sp > 0) {
        load_frame *f = &st[*sp - 1];
        const cJSON *o = cJSON_GetArrayItem(f->skin ? skins : nodes, f->idx);
        const cJSON *list = cJSON_GetObjectItemCaseSensitive(o, f->skin ? "joints" : "children");
        if (cJSON_IsArray(list) && f->i < cJSON_GetArraySize(list)) {
            load_push(st, sp, nstate, 0, index_in(cJSON_GetArrayItem(list, f->i++), nnode));
            continue;
        }
        if (!f->skin) {
            int m = index_of(o, "mesh", nmesh);
            if (m >= 0 && !mseen[m]) mseen[m] = 1, order[(*norder)++] = m;
            nstate[f->idx] = 2;
        }
        (*sp)--;
    }
}

/* The meshes in the order assimp 5.2.5 loads them (see the top of the file); *norder of
 * them. order holds nmesh ints. */
static sinew_result load_order(const cJSON *root, int *order, int *norder, const char *name,
                               sw_error *err) {
    const int nnode = count_of(root, "nodes"), nskin = count_of(root, "skins"),
              nmesh = count_of(root, "meshes");
    load_frame *st = malloc(sizeof *st * ((size_t)nnode + (size_t)nskin + 1));
    unsigned char *nstate = calloc((size_t)nnode + 1, 1), *sstate = calloc((size_t)nskin + 1, 1),
                  *mseen = calloc((size_t)nmesh + 1, 1);
    sinew_result rc = SINEW_OK;
    *norder = 0;
    if (!st || !nstate || !sstate || !mseen) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
        goto done;
    }
    int sp = 0;
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(root, "scene");
    const int s = sc ? index_in(sc, count_of(root, "scenes")) : count_of(root, "scenes") ? 0 : -1;
    const cJSON *e, *a;
    if (s >= 0)
        cJSON_ArrayForEach(
            e,
            cJSON_GetObjectItemCaseSensitive(
                cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "scenes"), s), "nodes")) {
            load_push(st, &sp, nstate, 0, index_in(e, nnode));
            load_run(root, st, &sp, nstate, mseen, order, norder);
        }
    for (int k = 0; k < nskin; ++k) {
        load_push(st, &sp, sstate, 1, k);
        load_run(root, st, &sp, nstate, mseen, order, norder);
    }
    cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(root, "animations")) {
        cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(a, "channels")) {
            const cJSON *t = cJSON_GetObjectItemCaseSensitive(e, "target");
            load_push(st, &sp, nstate, 0, index_of(t, "node", nnode));
            load_run(root, st, &sp, nstate, mseen, order, norder);
        }
    }
done:
    free(st);
    free(nstate);
    free(sstate);
    free(mseen);
    return rc;
}

/* Primitive k (mesh m's p-th) against assimp's mesh k: the same vertex count and, when
 * given, the same positions. */
static sinew_result match_primitive(gltf_doc *d, const cJSON *prim, int m, int p, int k, int32_t nv,
                                    const float *xyz, double *scratch) {
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    const int pa = index_of(attrs, "POSITION", count_of(d->root, "accessors"));
    const cJSON *acc =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(d->root, "accessors"), pa);
    if (pa < 0 || bytes_of(acc, "count", -1) != nv)
        return sw_error_set(d->err, SINEW_ERROR_UNSUPPORTED,
                            "%s: mesh %d primitive %d does not match assimp's mesh %d (%d "
                            "vertices): cannot place its vertex attributes",
                            d->name, m, p, k, (int)nv);
    if (!xyz) return SINEW_OK;
    sinew_result rc = read_accessor(d, pa, nv, "VEC3", 3, 0, "POSITION", scratch);
    if (rc) return rc;
    for (int64_t i = 0; i < 3 * (int64_t)nv; ++i)
        if (scratch[i] != (double)xyz[i] && !(isnan(scratch[i]) && isnan(xyz[i])))
            return sw_error_set(d->err, SINEW_ERROR_UNSUPPORTED,
                                "%s: mesh %d primitive %d: its positions are not assimp's mesh "
                                "%d's (vertex %lld): cannot place its vertex attributes",
                                d->name, m, p, k, (long long)(i / 3));
    return SINEW_OK;
}

/* Fills vals (prim_verts[k] values) from primitive k's attribute, checking each value. */
static sinew_result read_values(gltf_doc *d, int acc, int m, int p, int32_t nv, const char *attr,
                                double *vals) {
    sinew_result rc = read_accessor(d, acc, nv, "SCALAR", 1, 1, attr, vals);
    for (int32_t i = 0; i < nv && !rc; ++i)
        if (!(isfinite(vals[i]) && vals[i] > 0 && vals[i] <= GLTF_VALUE_MAX))
            rc = sw_error_set(d->err, SINEW_ERROR_INVALID_ARGUMENT,
                              "%s: mesh %d primitive %d vertex %d: %s = %g (must be finite, > 0 "
                              "and <= %g)",
                              d->name, m, p, (int)i, attr, vals[i], GLTF_VALUE_MAX);
    return rc;
}

/* Walks the loaded meshes' primitives (k counts them) against assimp's meshes. */
static sinew_result read_all(gltf_doc *d, const int *order, int norder, const char *attr,
                             int32_t nprims, const int32_t *prim_verts,
                             const float *const *prim_xyz, double *vals, double *scratch) {
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(d->root, "meshes");
    const int nacc = count_of(d->root, "accessors");
    int64_t at = 0;
    int k = 0;
    for (int j = 0; j < norder; ++j) {
        const cJSON *prim;
        int p = 0;
        cJSON_ArrayForEach(prim, cJSON_GetObjectItemCaseSensitive(
                                     cJSON_GetArrayItem(meshes, order[j]), "primitives")) {
            if (k >= nprims) break; /* the count check below names it */
            sinew_result rc = match_primitive(d, prim, order[j], p, k, prim_verts[k],
                                              prim_xyz ? prim_xyz[k] : NULL, scratch);
            if (rc) return rc;
            const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
            if (cJSON_GetObjectItemCaseSensitive(attrs, attr)) {
                int a = index_of(attrs, attr, nacc);
                if (a < 0)
                    return sw_error_set(d->err, SINEW_ERROR_PARSE,
                                        "%s: mesh %d primitive %d: %s is not an accessor", d->name,
                                        order[j], p, attr);
                rc = read_values(d, a, order[j], p, prim_verts[k], attr, vals + at);
                if (rc) return rc;
            }
            at += prim_verts[k], k++, p++;
        }
    }
    return SINEW_OK;
}

/* The number of primitives of the loaded meshes, and whether one has `attr`. */
static int64_t count_primitives(const cJSON *root, const int *order, int norder, const char *attr,
                                int *any) {
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes"), *prim;
    int64_t n = 0;
    *any = 0;
    for (int j = 0; j < norder; ++j)
        cJSON_ArrayForEach(prim, cJSON_GetObjectItemCaseSensitive(
                                     cJSON_GetArrayItem(meshes, order[j]), "primitives")) {
            n++;
            *any |= cJSON_GetObjectItemCaseSensitive(
                        cJSON_GetObjectItemCaseSensitive(prim, "attributes"), attr) != NULL;
        }
    return n;
}

/* With the document parsed: the order, the checks against assimp's meshes, the values. */
static sinew_result read_document(gltf_doc *d, const char *attr, int32_t nprims,
                                  const int32_t *prim_verts, const float *const *prim_xyz,
                                  double **out) {
    const int nmesh = count_of(d->root, "meshes");
    int *order = malloc(sizeof(int) * ((size_t)nmesh + 1)), norder = 0, any = 0;
    double *vals = NULL, *scratch = NULL;
    sinew_result rc =
        order ? load_order(d->root, order, &norder, d->name, d->err)
              : sw_error_set(d->err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", d->name);
    if (rc) goto done;
    const int64_t nfile = count_primitives(d->root, order, norder, attr, &any);
    if (!any) goto done; /* nothing painted: *out stays NULL */
    if (nfile != nprims) {
        rc = sw_error_set(d->err, SINEW_ERROR_UNSUPPORTED,
                          "%s: %lld glTF primitives but assimp made %d meshes: cannot place the "
                          "%s attribute",
                          d->name, (long long)nfile, (int)nprims, attr);
        goto done;
    }
    int64_t total = 0, most = 0;
    for (int32_t k = 0; k < nprims; ++k) {
        if (prim_verts[k] < 0) {
            rc = sw_error_set(d->err, SINEW_ERROR_INVALID_ARGUMENT, "%s: mesh %d has %d vertices",
                              d->name, (int)k, (int)prim_verts[k]);
            goto done;
        }
        total += prim_verts[k], most = prim_verts[k] > most ? prim_verts[k] : most;
    }
    vals = malloc(sizeof(double) * (size_t)(total ? total : 1));
    scratch = malloc(sizeof(double) * 3 * (size_t)(most ? most : 1));
    if (!vals || !scratch) {
        rc = sw_error_set(d->err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", d->name);
        goto done;
    }
    for (int64_t i = 0; i < total; ++i)
        vals[i] = 1;
    rc = read_all(d, order, norder, attr, nprims, prim_verts, prim_xyz, vals, scratch);
    if (!rc) *out = vals, vals = NULL;
done:
    free(order);
    free(vals);
    free(scratch);
    return rc;
}

sinew_result sw_gltf_float_attribute(const void *data, size_t len, int binary, const char *dir,
                                     const char *attr, const char *name, int32_t nprims,
                                     const int32_t *prim_verts, const float *const *prim_xyz,
                                     double **out, sw_error *err) {
    *out = NULL;
    gltf_doc d = {.binary = binary, .dir = dir, .name = name, .err = err};
    const char *json = data;
    size_t jlen = len;
    if (nprims < 0 || (nprims > 0 && !prim_verts) || !attr)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: no meshes to read %s into",
                            name, attr ? attr : "(null)");
    if (binary && !split_glb(data, len, &json, &jlen, &d.bin, &d.nbin))
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: not a glTF binary", name);
    cJSON *root = cJSON_ParseWithLength(json, jlen);
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: the glTF JSON does not parse", name);
    }
    d.root = root;
    d.nbuf = count_of(root, "buffers");
    d.decoded = calloc((size_t)d.nbuf + 1, sizeof *d.decoded);
    d.ndecoded = calloc((size_t)d.nbuf + 1, sizeof *d.ndecoded);
    sinew_result rc = d.decoded && d.ndecoded
                          ? read_document(&d, attr, nprims, prim_verts, prim_xyz, out)
                          : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    for (int b = 0; d.decoded && b < d.nbuf; ++b)
        free(d.decoded[b]);
    free(d.decoded);
    free(d.ndecoded);
    cJSON_Delete(root);
    return rc;
}
