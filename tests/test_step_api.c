/* The runtime's API promises (DESIGN.md §3) that need no allocation counter: identical
 * output for identical runs, clear errors for bad input with the state kept, and an
 * instance that recovers from them; its memory is one planned block, its budgets are
 * reported when they run out, and every phase of a step reports its figures. The
 * counted real-time contract, every path of the step with no allocation and no lock, is
 * test_step_contract.c. */
#include <math.h>
#include <stdint.h>

#include "bake_fixture.h"
#include "hash.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 1);
    return fx_ok ? &fx : NULL;
}

/* FNV-1a over float outputs: a bitwise fingerprint of a run. */
static uint64_t hash_floats(uint64_t h, const float *x, size_t n) {
    return sw_fnv1a(h, x, n * sizeof(float));
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
    uint64_t h = SW_FNV_START;
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
    ENSURE(sinew_instance_step(inst, -0.01f) == SINEW_ERROR_INVALID_ARGUMENT);
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

/* ---- the memory plan, budgets, def checks and step figures ------------------------
 * Creation reserves exactly the bytes sinew_instance_memory_size reports, in one block
 * through the host allocator, and nothing else; a contact pair budget that runs out is
 * reported by the step (flag, budget bit, dropped count) and never grows; a bad def is
 * rejected with a logged reason; every phase's time and count is reported. */

typedef struct {
    int allocs, frees;
    size_t last_size, last_align;
} alloc_count;

static void *count_alloc(size_t size, size_t align, void *user) {
    alloc_count *a = user;
    a->allocs++;
    a->last_size = size;
    a->last_align = align;
    void *p = NULL;
    return posix_memalign(&p, align, size) == 0 ? p : NULL;
}

static void count_free(void *p, void *user) {
    ((alloc_count *)user)->frees++;
    free(p);
}

/* A job system that runs every task at once on the caller (worker 0). */
static void *inline_enqueue(sinew_task_fn *task, uint32_t n, uint32_t min_range, void *ctx,
                            void *user) {
    (void)min_range, (void)user;
    task(0, n, 0, ctx);
    return NULL;
}

typedef struct {
    int calls;
    uint32_t last_id;
    sinew_log_level last_level;
} log_count;

static void count_log(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    log_count *l = user;
    (void)msg;
    l->calls++;
    l->last_id = id;
    l->last_level = level;
}

/* Steps an instance through the fixture's clip; the largest contact pair count seen and
 * whether any step flagged a budget. 0 when a step failed or its surface is not finite. */
static int run_clip(const bake_fixture *f, sinew_instance *inst, uint32_t *max_pairs,
                    uint32_t *budget_steps, uint32_t *max_dropped) {
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float pose[12 * 16], *x = malloc(sizeof(float) * 3 * ns);
    int ok = x && nb <= 16;
    *max_pairs = *budget_steps = *max_dropped = 0;
    for (int k = 0; k < f->ch.clip.nframes && ok; ++k) {
        bake_fixture_pose(f, k, pose);
        ok = sinew_instance_set_pose(inst, pose, nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK &&
             sinew_instance_read_surface(inst, x, NULL, ns) == SINEW_OK;
        for (uint32_t i = 0; ok && i < 3 * ns; ++i)
            ok = isfinite(x[i]);
        sinew_step_stats st = {.struct_size = sizeof st};
        ok = ok && sinew_instance_get_stats(inst, &st) == SINEW_OK;
        if (st.contact_pairs > *max_pairs) *max_pairs = st.contact_pairs;
        if (st.status & SINEW_STEP_BUDGET) {
            ok = ok && (st.budget_exceeded & SINEW_BUDGET_CONTACT_PAIRS);
            (*budget_steps)++;
        }
        if (st.contact_pairs_dropped > *max_dropped) *max_dropped = st.contact_pairs_dropped;
    }
    free(x);
    return ok;
}

TEST(create_reserves_the_reported_size_in_one_block) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    alloc_count ac = {0};
    sinew_instance_def d = sinew_instance_def_default();
    d.allocator = (sinew_allocator){count_alloc, count_free, &ac};
    size_t bytes = 0;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &bytes) == SINEW_OK);
    ENSURE(ac.allocs == 0); /* the query never allocates */
    ENSURE(bytes > 0 && bytes % 64 == 0);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    ENSUREF(ac.allocs == 1 && ac.last_size == bytes && ac.last_align == 64,
            "%d allocations, the last %zu bytes aligned %zu; reported %zu", ac.allocs, ac.last_size,
            ac.last_align, bytes);
    uint32_t pairs, budget, dropped;
    ENSURE(run_clip(f, inst, &pairs, &budget, &dropped));
    ENSURE(ac.allocs == 1 && ac.frees == 0);
    sinew_instance_destroy(inst);
    ENSURE(ac.frees == 1);
    /* a dynamic instance holds the frozen damping Hessian, its blocks' marks and the point
       it was taken at too (rank_total^2 + rank_total doubles and ndomains^2 bytes, the
       plan's alignment aside); the default def is quasistatic */
    size_t dyn = 0, dflt = 0, R = (size_t)sw_blob_get_view(f->blob)->rank_total,
           nd = (size_t)sw_blob_get_view(f->blob)->ndomains;
    size_t extra = (R * R + R) * sizeof(double) + nd * nd;
    d.mode = SINEW_STEP_DYNAMIC;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &dyn) == SINEW_OK);
    ENSUREF(dyn >= bytes + extra && dyn <= bytes + extra + 192,
            "dynamic %zu bytes, quasistatic %zu, rank %zu", dyn, bytes, R);
    ENSURE(sinew_instance_memory_size(f->blob, NULL, &dflt) == SINEW_OK && dflt == bytes);
    ENSURE(sinew_instance_memory_size(NULL, &d, &dyn) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_memory_size(f->blob, &d, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
}

TEST(a_contact_budget_that_runs_out_is_reported_never_grown) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *inst;
    uint32_t full_pairs, budget, dropped;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(run_clip(f, inst, &full_pairs, &budget, &dropped));
    sinew_instance_destroy(inst);
    ENSUREF(full_pairs >= 2, "the clip needs %u pairs at most: no contact to budget", full_pairs);
    ENSURE(budget == 0 && dropped == 0); /* the default budget never runs out */

    sinew_instance_def d = sinew_instance_def_default();
    size_t full_bytes = 0, small_bytes = 0, huge_bytes = 0;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &full_bytes) == SINEW_OK);
    d.max_contact_pairs = 0xffffffffu; /* more than the blob can need: what it needs */
    ENSURE(sinew_instance_memory_size(f->blob, &d, &huge_bytes) == SINEW_OK);
    ENSURE(huge_bytes == full_bytes);
    d.max_contact_pairs = 1;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &small_bytes) == SINEW_OK);
    ENSURE(small_bytes <= full_bytes);
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    uint32_t pairs;
    ENSURE(run_clip(f, inst, &pairs, &budget, &dropped));
    sinew_instance_destroy(inst);
    ENSUREF(pairs == 1 && budget > 0 && dropped == full_pairs - 1,
            "in use %u, flagged steps %u, dropped %u of %u", pairs, budget, dropped, full_pairs);
}

TEST(bad_defs_are_rejected_with_a_logged_reason) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    log_count lc = {0};
    sinew_instance_def d = sinew_instance_def_default();
    d.logger = (sinew_logger){count_log, &lc, SINEW_LOG_DEBUG};
    sinew_instance *inst = (sinew_instance *)&lc;
    d.mode = (sinew_step_mode)7;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(inst == NULL);
    ENSURE(lc.calls == 1 && lc.last_id == SINEW_MSG_INSTANCE_INVALID_ARGUMENT &&
           lc.last_level == SINEW_LOG_ERROR);
    d.mode = SINEW_STEP_QUASISTATIC;
    d.max_newton_iters = 101;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 2);
    d.max_newton_iters = 0;
    d.allocator.alloc = count_alloc; /* half an allocator */
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 3);
    d.allocator.alloc = NULL;
    d.tasks.worker_count = 4; /* half a job system */
    d.tasks.finish = count_free;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 4 && lc.last_id == SINEW_MSG_INSTANCE_INVALID_ARGUMENT);
    size_t bytes;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &bytes) == SINEW_ERROR_INVALID_ARGUMENT);
    d.tasks.enqueue = inline_enqueue; /* both, but no workers, or too many */
    d.tasks.worker_count = 0;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    d.tasks.worker_count = 257;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 7 && inst == NULL); /* memory_size logs its reason too */
    size_t serial_bytes, four_bytes;       /* the workers' scratch is reserved up front */
    d.tasks.worker_count = 4;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &four_bytes) == SINEW_OK);
    d.tasks = sinew_instance_def_default().tasks;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &serial_bytes) == SINEW_OK);
    ENSURE(four_bytes > serial_bytes);
    d.struct_size = 4; /* smaller than the fields every caller has */
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    d.struct_size = sizeof d;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    ENSURE(lc.last_id == SINEW_MSG_INSTANCE_CREATED && lc.last_level == SINEW_LOG_INFO);
    sinew_instance_destroy(inst);
    /* an old host's def: only the fields up to the logger, garbage after them ignored */
    unsigned char old[sizeof d];
    memset(old, 0xab, sizeof old);
    d = sinew_instance_def_default();
    d.struct_size = (uint32_t)(offsetof(sinew_instance_def, logger) + sizeof(sinew_logger));
    memcpy(old, &d, d.struct_size);
    ENSURE(sinew_instance_create(f->blob, (const sinew_instance_def *)(void *)old, &inst) ==
           SINEW_OK);
    sinew_instance_destroy(inst);
    /* a Newton Hessian that is none of the three */
    d = sinew_instance_def_default();
    d.logger = (sinew_logger){count_log, &lc, SINEW_LOG_DEBUG};
    d.newton_hessian = (sinew_newton_hessian)3;
    int calls = lc.calls;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT && !inst);
    ENSURE(lc.calls == calls + 1 && lc.last_id == SINEW_MSG_INSTANCE_INVALID_ARGUMENT &&
           lc.last_level == SINEW_LOG_ERROR);
}

TEST(every_phase_reports_its_time_and_counts) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    for (int mode = 0; mode < 2; ++mode) {
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        sinew_instance *inst;
        ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
        uint32_t nb = (uint32_t)f->ch.skel.nbones;
        float pose[12 * 16];
        ENSURE(nb <= 16);
        bake_fixture_pose(f, 5, pose);
        ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK && st.struct_size == sizeof st);
        const double ms[5] = {st.ms_skin, st.ms_contact, st.ms_dynamics, st.ms_solve, st.ms_output};
        for (int i = 0; i < 5; ++i)
            ENSUREF(isfinite(ms[i]) && ms[i] >= 0 && ms[i] < 1e4, "phase %d: %g ms", i, ms[i]);
        ENSURE(st.active_vertices > 0 && st.cubature_tets > 0);
        /* the start point's evaluation (an update below 0.3% of the correction is taken
         * without one at its end) and, dynamic, the frozen damping Hessian's */
        ENSUREF(st.potential_evals >= 1 + (uint32_t)mode &&
                    st.potential_evals >= st.newton_iterations + (uint32_t)mode,
                "%u evaluations, %u iterations", st.potential_evals, st.newton_iterations);
        /* a host built against the first stats struct gets only those fields */
        sinew_step_stats old;
        memset(&old, 0x5a, sizeof old);
        old.struct_size = (uint32_t)offsetof(sinew_step_stats, ms_skin);
        ENSURE(sinew_instance_get_stats(inst, &old) == SINEW_OK);
        ENSURE(old.struct_size == offsetof(sinew_step_stats, ms_skin));
        ENSURE(old.newton_iterations == st.newton_iterations && old.energy == st.energy);
        unsigned char tail[sizeof old - offsetof(sinew_step_stats, ms_skin)];
        memset(tail, 0x5a, sizeof tail);
        ENSURE(memcmp((unsigned char *)&old + offsetof(sinew_step_stats, ms_skin), tail,
                      sizeof tail) == 0);
        sinew_instance_destroy(inst);
    }
}

TEST(release_fixture) {
    cleanup();
}

SW_TEST_MAIN(CASE(identical_runs_give_identical_output), CASE(bad_input_is_rejected_and_state_kept),
             CASE(teleport_gives_a_status_and_a_finite_state),
             CASE(dynamic_flesh_overshoots_and_settles_when_the_clip_stops),
             CASE(create_reserves_the_reported_size_in_one_block),
             CASE(a_contact_budget_that_runs_out_is_reported_never_grown),
             CASE(bad_defs_are_rejected_with_a_logged_reason),
             CASE(every_phase_reports_its_time_and_counts), CASE(release_fixture))
