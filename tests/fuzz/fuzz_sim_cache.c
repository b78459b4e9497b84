/* libFuzzer harness for the simulate stage's cache reader (sw_sim_cache_parse,
 * precompute/bake/sim_cache.h): the bake reads that file back from a folder a user names,
 * so it is outside data. tests/CMakeLists.txt builds it with clang when clang has
 * libFuzzer and runs it for a few seconds on tests/fuzz/corpus/sim_cache (the seed is
 * test_bake_cache's tiny file, SINEW_WRITE_SEEDS=1 rewrites it) as the test
 * fuzz_sim_cache; tools/scripts/run-fuzz.sh runs it for longer.
 *
 * Each input is read twice against the seed's shape (key 0x1234, 4 vertices, sequences of
 * 2 and 1 poses): as it is, and with its checksum fixed up (random bytes rarely pass it,
 * so the second read explores the body). A refusal must name the file and leave the
 * output zeroed; an accepted cache has every index in range and every value finite. */
#include <math.h>

#include "fuzz_check.h"
#include "sim_cache.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void read_once(const uint8_t *b, size_t n) {
    static const int32_t npose[2] = {2, 1};
    sw_sim_cache c;
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_sim_cache_parse(b, n, "fuzz.bin", 0x1234, 4, 2, npose, &c, &err);
    if (rc != SINEW_OK) {
        sw_fuzz_check_error(rc, &err, "fuzz.bin");
        if (!sw_fuzz_zeroed(&c, sizeof c)) abort();
        return;
    }
    if (c.nseq != 2 || c.nverts != 4) abort();
    for (int32_t i = 0; i < 2; ++i) {
        const sw_sim_cache_seq *q = &c.seq[i];
        if (q->npose != npose[i] || q->contact_ptr[0] != 0 ||
            q->contact_ptr[q->npose] != q->ncontacts)
            abort();
        for (int32_t k = 0; k < q->npose * 12; ++k)
            if (!isfinite(q->x[k])) abort();
        for (int32_t k = 0; k < q->ncontacts; ++k) {
            const sw_contact *s = &q->contacts[k];
            if (s->p < 0 || s->p >= 4 || !isfinite(s->ka) || !isfinite(s->depth)) abort();
            for (int j = 0; j < 3; ++j)
                if (s->tri[j] < 0 || s->tri[j] >= 4 || !isfinite(s->beta[j]) || !isfinite(s->n[j]))
                    abort();
        }
    }
    sw_sim_cache_free(&c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    uint8_t *copy = (uint8_t *)sw_fuzz_copy(data, size);
    if (!copy) return 0;
    read_once(copy, size);
    if (size >= 16) {
        uint64_t h = sw_fnv1a(SW_FNV_START, copy, size - 8);
        memcpy(copy + size - 8, &h, 8);
        read_once(copy, size);
    }
    free(copy);
    return 0;
}
