/* The character as an engine imports it: assimp reads the file, and the viewer builds its
 * skeleton, render mesh, weights and clips the way the bake's import did (the bake is
 * precompute/import/scene_import.c; the viewer links only the runtime, so it repeats the
 * rules here).
 *
 * Bone order. The blob carries no bone names yet, so a host cannot map its skeleton by
 * name: it must reproduce the bake's order. That order is the skin joints' nodes in
 * depth-first node order (first child first). When the blob gains bone names the mapping
 * below becomes a lookup by name and this file stops depending on the bake's rules.
 *
 * Vertex order. The output surface is the render mesh in the import's order: each
 * skinned aiMesh in mesh order, then each boneless mesh shown below a joint (a rigid
 * prop), in node order. A UV seam's duplicate vertices stay separate (the blob welds
 * them to one position and normal, which the host does not need to know).
 *
 * Bind space (glTF 2.0 3.7.3.3): a glTF skin ignores the mesh node's transform, so a
 * mesh's bind space is placed at W = G_r IBM_r of its first joint r; other formats place
 * it by the mesh node. A bone's bind global is B = W offset^-1 and its transform at time
 * t is G(t) B^-1. */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "viewer.h"

typedef struct imp {
    const struct aiScene *sc;
    int32_t nn;                 /* nodes, depth-first */
    const struct aiNode **node; /* nn */
    int32_t *parent;            /* nn */
    double *G;                  /* 16 nn: node-pose globals */
    int32_t *node_bone;         /* nn: bone or -1 */
    int32_t *bone_node;         /* nbones */
    double *Binv;               /* 16 nbones */
    int gltf;
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
    s->G = malloc(sizeof(double) * 16 * (size_t)s->nn);
    if (!s->G) return 0;
    for (int32_t i = 0; i < s->nn; ++i) {
        double L[16];
        m4_ai(&s->node[i]->mTransformation, L);
        if (s->parent[i] < 0)
            memcpy(s->G + 16 * i, L, sizeof L);
        else
            m4_mul(s->G + 16 * s->parent[i], L, s->G + 16 * i);
    }
    return 1;
fail:
    free(stack), free(spar);
    return 0;
}

/* The node of an aiBone: names tie them, and names repeat (a mesh node named after the
 * joint that carries it), so among equal names take the node whose global is nearest the
 * bone's bind transform W0 offset^-1 (as the bake does). */
static int32_t bone_node_of(const imp *s, const double *W0, const struct aiBone *bone) {
    int32_t best = -1, count = 0;
    for (int32_t i = 0; i < s->nn; ++i)
        if (!strcmp(s->node[i]->mName.data, bone->mName.data)) {
            if (best < 0) best = i;
            count++;
        }
    if (count < 2) return best;
    double O[16], Oi[16], B[16], dbest = INFINITY;
    m4_ai(&bone->mOffsetMatrix, O);
    if (!m4_inv(O, Oi)) return best;
    m4_mul(W0, Oi, B);
    for (int32_t i = 0; i < s->nn; ++i) {
        if (strcmp(s->node[i]->mName.data, bone->mName.data)) continue;
        double d = 0;
        for (int k = 0; k < 16; ++k)
            d += (s->G[16 * i + k] - B[k]) * (s->G[16 * i + k] - B[k]);
        if (d < dbest) dbest = d, best = i;
    }
    return best;
}

static int32_t joint_at_or_above(const imp *s, int32_t i) {
    for (; i >= 0; i = s->parent[i])
        if (s->node_bone[i] >= 0) return s->node_bone[i];
    return -1;
}

#define FAIL(...) (snprintf(err, errlen, __VA_ARGS__), 0)

/* Skeleton: W per mesh, each bone's node, bones in node order, B^-1. */
static int build_skeleton(imp *s, double *W, int32_t *nbones, char *err, size_t errlen) {
    const struct aiScene *sc = s->sc;
    static const double I[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    int gltf = s->gltf;
    int32_t *offset_mesh = malloc(sizeof(int32_t) * (size_t)s->nn);
    double *offset = malloc(sizeof(double) * 16 * (size_t)s->nn);
    s->node_bone = malloc(sizeof(int32_t) * (size_t)s->nn);
    if (!offset_mesh || !offset || !s->node_bone) {
        free(offset_mesh), free(offset);
        return FAIL("out of memory");
    }
    for (int32_t i = 0; i < s->nn; ++i)
        offset_mesh[i] = -1, s->node_bone[i] = -1;
    int ok = 1;
    for (unsigned m = 0; m < sc->mNumMeshes && ok; ++m) {
        const struct aiMesh *me = sc->mMeshes[m];
        int32_t mesh_node = -1;
        for (int32_t i = 0; i < s->nn && mesh_node < 0; ++i)
            for (unsigned k = 0; k < s->node[i]->mNumMeshes; ++k)
                if (s->node[i]->mMeshes[k] == m) mesh_node = i;
        memcpy(W + 16 * m, gltf || mesh_node < 0 ? I : s->G + 16 * mesh_node, sizeof I);
        int32_t first = -1;
        unsigned first_bone = 0;
        for (unsigned b = 0; b < me->mNumBones && ok; ++b) {
            int32_t i = bone_node_of(s, W + 16 * m, me->mBones[b]);
            if (i < 0)
                ok = FAIL("bone '%s' of mesh %u has no node", me->mBones[b]->mName.data, m);
            else if (first < 0 || i < first)
                first = i, first_bone = b;
            if (i >= 0 && offset_mesh[i] < 0) {
                m4_ai(&me->mBones[b]->mOffsetMatrix, offset + 16 * i);
                offset_mesh[i] = (int32_t)m;
            }
        }
        if (ok && gltf && first >= 0) {
            double O[16];
            m4_ai(&me->mBones[first_bone]->mOffsetMatrix, O);
            m4_mul(s->G + 16 * first, O, W + 16 * m);
        }
    }
    int32_t nb = 0;
    for (int32_t i = 0; i < s->nn; ++i)
        if (offset_mesh[i] >= 0) s->node_bone[i] = nb++;
    if (ok && nb == 0) ok = FAIL("no skinned mesh (no mesh has bones): not a rigged character");
    if (ok && nb > VW_MAX_BONES) ok = FAIL("%d joints, at most %d", nb, VW_MAX_BONES);
    s->bone_node = ok ? malloc(sizeof(int32_t) * (size_t)nb) : NULL;
    s->Binv = ok ? malloc(sizeof(double) * 16 * (size_t)nb) : NULL;
    if (ok && (!s->bone_node || !s->Binv)) ok = FAIL("out of memory");
    for (int32_t i = 0; i < s->nn && ok; ++i) {
        int32_t b = s->node_bone[i];
        if (b < 0) continue;
        s->bone_node[b] = i;
        double oinv[16], B[16];
        if (!m4_inv(offset + 16 * i, oinv)) {
            ok = FAIL("joint '%s' has a singular inverse bind matrix", s->node[i]->mName.data);
            break;
        }
        m4_mul(W + 16 * offset_mesh[i], oinv, B);
        if (!m4_inv(B, s->Binv + 16 * b))
            ok = FAIL("joint '%s' has a singular bind transform", s->node[i]->mName.data);
    }
    free(offset_mesh), free(offset);
    *nbones = nb;
    return ok;
}

static void add_vertices(const struct aiMesh *me, const double *M, double k, float *x) {
    for (unsigned v = 0; v < me->mNumVertices; ++v) {
        const double p[3] = {me->mVertices[v].x, me->mVertices[v].y, me->mVertices[v].z};
        for (int r = 0; r < 3; ++r)
            x[3 * v + r] = (float)(k * (M[4 * r] * p[0] + M[4 * r + 1] * p[1] +
                                        M[4 * r + 2] * p[2] + M[4 * r + 3]));
    }
}

static int32_t add_tris(const struct aiMesh *me, uint32_t base, uint32_t *t) {
    int32_t n = 0;
    for (unsigned f = 0; f < me->mNumFaces; ++f) {
        if (me->mFaces[f].mNumIndices != 3) continue; /* points and lines */
        for (int c = 0; c < 3; ++c)
            if (t) t[3 * n + c] = base + me->mFaces[f].mIndices[c];
        n++;
    }
    return n;
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

/* Render mesh and weights: skinned meshes in mesh order, then rigid props in node order. */
static int build_render(imp *s, const double *W, vw_asset *a, char *err, size_t errlen) {
    const struct aiScene *sc = s->sc;
    int64_t nv = 0, nt = 0;
    for (int pass = 0; pass < 2; ++pass) {
        int32_t base = 0, tbase = 0;
        double *dense = NULL;
        for (unsigned m = 0; m < sc->mNumMeshes; ++m) {
            const struct aiMesh *me = sc->mMeshes[m];
            if (!me->mNumBones) continue;
            if (pass) {
                add_vertices(me, W + 16 * m, s->unit, a->rest + 3 * (size_t)base);
                add_tris(me, (uint32_t)base, a->tris + 3 * (size_t)tbase);
                dense = calloc((size_t)me->mNumVertices * (size_t)a->nbones, sizeof(double));
                if (!dense) return FAIL("out of memory");
                for (unsigned k = 0; k < me->mNumBones; ++k) {
                    const struct aiBone *bone = me->mBones[k];
                    int32_t b = s->node_bone[bone_node_of(s, W + 16 * m, bone)];
                    for (unsigned j = 0; j < bone->mNumWeights; ++j)
                        if (bone->mWeights[j].mVertexId < me->mNumVertices && b >= 0)
                            dense[(size_t)bone->mWeights[j].mVertexId * a->nbones + b] +=
                                bone->mWeights[j].mWeight;
                }
                for (unsigned v = 0; v < me->mNumVertices; ++v)
                    if (!top4(dense + (size_t)v * a->nbones, a->nbones, a->wbone + 4 * (base + v),
                              a->wgt + 4 * (base + v))) {
                        free(dense);
                        return FAIL("mesh %u, vertex %u has no skin weight", m, v);
                    }
                free(dense);
            }
            base += (int32_t)me->mNumVertices, tbase += add_tris(me, 0, NULL);
        }
        for (int32_t i = 0; i < s->nn; ++i) {
            int32_t b = joint_at_or_above(s, i);
            for (unsigned k = 0; k < s->node[i]->mNumMeshes && b >= 0; ++k) {
                const struct aiMesh *me = sc->mMeshes[s->node[i]->mMeshes[k]];
                if (me->mNumBones) continue;
                if (pass) {
                    add_vertices(me, s->G + 16 * i, s->unit, a->rest + 3 * (size_t)base);
                    add_tris(me, (uint32_t)base, a->tris + 3 * (size_t)tbase);
                    for (unsigned v = 0; v < me->mNumVertices; ++v) {
                        int32_t *wb = a->wbone + 4 * (base + v);
                        float *ww = a->wgt + 4 * (base + v);
                        wb[0] = b, wb[1] = wb[2] = wb[3] = 0;
                        ww[0] = 1, ww[1] = ww[2] = ww[3] = 0;
                    }
                }
                base += (int32_t)me->mNumVertices, tbase += add_tris(me, 0, NULL);
            }
        }
        nv = base, nt = tbase;
        if (pass) break;
        if (nv == 0 || nv > (1 << 26) || nt > (1 << 26))
            return FAIL("%lld render vertices (none, or too many)", (long long)nv);
        a->nverts = (int32_t)nv, a->ntris = (int32_t)nt;
        a->rest = malloc(sizeof(float) * 3 * (size_t)nv);
        a->tris = malloc(sizeof(uint32_t) * 3 * (size_t)(nt ? nt : 1));
        a->wbone = malloc(sizeof(int32_t) * 4 * (size_t)nv);
        a->wgt = malloc(sizeof(float) * 4 * (size_t)nv);
        if (!a->rest || !a->tris || !a->wbone || !a->wgt) return FAIL("out of memory");
    }
    return 1;
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
    double u = frac(k[i].mTime, k[j].mTime, t);
    const struct aiQuaternion *qa = &k[i].mValue, *qb = &k[j].mValue;
    double a[4] = {qa->w, qa->x, qa->y, qa->z}, b[4] = {qb->w, qb->x, qb->y, qb->z};
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], wa = 1 - u, wb = u, nrm = 0;
    if (d < 0)
        for (int c = 0; c < 4; ++c)
            b[c] = -b[c];
    d = fabs(d);
    if (d < 0.9995) {
        double th = acos(fmin(1.0, d)), s = sin(th);
        wa = sin((1 - u) * th) / s, wb = sin(u * th) / s;
    }
    for (int c = 0; c < 4; ++c)
        o[c] = wa * a[c] + wb * b[c], nrm += o[c] * o[c];
    nrm = sqrt(nrm);
    for (int c = 0; c < 4; ++c)
        o[c] = nrm > 1e-12 ? o[c] / nrm : (c == 0);
}

/* A node's local transform: its channel's keys over its bind TRS. */
static void node_local(const imp *s, int32_t i, const struct aiNodeAnim *c, double t, double *m) {
    m4_ai(&s->node[i]->mTransformation, m);
    if (!c) return;
    double tr[3], q[4] = {1, 0, 0, 0}, sc[3], R[9];
    for (int k = 0; k < 3; ++k) {
        sc[k] = sqrt(m[k] * m[k] + m[4 + k] * m[4 + k] + m[8 + k] * m[8 + k]);
        for (int r = 0; r < 3; ++r)
            R[3 * r + k] = sc[k] > 1e-300 ? m[4 * r + k] / sc[k] : (r == k);
        tr[k] = m[4 * k + 3];
    }
    double tq = R[0] + R[4] + R[8], k4;
    if (tq > 0) {
        k4 = 2 * sqrt(tq + 1);
        q[0] = 0.25 * k4, q[1] = (R[7] - R[5]) / k4, q[2] = (R[2] - R[6]) / k4,
        q[3] = (R[3] - R[1]) / k4;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[0] - R[4] - R[8]));
        q[0] = (R[7] - R[5]) / k4, q[1] = 0.25 * k4, q[2] = (R[1] + R[3]) / k4,
        q[3] = (R[2] + R[6]) / k4;
    } else if (R[4] > R[8]) {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[4] - R[0] - R[8]));
        q[0] = (R[2] - R[6]) / k4, q[1] = (R[1] + R[3]) / k4, q[2] = 0.25 * k4,
        q[3] = (R[5] + R[7]) / k4;
    } else {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[8] - R[0] - R[4]));
        q[0] = (R[3] - R[1]) / k4, q[1] = (R[2] + R[6]) / k4, q[2] = (R[5] + R[7]) / k4,
        q[3] = 0.25 * k4;
    }
    if (c->mNumPositionKeys) sample_vec(c->mPositionKeys, c->mNumPositionKeys, t, tr);
    if (c->mNumScalingKeys) sample_vec(c->mScalingKeys, c->mNumScalingKeys, t, sc);
    if (c->mNumRotationKeys) sample_quat(c->mRotationKeys, c->mNumRotationKeys, t, q);
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double Q[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k)
            m[4 * r + k] = Q[3 * r + k] * sc[k];
        m[4 * r + 3] = tr[r];
    }
}

static int asset_pose(const vw_asset *a, int clip, double t, float *out) {
    const imp *s = a->impl;
    if (clip < 0 || clip >= a->nclips) return 0;
    double dur = a->clip_duration[clip];
    t = dur > 0 ? fmod(t, dur) : 0;
    if (t < 0) t += dur;
    double *G = malloc(sizeof(double) * 16 * (size_t)s->nn);
    if (!G) return 0;
    const struct aiNodeAnim *const *ch = s->chan + (size_t)clip * s->nn;
    for (int32_t i = 0; i < s->nn; ++i) {
        double L[16];
        node_local(s, i, ch[i], t * s->tps[clip], L);
        if (s->parent[i] < 0)
            memcpy(G + 16 * i, L, sizeof L);
        else
            m4_mul(G + 16 * s->parent[i], L, G + 16 * i);
    }
    for (int32_t b = 0; b < a->nbones; ++b) {
        double M[16];
        m4_mul(G + 16 * s->bone_node[b], s->Binv + 16 * b, M);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c)
                out[12 * b + 3 * r + c] = (float)M[4 * r + c];
            out[12 * b + 9 + r] = (float)(M[4 * r + 3] * s->unit);
        }
    }
    free(G);
    return 1;
}

static void asset_release(vw_asset *a) {
    imp *s = a->impl;
    if (!s) return;
    free(s->node), free(s->parent), free(s->G), free(s->node_bone), free(s->bone_node);
    free(s->Binv), free(s->chan);
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

int vw_asset_import(const char *path, vw_asset *a, char *err, size_t errlen) {
    memset(a, 0, sizeof *a);
    FILE *f = fopen(path, "rb");
    if (!f) return FAIL("%s: cannot open", path);
    fclose(f);
    const char *dot = strrchr(path, '.');
    char ext[8] = {0};
    for (int i = 0; dot && dot[i + 1] && i < 7; ++i)
        ext[i] = (char)tolower((unsigned char)dot[i + 1]);
    int gltf = !strcmp(ext, "gltf") || !strcmp(ext, "glb");
    unsigned flags = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
    /* FBX is unrolled one vertex per face corner; the bake welds it back, and so must we */
    if (!gltf) flags |= aiProcess_JoinIdenticalVertices;
    imp *s = calloc(1, sizeof *s);
    if (!s) return FAIL("out of memory");
    a->impl = s, a->release = asset_release, a->pose = asset_pose;
    s->gltf = gltf;
    s->sc = aiImportFile(path, flags);
    if (!s->sc || !s->sc->mRootNode || (s->sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        snprintf(err, errlen, "%s: assimp could not read it: %s", path, aiGetErrorString());
        vw_asset_free(a);
        return 0;
    }
    s->unit = file_unit(s->sc, gltf);
    double *W = malloc(sizeof(double) * 16 * (s->sc->mNumMeshes + 1));
    int ok = W && build_nodes(s);
    if (!ok) snprintf(err, errlen, "%s: out of memory, or a node tree deeper than 4096", path);
    ok = ok && build_skeleton(s, W, &a->nbones, err, errlen);
    ok = ok && build_render(s, W, a, err, errlen);
    if (ok && (!build_clips(s, a) || !vw_asset_weld(a))) ok = FAIL("out of memory");
    free(W);
    if (!ok) vw_asset_free(a);
    return ok;
}

void vw_asset_free(vw_asset *a) {
    if (a->release) a->release(a);
    free(a->rest), free(a->tris), free(a->wbone), free(a->wgt), free(a->weld);
    memset(a, 0, sizeof *a);
}
