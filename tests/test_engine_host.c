/* What an engine does with a blob, for the Fox and the robot (real glTF files): it bakes
 * the asset, then, as a host, imports the same file itself with assimp, maps its own
 * skeleton to the blob's bones by name (parents and bind poses agree), its own vertex
 * buffers to the output surface through the output map (each output vertex at rest sits on
 * its source vertex), and plays a clip in its own bone order: the surface it gets is the
 * one the blob's bone order gives, bitwise. The clip's frames are the bake's own import of
 * the file's animation, standing in for the engine's animation system: an engine that
 * samples the animation itself computes each pose transform its own way, which moves the
 * pose, and so the surface, in the last bits (the mapping adds nothing to that). */
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "blob_write.h"
#include "scene_character.h"
#include "sinew/sinew.h"
#include "sw_test.h"
#ifdef SINEW_TEST_VIEWER
#include "viewer.h" /* samples/viewer: its import of the file, mapped onto the blob */
#endif

typedef struct baked {
    sw_character ch;
    sw_clip_split clips;
    sw_bake_result res;
    void *data;
    size_t size;
    sinew_blob *blob;
} baked;

static int bake_file(const char *path, const char *train, int32_t tets, baked *b) {
    memset(b, 0, sizeof *b);
    sw_scene_character_options o = {0};
    o.target_tets = tets;
    o.train_clips = train;
    sw_error err;
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3, p.max_train_frames = 8, p.threads = 2;
    p.pair_sweeps = 0, p.sibling_sweeps = 0;
    if (sw_character_from_scene(path, &o, &b->ch, &b->clips, NULL, &err) != SINEW_OK ||
        sw_bake(&b->ch, &p, &b->res, &err) != SINEW_OK ||
        sw_blob_write_memory(&b->res.view, &b->data, &b->size, &err) != SINEW_OK) {
        fprintf(stderr, "  %s: %s\n", path, err.msg);
        return 0;
    }
    sinew_blob_def d = sinew_blob_def_default();
    d.data = b->data;
    d.data_size = b->size;
    return sinew_blob_load(&d, &b->blob) == SINEW_OK;
}

static void baked_free(baked *b) {
    sinew_blob_destroy(b->blob);
    free(b->data);
    sw_bake_result_free(&b->res);
    sw_clip_split_free(&b->clips);
    sw_character_free(&b->ch);
}

/* Whether a node named `name` has a node named `above` among its ancestors (NULL: any
 * node). Names repeat in the robot (a mesh node named after its joint): every node of the
 * name is tried. */
static int has_above(const struct aiNode *n, const char *name, const char *above) {
    if (!strcmp(n->mName.data, name)) {
        if (!above) return 1;
        for (const struct aiNode *p = n->mParent; p; p = p->mParent)
            if (!strcmp(p->mName.data, above)) return 1;
    }
    for (unsigned i = 0; i < n->mNumChildren; ++i)
        if (has_above(n->mChildren[i], name, above)) return 1;
    return 0;
}

/* The host's skeleton: the skins' bones in the file's mesh and bone order (not the blob's),
 * each mapped to a blob bone by name; 0 when a name does not resolve or a parent differs. */
static int map_skeleton(const struct aiScene *sc, const sinew_blob *blob, int32_t *host_to_blob,
                        int32_t *nhost) {
    const uint32_t nb = sinew_blob_bone_count(blob);
    *nhost = 0;
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        for (unsigned k = 0; k < sc->mMeshes[m]->mNumBones; ++k) {
            const char *name = sc->mMeshes[m]->mBones[k]->mName.data;
            const int32_t b = sinew_blob_find_bone(blob, name);
            if (b < 0) {
                fprintf(stderr, "  host bone '%s' is not in the blob\n", name);
                return 0;
            }
            int seen = 0;
            for (int32_t i = 0; i < *nhost; ++i)
                seen |= host_to_blob[i] == b;
            if (!seen) host_to_blob[(*nhost)++] = b;
            /* the blob's parent is the nearest joint above the host's node */
            int32_t parent;
            if (sinew_blob_bone_parent(blob, (uint32_t)b, &parent) != SINEW_OK) return 0;
            const char *want = parent < 0 ? NULL : sinew_blob_bone_name(blob, (uint32_t)parent);
            if (!has_above(sc->mRootNode, name, want)) {
                fprintf(stderr, "  bone '%s': parent '%s' is not above it\n", name, want);
                return 0;
            }
        }
    return *nhost == (int32_t)nb;
}

/* Where mesh m's vertices sit in the blob's rest space, as a host works it out from its own
 * inverse bind matrix of the mesh's first bone and the blob's bind pose of that bone:
 * W = bind * offset (3x4, row-major). 0 for a mesh without bones. */
static int mesh_placement(const struct aiMesh *me, const sinew_blob *blob, double W[12]) {
    if (!me->mNumBones) return 0;
    const struct aiBone *bone = me->mBones[0];
    double B[12];
    const int32_t b = sinew_blob_find_bone(blob, bone->mName.data);
    if (b < 0 || sinew_blob_bone_bind(blob, (uint32_t)b, B) != SINEW_OK) return 0;
    const struct aiMatrix4x4 *o = &bone->mOffsetMatrix;
    const double O[3][4] = {
        {o->a1, o->a2, o->a3, o->a4}, {o->b1, o->b2, o->b3, o->b4}, {o->c1, o->c2, o->c3, o->c4}};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
            W[4 * r + c] = B[3 * r] * O[0][c] + B[3 * r + 1] * O[1][c] + B[3 * r + 2] * O[2][c] +
                           (c == 3 ? B[9 + r] : 0.0);
    return 1;
}

/* Output vertex i at rest against the host's vertex it maps to, placed by its mesh's W: the
 * largest distance. */
static double rest_map_error(const struct aiScene *sc, const sinew_blob *blob) {
    const uint32_t n = sinew_blob_surface_vertex_count(blob);
    int32_t *pairs = malloc(2 * sizeof(int32_t) * n);
    float *pos = malloc(3 * sizeof(float) * n);
    sinew_instance *inst = NULL;
    double worst = INFINITY;
    const uint32_t nb = sinew_blob_bone_count(blob);
    float *rest = calloc(12 * (size_t)nb, sizeof(float)); /* every bone at its bind pose */
    for (uint32_t k = 0; rest && k < nb; ++k)
        rest[12 * k] = rest[12 * k + 4] = rest[12 * k + 8] = 1;
    if (pairs && pos && rest && sinew_blob_output_sources(blob, pairs, 2 * n) == SINEW_OK &&
        sinew_instance_create(blob, NULL, &inst) == SINEW_OK &&
        sinew_instance_set_pose(inst, rest, nb) == SINEW_OK &&
        sinew_instance_step(inst, 1.0f / 30) == SINEW_OK &&
        sinew_instance_read_surface(inst, pos, NULL, n) == SINEW_OK) {
        worst = 0;
        for (uint32_t i = 0; i < n && worst < INFINITY; ++i) {
            const struct aiMesh *me = sc->mMeshes[pairs[2 * i]];
            const struct aiVector3D *x = &me->mVertices[pairs[2 * i + 1]];
            double W[12], d2 = 0;
            if (!mesh_placement(me, blob, W)) {
                worst = INFINITY;
                break;
            }
            for (int r = 0; r < 3; ++r) {
                const double y =
                    W[4 * r] * x->x + W[4 * r + 1] * x->y + W[4 * r + 2] * x->z + W[4 * r + 3];
                d2 += (pos[3 * i + r] - y) * (pos[3 * i + r] - y);
            }
            worst = fmax(worst, sqrt(d2));
        }
    }
    sinew_instance_destroy(inst);
    free(rest);
    free(pairs);
    free(pos);
    return worst;
}

/* Plays `frames` frames of the clip twice, in the blob's bone order and in the host's
 * (mapped by name); 1 when every frame's surfaces are bitwise equal. */
static int play_both_orders(const sinew_blob *blob, const sw_clip *clip,
                            const int32_t *host_to_blob, int32_t frames) {
    const uint32_t nb = sinew_blob_bone_count(blob), n = sinew_blob_surface_vertex_count(blob);
    float *blob_pose = malloc(12 * sizeof(float) * nb),
          *host_pose = malloc(12 * sizeof(float) * nb);
    float *a = malloc(6 * sizeof(float) * n), *h = malloc(6 * sizeof(float) * n);
    float *mapped = malloc(12 * sizeof(float) * nb);
    sinew_instance *ia = NULL, *ih = NULL;
    int same = a && h && blob_pose && host_pose && mapped &&
               sinew_instance_create(blob, NULL, &ia) == 0 &&
               sinew_instance_create(blob, NULL, &ih) == 0;
    for (int32_t f = 0; same && f < frames && f < clip->nframes; ++f) {
        for (uint32_t k = 0; k < nb; ++k)
            for (int c = 0; c < 12; ++c)
                blob_pose[12 * k + c] = (float)clip->T[((size_t)f * nb + k) * 12 + c];
        /* the host's pose array is in its own order; it hands sinew the blob's */
        for (uint32_t j = 0; j < nb; ++j)
            memcpy(host_pose + 12 * j, blob_pose + 12 * host_to_blob[j], 12 * sizeof(float));
        for (uint32_t j = 0; j < nb; ++j)
            memcpy(mapped + 12 * host_to_blob[j], host_pose + 12 * j, 12 * sizeof(float));
        same = sinew_instance_set_pose(ia, blob_pose, nb) == 0 &&
               sinew_instance_set_pose(ih, mapped, nb) == 0 &&
               sinew_instance_step(ia, 1.0f / 30) == 0 && sinew_instance_step(ih, 1.0f / 30) == 0 &&
               sinew_instance_read_surface(ia, a, a + 3 * n, n) == 0 &&
               sinew_instance_read_surface(ih, h, h + 3 * n, n) == 0 &&
               memcmp(a, h, 6 * sizeof(float) * n) == 0;
    }
    sinew_instance_destroy(ia);
    sinew_instance_destroy(ih);
    free(blob_pose), free(host_pose), free(mapped), free(a), free(h);
    return same;
}

#ifdef SINEW_TEST_VIEWER
/* The largest difference between the viewer's pose of clip `name` and the bake's import
 * of it (frame f at f / fps seconds), over the first `frames` frames. */
static double viewer_pose_error(const vw_asset *a, const char *name, const sw_clip *clip,
                                int32_t frames, float *P) {
    int k = -1;
    for (int c = 0; c < a->nclips; ++c)
        if (!strcmp(a->clip_names[c], name)) k = c;
    double worst = k < 0 ? INFINITY : 0;
    for (int32_t f = 0; k >= 0 && f < frames && f < clip->nframes; ++f) {
        if (!a->pose(a, k, f / clip->fps, P)) return INFINITY;
        for (int32_t i = 0; i < 12 * a->nbones; ++i)
            worst = fmax(worst, fabs(P[i] - clip->T[(size_t)f * 12 * a->nbones + i]));
    }
    return worst;
}

/* The viewer (samples/viewer/asset.c) maps the file onto the blob by bone names and the
 * output map: its vertex buffer must be this host's, vertex for vertex, its clip the
 * bake's import of the clip, and the surface it draws the one this host gets playing the
 * viewer's poses in its own bone order and scattering the output into its own meshes'
 * buffers, bitwise. */
static void viewer_as_host(const char *path, const baked *b, const struct aiScene *sc,
                           const int32_t *host_to_blob, const char *clip_name) {
    vw_asset a;
    char err[512] = "";
    const int imported = vw_asset_import(path, b->blob, &a, err, sizeof err);
    if (!imported) fprintf(stderr, "  viewer: %s\n", err);
    ENSURE(imported);
    const uint32_t nb = sinew_blob_bone_count(b->blob),
                   n = sinew_blob_surface_vertex_count(b->blob);
    ENSURE(a.nbones == (int32_t)nb && a.nverts == (int32_t)n);
    int32_t *pairs = malloc(2 * sizeof(int32_t) * n);
    float *P = malloc(12 * sizeof(float) * nb), *host_pose = malloc(12 * sizeof(float) * nb);
    float *mapped = malloc(12 * sizeof(float) * nb), *view = malloc(3 * sizeof(float) * n);
    float *out = malloc(3 * sizeof(float) * n);
    float **mesh_buf = calloc(sc->mNumMeshes, sizeof *mesh_buf);
    ENSURE(pairs && P && host_pose && mapped && view && out && mesh_buf);
    ENSURE(sinew_blob_output_sources(b->blob, pairs, 2 * n) == SINEW_OK);
    double rest = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const struct aiMesh *me = sc->mMeshes[pairs[2 * i]];
        const struct aiVector3D *x = &me->mVertices[pairs[2 * i + 1]];
        double W[12];
        ENSURE(mesh_placement(me, b->blob, W));
        for (int r = 0; r < 3; ++r)
            rest = fmax(rest, fabs(a.rest[3 * i + r] - (W[4 * r] * x->x + W[4 * r + 1] * x->y +
                                                        W[4 * r + 2] * x->z + W[4 * r + 3])));
    }
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        ENSURE((mesh_buf[m] = calloc(3 * (size_t)sc->mMeshes[m]->mNumVertices + 1, sizeof(float))));
    const double pose_err = viewer_pose_error(&a, clip_name, &b->clips.train[0], 20, P);
    fprintf(stderr,
            "    viewer: vertex buffer %.3g from the host's, clip %s %.3g from the bake's\n", rest,
            clip_name, pose_err);
    ENSURE(rest < 1e-6);
    ENSURE(pose_err < 1e-4);
    sinew_instance *iv = NULL, *ih = NULL;
    ENSURE(sinew_instance_create(b->blob, NULL, &iv) == SINEW_OK &&
           sinew_instance_create(b->blob, NULL, &ih) == SINEW_OK);
    int same = 1;
    for (int f = 0; f < 20 && same; ++f) {
        ENSURE(a.pose(&a, 0, f / 30.0, P));
        for (uint32_t j = 0; j < nb; ++j) /* the host's animation, in its own bone order */
            memcpy(host_pose + 12 * j, P + 12 * host_to_blob[j], 12 * sizeof(float));
        for (uint32_t j = 0; j < nb; ++j)
            memcpy(mapped + 12 * host_to_blob[j], host_pose + 12 * j, 12 * sizeof(float));
        ENSURE(sinew_instance_set_pose(iv, P, nb) == 0 && sinew_instance_step(iv, 1.0f / 30) == 0 &&
               sinew_instance_read_surface(iv, view, NULL, n) == 0);
        ENSURE(sinew_instance_set_pose(ih, mapped, nb) == 0 &&
               sinew_instance_step(ih, 1.0f / 30) == 0 &&
               sinew_instance_read_surface(ih, out, NULL, n) == 0);
        for (uint32_t i = 0; i < n; ++i) /* into the host's own vertex buffers */
            memcpy(mesh_buf[pairs[2 * i]] + 3 * pairs[2 * i + 1], out + 3 * i, 3 * sizeof(float));
        for (uint32_t i = 0; i < n && same; ++i)
            same = !memcmp(view + 3 * i, mesh_buf[pairs[2 * i]] + 3 * pairs[2 * i + 1],
                           3 * sizeof(float));
    }
    ENSURE(same);
    sinew_instance_destroy(iv);
    sinew_instance_destroy(ih);
    for (unsigned m = 0; m < sc->mNumMeshes; ++m)
        free(mesh_buf[m]);
    free(mesh_buf), free(pairs), free(P), free(host_pose), free(mapped), free(view), free(out);
    vw_asset_free(&a);
}
#endif

static void engine_host(const char *rel, const char *train, int32_t tets) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", SINEW_SHARED_DATA_DIR, rel);
    static baked b;
    ENSURE(bake_file(path, train, tets, &b));
    /* the host's own import, with the flags the bake's glTF import uses */
    const struct aiScene *sc =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
    ENSURE(sc);
    ENSURE(sinew_blob_source_mesh_count(b.blob) == sc->mNumMeshes);
    int32_t host_to_blob[256], nhost = 0;
    ENSURE(sinew_blob_bone_count(b.blob) <= 256);
    ENSURE(map_skeleton(sc, b.blob, host_to_blob, &nhost));
    const double err = rest_map_error(sc, b.blob);
    fprintf(stderr,
            "    %s: %d bones mapped by name, %u output vertices from %u meshes, at rest "
            "%.3g from their host vertices\n",
            rel, nhost, sinew_blob_surface_vertex_count(b.blob), sc->mNumMeshes, err);
    ENSURE(err < 1e-6);
    sinew_blob_provenance p;
    p.struct_size = sizeof p;
    ENSURE(sinew_blob_get_provenance(b.blob, &p) == SINEW_OK && p.sinew_version == SINEW_VERSION);
    ENSURE(p.source_hash == b.ch.source_hash && p.source_hash != 0);
    ENSURE(b.clips.ntrain > 0);
    ENSURE(play_both_orders(b.blob, &b.clips.train[0], host_to_blob, 20));
#ifdef SINEW_TEST_VIEWER
    viewer_as_host(path, &b, sc, host_to_blob, train);
#endif
    aiReleaseImport(sc);
    baked_free(&b);
}

TEST(the_fox_as_an_engine_sees_it) {
    NEED_DATA("gltf-fox/Fox.glb");
    engine_host("gltf-fox/Fox.glb", "Survey", 1000);
}

TEST(the_robot_as_an_engine_sees_it) {
    NEED_DATA("gltf-robot-quaternius/robot.glb");
    /* at the 3,000 tets the viewer plays it at (docs/notes/viewer.md) */
    engine_host("gltf-robot-quaternius/robot.glb", "Robot_Walking", 3000);
}

SW_TEST_MAIN(CASE(the_fox_as_an_engine_sees_it), CASE(the_robot_as_an_engine_sees_it))
