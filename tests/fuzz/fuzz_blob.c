/* libFuzzer harness for the blob parser (STYLE.md §9: a fuzz harness for every loader).
 * Not part of the default build. Build and run (clang with libFuzzer):
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/blob -Iruntime/math \
 *     tests/fuzz/fuzz_blob.c runtime/blob/blob_load.c -lm -o build-fuzz-blob
 *   mkdir -p /tmp/blob-corpus && ./build-fuzz-blob -max_len=65536 /tmp/blob-corpus
 *
 * Seed the corpus with real blobs (e.g. the bake's output, or the bytes test_blob writes)
 * for coverage beyond the header: random bytes almost never pass the checksum. Define
 * SW_FUZZ_FIX_CHECKSUM to have the harness overwrite the checksum field before parsing,
 * so mutations reach the semantic checks (hostile blobs).
 *
 * Every input is copied into a 64-byte aligned buffer of exactly its size, so that ASan
 * reports a read one byte past it. An accepted blob is re-validated and every index
 * chain a runtime follows is walked. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static double walk(const sw_blob_view *v) {
    const int64_t R = v->rank_total;
    double s = 0.0;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        s += v->bone_joints[6 * dom->bone + 5];
        for (int32_t k = 0; k < dom->vert_count; ++k) {
            int32_t x = v->domain_verts[dom->vert_begin + k];
            s += v->rest[3 * x + 2];
            for (int j = 0; j < 4; ++j) {
                int32_t b = v->skin_bone[4 * x + j];
                for (int32_t p = v->bone_parent[b]; p >= 0; p = v->bone_parent[p])
                    s += 1.0;
                s += v->skin_weight[4 * x + j];
            }
            s += v->basis[dom->basis_offset + (3 * k + 2) * dom->rank + dom->rank - 1];
        }
        for (int32_t i = 0; i < dom->rank; ++i)
            s += v->mass[(dom->q_offset + i) * R + R - 1] +
                 v->inertia_x[9 * (dom->q_offset + i) + 8];
        s += v->inertia_u[dom->inertia_offset + 9 * dom->rank * dom->rank - 1];
        for (int32_t c = dom->cub_begin; c < dom->cub_begin + dom->cub_count; ++c)
            for (int k = 0; k < 4; ++k)
                s += v->rest[3 * v->domain_verts[dom->vert_begin + v->cub_tets[4 * c + k]]];
    }
    for (int32_t t = 0; t < 3 * v->nsurf_tris; ++t) {
        int32_t sv = v->surf_tris[t];
        for (int32_t c = v->surf_copy_ptr[sv]; c < v->surf_copy_ptr[sv + 1]; ++c) {
            const sw_blob_domain *dom = &v->domains[v->surf_copies[2 * c]];
            s += v->rest[3 * v->domain_verts[dom->vert_begin + v->surf_copies[2 * c + 1]]];
        }
    }
    return s;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    void *copy = NULL;
    if (posix_memalign(&copy, 64, size ? size : 1) != 0) return 0;
    memcpy(copy, data, size);
#ifdef SW_FUZZ_FIX_CHECKSUM
    if (size >= sizeof(sinew_blob_header)) {
        uint64_t sum = sw_blob_checksum((uint8_t *)copy + 64, size - 64);
        memcpy((uint8_t *)copy + offsetof(sinew_blob_header, checksum), &sum, sizeof sum);
    }
#endif
    sw_blob_view v;
    char msg[512];
    if (sw_blob_parse(copy, size, &v, msg, sizeof msg) == SINEW_OK) {
        if (sw_blob_validate_view(&v, msg, sizeof msg) != SINEW_OK) abort();
        volatile double sink = walk(&v);
        (void)sink;
    }
    free(copy);
    return 0;
}
