/* Host task callbacks (sinew_task_callbacks, issue 13): a host's job system runs one
 * instance's cubature passes on its workers, and the step's output is bitwise the serial
 * step's for any worker count and any split of the domains: the pool's contiguous
 * chunks on 1, 2 and 4 workers, run at once or deferred to finish, and a host that runs
 * one domain at a time in reverse order on rotating workers. Quasistatic and dynamic,
 * over the clip and a snap. Runs under TSan (the "threads" label). */
#include <stdint.h>
#include <string.h>

#include "bake_fixture.h"
#include "sw_test.h"
#include "thread_pool.h"

enum { STEPS = 24 };

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
static int play(const bake_fixture *f, sinew_step_mode mode, host *h, float *out) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    if (h) {
        d.tasks.enqueue = enqueue;
        d.tasks.finish = finish;
        d.tasks.worker_count = h->workers;
        d.tasks.user = h;
    }
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return 0;
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
    for (int mode = 0; mode < 2; ++mode) {
        sinew_step_mode m = mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        ENSURE(play(&f, m, NULL, serial));
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
            ENSURE(play(&f, m, &h, tasked));
            sw_pool_destroy(h.pool);
            fprintf(stderr, "    %s, %d workers%s%s: %d tasks, %d finished\n",
                    mode ? "dynamic" : "quasistatic", hosts[k].workers,
                    h.deferred ? ", deferred" : "", h.reverse ? ", one domain a range" : "",
                    h.enqueued, h.finished);
            ENSURE(h.enqueued > STEPS); /* at least a cubature pass a step */
            ENSURE(h.finished == (h.deferred ? h.enqueued : 0));
            ENSUREF(memcmp(serial, tasked, n * sizeof(float)) == 0,
                    "%s on %d workers differs from the serial step",
                    mode ? "dynamic" : "quasistatic", hosts[k].workers);
        }
    }
    free(serial);
    free(tasked);
    bake_fixture_free(&f);
}

SW_TEST_MAIN(CASE(task_callbacks_give_the_serial_result_for_any_workers))
