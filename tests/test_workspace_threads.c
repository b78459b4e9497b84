/* Shared step workspaces (runtime/instance/workspace.c): instances that keep no scratch of
 * their own and step in workspaces lent to them give bitwise the results of instances
 * with their own, stepped interleaved in one workspace and on two threads whose
 * workspaces trade instances every step, allocating and locking nothing; they reserve far
 * less; the def and the workspace are checked. Quasistatic and dynamic, with condensation patches
 * around a ball that moves along the folding finger and a table under it (world_fixture.h). Runs
 * under TSan (the "threads" label). */
#include <pthread.h>
#include <stdint.h>

#include "blob_load.h"
#include "rt_interpose.h"
#include "sw_test.h"
#include "world_fixture.h"

enum { NINST = 4, STEPS = 40 };

/* Instance k's def: quasistatic or dynamic, with or without a patch budget. */
static sinew_instance_def def_of(int k, int shared) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = k % 2 ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
    d.max_patch_vertices = k >= 2 ? 400 : 0;
    d.shared_workspace = (uint32_t)shared;
    return d;
}

typedef struct {
    moving_scene ms;
    sinew_instance *in[NINST];
    float *out[NINST]; /* the surfaces of every step, 3 ns floats a step */
    uint32_t ns;
} run;

static int run_make(run *r, int shared) {
    memset(r, 0, sizeof *r);
    if (!moving_scene_make(&r->ms)) return 0;
    r->ns = sinew_blob_surface_vertex_count(r->ms.f->blob);
    for (int k = 0; k < NINST; ++k) {
        sinew_instance_def d = def_of(k, shared);
        if (sinew_instance_create(r->ms.f->blob, &d, &r->in[k]) != SINEW_OK ||
            sinew_instance_set_world(r->in[k], r->ms.w) != SINEW_OK)
            return 0;
        r->out[k] = malloc(sizeof(float) * 3 * r->ns * STEPS);
        if (!r->out[k]) return 0;
    }
    return 1;
}

static void run_free(run *r) {
    for (int k = 0; k < NINST; ++k) {
        sinew_instance_destroy(r->in[k]);
        free(r->out[k]);
    }
    sinew_world_destroy(r->ms.w);
}

/* The world and instance k's pose at step s. */
static void scene_at(run *r, int s) {
    sinew_transform t;
    ball_at(s, &t);
    sinew_world_set_collider_transform(r->ms.w, r->ms.ball, &t);
}

/* Step s of instance k (in ws, or its own scratch with ws NULL), its surface kept; the
 * steps with a patch counted into *patched. */
static int step_one(run *r, int k, int s, sinew_workspace *ws, uint32_t *patched) {
    const bake_fixture *f = r->ms.f;
    const int nb = f->ch.skel.nbones, nfr = f->ch.clip.nframes;
    float pose[12 * 16];
    if (nb > 16) return 0;
    bake_fixture_pose(f, (s + 5 * k) % nfr, pose);
    sinew_instance *in = r->in[k];
    if (sinew_instance_set_pose(in, pose, (uint32_t)nb) != SINEW_OK) return 0;
    sinew_result res =
        ws ? sinew_instance_step_in(in, ws, 1.0f / 30) : sinew_instance_step(in, 1.0f / 30);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    sinew_instance_get_stats(in, &st);
    *patched += st.patch_vertices > 0;
    return res == SINEW_OK && sinew_instance_read_surface(in, r->out[k] + (size_t)3 * r->ns * s,
                                                          NULL, r->ns) == SINEW_OK;
}

/* Two threads, each with its workspace, stepping half the instances a step: thread t
 * steps the instances k with (k + s) % 2 == t, so that every instance changes workspace
 * (and thread) every step. */
typedef struct {
    run *r;
    sinew_workspace *ws;
    int t, s, ok;
    uint32_t patched; /* this thread's own count: the threads share nothing they write */
} half;

static void *step_half(void *p) {
    half *h = p;
    h->ok = 1;
    for (int k = 0; k < NINST; ++k)
        if ((k + h->s) % 2 == h->t) h->ok &= step_one(h->r, k, h->s, h->ws, &h->patched);
    return NULL;
}

static int same_surfaces(const run *a, const run *b) {
    for (int k = 0; k < NINST; ++k)
        if (memcmp(a->out[k], b->out[k], sizeof(float) * 3 * a->ns * STEPS) != 0) {
            fprintf(stderr, "    instance %d differs\n", k);
            return 0;
        }
    return 1;
}

TEST(workspaces_lent_to_instances_give_their_own_scratchs_results_bitwise) {
    run own, one, two;
    ENSURE(run_make(&own, 0) && run_make(&one, 1) && run_make(&two, 1));
    const sinew_blob *blob = own.ms.f->blob;
    sinew_instance_def wd = def_of(3, 0); /* dynamic, with patches */
    sinew_workspace *ws[2];
    ENSURE(sinew_workspace_create(blob, &wd, &ws[0]) == SINEW_OK);
    ENSURE(sinew_workspace_create(blob, &wd, &ws[1]) == SINEW_OK);
    unsigned long allocs = 0, locks = 0;
    uint32_t patched = 0, shared = 0;
    for (int s = 0; s < STEPS; ++s) {
        scene_at(&own, s);
        scene_at(&one, s);
        scene_at(&two, s);
        for (int k = 0; k < NINST; ++k)
            ENSURE(step_one(&own, k, s, NULL, &patched));
        sw_rt_count_begin();
        int ok = 1;
        for (int k = 0; k < NINST; ++k)
            ok &= step_one(&one, k, s, ws[0], &shared); /* every instance in one workspace */
        sw_rt_counts cnt = sw_rt_count_end();
        ENSURE(ok);
        allocs += cnt.allocs + cnt.frees;
        locks += cnt.locks;
        half h[2] = {{&two, ws[0], 0, s, 0, 0}, {&two, ws[1], 1, s, 0, 0}};
        pthread_t th[2];
        for (int t = 0; t < 2; ++t)
            ENSURE(pthread_create(&th[t], NULL, step_half, &h[t]) == 0);
        for (int t = 0; t < 2; ++t)
            pthread_join(th[t], NULL);
        ENSURE(h[0].ok && h[1].ok);
    }
    fprintf(stderr,
            "    %u of %d steps with a patch; in the workspace %lu allocations, %lu locks\n",
            patched, NINST * STEPS, allocs, locks);
    unsigned active = sw_rt_interpose_active();
    if (active & SW_RT_CAT_ALLOCS) ENSURE(allocs == 0);
    if (active & SW_RT_CAT_LOCKS) ENSURE(locks == 0);
    ENSURE(patched > STEPS / 2); /* the patches' scratch is exercised */
    ENSURE(shared == patched);
    ENSURE(same_surfaces(&own, &one));
    ENSURE(same_surfaces(&own, &two));
    /* the instances differ from each other: the comparison is not of identical runs */
    ENSURE(memcmp(own.out[0], own.out[1], sizeof(float) * 3 * own.ns * STEPS) != 0);
    sinew_workspace_destroy(ws[0]);
    sinew_workspace_destroy(ws[1]);
    run_free(&own);
    run_free(&one);
    run_free(&two);
}

TEST(a_shared_instance_reserves_its_state_alone) {
    const bake_fixture *f = fixture();
    ENSURE(f != NULL);
    const int64_t R = sw_blob_get_view(f->blob)->rank_total;
    for (int k = 0; k < NINST; ++k) {
        sinew_instance_def own = def_of(k, 0), shared = def_of(k, 1);
        size_t a, b, w;
        ENSURE(sinew_instance_memory_size(f->blob, &own, &a) == SINEW_OK);
        ENSURE(sinew_instance_memory_size(f->blob, &shared, &b) == SINEW_OK);
        ENSURE(sinew_workspace_memory_size(f->blob, &own, &w) == SINEW_OK);
        fprintf(stderr, "    def %d: %zu bytes with its scratch, %zu without; workspace %zu\n", k,
                a, b, w);
        /* the Hessian and its factor (and the damping Hessian, the patch's copy) are the
           workspace's */
        const int64_t squares = 2 + (k % 2) + (k >= 2);
        ENSURE((int64_t)(a - b) >= squares * R * R * (int64_t)sizeof(double));
        ENSURE(w >= a - b && w < a - b + 4096); /* the same arrays, and its header */
    }
}

TEST(the_def_and_the_workspace_are_checked) {
    const bake_fixture *f = fixture();
    ENSURE(f != NULL);
    sinew_instance_def d = def_of(0, 2);
    sinew_instance *in = NULL;
    sinew_workspace *ws = NULL, *plain = NULL;
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_ERROR_INVALID_ARGUMENT && !in);
    ENSURE(sinew_workspace_create(f->blob, &d, &ws) == SINEW_ERROR_INVALID_ARGUMENT && !ws);
    ENSURE(sinew_workspace_create(NULL, NULL, &ws) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_workspace_create(f->blob, NULL, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    size_t bytes;
    ENSURE(sinew_workspace_memory_size(f->blob, NULL, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_workspace_memory_size(NULL, NULL, &bytes) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_workspace_destroy(NULL);
    /* a shared instance steps only in a workspace, and in one with its patches and its
       dynamics */
    d = def_of(3, 1);
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    ENSURE(sinew_workspace_create(f->blob, NULL, &plain) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step_in(in, plain, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_instance_def quasi = def_of(2, 0);
    ENSURE(sinew_workspace_create(f->blob, &quasi, &ws) == SINEW_OK);
    ENSURE(sinew_instance_step_in(in, ws, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_workspace_destroy(ws);
    ENSURE(sinew_instance_step_in(in, NULL, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step_in(NULL, plain, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_workspace_create(f->blob, &d, &ws) == SINEW_OK);
    ENSURE(sinew_instance_step_in(in, ws, 2.0f) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step_in(in, ws, 1.0f / 30) == SINEW_OK);
    /* a workspace of another blob (the same bytes loaded again) */
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = f->data;
    bd.data_size = f->size;
    sinew_blob *again = NULL;
    sinew_workspace *other = NULL;
    ENSURE(sinew_blob_load(&bd, &again) == SINEW_OK);
    ENSURE(sinew_workspace_create(again, &d, &other) == SINEW_OK);
    ENSURE(sinew_instance_step_in(in, other, 1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_workspace_destroy(other);
    sinew_blob_destroy(again);
    sinew_instance_destroy(in);
    sinew_workspace_destroy(ws);
    sinew_workspace_destroy(plain);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(workspaces_lent_to_instances_give_their_own_scratchs_results_bitwise),
             CASE(a_shared_instance_reserves_its_state_alone),
             CASE(the_def_and_the_workspace_are_checked), CASE(release_fixture))
