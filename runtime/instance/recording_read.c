/* Reading a recording (recording.h): every byte checked before a record is handed out,
 * since a recording comes with a bug report from outside. A damaged, cut or forged file
 * is SINEW_ERROR_CORRUPT with the byte and the reason, never a read out of bounds. */
#include <stdlib.h>
#include <string.h>

#include "hash.h"
#include "recording.h"
#include "sinew/sinew_world.h"
#include "sw_error.h"

/* The readers of recording.h: memcpy, so any byte offset will do. */
#define SW_REC_READER(name, type)                                                                  \
    type name(const unsigned char *p) {                                                            \
        type x;                                                                                    \
        memcpy(&x, p, sizeof x);                                                                   \
        return x;                                                                                  \
    }
SW_REC_READER(sw_rec_u32, uint32_t)
SW_REC_READER(sw_rec_u64, uint64_t)
SW_REC_READER(sw_rec_f32, float)
SW_REC_READER(sw_rec_f64, double)

/* Checks the preamble and every chunk, and concatenates the payloads into out->stream. */
static sinew_result read_chunks(const unsigned char *d, size_t n, sw_recording *out,
                                sw_error *err) {
    static const unsigned char magic[8] = {'S', 'I', 'N', 'E', 'W', 'R', 'E', 'C'};
    if (n < SW_REC_PREAMBLE_BYTES || memcmp(d, magic, sizeof magic) != 0)
        return sw_error_set(err, SINEW_ERROR_CORRUPT,
                            "not a sinew recording (no SINEWREC preamble)");
    out->version = sw_rec_u32(d + 8);
    if (sw_rec_u32(d + 12) != 0x01020304u)
        return sw_error_set(
            err, SINEW_ERROR_VERSION,
            "recorded on a host of the other byte order (replay it on one like it)");
    if (out->version < SW_REC_OLDEST_VERSION || out->version > SW_REC_VERSION)
        return sw_error_set(err, SINEW_ERROR_VERSION,
                            "recording format version %u; this library reads versions %u to %u",
                            (unsigned)out->version, (unsigned)SW_REC_OLDEST_VERSION,
                            (unsigned)SW_REC_VERSION);
    out->stream = malloc(n); /* the payloads are smaller than the file */
    if (!out->stream) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    size_t at = SW_REC_PREAMBLE_BYTES;
    for (uint32_t c = 0; at < n; ++c) {
        if (n - at < SW_REC_CHUNK_BYTES || sw_rec_u32(d + at) != SW_REC_CHUNK_TAG)
            return sw_error_set(err, SINEW_ERROR_CORRUPT, "chunk %u at byte %zu: %s", (unsigned)c,
                                at, n - at < SW_REC_CHUNK_BYTES ? "truncated header" : "bad tag");
        size_t len = sw_rec_u32(d + at + 4);
        if (len > n - at - SW_REC_CHUNK_BYTES)
            return sw_error_set(
                err, SINEW_ERROR_CORRUPT,
                "chunk %u at byte %zu: %zu payload bytes, the file has %zu left (truncated)",
                (unsigned)c, at, len, n - at - SW_REC_CHUNK_BYTES);
        const unsigned char *p = d + at + SW_REC_CHUNK_BYTES;
        if (sw_fnv1a(SW_FNV_START, p, len) != sw_rec_u64(d + at + 8))
            return sw_error_set(err, SINEW_ERROR_CORRUPT, "chunk %u at byte %zu: checksum mismatch",
                                (unsigned)c, at);
        memcpy(out->stream + out->size, p, len);
        out->size += len;
        at += SW_REC_CHUNK_BYTES + len;
    }
    return SINEW_OK;
}

/* A WORLD payload's size from its contents (0 when it does not add up). */
static size_t world_bytes(const unsigned char *p, size_t bytes) {
    if (bytes < 8) return 0;
    uint32_t nc = sw_rec_u32(p + 4);
    size_t at = 8;
    for (uint32_t i = 0; i < nc; ++i) {
        if (bytes - at < SW_REC_COLLIDER_BYTES) return 0;
        const unsigned char *c = p + at;
        uint64_t np = sw_rec_u32(c + 80), nv = sw_rec_u32(c + 84), nt = sw_rec_u32(c + 88);
        if (sw_rec_u32(c + 4) > (uint32_t)SINEW_SHAPE_MESH || np + nv > (1u << 26) ||
            nt > (1u << 26))
            return 0;
        uint64_t more = 12 * (np + nv + nt);
        if (more > bytes - at - SW_REC_COLLIDER_BYTES) return 0;
        at += SW_REC_COLLIDER_BYTES + (size_t)more;
    }
    return at;
}

/* Whether a record's size fits its type and contents. */
static int record_fits(const sw_recording *r, const sw_rec_record *rec) {
    switch ((sw_rec_type)rec->type) {
    case SW_REC_BEGIN:
        return rec->bytes == SW_REC_BEGIN_BYTES;
    case SW_REC_WORLD:
        return world_bytes(rec->p, rec->bytes) == rec->bytes;
    case SW_REC_ACTOR:
        return rec->bytes == 12 * sizeof(double);
    case SW_REC_POSE:
        return rec->bytes >= 4 && sw_rec_u32(rec->p) == r->bones &&
               rec->bytes == 4 + 48 * (uint64_t)r->bones;
    case SW_REC_TELEPORT:
    case SW_REC_RESET:
        return rec->bytes == 0;
    case SW_REC_STEP:
        return rec->bytes >= SW_REC_STEP_BYTES &&
               rec->bytes ==
                   SW_REC_STEP_BYTES + SW_REC_MOVE_BYTES * (uint64_t)sw_rec_u32(rec->p + 12);
    case SW_REC_END:
        return rec->bytes == 4;
    case SW_REC_MESH: /* version 2 on */
        return r->version >= 2 && rec->bytes >= 8 &&
               rec->bytes == 8 + 12 * (uint64_t)sw_rec_u32(rec->p + 4);
    case SW_REC_IGNORE:
        return r->version >= 2 && rec->bytes == 4;
    case SW_REC_PLACE:
        return r->version >= 2 && rec->bytes == SW_REC_PLACE_BYTES;
    case SW_REC_LOD:
        return r->version >= 3 && rec->bytes == 4;
    }
    return 0;
}

int sw_recording_next(const sw_recording *r, size_t *pos, sw_rec_record *rec) {
    if (r->size - *pos < SW_REC_HEADER_BYTES) return 0;
    const unsigned char *h = r->stream + *pos;
    rec->type = sw_rec_u32(h);
    rec->bytes = sw_rec_u32(h + 4);
    if (rec->bytes > r->size - *pos - SW_REC_HEADER_BYTES) return 0;
    rec->p = h + SW_REC_HEADER_BYTES;
    *pos += SW_REC_HEADER_BYTES + rec->bytes;
    return 1;
}

/* Walks the records: each whole and of its type's size, BEGIN first and once, END last. */
static sinew_result check_records(sw_recording *r, sw_error *err) {
    size_t pos = 0, at = 0;
    sw_rec_record rec;
    uint32_t steps = 0, count = 0, ended = 0;
    while (at = pos, sw_recording_next(r, &pos, &rec)) {
        if (ended)
            return sw_error_set(err, SINEW_ERROR_CORRUPT, "record %u (stream byte %zu) after END",
                                (unsigned)count, at);
        if ((count == 0) != (rec.type == SW_REC_BEGIN))
            return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                "record %u (stream byte %zu): type %u where %s", (unsigned)count,
                                at, (unsigned)rec.type,
                                count == 0 ? "BEGIN must come first" : "BEGIN again");
        if (rec.type == SW_REC_BEGIN) {
            r->blob_hash = sw_rec_u64(rec.p);
            r->blob_bytes = sw_rec_u64(rec.p + 8);
            r->bones = sw_rec_u32(rec.p + 16);
            r->surface = sw_rec_u32(rec.p + 20);
        }
        if (!record_fits(r, &rec))
            return sw_error_set(
                err, SINEW_ERROR_CORRUPT,
                "record %u (stream byte %zu): type %u with %u bytes does not add up",
                (unsigned)count, at, (unsigned)rec.type, (unsigned)rec.bytes);
        if (rec.type == SW_REC_STEP) steps++;
        if (rec.type == SW_REC_END) {
            ended = 1;
            if (sw_rec_u32(rec.p) != steps)
                return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                    "END says %u steps, the recording holds %u (records lost)",
                                    (unsigned)sw_rec_u32(rec.p), (unsigned)steps);
        }
        count++;
    }
    if (at != r->size)
        return sw_error_set(err, SINEW_ERROR_CORRUPT,
                            "record %u (stream byte %zu): cut short (the file was truncated)",
                            (unsigned)count, at);
    if (!ended)
        return sw_error_set(
            err, SINEW_ERROR_CORRUPT,
            "no END record after %u steps: the recorder was not closed, or the file "
            "was cut",
            (unsigned)steps);
    r->steps = steps;
    return SINEW_OK;
}

sinew_result sw_recording_parse(const void *data, size_t n, sw_recording *out, sw_error *err) {
    sw_error_clear(err);
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!data && n) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "no data");
    sinew_result r = read_chunks(data, n, out, err);
    if (r == SINEW_OK) r = check_records(out, err);
    if (r != SINEW_OK) sw_recording_free(out);
    return r;
}

void sw_recording_free(sw_recording *r) {
    if (!r) return;
    free(r->stream);
    memset(r, 0, sizeof *r);
}
