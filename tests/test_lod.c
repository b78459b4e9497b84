/* Levels of detail (sinew_lod): the pose-space level corrects skinning on the bake's own
 * poses and on held-out ones against the full-space reference; every level gives the same
 * flesh turned, moved and scaled; a change of level moves no vertex by more than the frame
 * itself moves the surface; levels a blob lacks, and broken LOD sections, are refused. On
 * the folding finger at 2,000 tets. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake_eval.h"
#include "bake_fixture.h"
#include "instance.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

/* The rest bounding-box diagonal of the blob. */
static double diag(const sw_blob_view *v) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < v->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], v->rest[3 * i + k]);
            hi[k] = fmax(hi[k], v->rest[3 * i + k]);
        }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

TEST(the_pose_space_level_corrects_skinning_where_the_reference_bends) {
    const bake_fixture *f = fixture();
    ENSURE(f && sinew_blob_lod_count(f->blob) == 3);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    ENSURE(v->lod_rank >= 1 && v->lod_rank <= SINEW_BLOB_LOD_MAX_RANK);
    /* on the training poses it holds most of the correction, held out it still beats
       skinning; the full level is the better one on both */
    sw_error err;
    for (int l = 0; l < 3; ++l) {
        sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC, .dt = 1.0f / 30, .lod = l};
        sw_eval_result tr;
        ENSURE(sw_eval_correction_opts(f->blob, f->res.mass, f->res.train_T, f->res.train_x,
                                       f->res.ntrain, &o, &tr, &err) == SINEW_OK);
        ENSURE(tr.failed == 0 && tr.frames == f->res.ntrain);
        fprintf(stderr, "  level %d: training surface error %.4f, held-out %.4f\n", l,
                tr.surface_error, f->res.lod_heldout[l]);
        ENSUREF(tr.surface_error < (l == 2 ? 0.35 : 0.1), "level %d trains to %.4f", l,
                tr.surface_error);
        ENSURE(f->res.lod_heldout[l] > 0 && f->res.lod_heldout[l] < 1);
    }
    ENSURE(f->res.lod_heldout[0] < f->res.lod_heldout[2]);
}

/* The output surface (actor frame) of one step at clip frame k, level l, the actor at
 * A (NULL: identity) with the bones scaled by s. */
static int surface_at(const bake_fixture *f, sinew_lod l, const double *A, double s, int k,
                      float *x) {
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, NULL, &inst) != SINEW_OK) return 0;
    int32_t nb = f->ch.skel.nbones;
    float *T = malloc(sizeof(float) * 12 * (size_t)nb);
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    int ok = T && sinew_instance_set_lod(inst, l) == SINEW_OK &&
             (!A || sinew_instance_set_actor(inst, A) == SINEW_OK);
    for (int j = 0; ok && j <= k; ++j) {
        bake_fixture_pose(f, j, T);
        for (int32_t i = 0; i < 12 * nb; ++i)
            T[i] *= (float)s;
        ok = sinew_instance_set_pose(inst, T, (uint32_t)nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK;
    }
    ok = ok && sinew_instance_read_surface(inst, x, NULL, ns) == SINEW_OK;
    sinew_instance_destroy(inst);
    free(T);
    return ok;
}

TEST(every_level_is_the_same_flesh_turned_moved_and_scaled) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const double L = diag(sw_blob_get_view(f->blob));
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    float *a = malloc(sizeof(float) * 3 * ns), *b = malloc(sizeof(float) * 3 * ns);
    ENSURE(a && b);
    const double c = cos(2.5), s = sin(2.5);
    const double A[12] = {c, -s, 0, s, c, 0, 0, 0, 1, 3e4, -2e4, 5e3}; /* turned, far out */
    for (int l = 0; l < 3; ++l) {
        ENSURE(surface_at(f, (sinew_lod)l, NULL, 1, 9, a));
        ENSURE(surface_at(f, (sinew_lod)l, A, 1, 9, b));
        double gap = 0;
        for (uint32_t i = 0; i < 3 * ns; ++i)
            gap = fmax(gap, fabs((double)a[i] - b[i]));
        ENSUREF(gap < 1e-5 * L, "level %d: turned and moved, %.3g of the size", l, gap / L);
        ENSURE(surface_at(f, (sinew_lod)l, NULL, 2, 9, b)); /* twice the size */
        gap = 0;
        for (uint32_t i = 0; i < 3 * ns; ++i)
            gap = fmax(gap, fabs(2.0 * a[i] - b[i]));
        ENSUREF(gap < 1e-5 * L, "level %d: scaled, %.3g of the size", l, gap / L);
    }
    free(a), free(b);
}

/* Steps the clip for `frames` frames at level `start`, the level changed at the frames of
 * `at` (to to[k]), the surface of each frame into x (frames x 3 ns doubles) and the level
 * it shows into shown (the old one at a change); the stats' level and fade checked. */
static int play(const bake_fixture *f, int frames, sinew_lod start, const int *at,
                const sinew_lod *to, int nat, double *x, sinew_lod *shown) {
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, NULL, &inst) != SINEW_OK) return 0;
    int32_t nb = f->ch.skel.nbones;
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    float *T = malloc(sizeof(float) * 12 * (size_t)nb), *y = malloc(sizeof(float) * 3 * ns);
    int ok = T && y && sinew_instance_set_lod(inst, start) == SINEW_OK, k = 0;
    sinew_lod level = start;
    float fade = 0;
    for (int j = 0; ok && j < frames; ++j) {
        int change = k < nat && at[k] == j;
        shown[j] = level;
        if (change) ok = sinew_instance_set_lod(inst, level = to[k++]) == SINEW_OK;
        bake_fixture_pose(f, j, T);
        ok = ok && sinew_instance_set_pose(inst, T, (uint32_t)nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK &&
             sinew_instance_read_surface(inst, y, NULL, ns) == SINEW_OK;
        sinew_step_stats st = {.struct_size = sizeof st};
        ok = ok && sinew_instance_get_stats(inst, &st) == SINEW_OK;
        /* a change shows all of the old surface, then fades by 1/8 a step at the fastest */
        ok = ok && st.lod == (uint32_t)level &&
             (change ? st.lod_blend == 1.0f
                     : st.lod_blend <= fade && st.lod_blend >= fade - 1.0f / 8 - 1e-6f);
        fade = st.lod_blend;
        for (uint32_t i = 0; ok && i < 3 * ns; ++i)
            x[(size_t)j * 3 * ns + i] = y[i];
    }
    sinew_instance_destroy(inst);
    free(T), free(y);
    return ok;
}

/* The largest move of a vertex from frame j - 1 to frame j. */
static double largest_move(const double *x, uint32_t ns, int j) {
    double m = 0;
    for (uint32_t s = 0; s < ns; ++s) {
        const double *a = x + ((size_t)j * ns + s) * 3, *b = a - 3 * (size_t)ns;
        m = fmax(m, sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                         (a[2] - b[2]) * (a[2] - b[2])));
    }
    return m;
}

TEST(a_change_of_level_moves_no_vertex_more_than_the_frame_moves) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const int frames = 40;
    const double L = diag(sw_blob_get_view(f->blob));
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    double *pure[3], *mixed = malloc(sizeof(double) * 3 * ns * frames);
    sinew_lod shown[40], unused[40];
    for (int l = 0; l < 3; ++l) {
        pure[l] = malloc(sizeof(double) * 3 * ns * frames);
        ENSURE(pure[l] && play(f, frames, (sinew_lod)l, NULL, NULL, 0, pure[l], unused));
    }
    ENSURE(mixed);
    /* every change there is, some in the middle of another's fade, some at still frames
       (the clip's last pose is its first) */
    const int at[] = {3, 9, 11, 14, 18, 21, 23, 24, 29, 35};
    const sinew_lod to[] = {SINEW_LOD_POSE_SPACE, SINEW_LOD_FULL,       SINEW_LOD_POSE_SPACE,
                            SINEW_LOD_REDUCED,    SINEW_LOD_POSE_SPACE, SINEW_LOD_REDUCED,
                            SINEW_LOD_FULL,       SINEW_LOD_POSE_SPACE, SINEW_LOD_FULL,
                            SINEW_LOD_POSE_SPACE};
    ENSURE(play(f, frames, SINEW_LOD_FULL, at, to, 10, mixed, shown));
    /* a frame moves the surface as much as the levels it shows move it, and a change adds
       at most half of that: nothing where the character stands still (the clip's loop) */
    double worst = 0;
    for (int j = 1; j < frames; ++j) {
        sinew_lod a = shown[j - 1], b = shown[j];
        double own = fmax(largest_move(pure[a], ns, j), largest_move(pure[b], ns, j));
        double moved = largest_move(mixed, ns, j);
        if (getenv("SW_LOD_TRACE"))
            fprintf(stderr, "  frame %d (%d, %d): %.4f / %.4f\n", j, a, b, moved, own);
        worst = fmax(worst, (moved - own) / fmax(own, 1e-300));
        ENSUREF(moved <= 1.5 * own + 1e-4 * L,
                "frame %d: a vertex moved %.4g, the frame moves the surface %.4g", j, moved, own);
    }
    fprintf(stderr, "  a change's largest addition to a frame's move: %.3f of it\n", worst);
    for (int l = 0; l < 3; ++l)
        free(pure[l]);
    free(mixed);
}

TEST(levels_a_blob_lacks_are_refused) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_lod(NULL, SINEW_LOD_FULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_set_lod(inst, (sinew_lod)3) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_set_lod(inst, (sinew_lod)-1) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_instance_destroy(inst);
    /* the same blob written without the pose-space level: two levels */
    sw_blob_view v = *sw_blob_get_view(f->blob);
    v.lod_rank = v.nlod_verts = 0;
    void *data = NULL;
    size_t size = 0;
    sw_error err;
    ENSURE(sw_blob_write_memory(&v, &data, &size, &err) == SINEW_OK);
    sinew_blob_def d = sinew_blob_def_default();
    d.data = data;
    d.data_size = size;
    sinew_blob *blob;
    ENSURE(sinew_blob_load(&d, &blob) == SINEW_OK);
    ENSURE(sinew_blob_lod_count(blob) == 2 && sinew_blob_lod_count(NULL) == 0);
    ENSURE(sinew_instance_create(blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_lod(inst, SINEW_LOD_POSE_SPACE) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_set_lod(inst, SINEW_LOD_REDUCED) == SINEW_OK);
    ENSURE(sinew_lod_for_screen_size(blob, 0.01f) == SINEW_LOD_REDUCED);
    sinew_instance_destroy(inst);
    sinew_blob_destroy(blob);
    free(data);
}

TEST(the_screen_size_rule_picks_cheaper_levels_further_away) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.5f) == SINEW_LOD_FULL);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.25f) == SINEW_LOD_FULL);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.2f) == SINEW_LOD_REDUCED);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.08f) == SINEW_LOD_REDUCED);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.05f) == SINEW_LOD_POSE_SPACE);
    ENSURE(sinew_lod_for_screen_size(f->blob, 0.0f) == SINEW_LOD_POSE_SPACE);
    ENSURE(sinew_lod_for_screen_size(f->blob, NAN) == SINEW_LOD_FULL);
    ENSURE(sinew_lod_for_screen_size(f->blob, INFINITY) == SINEW_LOD_FULL);
}

TEST(broken_lod_sections_are_refused) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v0 = sw_blob_get_view(f->blob);
    const int32_t n = v0->nlod_verts, m = v0->lod_rank;
    int32_t *bone = malloc(sizeof(int32_t) * 4 * (size_t)n);
    double *w = malloc(sizeof(double) * 4 * (size_t)n);
    float *B = malloc(sizeof(float) * 3 * (size_t)n * m);
    double *W = malloc(sizeof(double) * (size_t)m * (9 * v0->nbones + 1));
    ENSURE(bone && w && B && W);
    char msg[256];
    struct {
        int what;
        sinew_result want;
    } cases[] = {{0, SINEW_ERROR_CORRUPT},
                 {1, SINEW_ERROR_CORRUPT},
                 {2, SINEW_ERROR_CORRUPT},
                 {3, SINEW_ERROR_NOT_FINITE},
                 {4, SINEW_ERROR_NOT_FINITE}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        sw_blob_view v = *v0;
        memcpy(bone, v0->lod_bone, sizeof(int32_t) * 4 * (size_t)n);
        memcpy(w, v0->lod_weight, sizeof(double) * 4 * (size_t)n);
        memcpy(B, v0->lod_basis, sizeof(float) * 3 * (size_t)n * m);
        memcpy(W, v0->lod_map, sizeof(double) * (size_t)m * (9 * v0->nbones + 1));
        v.lod_bone = bone, v.lod_weight = w, v.lod_basis = B, v.lod_map = W;
        ENSURE(sw_blob_validate_view(&v, msg, sizeof msg) == SINEW_OK);
        switch (cases[k].what) {
        case 0:
            bone[4 * (n / 2) + 1] = v.nbones;
            break; /* a bone the blob lacks */
        case 1:
            w[4 * (n / 3)] += 0.5;
            break; /* weights not summing to 1 */
        case 2:
            B[(size_t)3 * n * m / 2] = 1.5f;
            break; /* not an orthonormal mode */
        case 3:
            B[7] = NAN;
            break;
        default:
            W[m] = INFINITY;
            break;
        }
        sinew_result r = sw_blob_validate_view(&v, msg, sizeof msg);
        ENSUREF(r == cases[k].want, "case %zu: %d (%s)", k, (int)r, msg);
        ENSURE(strstr(msg, "LOD_") != NULL);
    }
    free(bone), free(w), free(B), free(W);
}

static void cleanup(void) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

TEST(zz_cleanup) {
    cleanup();
}

SW_TEST_MAIN(CASE(the_pose_space_level_corrects_skinning_where_the_reference_bends),
             CASE(every_level_is_the_same_flesh_turned_moved_and_scaled),
             CASE(a_change_of_level_moves_no_vertex_more_than_the_frame_moves),
             CASE(levels_a_blob_lacks_are_refused),
             CASE(the_screen_size_rule_picks_cheaper_levels_further_away),
             CASE(broken_lod_sections_are_refused), CASE(zz_cleanup))
