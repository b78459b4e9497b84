/* The runtime's contract (DESIGN.md §3): no allocation and no lock inside the step
 * (counted by the interposer over 10,000 steps after warm-up), identical output for
 * identical runs, clear errors for bad input with the state kept, and an instance that
 * recovers from them. */
#include <stdint.h>

#include "bake_fixture.h"
#include "rt_interpose.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 1);
    return fx_ok ? &fx : NULL;
}

/* FNV-1a over float outputs: a bitwise fingerprint of a run. */
static uint64_t hash_floats(uint64_t h, const float *x, size_t n) {
    const unsigned char *p = (const unsigned char *)x;
    for (size_t i = 0; i < n * sizeof(float); ++i)
        h = (h ^ p[i]) * 0x100000001b3ULL;
    return h;
}

static uint64_t run_hash(sinew_step_mode mode, int steps) {
    const bake_fixture *f = fixture();
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return 0;
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    float *pose = malloc(sizeof(float) * 12 * f->ch.skel.nbones),
          *x = malloc(sizeof(float) * 3 * ns);
    uint64_t h = 0xcbf29ce484222325ULL;
    for (int s = 0; s < steps; ++s) {
        bake_fixture_pose(f, s, pose);
        sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones);
        sinew_instance_step(inst, 1.0f / 30);
        sinew_instance_read_surface(inst, x, NULL, ns);
        h = hash_floats(h, x, 3 * ns);
    }
    free(pose);
    free(x);
    sinew_instance_destroy(inst);
    return h;
}

static void count_steps(sinew_step_mode mode) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    unsigned active = sw_rt_interpose_active(); /* outside the counted section */
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob), nb = (uint32_t)f->ch.skel.nbones;
    int frames = f->ch.clip.nframes;
    float *poses = malloc(sizeof(float) * 12 * nb * frames), *x = malloc(sizeof(float) * 3 * ns),
          *n = malloc(sizeof(float) * 3 * ns);
    for (int k = 0; k < frames; ++k)
        bake_fixture_pose(f, k, poses + (size_t)12 * nb * k);
    for (int s = 0; s < 20; ++s) { /* warm-up */
        sinew_instance_set_pose(inst, poses + (size_t)12 * nb * (s % frames), nb);
        sinew_instance_step(inst, 1.0f / 30);
    }
    sinew_step_stats st;
    st.struct_size = sizeof st;
    sw_rt_count_begin();
    for (int s = 0; s < 10000; ++s) {
        sinew_instance_set_pose(inst, poses + (size_t)12 * nb * (s % frames), nb);
        sinew_instance_step(inst, 1.0f / 30);
        sinew_instance_read_surface(inst, x, n, ns);
        sinew_instance_get_stats(inst, &st);
    }
    sw_rt_counts c = sw_rt_count_end();
    char buf[512];
    fprintf(stderr, "    10000 steps: %s\n", sw_rt_counts_describe(&c, buf, sizeof buf));
    if (active & SW_RT_CAT_ALLOCS) ENSUREF(c.allocs == 0, "%s", buf);
    if (active & SW_RT_CAT_FREES) ENSUREF(c.frees == 0, "%s", buf);
    if (active & SW_RT_CAT_MAPS) ENSUREF(c.maps == 0, "%s", buf);
    if (active & SW_RT_CAT_LOCKS) ENSUREF(c.locks == 0, "%s", buf);
    if (!(active & SW_RT_CAT_LOCKS)) fprintf(stderr, "    (locks not observable in this build)\n");
    free(poses);
    free(x);
    free(n);
    sinew_instance_destroy(inst);
}

TEST(quasistatic_step_allocates_and_locks_nothing) {
    count_steps(SINEW_STEP_QUASISTATIC);
}
TEST(dynamic_step_allocates_and_locks_nothing) {
    count_steps(SINEW_STEP_DYNAMIC);
}

TEST(identical_runs_give_identical_output) {
    ENSURE(fixture());
    uint64_t a = run_hash(SINEW_STEP_QUASISTATIC, 40), b = run_hash(SINEW_STEP_QUASISTATIC, 40);
    uint64_t c = run_hash(SINEW_STEP_DYNAMIC, 40), d = run_hash(SINEW_STEP_DYNAMIC, 40);
    ENSURE(a != 0 && a == b);
    ENSURE(c != 0 && c == d);
    ENSURE(a != c); /* the two modes really differ */
}

TEST(bad_input_is_rejected_and_state_kept) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *inst;
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(sinew_instance_create(NULL, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    d.mode = (sinew_step_mode)7;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    d = sinew_instance_def_default();
    d.struct_size = 2;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float *pose = malloc(sizeof(float) * 12 * nb), *x0 = malloc(sizeof(float) * 3 * ns),
          *x1 = malloc(sizeof(float) * 3 * ns);
    bake_fixture_pose(f, 4, pose);
    ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
    for (int k = 0; k < 10; ++k) /* converged: a repeated step leaves the shape */
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(inst, x0, NULL, ns) == SINEW_OK);
    /* wrong counts, NaN, a non-rigid transform, absurd dt: errors, nothing changes */
    ENSURE(sinew_instance_set_pose(inst, pose, nb + 1) == SINEW_ERROR_INVALID_ARGUMENT);
    pose[5] = NAN;
    ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_ERROR_NOT_FINITE);
    bake_fixture_pose(f, 4, pose);
    pose[0] = 3.0f;
    ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step(inst, 0.0f) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step(inst, NAN) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step(inst, 1e6f) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_read_surface(inst, x1, NULL, ns + 1) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_read_surface(inst, x1, NULL, ns) == SINEW_OK);
    ENSURE(memcmp(x0, x1, sizeof(float) * 3 * ns) == 0);
    /* the instance goes on: the same pose again gives the same result */
    bake_fixture_pose(f, 4, pose);
    ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(inst, x1, NULL, ns) == SINEW_OK);
    for (uint32_t i = 0; i < 3 * ns; ++i)
        ENSURE(isfinite(x1[i]) && fabsf(x1[i] - x0[i]) < 1e-3f);
    free(pose);
    free(x0);
    free(x1);
    sinew_instance_destroy(inst);
}

TEST(teleport_gives_a_status_and_a_finite_state) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float *pose = malloc(sizeof(float) * 12 * nb), *x = malloc(sizeof(float) * 3 * ns);
    for (int s = 0; s < 5; ++s) {
        bake_fixture_pose(f, s, pose);
        sinew_instance_set_pose(inst, pose, nb);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    }
    for (uint32_t b = 0; b < nb; ++b)
        pose[12 * b + 9] += 1000.0f; /* jump far away */
    ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK);
    ENSURE(st.status & SINEW_STEP_TELEPORT);
    ENSURE(sinew_instance_read_surface(inst, x, NULL, ns) == SINEW_OK);
    for (uint32_t i = 0; i < 3 * ns; ++i)
        ENSURE(isfinite(x[i]));
    free(pose);
    free(x);
    sinew_instance_destroy(inst);
}

TEST(dynamic_flesh_overshoots_and_settles_when_the_clip_stops) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    sinew_instance *dyn;
    ENSURE(sinew_instance_create(f->blob, &d, &dyn) == SINEW_OK);
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float *pose = malloc(sizeof(float) * 12 * nb), *a = malloc(sizeof(float) * 3 * ns),
          *b = malloc(sizeof(float) * 3 * ns);
    int peak = f->ch.clip.nframes / 2;
    double after = 0, settled = 0;
    for (int s = 0; s < peak + 150; ++s) { /* bend to the peak, then hold the pose */
        bake_fixture_pose(f, s < peak ? s : peak, pose);
        sinew_instance_set_pose(dyn, pose, nb);
        ENSURE(sinew_instance_step(dyn, 1.0f / 30) == SINEW_OK);
        memcpy(a, b, sizeof(float) * 3 * ns);
        sinew_instance_read_surface(dyn, b, NULL, ns);
        double move = 0; /* surface motion during this frame while the bones stand still */
        for (uint32_t i = 0; i < 3 * ns; ++i)
            move = fmax(move, fabs((double)a[i] - b[i]));
        if (s >= peak + 1 && s <= peak + 3) after = fmax(after, move);
        if (s == peak + 149) settled = move;
    }
    fprintf(stderr, "    surface motion per frame after the clip stops: %.3g, 5 s later %.3g\n",
            after, settled);
    ENSUREF(after > 1e-4, "the flesh stops dead with the bones (%.3g): no inertia", after);
    ENSUREF(settled < 0.05 * after, "the flesh did not settle (%.3g -> %.3g)", after, settled);
    free(pose);
    free(a);
    free(b);
    sinew_instance_destroy(dyn);
}

static void cleanup(void) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

TEST(release_fixture) {
    cleanup();
}

SW_TEST_MAIN(CASE(quasistatic_step_allocates_and_locks_nothing),
             CASE(dynamic_step_allocates_and_locks_nothing),
             CASE(identical_runs_give_identical_output), CASE(bad_input_is_rejected_and_state_kept),
             CASE(teleport_gives_a_status_and_a_finite_state),
             CASE(dynamic_flesh_overshoots_and_settles_when_the_clip_stops), CASE(release_fixture))
