/* Instances on several threads stepping against one shared world (read-only while they
 * step) give bitwise the output of the same instances stepped one after another; named
 * for the TSan stage (tests/abi.cmake labels "thread" tests). The world holds every kind
 * of query: a box, a sphere, a triangle mesh (Embree) and a convex hull (libccd); every
 * other instance simulates condensation patches. */
#include <pthread.h>
#include <stdint.h>

#include "hash.h"
#include "sw_test.h"
#include "props_fixture.h"
#include "world_fixture.h"

enum { NTHREADS = 4, THREAD_STEPS = 40 };

typedef struct {
    const moving_scene *m;
    int offset;
    uint64_t hash;
    double mesh_push, hull_push; /* the forces on the mesh and the hull, summed */
} run_arg;

static sinew_collider_id mesh_id, hull_id;

static uint64_t hash_floats(uint64_t h, const float *x, size_t n) {
    return sw_fnv1a(h, x, n * sizeof(float));
}

/* Instance `offset` steps its clip from frame `offset` against the shared, fixed world. */
static void *run_instance(void *vp) {
    run_arg *a = vp;
    const bake_fixture *f = a->m->f;
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    sinew_instance *inst;
    a->hash = 0;
    sinew_instance_def d = sinew_instance_def_default();
    d.max_patch_vertices = a->offset % 2 ? 200 : 0;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return NULL;
    sinew_instance_set_world(inst, a->m->w);
    float *pose = malloc(sizeof(float) * 12 * nb), *x = malloc(sizeof(float) * 3 * ns);
    uint64_t h = SW_FNV_START;
    for (int s = 0; s < THREAD_STEPS; ++s) {
        bake_fixture_pose(f, s + a->offset, pose);
        sinew_instance_set_pose(inst, pose, nb);
        sinew_instance_step(inst, 1.0f / 30);
        sinew_instance_read_surface(inst, x, NULL, ns);
        h = hash_floats(h, x, 3 * ns);
        float F[3], M[3];
        if (sinew_instance_collider_force(inst, mesh_id, F, M) == SINEW_OK)
            a->mesh_push += fabsf(F[0]) + fabsf(F[1]) + fabsf(F[2]);
        if (sinew_instance_collider_force(inst, hull_id, F, M) == SINEW_OK)
            a->hull_push += fabsf(F[0]) + fabsf(F[1]) + fabsf(F[2]);
    }
    a->hash = h;
    free(pose);
    free(x);
    sinew_instance_destroy(inst);
    return NULL;
}

TEST(instances_on_threads_sharing_a_world_match_a_sequential_run) {
    moving_scene m;
    ENSURE(moving_scene_make(&m));
    ENSURE(props_add(m.w, 1.4f, 2.9f, &mesh_id, &hull_id)); /* a tent over, a wedge under */
    run_arg seq[NTHREADS], par[NTHREADS];
    pthread_t th[NTHREADS];
    for (int i = 0; i < NTHREADS; ++i) {
        seq[i] = (run_arg){&m, 3 * i, 0, 0, 0};
        run_instance(&seq[i]);
        par[i] = (run_arg){&m, 3 * i, 0, 0, 0};
    }
    for (int i = 0; i < NTHREADS; ++i)
        ENSURE(pthread_create(&th[i], NULL, run_instance, &par[i]) == 0);
    for (int i = 0; i < NTHREADS; ++i)
        pthread_join(th[i], NULL);
    for (int i = 0; i < NTHREADS; ++i) {
        ENSURE(seq[i].hash != 0);
        ENSURE(par[i].hash == seq[i].hash);
    }
    ENSURE(seq[0].hash != seq[1].hash);
    double mesh_push = 0, hull_push = 0;
    for (int i = 0; i < NTHREADS; ++i)
        mesh_push += seq[i].mesh_push, hull_push += seq[i].hull_push;
    ENSUREF(mesh_push > 0 && hull_push > 0, "the mesh felt %g, the hull %g", mesh_push, hull_push);
    sinew_world_destroy(m.w);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
    fx_ok = -1;
}

SW_TEST_MAIN(CASE(instances_on_threads_sharing_a_world_match_a_sequential_run),
             CASE(release_fixture))
