/* World-file reader (world_io.h): JSON through Debian's libcjson, validated field by
 * field into sinew_collider_defs, keyframes and owned arrays. Every message names the
 * file, the collider and the field. */
#include "world_io.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "mesh_io.h"

/* Where an error happened: the file, and the collider being read (index -1: none). */
typedef struct wctx {
    const char *file;
    const char *base_dir;
    sw_error *err;
    int32_t index;
    const char *name; /* the collider's given name, or NULL */
} wctx;

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static sinew_result
fail(const wctx *c, sinew_result code, const char *field, const char *fmt, ...) {
    if (!c->err) return code;
    char what[320], where[160] = "";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (c->index >= 0 && c->name)
        snprintf(where, sizeof where, "collider \"%s\" (#%d): ", c->name, (int)c->index);
    else if (c->index >= 0)
        snprintf(where, sizeof where, "collider #%d: ", (int)c->index);
    return sw_error_set(c->err, code, "%.200s: %s%s%s%s", c->file, where, field ? field : "",
                        field ? ": " : "", what);
}

/* ---- typed values ---------------------------------------------------------------- */

/* A finite number. */
static sinew_result get_number(const wctx *c, const cJSON *it, const char *field, double *v) {
    *v = 0;
    if (!cJSON_IsNumber(it))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "must be a number");
    if (!isfinite(it->valuedouble))
        return fail(c, SINEW_ERROR_NOT_FINITE, field, "must be finite (got %g)", it->valuedouble);
    *v = it->valuedouble;
    return SINEW_OK;
}

/* A finite number that fits a float (the collider definition's type). */
static sinew_result get_float(const wctx *c, const cJSON *it, const char *field, double *v) {
    sinew_result rc = get_number(c, it, field, v);
    if (!rc && fabs(*v) > FLT_MAX)
        return fail(c, SINEW_ERROR_NOT_FINITE, field, "%g is beyond float range", *v);
    return rc;
}

/* An array of exactly n float-range numbers. */
static sinew_result get_vec(const wctx *c, const cJSON *it, int n, const char *field, double *v) {
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "must be an array of %d numbers", n);
    int k = 0;
    for (const cJSON *e = it->child; e; e = e->next, ++k) {
        char sub[96];
        snprintf(sub, sizeof sub, "%s[%d]", field, k);
        sinew_result rc = get_float(c, e, sub, v + k);
        if (rc) return rc;
    }
    return SINEW_OK;
}

/* An integer in [lo, hi]. */
static sinew_result get_int(const wctx *c, const cJSON *it, const char *field, double lo, double hi,
                            int32_t *v) {
    double d = 0;
    sinew_result rc = get_number(c, it, field, &d);
    if (rc) return rc;
    if (d != floor(d) || d < lo || d > hi)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "must be an integer in [%.0f, %.0f]",
                    lo, hi);
    *v = (int32_t)d;
    return SINEW_OK;
}

/* A number > 0 (positive) or >= 0 (!positive), in float range. */
static sinew_result get_size(const wctx *c, const cJSON *it, const char *field, int positive,
                             float *out) {
    double v = 0;
    sinew_result rc = get_float(c, it, field, &v);
    if (rc) return rc;
    if (positive ? !(v > 0) : !(v >= 0))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "must be a %s finite number (got %g)",
                    positive ? "positive" : "non-negative", v);
    *out = (float)v;
    if (positive && !(*out > 0))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "%g is below float range", v);
    return SINEW_OK;
}

/* ---- keys of an object ----------------------------------------------------------- */

static int in_list(const char *s, const char *const *list) {
    for (; *list; ++list)
        if (!strcmp(s, *list)) return 1;
    return 0;
}

/* Every key of `obj` is in `allowed` (else `misplaced` may explain it: a field of another
 * shape) and none repeats. `what` names the object in messages. */
static sinew_result check_keys(const wctx *c, const cJSON *obj, const char *field,
                               const char *const *allowed, const char *const *misplaced,
                               const char *misplaced_why) {
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *k = e->string ? e->string : "";
        char key[96];
        snprintf(key, sizeof key, "%s%s\"%.64s\"", field ? field : "", field ? ": " : "", k);
        if (!in_list(k, allowed)) {
            if (misplaced && in_list(k, misplaced))
                return fail(c, SINEW_ERROR_INVALID_ARGUMENT, key, "%s", misplaced_why);
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, key, "unknown key");
        }
        for (const cJSON *p = obj->child; p != e; p = p->next)
            if (p->string && !strcmp(p->string, k))
                return fail(c, SINEW_ERROR_INVALID_ARGUMENT, key, "repeated key");
    }
    return SINEW_OK;
}

static sinew_result required(const wctx *c, const cJSON *obj, const char *key, const char *field,
                             const cJSON **out) {
    *out = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!*out) return fail(c, SINEW_ERROR_INVALID_ARGUMENT, field, "missing");
    return SINEW_OK;
}

/* ---- shapes ---------------------------------------------------------------------- */

static const char *const shape_names[] = {"plane", "sphere", "capsule", "box",
                                          "hull",  "mesh",   NULL};
/* Per shape: its own keys (after the common ones). */
static const char *const shape_keys[6][8] = {
    {"name", "shape", "stiffness", "friction", "motion", "normal", "offset", NULL},
    {"name", "shape", "stiffness", "friction", "motion", "radius", NULL},
    {"name", "shape", "stiffness", "friction", "motion", "radius", "half_height", NULL},
    {"name", "shape", "stiffness", "friction", "motion", "half_extents", NULL},
    {"name", "shape", "stiffness", "friction", "motion", "points", NULL},
    {"name", "shape", "stiffness", "friction", "motion", "obj", NULL},
};
static const char *const all_shape_keys[] = {"normal",       "offset", "radius", "half_height",
                                             "half_extents", "points", "obj",    NULL};

/* Points of a hull: not all coplanar (relative tolerance on the spread). */
static int hull_is_solid(const float *P, uint32_t n) {
    double a[3] = {P[0], P[1], P[2]}, b[3], best = 0, L2;
    uint32_t ib = 0, ic = 0;
    for (uint32_t i = 1; i < n; ++i) {
        double d = 0;
        for (int k = 0; k < 3; ++k)
            d += (P[3 * i + k] - a[k]) * (P[3 * i + k] - a[k]);
        if (d > best) best = d, ib = i;
    }
    if (!(best > 0)) return 0;
    L2 = best;
    for (int k = 0; k < 3; ++k)
        b[k] = P[3 * ib + k] - a[k];
    double nrm[3] = {0, 0, 0};
    best = 0;
    for (uint32_t i = 1; i < n; ++i) {
        double e[3] = {P[3 * i] - a[0], P[3 * i + 1] - a[1], P[3 * i + 2] - a[2]};
        double x[3] = {b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2],
                       b[0] * e[1] - b[1] * e[0]};
        double d = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        if (d > best) best = d, ic = i, memcpy(nrm, x, sizeof nrm);
    }
    if (!(best > 1e-18 * L2 * L2)) return 0; /* all on one line */
    (void)ic;
    double vol = 0, nn = sqrt(best);
    for (uint32_t i = 1; i < n; ++i) {
        double h = fabs(nrm[0] * (P[3 * i] - a[0]) + nrm[1] * (P[3 * i + 1] - a[1]) +
                        nrm[2] * (P[3 * i + 2] - a[2])) /
                   nn;
        if (h > vol) vol = h;
    }
    return vol > 1e-9 * sqrt(L2);
}

static sinew_result read_hull(const wctx *c, const cJSON *it, sw_world_collider_spec *s) {
    const char *f = "\"points\"";
    if (!cJSON_IsArray(it))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, f, "must be an array of [x, y, z] points");
    int n = cJSON_GetArraySize(it);
    if (n < 4 || n > SW_WORLD_MAX_HULL_POINTS)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, f, "has %d points (4 ..= %d)", n,
                    SW_WORLD_MAX_HULL_POINTS);
    s->points = malloc(sizeof(float) * 3 * (size_t)n);
    if (!s->points) return fail(c, SINEW_ERROR_OUT_OF_MEMORY, f, "out of memory");
    int i = 0;
    for (const cJSON *e = it->child; e; e = e->next, ++i) {
        char sub[32];
        double p[3];
        snprintf(sub, sizeof sub, "\"points\"[%d]", i);
        sinew_result rc = get_vec(c, e, 3, sub, p);
        if (rc) return rc;
        for (int k = 0; k < 3; ++k)
            s->points[3 * i + k] = (float)p[k];
    }
    s->def.points = s->points;
    s->def.point_count = (uint32_t)n;
    if (!hull_is_solid(s->points, (uint32_t)n))
        return fail(c, SINEW_ERROR_DEGENERATE, f, "all %d points are coplanar", n);
    return SINEW_OK;
}

static sinew_result read_mesh(const wctx *c, const cJSON *it, sw_world_collider_spec *s) {
    const char *f = "\"obj\"";
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, f, "must be a non-empty path");
    const char *rel = it->valuestring;
    if (rel[0] == '/')
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, f,
                    "\"%.200s\" must be relative to the world file's folder", rel);
    if (!c->base_dir)
        return fail(c, SINEW_ERROR_UNSUPPORTED, f,
                    "mesh colliders need a world file's folder to resolve \"%.200s\"", rel);
    char path[4096];
    if ((size_t)snprintf(path, sizeof path, "%s/%s", c->base_dir, rel) >= sizeof path)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, f, "path too long");
    sw_trimesh m;
    sw_error oe;
    sw_error_clear(&oe);
    sinew_result rc = sw_read_obj(path, &m, &oe);
    if (rc) return fail(c, rc, f, "%s", oe.msg);
    s->vertices = malloc(sizeof(float) * 3 * (size_t)m.nverts);
    s->indices = malloc(sizeof(uint32_t) * 3 * (size_t)m.ntris);
    if (!s->vertices || !s->indices) {
        sw_trimesh_free(&m);
        return fail(c, SINEW_ERROR_OUT_OF_MEMORY, f, "%s: out of memory", path);
    }
    for (int64_t i = 0; i < 3 * (int64_t)m.nverts; ++i) {
        if (fabs(m.X[i]) > FLT_MAX) {
            rc = fail(c, SINEW_ERROR_NOT_FINITE, f, "%s: vertex %lld: %g is beyond float range",
                      path, (long long)(i / 3 + 1), m.X[i]);
            break;
        }
        s->vertices[i] = (float)m.X[i];
    }
    for (int32_t t = 0; !rc && t < m.ntris; ++t) {
        const float *v[3];
        for (int k = 0; k < 3; ++k) {
            s->indices[3 * t + k] = (uint32_t)m.tris[3 * t + k];
            v[k] = s->vertices + 3 * m.tris[3 * t + k];
        }
        double e1[3], e2[3];
        for (int k = 0; k < 3; ++k)
            e1[k] = (double)v[1][k] - v[0][k], e2[k] = (double)v[2][k] - v[0][k];
        double x[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double a = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        double l = sqrt((e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) *
                        (e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]));
        if (!(a > 1e-12 * l) || !(l > 0))
            rc = fail(c, SINEW_ERROR_DEGENERATE, f, "%s: triangle %d has zero area", path,
                      (int)t + 1);
    }
    s->def.vertices = s->vertices;
    s->def.vertex_count = (uint32_t)m.nverts;
    s->def.indices = s->indices;
    s->def.triangle_count = (uint32_t)m.ntris;
    sw_trimesh_free(&m);
    return rc;
}

/* ---- motion ---------------------------------------------------------------------- */

static sinew_result read_motion(const wctx *c, const cJSON *it, sw_world_collider_spec *s) {
    static const char *const key_fields[] = {"frame", "position", "rotation", NULL};
    if (!cJSON_IsArray(it))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"motion\"", "must be an array of keys");
    int n = cJSON_GetArraySize(it);
    if (n < 1 || n > SW_WORLD_MAX_KEYS)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"motion\"", "has %d keys (1 ..= %d)", n,
                    SW_WORLD_MAX_KEYS);
    s->keys = calloc((size_t)n, sizeof *s->keys);
    if (!s->keys) return fail(c, SINEW_ERROR_OUT_OF_MEMORY, "\"motion\"", "out of memory");
    int i = 0;
    sinew_result rc;
    for (const cJSON *e = it->child; e; e = e->next, ++i) {
        char kf[48], sub[96];
        const cJSON *v;
        sw_world_key *k = &s->keys[i];
        snprintf(kf, sizeof kf, "\"motion\"[%d]", i);
        if (!cJSON_IsObject(e))
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, kf,
                        "must be an object {\"frame\", \"position\", \"rotation\"}");
        if ((rc = check_keys(c, e, kf, key_fields, NULL, NULL))) return rc;
        snprintf(sub, sizeof sub, "%s: \"frame\"", kf);
        if ((rc = required(c, e, "frame", sub, &v)) ||
            (rc = get_int(c, v, sub, 0, INT32_MAX, &k->frame)))
            return rc;
        if (i > 0 && k->frame <= k[-1].frame)
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, sub,
                        "%d does not follow the previous key's frame %d (frames must strictly "
                        "increase)",
                        (int)k->frame, (int)k[-1].frame);
        snprintf(sub, sizeof sub, "%s: \"position\"", kf);
        if ((rc = required(c, e, "position", sub, &v)) || (rc = get_vec(c, v, 3, sub, k->position)))
            return rc;
        snprintf(sub, sizeof sub, "%s: \"rotation\"", kf);
        if ((rc = required(c, e, "rotation", sub, &v)) || (rc = get_vec(c, v, 4, sub, k->rotation)))
            return rc;
        double m = 0, n2 = 0;
        for (int q = 0; q < 4; ++q)
            m = fmax(m, fabs(k->rotation[q]));
        for (int q = 0; q < 4 && m > 0; ++q)
            n2 += (k->rotation[q] / m) * (k->rotation[q] / m);
        if (!(m > 1e-30))
            return fail(
                c, SINEW_ERROR_DEGENERATE, sub,
                "the zero quaternion is no rotation (w, x, y, z; identity is [1, 0, 0, 0])");
        for (int q = 0; q < 4; ++q)
            k->rotation[q] = k->rotation[q] / m / sqrt(n2);
    }
    s->nkeys = n;
    return SINEW_OK;
}

/* ---- one collider ---------------------------------------------------------------- */

static sinew_result read_collider(wctx *c, const cJSON *obj, sw_world_collider_spec *s) {
    sinew_result rc;
    const cJSON *v;
    s->def = sinew_collider_def_default();
    if (!cJSON_IsObject(obj))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, NULL, "must be an object");
    /* the name first, so that every later message can name the collider */
    if ((v = cJSON_GetObjectItemCaseSensitive(obj, "name"))) {
        if (!cJSON_IsString(v) || !v->valuestring[0])
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"name\"", "must be a non-empty string");
        if (strlen(v->valuestring) >= SW_WORLD_NAME_MAX)
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"name\"",
                        "\"%.40s...\" is %zu bytes "
                        "long (at most %d)",
                        v->valuestring, strlen(v->valuestring), SW_WORLD_NAME_MAX - 1);
        snprintf(s->name, sizeof s->name, "%s", v->valuestring);
        c->name = s->name;
    } else {
        snprintf(s->name, sizeof s->name, "collider%d", (int)c->index);
    }
    if ((rc = required(c, obj, "shape", "\"shape\"", &v))) return rc;
    int shape = -1;
    if (cJSON_IsString(v))
        for (int i = 0; shape_names[i]; ++i)
            if (!strcmp(v->valuestring, shape_names[i])) shape = i;
    if (shape < 0)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"shape\"",
                    "must be one of \"plane\", \"sphere\", \"capsule\", \"box\", \"hull\", "
                    "\"mesh\"");
    char why[64];
    snprintf(why, sizeof why, "not a field of a %s collider", shape_names[shape]);
    if ((rc = check_keys(c, obj, NULL, shape_keys[shape], all_shape_keys, why))) return rc;
    s->def.shape = (sinew_shape)shape;
    double d[3];
    switch (shape) {
    case SINEW_SHAPE_PLANE: {
        double o = 0, n;
        if ((rc = required(c, obj, "normal", "\"normal\"", &v)) ||
            (rc = get_vec(c, v, 3, "\"normal\"", d)))
            return rc;
        n = fmax(fabs(d[0]), fmax(fabs(d[1]), fabs(d[2])));
        if (!(n > 1e-30))
            return fail(c, SINEW_ERROR_DEGENERATE, "\"normal\"", "must not be the zero vector");
        d[0] /= n, d[1] /= n, d[2] /= n;
        n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; ++k)
            s->def.normal[k] = (float)(d[k] / n);
        if ((rc = required(c, obj, "offset", "\"offset\"", &v)) ||
            (rc = get_float(c, v, "\"offset\"", &o)))
            return rc;
        s->def.offset = (float)o;
        break;
    }
    case SINEW_SHAPE_SPHERE:
    case SINEW_SHAPE_CAPSULE:
        if ((rc = required(c, obj, "radius", "\"radius\"", &v)) ||
            (rc = get_size(c, v, "\"radius\"", 1, &s->def.radius)))
            return rc;
        if (shape == SINEW_SHAPE_CAPSULE &&
            ((rc = required(c, obj, "half_height", "\"half_height\"", &v)) ||
             (rc = get_size(c, v, "\"half_height\"", 0, &s->def.half_height))))
            return rc;
        break;
    case SINEW_SHAPE_BOX:
        if ((rc = required(c, obj, "half_extents", "\"half_extents\"", &v)) ||
            (rc = get_vec(c, v, 3, "\"half_extents\"", d)))
            return rc;
        for (int k = 0; k < 3; ++k) {
            s->def.half_extents[k] = (float)d[k];
            if (!(s->def.half_extents[k] > 0))
                return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"half_extents\"",
                            "must be 3 positive finite numbers (entry %d is %g)", k, d[k]);
        }
        break;
    case SINEW_SHAPE_HULL:
        if ((rc = required(c, obj, "points", "\"points\"", &v)) || (rc = read_hull(c, v, s)))
            return rc;
        break;
    default:
        if ((rc = required(c, obj, "obj", "\"obj\"", &v)) || (rc = read_mesh(c, v, s))) return rc;
        break;
    }
    if ((v = cJSON_GetObjectItemCaseSensitive(obj, "stiffness")) &&
        (rc = get_size(c, v, "\"stiffness\"", 0, &s->def.stiffness)))
        return rc;
    if ((v = cJSON_GetObjectItemCaseSensitive(obj, "friction")) &&
        (rc = get_size(c, v, "\"friction\"", 0, &s->def.friction)))
        return rc;
    if ((v = cJSON_GetObjectItemCaseSensitive(obj, "motion")) && (rc = read_motion(c, v, s)))
        return rc;
    sw_world_collider_at(s, 0.0, &s->def.transform);
    return SINEW_OK;
}

/* ---- the file -------------------------------------------------------------------- */

static sinew_result parse_json_error(const wctx *c, const char *text, size_t len, size_t off,
                                     const char *what) {
    long long line = 1, col = 1;
    if (off > len) off = len;
    for (size_t i = 0; i < off; ++i) {
        if (text[i] == '\n')
            line++, col = 1;
        else
            col++;
    }
    return fail(c, SINEW_ERROR_PARSE, NULL, "%lld:%lld: %s", line, col, what);
}

static sinew_result read_root(wctx *c, const cJSON *root, sw_world_file *out) {
    static const char *const top_keys[] = {"sinew_world", "frames", "pose", "colliders", NULL};
    sinew_result rc;
    const cJSON *v;
    if (!cJSON_IsObject(root))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, NULL, "the top level must be an object");
    v = cJSON_GetObjectItemCaseSensitive(root, "sinew_world");
    if (!v)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"sinew_world\"",
                    "missing (the schema version; not a sinew world file?)");
    if (!cJSON_IsNumber(v))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"sinew_world\"",
                    "must be the schema version number %d", SW_WORLD_SCHEMA_VERSION);
    if (v->valuedouble != SW_WORLD_SCHEMA_VERSION)
        return fail(c, SINEW_ERROR_VERSION, "\"sinew_world\"",
                    "schema version %g is not supported (this reader reads version %d)",
                    v->valuedouble, SW_WORLD_SCHEMA_VERSION);
    if ((rc = check_keys(c, root, NULL, top_keys, NULL, NULL))) return rc;
    out->frames = -1;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "frames")) &&
        (rc = get_int(c, v, "\"frames\"", 1, INT32_MAX, &out->frames)))
        return rc;
    out->rest_pose = 0;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "pose"))) {
        if (!cJSON_IsString(v) ||
            (strcmp(v->valuestring, "clip") && strcmp(v->valuestring, "rest")))
            return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"pose\"",
                        "must be \"clip\" (the character plays its clip) or \"rest\" (it holds "
                        "its rest pose while the colliders move)");
        out->rest_pose = !strcmp(v->valuestring, "rest");
    }
    if ((rc = required(c, root, "colliders", "\"colliders\"", &v))) return rc;
    if (!cJSON_IsArray(v))
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"colliders\"", "must be an array");
    int n = cJSON_GetArraySize(v);
    if (n > SW_WORLD_MAX_COLLIDERS)
        return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"colliders\"",
                    "has %d colliders (at most %d)", n, SW_WORLD_MAX_COLLIDERS);
    if (n > 0 && !(out->colliders = calloc((size_t)n, sizeof *out->colliders)))
        return fail(c, SINEW_ERROR_OUT_OF_MEMORY, "\"colliders\"", "out of memory");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        c->index = i;
        c->name = NULL;
        out->ncolliders = i + 1; /* so that a failure frees this one's arrays too */
        if ((rc = read_collider(c, e, &out->colliders[i]))) return rc;
        for (int j = 0; j < i; ++j)
            if (!strcmp(out->colliders[j].name, out->colliders[i].name))
                return fail(c, SINEW_ERROR_INVALID_ARGUMENT, "\"name\"",
                            "\"%s\" is also collider #%d's name (names must be unique; an "
                            "unnamed collider is named collider<index>)",
                            out->colliders[i].name, j);
    }
    return SINEW_OK;
}

sinew_result sw_world_file_parse(const char *text, size_t len, const char *base_dir,
                                 const char *name_for_errors, sw_world_file *out, sw_error *err) {
    wctx c = {name_for_errors ? name_for_errors : "<world>", base_dir, err, -1, NULL};
    if (out) memset(out, 0, sizeof *out);
    if (!out || (!text && len))
        return fail(&c, SINEW_ERROR_INVALID_ARGUMENT, NULL, "sw_world_file_parse: no %s",
                    out ? "text" : "output");
    snprintf(out->path, sizeof out->path, "%s", c.file);
    out->frames = -1;
    if (len > SW_WORLD_MAX_FILE_BYTES)
        return fail(&c, SINEW_ERROR_INVALID_ARGUMENT, NULL, "%zu bytes (at most %zu)", len,
                    SW_WORLD_MAX_FILE_BYTES);
    if (len == 0) return fail(&c, SINEW_ERROR_PARSE, NULL, "1:1: empty file");
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, len, &end, 0);
    if (!root) {
        size_t off = end && end >= text ? (size_t)(end - text) : 0;
        return parse_json_error(&c, text, len, off, "malformed JSON");
    }
    size_t off = (size_t)(end - text);
    while (off < len &&
           (text[off] == ' ' || text[off] == '\t' || text[off] == '\n' || text[off] == '\r'))
        ++off;
    sinew_result rc;
    if (off < len)
        rc = parse_json_error(&c, text, len, off, "text after the JSON value");
    else
        rc = read_root(&c, root, out);
    cJSON_Delete(root);
    if (rc) sw_world_file_free(out);
    return rc;
}

sinew_result sw_world_file_read(const char *path, sw_world_file *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!path || !out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_world_file_read: no %s",
                            path ? "output" : "path");
    out->frames = -1;
    FILE *f = fopen(path, "rb");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
    char *buf = NULL;
    size_t n = 0, cap = 0;
    sinew_result rc = SINEW_OK;
    for (;;) {
        if (n == cap) {
            if (cap > SW_WORLD_MAX_FILE_BYTES) {
                rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                  "%s: larger than %zu bytes (the world file limit)", path,
                                  SW_WORLD_MAX_FILE_BYTES);
                break;
            }
            size_t nc = cap ? 2 * cap : 1 << 16;
            char *nb = realloc(buf, nc + 1);
            if (!nb) {
                rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
                break;
            }
            buf = nb;
            cap = nc;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
    }
    if (!rc && ferror(f)) rc = sw_error_set(err, SINEW_ERROR_IO, "%s: read error", path);
    fclose(f);
    if (!rc && n > SW_WORLD_MAX_FILE_BYTES)
        rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                          "%s: larger than %zu bytes (the world file limit)", path,
                          SW_WORLD_MAX_FILE_BYTES);
    if (rc) {
        free(buf);
        return rc;
    }
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    rc = sw_world_file_parse(buf, n, dir, path, out, err);
    free(buf);
    return rc;
}

void sw_world_file_free(sw_world_file *w) {
    if (!w) return;
    for (int32_t i = 0; i < w->ncolliders && w->colliders; ++i) {
        free(w->colliders[i].points);
        free(w->colliders[i].vertices);
        free(w->colliders[i].indices);
        free(w->colliders[i].keys);
    }
    free(w->colliders);
    memset(w, 0, sizeof *w);
}
