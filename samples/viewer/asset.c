/* The character as an engine imports it: assimp reads the file, and the viewer maps it
 * onto the blob through what the blob says, not through the bake's import rules.
 *
 * Bones by name: blob bone b is the file's node named sinew_blob_bone_name(b) (among
 * nodes of one name, the one nearest the blob's bind pose). Its transform at time t is
 * G(t) B^-1, G the node's global in the clip and B the blob's bind pose of the bone.
 *
 * Vertices by the output map: output vertex i is vertex v of source mesh m
 * (sinew_blob_output_sources). A skinned mesh is placed in bind space by W = B offset of
 * any of its bones (glTF 2.0 3.7.3.3: a skin ignores the mesh node's transform; W is the
 * same for every bone of the mesh), a boneless prop by its node and rides the bone at or
 * above it. The triangles are the blob's, over the output vertices. */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "assimp_trial.h"
#include "gltf_precheck.h"
#include "viewer.h"

typedef struct imp {
    const struct aiScene *sc;
    int32_t nn;                     /* nodes, depth-first */
    const struct aiNode **node;     /* nn */
    int32_t *parent;                /* nn */
    double *G;                      /* 16 nn: node-pose globals */
    int32_t *node_bone;             /* nn: bone or -1 */
    int32_t *bone_node;             /* nbones */
    double *Binv;                   /* 16 nbones: the blob's bind poses inverted */
    vw_trs *rest_trs;               /* nn: each node's node-pose local */
    double unit;                    /* file unit in metres (positions scale) */
    const struct aiNodeAnim **chan; /* nclips x nn */
    double tps[VW_MAX_CLIPS];
} imp;

static void m4_mul(const double *a, const double *b, double *o) {
    double r[16];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0;
            for (int k = 0; k < 4; ++k)
                s += a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = s;
        }
    memcpy(o, r, sizeof r);
}

static int m4_inv(const double *m, double *o) {
    const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
                 i = m[10];
    const double A = e * i - f * h, B = f * g - d * i, C = d * h - e * g,
                 det = a * A + b * B + c * C;
    if (!isfinite(det) || fabs(det) < 1e-300) return 0;
    const double r = 1.0 / det;
    const double inv[9] = {A * r, (c * h - b * i) * r, (b * f - c * e) * r,
                           B * r, (a * i - c * g) * r, (c * d - a * f) * r,
                           C * r, (b * g - a * h) * r, (a * e - b * d) * r};
    for (int row = 0; row < 3; ++row) {
        for (int k = 0; k < 3; ++k)
            o[4 * row + k] = inv[3 * row + k];
        o[4 * row + 3] =
            -(inv[3 * row] * m[3] + inv[3 * row + 1] * m[7] + inv[3 * row + 2] * m[11]);
    }
    o[12] = o[13] = o[14] = 0, o[15] = 1;
    return 1;
}

static void m4_ai(const struct aiMatrix4x4 *m, double *o) {
    const ai_real v[16] = {m->a1, m->a2, m->a3, m->a4, m->b1, m->b2, m->b3, m->b4,
                           m->c1, m->c2, m->c3, m->c4, m->d1, m->d2, m->d3, m->d4};
    for (int k = 0; k < 16; ++k)
        o[k] = (double)v[k];
}

/* The blob's bone b as a node: the file's node of the bone's name; names repeat (a mesh
 * node named after the joint that carries it), so among equal names the node whose node
 * pose lies nearest the blob's bind pose. */
static int32_t node_of_bone(const imp *s, const char *name, const double *B) {
    int32_t best = -1;
    double dbest = INFINITY;
    for (int32_t i = 0; i < s->nn; ++i) {
        if (strcmp(s->node[i]->mName.data, name)) continue;
        double d = 0;
        for (int k = 0; k < 12; ++k)
            d += (s->G[16 * i + k] - B[k]) * (s->G[16 * i + k] - B[k]);
        if (d < dbest) dbest = d, best = i;
    }
    return best;
}

#define FAIL(...) (snprintf(err, errlen, __VA_ARGS__), 0)

/* The blob's bind pose of bone b as a 4x4 in the file's units. */
static int blob_bind(const imp *s, const sinew_blob *blob, uint32_t b, double *B) {
    double bind[12];
    if (sinew_blob_bone_bind(blob, b, bind) != SINEW_OK) return 0;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            B[4 * r + c] = bind[3 * r + c];
        B[4 * r + 3] = bind[9 + r] / s->unit;
    }
    B[12] = B[13] = B[14] = 0, B[15] = 1;
    return 1;
}

/* Skeleton by name: each blob bone's node and the inverse of its bind pose. */
static int map_skeleton(imp *s, const sinew_blob *blob, int32_t *nbones, char *err, size_t errlen) {
    const uint32_t nb = sinew_blob_bone_count(blob);
    if (nb == 0 || nb > VW_MAX_BONES)
        return FAIL("the blob has %u bones (1 to %d)", nb, VW_MAX_BONES);
    if (!sinew_blob_bone_name(blob, 0))
        return FAIL("the blob has no bone names (baked before they were recorded: bake it again)");
    s->node_bone = malloc(sizeof(int32_t) * (size_t)s->nn);
    s->bone_node = malloc(sizeof(int32_t) * nb);
    s->Binv = malloc(sizeof(double) * 16 * nb);
    if (!s->node_bone || !s->bone_node || !s->Binv) return FAIL("out of memory");
    for (int32_t i = 0; i < s->nn; ++i)
        s->node_bone[i] = -1;
    for (uint32_t b = 0; b < nb; ++b) {
        const char *name = sinew_blob_bone_name(blob, b);
        double B[16];
        if (!blob_bind(s, blob, b, B))
            return FAIL("bone %u ('%s'): the blob has no bind pose", b, name);
        const int32_t i = node_of_bone(s, name, B);
        if (i < 0) return FAIL("the blob's bone %u, '%s', is no node of the file", b, name);
        if (!m4_inv(B, s->Binv + 16 * b)) return FAIL("bone '%s' has a singular bind pose", name);
        s->bone_node[b] = i, s->node_bone[i] = (int32_t)b;
    }
    *nbones = (int32_t)nb;
    return 1;
}

static int32_t joint_at_or_above(const imp *s, int32_t i) {
    for (; i >= 0; i = s->parent[i])
        if (s->node_bone[i] >= 0) return s->node_bone[i];
    return -1;
}

/* Keeps a dense row's 4 largest weights (ties: the lower bone), renormalised. */
static int top4(const double *row, int32_t nb, int32_t *bone, float *w) {
    int32_t top[4] = {-1, -1, -1, -1};
    for (int32_t b = 0; b < nb; ++b) {
        if (!(row[b] > 0)) continue;
        for (int k = 0; k < 4; ++k)
            if (top[k] < 0 || row[b] > row[top[k]]) {
                for (int j = 3; j > k; --j)
                    top[j] = top[j - 1];
                top[k] = b;
                break;
            }
    }
    double sum = 0;
    for (int k = 0; k < 4; ++k)
        sum += top[k] >= 0 ? row[top[k]] : 0;
    if (!(sum > 0)) return 0;
    for (int k = 0; k < 4; ++k)
        bone[k] = top[k] >= 0 ? top[k] : 0, w[k] = top[k] >= 0 ? (float)(row[top[k]] / sum) : 0.f;
    return 1;
}

/* How a source mesh reaches the output: its vertices placed by W (the bind space of a
 * skinned mesh, W = B offset of a bone, any bone giving the same; a rigid prop's node),
 * and per vertex 4 bones and weights. */
typedef struct mesh_map {
    double W[16];
    int32_t *wbone; /* 4 nverts */
    float *wgt;
} mesh_map;

static int map_skinned(const imp *s, const sinew_blob *blob, unsigned m, mesh_map *mm, int32_t nb,
                       char *err, size_t errlen) {
    const struct aiMesh *me = s->sc->mMeshes[m];
    double *dense = calloc((size_t)me->mNumVertices * (size_t)nb, sizeof(double));
    if (!dense) return FAIL("out of memory");
    int ok = 1;
    for (unsigned k = 0; k < me->mNumBones && ok; ++k) {
        const struct aiBone *bone = me->mBones[k];
        const int32_t b = sinew_blob_find_bone(blob, bone->mName.data);
        if (b < 0) {
            ok = FAIL("mesh %u's bone '%.200s' is not in the blob", m, bone->mName.data);
            break;
        }
        if (k == 0) { /* W = B offset */
            double O[16], B[16];
            m4_ai(&bone->mOffsetMatrix, O);
            ok = blob_bind(s, blob, (uint32_t)b, B);
            m4_mul(B, O, mm->W);
        }
        for (unsigned j = 0; j < bone->mNumWeights; ++j)
            if (bone->mWeights[j].mVertexId < me->mNumVertices)
                dense[(size_t)bone->mWeights[j].mVertexId * nb + b] += bone->mWeights[j].mWeight;
    }
    for (unsigned v = 0; v < me->mNumVertices && ok; ++v)
        if (!top4(dense + (size_t)v * nb, nb, mm->wbone + 4 * v, mm->wgt + 4 * v))
            mm->wbone[4 * v] = -1; /* (an error only if the output uses it) */
    free(dense);
    return ok;
}

static int map_rigid(const imp *s, unsigned m, mesh_map *mm, char *err, size_t errlen) {
    const struct aiMesh *me = s->sc->mMeshes[m];
    int32_t b = -1;
    for (int32_t i = 0; i < s->nn && b < 0; ++i)
        for (unsigned k = 0; k < s->node[i]->mNumMeshes && b < 0; ++k)
            if (s->node[i]->mMeshes[k] == m) {
                b = joint_at_or_above(s, i);
                memcpy(mm->W, s->G + 16 * i, sizeof mm->W);
            }
    if (b < 0) return FAIL("mesh %u has no bones and hangs below no bone", m);
    for (unsigned v = 0; v < me->mNumVertices; ++v) {
        int32_t *wb = mm->wbone + 4 * v;
        float *ww = mm->wgt + 4 * v;
        wb[0] = b, wb[1] = wb[2] = wb[3] = 0;
        ww[0] = 1, ww[1] = ww[2] = ww[3] = 0;
    }
    return 1;
}

/* Output vertex i of the blob is vertex pairs[2i + 1] of mesh pairs[2i]: the host's own
 * vertex, placed and weighted as its mesh says. */
static int place_outputs(const imp *s, const int32_t *pairs, mesh_map *mm, vw_asset *a, char *err,
                         size_t errlen) {
    for (int32_t i = 0; i < a->nverts; ++i) {
        const int32_t m = pairs[2 * i], v = pairs[2 * i + 1];
        if (m < 0 || (unsigned)m >= s->sc->mNumMeshes || v < 0 ||
            (unsigned)v >= s->sc->mMeshes[m]->mNumVertices)
            return FAIL("output vertex %d comes from mesh %d, vertex %d: not in the file", i, m, v);
        if (!mm[m].wbone) return FAIL("out of memory");
        if (mm[m].wbone[4 * v] < 0) return FAIL("mesh %d, vertex %d has no skin weight", m, v);
        const struct aiVector3D *x = &s->sc->mMeshes[m]->mVertices[v];
        const double *W = mm[m].W, p[3] = {x->x, x->y, x->z};
        for (int r = 0; r < 3; ++r) {
            a->rest[3 * i + r] = (float)(s->unit * (W[4 * r] * p[0] + W[4 * r + 1] * p[1] +
                                                    W[4 * r + 2] * p[2] + W[4 * r + 3]));
            if (!isfinite(a->rest[3 * i + r]))
                return FAIL("mesh %d, vertex %d is not finite in the bind pose", m, v);
        }
        memcpy(a->wbone + 4 * i, mm[m].wbone + 4 * v, 4 * sizeof(int32_t));
        memcpy(a->wgt + 4 * i, mm[m].wgt + 4 * v, 4 * sizeof(float));
    }
    return 1;
}

/* Render mesh: the blob's output vertices by the output map, its triangles as the blob's. */
static int map_render(imp *s, const sinew_blob *blob, vw_asset *a, char *err, size_t errlen) {
    const uint32_t nv = sinew_blob_surface_vertex_count(blob);
    const uint32_t nt = sinew_blob_surface_triangle_count(blob);
    const unsigned nm = s->sc->mNumMeshes;
    if (sinew_blob_source_mesh_count(blob) != nm)
        return FAIL("the blob was baked from %u meshes, the file has %u: not the file it was "
                    "baked from",
                    sinew_blob_source_mesh_count(blob), nm);
    if (nv == 0 || nv > (1u << 26) || nt > (1u << 26))
        return FAIL("the blob's surface has %u vertices (none, or too many)", nv);
    a->nverts = (int32_t)nv, a->ntris = (int32_t)nt;
    a->rest = malloc(sizeof(float) * 3 * nv);
    a->tris = malloc(sizeof(uint32_t) * 3 * (nt ? nt : 1));
    a->wbone = malloc(sizeof(int32_t) * 4 * nv);
    a->wgt = malloc(sizeof(float) * 4 * nv);
    int32_t *pairs = malloc(sizeof(int32_t) * 2 * nv);
    mesh_map *mm = calloc(nm ? nm : 1, sizeof *mm);
    int ok = a->rest && a->tris && a->wbone && a->wgt && pairs && mm;
    if (!ok) ok = FAIL("out of memory");
    if (ok && sinew_blob_surface_triangles(blob, a->tris, 3 * nt) != SINEW_OK)
        ok = FAIL("cannot read the blob's triangles");
    sinew_result r = ok ? sinew_blob_output_sources(blob, pairs, 2 * nv) : SINEW_OK;
    if (ok && r != SINEW_OK)
        ok = FAIL("the blob has no output map (%s): bake it again", sinew_result_string(r));
    for (unsigned m = 0; m < nm && ok; ++m) {
        const struct aiMesh *me = s->sc->mMeshes[m];
        mm[m].wbone = malloc(sizeof(int32_t) * 4 * (me->mNumVertices + 1));
        mm[m].wgt = malloc(sizeof(float) * 4 * (me->mNumVertices + 1));
        if (!mm[m].wbone || !mm[m].wgt)
            ok = FAIL("out of memory");
        else if (me->mNumBones)
            ok = map_skinned(s, blob, m, &mm[m], a->nbones, err, errlen);
        else {
            for (unsigned v = 0; v < me->mNumVertices; ++v)
                mm[m].wbone[4 * v] = -1; /* a mesh no output vertex needs may hang anywhere */
            int used = 0;
            for (uint32_t i = 0; i < nv && !used; ++i)
                used = pairs[2 * i] == (int32_t)m;
            if (used) ok = map_rigid(s, m, &mm[m], err, errlen);
        }
    }
    if (ok) ok = place_outputs(s, pairs, mm, a, err, errlen);
    for (unsigned m = 0; mm && m < nm; ++m)
        free(mm[m].wbone), free(mm[m].wgt);
    free(mm), free(pairs);
    return ok;
}

/* Keys: positions and scales linear, rotations by shortest-path slerp; before the first
 * key the first value holds, after the last the last (the bake samples them so too). */
static unsigned key_before(const void *keys, size_t stride, unsigned n, double t) {
    unsigned lo = 0, hi = n;
    while (lo < hi) {
        unsigned mid = lo + (hi - lo) / 2;
        if (*(const double *)((const char *)keys + (size_t)mid * stride) <= t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo ? lo - 1 : 0;
}

static double frac(double ta, double tb, double t) {
    return t > ta && tb > ta ? fmin(1.0, (t - ta) / (tb - ta)) : 0.0;
}

static void sample_vec(const struct aiVectorKey *k, unsigned n, double t, double *o) {
    unsigned i = key_before(k, sizeof *k, n, t), j = i + 1 < n ? i + 1 : i;
    double u = frac(k[i].mTime, k[j].mTime, t);
    o[0] = (1 - u) * k[i].mValue.x + u * k[j].mValue.x;
    o[1] = (1 - u) * k[i].mValue.y + u * k[j].mValue.y;
    o[2] = (1 - u) * k[i].mValue.z + u * k[j].mValue.z;
}

static void sample_quat(const struct aiQuatKey *k, unsigned n, double t, double *o) {
    unsigned i = key_before(k, sizeof *k, n, t), j = i + 1 < n ? i + 1 : i;
    const struct aiQuaternion *qa = &k[i].mValue, *qb = &k[j].mValue;
    const double a[4] = {qa->w, qa->x, qa->y, qa->z}, b[4] = {qb->w, qb->x, qb->y, qb->z};
    vw_quat_slerp(a, b, frac(k[i].mTime, k[j].mTime, t), o);
}

/* A node's local transform as translation, rotation and scale (its node pose's). */
static void trs_of(const double *m, vw_trs *o) {
    double R[9];
    for (int k = 0; k < 3; ++k) {
        o->s[k] = sqrt(m[k] * m[k] + m[4 + k] * m[4 + k] + m[8 + k] * m[8 + k]);
        for (int r = 0; r < 3; ++r)
            R[3 * r + k] = o->s[k] > 1e-300 ? m[4 * r + k] / o->s[k] : (r == k);
        o->t[k] = m[4 * k + 3];
    }
    vw_quat_from_matrix(R, o->q);
}

static void trs_matrix(const vw_trs *l, double *m) {
    double Q[9];
    vw_quat_matrix(l->q, Q);
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k)
            m[4 * r + k] = Q[3 * r + k] * l->s[k];
        m[4 * r + 3] = l->t[r];
    }
    m[12] = m[13] = m[14] = 0, m[15] = 1;
}

/* Globals from locals (4x4 each), parents first (the nodes are in depth-first order). */
static void globals(const imp *s, const double *L, double *G) {
    for (int32_t i = 0; i < s->nn; ++i)
        if (s->parent[i] < 0)
            memcpy(G + 16 * i, L + 16 * i, 16 * sizeof(double));
        else
            m4_mul(G + 16 * s->parent[i], L + 16 * i, G + 16 * i);
}

static int build_nodes(imp *s) {
    int32_t cap = 64, top = 0;
    const struct aiNode **stack = malloc(sizeof *stack * 4096);
    int32_t *spar = malloc(sizeof *spar * 4096);
    s->node = malloc(sizeof *s->node * (size_t)cap);
    s->parent = malloc(sizeof *s->parent * (size_t)cap);
    if (!stack || !spar || !s->node || !s->parent) goto fail;
    stack[top] = s->sc->mRootNode, spar[top++] = -1;
    while (top) {
        const struct aiNode *nd = stack[--top];
        int32_t par = spar[top];
        if (s->nn == cap) {
            cap *= 2;
            const struct aiNode **a = realloc(s->node, sizeof *a * (size_t)cap);
            int32_t *b = a ? realloc(s->parent, sizeof *b * (size_t)cap) : NULL;
            if (a) s->node = a;
            if (!a || !b) goto fail;
            s->parent = b;
        }
        s->node[s->nn] = nd, s->parent[s->nn] = par;
        int32_t self = s->nn++;
        if (top + (int32_t)nd->mNumChildren > 4096) goto fail;
        for (unsigned c = nd->mNumChildren; c-- > 0;) /* first child popped first */
            stack[top] = nd->mChildren[c], spar[top++] = self;
    }
    free(stack), free(spar);
    double *L = malloc(sizeof(double) * 16 * (size_t)s->nn);
    s->G = malloc(sizeof(double) * 16 * (size_t)s->nn);
    s->rest_trs = malloc(sizeof *s->rest_trs * (size_t)s->nn);
    int ok = L && s->G && s->rest_trs;
    for (int32_t i = 0; ok && i < s->nn; ++i) {
        m4_ai(&s->node[i]->mTransformation, L + 16 * i);
        trs_of(L + 16 * i, &s->rest_trs[i]);
    }
    if (ok) globals(s, L, s->G);
    free(L);
    return ok;
fail:
    free(stack), free(spar);
    return 0;
}

/* Every node's local transform in `clip` at t seconds (looped): its channel's keys over
 * its node pose. */
static int asset_sample(const vw_asset *a, int clip, double t, vw_trs *local) {
    const imp *s = a->impl;
    if (clip < 0 || clip >= a->nclips) return 0;
    const double dur = a->clip_duration[clip];
    t = dur > 0 ? fmod(t, dur) : 0;
    if (t < 0) t += dur;
    const double tick = t * s->tps[clip];
    const struct aiNodeAnim *const *ch = s->chan + (size_t)clip * s->nn;
    for (int32_t i = 0; i < s->nn; ++i) {
        const struct aiNodeAnim *c = ch[i];
        local[i] = s->rest_trs[i];
        if (!c) continue;
        if (c->mNumPositionKeys)
            sample_vec(c->mPositionKeys, c->mNumPositionKeys, tick, local[i].t);
        if (c->mNumScalingKeys) sample_vec(c->mScalingKeys, c->mNumScalingKeys, tick, local[i].s);
        if (c->mNumRotationKeys)
            sample_quat(c->mRotationKeys, c->mNumRotationKeys, tick, local[i].q);
    }
    return 1;
}

/* Bone b's transform: its node's global times the inverse of the blob's bind pose, in
 * the blob's units. */
static int asset_compose(const vw_asset *a, const vw_trs *local, float *out) {
    const imp *s = a->impl;
    double *L = malloc(sizeof(double) * 32 * (size_t)s->nn), *G = L + 16 * (size_t)s->nn;
    if (!L) return 0;
    for (int32_t i = 0; i < s->nn; ++i)
        trs_matrix(&local[i], L + 16 * i);
    globals(s, L, G);
    for (int32_t b = 0; b < a->nbones; ++b) {
        double M[16];
        m4_mul(G + 16 * s->bone_node[b], s->Binv + 16 * b, M);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c)
                out[12 * b + 3 * r + c] = (float)M[4 * r + c];
            out[12 * b + 9 + r] = (float)(M[4 * r + 3] * s->unit);
        }
    }
    free(L);
    return 1;
}

static int asset_pose(const vw_asset *a, int clip, double t, float *out) {
    vw_trs *local = malloc(sizeof *local * (size_t)a->nnodes);
    int ok = local && asset_sample(a, clip, t, local) && asset_compose(a, local, out);
    free(local);
    return ok;
}

static void asset_release(vw_asset *a) {
    imp *s = a->impl;
    if (!s) return;
    free(s->node), free(s->parent), free(s->G), free(s->node_bone), free(s->bone_node);
    free(s->Binv), free(s->chan), free(s->rest_trs);
    if (s->sc) aiReleaseImport(s->sc);
    free(s);
}

/* The channels of every clip: a channel drives the first node of its name, or a joint of
 * that name when there is one. */
static int build_clips(imp *s, vw_asset *a) {
    const struct aiScene *sc = s->sc;
    a->nclips = sc->mNumAnimations < VW_MAX_CLIPS ? (int32_t)sc->mNumAnimations : VW_MAX_CLIPS;
    s->chan = calloc((size_t)(a->nclips ? a->nclips : 1) * (size_t)s->nn, sizeof *s->chan);
    if (!s->chan) return 0;
    for (int32_t k = 0; k < a->nclips; ++k) {
        const struct aiAnimation *an = sc->mAnimations[k];
        s->tps[k] = an->mTicksPerSecond > 0 ? an->mTicksPerSecond : 25.0;
        a->clip_duration[k] = isfinite(an->mDuration) ? an->mDuration / s->tps[k] : 0;
        if (an->mName.data[0])
            snprintf(a->clip_names[k], sizeof a->clip_names[k], "%.63s", an->mName.data);
        else
            snprintf(a->clip_names[k], sizeof a->clip_names[k], "clip%d", k);
        for (unsigned c = 0; c < an->mNumChannels; ++c) {
            int32_t hit = -1;
            for (int32_t i = 0; i < s->nn; ++i)
                if (!strcmp(s->node[i]->mName.data, an->mChannels[c]->mNodeName.data) &&
                    (hit < 0 || (s->node_bone[i] >= 0 && s->node_bone[hit] < 0)))
                    hit = i;
            if (hit >= 0 && !s->chan[(size_t)k * s->nn + hit])
                s->chan[(size_t)k * s->nn + hit] = an->mChannels[c];
        }
    }
    return 1;
}

/* The file's unit in metres: glTF is in metres; FBX says how many centimetres its unit is. */
static double file_unit(const struct aiScene *sc, int gltf) {
    const struct aiMetadata *md = sc->mMetaData;
    if (gltf || !md) return 1;
    for (unsigned i = 0; i < md->mNumProperties; ++i) {
        if (strcmp(md->mKeys[i].data, "UnitScaleFactor") || !md->mValues[i].mData) continue;
        double f = md->mValues[i].mType == AI_FLOAT    ? *(const float *)md->mValues[i].mData
                   : md->mValues[i].mType == AI_DOUBLE ? *(const double *)md->mValues[i].mData
                                                       : 0;
        return isfinite(f) && f > 0 ? 0.01 * f : 1;
    }
    return 1;
}

/* The whole file (at most 1 GiB; the caller frees it), or NULL. */
static char *read_all(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    long len = f && !fseek(f, 0, SEEK_END) ? ftell(f) : -1;
    char *data = len >= 0 && len <= (1L << 30) && !fseek(f, 0, SEEK_SET)
                     ? malloc(len ? (size_t)len : 1)
                     : NULL;
    if (data && fread(data, 1, (size_t)len, f) != (size_t)len) free(data), data = NULL;
    if (f) fclose(f);
    *n = data ? (size_t)len : 0;
    return data;
}

/* The file as shipped against the one the blob was baked from: a changed file plays, but
 * an engine would bake it again. */
static void check_provenance(const char *path, const char *data, size_t n, const sinew_blob *blob) {
    sinew_blob_provenance p;
    p.struct_size = sizeof p;
    if (sinew_blob_get_provenance(blob, &p) == SINEW_OK &&
        sinew_hash_bytes(data, n) != p.source_hash)
        fprintf(stderr,
                "sinew-view: warning: %s differs from the file the blob was baked from "
                "(bake it again)\n",
                path);
}

/* Debian's assimp 5.2.5 crashes on some glTF structures that are legal or merely
 * malformed (a skin without inverse bind matrices, an index past its array: see
 * gltf_precheck.c); the bake refuses them before assimp reads the bytes, and so must a
 * host importing through the same assimp (fuzz_view_asset found the first). */
static int safe_for_assimp(const char *path, const char *data, size_t n, int binary, char *err,
                           size_t errlen) {
    sw_error e;
    sw_error_clear(&e);
    if (sw_gltf_precheck(data, n, binary, path, &e) == SINEW_OK) return 1;
    snprintf(err, errlen, "%s", e.msg);
    return 0;
}

int vw_asset_import(const char *path, const sinew_blob *blob, vw_asset *a, char *err,
                    size_t errlen) {
    memset(a, 0, sizeof *a);
    size_t nbytes = 0;
    char *bytes = read_all(path, &nbytes);
    if (!bytes) return FAIL("%s: cannot read (or larger than 1 GiB)", path);
    const char *dot = strrchr(path, '.');
    char ext[8] = {0};
    for (int i = 0; dot && dot[i + 1] && i < 7; ++i)
        ext[i] = (char)tolower((unsigned char)dot[i + 1]);
    int gltf = !strcmp(ext, "gltf") || !strcmp(ext, "glb");
    if (gltf && !safe_for_assimp(path, bytes, nbytes, !strcmp(ext, "glb"), err, errlen)) {
        free(bytes);
        return 0;
    }
    unsigned flags = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
    /* FBX is unrolled one vertex per face corner; the bake welds it back, and so must we
     * (the output map's vertex indices are the welded mesh's) */
    if (!gltf) flags |= aiProcess_JoinIdenticalVertices;
    imp *s = calloc(1, sizeof *s);
    if (!s) {
        free(bytes);
        return FAIL("out of memory");
    }
    a->impl = s, a->release = asset_release, a->pose = asset_pose;
    a->sample = asset_sample, a->compose = asset_compose;
    sw_error e;
    sw_error_clear(&e);
    if (sw_assimp_trial(path, NULL, 0, NULL, flags, SW_ASSIMP_TRIAL_SECONDS, path, &e) !=
        SINEW_OK) {
        snprintf(err, errlen, "%s", e.msg);
        vw_asset_free(a);
        free(bytes);
        return 0;
    }
    s->sc = aiImportFile(path, flags);
    if (!s->sc || !s->sc->mRootNode || (s->sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        snprintf(err, errlen, "%s: assimp could not read it: %s", path, aiGetErrorString());
        vw_asset_free(a);
        free(bytes);
        return 0;
    }
    s->unit = file_unit(s->sc, gltf);
    int ok = build_nodes(s);
    if (!ok) snprintf(err, errlen, "%s: out of memory, or a node tree deeper than 4096", path);
    a->nnodes = s->nn;
    char why[400] = "";
    ok = ok && map_skeleton(s, blob, &a->nbones, why, sizeof why) &&
         map_render(s, blob, a, why, sizeof why);
    if (why[0]) snprintf(err, errlen, "%s: %s", path, why);
    if (ok && (!build_clips(s, a) || !vw_asset_weld(a))) ok = FAIL("out of memory");
    if (ok) check_provenance(path, bytes, nbytes, blob);
    if (!ok) vw_asset_free(a);
    free(bytes);
    return ok;
}

void vw_asset_free(vw_asset *a) {
    if (a->release) a->release(a);
    free(a->rest), free(a->tris), free(a->wbone), free(a->wgt), free(a->weld);
    memset(a, 0, sizeof *a);
}
