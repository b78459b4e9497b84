/* The render mesh embedded in the tets: the embedding reproduces the render
 * mesh at rest; a blob with one outputs it through the public API (counts, triangles,
 * positions, normals), welded duplicates identical under deformation; the loader rejects a
 * damaged render section with a message naming it; the step stays allocation- and
 * lock-free. (A blob without a render mesh is the one it always was: test_golden_hash.)
 *
 * The test character: the finger sample, its render mesh the tets' boundary with every
 * fifth vertex pushed outside the tets (extrapolated embeddings) and a UV seam's worth of
 * duplicated vertices (every seventh triangle's first corner split off). */
#include <float.h>

#include "bake.h"
#include "blob_synth.h"
#include "character_io.h"
#include "dqs.h"
#include "embed.h"
#include "instance.h"
#include "instance_internal.h"
#include "mesh_io.h"
#include "recording.h"
#include "rt_interpose.h"
#include "samples.h"
#include "sinew/sinew_world.h"
#include "surface_normals.h"
#include "sw_test.h"

/* Push out: 20% of the finger's 2000-tet edge. */
#define PUSH 0.03

/* The render mesh described above, from the boundary of m. */
static int make_render(const sw_tetmesh *m, sw_trimesh *r) {
    sw_surface s;
    sw_error err;
    if (sw_tetmesh_surface(m, &s, &err) != SINEW_OK) return 0;
    int32_t *local = malloc(sizeof(int32_t) * (size_t)m->nverts), ndup = 0;
    for (int32_t t = 0; t < s.ntris; t += 7)
        ndup++;
    r->nverts = s.nverts + ndup;
    r->ntris = s.ntris;
    r->X = malloc(sizeof(double) * 3 * (size_t)r->nverts);
    r->tris = malloc(sizeof(int32_t) * 3 * (size_t)r->ntris);
    double *n = malloc(sizeof(double) * 3 * (size_t)s.nverts);
    for (int32_t i = 0; i < s.nverts; ++i) {
        local[s.verts[i]] = i;
        memcpy(r->X + 3 * i, m->X + 3 * s.verts[i], 3 * sizeof(double));
    }
    for (int32_t k = 0; k < 3 * s.ntris; ++k)
        r->tris[k] = local[s.tris[k]];
    sw_surface_normals(s.nverts, r->X, r->ntris, r->tris, n);
    for (int32_t i = 0; i < s.nverts; i += 5)
        for (int k = 0; k < 3; ++k)
            r->X[3 * i + k] += PUSH * n[3 * i + k];
    for (int32_t t = 0, d = s.nverts; t < s.ntris; t += 7, ++d) {
        memcpy(r->X + 3 * d, r->X + 3 * r->tris[3 * t], 3 * sizeof(double));
        r->tris[3 * t] = d;
    }
    free(n);
    free(local);
    sw_surface_free(&s);
    return 1;
}

/* |a - b| relative to the size of the coordinates. */
static double rel_err(const double *a, const double *b, int64_t n) {
    double e = 0, scale = 1e-300;
    for (int64_t i = 0; i < n; ++i) {
        e = fmax(e, fabs(a[i] - b[i]));
        scale = fmax(scale, fabs(b[i]));
    }
    return e / scale;
}

/* ---- the baked character with a render mesh (shared by the tests below) ----------- */

static int fx_ok = -1; /* -1 not made yet, 0 failed, 1 made */
static struct {
    sw_character ch;
    sw_bake_result res;
    void *data;
    size_t size;
    sinew_blob *blob;
} fx;

static int finger_fixture(void) {
    if (fx_ok >= 0) return fx_ok;
    sw_error err;
    fx_ok = 0;
    if (sw_sample_make("finger", 2000, 12, &fx.ch, &err) != SINEW_OK ||
        !make_render(&fx.ch.mesh, &fx.ch.render))
        return 0;
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3;
    p.max_train_frames = 8;
    p.threads = 2;
    if (sw_bake(&fx.ch, &p, &fx.res, &err) != SINEW_OK ||
        sw_blob_write_memory(&fx.res.view, &fx.data, &fx.size, &err) != SINEW_OK) {
        fprintf(stderr, "  bake: %s\n", err.msg);
        return 0;
    }
    fprintf(stderr,
            "    finger: %d render vertices (%d welded), %d outside by %.4g at most, "
            "|b| <= %.3g, embedded in %.1f ms\n",
            fx.ch.render.nverts, fx.res.render_welded, fx.res.render_outside,
            fx.res.render_max_outside, fx.res.render_max_bary, 1e3 * fx.res.embed_seconds);
    sinew_blob_def d = sinew_blob_def_default();
    d.data = fx.data;
    d.data_size = fx.size;
    fx_ok = sinew_blob_load(&d, &fx.blob) == SINEW_OK;
    return fx_ok;
}

static void pose_of(int frame, float *T) {
    const double *Td = fx.ch.clip.T + (size_t)(frame % fx.ch.clip.nframes) * 12 * fx.ch.skel.nbones;
    for (int i = 0; i < 12 * fx.ch.skel.nbones; ++i)
        T[i] = (float)Td[i];
}

/* ---- the embedding -------------------------------------------------------------- */

/* The embedding of a render mesh reproduces every rest position. */
static int check_reproduction(const sw_tetmesh *m, const sw_trimesh *r, const sw_embedding *e,
                              double *worst) {
    *worst = 0;
    for (int32_t i = 0; i < r->nverts; ++i) {
        const double *b = e->bary + 4 * i;
        double x[3];
        for (int k = 0; k < 3; ++k) {
            x[k] = 0;
            for (int c = 0; c < 4; ++c)
                x[k] += b[c] * m->X[3 * m->tets[4 * e->tet[i] + c] + k];
        }
        *worst = fmax(*worst, rel_err(x, r->X + 3 * i, 3));
        if (e->weld[e->weld[i]] != e->weld[i] ||
            memcmp(r->X + 3 * i, r->X + 3 * e->weld[i], 3 * sizeof(double)) != 0)
            return 0;
    }
    return 1;
}

TEST(embedding_reproduces_the_arm_at_rest) {
    NEED_DATA("arm-libigl/arm.obj");
    static const int32_t tets[] = {3000, 100000};
    for (int k = 0; k < 2; ++k) {
        sw_character c;
        sw_error err;
        ENSUREF(sw_character_from_surface(SINEW_SHARED_DATA_DIR "/arm-libigl/arm.obj", tets[k],
                                          SW_MESHER_LATTICE,
                                          SINEW_SHARED_DATA_DIR "/arm-libigl/arm.tgf", NULL, 4, &c,
                                          NULL, &err) == SINEW_OK,
                "%s", err.msg);
        ENSURE(c.render.nverts > 0 && c.render.ntris > 0); /* the surface is the render mesh */
        sw_embedding e;
        ENSUREF(sw_embed_render(&c.mesh, &c.render, &e, &err) == SINEW_OK, "%s", err.msg);
        double worst;
        ENSURE(check_reproduction(&c.mesh, &c.render, &e, &worst));
        fprintf(stderr,
                "    arm, %d tets: %d render vertices (%d welded) in %.1f ms; %d outside, by "
                "%.4g at most (vertex %d), |b| <= %.3g; reproduced to %.2g\n",
                c.mesh.ntets, c.render.nverts, e.nwelded, 1e3 * e.seconds, e.outside, e.max_outside,
                e.worst, e.max_bary, worst);
        ENSUREF(worst <= 1e-12, "rest positions reproduced to %g relative", worst);
        sw_embedding_free(&e);
        sw_character_free(&c);
    }
}

TEST(embedding_refuses_what_does_not_fit) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1000, 4, &c, &err) == SINEW_OK);
    ENSURE(make_render(&c.mesh, &c.render));
    sw_embedding e;
    /* a vertex far away: the extrapolation it needs is refused, naming it */
    double keep = c.render.X[3 * 7];
    c.render.X[3 * 7] = 1e3;
    ENSURE(sw_embed_render(&c.mesh, &c.render, &e, &err) == SINEW_ERROR_UNSUPPORTED);
    ENSUREF(strstr(err.msg, "render vertex 7") && strstr(err.msg, "outside the tets"), "%s",
            err.msg);
    c.render.X[3 * 7] = NAN;
    ENSURE(sw_embed_render(&c.mesh, &c.render, &e, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    c.render.X[3 * 7] = keep;
    c.render.tris[5] = c.render.nverts;
    ENSURE(sw_embed_render(&c.mesh, &c.render, &e, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(err.msg, "render mesh: triangle 1"), "%s", err.msg);
    sw_character_free(&c);
}

/* ---- the blob and the runtime ---------------------------------------------------- */

TEST(the_output_surface_is_the_render_mesh) {
    ENSURE(finger_fixture());
    const sw_trimesh *r = &fx.ch.render;
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    ENSURE(sinew_blob_surface_vertex_count(fx.blob) == (uint32_t)r->nverts);
    ENSURE(sinew_blob_surface_triangle_count(fx.blob) == (uint32_t)r->ntris);
    uint32_t *tris = malloc(sizeof(uint32_t) * 3 * (size_t)r->ntris);
    ENSURE(sinew_blob_surface_triangles(fx.blob, tris, 3 * (uint32_t)r->ntris) == SINEW_OK);
    int same = 1;
    for (int32_t k = 0; k < 3 * r->ntris; ++k)
        same &= tris[k] == (uint32_t)r->tris[k];
    free(tris);
    ENSURE(same);
    /* the blob's embedding of the rest positions: the render mesh, to rounding */
    double *x = malloc(sizeof(double) * 3 * (size_t)r->nverts);
    sw_output_from_full(v, v->rest, x);
    double e = rel_err(x, r->X, 3 * (int64_t)r->nverts);
    free(x);
    ENSUREF(e <= 1e-12, "the blob reproduces the rest render mesh to %g relative", e);

    /* the runtime at the rest pose: the render mesh, to float precision (a step at rest
       leaves q at 0 up to the solver's tolerance) */
    sinew_instance *in;
    ENSURE(sinew_instance_create(fx.blob, NULL, &in) == SINEW_OK);
    float *T = malloc(sizeof(float) * 12 * (size_t)fx.ch.skel.nbones);
    float *p = malloc(sizeof(float) * 3 * (size_t)r->nverts);
    for (int32_t b = 0; b < fx.ch.skel.nbones; ++b) {
        memset(T + 12 * b, 0, 12 * sizeof(float));
        T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
    }
    ENSURE(sinew_instance_set_pose(in, T, (uint32_t)fx.ch.skel.nbones) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(in, p, NULL, (uint32_t)r->nverts) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(in, p, NULL, (uint32_t)v->nsurf_verts) ==
           SINEW_ERROR_INVALID_ARGUMENT); /* the boundary's count is not the output's */
    double dmax = 0;
    for (int64_t i = 0; i < 3 * (int64_t)r->nverts; ++i)
        dmax = fmax(dmax, fabs(p[i] - r->X[i]));
    fprintf(stderr, "    rest pose: output within %.3g of the render mesh\n", dmax);
    ENSUREF(dmax <= 1e-5, "the output at rest is %g from the render mesh", dmax);
    free(T);
    free(p);
    sinew_instance_destroy(in);
}

TEST(welded_duplicates_move_and_shade_as_one) {
    ENSURE(finger_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    const uint32_t n = (uint32_t)v->nrender_verts;
    ENSURE(fx.res.render_welded > 0 && fx.res.render_outside > 0);
    sinew_instance *in;
    ENSURE(sinew_instance_create(fx.blob, NULL, &in) == SINEW_OK);
    float *T = malloc(sizeof(float) * 12 * (size_t)fx.ch.skel.nbones);
    float *p = malloc(sizeof(float) * 3 * n), *nr = malloc(sizeof(float) * 3 * n);
    double *full = malloc(sizeof(double) * 3 * (size_t)v->nverts),
           *cnt = malloc(sizeof(double) * (size_t)v->nverts), *ref = malloc(sizeof(double) * 3 * n);
    double moved = 0, consistent = 0;
    for (int f = 0; f < fx.ch.clip.nframes; ++f) {
        pose_of(f, T);
        ENSURE(sinew_instance_set_pose(in, T, (uint32_t)fx.ch.skel.nbones) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        ENSURE(sinew_instance_read_surface(in, p, nr, n) == SINEW_OK);
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t w = (uint32_t)v->render_weld[i];
            ENSUREF(memcmp(p + 3 * i, p + 3 * w, 3 * sizeof(float)) == 0 &&
                        memcmp(nr + 3 * i, nr + 3 * w, 3 * sizeof(float)) == 0,
                    "frame %d: vertex %u and its representative %u differ", f, i, w);
            double l = sqrt(nr[3 * i] * nr[3 * i] + nr[3 * i + 1] * nr[3 * i + 1] +
                            nr[3 * i + 2] * nr[3 * i + 2]);
            ENSUREF(fabs(l - 1) < 1e-5, "frame %d: vertex %u's normal has length %g", f, i, l);
        }
        for (int64_t i = 0; i < 3 * (int64_t)n; ++i)
            moved = fmax(moved, fabs(p[i] - fx.ch.render.X[i]));
        /* the runtime's embedding is the blob's embedding of its simulation vertices */
        sw_instance_full_positions(in, full, cnt);
        sw_output_from_full(v, full, ref);
        consistent = fmax(consistent, rel_err(sw_instance_surface(in), ref, 3 * (int64_t)n));
    }
    fprintf(stderr, "    clip: moved %.3g; output vs. embedded full positions %.3g\n", moved,
            consistent);
    ENSURE(moved > 0.1);         /* the clip bends the finger */
    ENSURE(consistent <= 1e-12); /* the same map */
    free(T), free(p), free(nr), free(full), free(cnt), free(ref);
    sinew_instance_destroy(in);
}

/* The collision surface under a render mesh: the tet boundary (closed: a world takes it as
 * a mesh collider), at the solved positions of its vertices through the clip, in the
 * actor's frame; skinned before the first step and at the pose-space level; refused,
 * saying why, when the instance was not asked to write it. */
TEST(the_collision_surface_is_the_boundary_under_a_render_mesh) {
    ENSURE(finger_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    const uint32_t nc = sinew_blob_collision_vertex_count(fx.blob),
                   nt = sinew_blob_collision_triangle_count(fx.blob),
                   nb = (uint32_t)fx.ch.skel.nbones;
    ENSURE(nc == (uint32_t)v->nsurf_verts && nt == (uint32_t)v->nsurf_tris); /* manifold */
    ENSURE(nc != sinew_blob_surface_vertex_count(fx.blob));
    uint32_t *tris = malloc(sizeof(uint32_t) * 3 * nt);
    ENSURE(sinew_blob_collision_triangles(fx.blob, tris, 3 * nt - 1) == SINEW_ERROR_CAPACITY);
    ENSURE(sinew_blob_collision_triangles(fx.blob, tris, 3 * nt) == SINEW_OK);
    sinew_instance *in[3]; /* asked, not asked, asked and placed */
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(sinew_instance_create(fx.blob, &d, &in[1]) == SINEW_OK);
    d.collision_surface = 2;
    ENSURE(sinew_instance_create(fx.blob, &d, &in[0]) == SINEW_ERROR_INVALID_ARGUMENT);
    d.collision_surface = 1;
    ENSURE(sinew_instance_create(fx.blob, &d, &in[0]) == SINEW_OK);
    ENSURE(sinew_instance_create(fx.blob, &d, &in[2]) == SINEW_OK);
    const double c = cos(2.0), sn = sin(2.0), far = 1e4;
    const double actor[12] = {c, -sn, 0, sn, c, 0, 0, 0, 1, far, -far, 0.5 * far};
    ENSURE(sinew_instance_set_actor(in[2], actor) == SINEW_OK);
    float *T = malloc(sizeof(float) * 12 * nb), *p = malloc(sizeof(float) * 3 * nc),
          *q = malloc(sizeof(float) * 3 * nc);
    double *full = malloc(sizeof(double) * 3 * (size_t)v->nverts),
           *cnt = malloc(sizeof(double) * (size_t)v->nverts);
    /* before a step: the boundary skinned at the rest pose, the rest boundary */
    ENSURE(sinew_instance_read_collision_surface(in[1], p, nc) == SINEW_OK);
    double at_rest = 0;
    for (uint32_t s = 0; s < nc; ++s)
        for (int k = 0; k < 3; ++k)
            at_rest = fmax(
                at_rest,
                fabs(p[3 * s + k] -
                     v->rest[3 * (int64_t)sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]) + k]));
    ENSUREF(at_rest <= 1e-6, "before a step the collision surface is %g from the rest", at_rest);
    ENSURE(sinew_instance_read_collision_surface(in[0], p, nc + 1) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_read_collision_surface(NULL, p, nc) == SINEW_ERROR_INVALID_ARGUMENT);
    double solved = 0, placed = 0, moved = 0;
    for (int f = 0; f < fx.ch.clip.nframes; ++f) {
        pose_of(f, T);
        for (int k = 0; k < 3; ++k) {
            ENSURE(sinew_instance_set_pose(in[k], T, nb) == SINEW_OK);
            ENSURE(sinew_instance_step(in[k], 1.0f / 30) == SINEW_OK);
        }
        /* asking for it changes nothing the step outputs */
        ENSUREF(sw_instance_surface_hash(in[0]) == sw_instance_surface_hash(in[1]),
                "frame %d: the output differs when the collision surface is asked for", f);
        ENSURE(sinew_instance_read_collision_surface(in[0], p, nc) == SINEW_OK);
        ENSURE(sinew_instance_read_collision_surface(in[2], q, nc) == SINEW_OK);
        sw_instance_full_positions(in[0], full, cnt);
        for (uint32_t s = 0; s < nc; ++s) {
            const double *x = full + 3 * (int64_t)sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]);
            for (int k = 0; k < 3; ++k) {
                solved = fmax(solved, fabs(p[3 * s + k] - x[k]));
                placed = fmax(placed, fabs(p[3 * s + k] - q[3 * s + k]));
                moved = fmax(
                    moved,
                    fabs(p[3 * s + k] -
                         v->rest[3 * (int64_t)sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]) +
                                 k]));
            }
        }
    }
    fprintf(stderr,
            "    collision surface (%u vertices): moved %.3g, from the solved boundary %.2e, "
            "placed far and turned %.2e\n",
            nc, moved, solved, placed);
    ENSURE(moved > 0.1);
    ENSUREF(solved <= 1e-6, "the collision surface is %g from the solved boundary", solved);
    ENSUREF(placed <= 1e-5, "placed far and turned, it is %g from the unplaced one", placed);
    /* not asked: refused after a step */
    ENSURE(sinew_instance_read_collision_surface(in[1], p, nc) == SINEW_ERROR_INVALID_ARGUMENT);
    /* the pose-space level: skinned at the pose */
    if (sinew_blob_lod_count(fx.blob) == 3) {
        ENSURE(sinew_instance_set_lod(in[0], SINEW_LOD_POSE_SPACE) == SINEW_OK);
        for (int f = 0; f < 2; ++f) { /* the change's step, then the level's at a bent pose */
            pose_of(fx.ch.clip.nframes / 2 + f, T);
            ENSURE(sinew_instance_set_pose(in[0], T, nb) == SINEW_OK);
            ENSURE(sinew_instance_step(in[0], 1.0f / 30) == SINEW_OK);
        }
        ENSURE(sinew_instance_read_collision_surface(in[0], p, nc) == SINEW_OK);
        double skinned = 0;
        for (uint32_t s = 0; s < nc; ++s) {
            int32_t gv = sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]);
            double Rm[9], t[3];
            sw_dqs_blend(in[0]->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, Rm, t);
            for (int k = 0; k < 3; ++k) {
                const double *X = v->rest + 3 * (int64_t)gv;
                double y = Rm[3 * k] * X[0] + Rm[3 * k + 1] * X[1] + Rm[3 * k + 2] * X[2] + t[k];
                skinned = fmax(skinned, fabs(p[3 * s + k] - y));
            }
        }
        ENSUREF(skinned <= 1e-6, "at the pose-space level it is %g from its skinning", skinned);
    }
    /* closed and edge-manifold: a world takes it as a mesh collider */
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    sinew_collider_def cd = sinew_collider_def_default();
    cd.shape = SINEW_SHAPE_MESH;
    cd.vertices = p;
    cd.vertex_count = nc;
    cd.indices = tris;
    cd.triangle_count = nt;
    sinew_collider_id id;
    ENSURE(sinew_world_add_collider(w, &cd, &id) == SINEW_OK);
    sinew_world_destroy(w);
    for (int k = 0; k < 3; ++k)
        sinew_instance_destroy(in[k]);
    free(T), free(p), free(q), free(full), free(cnt), free(tris);
}

/* ---- the loader ------------------------------------------------------------------ */

/* Parses the forged copy (checksum fixed) and checks the code and the message's words. */
static int rejects(uint8_t *b, sinew_result code, const char *a, const char *c) {
    return parse_refuses(b, fx.size, code, a, c);
}

TEST(the_loader_rejects_a_damaged_render_mesh) {
    ENSURE(finger_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    uint8_t *b = NULL;
    ENSURE(posix_memalign((void **)&b, 64, fx.size) == 0);
#define FRESH() memcpy(b, fx.data, fx.size)
    int32_t dup = -1; /* a duplicate and another one */
    for (int32_t i = 0; i < v->nrender_verts && dup < 0; ++i)
        if (v->render_weld[i] != i) dup = i;
    ENSURE(dup >= 0);

    FRESH();
    ((int32_t *)section(b, SINEW_SECTION_RENDER_TET))[3] = v->nembed_tets;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_TET", "render vertex 3"));
    FRESH();
    ((int32_t *)section(b, SINEW_SECTION_RENDER_TETS))[5] = -1;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_TETS", "tet 1 corner 1"));
    FRESH();
    ((double *)section(b, SINEW_SECTION_RENDER_BARY))[9] = NAN;
    ENSURE(rejects(b, SINEW_ERROR_NOT_FINITE, "RENDER_BARY", "render vertex 2"));
    FRESH();
    ((double *)section(b, SINEW_SECTION_RENDER_BARY))[9] += 0.5; /* sum 1.5 */
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_BARY", "sum"));
    FRESH();
    ((int32_t *)section(b, SINEW_SECTION_RENDER_WELD))[0] = v->nrender_verts;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_WELD", "outside"));
    FRESH(); /* a representative welded to a duplicate: not idempotent */
    ((int32_t *)section(b, SINEW_SECTION_RENDER_WELD))[v->render_weld[dup]] = dup;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_WELD", "idempotent"));
    FRESH();
    ((int32_t *)section(b, SINEW_SECTION_RENDER_TRIS))[4] = -2;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_TRIS", "triangle 1 corner 1"));
    FRESH(); /* a node whose copies are of two vertices */
    int32_t *nc = section(b, SINEW_SECTION_RENDER_NODE_COPIES);
    int32_t n2 = -1;
    for (int32_t n = 0; n < v->nrender_nodes && n2 < 0; ++n)
        if (v->render_node_ptr[n + 1] - v->render_node_ptr[n] >= 2) n2 = n;
    ENSURE(n2 >= 0);
    int32_t c1 = v->render_node_ptr[n2] + 1;
    nc[2 * c1 + 1] = (nc[2 * c1 + 1] + 1) % v->domains[nc[2 * c1]].vert_count;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_NODE_COPIES", "is of vertex"));
    FRESH();
    ((sinew_blob_render_meta *)section(b, SINEW_SECTION_RENDER_META))->nrender_verts += 1;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_TET", "RENDER_META needs"));
    FRESH();
    ((sinew_blob_render_meta *)section(b, SINEW_SECTION_RENDER_META))->reserved[1] = 7;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_META", "reserved"));
    FRESH(); /* one of the eight turned into an unknown id: the rest is incomplete */
    entry(b, SINEW_SECTION_RENDER_WELD)->id = 200;
    ENSURE(rejects(b, SINEW_ERROR_CORRUPT, "RENDER_WELD", "all or none"));
    FRESH(); /* all eight unknown: a blob of the tet boundary, as an older writer's (whose
                blobs had no asset description either: its output map is the render mesh's) */
    for (uint32_t id = SINEW_SECTION_RENDER_FIRST; id <= SINEW_SECTION_RENDER_LAST; ++id)
        entry(b, id)->id = 100 + id;
    for (uint32_t id = SINEW_SECTION_ASSET_FIRST; id <= SINEW_SECTION_ASSET_LAST; ++id)
        entry(b, id)->id = 100 + id;
    for (uint32_t id = SINEW_SECTION_LOD_FIRST; id <= SINEW_SECTION_LOD_LAST; ++id)
        if (entry(b, id)) entry(b, id)->id = 100 + id; /* (its vertices are the render mesh's) */
    fix_checksum(b, fx.size);
    sw_blob_view plain;
    char msg[512];
    ENSUREF(sw_blob_parse(b, fx.size, &plain, msg, sizeof msg) == SINEW_OK, "%s", msg);
    ENSURE(plain.nrender_verts == 0 && sw_blob_output_verts(&plain) == plain.nsurf_verts);
#undef FRESH
    free(b);
}

/* The synthetic character of blob_synth.h with a render mesh: written, parsed back the
 * same, and the fuzz seed tests/fuzz/corpus/blob_fixed/synth_render.blob is these bytes
 * (SINEW_WRITE_SEEDS=1 rewrites it), so the blob fuzzers start from a render mesh. */
TEST(the_synthetic_render_blob_round_trips_and_seeds_the_fuzzer) {
    static fixture f;
    static render_fixture r;
    fixture_init(&f, 7);
    fixture_add_render(&f, &r);
    size_t size = 0;
    sw_blob_view v;
    uint8_t *b = write_parsed(&f, &size, &v);
    ENSURE(b);
    ENSURE(hdr(b)->section_count == SINEW_SECTION_RENDER_LAST);
    ENSURE(v.nrender_verts == NRV && sw_blob_output_verts(&v) == NRV &&
           sw_blob_output_ntris(&v) == NRT);
    ENSURE(memcmp(v.render_bary, r.render_bary, sizeof r.render_bary) == 0 &&
           memcmp(v.render_node_copies, r.render_node_copies, sizeof r.render_node_copies) == 0);
    /* without it, the very bytes of before: 26 sections */
    fixture plain;
    fixture_init(&plain, 7);
    size_t psize = 0;
    uint8_t *p = write_fixture(&plain, &psize);
    ENSURE(p && hdr(p)->section_count == SINEW_SECTION_COUNT_V1 && psize < size);
    free(p);
    ENSURE(seed_is("synth_render.blob", b, size));
    free(b);
}

/* ---- the real-time contract with a render mesh ------------------------------------- */

TEST(the_step_with_a_render_mesh_allocates_and_locks_nothing) {
    ENSURE(finger_fixture());
    const uint32_t n = (uint32_t)sinew_blob_surface_vertex_count(fx.blob),
                   nb = (uint32_t)fx.ch.skel.nbones;
    sinew_instance *q, *d;
    sinew_instance_def dd = sinew_instance_def_default();
    dd.mode = SINEW_STEP_DYNAMIC;
    ENSURE(sinew_instance_create(fx.blob, NULL, &q) == SINEW_OK);
    ENSURE(sinew_instance_create(fx.blob, &dd, &d) == SINEW_OK);
    float *T = malloc(sizeof(float) * 12 * nb), *p = malloc(sizeof(float) * 3 * n),
          *nr = malloc(sizeof(float) * 3 * n);
    const int active = sw_rt_interpose_active();
    int bad = 0;
    sw_rt_count_begin();
    for (int s = 0; s < 200; ++s) {
        pose_of(s, T);
        bad += sinew_instance_set_pose(q, T, nb) != SINEW_OK;
        bad += sinew_instance_set_pose(d, T, nb) != SINEW_OK;
        bad += sinew_instance_step(q, 1.0f / 30) != SINEW_OK;
        bad += sinew_instance_step(d, 1.0f / 30) != SINEW_OK;
        bad += sinew_instance_read_surface(q, p, nr, n) != SINEW_OK;
        bad += sinew_instance_read_surface(d, p, nr, n) != SINEW_OK;
    }
    sw_rt_counts c = sw_rt_count_end();
    char buf[256];
    fprintf(stderr, "    400 steps with a render mesh: %s\n",
            sw_rt_counts_describe(&c, buf, sizeof buf));
    free(T), free(p), free(nr);
    sinew_instance_destroy(q);
    sinew_instance_destroy(d);
    ENSURE(bad == 0);
    if (active & SW_RT_CAT_ALLOCS) ENSURE(c.allocs == 0);
    if (active & SW_RT_CAT_FREES) ENSURE(c.frees == 0);
    if (active & SW_RT_CAT_MAPS) ENSURE(c.maps == 0);
    if (active & SW_RT_CAT_LOCKS) ENSURE(c.locks == 0);
    if ((active & (SW_RT_CAT_ALLOCS | SW_RT_CAT_LOCKS)) != (SW_RT_CAT_ALLOCS | SW_RT_CAT_LOCKS))
        SKIP("allocations or locks cannot be observed in this build (active mask %d): every "
             "observable count is 0, the contract is not proven here",
             active);
}

/* r cut to the triangles wholly in the upper half of its longest extent, its vertices
 * renumbered (a render mesh over part of the body). */
static void keep_upper_half(sw_trimesh *r) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < r->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], r->X[3 * i + k]);
            hi[k] = fmax(hi[k], r->X[3 * i + k]);
        }
    int a = 0;
    for (int k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[a] - lo[a]) a = k;
    double mid = 0.5 * (lo[a] + hi[a]);
    int32_t *map = malloc(sizeof(int32_t) * (size_t)r->nverts), nt = 0, nv = 0;
    for (int32_t i = 0; i < r->nverts; ++i)
        map[i] = -1;
    for (int32_t t = 0; t < r->ntris; ++t) {
        const int32_t *c = r->tris + 3 * t;
        if (r->X[3 * c[0] + a] <= mid || r->X[3 * c[1] + a] <= mid || r->X[3 * c[2] + a] <= mid)
            continue;
        for (int k = 0; k < 3; ++k) {
            if (map[c[k]] < 0) map[c[k]] = nv++;
            r->tris[3 * nt + k] = c[k];
        }
        nt++;
    }
    double *X = malloc(sizeof(double) * 3 * (size_t)nv);
    for (int32_t i = 0; i < r->nverts; ++i)
        if (map[i] >= 0) memcpy(X + 3 * map[i], r->X + 3 * i, 3 * sizeof(double));
    for (int32_t k = 0; k < 3 * nt; ++k)
        r->tris[k] = map[r->tris[k]];
    free(r->X);
    free(map);
    r->X = X;
    r->nverts = nv;
    r->ntris = nt;
}

/* Under a render mesh the boundary's surface copies are read only by the world's contact:
 * an instance skins them only while a world is attached (instance.c's active vertices).
 * Stepped without one, then with an empty world: every copy the world reads sits where
 * its own skinning of the current pose and the state put it. */
TEST(surface_copies_follow_the_pose_once_a_world_is_attached) {
    /* the finger under a render mesh of its upper half: the other half's boundary
       vertices carry no render node */
    sw_character ch;
    sw_bake_result res;
    sw_error err;
    void *data = NULL;
    size_t size = 0;
    sinew_blob *blob;
    ENSURE(sw_sample_make("finger", 2000, 12, &ch, &err) == SINEW_OK);
    ENSURE(make_render(&ch.mesh, &ch.render));
    keep_upper_half(&ch.render);
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3;
    p.max_train_frames = 8;
    p.threads = 2;
    ENSUREF(sw_bake(&ch, &p, &res, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(sw_blob_write_memory(&res.view, &data, &size, &err) == SINEW_OK);
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = data;
    bd.data_size = size;
    ENSURE(sinew_blob_load(&bd, &blob) == SINEW_OK);
    const sw_blob_view *v = sw_blob_get_view(blob);
    const uint32_t nb = (uint32_t)ch.skel.nbones;
    sinew_instance *in;
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_instance_create(blob, NULL, &in) == SINEW_OK);
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    ENSUREF(in->red.nact_step < in->red.nact && !in->red.skin_surface,
            "%d of %d active vertices every step", in->red.nact_step, in->red.nact);
    float *T = malloc(sizeof(float) * 12 * nb);
    ENSURE(T);
    int s = 0;
    for (; s < 4; ++s) {
        for (uint32_t i = 0; i < 12 * nb; ++i)
            T[i] = (float)ch.clip.T[(size_t)s * 12 * nb + i];
        ENSURE(sinew_instance_set_pose(in, T, nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    }
    ENSURE(sinew_instance_set_world(in, w) == SINEW_OK && in->red.skin_surface);
    for (uint32_t i = 0; i < 12 * nb; ++i) /* a pose the surface copies were never skinned at */
        T[i] = (float)ch.clip.T[(size_t)(s + 2) * 12 * nb + i];
    ENSURE(sinew_instance_set_pose(in, T, nb) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    double gap = 0;
    for (int32_t i = 0; i < v->nsurf_copies; ++i) {
        const sw_blob_domain *D = &v->domains[v->surf_copies[2 * i]];
        int32_t lv = v->surf_copies[2 * i + 1], gv = v->domain_verts[D->vert_begin + lv],
                r = D->rank;
        double Rm[9], t[3], y[3], x[3];
        sw_dqs_blend(in->bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, Rm, t);
        for (int k = 0; k < 3; ++k) {
            y[k] = v->rest[3 * (int64_t)gv + k];
            for (int32_t j = 0; j < r; ++j)
                y[k] += v->basis[D->basis_offset + (int64_t)(3 * lv + k) * r + j] *
                        in->solver.q[D->q_offset + j];
        }
        for (int k = 0; k < 3; ++k) {
            x[k] = Rm[3 * k] * y[0] + Rm[3 * k + 1] * y[1] + Rm[3 * k + 2] * y[2] + t[k];
            gap = fmax(gap, fabs(x[k] - in->wc.copy_x[3 * (int64_t)i + k]));
        }
    }
    fprintf(stderr, "    %d surface copies with a world: within %.2e of their own skinning\n",
            v->nsurf_copies, gap);
    ENSUREF(gap <= 1e-9 * in->size, "a surface copy is %g from its own skinning", gap);
    ENSURE(sinew_instance_set_world(in, NULL) == SINEW_OK && !in->red.skin_surface);
    free(T);
    sinew_world_destroy(w);
    sinew_instance_destroy(in);
    sinew_blob_destroy(blob);
    free(data);
    sw_bake_result_free(&res);
    sw_character_free(&ch);
}

TEST(release_fixture) {
    if (fx_ok > 0) {
        sinew_blob_destroy(fx.blob);
        free(fx.data);
        sw_bake_result_free(&fx.res);
        sw_character_free(&fx.ch);
    }
}

SW_TEST_MAIN(CASE(embedding_reproduces_the_arm_at_rest), CASE(embedding_refuses_what_does_not_fit),
             CASE(the_output_surface_is_the_render_mesh),
             CASE(welded_duplicates_move_and_shade_as_one),
             CASE(the_collision_surface_is_the_boundary_under_a_render_mesh),
             CASE(the_loader_rejects_a_damaged_render_mesh),
             CASE(the_synthetic_render_blob_round_trips_and_seeds_the_fuzzer),
             CASE(the_step_with_a_render_mesh_allocates_and_locks_nothing),
             CASE(surface_copies_follow_the_pose_once_a_world_is_attached), CASE(release_fixture))
