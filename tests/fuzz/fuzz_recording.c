/* libFuzzer harness for the recording reader (sw_recording_parse, runtime/instance/
 * recording.h): a recording arrives with a bug report, so it is outside data.
 * tests/CMakeLists.txt builds it with clang when clang has libFuzzer and runs it for a few
 * seconds on tests/fuzz/corpus/recording (the seeds are test_record_replay's three-step
 * recordings, one of format version 1 and one of version 2 with MESH and IGNORE records;
 * SINEW_WRITE_SEEDS=1 rewrites them) as the test fuzz_recording;
 * tools/scripts/run-fuzz.sh runs it for longer.
 *
 * Each input is read twice: as it is, and with every chunk's checksum fixed up (random
 * bytes rarely pass it, so the second read explores the records). A refusal must say why
 * and leave the output zeroed; an accepted recording walks from BEGIN to END with every
 * record inside the stream. */
#include "fuzz_check.h"
#include "hash.h"
#include "recording.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void read_once(const uint8_t *b, size_t n) {
    sw_recording r;
    sw_error err;
    sinew_result rc = sw_recording_parse(b, n, &r, &err);
    if (rc != SINEW_OK) {
        if (err.code != rc || err.msg[0] == 0 || !sw_fuzz_zeroed(&r, sizeof r)) abort();
        return;
    }
    size_t pos = 0;
    sw_rec_record rec;
    uint32_t first = 0, last = 0, steps = 0, count = 0;
    while (sw_recording_next(&r, &pos, &rec)) {
        if (rec.p < r.stream || rec.p + rec.bytes > r.stream + r.size) abort();
        if (count++ == 0) first = rec.type;
        last = rec.type;
        steps += rec.type == SW_REC_STEP;
    }
    if (pos != r.size || first != SW_REC_BEGIN || last != SW_REC_END || steps != r.steps) abort();
    sw_recording_free(&r);
}

/* Every chunk's checksum recomputed, as far as the chunks' sizes hold. */
static void fix_chunks(uint8_t *b, size_t n) {
    size_t at = SW_REC_PREAMBLE_BYTES;
    while (n - at >= SW_REC_CHUNK_BYTES && at < n) {
        uint32_t len;
        memcpy(&len, b + at + 4, 4);
        if (len > n - at - SW_REC_CHUNK_BYTES) return;
        uint64_t h = sw_fnv1a(SW_FNV_START, b + at + SW_REC_CHUNK_BYTES, len);
        memcpy(b + at + 8, &h, 8);
        at += SW_REC_CHUNK_BYTES + len;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    uint8_t *copy = (uint8_t *)sw_fuzz_copy(data, size);
    if (!copy) return 0;
    read_once(copy, size);
    if (size >= SW_REC_PREAMBLE_BYTES) {
        fix_chunks(copy, size);
        read_once(copy, size);
    }
    free(copy);
    return 0;
}
