/* Replaying a recording (recording.h) through the public functions, as the host called
 * them: a fresh instance with the recorded def, the world rebuilt slot by slot (so its
 * colliders are queried in the recorded order), and each step's surface hash compared. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "recording.h"
#include "sinew/sinew_world.h"

typedef struct replay {
    const sinew_blob *blob;
    const sinew_logger *logger;
    sinew_instance *inst;
    sinew_world *world;
    sinew_collider_id *ids; /* per recorded slot, 0: none */
    uint32_t nids;
    unsigned char *placed; /* per slot: a PLACE set it for the next STEP */
    sw_replay_report *rep;
} replay;

static sinew_result refuse(replay *rp, sinew_result r, const char *what, uint32_t record) {
    snprintf(rp->rep->msg, sizeof rp->rep->msg, "record %u: %s (%s)", (unsigned)record, what,
             sinew_result_string(r));
    return r;
}

static void drop_world(replay *rp) {
    if (rp->inst) {
        sinew_instance_set_world(rp->inst, NULL);
        sinew_instance_ignore_collider(rp->inst, 0); /* an IGNORE after WORLD says it again */
    }
    sinew_world_destroy(rp->world);
    free(rp->ids);
    free(rp->placed);
    rp->world = NULL;
    rp->ids = NULL;
    rp->placed = NULL;
    rp->nids = 0;
}

/* Collider c of a WORLD payload (at p) as its def; its arrays point into p, converted
 * where the floats are unaligned (pts: scratch of 3 np + 3 nv floats, tris 3 nt). */
static const unsigned char *collider_def(const unsigned char *p, sinew_collider_def *d,
                                         uint32_t *slot, float **pts, uint32_t **tris) {
    *d = sinew_collider_def_default();
    *slot = sw_rec_u32(p);
    d->shape = (sinew_shape)sw_rec_u32(p + 4);
    float f[18];
    for (int i = 0; i < 18; ++i)
        f[i] = sw_rec_f32(p + 8 + 4 * i);
    memcpy(d->normal, f, sizeof d->normal);
    d->offset = f[3];
    d->radius = f[4];
    d->half_height = f[5];
    memcpy(d->half_extents, f + 6, sizeof d->half_extents);
    d->stiffness = f[9];
    d->friction = f[10];
    memcpy(d->transform.position, f + 11, sizeof d->transform.position);
    memcpy(d->transform.rotation, f + 14, sizeof d->transform.rotation);
    d->point_count = sw_rec_u32(p + 80);
    d->vertex_count = sw_rec_u32(p + 84);
    d->triangle_count = sw_rec_u32(p + 88);
    size_t nf = 3 * ((size_t)d->point_count + d->vertex_count), nt = 3 * (size_t)d->triangle_count;
    *pts = malloc(nf * sizeof(float) + 1);
    *tris = malloc(nt * sizeof(uint32_t) + 1);
    if (!*pts || !*tris) return NULL;
    memcpy(*pts, p + SW_REC_COLLIDER_BYTES, nf * sizeof(float));
    memcpy(*tris, p + SW_REC_COLLIDER_BYTES + nf * sizeof(float), nt * sizeof(uint32_t));
    d->points = d->point_count ? *pts : NULL;
    d->vertices = d->vertex_count ? *pts : NULL;
    d->indices = d->triangle_count ? *tris : NULL;
    return p + SW_REC_COLLIDER_BYTES + 4 * (nf + nt);
}

/* A WORLD record: a new world of the recorded capacity, each collider in its recorded slot
 * (a free slot before it held by a placeholder until the others are added). */
static sinew_result replay_world(replay *rp, const sw_rec_record *rec, uint32_t k) {
    drop_world(rp);
    uint32_t cap = sw_rec_u32(rec->p), nc = sw_rec_u32(rec->p + 4);
    if (cap == 0) return SINEW_OK; /* detached */
    sinew_world_def wd = sinew_world_def_default();
    wd.max_colliders = cap;
    wd.logger = *rp->logger;
    sinew_result r = sinew_world_create(&wd, &rp->world);
    if (r != SINEW_OK) return refuse(rp, r, "the recorded world could not be created", k);
    rp->ids = calloc(cap, sizeof *rp->ids);
    rp->placed = calloc(cap, 1);
    unsigned char *hole = calloc(cap, 1);
    if (!rp->ids || !rp->placed || !hole) {
        free(hole);
        return refuse(rp, SINEW_ERROR_OUT_OF_MEMORY, "world", k);
    }
    rp->nids = cap;
    sinew_collider_def filler = sinew_collider_def_default();
    filler.shape = SINEW_SHAPE_SPHERE;
    filler.radius = 1;
    const unsigned char *p = rec->p + 8;
    uint32_t next = 0; /* the next slot the world fills */
    for (uint32_t i = 0; i < nc && r == SINEW_OK; ++i) {
        sinew_collider_def d;
        uint32_t slot;
        float *pts = NULL;
        uint32_t *tris = NULL;
        p = collider_def(p, &d, &slot, &pts, &tris);
        if (!p)
            r = SINEW_ERROR_OUT_OF_MEMORY;
        else if (slot >= cap || slot < next)
            r = SINEW_ERROR_CORRUPT;
        for (; r == SINEW_OK && next < slot; ++next) {
            hole[next] = 1;
            r = sinew_world_add_collider(rp->world, &filler, &rp->ids[next]);
        }
        if (r == SINEW_OK) r = sinew_world_add_collider(rp->world, &d, &rp->ids[next++]);
        free(pts);
        free(tris);
    }
    for (uint32_t s = 0; s < next; ++s)
        if (hole[s]) {
            sinew_world_remove_collider(rp->world, rp->ids[s]);
            rp->ids[s] = 0;
        }
    free(hole);
    if (r != SINEW_OK) return refuse(rp, r, "a recorded collider was refused", k);
    r = sinew_instance_set_world(rp->inst, rp->world);
    return r == SINEW_OK ? r : refuse(rp, r, "set_world refused the recorded world", k);
}

/* A STEP record: the colliders where the step saw them, the step, its hash compared. */
static sinew_result replay_step(replay *rp, const sw_rec_record *rec, uint32_t k) {
    float dt = sw_rec_f32(rec->p);
    uint32_t want_r = sw_rec_u32(rec->p + 4), nc = sw_rec_u32(rec->p + 12);
    uint64_t want = sw_rec_u64(rec->p + 16);
    for (uint32_t i = 0; i < nc; ++i) {
        const unsigned char *m = rec->p + SW_REC_STEP_BYTES + SW_REC_MOVE_BYTES * (size_t)i;
        uint32_t slot = sw_rec_u32(m);
        if (slot >= rp->nids || !rp->ids[slot])
            return refuse(rp, SINEW_ERROR_CORRUPT,
                          "a step moves a collider the recorded world does not hold (added "
                          "after the world was attached)",
                          k);
        if (rp->placed[slot]) { /* in doubles, by the PLACE before */
            rp->placed[slot] = 0;
            continue;
        }
        sinew_transform t;
        for (int j = 0; j < 3; ++j)
            t.position[j] = sw_rec_f32(m + 4 + 4 * j);
        for (int j = 0; j < 4; ++j)
            t.rotation[j] = sw_rec_f32(m + 16 + 4 * j);
        sinew_result r = sinew_world_set_collider_transform(rp->world, rp->ids[slot], &t);
        if (r != SINEW_OK) return refuse(rp, r, "a recorded collider transform was refused", k);
    }
    sinew_result r = sinew_instance_step(rp->inst, dt);
    uint64_t got = sw_instance_surface_hash(rp->inst);
    sw_replay_report *rep = rp->rep;
    if (got != want || (uint32_t)r != want_r) {
        if (rep->differing++ == 0) {
            rep->first_diff = rep->steps;
            rep->want = want;
            rep->got = got;
        }
    }
    rep->steps++;
    return SINEW_OK;
}

/* The replay world's id of a recorded slot (0 and a refusal when it holds none). */
static sinew_collider_id slot_id(replay *rp, uint32_t slot, uint32_t k) {
    if (slot < rp->nids && rp->ids[slot]) return rp->ids[slot];
    refuse(rp, SINEW_ERROR_CORRUPT,
           "a record names a collider the recorded world does not hold (added after the "
           "world was attached)",
           k);
    return 0;
}

/* A MESH record: the vertices the host gave the mesh before the next step. */
static sinew_result replay_mesh(replay *rp, const sw_rec_record *rec, uint32_t k) {
    sinew_collider_id id = slot_id(rp, sw_rec_u32(rec->p), k);
    if (!id) return SINEW_ERROR_CORRUPT;
    uint32_t nv = sw_rec_u32(rec->p + 4);
    float *xyz = malloc(12 * (size_t)nv + 1); /* the payload's floats may be unaligned */
    if (!xyz) return refuse(rp, SINEW_ERROR_OUT_OF_MEMORY, "mesh vertices", k);
    memcpy(xyz, rec->p + 8, 12 * (size_t)nv);
    sinew_result r = sinew_world_set_mesh_vertices(rp->world, id, xyz, nv);
    free(xyz);
    return r == SINEW_OK ? r : refuse(rp, r, "recorded mesh vertices were refused", k);
}

/* A PLACE record: the collider's placement in doubles, which the next STEP keeps. */
static sinew_result replay_place(replay *rp, const sw_rec_record *rec, uint32_t k) {
    uint32_t slot = sw_rec_u32(rec->p);
    sinew_collider_id id = slot_id(rp, slot, k);
    if (!id) return SINEW_ERROR_CORRUPT;
    double pos[3], rot[4];
    for (int j = 0; j < 3; ++j)
        pos[j] = sw_rec_f64(rec->p + 4 + 8 * j);
    for (int j = 0; j < 4; ++j)
        rot[j] = sw_rec_f64(rec->p + 28 + 8 * j);
    sinew_result r = sinew_world_set_collider_transform_d(rp->world, id, pos, rot);
    if (r != SINEW_OK) return refuse(rp, r, "a recorded placement was refused", k);
    rp->placed[slot] = 1;
    return SINEW_OK;
}

/* An IGNORE record: the collider in that slot of the replay's world, or none. */
static sinew_result replay_ignore(replay *rp, const sw_rec_record *rec, uint32_t k) {
    uint32_t slot = sw_rec_u32(rec->p);
    sinew_collider_id id = slot == SW_REC_NO_SLOT ? 0 : slot_id(rp, slot, k);
    if (slot != SW_REC_NO_SLOT && !id) return SINEW_ERROR_CORRUPT;
    sinew_result r = sinew_instance_ignore_collider(rp->inst, id);
    return r == SINEW_OK ? r : refuse(rp, r, "a recorded ignore_collider was refused", k);
}

/* The instance of BEGIN's def. */
static sinew_result replay_begin(replay *rp, const sw_recording *rec, const sw_rec_record *b) {
    uint64_t h = sinew_hash_bytes(rp->blob->data, rp->blob->size);
    if (h != rec->blob_hash || rp->blob->size != rec->blob_bytes) {
        snprintf(rp->rep->msg, sizeof rp->rep->msg,
                 "the recording was made with another blob (its hash %016llx, %llu bytes; "
                 "this blob's %016llx, %zu bytes)",
                 (unsigned long long)rec->blob_hash, (unsigned long long)rec->blob_bytes,
                 (unsigned long long)h, rp->blob->size);
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    if (sinew_blob_bone_count(rp->blob) != rec->bones ||
        sinew_blob_surface_vertex_count(rp->blob) != rec->surface)
        return refuse(rp, SINEW_ERROR_INVALID_ARGUMENT,
                      "the recording is of another blob (bone or surface vertex counts differ)", 0);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = (sinew_step_mode)sw_rec_u32(b->p + 24);
    d.max_newton_iters = sw_rec_u32(b->p + 28);
    d.max_contact_pairs = sw_rec_u32(b->p + 32);
    d.max_world_contacts = sw_rec_u32(b->p + 36);
    d.max_patch_vertices = sw_rec_u32(b->p + 40);
    d.patch_radius = sw_rec_f32(b->p + 44);
    d.self_contact = (sinew_self_contact)sw_rec_u32(b->p + 48);
    d.newton_hessian = (sinew_newton_hessian)sw_rec_u32(b->p + 52);
    d.logger = *rp->logger;
    sinew_result r = sinew_instance_create(rp->blob, &d, &rp->inst);
    return r == SINEW_OK ? r : refuse(rp, r, "the recorded instance def was refused", 0);
}

/* One record after BEGIN. */
static sinew_result replay_record(replay *rp, const sw_rec_record *rec, uint32_t k) {
    sinew_result r = SINEW_OK;
    switch ((sw_rec_type)rec->type) {
    case SW_REC_WORLD:
        return replay_world(rp, rec, k);
    case SW_REC_STEP:
        return replay_step(rp, rec, k);
    case SW_REC_MESH:
        return replay_mesh(rp, rec, k);
    case SW_REC_IGNORE:
        return replay_ignore(rp, rec, k);
    case SW_REC_PLACE:
        return replay_place(rp, rec, k);
    case SW_REC_LOD:
        r = sinew_instance_set_lod(rp->inst, (sinew_lod)sw_rec_u32(rec->p));
        if (r != SINEW_OK) return refuse(rp, r, "a recorded set_lod was refused", k);
        break;
    case SW_REC_ACTOR: {
        double T[12];
        for (int i = 0; i < 12; ++i)
            T[i] = sw_rec_f64(rec->p + 8 * i);
        r = sinew_instance_set_actor(rp->inst, T);
        break;
    }
    case SW_REC_POSE: {
        uint32_t n = sw_rec_u32(rec->p);
        float *T = malloc(48 * (size_t)n + 1);
        if (!T) return refuse(rp, SINEW_ERROR_OUT_OF_MEMORY, "pose", k);
        memcpy(T, rec->p + 4, 48 * (size_t)n);
        r = sinew_instance_set_pose(rp->inst, T, n);
        free(T);
        break;
    }
    case SW_REC_TELEPORT:
        r = sinew_instance_mark_teleport(rp->inst);
        break;
    case SW_REC_RESET:
        r = sinew_instance_reset(rp->inst);
        break;
    case SW_REC_BEGIN:
    case SW_REC_END:
        break;
    }
    return r == SINEW_OK ? r : refuse(rp, r, "a recorded call was refused on replay", k);
}

sinew_result sw_recording_replay(const sinew_blob *blob, const sw_recording *rec,
                                 const sinew_logger *logger, float *surface,
                                 sw_replay_report *rep) {
    memset(rep, 0, sizeof *rep);
    rep->first_diff = -1;
    sinew_logger quiet = sinew_logger_default();
    replay rp = {blob, logger ? logger : &quiet, NULL, NULL, NULL, 0, NULL, rep};
    if (!blob || !rec || !rec->stream) return SINEW_ERROR_INVALID_ARGUMENT;
    size_t pos = 0;
    sw_rec_record r0;
    if (!sw_recording_next(rec, &pos, &r0) || r0.type != SW_REC_BEGIN)
        return refuse(&rp, SINEW_ERROR_CORRUPT, "no BEGIN record", 0);
    sinew_result r = replay_begin(&rp, rec, &r0);
    sw_rec_record one;
    for (uint32_t k = 1; r == SINEW_OK && sw_recording_next(rec, &pos, &one); ++k)
        r = replay_record(&rp, &one, k);
    if (r == SINEW_OK && surface)
        r = sinew_instance_read_surface(rp.inst, surface, NULL, rec->surface);
    drop_world(&rp);
    sinew_instance_destroy(rp.inst);
    return r;
}
