/* Profiler zones (sinew_instance_def.profiler): every step opens and closes one zone per
 * phase, in order, balanced, with the same static names each step; a def with only one of
 * the two callbacks is refused; a paused frame (dt 0) opens none. The synthetic character
 * of blob_synth.h is stepped. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "blob_write.h"
#include "sinew/sinew.h"
#include "sw_test.h"

#include "blob_synth.h"

static fixture g_fix;

typedef struct zones {
    const char *names[64];
    int n, depth, max_depth, unbalanced;
} zones;

static void begin(const char *name, void *user) {
    zones *z = user;
    if (z->n < 64) z->names[z->n] = name;
    z->n++;
    if (++z->depth > z->max_depth) z->max_depth = z->depth;
}

static void end(const char *name, void *user) {
    zones *z = user;
    if (z->depth < 1 || z->n < 1 || name != z->names[(z->n - 1) % 64]) z->unbalanced++;
    z->depth--;
}

static sinew_blob *synth_blob(void **data) {
    size_t size = 0;
    fixture_init(&g_fix, 4);
    *data = write_fixture(&g_fix, &size);
    sinew_blob_def d = sinew_blob_def_default();
    d.data = *data;
    d.data_size = size;
    sinew_blob *blob = NULL;
    return *data && sinew_blob_load(&d, &blob) == SINEW_OK ? blob : NULL;
}

TEST(a_step_opens_one_zone_a_phase) {
    static const char *const want[] = {"skin",   "contact", "dynamics", "self_contact", "world",
                                       "oracle", "solve",   "advance",  "output"};
    void *data = NULL;
    sinew_blob *blob = synth_blob(&data);
    ENSURE(blob);
    zones z;
    memset(&z, 0, sizeof z);
    sinew_instance_def d = sinew_instance_def_default();
    d.profiler.zone_begin = begin;
    d.profiler.zone_end = end;
    d.profiler.user = &z;
    sinew_instance *inst = NULL;
    ENSURE(sinew_instance_create(blob, &d, &inst) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
    ENSUREF(z.n == 9, "%d zones", z.n);
    for (int i = 0; i < 9; ++i)
        ENSUREF(strcmp(z.names[i], want[i]) == 0, "zone %d is %s", i, z.names[i]);
    ENSURE(z.depth == 0 && z.max_depth == 1 && z.unbalanced == 0);
    const char *first = z.names[0];
    ENSURE(sinew_instance_step(inst, 0.0f) == SINEW_OK && z.n == 9); /* paused: none */
    ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK && z.n == 18);
    ENSURE(z.names[9] == first && z.unbalanced == 0); /* the same static strings */
    sinew_instance_destroy(inst);

    d.profiler.zone_end = NULL; /* half a profiler */
    ENSURE(sinew_instance_create(blob, &d, &inst) == SINEW_ERROR_INVALID_ARGUMENT);
    sinew_blob_destroy(blob);
    free(data);
}

SW_TEST_MAIN(CASE(a_step_opens_one_zone_a_phase))
