/* The recorder (sinew.h, format in recording.h): the calls an instance receives, appended
 * to a buffer the recorder owns and written to its file one checksummed chunk at a time.
 * A recorded call only copies its arguments into the buffer, so a step allocates and
 * locks nothing; the one I/O a step can do is the write(2) of a buffer it filled.
 *
 * The host moves a mesh collider's vertices through the world, not the instance, so no
 * hook sees it: the step compares each mesh's move count with the one this recorder last
 * wrote and writes the vertices of those that moved. The counts it saw are the
 * recorder's own (sized when a world is recorded, outside the step), never a flag in the
 * world: instances on other threads may step with the same world and record it too. */
#include <fcntl.h>
#include <stddef.h>
#include <string.h>
#include <unistd.h>

#include "alloc.h"
#include "blob_load.h"
#include "collision.h"
#include "def_read.h"
#include "hash.h"
#include "instance_internal.h"
#include "log.h"
#include "recording.h"

#define SW_REC_DEFAULT_BUFFER (1u << 20)
#define SW_REC_MIN_BUFFER (1u << 16)

struct sinew_recorder {
    int fd;
    sinew_allocator allocator;
    sinew_logger logger;
    unsigned char *buf; /* SW_REC_CHUNK_BYTES of chunk header, then the payload */
    size_t cap, used;   /* payload bytes the buffer holds, and holds now */
    sinew_result err;   /* the first I/O failure (SINEW_OK: none) */
    sinew_instance *inst;
    uint32_t steps;
    uint32_t *moves; /* per world slot: its mesh's move count as last written */
    uint32_t nmoves;
};

static sinew_result io_fail(sinew_recorder *rec, const char *what) {
    if (rec->err == SINEW_OK)
        sw_log(&rec->logger, SINEW_LOG_ERROR, SINEW_MSG_RECORDER_IO, "sinew_recorder: %s failed",
               what);
    rec->err = SINEW_ERROR_IO;
    return rec->err;
}

/* All n bytes of p to the file (write(2) may write fewer). */
static sinew_result write_all(sinew_recorder *rec, const unsigned char *p, size_t n) {
    while (n > 0 && rec->err == SINEW_OK) {
        ssize_t w = write(rec->fd, p, n);
        if (w <= 0) return io_fail(rec, "write");
        p += w;
        n -= (size_t)w;
    }
    return rec->err;
}

/* The buffered payload as one chunk: tag, size, FNV-1a 64, payload. */
static sinew_result flush_chunk(sinew_recorder *rec) {
    if (rec->used == 0 || rec->err != SINEW_OK) return rec->err;
    uint32_t head[2] = {SW_REC_CHUNK_TAG, (uint32_t)rec->used};
    uint64_t h = sw_fnv1a(SW_FNV_START, rec->buf + SW_REC_CHUNK_BYTES, rec->used);
    memcpy(rec->buf, head, sizeof head);
    memcpy(rec->buf + sizeof head, &h, sizeof h);
    sinew_result r = write_all(rec, rec->buf, SW_REC_CHUNK_BYTES + rec->used);
    rec->used = 0;
    return r;
}

/* Appends n bytes of the record stream, flushing full buffers. */
static void put(sinew_recorder *rec, const void *data, size_t n) {
    const unsigned char *p = data;
    while (n > 0 && rec->err == SINEW_OK) {
        size_t k = rec->cap - rec->used < n ? rec->cap - rec->used : n;
        memcpy(rec->buf + SW_REC_CHUNK_BYTES + rec->used, p, k);
        rec->used += k;
        p += k;
        n -= k;
        if (rec->used == rec->cap) flush_chunk(rec);
    }
}

static void put_u32(sinew_recorder *rec, uint32_t x) {
    put(rec, &x, sizeof x);
}

static void put_f32(sinew_recorder *rec, float x) {
    put(rec, &x, sizeof x);
}

static void put_header(sinew_recorder *rec, sw_rec_type type, size_t bytes) {
    put_u32(rec, (uint32_t)type);
    put_u32(rec, (uint32_t)bytes);
}

SINEW_API sinew_result sinew_recorder_open(const sinew_recorder_def *def, sinew_recorder **out) {
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    sinew_recorder_def d = sinew_recorder_def_default();
    if (sw_def_read(&d, sizeof d, def, offsetof(sinew_recorder_def, path) + sizeof d.path) ||
        !d.path)
        return SINEW_ERROR_INVALID_ARGUMENT;
    size_t cap = d.buffer_bytes ? d.buffer_bytes : SW_REC_DEFAULT_BUFFER;
    if (cap < SW_REC_MIN_BUFFER) cap = SW_REC_MIN_BUFFER;
    sinew_recorder *rec = sw_alloc(&d.allocator, sizeof *rec, SW_ALLOC_ALIGN);
    unsigned char *buf = rec ? sw_alloc(&d.allocator, SW_REC_CHUNK_BYTES + cap, 64) : NULL;
    if (!buf) {
        sw_free(&d.allocator, rec);
        return SINEW_ERROR_OUT_OF_MEMORY;
    }
    *rec = (sinew_recorder){-1, d.allocator, d.logger, buf, cap, 0, SINEW_OK, NULL, 0, NULL, 0};
    rec->fd = open(d.path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (rec->fd < 0) {
        sw_log(&d.logger, SINEW_LOG_ERROR, SINEW_MSG_RECORDER_IO,
               "sinew_recorder_open: cannot create %s", d.path);
        sw_free(&d.allocator, buf);
        sw_free(&d.allocator, rec);
        return SINEW_ERROR_IO;
    }
    unsigned char pre[SW_REC_PREAMBLE_BYTES] = {'S', 'I', 'N', 'E', 'W', 'R', 'E', 'C'};
    const uint32_t tail[2] = {SW_REC_VERSION, 0x01020304u}; /* the host's byte order */
    memcpy(pre + 8, tail, sizeof tail);
    if (write_all(rec, pre, sizeof pre) != SINEW_OK) {
        close(rec->fd);
        sw_free(&d.allocator, buf);
        sw_free(&d.allocator, rec);
        return SINEW_ERROR_IO;
    }
    *out = rec;
    return SINEW_OK;
}

SINEW_API sinew_result sinew_recorder_flush(sinew_recorder *rec) {
    if (!rec) return SINEW_ERROR_INVALID_ARGUMENT;
    return flush_chunk(rec);
}

SINEW_API sinew_result sinew_recorder_close(sinew_recorder *rec) {
    if (!rec) return SINEW_OK;
    if (rec->inst) sinew_instance_set_recorder(rec->inst, NULL);
    put_header(rec, SW_REC_END, 4);
    put_u32(rec, rec->steps);
    flush_chunk(rec);
    if (close(rec->fd) != 0 && rec->err == SINEW_OK) io_fail(rec, "close");
    sinew_result r = rec->err;
    sinew_allocator a = rec->allocator;
    sw_free(&a, rec->buf);
    sw_free(&a, rec->moves);
    sw_free(&a, rec);
    return r;
}

/* BEGIN: the blob and the def the replay creates its instance from. */
static void put_begin(sinew_recorder *rec, const sinew_instance *in, const sinew_blob *blob) {
    const sinew_instance_def *d = &in->def;
    uint64_t head[2] = {sinew_hash_bytes(blob->data, blob->size), blob->size};
    put_header(rec, SW_REC_BEGIN, SW_REC_BEGIN_BYTES);
    put(rec, head, sizeof head);
    put_u32(rec, (uint32_t)in->v->nbones);
    put_u32(rec, (uint32_t)sw_blob_output_verts(in->v));
    const uint32_t u[5] = {(uint32_t)d->mode, d->max_newton_iters, d->max_contact_pairs,
                           d->max_world_contacts, d->max_patch_vertices};
    put(rec, u, sizeof u);
    put_f32(rec, d->patch_radius);
    put_u32(rec, (uint32_t)d->self_contact);
    put_u32(rec, (uint32_t)d->newton_hessian);
}

SINEW_API sinew_result sinew_instance_set_recorder(sinew_instance *inst, sinew_recorder *rec) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    if (!rec) {
        if (inst->rec) inst->rec->inst = NULL;
        inst->rec = NULL;
        return SINEW_OK;
    }
    if (inst->touched || inst->rec || rec->inst) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_RECORDER_REFUSED,
               "sinew_instance_set_recorder: %s",
               inst->touched ? "attach a recorder before the instance is posed, placed or "
                               "stepped (right after sinew_instance_create)"
                             : "the instance or the recorder is already attached");
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    inst->rec = rec;
    rec->inst = inst;
    put_begin(rec, inst, inst->blob);
    if (inst->wc.world) sw_rec_world(inst);
    return rec->err;
}

/* A collider's record (SW_REC_COLLIDER_BYTES and its arrays), and the arrays' bytes. */
static size_t collider_bytes(const sw_collider *c) {
    uint32_t np, nt;
    (void)sw_collider_points(c, &np);
    (void)sw_collider_triangles(c, &nt);
    return SW_REC_COLLIDER_BYTES + 12 * (size_t)np + 12 * (size_t)nt;
}

static void put_collider(sinew_recorder *rec, uint32_t slot, const sw_collider *c) {
    sinew_collider_def d;
    sw_collider_source(c, &d);
    uint32_t np, nt;
    const double *X = sw_collider_points(c, &np);
    const uint32_t *T = sw_collider_triangles(c, &nt);
    put_u32(rec, slot);
    put_u32(rec, (uint32_t)d.shape);
    put(rec, d.normal, sizeof d.normal);
    const float f[3] = {d.offset, d.radius, d.half_height};
    put(rec, f, sizeof f);
    put(rec, d.half_extents, sizeof d.half_extents);
    put_f32(rec, d.stiffness);
    put_f32(rec, d.friction);
    put(rec, &d.transform, sizeof d.transform);
    put_u32(rec, d.shape == SINEW_SHAPE_HULL ? np : 0);
    put_u32(rec, d.shape == SINEW_SHAPE_MESH ? np : 0);
    put_u32(rec, nt);
    for (uint32_t i = 0; i < 3 * np; ++i)
        put_f32(rec, (float)X[i]); /* the def's floats, held exactly */
    put(rec, T, 12 * (size_t)nt);
}

/* The move counts of the world's meshes as a WORLD record writes their vertices: room
 * for every slot the world can have, so no step needs more. */
static void note_moves(sinew_recorder *rec, const sinew_world *w) {
    uint32_t cap = w ? sw_world_capacity(w) : 0;
    if (cap > rec->nmoves) {
        sw_free(&rec->allocator, rec->moves);
        rec->nmoves = 0;
        rec->moves = sw_alloc(&rec->allocator, sizeof(uint32_t) * cap, SW_ALLOC_ALIGN);
        if (!rec->moves) {
            if (rec->err == SINEW_OK)
                sw_log(&rec->logger, SINEW_LOG_ERROR, SINEW_MSG_RECORDER_IO,
                       "sinew_recorder: no memory for the move counts of %u colliders",
                       (unsigned)cap);
            rec->err = SINEW_ERROR_OUT_OF_MEMORY;
            return;
        }
        rec->nmoves = cap;
    }
    uint32_t ns = sw_world_slot_count(w);
    for (uint32_t s = 0; s < rec->nmoves; ++s) {
        const sw_collider *c = s < ns ? sw_world_slot(w, s) : NULL;
        rec->moves[s] = c ? sw_collider_vertex_moves(c) : 0;
    }
}

void sw_rec_world(sinew_instance *in) {
    sinew_recorder *rec = in->rec;
    if (!rec) return;
    const sinew_world *w = in->wc.world;
    note_moves(rec, w);
    uint32_t ns = sw_world_slot_count(w), live = 0;
    size_t bytes = 8;
    for (uint32_t s = 0; s < ns; ++s)
        if (sw_world_slot(w, s)) {
            live++;
            bytes += collider_bytes(sw_world_slot(w, s));
        }
    put_header(rec, SW_REC_WORLD, bytes);
    put_u32(rec, w ? sw_world_capacity(w) : 0);
    put_u32(rec, live);
    for (uint32_t s = 0; s < ns; ++s)
        if (sw_world_slot(w, s)) put_collider(rec, s, sw_world_slot(w, s));
    /* the replay's new world starts ignoring nothing; the id the instance keeps may name
       a collider of this world too */
    if (w && in->wc.ignore) sw_rec_ignore(in);
}

void sw_rec_ignore(sinew_instance *in) {
    sinew_recorder *rec = in->rec;
    if (!rec || !in->wc.world) return; /* without a world, the next WORLD record says it */
    int32_t s = in->wc.ignore ? sw_world_slot_of(in->wc.world, in->wc.ignore) : -1;
    put_header(rec, SW_REC_IGNORE, 4);
    put_u32(rec, s < 0 ? SW_REC_NO_SLOT : (uint32_t)s);
}

void sw_rec_lod(sinew_instance *in) {
    sinew_recorder *rec = in->rec;
    if (!rec) return;
    put_header(rec, SW_REC_LOD, 4);
    put_u32(rec, (uint32_t)in->lod);
}

/* A MESH record for each mesh moved since the recorder last wrote its vertices. */
static void put_moved_meshes(sinew_recorder *rec, const sinew_world *w) {
    uint32_t ns = sw_world_slot_count(w);
    for (uint32_t s = 0; s < ns && s < rec->nmoves; ++s) {
        const sw_collider *c = sw_world_slot(w, s);
        if (!c || sw_collider_vertex_moves(c) == rec->moves[s]) continue;
        uint32_t nv;
        const double *X = sw_collider_points(c, &nv);
        put_header(rec, SW_REC_MESH, 8 + 12 * (size_t)nv);
        put_u32(rec, s);
        put_u32(rec, nv);
        for (uint32_t i = 0; i < 3 * nv; ++i)
            put_f32(rec, (float)X[i]); /* the host's floats, held exactly */
        rec->moves[s] = sw_collider_vertex_moves(c);
    }
}

/* A PLACE record for each live collider placed in doubles that its float transform does
 * not hold exactly (the STEP's floats would lose it). */
static void put_placements(sinew_recorder *rec, const sinew_world *w) {
    uint32_t ns = sw_world_slot_count(w);
    for (uint32_t s = 0; s < ns; ++s) {
        const sw_collider *c = sw_world_slot(w, s);
        if (!c) continue;
        double pos[3], rot[4];
        sw_collider_placement(c, pos, rot);
        int exact = 1;
        for (int i = 0; i < 3; ++i)
            exact &= pos[i] == (double)(float)pos[i];
        for (int i = 0; i < 4; ++i)
            exact &= rot[i] == (double)(float)rot[i];
        if (exact) continue;
        put_header(rec, SW_REC_PLACE, SW_REC_PLACE_BYTES);
        put_u32(rec, s);
        put(rec, pos, sizeof pos);
        put(rec, rot, sizeof rot);
    }
}

void sw_rec_actor(sinew_instance *in, const double transform[12]) {
    if (!in->rec) return;
    put_header(in->rec, SW_REC_ACTOR, 12 * sizeof(double));
    put(in->rec, transform, 12 * sizeof(double));
}

void sw_rec_pose(sinew_instance *in, const float *transforms) {
    if (!in->rec) return;
    size_t n = 12 * (size_t)in->v->nbones * sizeof(float);
    put_header(in->rec, SW_REC_POSE, 4 + n);
    put_u32(in->rec, (uint32_t)in->v->nbones);
    put(in->rec, transforms, n);
}

void sw_rec_mark(sinew_instance *in, sw_rec_type type) {
    if (in->rec) put_header(in->rec, type, 0);
}

void sw_rec_step(sinew_instance *in, float dt, sinew_result r) {
    sinew_recorder *rec = in->rec;
    if (!rec) return;
    const sinew_world *w = in->wc.world;
    uint32_t ns = sw_world_slot_count(w), live = 0;
    for (uint32_t s = 0; s < ns; ++s)
        live += sw_world_slot(w, s) != NULL;
    put_moved_meshes(rec, w); /* the step saw them: nothing moves them during it */
    put_placements(rec, w);
    put_header(rec, SW_REC_STEP, SW_REC_STEP_BYTES + (size_t)live * SW_REC_MOVE_BYTES);
    put_f32(rec, dt);
    put_u32(rec, (uint32_t)r);
    put_u32(rec, in->stats.status);
    put_u32(rec, live);
    uint64_t h = sw_instance_surface_hash(in);
    put(rec, &h, sizeof h);
    for (uint32_t s = 0; s < ns; ++s) {
        const sw_collider *c = sw_world_slot(w, s);
        if (!c) continue;
        sinew_collider_def d;
        sw_collider_source(c, &d);
        put_u32(rec, s);
        put(rec, &d.transform, sizeof d.transform);
    }
    rec->steps++;
}
