/* World files as a host reads them: cJSON for the file, the public sinew_world.h for the
 * colliders. Key frames are the tools' 30 a second; the viewer loops them. */
#include "world.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define FAIL(...) (snprintf(err, errlen, __VA_ARGS__), 0)

static int read_floats(const cJSON *o, const char *name, float *out, int n, int required) {
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, name);
    if (!a) return !required;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return 0;
    for (int k = 0; k < n; ++k) {
        const cJSON *x = cJSON_GetArrayItem(a, k);
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) return 0;
        out[k] = (float)x->valuedouble;
    }
    return 1;
}

static int read_float(const cJSON *o, const char *name, float *out) {
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(o, name);
    if (!x) return 1;
    if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) return 0;
    *out = (float)x->valuedouble;
    return 1;
}

/* q scaled to unit length (by its largest component first, so that tiny or huge finite
 * components do not underflow or overflow): 0 for the zero quaternion, as the tools' world
 * reader refuses it. */
static int unit_rotation(float q[4]) {
    double m = 0, n2 = 0;
    for (int k = 0; k < 4; ++k)
        m = fmax(m, fabs(q[k]));
    if (!(m > 1e-30)) return 0;
    for (int k = 0; k < 4; ++k)
        n2 += (q[k] / m) * (q[k] / m);
    for (int k = 0; k < 4; ++k)
        q[k] = (float)(q[k] / m / sqrt(n2));
    return 1;
}

/* An OBJ's vertices and faces (fanned into triangles; negative indices count back). */
static int read_obj(const char *path, vw_collider *c, char *err, size_t errlen) {
    FILE *f = fopen(path, "r");
    if (!f) return FAIL("%s: cannot open", path);
    char line[1024];
    int nv = 0, nt = 0, cv = 0, ct = 0, ok = 1, ln = 0;
    while (ok && fgets(line, sizeof line, f)) {
        ln++;
        if (line[0] == 'v' && line[1] == ' ') {
            float p[3];
            if (sscanf(line + 2, "%f %f %f", &p[0], &p[1], &p[2]) != 3 ||
                !isfinite(p[0] + p[1] + p[2])) {
                ok = FAIL("%s:%d: a vertex needs 3 numbers", path, ln);
                break;
            }
            if (nv == cv) {
                cv = cv ? 2 * cv : 64;
                float *g = realloc(c->shape, sizeof(float) * 3 * (size_t)cv);
                if (!g)
                    ok = FAIL("out of memory");
                else
                    c->shape = g;
            }
            if (ok) memcpy(c->shape + 3 * nv++, p, sizeof p);
        } else if (line[0] == 'f' && line[1] == ' ') {
            long idx[64];
            int n = 0;
            for (char *t = strtok(line + 2, " \t\r\n"); t && n < 64; t = strtok(NULL, " \t\r\n")) {
                long k = strtol(t, NULL, 10);
                idx[n++] = k < 0 ? nv + k : k - 1;
            }
            for (int k = 0; k < n && ok; ++k)
                if (idx[k] < 0 || idx[k] >= nv)
                    ok = FAIL("%s:%d: a face names a vertex not yet given", path, ln);
            for (int k = 2; k < n && ok; ++k) {
                if (nt == ct) {
                    ct = ct ? 2 * ct : 64;
                    uint32_t *g = realloc(c->shape_tris, sizeof(uint32_t) * 3 * (size_t)ct);
                    if (!g) {
                        ok = FAIL("out of memory");
                        break;
                    }
                    c->shape_tris = g;
                }
                const uint32_t tri[3] = {(uint32_t)idx[0], (uint32_t)idx[k - 1], (uint32_t)idx[k]};
                memcpy(c->shape_tris + 3 * nt++, tri, sizeof tri);
            }
        }
    }
    fclose(f);
    if (ok && (!nv || !nt)) ok = FAIL("%s: no triangles", path);
    c->def.vertices = c->shape, c->def.vertex_count = (uint32_t)nv;
    c->def.indices = c->shape_tris, c->def.triangle_count = (uint32_t)nt;
    return ok;
}

static int read_hull(const cJSON *o, vw_collider *c, int i, char *err, size_t errlen) {
    const cJSON *pts = cJSON_GetObjectItemCaseSensitive(o, "points"), *p;
    const int n = cJSON_IsArray(pts) ? cJSON_GetArraySize(pts) : 0;
    if (n < 4 || n > VW_WORLD_MAX_HULL)
        return FAIL("collider %d (hull): 4 to %d points (the viewer draws hulls of so many)", i,
                    VW_WORLD_MAX_HULL);
    c->shape = malloc(sizeof(float) * 3 * (size_t)n);
    if (!c->shape) return FAIL("out of memory");
    int k = 0;
    cJSON_ArrayForEach(p, pts) {
        if (!cJSON_IsArray(p) || cJSON_GetArraySize(p) != 3)
            return FAIL("collider %d (hull): point %d is not [x, y, z]", i, k);
        for (int j = 0; j < 3; ++j) {
            const cJSON *x = cJSON_GetArrayItem(p, j);
            if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
                return FAIL("collider %d (hull): point %d is not [x, y, z]", i, k);
            c->shape[3 * k + j] = (float)x->valuedouble;
        }
        k++;
    }
    c->def.points = c->shape, c->def.point_count = (uint32_t)n;
    return 1;
}

/* A hull's faces for drawing: every triangle of points with all points behind it
 * (O(n^4), hence the viewer's limit on hull points; coplanar points give overlapping
 * triangles, drawn alike). */
static int hull_mesh(vw_collider *c) {
    const int n = (int)c->def.point_count;
    const float *p = c->shape;
    int cap = 64;
    c->tris = malloc(sizeof(uint32_t) * 3 * (size_t)cap);
    c->local = malloc(sizeof(float) * 3 * (size_t)n);
    if (!c->tris || !c->local) return 0;
    memcpy(c->local, p, sizeof(float) * 3 * (size_t)n);
    c->nverts = n, c->ntris = 0;
    for (int a = 0; a < n; ++a)
        for (int b = a + 1; b < n; ++b)
            for (int d = b + 1; d < n; ++d) {
                const float *A = p + 3 * a, *B = p + 3 * b, *D = p + 3 * d;
                float e1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]},
                      e2[3] = {D[0] - A[0], D[1] - A[1], D[2] - A[2]};
                float nn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                               e1[0] * e2[1] - e1[1] * e2[0]};
                float l = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
                if (!(l > 1e-12f)) continue;
                int above = 0, below = 0;
                for (int q = 0; q < n; ++q) {
                    float s = (nn[0] * (p[3 * q] - A[0]) + nn[1] * (p[3 * q + 1] - A[1]) +
                               nn[2] * (p[3 * q + 2] - A[2])) /
                              l;
                    above += s > 1e-6f, below += s < -1e-6f;
                }
                if (above && below) continue;
                if (c->ntris == cap) {
                    cap *= 2;
                    uint32_t *g = realloc(c->tris, sizeof(uint32_t) * 3 * (size_t)cap);
                    if (!g) return 0;
                    c->tris = g;
                }
                const uint32_t t[3] = {(uint32_t)a, (uint32_t)(above ? d : b),
                                       (uint32_t)(above ? b : d)};
                memcpy(c->tris + 3 * c->ntris++, t, sizeof t);
            }
    return 1;
}

/* A unit sphere's mesh (rings x segments), stretched per shape below. */
static int sphere_mesh(vw_collider *c, int rings, int segs) {
    c->nverts = (rings + 1) * (segs + 1), c->ntris = 2 * rings * segs;
    c->local = malloc(sizeof(float) * 3 * (size_t)c->nverts);
    c->tris = malloc(sizeof(uint32_t) * 3 * (size_t)c->ntris);
    if (!c->local || !c->tris) return 0;
    for (int r = 0, v = 0; r <= rings; ++r)
        for (int s = 0; s <= segs; ++s, ++v) {
            double th = PI * r / rings, ph = 2 * PI * s / segs;
            c->local[3 * v] = (float)(sin(th) * cos(ph));
            c->local[3 * v + 1] = (float)cos(th);
            c->local[3 * v + 2] = (float)(sin(th) * sin(ph));
        }
    for (int r = 0, t = 0; r < rings; ++r)
        for (int s = 0; s < segs; ++s) {
            uint32_t a = (uint32_t)(r * (segs + 1) + s), b = a + (uint32_t)segs + 1;
            uint32_t q[6] = {a, b, a + 1, a + 1, b, b + 1};
            memcpy(c->tris + 3 * t, q, sizeof q);
            t += 2;
        }
    return 1;
}

/* The drawn shape: a sphere stretched to a box (its corners rounded off by the sphere's
 * few segments would mislead, so a box gets 6 rings and 4 segments: a cuboid), a capsule
 * (hemispheres pushed apart) or a plane's square. */
static int collider_mesh(vw_collider *c, float size) {
    const sinew_collider_def *d = &c->def;
    if (d->shape == SINEW_SHAPE_HULL) {
        if (!hull_mesh(c)) return 0;
    } else if (d->shape == SINEW_SHAPE_MESH) {
        c->nverts = (int32_t)d->vertex_count, c->ntris = (int32_t)d->triangle_count;
        c->local = malloc(sizeof(float) * 3 * (size_t)c->nverts);
        c->tris = malloc(sizeof(uint32_t) * 3 * (size_t)c->ntris);
        if (!c->local || !c->tris) return 0;
        memcpy(c->local, c->shape, sizeof(float) * 3 * (size_t)c->nverts);
        memcpy(c->tris, c->shape_tris, sizeof(uint32_t) * 3 * (size_t)c->ntris);
    } else if (d->shape == SINEW_SHAPE_BOX) {
        static const float corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                           {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
        static const uint32_t faces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7},
                                              {0, 1, 5}, {0, 5, 4}, {3, 7, 6}, {3, 6, 2},
                                              {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
        c->nverts = 8, c->ntris = 12;
        c->local = malloc(sizeof corner), c->tris = malloc(sizeof faces);
        if (!c->local || !c->tris) return 0;
        for (int v = 0; v < 8; ++v)
            for (int k = 0; k < 3; ++k)
                c->local[3 * v + k] = corner[v][k] * d->half_extents[k];
        memcpy(c->tris, faces, sizeof faces);
    } else if (d->shape == SINEW_SHAPE_PLANE) {
        float n[3] = {d->normal[0], d->normal[1], d->normal[2]}, u[3], w[3];
        float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k)
            n[k] /= l;
        float a[3] = {fabsf(n[0]) < 0.9f ? 1.0f : 0.0f, fabsf(n[0]) < 0.9f ? 0.0f : 1.0f, 0};
        u[0] = n[1] * a[2] - n[2] * a[1], u[1] = n[2] * a[0] - n[0] * a[2],
        u[2] = n[0] * a[1] - n[1] * a[0];
        l = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        for (int k = 0; k < 3; ++k)
            u[k] /= l;
        w[0] = n[1] * u[2] - n[2] * u[1], w[1] = n[2] * u[0] - n[0] * u[2],
        w[2] = n[0] * u[1] - n[1] * u[0];
        c->nverts = 4, c->ntris = 2;
        c->local = malloc(sizeof(float) * 12), c->tris = malloc(sizeof(uint32_t) * 6);
        if (!c->local || !c->tris) return 0;
        for (int v = 0; v < 4; ++v) {
            float su = (v == 1 || v == 2) ? size : -size, sw = v >= 2 ? size : -size;
            for (int k = 0; k < 3; ++k)
                c->local[3 * v + k] = d->offset * n[k] + su * u[k] + sw * w[k];
        }
        const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
        memcpy(c->tris, q, sizeof q);
    } else {
        if (!sphere_mesh(c, 16, 24)) return 0;
        for (int32_t v = 0; v < c->nverts; ++v) {
            float *p = c->local + 3 * v;
            for (int k = 0; k < 3; ++k)
                p[k] *= d->radius;
            if (d->shape == SINEW_SHAPE_CAPSULE)
                p[1] += p[1] >= 0 ? d->half_height : -d->half_height;
        }
    }
    c->pos = malloc(sizeof(float) * 3 * (size_t)c->nverts);
    c->nrm = malloc(sizeof(float) * 3 * (size_t)c->nverts);
    return c->pos && c->nrm;
}

static int read_collider(const cJSON *o, const char *dir, vw_collider *c, int i, char *err,
                         size_t errlen) {
    c->def = sinew_collider_def_default();
    sinew_collider_def *d = &c->def;
    const cJSON *sh = cJSON_GetObjectItemCaseSensitive(o, "shape");
    const char *s = cJSON_IsString(sh) ? sh->valuestring : "";
    int ok = 1;
    if (!strcmp(s, "sphere")) {
        d->shape = SINEW_SHAPE_SPHERE;
        ok = read_float(o, "radius", &d->radius);
    } else if (!strcmp(s, "capsule")) {
        d->shape = SINEW_SHAPE_CAPSULE;
        ok = read_float(o, "radius", &d->radius) && read_float(o, "half_height", &d->half_height);
    } else if (!strcmp(s, "box")) {
        d->shape = SINEW_SHAPE_BOX;
        ok = read_floats(o, "half_extents", d->half_extents, 3, 1);
    } else if (!strcmp(s, "plane")) {
        d->shape = SINEW_SHAPE_PLANE;
        ok = read_floats(o, "normal", d->normal, 3, 0) && read_float(o, "offset", &d->offset);
    } else if (!strcmp(s, "hull")) {
        d->shape = SINEW_SHAPE_HULL;
        if (!read_hull(o, c, i, err, errlen)) return 0;
    } else if (!strcmp(s, "mesh")) {
        const cJSON *obj = cJSON_GetObjectItemCaseSensitive(o, "obj");
        char path[1024];
        d->shape = SINEW_SHAPE_MESH;
        if (!cJSON_IsString(obj)) return FAIL("collider %d (mesh): \"obj\" names no file", i);
        /* (relative to the world file, as the tools read it) */
        size_t nd = obj->valuestring[0] == '/' ? 0 : strlen(dir), nf = strlen(obj->valuestring);
        if (nd + nf >= sizeof path)
            return FAIL("collider %d (mesh): the path of \"%.64s...\" is too long", i,
                        obj->valuestring);
        memcpy(path, dir, nd);
        memcpy(path + nd, obj->valuestring, nf + 1);
        if (!read_obj(path, c, err, errlen)) return 0;
    } else {
        return FAIL("collider %d: shape '%s' (sphere, capsule, box, plane, hull or mesh)", i, s);
    }
    ok = ok && read_float(o, "friction", &d->friction) && read_float(o, "stiffness", &d->stiffness);
    if (!ok) return FAIL("collider %d (%s): a size is missing or not a number", i, s);
    const cJSON *motion = cJSON_GetObjectItemCaseSensitive(o, "motion"), *k;
    cJSON_ArrayForEach(k, motion) {
        if (c->nkeys == VW_WORLD_MAX_KEYS)
            return FAIL("collider %d: more than %d keys", i, VW_WORLD_MAX_KEYS);
        vw_key *key = &c->keys[c->nkeys++];
        float f = 0;
        key->rotation[0] = 1, key->rotation[1] = key->rotation[2] = key->rotation[3] = 0;
        if (!read_float(k, "frame", &f) || !read_floats(k, "position", key->position, 3, 1) ||
            !read_floats(k, "rotation", key->rotation, 4, 0))
            return FAIL("collider %d: key %d needs frame, position and rotation [w, x, y, z]", i,
                        c->nkeys - 1);
        key->frame = f;
        if (c->nkeys > 1 && !(key->frame > key[-1].frame))
            return FAIL("collider %d: key %d's frame %g does not follow %g (frames must strictly "
                        "increase)",
                        i, c->nkeys - 1, key->frame, key[-1].frame);
        if (!unit_rotation(key->rotation))
            return FAIL("collider %d: key %d: the zero quaternion is no rotation (w, x, y, z)", i,
                        c->nkeys - 1);
    }
    if (c->nkeys) {
        memcpy(d->transform.position, c->keys[0].position, sizeof d->transform.position);
        memcpy(d->transform.rotation, c->keys[0].rotation, sizeof d->transform.rotation);
    }
    return 1;
}

int vw_world_load(const char *path, vw_world *w, char *err, size_t errlen) {
    memset(w, 0, sizeof *w);
    FILE *f = fopen(path, "rb");
    if (!f) return FAIL("%s: cannot open", path);
    char *text = malloc(1 << 20);
    size_t n = text ? fread(text, 1, (1 << 20) - 1, f) : 0;
    fclose(f);
    if (!text) return FAIL("out of memory");
    text[n] = 0;
    char dir[1024] = "";
    const char *slash = strrchr(path, '/');
    if (slash && slash - path < (long)sizeof dir - 1) memcpy(dir, path, (size_t)(slash - path) + 1);
    cJSON *root = cJSON_Parse(text);
    free(text);
    if (!root) return FAIL("%s: not JSON (or larger than 1 MiB)", path);
    int ok = 1;
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "sinew_world");
    const cJSON *pose = cJSON_GetObjectItemCaseSensitive(root, "pose");
    const cJSON *cols = cJSON_GetObjectItemCaseSensitive(root, "colliders"), *c;
    if (!cJSON_IsNumber(ver) || ver->valueint != 1)
        ok = FAIL("%s: not a world file of schema 1 (\"sinew_world\": 1)", path);
    w->rest_pose = cJSON_IsString(pose) && !strcmp(pose->valuestring, "rest");
    sinew_world_def wd = sinew_world_def_default();
    if (ok && sinew_world_create(&wd, &w->world) != SINEW_OK) ok = FAIL("cannot create a world");
    cJSON_ArrayForEach(c, cols) {
        if (!ok) break;
        if (w->ncol == VW_WORLD_MAX_COLLIDERS) {
            ok = FAIL("%s: more than %d colliders", path, VW_WORLD_MAX_COLLIDERS);
            break;
        }
        vw_collider *vc = &w->col[w->ncol++];
        ok = read_collider(c, dir, vc, w->ncol - 1, err, errlen);
        if (!ok) break;
        sinew_result r = sinew_world_add_collider(w->world, &vc->def, &vc->id);
        if (r != SINEW_OK)
            ok = FAIL("%s: collider %d refused: %s", path, w->ncol - 1, sinew_result_string(r));
        else if (!collider_mesh(vc, 4.0f))
            ok = FAIL("out of memory");
        for (int k = 0; k < vc->nkeys; ++k)
            w->period_s = fmax(w->period_s, vc->keys[k].frame / 30.0);
    }
    cJSON_Delete(root);
    if (!ok) vw_world_free(w);
    return ok;
}

static void place(vw_collider *c, const sinew_transform *t) {
    const float *q = t->rotation;
    float l = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    float w = q[0] / l, x = q[1] / l, y = q[2] / l, z = q[3] / l;
    const float R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                        2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                        2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int32_t v = 0; v < c->nverts; ++v)
        for (int r = 0; r < 3; ++r)
            c->pos[3 * v + r] = R[3 * r] * c->local[3 * v] + R[3 * r + 1] * c->local[3 * v + 1] +
                                R[3 * r + 2] * c->local[3 * v + 2] + t->position[r];
}

void vw_world_move(vw_world *w, double t) {
    double frame = w->period_s > 0 ? fmod(t, w->period_s + 1.0) * 30.0 : 0;
    for (int i = 0; i < w->ncol; ++i) {
        vw_collider *c = &w->col[i];
        sinew_transform tr = c->def.transform;
        if (c->held) {
            tr = c->now;
            memcpy(tr.position, c->hold, sizeof c->hold);
            sinew_world_set_collider_transform(w->world, c->id, &tr);
        } else if (c->nkeys) {
            int k = 0;
            while (k + 1 < c->nkeys && c->keys[k + 1].frame <= frame)
                ++k;
            const vw_key *a = &c->keys[k], *b = &c->keys[k + 1 < c->nkeys ? k + 1 : k];
            double u = b->frame > a->frame
                           ? fmin(1.0, fmax(0.0, (frame - a->frame) / (b->frame - a->frame)))
                           : 0;
            float dot = 0;
            for (int j = 0; j < 4; ++j)
                dot += a->rotation[j] * b->rotation[j];
            for (int j = 0; j < 3; ++j)
                tr.position[j] = (float)((1 - u) * a->position[j] + u * b->position[j]);
            for (int j = 0; j < 4; ++j) /* (normalised lerp: keys are close) */
                tr.rotation[j] =
                    (float)((1 - u) * a->rotation[j] + u * (dot < 0 ? -1 : 1) * b->rotation[j]);
            sinew_world_set_collider_transform(w->world, c->id, &tr);
        }
        c->now = tr;
        place(c, &tr);
    }
}

void vw_world_hold(vw_world *w, int i, const float p[3]) {
    vw_collider *c = &w->col[i];
    c->held = 1;
    memcpy(c->hold, p, sizeof c->hold);
    memcpy(c->now.position, p, sizeof c->hold);
    sinew_world_set_collider_transform(w->world, c->id, &c->now);
    place(c, &c->now);
}

void vw_world_position(const vw_world *w, int i, float p[3]) {
    memcpy(p, w->col[i].now.position, 3 * sizeof(float));
}

void vw_world_free(vw_world *w) {
    for (int i = 0; i < w->ncol; ++i)
        free(w->col[i].local), free(w->col[i].pos), free(w->col[i].nrm), free(w->col[i].tris),
            free(w->col[i].shape), free(w->col[i].shape_tris);
    sinew_world_destroy(w->world);
    memset(w, 0, sizeof *w);
}
