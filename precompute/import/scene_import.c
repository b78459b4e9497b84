/* A rigged character from assimp's scene (sw_scene_build, scene_internal.h; the file is
 * read by scene_read.c): the node table, the skeleton from the skins' joints, the render
 * mesh and its weights; the clips are sampled by scene_clip.c.
 *
 * Bind space. glTF skins ignore the skinned mesh node's transform (glTF 2.0 §3.7.3.3): a
 * vertex v is skinned as sum_j w_j G_j IBM_j v, so v is already in world units at bind and
 * joint j's bind global is IBM_j^-1. Other formats (FBX) place the mesh by its node, and
 * assimp's offset matrix maps mesh space to bone space, so a vertex is W v with W the mesh
 * node's global transform and the joint's bind global is W offset_j^-1. Either way
 * B_j = W offset_j^-1 (W = I for glTF) and a bone's transform is G_j(t) B_j^-1. */
#include <assimp/cimport.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_attribute.h"
#include "scene_internal.h"

#define SW_SCENE_MAX_NODES (1 << 20)
#define SW_SCENE_MAX_VERTS (1 << 26)
#define SW_SCENE_MAX_WEIGHTS ((size_t)1 << 28) /* vertices x bones doubles (2 GiB) */

typedef struct scene_state {
    const struct aiScene *sc;
    const char *name; /* for messages */
    int gltf;
    sw_scene_nodes nodes;
    int32_t *mesh_node;   /* per aiMesh: first node that shows it, or -1 */
    double *W;            /* per aiMesh: 16, its bind space placed in the world */
    size_t *bone_base;    /* per aiMesh: where its bones start in bone_at */
    int32_t *bone_at;     /* per aiBone of every mesh: its node */
    int32_t *node_bone;   /* per node: its bone, or -1 */
    double *offset;       /* per node: 16, the first skin's offset matrix of a joint node */
    int32_t *offset_mesh; /* per node: the mesh that offset came from, -1: not a joint */
    int32_t nbones;
    int32_t *bone_node; /* per bone */
    double *B, *Binv;   /* per bone: 16, bind global transform and its inverse */
    const void *bytes;  /* a glTF's bytes (NULL for other formats), for what assimp drops */
    size_t nbytes;
    int binary;      /* the bytes are a .glb */
    const char *dir; /* the folder of a .gltf read from a path (its buffer files), or NULL */
} scene_state;

static void state_free(scene_state *s) {
    free(s->nodes.node);
    free(s->nodes.parent);
    free(s->nodes.G);
    free(s->mesh_node);
    free(s->W);
    free(s->bone_base);
    free(s->bone_at);
    free(s->node_bone);
    free(s->offset);
    free(s->offset_mesh);
    free(s->bone_node);
    free(s->B);
    free(s->Binv);
}

static sinew_result oom(scene_state *s, sw_error *err) {
    return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
}

/* The node table in depth-first order, with the file's node-pose global transforms. */
static sinew_result build_nodes(scene_state *s, sw_error *err) {
    sw_scene_nodes *n = &s->nodes;
    size_t cap = 64, top = 0;
    const struct aiNode **stack = malloc(cap * sizeof *stack);
    int32_t *stack_parent = malloc(cap * sizeof *stack_parent);
    n->node = malloc(cap * sizeof *n->node);
    n->parent = malloc(cap * sizeof *n->parent);
    size_t ncap = cap;
    sinew_result rc = SINEW_OK;
    if (!stack || !stack_parent || !n->node || !n->parent) goto nomem;
    stack[top] = s->sc->mRootNode, stack_parent[top++] = -1;
    while (top) {
        const struct aiNode *nd = stack[--top];
        int32_t par = stack_parent[top];
        if (n->n >= SW_SCENE_MAX_NODES) {
            rc = sw_error_set(err, SINEW_ERROR_CAPACITY, "%s: more than %d nodes", s->name,
                              SW_SCENE_MAX_NODES);
            goto done;
        }
        if ((size_t)n->n == ncap) {
            ncap *= 2;
            void *a = realloc(n->node, ncap * sizeof *n->node);
            if (a) n->node = a;
            void *b = realloc(n->parent, ncap * sizeof *n->parent);
            if (b) n->parent = b;
            if (!a || !b) goto nomem;
        }
        n->node[n->n] = nd;
        n->parent[n->n] = par;
        int32_t self = n->n++;
        if (top + nd->mNumChildren > cap) {
            while (top + nd->mNumChildren > cap)
                cap *= 2;
            void *a = realloc(stack, cap * sizeof *stack);
            if (a) stack = a;
            void *b = realloc(stack_parent, cap * sizeof *stack_parent);
            if (b) stack_parent = b;
            if (!a || !b) goto nomem;
        }
        for (unsigned c = nd->mNumChildren; c-- > 0;) /* first child popped first */
            stack[top] = nd->mChildren[c], stack_parent[top++] = self;
    }
    n->G = malloc(sizeof(double) * 16 * (size_t)n->n);
    if (!n->G) goto nomem;
    for (int32_t i = 0; i < n->n; ++i) {
        double L[16];
        if (!sw_m4_from_ai(&n->node[i]->mTransformation, L)) {
            rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                              "%s: node '%s' has a transform that is not finite", s->name,
                              n->node[i]->mName.data);
            goto done;
        }
        if (n->parent[i] < 0)
            memcpy(n->G + 16 * i, L, sizeof L);
        else
            sw_m4_mul(n->G + 16 * n->parent[i], L, n->G + 16 * i);
    }
    goto done;
nomem:
    rc = oom(s, err);
done:
    free(stack);
    free(stack_parent);
    return rc;
}

static int32_t find_node(const sw_scene_nodes *n, const char *name) {
    for (int32_t i = 0; i < n->n; ++i)
        if (!strcmp(n->node[i]->mName.data, name)) return i;
    return -1;
}

static void mesh_bind_world(const scene_state *s, unsigned m, double *W);

/* The node of a bone of mesh m. assimp ties bones to nodes by name only, and names repeat
 * (robot.glb: Blender named mesh objects after the bones that carry them: "Head" is a mesh
 * node and a joint), so among nodes of that name take the one whose node-pose global
 * transform is nearest the bone's bind transform W offset^-1 (W as place_meshes starts
 * it: the mesh node's for FBX, I for glTF). */
static int32_t find_bone_node(const scene_state *s, unsigned m, const struct aiBone *bone) {
    int32_t best = find_node(&s->nodes, bone->mName.data), second = -1;
    for (int32_t i = best + 1; best >= 0 && i < s->nodes.n && second < 0; ++i)
        if (!strcmp(s->nodes.node[i]->mName.data, bone->mName.data)) second = i;
    double O[16], W[16], Oinv[16], B[16];
    if (second < 0 || !sw_m4_from_ai(&bone->mOffsetMatrix, O) || !sw_m4_affine_inverse(O, Oinv))
        return best;
    mesh_bind_world(s, m, W);
    sw_m4_mul(W, Oinv, B);
    double dbest = INFINITY;
    for (int32_t i = best; i < s->nodes.n; ++i) {
        if (strcmp(s->nodes.node[i]->mName.data, bone->mName.data)) continue;
        double d = 0;
        for (int k = 0; k < 16; ++k)
            d += (s->nodes.G[16 * i + k] - B[k]) * (s->nodes.G[16 * i + k] - B[k]);
        if (d < dbest) dbest = d, best = i;
    }
    return best;
}

/* W of mesh m: the bind space's placement in the world (see the file comment). */
static void mesh_bind_world(const scene_state *s, unsigned m, double *W) {
    memcpy(W, s->W + 16 * m, 16 * sizeof(double));
}

/* Every mesh's W and every bone's node. FBX: the mesh node's global transform. glTF: the
 * mesh node does not count, and the skin's bind space is placed where the file's node
 * pose puts it: W = G_r IBM_r of the mesh's first joint r in node order (a rigid
 * transform when the node pose is the bind pose: the Z_UP node of COLLADA2GLTF exports,
 * SimpleSkin's shift by -0.5 in x). Bones are tied to nodes with W = I (find_bone_node). */
static sinew_result place_meshes(scene_state *s, sw_error *err) {
    static const double I[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const struct aiScene *sc = s->sc;
    size_t nbones = 0;
    s->W = malloc(sizeof(double) * 16 * (sc->mNumMeshes ? sc->mNumMeshes : 1));
    s->bone_base = malloc(sizeof(size_t) * (sc->mNumMeshes ? sc->mNumMeshes : 1));
    if (!s->W || !s->bone_base) return oom(s, err);
    for (unsigned m = 0; m < sc->mNumMeshes; ++m) {
        s->bone_base[m] = nbones;
        nbones += sc->mMeshes[m]->mNumBones;
        if (s->gltf || s->mesh_node[m] < 0)
            memcpy(s->W + 16 * m, I, sizeof I);
        else
            memcpy(s->W + 16 * m, s->nodes.G + 16 * s->mesh_node[m], sizeof I);
    }
    s->bone_at = malloc(sizeof(int32_t) * (nbones ? nbones : 1));
    if (!s->bone_at) return oom(s, err);
    for (unsigned m = 0; m < sc->mNumMeshes; ++m) {
        const struct aiMesh *me = sc->mMeshes[m];
        int32_t first = -1;
        unsigned first_bone = 0;
        for (unsigned b = 0; b < me->mNumBones; ++b) {
            int32_t i = find_bone_node(s, m, me->mBones[b]);
            if (i < 0)
                return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                    "%s: bone '%s' of mesh %u has no node", s->name,
                                    me->mBones[b]->mName.data, m);
            s->bone_at[s->bone_base[m] + b] = i;
            if (first < 0 || i < first) first = i, first_bone = b;
        }
        double O[16];
        if (!s->gltf || first < 0) continue;
        if (!sw_m4_from_ai(&me->mBones[first_bone]->mOffsetMatrix, O))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "%s: bone '%s' has an offset matrix that is not finite", s->name,
                                me->mBones[first_bone]->mName.data);
        sw_m4_mul(s->nodes.G + 16 * first, O, s->W + 16 * m);
    }
    return SINEW_OK;
}

/* Joints: every aiBone's node; bones in node order; B_j and its inverse. */
static sinew_result find_joints(scene_state *s, sw_error *err) {
    const struct aiScene *sc = s->sc;
    int32_t nn = s->nodes.n;
    s->mesh_node = malloc(sizeof(int32_t) * (sc->mNumMeshes ? sc->mNumMeshes : 1));
    s->node_bone = malloc(sizeof(int32_t) * (size_t)nn);
    s->offset = malloc(sizeof(double) * 16 * (size_t)nn);
    s->offset_mesh = malloc(sizeof(int32_t) * (size_t)nn);
    if (!s->mesh_node || !s->node_bone || !s->offset || !s->offset_mesh) return oom(s, err);
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        s->mesh_node[m] = -1;
    for (int32_t i = nn; i-- > 0;) /* backwards: the first node that shows a mesh wins */
        for (unsigned k = 0; k < s->nodes.node[i]->mNumMeshes; ++k)
            if (s->nodes.node[i]->mMeshes[k] < sc->mNumMeshes)
                s->mesh_node[s->nodes.node[i]->mMeshes[k]] = i;
    for (int32_t i = 0; i < nn; ++i)
        s->offset_mesh[i] = -1, s->node_bone[i] = -1;
    sinew_result rc = place_meshes(s, err);
    if (rc) return rc;
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        for (unsigned b = 0; b < sc->mMeshes[m]->mNumBones; ++b) {
            const struct aiBone *bone = sc->mMeshes[m]->mBones[b];
            int32_t i = s->bone_at[s->bone_base[m] + b];
            if (s->offset_mesh[i] >= 0) continue; /* (later skins of the joint agree or lose) */
            if (!sw_m4_from_ai(&bone->mOffsetMatrix, s->offset + 16 * i))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "%s: bone '%s' has an offset matrix that is not finite",
                                    s->name, bone->mName.data);
            s->offset_mesh[i] = (int32_t)m;
        }
    for (int32_t i = 0; i < nn; ++i)
        if (s->offset_mesh[i] >= 0) s->node_bone[i] = s->nbones++;
    s->nodes.node_bone = s->node_bone;
    if (s->nbones == 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: no skinned mesh (no mesh has bones): not a rigged character",
                            s->name);
    if (s->nbones > SW_MAX_BONES)
        return sw_error_set(err, SINEW_ERROR_CAPACITY, "%s: %d joints, at most %d", s->name,
                            s->nbones, SW_MAX_BONES);
    s->bone_node = malloc(sizeof(int32_t) * (size_t)s->nbones);
    s->B = malloc(sizeof(double) * 16 * (size_t)s->nbones);
    s->Binv = malloc(sizeof(double) * 16 * (size_t)s->nbones);
    if (!s->bone_node || !s->B || !s->Binv) return oom(s, err);
    for (int32_t i = 0; i < nn; ++i) {
        int32_t b = s->node_bone[i];
        if (b < 0) continue;
        s->bone_node[b] = i;
        double W[16], oinv[16];
        mesh_bind_world(s, (unsigned)s->offset_mesh[i], W);
        if (!sw_m4_affine_inverse(s->offset + 16 * i, oinv))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "%s: joint '%s' has a singular inverse bind matrix", s->name,
                                s->nodes.node[i]->mName.data);
        sw_m4_mul(W, oinv, s->B + 16 * b);
        if (!sw_m4_affine_inverse(s->B + 16 * b, s->Binv + 16 * b))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "%s: joint '%s' has a singular bind transform", s->name,
                                s->nodes.node[i]->mName.data);
    }
    return SINEW_OK;
}

/* A name cut to 63 bytes and terminated. */
static void copy_name(char dst[64], const char *src) {
    size_t n = strnlen(src, 63);
    memcpy(dst, src, n);
    dst[n] = 0;
}

/* The nearest joint at or above node i, as a bone index, or -1. */
static int32_t joint_at_or_above(const scene_state *s, int32_t i) {
    for (; i >= 0; i = s->nodes.parent[i])
        if (s->node_bone[i] >= 0) return s->node_bone[i];
    return -1;
}

/* Heads at the bind globals' origins; tails at the mean of the child joints' heads, or
 * (leaves, and bones whose children sit on their head) a quarter of the parent bone's
 * length further along it, or (no parent bone) 5% of the render mesh's size up +Y. Runs
 * after build_render (the size). */
static sinew_result build_skeleton(scene_state *s, sw_imported_character *out, sw_error *err) {
    int32_t nb = s->nbones;
    sw_skeleton *k = &out->skel;
    k->joints = calloc(6 * (size_t)nb, sizeof(double));
    k->bones = malloc(sizeof(int32_t) * 2 * (size_t)nb);
    k->parent = malloc(sizeof(int32_t) * (size_t)nb);
    out->bone_names = calloc((size_t)nb, sizeof *out->bone_names);
    out->bone_bind = malloc(12 * sizeof(double) * (size_t)nb);
    int32_t *nchild = calloc((size_t)nb, sizeof(int32_t));
    if (!k->joints || !k->bones || !k->parent || !out->bone_names || !out->bone_bind || !nchild) {
        free(nchild);
        return oom(s, err);
    }
    k->njoints = 2 * nb;
    k->nbones = nb;
    double lo[3], hi[3];
    for (int32_t b = 0; b < nb; ++b) {
        const struct aiNode *nd = s->nodes.node[s->bone_node[b]];
        copy_name(out->bone_names[b], nd->mName.data);
        for (int c = 0; c < 3; ++c) {
            k->joints[3 * b + c] = s->B[16 * b + 4 * c + 3];
            for (int j = 0; j < 3; ++j)
                out->bone_bind[12 * b + 3 * c + j] = s->B[16 * b + 4 * c + j];
            out->bone_bind[12 * b + 9 + c] = s->B[16 * b + 4 * c + 3];
        }
        k->bones[2 * b] = b;
        k->bones[2 * b + 1] = nb + b;
        k->parent[b] = joint_at_or_above(s, s->nodes.parent[s->bone_node[b]]);
    }
    double *tail = k->joints + 3 * nb;
    for (int32_t b = 0; b < nb; ++b) {
        int32_t p = k->parent[b];
        if (p < 0) continue;
        nchild[p]++;
        for (int c = 0; c < 3; ++c)
            tail[3 * p + c] += k->joints[3 * b + c];
    }
    double size = 0; /* the character's size: the largest extent of the render mesh */
    for (int c = 0; c < 3; ++c) {
        lo[c] = INFINITY, hi[c] = -INFINITY;
        for (int32_t v = 0; v < out->render.nverts; ++v)
            lo[c] = fmin(lo[c], out->render.X[3 * v + c]),
            hi[c] = fmax(hi[c], out->render.X[3 * v + c]);
        size = fmax(size, hi[c] - lo[c]);
    }
    if (!(size > 0)) size = 1;
    /* Parents come before children in node order: a leaf's parent tail is final. */
    for (int32_t b = 0; b < nb; ++b) {
        double *h = k->joints + 3 * b, *t = tail + 3 * b, d[3] = {0}, len = 0;
        if (nchild[b]) {
            for (int c = 0; c < 3; ++c)
                t[c] /= nchild[b], len += (t[c] - h[c]) * (t[c] - h[c]);
            if (sqrt(len) > 1e-6 * size) continue;
        }
        int32_t p = k->parent[b];
        double plen = 0;
        if (p >= 0) {
            for (int c = 0; c < 3; ++c)
                d[c] = tail[3 * p + c] - k->joints[3 * p + c], plen += d[c] * d[c];
            plen = sqrt(plen);
        }
        if (plen > 1e-6 * size) {
            for (int c = 0; c < 3; ++c)
                t[c] = h[c] + 0.25 * d[c];
        } else { /* a root leaf or a zero-length parent: a small bone up +Y */
            t[0] = h[0], t[1] = h[1] + 0.05 * size, t[2] = h[2];
        }
    }
    free(nchild);
    sw_error verr;
    if (sw_skeleton_validate(k, &verr) != SINEW_OK)
        return sw_error_set(err, verr.code, "%s: skeleton: %s", s->name, verr.msg);
    return SINEW_OK;
}

/* Adds mesh m's triangles and positions (through M) at vertex `base`, triangle `tbase`. */
static sinew_result add_mesh(scene_state *s, unsigned m, const double *M, int32_t base,
                             int32_t tbase, sw_imported_character *out, sw_error *err) {
    const struct aiMesh *me = s->sc->mMeshes[m];
    for (unsigned v = 0; v < me->mNumVertices; ++v) {
        const double p[3] = {me->mVertices[v].x, me->mVertices[v].y, me->mVertices[v].z};
        double *x = out->render.X + 3 * ((size_t)base + v);
        for (int r = 0; r < 3; ++r) {
            x[r] = M[4 * r] * p[0] + M[4 * r + 1] * p[1] + M[4 * r + 2] * p[2] + M[4 * r + 3];
            if (!isfinite(x[r]))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "%s: mesh %u, vertex %u is not finite", s->name, m, v);
        }
        out->render_source[base + v] = (int32_t)m;
        out->render_source_vertex[base + v] = (int32_t)v;
    }
    int32_t t = tbase;
    for (unsigned f = 0; f < me->mNumFaces; ++f) {
        const struct aiFace *fc = &me->mFaces[f];
        if (fc->mNumIndices != 3) continue; /* points and lines */
        for (int c = 0; c < 3; ++c) {
            if (fc->mIndices[c] >= me->mNumVertices)
                return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                    "%s: mesh %u, face %u has vertex %u of %u", s->name, m, f,
                                    fc->mIndices[c], me->mNumVertices);
            out->render.tris[3 * t + c] = base + (int32_t)fc->mIndices[c];
        }
        t++;
    }
    return SINEW_OK;
}

static int32_t count_tris(const struct aiMesh *me) {
    int32_t n = 0;
    for (unsigned f = 0; f < me->mNumFaces; ++f)
        n += me->mFaces[f].mNumIndices == 3;
    return n;
}

/* Adds skinned mesh m's weights at row `base` into the dense matrix. */
static sinew_result add_weights(scene_state *s, unsigned m, int32_t base, double *w,
                                sw_error *err) {
    const struct aiMesh *me = s->sc->mMeshes[m];
    int32_t nb = s->nbones;
    for (unsigned k = 0; k < me->mNumBones; ++k) {
        const struct aiBone *bone = me->mBones[k];
        int32_t b = s->node_bone[s->bone_at[s->bone_base[m] + k]];
        for (unsigned j = 0; j < bone->mNumWeights; ++j) {
            unsigned v = bone->mWeights[j].mVertexId;
            double x = bone->mWeights[j].mWeight;
            if (v >= me->mNumVertices)
                return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                    "%s: bone '%s' weights vertex %u of %u", s->name,
                                    bone->mName.data, v, me->mNumVertices);
            if (!isfinite(x) || x < 0)
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "%s: bone '%s' has weight %g on vertex %u", s->name,
                                    bone->mName.data, x, v);
            w[((size_t)base + v) * nb + b] += x;
        }
    }
    return SINEW_OK;
}

/* Keeps each row's 4 largest weights, renormalised; `skinned` marks rows to check. */
static sinew_result limit_weights(scene_state *s, sw_imported_character *out,
                                  const unsigned char *skinned, sw_error *err) {
    int32_t nb = s->nbones, unweighted = 0, nskinned = 0;
    double drop_sum = 0, drop_max = 0;
    for (int32_t v = 0; v < out->render.nverts; ++v) {
        double *row = out->weights.w + (size_t)v * nb, sum = 0, kept = 0;
        int32_t top[4] = {-1, -1, -1, -1};
        for (int32_t b = 0; b < nb; ++b) {
            sum += row[b];
            if (!(row[b] > 0)) continue;
            for (int k = 0; k < 4; ++k) /* insertion into the 4 largest (ties: lower bone) */
                if (top[k] < 0 || row[b] > row[top[k]]) {
                    for (int j = 3; j > k; --j)
                        top[j] = top[j - 1];
                    top[k] = b;
                    break;
                }
        }
        if (!(sum > 0)) {
            unweighted++;
            continue;
        }
        for (int k = 0; k < 4; ++k)
            if (top[k] >= 0) kept += row[top[k]];
        double keep[4] = {0};
        for (int k = 0; k < 4; ++k)
            if (top[k] >= 0) keep[k] = row[top[k]] / kept;
        memset(row, 0, sizeof(double) * (size_t)nb);
        for (int k = 0; k < 4; ++k)
            if (top[k] >= 0) row[top[k]] = keep[k];
        if (skinned[v]) {
            double share = (sum - kept) / sum;
            nskinned++;
            drop_sum += share;
            drop_max = fmax(drop_max, share);
        }
    }
    if (unweighted)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: %d of %d skinned vertices have no weight", s->name, unweighted,
                            out->render.nverts);
    out->weight_dropped_max = drop_max;
    out->weight_dropped_mean = nskinned ? drop_sum / nskinned : 0;
    return SINEW_OK;
}

/* Skinned meshes (each aiMesh once, in mesh order), then rigid props (each node that
 * shows a boneless mesh below a joint, in node order), with their weights. A boneless
 * mesh shown by a node outside the skeleton counts as ignored, once per node. */
static sinew_result build_render(scene_state *s, sw_imported_character *out, sw_error *err) {
    const struct aiScene *sc = s->sc;
    int64_t nv = 0, nt = 0;
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        if (sc->mMeshes[m]->mNumBones) {
            out->nskinned++;
            nv += sc->mMeshes[m]->mNumVertices, nt += count_tris(sc->mMeshes[m]);
        }
    for (int32_t i = 0; i < s->nodes.n; ++i) {
        const struct aiNode *nd = s->nodes.node[i];
        int rigid = joint_at_or_above(s, i) >= 0;
        for (unsigned k = 0; k < nd->mNumMeshes; ++k) {
            unsigned m = nd->mMeshes[k];
            if (m >= sc->mNumMeshes || sc->mMeshes[m]->mNumBones) continue;
            if (!rigid) {
                out->nignored++;
                continue;
            }
            out->nrigid++;
            nv += sc->mMeshes[m]->mNumVertices, nt += count_tris(sc->mMeshes[m]);
        }
    }
    if (nv > SW_SCENE_MAX_VERTS || nt > SW_SCENE_MAX_VERTS ||
        (size_t)nv * (size_t)s->nbones > SW_SCENE_MAX_WEIGHTS)
        return sw_error_set(err, SINEW_ERROR_CAPACITY, "%s: %lld vertices x %d bones is too big",
                            s->name, (long long)nv, s->nbones);
    if (nv == 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: the skinned meshes are empty",
                            s->name);
    out->render.nverts = (int32_t)nv;
    out->render.ntris = (int32_t)nt;
    out->render.X = malloc(sizeof(double) * 3 * (size_t)nv);
    out->render.tris = malloc(sizeof(int32_t) * 3 * (size_t)(nt ? nt : 1));
    out->render_source = malloc(sizeof(int32_t) * (size_t)nv);
    out->render_source_vertex = malloc(sizeof(int32_t) * (size_t)nv);
    out->nsource_meshes = (int32_t)sc->mNumMeshes;
    out->source_mesh_verts = malloc(sizeof(int32_t) * (sc->mNumMeshes ? sc->mNumMeshes : 1));
    out->weights.w = calloc((size_t)nv * (size_t)s->nbones, sizeof(double));
    unsigned char *skinned = calloc((size_t)nv, 1);
    if (!out->render.X || !out->render.tris || !out->render_source || !out->weights.w || !skinned ||
        !out->render_source_vertex || !out->source_mesh_verts) {
        free(skinned);
        return oom(s, err);
    }
    out->weights.nverts = (int32_t)nv;
    out->weights.nbones = s->nbones;
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        out->source_mesh_verts[m] = (int32_t)sc->mMeshes[m]->mNumVertices;
    int32_t base = 0, tbase = 0;
    sinew_result rc = SINEW_OK;
    for (unsigned m = 0; m < sc->mNumMeshes && !rc; ++m) {
        const struct aiMesh *me = sc->mMeshes[m];
        if (!me->mNumBones) continue;
        double W[16];
        mesh_bind_world(s, m, W);
        rc = add_mesh(s, m, W, base, tbase, out, err);
        if (!rc) rc = add_weights(s, m, base, out->weights.w, err);
        memset(skinned + base, 1, me->mNumVertices);
        base += (int32_t)me->mNumVertices, tbase += count_tris(me);
    }
    for (int32_t i = 0; i < s->nodes.n && !rc; ++i) {
        const struct aiNode *nd = s->nodes.node[i];
        int32_t b = joint_at_or_above(s, i);
        if (b < 0) continue;
        for (unsigned k = 0; k < nd->mNumMeshes && !rc; ++k) {
            unsigned m = nd->mMeshes[k];
            if (m >= sc->mNumMeshes || sc->mMeshes[m]->mNumBones) continue;
            const struct aiMesh *me = sc->mMeshes[m];
            rc = add_mesh(s, m, s->nodes.G + 16 * i, base, tbase, out, err);
            for (unsigned v = 0; v < me->mNumVertices; ++v)
                out->weights.w[((size_t)base + v) * s->nbones + b] = 1;
            base += (int32_t)me->mNumVertices, tbase += count_tris(me);
        }
    }
    if (!rc) rc = limit_weights(s, out, skinned, err);
    free(skinned);
    return rc;
}

/* The file's length unit in metres: glTF is in metres; FBX says how many centimetres
 * its unit is (assimp's metadata "UnitScaleFactor"; Blender writes 1 and scales its
 * objects by 100, so the world is in centimetres); other formats are taken as metres. */
static double file_unit(const scene_state *s) {
    const struct aiMetadata *md = s->sc->mMetaData;
    if (s->gltf || !md) return 1;
    for (unsigned i = 0; i < md->mNumProperties; ++i) {
        if (strcmp(md->mKeys[i].data, "UnitScaleFactor") || !md->mValues[i].mData) continue;
        double f = md->mValues[i].mType == AI_FLOAT    ? *(const float *)md->mValues[i].mData
                   : md->mValues[i].mType == AI_DOUBLE ? *(const double *)md->mValues[i].mData
                                                       : 0;
        return isfinite(f) && f > 0 ? 0.01 * f : 1;
    }
    return 1;
}

/* unit_scale: the file's unit, or what makes the render mesh target_height tall. */
static sinew_result apply_scale(scene_state *s, const sw_import_options *o,
                                sw_imported_character *out, sw_error *err) {
    double k = file_unit(s);
    if (o->target_height > 0) {
        double lo = INFINITY, hi = -INFINITY;
        for (int32_t v = 0; v < out->render.nverts; ++v)
            lo = fmin(lo, out->render.X[3 * v + 1]), hi = fmax(hi, out->render.X[3 * v + 1]);
        if (!(hi - lo > 0))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "%s: the render mesh has no height to scale to %g m", s->name,
                                o->target_height);
        k = o->target_height / (hi - lo);
    }
    out->unit_scale = k;
    for (size_t i = 0; i < 3 * (size_t)out->render.nverts; ++i)
        out->render.X[i] *= k;
    for (size_t i = 0; i < 3 * (size_t)out->skel.njoints; ++i)
        out->skel.joints[i] *= k;
    /* the bind frames keep their orientation; their origins move with the scale */
    for (int32_t b = 0; b < out->skel.nbones; ++b)
        for (int c = 9; c < 12; ++c)
            out->bone_bind[12 * b + c] *= k;
    return SINEW_OK;
}

_Static_assert(sizeof(struct aiVector3D) == 3 * sizeof(float), "assimp built with float vertices");

/* A glTF's painted stiffness multiplier (the _SINEW_STIFFNESS attribute, which assimp drops;
 * gltf_attribute.h) onto each render vertex, through the aiMesh and vertex it came from. */
static sinew_result paint_stiffness(scene_state *s, sw_imported_character *out, sw_error *err) {
    const struct aiScene *sc = s->sc;
    const unsigned nm = sc->mNumMeshes;
    const float **xyz = malloc(sizeof *xyz * (nm ? nm : 1));
    int64_t *first = malloc(sizeof *first * ((size_t)nm + 1));
    double *per = NULL;
    sinew_result rc = SINEW_OK;
    if (!xyz || !first) {
        rc = oom(s, err);
        goto done;
    }
    first[0] = 0;
    for (unsigned m = 0; m < nm; ++m) {
        xyz[m] = (const float *)sc->mMeshes[m]->mVertices; /* x, y, z floats (asserted above) */
        first[m + 1] = first[m] + out->source_mesh_verts[m];
    }
    rc =
        sw_gltf_float_attribute(s->bytes, s->nbytes, s->binary, s->dir, "_SINEW_STIFFNESS", s->name,
                                out->nsource_meshes, out->source_mesh_verts, xyz, &per, err);
    if (rc || !per) goto done;
    out->render_stiffness = malloc(sizeof(double) * (size_t)out->render.nverts);
    if (!out->render_stiffness) {
        rc = oom(s, err);
        goto done;
    }
    for (int32_t i = 0; i < out->render.nverts; ++i)
        out->render_stiffness[i] = per[first[out->render_source[i]] + out->render_source_vertex[i]];
done:
    free(xyz);
    free(first);
    free(per);
    return rc;
}

static sinew_result import_scene(scene_state *s, const sw_import_options *o,
                                 sw_imported_character *out, sw_error *err) {
    sinew_result rc;
    if ((rc = build_nodes(s, err)) || (rc = find_joints(s, err)) ||
        (rc = build_render(s, out, err)) || (rc = build_skeleton(s, out, err)) ||
        (rc = apply_scale(s, o, out, err)))
        return rc;
    if (s->bytes && (rc = paint_stiffness(s, out, err))) return rc;
    const struct aiScene *sc = s->sc;
    out->clips = calloc(sc->mNumAnimations ? sc->mNumAnimations : 1, sizeof *out->clips);
    if (!out->clips) return oom(s, err);
    for (unsigned a = 0; a < sc->mNumAnimations; ++a) {
        sw_imported_clip *c = &out->clips[a];
        rc = sw_scene_sample_clip(sc->mAnimations[a], &s->nodes, s->nbones, s->bone_node, s->Binv,
                                  out->unit_scale, o->fps, s->name, c, err);
        if (rc) return rc;
        out->nclips++;
        if (sc->mAnimations[a]->mName.data[0])
            copy_name(c->name, sc->mAnimations[a]->mName.data);
        else
            snprintf(c->name, sizeof c->name, "clip%u", a);
    }
    return SINEW_OK;
}

sinew_result sw_scene_build(const struct aiScene *sc, const char *name, const void *bytes,
                            size_t nbytes, int binary, const char *dir, const sw_import_options *o,
                            sw_imported_character *out, sw_error *err) {
    if (!sc)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: assimp could not read it: %s", name,
                            aiGetErrorString());
    sinew_result rc;
    if (!sc->mRootNode || (sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        rc = sw_error_set(err, SINEW_ERROR_PARSE, "%s: assimp read an incomplete scene", name);
    } else {
        scene_state s = {.sc = sc,
                         .name = name,
                         .gltf = bytes != NULL,
                         .bytes = bytes,
                         .nbytes = nbytes,
                         .binary = binary,
                         .dir = dir};
        rc = import_scene(&s, o, out, err);
        state_free(&s);
    }
    aiReleaseImport(sc);
    if (rc) sw_imported_character_free(out);
    return rc;
}

void sw_imported_character_free(sw_imported_character *c) {
    if (!c) return;
    sw_trimesh_free(&c->render);
    free(c->render_source);
    free(c->render_source_vertex);
    free(c->source_mesh_verts);
    free(c->render_stiffness);
    free(c->bone_bind);
    sw_skeleton_free(&c->skel);
    free(c->bone_names);
    sw_weights_free(&c->weights);
    for (int32_t i = 0; i < c->nclips; ++i)
        sw_clip_free(&c->clips[i].clip);
    free(c->clips);
    memset(c, 0, sizeof *c);
}
