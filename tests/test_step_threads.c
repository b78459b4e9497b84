/* N instances of one shared blob stepped on N threads give bitwise the results of
 * stepping them one by one (DESIGN.md §3: the blob is immutable and shared, an instance
 * is owned by one thread, no coordination). Runs under TSan (the "threads" label). */
#include <pthread.h>
#include <stdint.h>

#include "bake_fixture.h"
#include "sw_test.h"

enum { NINST = 4, STEPS = 30 };

typedef struct {
    const bake_fixture *f;
    int index;  /* instances differ: each starts at another clip offset and mode */
    float *out; /* final surface */
    int ok;
} job;

static void *run(void *p) {
    job *j = p;
    const bake_fixture *f = j->f;
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = j->index % 2 ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
    sinew_instance *inst;
    j->ok = 0;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return NULL;
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float pose[12 * 16];
    int ok = nb <= 16;
    for (int s = 0; s < STEPS && ok; ++s) {
        bake_fixture_pose(f, s + 3 * j->index, pose);
        ok = sinew_instance_set_pose(inst, pose, nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK;
    }
    ok = ok && sinew_instance_read_surface(inst, j->out, NULL, ns) == SINEW_OK;
    sinew_instance_destroy(inst);
    j->ok = ok;
    return NULL;
}

TEST(parallel_instances_match_sequential) {
    bake_fixture f;
    ENSURE(bake_fixture_make(&f, "finger", 1500, 10, 0));
    uint32_t ns = sinew_blob_surface_vertex_count(f.blob);
    job seq[NINST], par[NINST];
    for (int i = 0; i < NINST; ++i) {
        seq[i] = (job){&f, i, malloc(sizeof(float) * 3 * ns), 0};
        par[i] = (job){&f, i, malloc(sizeof(float) * 3 * ns), 0};
        run(&seq[i]);
    }
    pthread_t th[NINST];
    for (int i = 0; i < NINST; ++i)
        ENSURE(pthread_create(&th[i], NULL, run, &par[i]) == 0);
    for (int i = 0; i < NINST; ++i)
        pthread_join(th[i], NULL);
    for (int i = 0; i < NINST; ++i) {
        ENSURE(seq[i].ok && par[i].ok);
        ENSUREF(memcmp(seq[i].out, par[i].out, sizeof(float) * 3 * ns) == 0, "instance %d differs",
                i);
    }
    ENSURE(memcmp(seq[0].out, seq[2].out, sizeof(float) * 3 * ns) !=
           0); /* they are different runs */
    for (int i = 0; i < NINST; ++i) {
        free(seq[i].out);
        free(par[i].out);
    }
    bake_fixture_free(&f);
}

SW_TEST_MAIN(CASE(parallel_instances_match_sequential))
