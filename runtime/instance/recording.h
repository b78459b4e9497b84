/* A recording of the calls one instance received (sinew_recorder, sinew.h): its format,
 * the recorder's hooks the public functions call, and the reader and replayer that
 * sinew-replay and the tests use.
 *
 * The file, in the host's byte order (the preamble says which):
 *   preamble  "SINEWREC", u32 format version (SW_REC_VERSION), u32 0x01020304
 *   chunks    u32 'SWCK', u32 payload bytes n, u64 FNV-1a 64 of the payload, n bytes
 * The chunks' payloads, concatenated, are the records: u32 type, u32 payload bytes, the
 * payload (a record may straddle two chunks: the recorder flushes a full buffer as one
 * chunk wherever it is). The first record is BEGIN, the last END; a file without END was
 * not closed (or was cut) and is refused. Payloads (f32/f64/u32/u64 as named):
 *   BEGIN     u64 blob hash (sinew_hash_bytes of its bytes), u64 blob bytes, u32 bones,
 *             u32 surface vertices, the def: u32 mode, max_newton_iters, max_contact_pairs,
 *             max_world_contacts, max_patch_vertices, f32 patch_radius, u32 self_contact,
 *             newton_hessian
 *   WORLD     u32 capacity (0: detached), u32 colliders, each SW_REC_COLLIDER_BYTES: u32
 *             slot, shape, f32 normal[3], offset, radius, half_height, half_extents[3],
 *             stiffness, friction, position[3], rotation[4], u32 points, vertices,
 *             triangles; then f32 3 points, f32 3 vertices, u32 3 triangles
 *   ACTOR     f64 transform[12]
 *   POSE      u32 bones, f32 12 a bone
 *   TELEPORT, RESET   nothing
 *   STEP      f32 dt, u32 result, u32 status, u32 colliders, u64 surface hash
 *             (sw_instance_surface_hash after the step), then per collider u32 slot,
 *             f32 position[3], rotation[4] (the transforms the step saw)
 *   END       u32 steps
 * Version 2 adds two records (a version-1 file has neither, and replays as before):
 *   MESH      u32 slot, u32 vertices, f32 3 a vertex: a mesh collider's vertices as the
 *             next step saw them, written just before that STEP for each mesh that
 *             sinew_world_set_mesh_vertices moved since the recorder last wrote it (in a
 *             WORLD or a MESH record). A record of its own rather than a part of STEP:
 *             STEP keeps its fixed layout (and the version-1 reader of it), a mesh that
 *             did not move costs nothing, and each record's size says its vertex count.
 *   IGNORE    u32 slot in the last WORLD record, or SW_REC_NO_SLOT (ignores nothing):
 *             sinew_instance_ignore_collider, written at the call when a world is
 *             attached and after every WORLD record while an id is ignored (replay
 *             clears the ignored collider when it rebuilds a world).
 *   PLACE     u32 slot, f64 position[3], rotation[4]: a collider's placement in doubles
 *             (sinew_world_set_collider_transform_d) as the next step saw it, written
 *             just before that STEP for each collider whose placement is not its float
 *             transform's; replay takes it instead of that STEP's floats.
 * Version 3 adds one (a version-1 or -2 file has none, and replays as before):
 *   LOD       u32 level: sinew_instance_set_lod, written at the call. */
#ifndef SW_RECORDING_H
#define SW_RECORDING_H

#include <stddef.h>
#include <stdint.h>

#include "sinew/sinew.h"
#include "sw_error.h"

#define SW_REC_VERSION 3u /* also reads 2 (no LOD) and 1 (no MESH, no IGNORE, no PLACE) */
#define SW_REC_OLDEST_VERSION 1u
#define SW_REC_PREAMBLE_BYTES 16u
#define SW_REC_CHUNK_BYTES 16u
#define SW_REC_CHUNK_TAG 0x4b435753u /* "SWCK" */
#define SW_REC_HEADER_BYTES 8u       /* a record's type and size */
#define SW_REC_BEGIN_BYTES 56u
#define SW_REC_COLLIDER_BYTES 92u
#define SW_REC_STEP_BYTES 24u
#define SW_REC_MOVE_BYTES 32u  /* a collider's slot and transform in a STEP */
#define SW_REC_PLACE_BYTES 60u /* a collider's slot and placement in doubles */
#define SW_REC_NO_SLOT 0xffffffffu

typedef enum sw_rec_type {
    SW_REC_BEGIN = 1,
    SW_REC_WORLD = 2,
    SW_REC_ACTOR = 3,
    SW_REC_POSE = 4,
    SW_REC_TELEPORT = 5,
    SW_REC_RESET = 6,
    SW_REC_STEP = 7,
    SW_REC_END = 8,
    SW_REC_MESH = 9,    /* version 2 */
    SW_REC_IGNORE = 10, /* version 2 */
    SW_REC_PLACE = 11,  /* version 2 */
    SW_REC_LOD = 12     /* version 3 */
} sw_rec_type;

/* The recorder's hooks: each appends its call's record when a recorder is attached (one
 * test otherwise). Called by the public functions after the call succeeded. */
void sw_rec_actor(sinew_instance *in, const double transform[12]);
void sw_rec_pose(sinew_instance *in, const float *transforms);
void sw_rec_mark(sinew_instance *in, sw_rec_type type); /* TELEPORT, RESET */
void sw_rec_world(sinew_instance *in);
void sw_rec_step(sinew_instance *in, float dt, sinew_result r); /* and its MESH records */
void sw_rec_ignore(sinew_instance *in); /* the instance's ignored collider as it is now */
void sw_rec_lod(sinew_instance *in);    /* the level the host set */

/* FNV-1a 64 of the output surface's positions and normals as the step left them (the
 * simulation frame's doubles the host's floats come from). O(surface). */
uint64_t sw_instance_surface_hash(const sinew_instance *in);

/* A parsed recording: its records' bytes, every chunk checked. */
typedef struct sw_recording {
    unsigned char *stream; /* the records (owned; sw_recording_free) */
    size_t size;
    uint32_t version, steps;
    uint32_t bones, surface; /* BEGIN's */
    uint64_t blob_hash, blob_bytes;
} sw_recording;

/* One record: its type, payload and size. */
typedef struct sw_rec_record {
    uint32_t type, bytes;
    const unsigned char *p;
} sw_rec_record;

/* Parses and validates n bytes of a recording into *out: the preamble, every chunk's
 * size and checksum, every record's type and size against its contents, BEGIN first and
 * END last. Anything else is SINEW_ERROR_CORRUPT (or _VERSION) with err's message naming
 * the byte and what is wrong, never a crash. Allocates the stream (malloc). */
sinew_result sw_recording_parse(const void *data, size_t n, sw_recording *out, sw_error *err);
void sw_recording_free(sw_recording *r);

/* The record at *pos of a parsed recording, advancing *pos; 0 at the end. */
int sw_recording_next(const sw_recording *r, size_t *pos, sw_rec_record *rec);

/* Little readers of a validated payload (unaligned, host order). */
uint32_t sw_rec_u32(const unsigned char *p);
uint64_t sw_rec_u64(const unsigned char *p);
float sw_rec_f32(const unsigned char *p);
double sw_rec_f64(const unsigned char *p);

/* What a replay found. */
typedef struct sw_replay_report {
    uint32_t steps;     /* STEP records replayed */
    uint32_t differing; /* steps whose surface hash or result differed */
    int64_t first_diff; /* the first such step (0-based), -1: none */
    uint64_t want, got; /* its recorded and replayed hashes */
    char msg[256];      /* why a replay failed (an error return) */
} sw_replay_report;

/* Replays a parsed recording against `blob` (whose hash must be the recording's): a new
 * instance with the recorded def, a world rebuilt from its WORLD records, every call in
 * order, each step's result and surface hash compared with the recorded ones. With
 * surface not NULL, the last step's surface positions (3 floats a vertex, as
 * sinew_instance_read_surface) go there. SINEW_OK when the calls replayed (rep->differing
 * says whether bitwise); an error with rep->msg when the recording does not fit the blob or
 * a call the recording made was refused. */
sinew_result sw_recording_replay(const sinew_blob *blob, const sw_recording *rec,
                                 const sinew_logger *logger, float *surface, sw_replay_report *rep);

#endif
