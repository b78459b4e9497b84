/* The simulate stage's cache (precompute/bake/sim_cache.h, bake_cache.c): a
 * re-bake that changes only the cubature reads the solutions back, bitwise the ones it
 * would solve, and writes the very blob a bake without the cache writes; a change of
 * material, pose or simulator misses; a damaged, truncated or forged file is refused with
 * a message naming it, and the bake solves around it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake.h"
#include "blob_write.h"
#include "fullsim.h"
#include "samples.h"
#include "sim_cache.h"
#include "sw_test.h"

static sw_bake_params quick(const char *dir) {
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 2;
    p.threads = 2;
    p.cache_dir = dir;
    return p;
}

/* The blob's bytes of a bake (malloc'd). */
static void *blob_bytes(const sw_bake_result *r, size_t *n) {
    void *b = NULL;
    sw_error err;
    return sw_blob_write_memory(&r->view, &b, n, &err) == SINEW_OK ? b : NULL;
}

static int same_solutions(const sw_bake_result *a, const sw_bake_result *b, size_t px) {
    return a->ntrain == b->ntrain && a->nheldout == b->nheldout &&
           !memcmp(a->train_x, b->train_x, a->ntrain * px) &&
           !memcmp(a->heldout_x, b->heldout_x, a->nheldout * px);
}

/* |a - b| over |b - rest| across n poses' solutions */
static double rel_apart(const sw_character *c, const double *a, const double *b, int32_t n) {
    double d = 0, s = 0;
    int64_t nv3 = 3 * (int64_t)c->mesh.nverts;
    for (int64_t k = 0; k < n * nv3; ++k) {
        d += (a[k] - b[k]) * (a[k] - b[k]);
        s += (b[k] - c->mesh.X[k % nv3]) * (b[k] - c->mesh.X[k % nv3]);
    }
    return sqrt(d / s);
}

TEST(a_rebake_reads_the_solutions_back_and_writes_the_same_blob) {
    char dir[] = "/tmp/sinew-cache-XXXXXX";
    ENSURE(mkdtemp(dir));
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    size_t px = (size_t)3 * c.mesh.nverts * sizeof(double), n0, n1;
    sw_bake_params plain = quick(NULL), cached = quick(dir);
    sw_bake_result r0, r1, r2, r3;
    ENSUREF(sw_bake(&c, &plain, &r0, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_bake(&c, &cached, &r1, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(!r0.simulate_cached && !r1.simulate_cached); /* the first fills the cache */
    cached.cubature_tol = 0.1;                          /* only the cubature changes: a hit */
    ENSUREF(sw_bake(&c, &cached, &r2, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(r2.simulate_cached && same_solutions(&r0, &r2, px));
    ENSURE(r2.train_unsettled == r0.train_unsettled &&
           r2.heldout_unsettled == r0.heldout_unsettled);
    cached.cubature_tol = plain.cubature_tol; /* the same bake from the cache: the same blob */
    ENSUREF(sw_bake(&c, &cached, &r3, &err) == SINEW_OK, "%s", err.msg);
    void *b0 = blob_bytes(&r0, &n0), *b1 = blob_bytes(&r3, &n1);
    ENSURE(b0 && b1 && r3.simulate_cached && n0 == n1 && !memcmp(b0, b1, n0));
    free(b0);
    free(b1);
    sw_bake_result_free(&r3);
    /* a change of material, of a pose or of the simulator misses */
    c.youngs *= 1.01;
    ENSUREF(sw_bake(&c, &cached, &r3, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(!r3.simulate_cached);
    sw_bake_result_free(&r3);
    c.youngs /= 1.01;
    c.clip.T[12 * c.skel.nbones * (c.clip.nframes - 1)] += 1e-9;
    ENSUREF(sw_bake(&c, &cached, &r3, &err) == SINEW_OK, "%s", err.msg);
    /* one file per chain: the clip's path (training then held-out frames, and the way
       home from its last training frame) is solved again, the joint sweeps are read back */
    ENSURE(!r3.simulate_cached && r3.simulate_solved == c.clip.nframes + r3.return_poses &&
           r2.simulate_solved == 0 && r1.simulate_solved == r1.ntrain + r1.nheldout);
    sw_bake_result_free(&r3);
    cached.self_contact = 0;
    ENSUREF(sw_bake(&c, &cached, &r3, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(!r3.simulate_cached);
    sw_bake_result_free(&r3);
    /* the reference's solver (sinew-bake --solver): a miss, solved by the other solver, the
       same equilibria within the solvers' tolerances */
    cached.self_contact = 1;
    sw_fullsim_params direct = sw_fullsim_params_default();
    direct.solver = SW_SOLVER_CHOLMOD;
    cached.reference = &direct;
    ENSUREF(sw_bake(&c, &cached, &r3, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(!r3.simulate_cached && r3.ntrain == r0.ntrain && !same_solutions(&r0, &r3, px));
    double apart = rel_apart(&c, r0.train_x, r3.train_x, r0.ntrain);
    printf("    CHOLMOD against PCG references: %.2e of the displacement\n", apart);
    ENSURE(apart < 1e-4);
    sw_bake_result_free(&r3);
    cached.reference = NULL;
    /* a cache "folder" that is a file: an error that names it, before any solve */
    char file[160];
    snprintf(file, sizeof file, "%s/plain", dir);
    FILE *f = fopen(file, "w");
    ENSURE(f && fclose(f) == 0);
    cached.cache_dir = file;
    ENSURE(sw_bake(&c, &cached, &r3, &err) == SINEW_ERROR_IO && strstr(err.msg, file) &&
           strstr(err.msg, "not a folder"));
    sw_bake_result_free(&r0);
    sw_bake_result_free(&r1);
    sw_bake_result_free(&r2);
    sw_character_free(&c);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    ENSURE(system(cmd) == 0);
}

/* A small cache of 2 sequences (2 poses and 1) over 4 vertices, one contact. */
static void tiny(sw_sim_cache *c, sw_sim_cache_seq *q, double *x, int32_t *ptr, sw_contact *k) {
    for (int i = 0; i < 36; ++i)
        x[i] = 0.25 * i;
    ptr[0] = 0, ptr[1] = 1, ptr[2] = 1, ptr[3] = 0, ptr[4] = 0;
    memset(k, 0, sizeof *k);
    k->p = 3, k->tri[0] = 0, k->tri[1] = 1, k->tri[2] = 2;
    k->beta[0] = k->beta[1] = k->beta[2] = 1.0 / 3, k->ka = 0.5, k->n[1] = 1, k->depth = 0.1;
    q[0] = (sw_sim_cache_seq){2, 0, 1, 1, x, ptr, k};
    q[1] = (sw_sim_cache_seq){1, 0, 0, 0, x + 24, ptr + 3, NULL};
    *c = (sw_sim_cache){0x1234, 4, 2, q};
}

/* Re-seals b after an edit (the checksum), as a forger would. */
static void reseal(uint8_t *b, size_t n) {
    uint64_t h = sw_fnv1a(SW_FNV_START, b, n - 8);
    memcpy(b + n - 8, &h, 8);
}

static int refused(const uint8_t *b, size_t n, sinew_result code, const char *needle) {
    static const int32_t npose[2] = {2, 1};
    sw_sim_cache out;
    sw_error err;
    sinew_result r = sw_sim_cache_parse(b, n, "c.bin", 0x1234, 4, 2, npose, &out, &err);
    int ok = r == code && strstr(err.msg, "c.bin") && strstr(err.msg, needle) && !out.seq;
    if (!ok) fprintf(stderr, "    got %d '%s', wanted %d '%s'\n", r, err.msg, code, needle);
    return ok;
}

TEST(a_damaged_or_forged_file_is_refused_by_name) {
    sw_sim_cache c, back;
    sw_sim_cache_seq q[2];
    double x[36];
    int32_t ptr[5];
    sw_contact k;
    tiny(&c, q, x, ptr, &k);
    uint8_t *b;
    size_t n;
    sw_error err;
    ENSURE(sw_sim_cache_encode(&c, &b, &n, &err) == SINEW_OK);
    static const int32_t npose[2] = {2, 1};
    ENSURE(sw_sim_cache_parse(b, n, "c.bin", 0x1234, 4, 2, npose, &back, &err) == SINEW_OK);
    ENSURE(back.seq[0].ncontacts == 1 && back.seq[0].contacts[0].p == 3 &&
           !memcmp(back.seq[1].x, x + 24, 12 * sizeof(double)) && back.seq[0].unsettled == 1);
    sw_sim_cache_free(&back);
    uint8_t *m = malloc(n);
    ENSURE(m);
    /* header of the file: magic 8, key 8, nverts 4, nseq 4; the table 2 x 16; then x of
       sequence 0 (2 x 12 doubles), its contact_ptr (3), the contact (p at its start) */
    const size_t table = 24, x0 = table + 32, ptr0 = x0 + 24 * 8, c0 = ptr0 + 12;
#define FRESH() memcpy(m, b, n)
    FRESH(), m[n - 20] ^= 1;
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "checksum"));
    ENSURE(refused(b, n - 9, SINEW_ERROR_CORRUPT, "checksum"));
    ENSURE(refused(b, 10, SINEW_ERROR_CORRUPT, "not a simulate cache"));
    FRESH(), m[7] = 2, reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "not a simulate cache"));
    FRESH(), m[8] ^= 1, reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_INVALID_ARGUMENT, "other inputs"));
    int32_t bad = 3; /* sequence 0 with 3 poses */
    FRESH(), memcpy(m + table, &bad, 4), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "sequence 0"));
    bad = 2000000000; /* more contacts than the file can hold */
    FRESH(), memcpy(m + table + 12, &bad, 4), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "sequence 0"));
    bad = 5; /* 5 failed of 2 poses */
    FRESH(), memcpy(m + table + 4, &bad, 4), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "sequence 0"));
    double nan = NAN;
    FRESH(), memcpy(m + x0 + 8, &nan, 8), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_NOT_FINITE, "not finite"));
    bad = 2; /* contact_ptr ending at 2 of 1 contact */
    FRESH(), memcpy(m + ptr0 + 8, &bad, 4), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "contact_ptr"));
    bad = 4; /* the contact's vertex out of range */
    FRESH(), memcpy(m + c0, &bad, 4), reseal(m, n);
    ENSURE(refused(m, n, SINEW_ERROR_CORRUPT, "out of range"));
#undef FRESH
    if (getenv("SINEW_WRITE_SEEDS")) { /* the fuzzer's seed: these bytes */
        FILE *f = fopen(SINEW_SOURCE_DIR "/tests/fuzz/corpus/sim_cache/tiny.bin", "wb");
        ENSURE(f && fwrite(b, 1, n, f) == n && fclose(f) == 0);
    }
    free(m);
    free(b);
}

SW_TEST_MAIN(CASE(a_rebake_reads_the_solutions_back_and_writes_the_same_blob),
             CASE(a_damaged_or_forged_file_is_refused_by_name))
