/* An instance's memory plan, budgets, def checks and step figures (DESIGN.md §3-§4.8):
 * creation reserves exactly the bytes sinew_instance_memory_size reports, in one block
 * through the host allocator, and nothing else; a contact pair budget that runs out is
 * reported by the step (flag, budget bit, dropped count) and never grows; a bad def is
 * rejected with a logged reason; every phase's time and count is reported. */
#include <math.h>
#include <stdint.h>

#include "bake_fixture.h"
#include "sw_test.h"

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

static bake_fixture fx;
static int fx_ready;

/* One small finger shared by the cases, its clip folded into self-contact. */
static int fixture(void) {
    if (!fx_ready) fx_ready = bake_fixture_make(&fx, "finger", 2000, 12, 1);
    return fx_ready;
}

/* Steps an instance through the fixture's clip; the largest contact pair count seen and
 * whether any step flagged a budget. 0 when a step failed or its surface is not finite. */
static int run_clip(sinew_instance *inst, uint32_t *max_pairs, uint32_t *budget_steps,
                    uint32_t *max_dropped) {
    uint32_t nb = (uint32_t)fx.ch.skel.nbones, ns = sinew_blob_surface_vertex_count(fx.blob);
    float pose[12 * 16], *x = malloc(sizeof(float) * 3 * ns);
    int ok = x && nb <= 16;
    *max_pairs = *budget_steps = *max_dropped = 0;
    for (int f = 0; f < fx.ch.clip.nframes && ok; ++f) {
        bake_fixture_pose(&fx, f, pose);
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
    ENSURE(fixture());
    alloc_count ac = {0};
    sinew_instance_def d = sinew_instance_def_default();
    d.allocator = (sinew_allocator){count_alloc, count_free, &ac};
    size_t bytes = 0;
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &bytes) == SINEW_OK);
    ENSURE(ac.allocs == 0); /* the query never allocates */
    ENSURE(bytes > 0 && bytes % 64 == 0);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_OK);
    ENSUREF(ac.allocs == 1 && ac.last_size == bytes && ac.last_align == 64,
            "%d allocations, the last %zu bytes aligned %zu; reported %zu", ac.allocs, ac.last_size,
            ac.last_align, bytes);
    uint32_t pairs, budget, dropped;
    ENSURE(run_clip(inst, &pairs, &budget, &dropped));
    ENSURE(ac.allocs == 1 && ac.frees == 0);
    sinew_instance_destroy(inst);
    ENSURE(ac.frees == 1);
    /* the same layout for a quasistatic and a dynamic instance, and the default def */
    size_t dyn = 0, dflt = 0;
    d.mode = SINEW_STEP_DYNAMIC;
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &dyn) == SINEW_OK && dyn == bytes);
    ENSURE(sinew_instance_memory_size(fx.blob, NULL, &dflt) == SINEW_OK && dflt == bytes);
    ENSURE(sinew_instance_memory_size(NULL, &d, &dyn) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_memory_size(fx.blob, &d, NULL) == SINEW_ERROR_INVALID_ARGUMENT);
}

TEST(a_contact_budget_that_runs_out_is_reported_never_grown) {
    ENSURE(fixture());
    sinew_instance *inst;
    uint32_t full_pairs, budget, dropped;
    ENSURE(sinew_instance_create(fx.blob, NULL, &inst) == SINEW_OK);
    ENSURE(run_clip(inst, &full_pairs, &budget, &dropped));
    sinew_instance_destroy(inst);
    ENSUREF(full_pairs >= 2, "the clip needs %u pairs at most: no contact to budget", full_pairs);
    ENSURE(budget == 0 && dropped == 0); /* the default budget never runs out */

    sinew_instance_def d = sinew_instance_def_default();
    size_t full_bytes = 0, small_bytes = 0, huge_bytes = 0;
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &full_bytes) == SINEW_OK);
    d.max_contact_pairs = 0xffffffffu; /* more than the blob can need: what it needs */
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &huge_bytes) == SINEW_OK);
    ENSURE(huge_bytes == full_bytes);
    d.max_contact_pairs = 1;
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &small_bytes) == SINEW_OK);
    ENSURE(small_bytes <= full_bytes);
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_OK);
    uint32_t pairs;
    ENSURE(run_clip(inst, &pairs, &budget, &dropped));
    sinew_instance_destroy(inst);
    ENSUREF(pairs == 1 && budget > 0 && dropped == full_pairs - 1,
            "in use %u, flagged steps %u, dropped %u of %u", pairs, budget, dropped, full_pairs);
}

TEST(bad_defs_are_rejected_with_a_logged_reason) {
    ENSURE(fixture());
    log_count lc = {0};
    sinew_instance_def d = sinew_instance_def_default();
    d.logger = (sinew_logger){count_log, &lc, SINEW_LOG_DEBUG};
    sinew_instance *inst = (sinew_instance *)&lc;
    d.mode = (sinew_step_mode)7;
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(inst == NULL);
    ENSURE(lc.calls == 1 && lc.last_id == SINEW_MSG_INSTANCE_INVALID_ARGUMENT &&
           lc.last_level == SINEW_LOG_ERROR);
    d.mode = SINEW_STEP_QUASISTATIC;
    d.max_newton_iters = 101;
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 2);
    d.max_newton_iters = 0;
    d.allocator.alloc = count_alloc; /* half an allocator */
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(lc.calls == 3);
    d.allocator.alloc = NULL;
    d.tasks.worker_count = 4; /* reserved: the step is serial in this version */
    d.tasks.finish = count_free;
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_ERROR_UNSUPPORTED);
    ENSURE(lc.calls == 4 && lc.last_id == SINEW_MSG_INSTANCE_UNSUPPORTED);
    size_t bytes;
    ENSURE(sinew_instance_memory_size(fx.blob, &d, &bytes) == SINEW_ERROR_UNSUPPORTED);
    d.tasks = sinew_instance_def_default().tasks;
    d.struct_size = 4; /* smaller than the fields every caller has */
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    d.struct_size = sizeof d;
    ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_OK);
    ENSURE(lc.last_id == SINEW_MSG_INSTANCE_CREATED && lc.last_level == SINEW_LOG_INFO);
    sinew_instance_destroy(inst);
    /* an old host's def: only the fields up to the logger, garbage after them ignored */
    unsigned char old[sizeof d];
    memset(old, 0xab, sizeof old);
    d = sinew_instance_def_default();
    d.struct_size = (uint32_t)(offsetof(sinew_instance_def, logger) + sizeof(sinew_logger));
    memcpy(old, &d, d.struct_size);
    ENSURE(sinew_instance_create(fx.blob, (const sinew_instance_def *)(void *)old, &inst) ==
           SINEW_OK);
    sinew_instance_destroy(inst);
}

TEST(every_phase_reports_its_time_and_counts) {
    ENSURE(fixture());
    for (int mode = 0; mode < 2; ++mode) {
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        sinew_instance *inst;
        ENSURE(sinew_instance_create(fx.blob, &d, &inst) == SINEW_OK);
        uint32_t nb = (uint32_t)fx.ch.skel.nbones;
        float pose[12 * 16];
        ENSURE(nb <= 16);
        bake_fixture_pose(&fx, 5, pose);
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
    if (fx_ready) bake_fixture_free(&fx);
    fx_ready = 0;
}

SW_TEST_MAIN(CASE(create_reserves_the_reported_size_in_one_block),
             CASE(a_contact_budget_that_runs_out_is_reported_never_grown),
             CASE(bad_defs_are_rejected_with_a_logged_reason),
             CASE(every_phase_reports_its_time_and_counts), CASE(release_fixture))
