/* The collision world's private layout: the world (slots with generations, its own
 * Embree device) and one collider (transform, local bounds, the shape's data). Shared by
 * world.c, collider.c, shapes.c, hull.c and mesh.c only. */
#ifndef SW_COLLISION_INTERNAL_H
#define SW_COLLISION_INTERNAL_H

#include <stdint.h>

#include <embree3/rtcore.h>

#include "collision.h"
#include "vec3.h"

/* Largest sizes a collider may have: bigger is a unit mistake, not a real collider. */
#define SW_COLLIDER_MAX_SIZE 1e15
#define SW_HULL_MAX_POINTS 4096u
#define SW_MESH_MAX_TRIANGLES (1u << 24)
#define SW_MESH_MAX_VERTICES (3u << 24)

/* An id is (generation << SW_ID_SLOT_BITS) | (slot + 1): never 0, and a removed
 * collider's id stays invalid until its slot has been reused 2^16 times. */
#define SW_ID_SLOT_BITS 16u
#define SW_WORLD_MAX_COLLIDERS ((1u << SW_ID_SLOT_BITS) - 1u)

typedef struct sw_hull {
    double *points; /* 3 * count, the collider's frame */
    uint32_t count;
    double center[3]; /* mean of the points: strictly inside (they are not coplanar) */
    double axes[9];   /* rows: the points' principal directions (MPR's extra rays) */
    double tolerance; /* MPR's portal tolerance, relative to the hull's size */
} sw_hull;

typedef struct sw_mesh {
    double *X;      /* 3 * nverts */
    uint32_t *tris; /* 3 * ntris */
    uint32_t nverts, ntris;
    double *face_n; /* 3 * ntris unit face normals */
    double *edge_n; /* 9 * ntris: triangle t's edge e (from corner e to e+1) pseudonormal */
    double *vert_n; /* 3 * nverts angle-weighted vertex pseudonormals (unit) */
    uint32_t *twin; /* 3 * ntris: the other use 3 t' + e' of triangle t's edge e, or
                       UINT32_MAX on a boundary (the edge map, kept for moves) */
    uint8_t *dead;  /* ntris: zero area at the current vertices (only after a move):
                       skipped by queries, zero in the pseudonormals */
    uint32_t ndead;
    double diagonal;  /* of the local box: the radius that reaches every triangle */
    RTCScene scene;   /* committed at add time and at each move, only read by queries */
    RTCGeometry geom; /* its one geometry (retained) and that geometry's vertex buffer */
    float *vb;
    int refits;     /* the geometry refits its BVH: set at its first move */
    uint32_t moves; /* sinew_world_set_mesh_vertices calls that changed X: a recorder
                       compares it with the count it last wrote (read-only in a step) */
} sw_mesh;

struct sw_collider {
    sinew_shape shape;
    double R[9], t[3];   /* world = R local + t */
    double lo[3], hi[3]; /* local box of the solid (plane: +-HUGE_VAL where unbounded) */
    double box[6];       /* world box of the solid (lo, hi) at R, t: sw_collider_place */
    double stiffness, friction;
    /* the def it was added with (arrays NULL) and the host's last transform, as given:
       what a recording (sinew_recorder) writes so a replay builds the same collider */
    sinew_collider_def src;
    double src_pos[3], src_rot[4]; /* the host's last placement in doubles (exact either way) */
    union {
        struct {
            double n[3], offset;
        } plane;
        double radius; /* sphere */
        struct {
            double radius, half_height;
        } capsule;
        double half[3]; /* box */
    } u;
    sw_hull hull;
    sw_mesh mesh;
};

struct sinew_world {
    sinew_allocator allocator;
    sinew_logger logger;
    RTCDevice device;
    uint32_t capacity;   /* max_colliders */
    uint32_t live;       /* colliders in the slots */
    uint32_t used;       /* slots ever used: the high-water mark of [0, capacity) */
    sw_collider **slots; /* capacity pointers, NULL when free */
    uint16_t *generation;
};

/* Sets the collider's transform and the world box it gives (outside any step: the
 * detection reads the box for every cluster of every character). */
void sw_collider_place(sw_collider *c, const double R[9], const double t[3]);

/* The signed distance, closest point and outward normal in the collider's own frame
 * (hit in that frame); 0 when y is outside and farther than `radius`. */
int sw_shape_query_local(const sw_collider *c, const double y[3], double radius,
                         sw_collider_hit *hit);

/* Closed forms (shapes.c): check the def's sizes, fill the shape and its local box. */
sinew_result sw_shapes_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c);
int sw_plane_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);
int sw_sphere_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);
int sw_capsule_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);
int sw_box_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);

/* Hulls (hull.c): validated copy of the points; the libccd MPR query. */
sinew_result sw_hull_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c);
void sw_hull_release(sinew_world *w, sw_collider *c);
int sw_hull_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);

/* Meshes (mesh.c): validation, pseudonormals, the committed Embree scene; the query. */
sinew_result sw_mesh_build(sinew_world *w, const sinew_collider_def *d, sw_collider *c);
void sw_mesh_release(sinew_world *w, sw_collider *c);
int sw_mesh_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h);

/* What a mesh's vertices determine (mesh_update.c), at add time and at each move: the
 * local box and diagonal from m->X; the unit face normals, zero for the dead triangles
 * (returns how many are dead); the edge and vertex pseudonormals from those (the edge
 * map, m->twin, built); the move itself, on checked input (finite, within 1e15). */
void sw_mesh_bounds(sw_collider *c);
uint32_t sw_mesh_face_normals(sw_mesh *m);
void sw_mesh_feature_normals(sw_mesh *m);
sinew_result sw_mesh_move(sinew_world *w, sw_collider *c, const float *xyz);

/* Logs an error of the world (SINEW_MSG_WORLD_* id from the result) and returns `code`. */
sinew_result sw_world_fail(const sinew_world *w, sinew_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Whether a size is finite, > 0 and at most SW_COLLIDER_MAX_SIZE. */
static inline int sw_size_ok(double s) {
    return s > 0 && s <= SW_COLLIDER_MAX_SIZE;
}

#endif
