/* The bake as a pipeline (bake.c, sw_bake_stages): one table of stages that sw_bake runs
 * and the log, the report and --json read; the result's owned arrays without a fixed
 * count; the blob to ship from a character's only clip (sw_bake_ships_whole_clip); an
 * unwritable output found before the bake (sw_write_file_check). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sw_test.h"

#include "bake.h"
#include "blob_write.h"

/* Every row names its stage once, runs it, logs it and says what it reads and writes;
 * the stages sw_bake_solutions runs come before the basis is built from their solutions. */
TEST(stage_table_is_whole) {
    int basis = -1;
    for (int i = 0; i < SW_BAKE_NSTAGES; ++i) {
        const sw_bake_stage *st = &sw_bake_stages[i];
        ENSUREF(st->name && st->run && st->summary && st->reads && st->writes && st->reads[0] &&
                    st->writes[0],
                "stage %d is not whole", i);
        if (!st->name) return;
        for (int j = 0; j < i; ++j)
            ENSUREF(strcmp(sw_bake_stages[j].name, st->name) != 0, "stage '%s' twice", st->name);
        if (!strcmp(st->name, "basis")) basis = i;
        if (st->solutions)
            ENSUREF(basis < 0, "'%s' runs for the solutions after the basis", st->name);
    }
    ENSURE(basis > 0);
    ENSURE(!strcmp(sw_bake_stages[0].name, "prepare"));
}

/* The owned list grows past any fixed count and frees everything it holds. */
TEST(owned_arrays_have_no_fixed_count) {
    sw_bake_result r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 1000; ++i)
        ENSURE(sw_bake_own(&r, malloc(8)) != NULL);
    ENSURE(r.nowned == 1000);
    ENSURE(sw_bake_own(&r, NULL) == NULL && r.nowned == 1000);
    sw_bake_result_free(&r);
    ENSURE(r.nowned == 0 && r.owned == NULL);
}

/* Only a character's own clip, split to measure it, ships re-baked on the whole clip. */
TEST(only_clip_ships_whole) {
    sw_character c;
    memset(&c, 0, sizeof c);
    sw_bake_params p = sw_bake_params_default();
    ENSURE(!sw_bake_ships_whole_clip(&c, &p)); /* no clip: random held-out poses */
    c.clip.nframes = 12;
    ENSURE(sw_bake_ships_whole_clip(&c, &p));
    p.ship_split = 1;
    ENSURE(!sw_bake_ships_whole_clip(&c, &p));
    p.ship_split = 0;
    sw_clip train;
    memset(&train, 0, sizeof train);
    p.train_clips = &train;
    p.ntrain_clips = 1; /* clips of their own are not split */
    ENSURE(!sw_bake_ships_whole_clip(&c, &p));
}

/* A blob path whose folder is missing, or a folder, fails before the bake, saying why;
 * a writable one leaves nothing behind. */
TEST(output_checked_before_the_bake) {
    sw_error err;
    char dir[] = "/tmp/sw_bake_stages_XXXXXX", path[96], tmp[100];
    ENSURE(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/no/such/a.blob", dir);
    ENSURE(sw_write_file_check(path, &err) == SINEW_ERROR_IO);
    ENSUREF(strstr(err.msg, "No such file") != NULL, "%s", err.msg);
    ENSURE(sw_write_file_check(dir, &err) == SINEW_ERROR_IO);
    snprintf(path, sizeof path, "%s/a.blob", dir);
    ENSURE(sw_write_file_check(path, &err) == SINEW_OK);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    ENSURE(access(tmp, F_OK) != 0 && access(path, F_OK) != 0);
    rmdir(dir);
}

SW_TEST_MAIN(CASE(stage_table_is_whole), CASE(owned_arrays_have_no_fixed_count),
             CASE(only_clip_ships_whole), CASE(output_checked_before_the_bake))
