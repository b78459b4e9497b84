/* Hostile blobs, stepped: a small real bake (a cylinder of 1,000 tets at rank
 * 2, with pose-space contact pairs) is mutated a few thousand times from a fixed seed, a
 * few bytes each, anywhere in the file or inside one section picked at random (so that the
 * small index sections, META and the table are hit as often as the large arrays), the
 * checksum is fixed up, and each result loaded. A refused blob must come with a message;
 * an accepted one is stepped in both modes through the rest pose and a bent one, and every
 * step must either succeed with a finite surface or fail cleanly. ASan/UBSan builds run
 * fewer mutations. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "blob_load.h"
#include "blob_write.h"
#include "samples.h"
#include "sinew/sinew.h"
#include "sw_test.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define MUTATIONS 300
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define MUTATIONS 300
#endif
#endif
#ifndef MUTATIONS
#define MUTATIONS 4000
#endif

static uint64_t rng = 0x5eed15;
static uint32_t next(void) {
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(rng >> 33);
}

/* Every bone turned about z by `bent` times a per-bone factor, shifted a little. */
static void pose(float *T, int32_t nbones, double bent) {
    for (int32_t b = 0; b < nbones; ++b) {
        double a = bent * (0.3 + 0.2 * (b % 3)), c = cos(a), s = sin(a);
        const double R[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
        for (int i = 0; i < 9; ++i)
            T[12 * b + i] = (float)R[i];
        T[12 * b + 9] = (float)(0.1 * bent);
        T[12 * b + 10] = (float)(-0.05 * bent * b);
        T[12 * b + 11] = 0.0f;
    }
}

/* Steps an accepted blob; 0 when a step reports success with a non-finite surface or an
 * API call fails in a way the contract does not allow. */
static int step_blob(const sinew_blob *blob, int mode, int *steps_ok, int *steps_failed) {
    const int32_t nb = (int32_t)sinew_blob_bone_count(blob);
    const int32_t ns = (int32_t)sinew_blob_surface_vertex_count(blob);
    float *T = malloc((size_t)12 * nb * sizeof(float));
    float *pos = malloc((size_t)6 * ns * sizeof(float));
    int ok = T && pos;
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
    d.max_newton_iters = 3;
    sinew_instance *in = NULL;
    sinew_result r = ok ? sinew_instance_create(blob, &d, &in) : SINEW_ERROR_OUT_OF_MEMORY;
    if (r != SINEW_OK) {
        fprintf(stderr, "  instance_create: %d\n", (int)r);
        ok = 0;
    }
    const double bends[3] = {0.0, 0.8, 0.4};
    for (int f = 0; ok && f < 3; ++f) {
        pose(T, nb, bends[f]);
        if (sinew_instance_set_pose(in, T, (uint32_t)nb) != SINEW_OK) ok = 0;
        r = sinew_instance_step(in, 1.0f / 30.0f);
        if (r != SINEW_OK) {
            ++*steps_failed; /* e.g. NOT_FINITE: undone, reported */
            continue;
        }
        ++*steps_ok;
        if (sinew_instance_read_surface(in, pos, pos + 3 * ns, (uint32_t)ns) != SINEW_OK) ok = 0;
        for (int64_t i = 0; ok && i < 6 * (int64_t)ns; ++i)
            if (!isfinite(pos[i])) {
                fprintf(stderr, "  frame %d: step OK but surface value %lld is %g\n", f,
                        (long long)i, pos[i]);
                ok = 0;
            }
    }
    sinew_instance_destroy(in);
    free(pos);
    free(T);
    return ok;
}

TEST(mutated_blobs_load_cleanly_and_step_finite) {
    sw_character ch;
    sw_bake_result res;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1000, 12, &ch, &err) == SINEW_OK);
    sw_bake_params p = sw_bake_params_default();
    p.max_rank = 2;
    p.threads = 2;
    ENSUREF(sw_bake(&ch, &p, &res, &err) == SINEW_OK, "%s", err.msg);
    void *clean = NULL;
    size_t size = 0;
    ENSURE(sw_blob_write_memory(&res.view, &clean, &size, &err) == SINEW_OK);
    ENSUREF(res.view.ncontacts > 0, "the bake has no contact pairs to mutate");
    uint8_t *b = NULL;
    ENSURE(posix_memalign((void **)&b, 64, size) == 0);
    const sinew_blob_section *table = (const sinew_blob_section *)((const uint8_t *)clean + 64);
    const uint32_t nsec = ((const sinew_blob_header *)clean)->section_count;
    int accepted = 0, refused = 0, steps_ok = 0, steps_failed = 0, bad = 0;
    for (int m = 0; m < MUTATIONS && bad < 5; ++m) {
        memcpy(b, clean, size);
        const int nbytes = 1 + (int)(next() % 4);
        for (int k = 0; k < nbytes; ++k) {
            size_t at;
            if (next() % 2) { /* anywhere past the header */
                at = 64 + next() % (uint32_t)(size - 64);
            } else { /* inside one section (or its table entry) */
                const sinew_blob_section *s = &table[next() % nsec];
                const uint64_t bytes = s->count * s->elem_size;
                at = bytes == 0 || next() % 8 == 0
                         ? (size_t)((const uint8_t *)s - (const uint8_t *)clean) + next() % 32
                         : (size_t)(s->offset + next() % bytes);
            }
            switch (next() % 3) {
            case 0:
                b[at] = (uint8_t)next();
                break;
            case 1:
                b[at] ^= (uint8_t)(1u << (next() % 8));
                break;
            default: /* a small integer (0xff.. for negatives) */
                b[at] = (uint8_t)((int)(next() % 5) - 2);
                break;
            }
        }
        ((sinew_blob_header *)(void *)b)->checksum = sw_blob_checksum(b + 64, size - 64);
        sinew_blob_def def = sinew_blob_def_default();
        def.data = b;
        def.data_size = size;
        sinew_blob *blob = NULL;
        char msg[512];
        sw_blob_view v;
        sinew_result pr = sw_blob_parse(b, size, &v, msg, sizeof msg);
        sinew_result lr = sinew_blob_load(&def, &blob);
        if (pr != lr || (lr == SINEW_OK) != (blob != NULL)) {
            fprintf(stderr, "  mutation %d: parse %d but load %d\n", m, (int)pr, (int)lr);
            bad++;
        } else if (lr != SINEW_OK) {
            refused++;
            if (msg[0] == '\0') {
                fprintf(stderr, "  mutation %d: refused (%d) without a message\n", m, (int)lr);
                bad++;
            }
        } else {
            accepted++;
            if (!step_blob(blob, m % 2, &steps_ok, &steps_failed)) {
                fprintf(stderr, "  mutation %d (accepted) failed to step cleanly\n", m);
                bad++;
            }
        }
        sinew_blob_destroy(blob);
    }
    fprintf(stderr,
            "  %d mutations of %zu bytes: %d refused, %d accepted; steps %d ok, %d failed\n",
            MUTATIONS, size, refused, accepted, steps_ok, steps_failed);
    free(b);
    free(clean);
    sw_bake_result_free(&res);
    sw_character_free(&ch);
    ENSURE(bad == 0);
    ENSURE(accepted > 0 && refused > 0 && steps_ok > 0);
}

SW_TEST_MAIN(CASE(mutated_blobs_load_cleanly_and_step_finite))
