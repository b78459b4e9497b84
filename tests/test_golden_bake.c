/* The bake is deterministic in its thread count: a small finger baked on 1, 2
 * and 3 worker threads (sw_bake_params.threads: the training simulations, the cubature
 * and the reduction run on the bake's pool) gives the same blob, byte for byte. Every
 * reduction of the bake has a fixed order; a change that makes one depend on the thread
 * schedule fails here. The blob's FNV-1a hash is printed for the record (not pinned: the
 * blob is the bake's, and other commits change the bake on purpose). */
#include <stdint.h>

#include "bake_fixture.h"
#include "hash.h"
#include "sw_test.h"

TEST(blob_bytes_are_identical_on_1_2_3_bake_threads) {
    static const int threads[] = {1, 2, 3};
    bake_fixture f[3];
    int ok = 1;
    for (int t = 0; t < 3 && ok; ++t) {
        /* a fold deep enough for contact pairs, with the clip's return path */
        ok = bake_fixture_make_threads(&f[t], "finger", 2000, 12, 1, threads[t]);
        if (!ok) break;
        fprintf(stderr, "  %d bake threads: blob %zu bytes, FNV-1a 0x%016llx\n", threads[t],
                f[t].size, (unsigned long long)sw_fnv1a(SW_FNV_START, f[t].data, f[t].size));
    }
    ENSUREF(ok, "a bake failed");
    ENSUREF(sw_blob_get_view(f[0].blob)->ncontacts > 0, "no contact pairs: the blob proves less");
    for (int t = 1; t < 3; ++t) {
        ENSUREF(f[t].size == f[0].size, "%d threads: %zu bytes, 1 thread: %zu", threads[t],
                f[t].size, f[0].size);
        /* the sections that differ (the header's checksum differs with any of them) */
        const sinew_blob_header *hd = f[0].data;
        const sinew_blob_section *sec =
            (const sinew_blob_section *)((const char *)f[0].data + hd->section_table_offset);
        int differ = 0;
        for (uint32_t k = 0; k < hd->section_count; ++k) {
            size_t n = (size_t)sec[k].count * sec[k].elem_size;
            if (memcmp((const char *)f[0].data + sec[k].offset,
                       (const char *)f[t].data + sec[k].offset, n) == 0)
                continue;
            differ++;
            fprintf(stderr, "  %d threads: section %s (%zu bytes) differs from 1 thread's\n",
                    threads[t], sw_blob_section_name(sec[k].id), n);
        }
        ENSUREF(differ == 0 && memcmp(f[t].data, f[0].data, f[0].size) == 0,
                "%d threads: the blob differs from 1 thread's (%d sections)", threads[t], differ);
    }
    for (int t = 0; t < 3; ++t)
        bake_fixture_free(&f[t]);
}

SW_TEST_MAIN(CASE(blob_bytes_are_identical_on_1_2_3_bake_threads))
