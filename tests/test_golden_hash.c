/* Golden hash of the stepped surface (STYLE.md §7, the determinism tests of Box2D and
 * Jolt): four instances of one small baked finger, quasistatic and dynamic, each from
 * another clip offset, are stepped on 1, 2 and 4 threads; every run gives the same
 * surfaces (positions and normals of every step), and their FNV-1a hash is the
 * recorded golden value. A change that claims to keep behaviour must not move it; a
 * change that means to change the physics records the new value here and says why in
 * its commit (the values' history: docs/notes/golden-hashes.md).
 * The thread counts here are instances stepped on several host threads (no task
 * callbacks); instances 1 and 3 are dynamic. */
#include <pthread.h>
#include <stdint.h>

#include <math.h>
#include <string.h>

#include "bake_fixture.h"
#include "blob_load.h"
#include "blob_write.h"
#include "props_fixture.h"
#include "hash.h"
#include "sw_test.h"

enum { NINST = 4, STEPS = 24 };
/* the modes' instances (surface_hash_of_every_mode_is_golden) come after the four */
enum { MODE_EXHAUSTIVE = NINST, MODE_POSE_PAIRS, MODE_PATCH, MODE_TURNED, NMODES };

/* FNV-1a 64 of the four instances' surfaces, instance after instance. */
#define GOLDEN_SURFACE_HASH 0xdafdee5e387ca237ull

typedef struct {
    const bake_fixture *f;
    int begin, end;    /* the instances of the run */
    int first, stride; /* this thread steps instances begin + first, + stride, ... */
    uint64_t hash[NMODES];
    int ok[NMODES];
} job;

/* The modes' run (surface_hash_of_every_mode_is_golden): instances 4.. of the same
 * fixture, each with one more of the step's paths. */
#define GOLDEN_MODES_HASH 0xf8d95edcaa5c5d74ull

static sinew_world *props_world; /* the patch instance's: the props pressing the finger */

/* Turns pose (12 floats a bone) by 130 degrees about (2, -1, 2) / 3 and moves it by
 * (40, -25, 70): the turned character's. */
static void turn_pose(float *pose, uint32_t nb) {
    const double c = cos(130 * 3.14159265358979 / 180), sn = sin(130 * 3.14159265358979 / 180),
                 a[3] = {2 / 3.0, -1 / 3.0, 2 / 3.0}, t[3] = {40, -25, 70};
    double G[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            G[3 * i + j] = (i == j ? c : 0) + (1 - c) * a[i] * a[j] +
                           sn * (i == 0   ? (j == 1   ? -a[2]
                                             : j == 2 ? a[1]
                                                      : 0)
                                 : i == 1 ? (j == 0   ? a[2]
                                             : j == 2 ? -a[0]
                                                      : 0)
                                          : (j == 0   ? -a[1]
                                             : j == 1 ? a[0]
                                                      : 0));
    for (uint32_t b = 0; b < nb; ++b) {
        float *T = pose + 12 * b, o[12];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                o[3 * i + j] =
                    (float)(G[3 * i] * T[j] + G[3 * i + 1] * T[3 + j] + G[3 * i + 2] * T[6 + j]);
            o[9 + i] =
                (float)(G[3 * i] * T[9] + G[3 * i + 1] * T[10] + G[3 * i + 2] * T[11] + t[i]);
        }
        memcpy(T, o, sizeof o);
    }
}

/* Steps instance i through STEPS clip frames from offset 3 i, hashing every surface. */
static int hash_instance(const bake_fixture *f, int i, uint64_t *h) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = i % 2 && i < NINST ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
    if (i == MODE_EXHAUSTIVE) d.self_contact = SINEW_SELF_CONTACT_EXHAUSTIVE;
    if (i == MODE_POSE_PAIRS) d.self_contact = SINEW_SELF_CONTACT_POSE_PAIRS;
    if (i == MODE_PATCH) d.max_patch_vertices = 400;
    sinew_instance *inst;
    *h = SW_FNV_START;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return 0;
    if (i == MODE_PATCH) sinew_instance_set_world(inst, props_world);
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float *pose = malloc(sizeof(float) * 12 * nb), *x = malloc(sizeof(float) * 6 * ns);
    int ok = pose && x;
    for (int s = 0; s < STEPS && ok; ++s) {
        bake_fixture_pose(f, s + 3 * i, pose);
        if (i == MODE_TURNED) turn_pose(pose, nb);
        ok = sinew_instance_set_pose(inst, pose, nb) == SINEW_OK &&
             sinew_instance_step(inst, 1.0f / 30) == SINEW_OK &&
             sinew_instance_read_surface(inst, x, x + 3 * ns, ns) == SINEW_OK;
        if (ok) *h = sw_fnv1a(*h, x, sizeof(float) * 6 * ns);
    }
    free(pose);
    free(x);
    sinew_instance_destroy(inst);
    return ok;
}

static void *run(void *p) {
    job *j = p;
    for (int i = j->begin + j->first; i < j->end; i += j->stride)
        j->ok[i] = hash_instance(j->f, i, &j->hash[i]);
    return NULL;
}

/* The combined hash of instances [begin, end) stepped on `nthreads` threads (0 on
 * failure). */
static uint64_t hash_on_threads(const bake_fixture *f, int begin, int end, int nthreads) {
    job jobs[4];
    pthread_t th[4];
    for (int t = 0; t < nthreads; ++t) {
        jobs[t] = (job){.f = f, .begin = begin, .end = end, .first = t, .stride = nthreads};
        if (pthread_create(&th[t], NULL, run, &jobs[t]) != 0) return 0;
    }
    for (int t = 0; t < nthreads; ++t)
        pthread_join(th[t], NULL);
    uint64_t h = SW_FNV_START;
    for (int i = begin; i < end; ++i) {
        const job *j = &jobs[(i - begin) % nthreads];
        if (!j->ok[i]) return 0;
        h = sw_fnv1a(h, &j->hash[i], sizeof j->hash[i]);
    }
    return h;
}

TEST(surface_hash_is_golden_on_1_2_4_threads) {
    bake_fixture f;
    /* a fold deep enough for pose-space contact pairs, both branches of its return path */
    ENSURE(bake_fixture_make(&f, "finger", 2000, 12, 1));
    fprintf(stderr, "  fixture springs: %g E h\n", f.res.spring_k / f.res.spring_eh);
    ENSUREF(sw_blob_get_view(f.blob)->ncontacts > 0, "no contact pairs: the hash would miss them");
    static const int threads[] = {1, 2, 4};
    uint64_t h[3];
    for (int t = 0; t < 3; ++t) {
        h[t] = hash_on_threads(&f, 0, NINST, threads[t]);
        fprintf(stderr, "  %d threads: surface hash 0x%016llx\n", threads[t],
                (unsigned long long)h[t]);
    }
    bake_fixture_free(&f);
    ENSURE(h[0] != 0);
    ENSUREF(h[1] == h[0] && h[2] == h[0], "the hash depends on the thread count");
    ENSUREF(h[0] == GOLDEN_SURFACE_HASH, "surface hash 0x%016llx, golden 0x%016llx",
            (unsigned long long)h[0], (unsigned long long)GOLDEN_SURFACE_HASH);
}

/* The step's other paths, each an instance: exhaustive and pose-pairs self-contact, a
 * condensation patch against the props (a mesh and a hull), and the character turned
 * 130 degrees and carried away (what the pose-space lookups must not notice). */
TEST(surface_hash_of_every_mode_is_golden) {
    bake_fixture f;
    ENSURE(bake_fixture_make(&f, "finger", 2000, 12, 1));
    sinew_world_def wd = sinew_world_def_default();
    sinew_collider_id tent, wedge;
    ENSURE(sinew_world_create(&wd, &props_world) == SINEW_OK &&
           props_add(props_world, 2.2f, 1.2f, &tent, &wedge));
    uint64_t h1 = hash_on_threads(&f, NINST, NMODES, 1), h2 = hash_on_threads(&f, NINST, NMODES, 2);
    fprintf(stderr, "  modes: surface hash 0x%016llx (1 thread), 0x%016llx (2)\n",
            (unsigned long long)h1, (unsigned long long)h2);
    sinew_world_destroy(props_world);
    bake_fixture_free(&f);
    ENSURE(h1 != 0);
    ENSUREF(h2 == h1, "the hash depends on the thread count");
    ENSUREF(h1 == GOLDEN_MODES_HASH, "surface hash 0x%016llx, golden 0x%016llx",
            (unsigned long long)h1, (unsigned long long)GOLDEN_MODES_HASH);
}

/* The bake stores the reduced mass and springs by domain blocks (blob version 4); the same
 * blob written with them dense (version 2, as blobs were before) steps bitwise alike:
 * the golden hash, and every mode's. */
TEST(a_dense_blob_of_before_steps_the_same) {
    bake_fixture f;
    ENSURE(bake_fixture_make(&f, "finger", 2000, 12, 1));
    const sw_blob_view *v = sw_blob_get_view(f.blob);
    ENSURE(v->reduced_blocks);
    const int32_t R = v->rank_total;
    double *mass = malloc(sizeof(double) * R * R), *spring = malloc(sizeof(double) * R * R);
    ENSURE(mass && spring);
    for (int32_t i = 0; i < R; ++i)
        for (int32_t j = 0; j < R; ++j) {
            mass[(int64_t)i * R + j] = sw_blob_reduced_entry(v, SW_BLOB_MASS, i, j);
            spring[(int64_t)i * R + j] = sw_blob_reduced_entry(v, SW_BLOB_SPRINGS, i, j);
        }
    sw_blob_view dense = *v;
    dense.mass = mass, dense.spring_hessian = spring, dense.reduced_blocks = NULL;
    dense.nmass = dense.nspring_hessian = (int64_t)R * R;
    void *data = NULL;
    size_t size = 0;
    sw_error err;
    ENSUREF(sw_blob_write_memory(&dense, &data, &size, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(((const sinew_blob_header *)data)->version < 4);
    fprintf(stderr, "  blob by blocks %zu bytes, dense %zu\n", f.size, size);
    sinew_blob *packed = f.blob;
    sinew_blob_def d = sinew_blob_def_default();
    d.data = data;
    d.data_size = size;
    ENSURE(sinew_blob_load(&d, &f.blob) == SINEW_OK);
    sinew_world_def wd = sinew_world_def_default();
    sinew_collider_id tent, wedge;
    ENSURE(sinew_world_create(&wd, &props_world) == SINEW_OK &&
           props_add(props_world, 2.2f, 1.2f, &tent, &wedge));
    uint64_t h = hash_on_threads(&f, 0, NINST, 1), hm = hash_on_threads(&f, NINST, NMODES, 1);
    sinew_world_destroy(props_world);
    sinew_blob_destroy(f.blob);
    f.blob = packed;
    bake_fixture_free(&f);
    free(data);
    free(mass);
    free(spring);
    ENSUREF(h == GOLDEN_SURFACE_HASH && hm == GOLDEN_MODES_HASH,
            "dense: surface hash 0x%016llx, modes 0x%016llx", (unsigned long long)h,
            (unsigned long long)hm);
}

SW_TEST_MAIN(CASE(surface_hash_is_golden_on_1_2_4_threads),
             CASE(surface_hash_of_every_mode_is_golden),
             CASE(a_dense_blob_of_before_steps_the_same))
