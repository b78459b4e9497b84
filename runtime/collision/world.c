/* The collision world (sinew_world.h): its slots with generation ids, its own Embree
 * device (one thread: the default device would start a spinning TBB pool, STYLE.md §6)
 * whose errors go to the world's logger, and the public add, remove and move. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "alloc.h"
#include "collision_internal.h"
#include "def_read.h"
#include "dqs.h"
#include "log.h"

static uint32_t message_id(sinew_result code) {
    switch (code) {
    case SINEW_ERROR_OUT_OF_MEMORY:
        return SINEW_MSG_WORLD_OUT_OF_MEMORY;
    case SINEW_ERROR_DEGENERATE:
        return SINEW_MSG_WORLD_DEGENERATE;
    case SINEW_ERROR_CAPACITY:
        return SINEW_MSG_WORLD_CAPACITY;
    case SINEW_ERROR_UNSUPPORTED:
        return SINEW_MSG_WORLD_EMBREE;
    default:
        return SINEW_MSG_WORLD_INVALID_ARGUMENT;
    }
}

static sinew_result vfail(const sinew_logger *lg, sinew_result code, const char *fmt, va_list ap) {
    if (!lg || lg->max_level < SINEW_LOG_ERROR) return code;
    char text[640];
    vsnprintf(text, sizeof text, fmt, ap);
    sw_log(lg, SINEW_LOG_ERROR, message_id(code), "%s", text);
    return code;
}

sinew_result sw_world_fail(const sinew_world *w, sinew_result code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vfail(w ? &w->logger : NULL, code, fmt, ap);
    va_end(ap);
    return code;
}

static sinew_result logger_fail(const sinew_logger *lg, sinew_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static sinew_result logger_fail(const sinew_logger *lg, sinew_result code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vfail(lg, code, fmt, ap);
    va_end(ap);
    return code;
}

/* Embree's errors (from any of its calls on this world's device) as log messages. */
static void on_embree_error(void *user, enum RTCError code, const char *str) {
    const sinew_world *w = user;
    sw_log(&w->logger, SINEW_LOG_ERROR, SINEW_MSG_WORLD_EMBREE, "Embree error %d: %s", (int)code,
           str ? str : "");
}

/* The def with its defaults and checked; logs through its own logger. */
static sinew_result read_world_def(const sinew_world_def *def, sinew_world_def *d) {
    *d = sinew_world_def_default();
    if (def && sw_def_read(d, sizeof *d, def,
                           offsetof(sinew_world_def, max_colliders) + sizeof(uint32_t)) != SINEW_OK)
        return logger_fail(NULL, SINEW_ERROR_INVALID_ARGUMENT, "bad struct_size");
    if (d->max_colliders == 0) d->max_colliders = 256;
    const char *bad = d->max_colliders > SW_WORLD_MAX_COLLIDERS ? "max_colliders is above 65535"
                      : sw_allocator_check(&d->allocator) != SINEW_OK
                          ? "allocator.alloc and allocator.free must both be set or both be NULL"
                          : NULL;
    if (bad)
        return logger_fail(&d->logger, SINEW_ERROR_INVALID_ARGUMENT, "sinew_world_create: %s", bad);
    return SINEW_OK;
}

sinew_result sinew_world_create(const sinew_world_def *def, sinew_world **out) {
    if (!out) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_world_def d;
    sinew_result r = read_world_def(def, &d);
    if (r != SINEW_OK) return r;
    sinew_world *w = sw_alloc(&d.allocator, sizeof *w, SW_ALLOC_ALIGN);
    if (!w)
        return logger_fail(&d.logger, SINEW_ERROR_OUT_OF_MEMORY,
                           "sinew_world_create: no memory for the world");
    w->allocator = d.allocator;
    w->logger = d.logger;
    w->capacity = d.max_colliders;
    w->slots = sw_alloc(&w->allocator, sizeof(sw_collider *) * w->capacity, SW_ALLOC_ALIGN);
    w->generation = sw_alloc(&w->allocator, sizeof(uint16_t) * w->capacity, SW_ALLOC_ALIGN);
    if (!w->slots || !w->generation) {
        sinew_world_destroy(w);
        return logger_fail(&d.logger, SINEW_ERROR_OUT_OF_MEMORY,
                           "sinew_world_create: no memory for %u collider slots",
                           (unsigned)d.max_colliders);
    }
    w->device = rtcNewDevice("threads=1");
    if (!w->device) {
        int e = (int)rtcGetDeviceError(NULL);
        sinew_world_destroy(w);
        return logger_fail(&d.logger, SINEW_ERROR_UNSUPPORTED,
                           "sinew_world_create: Embree could not create a device (error %d)", e);
    }
    rtcSetDeviceErrorFunction(w->device, on_embree_error, w);
    *out = w;
    return SINEW_OK;
}

static void collider_free(sinew_world *w, sw_collider *c) {
    if (!c) return;
    if (c->shape == SINEW_SHAPE_HULL) sw_hull_release(w, c);
    if (c->shape == SINEW_SHAPE_MESH) sw_mesh_release(w, c);
    sw_free(&w->allocator, c);
}

void sinew_world_destroy(sinew_world *world) {
    if (!world) return;
    sinew_allocator a = world->allocator;
    if (world->slots)
        for (uint32_t i = 0; i < world->used; ++i)
            collider_free(world, world->slots[i]);
    if (world->device) rtcReleaseDevice(world->device);
    sw_free(&a, world->slots);
    sw_free(&a, world->generation);
    sw_free(&a, world);
}

/* R and t of a public transform: finite (NOT_FINITE) and a nonzero quaternion
 * (INVALID_ARGUMENT), normalised with a scale so that huge components do not overflow. */
static sinew_result read_placement(const sinew_world *w, const double *pos, const double *rot,
                                   const char *fn, double R[9], double t[3]) {
    double q[4], s = 0;
    for (int i = 0; i < 4; ++i)
        s = fmax(s, fabs(q[i] = rot[i]));
    for (int i = 0; i < 3; ++i)
        t[i] = pos[i];
    if (!isfinite(s) || !sw_v3_isfinite(t))
        return sw_world_fail(w, SINEW_ERROR_NOT_FINITE, "%s: the transform is not finite", fn);
    if (!(s > 0))
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: the transform's quaternion is zero", fn);
    double n = 0;
    for (int i = 0; i < 4; ++i)
        n += (q[i] / s) * (q[i] / s);
    n = s * sqrt(n);
    for (int i = 0; i < 4; ++i)
        q[i] /= n;
    sw_quat_to_matrix(q, R);
    return SINEW_OK;
}

/* The float transform's placement, in doubles. */
static void placement_of(const sinew_transform *tf, double pos[3], double rot[4]) {
    for (int i = 0; i < 3; ++i)
        pos[i] = tf->position[i];
    for (int i = 0; i < 4; ++i)
        rot[i] = tf->rotation[i];
}

static sinew_result read_transform(const sinew_world *w, const sinew_transform *tf, const char *fn,
                                   double R[9], double t[3]) {
    double pos[3], rot[4];
    placement_of(tf, pos, rot);
    return read_placement(w, pos, rot, fn, R, t);
}

/* The common fields of a def: shape, stiffness, friction. */
static sinew_result check_common(sinew_world *w, const sinew_collider_def *d) {
    const char *fn = "sinew_world_add_collider";
    if ((int)d->shape < SINEW_SHAPE_PLANE || (int)d->shape > SINEW_SHAPE_MESH)
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT, "%s: unknown shape %d", fn,
                             (int)d->shape);
    if (!isfinite(d->stiffness) || !isfinite(d->friction))
        return sw_world_fail(w, SINEW_ERROR_NOT_FINITE, "%s: stiffness or friction not finite", fn);
    if (d->stiffness < 0 || d->friction < 0 || d->stiffness > SW_COLLIDER_MAX_SIZE)
        return sw_world_fail(w, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: stiffness %g or friction %g is negative or absurd", fn,
                             (double)d->stiffness, (double)d->friction);
    return SINEW_OK;
}

/* The lowest free slot (< capacity), or -1. */
static int32_t free_slot(const sinew_world *w) {
    for (uint32_t i = 0; i < w->capacity; ++i)
        if (!w->slots[i]) return (int32_t)i;
    return -1;
}

static sinew_result build_shape(sinew_world *w, const sinew_collider_def *d, sw_collider *c) {
    if (d->shape == SINEW_SHAPE_HULL) return sw_hull_build(w, d, c);
    if (d->shape == SINEW_SHAPE_MESH) return sw_mesh_build(w, d, c);
    return sw_shapes_build(w, d, c);
}

sinew_result sinew_world_add_collider(sinew_world *world, const sinew_collider_def *def,
                                      sinew_collider_id *out) {
    const char *fn = "sinew_world_add_collider";
    if (!world || !def || !out)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT, "%s: NULL world, def or out", fn);
    sinew_collider_def d = sinew_collider_def_default();
    if (sw_def_read(&d, sizeof d, def, offsetof(sinew_collider_def, shape) + sizeof(sinew_shape)))
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT, "%s: bad struct_size %u", fn,
                             (unsigned)def->struct_size);
    double R[9], t[3];
    sinew_result r = check_common(world, &d);
    if (r == SINEW_OK) r = read_transform(world, &d.transform, fn, R, t);
    if (r != SINEW_OK) return r;
    int32_t slot = free_slot(world);
    if (slot < 0)
        return sw_world_fail(world, SINEW_ERROR_CAPACITY, "%s: the world's %u colliders are used",
                             fn, (unsigned)world->capacity);
    sw_collider *c = sw_alloc(&world->allocator, sizeof *c, SW_ALLOC_ALIGN);
    if (!c) return sw_world_fail(world, SINEW_ERROR_OUT_OF_MEMORY, "%s: no memory", fn);
    c->shape = d.shape;
    memcpy(c->R, R, sizeof R);
    memcpy(c->t, t, sizeof t);
    c->stiffness = d.stiffness;
    c->friction = d.friction;
    c->src = d;
    c->src.points = c->src.vertices = NULL;
    c->src.indices = NULL;
    placement_of(&d.transform, c->src_pos, c->src_rot);
    if ((r = build_shape(world, &d, c)) != SINEW_OK) {
        sw_free(&world->allocator, c);
        return r;
    }
    sw_collider_place(c, R, t); /* the world box needs the shape's local box */
    world->slots[slot] = c;
    world->live++;
    if ((uint32_t)slot >= world->used) world->used = (uint32_t)slot + 1;
    *out = sw_collider_id_of(world, (uint32_t)slot);
    return SINEW_OK;
}

sinew_result sinew_world_remove_collider(sinew_world *world, sinew_collider_id id) {
    int32_t s = world ? sw_world_slot_of(world, id) : -1;
    if (s < 0)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                             "sinew_world_remove_collider: id 0x%08x is not a live collider%s",
                             (unsigned)id, world ? "" : " (NULL world)");
    collider_free(world, world->slots[s]);
    world->slots[s] = NULL;
    world->generation[s]++; /* the old id is stale from now on */
    world->live--;
    while (world->used > 0 && !world->slots[world->used - 1])
        world->used--;
    return SINEW_OK;
}

sinew_result sinew_world_set_collider_transform(sinew_world *world, sinew_collider_id id,
                                                const sinew_transform *transform) {
    const char *fn = "sinew_world_set_collider_transform";
    int32_t s = world ? sw_world_slot_of(world, id) : -1;
    if (s < 0 || !transform)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: id 0x%08x is not a live collider or the transform is NULL", fn,
                             (unsigned)id);
    double R[9], t[3];
    sinew_result r = read_transform(world, transform, fn, R, t);
    if (r != SINEW_OK) return r; /* the old transform stays */
    sw_collider_place(world->slots[s], R, t);
    world->slots[s]->src.transform = *transform;
    placement_of(transform, world->slots[s]->src_pos, world->slots[s]->src_rot);
    return SINEW_OK;
}

sinew_result sinew_world_set_collider_transform_d(sinew_world *world, sinew_collider_id id,
                                                  const double position[3],
                                                  const double rotation[4]) {
    const char *fn = "sinew_world_set_collider_transform_d";
    int32_t s = world ? sw_world_slot_of(world, id) : -1;
    if (s < 0 || !position || !rotation)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: id 0x%08x is not a live collider or the placement is NULL", fn,
                             (unsigned)id);
    double R[9], t[3];
    sinew_result r = read_placement(world, position, rotation, fn, R, t);
    if (r != SINEW_OK) return r; /* the old transform stays */
    sw_collider *c = world->slots[s];
    sw_collider_place(c, R, t);
    for (int i = 0; i < 3; ++i)
        c->src.transform.position[i] = (float)(c->src_pos[i] = position[i]);
    for (int i = 0; i < 4; ++i)
        c->src.transform.rotation[i] = (float)(c->src_rot[i] = rotation[i]);
    return SINEW_OK;
}

sinew_result sinew_world_set_mesh_vertices(sinew_world *world, sinew_collider_id id,
                                           const float *xyz, uint32_t vertex_count) {
    const char *fn = "sinew_world_set_mesh_vertices";
    int32_t s = world ? sw_world_slot_of(world, id) : -1;
    if (s < 0 || !xyz)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: id 0x%08x is not a live collider or xyz is NULL", fn,
                             (unsigned)id);
    sw_collider *c = world->slots[s];
    if (c->shape != SINEW_SHAPE_MESH || vertex_count != c->mesh.nverts)
        return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                             "%s: collider 0x%08x is not a mesh of %u vertices (shape %d, %u)", fn,
                             (unsigned)id, (unsigned)vertex_count, (int)c->shape,
                             (unsigned)c->mesh.nverts);
    /* checked whole before anything changes: a refused move keeps the old vertices */
    for (size_t i = 0; i < (size_t)3 * vertex_count; ++i) {
        if (!isfinite(xyz[i]))
            return sw_world_fail(world, SINEW_ERROR_NOT_FINITE, "%s: vertex %zu is not finite", fn,
                                 i / 3);
        if (!(fabs(xyz[i]) <= SW_COLLIDER_MAX_SIZE))
            return sw_world_fail(world, SINEW_ERROR_INVALID_ARGUMENT,
                                 "%s: vertex %zu is beyond 1e15", fn, i / 3);
    }
    return sw_mesh_move(world, c, xyz);
}

uint32_t sinew_world_collider_count(const sinew_world *world) {
    return world ? world->live : 0;
}

uint32_t sw_world_capacity(const sinew_world *w) {
    return w ? w->capacity : 0;
}

uint32_t sw_world_slot_count(const sinew_world *w) {
    return w ? w->used : 0;
}

const sw_collider *sw_world_slot(const sinew_world *w, uint32_t slot) {
    return w && slot < w->used ? w->slots[slot] : NULL;
}

sinew_collider_id sw_collider_id_of(const sinew_world *w, uint32_t slot) {
    if (!w || slot >= w->capacity || !w->slots[slot]) return 0;
    return ((sinew_collider_id)w->generation[slot] << SW_ID_SLOT_BITS) | (slot + 1u);
}

int32_t sw_world_slot_of(const sinew_world *w, sinew_collider_id id) {
    uint32_t low = id & ((1u << SW_ID_SLOT_BITS) - 1u);
    if (!w || low == 0 || low > w->used) return -1;
    uint32_t s = low - 1;
    if (!w->slots[s] || w->generation[s] != (uint16_t)(id >> SW_ID_SLOT_BITS)) return -1;
    return (int32_t)s;
}
