/* Host task callbacks (sinew_task_callbacks): a host's job system runs one
 * instance's cubature passes on its workers, and the step's output is bitwise the serial
 * step's for any worker count and any split of the domains: the pool's contiguous
 * chunks on 1, 2 and 4 workers, run at once or deferred to finish, and a host that runs
 * one domain at a time in reverse order on rotating workers. Quasistatic and dynamic,
 * over the clip and a snap, and both again against a mesh and a hull with condensation
 * patches. Runs under TSan (the "threads" label). */
#include <stdint.h>
#include <string.h>

#include "bake_fixture.h"
#include "props_fixture.h"
#include "sw_test.h"
#include "thread_pool.h"

enum { STEPS = 24 };

static uint32_t patch_seen; /* the largest patch of the plays since it was zeroed */

/* A test host: a pthread pool, one task at a time. */
typedef struct {
    sw_pool *pool;
    int deferred; /* enqueue returns a handle and finish runs the task */
    int reverse;  /* one domain a range, last first, on workers 0, 1, 2, ... in turn */
    uint32_t workers;
    sinew_task_fn *task;
    void *ctx;
    uint32_t n;
    int enqueued, finished, ranges;
} host;

static void run_range(void *ctx, int64_t begin, int64_t end, int worker) {
    host *h = ctx;
    if (begin < end) h->task((uint32_t)begin, (uint32_t)end, (uint32_t)worker, h->ctx);
}

static void run(host *h) {
    if (!h->reverse) {
        sw_pool_parallel_for(h->pool, h->n, run_range, h);
        return;
    }
    for (uint32_t i = 0; i < h->n; ++i) {
        uint32_t item = h->n - 1 - i;
        h->task(item, item + 1, i % h->workers, h->ctx);
        h->ranges++;
    }
}

static void *enqueue(sinew_task_fn *task, uint32_t n, uint32_t min_range, void *ctx, void *user) {
    host *h = user;
    (void)min_range;
    h->task = task, h->ctx = ctx, h->n = n;
    h->enqueued++;
    if (h->deferred) return h;
    run(h);
    return NULL;
}

static void finish(void *handle, void *user) {
    host *h = user;
    if (handle == h) run(h);
    h->finished++;
}

/* The output after each step of the clip (then a 60 degree snap of the last bone held
 * for a few steps) into out (STEPS + 4 surfaces); 1 on success. */
static int play(const bake_fixture *f, sinew_step_mode mode, const sinew_world *w, host *h,
                float *out) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    d.max_patch_vertices = w ? 400 : 0; /* with a world: condensation patches */
    if (h) {
        d.tasks.enqueue = enqueue;
        d.tasks.finish = finish;
        d.tasks.worker_count = h->workers;
        d.tasks.user = h;
    }
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return 0;
    if (w && sinew_instance_set_world(inst, w) != SINEW_OK) return 0;
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float pose[12 * 16];
    int ok = nb <= 16;
    for (int s = 0; s < STEPS + 4 && ok; ++s) {
        bake_fixture_pose(f, s < STEPS ? s : STEPS - 1, pose);
        if (s >= STEPS) { /* the last bone turned about x by 60 degrees */
            float *T = pose + 12 * (nb - 1), c = 0.5f, sn = 0.8660254f;
            for (int j = 0; j < 3; ++j) {
                float y = T[3 + j], z = T[6 + j];
                T[3 + j] = c * y - sn * z;
                T[6 + j] = sn * y + c * z;
            }
        }
        ok = sinew_instance_set_pose(inst, pose, nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK &&
             sinew_instance_read_surface(inst, out + (size_t)s * 3 * ns, NULL, ns) == SINEW_OK;
        sinew_step_stats st = {.struct_size = sizeof st};
        ok = ok && sinew_instance_get_stats(inst, &st) == SINEW_OK;
        if (st.patch_vertices > patch_seen) patch_seen = st.patch_vertices;
    }
    sinew_instance_destroy(inst);
    return ok;
}

TEST(task_callbacks_give_the_serial_result_for_any_workers) {
    bake_fixture f;
    ENSURE(bake_fixture_make(&f, "finger", 2000, 12, 1));
    const sw_blob_view *v = sw_blob_get_view(f.blob);
    ENSURE(v->ndomains > 1); /* the cubature runs one task item a domain */
    size_t n = (size_t)(STEPS + 4) * 3 * sinew_blob_surface_vertex_count(f.blob);
    float *serial = malloc(n * sizeof(float)), *tasked = malloc(n * sizeof(float));
    ENSURE(serial && tasked);
    /* the props of props_fixture.h pressing the finger: patches in modes 2 and 3 */
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    sinew_collider_id tent, wedge;
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK && props_add(w, 2.2f, 1.2f, &tent, &wedge));
    static const char *const names[] = {"quasistatic", "dynamic", "quasistatic with patches",
                                        "dynamic with patches"};
    for (int mode = 0; mode < 4; ++mode) {
        sinew_step_mode m = mode % 2 ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        const sinew_world *pw = mode >= 2 ? w : NULL;
        patch_seen = 0;
        ENSURE(play(&f, m, pw, NULL, serial));
        ENSUREF((patch_seen > 0) == (pw != NULL), "%s: largest patch %u", names[mode], patch_seen);
        static const struct {
            int workers, deferred, reverse;
        } hosts[] = {{1, 0, 0}, {2, 0, 0}, {4, 0, 0}, {2, 1, 0}, {3, 0, 1}, {4, 1, 1}};
        for (size_t k = 0; k < sizeof hosts / sizeof hosts[0]; ++k) {
            host h = {0};
            h.workers = (uint32_t)hosts[k].workers;
            h.deferred = hosts[k].deferred;
            h.reverse = hosts[k].reverse;
            h.pool = sw_pool_create(hosts[k].workers);
            ENSURE(h.pool && sw_pool_size(h.pool) == hosts[k].workers);
            ENSURE(play(&f, m, pw, &h, tasked));
            sw_pool_destroy(h.pool);
            fprintf(stderr, "    %s, %d workers%s%s: %d tasks, %d finished\n", names[mode],
                    hosts[k].workers, h.deferred ? ", deferred" : "",
                    h.reverse ? ", one domain a range" : "", h.enqueued, h.finished);
            ENSURE(h.enqueued > STEPS); /* at least a cubature pass a step */
            ENSURE(h.finished == (h.deferred ? h.enqueued : 0));
            ENSUREF(memcmp(serial, tasked, n * sizeof(float)) == 0,
                    "%s on %d workers differs from the serial step", names[mode], hosts[k].workers);
        }
    }
    free(serial);
    free(tasked);
    sinew_world_destroy(w);
    bake_fixture_free(&f);
}

SW_TEST_MAIN(CASE(task_callbacks_give_the_serial_result_for_any_workers))
