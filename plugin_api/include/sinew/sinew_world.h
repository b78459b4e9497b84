/* sinew — the collision world (DESIGN.md §4.5): static triangle meshes in an Embree
 * scene, convex shapes in closed form (plane, sphere, capsule, box) or through libccd
 * MPR (hulls), each with a rigid transform the host may move every frame.
 *
 * Thread-safety contract (in the manner of Embree's "never commit while queries run"):
 *  - A world is built and changed (create, add, remove, set_transform, set_mesh_vertices,
 *    destroy) by one thread at a time, and never while an instance that uses it is
 *    stepping.
 *  - While no such change runs, any number of instances on any number of threads step
 *    against one world at once: a step only reads it (no allocation, no lock, no commit).
 *  - The contact forces an instance exerted are the instance's own (read them from the
 *    instance's owner thread after its step).
 *
 * Colliders live in their own frame: the host moves them by their transform, which never
 * rebuilds anything; a mesh's vertices may move too (another character's surface), which
 * refits its BVH. Units are the character's: lengths in its units, stiffness in the
 * blob's penalty units (force per length per area, as the blob's contact stiffness). */
#ifndef SINEW_WORLD_H
#define SINEW_WORLD_H

#include "sinew_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How to create a world. */
typedef struct sinew_world_def {
    uint32_t struct_size;      /**< sizeof(sinew_world_def), set by the default */
    uint32_t max_colliders;    /**< capacity, reserved at creation; 0 means 256 */
    sinew_allocator allocator; /**< memory hooks; zero means the C library */
    sinew_logger logger;       /**< log hook, kept for the world's life; zero: errors to stderr */
} sinew_world_def;

/** A sinew_world_def with every field at its default. */
static inline sinew_world_def sinew_world_def_default(void) {
    sinew_world_def d;
    d.struct_size = (uint32_t)sizeof(sinew_world_def);
    d.max_colliders = 0;
    d.allocator = sinew_allocator_default();
    d.logger = sinew_logger_default();
    return d;
}

/** Collider shapes. All but the plane and the mesh are convex solids; a plane is the
 * half-space behind it; a mesh is solid behind its triangles' front faces. */
typedef enum sinew_shape {
    SINEW_SHAPE_PLANE = 0,   /**< n . x = offset, solid where n . x < offset */
    SINEW_SHAPE_SPHERE = 1,  /**< radius, centred at the origin */
    SINEW_SHAPE_CAPSULE = 2, /**< radius around the segment y in [-half_height, half_height] */
    SINEW_SHAPE_BOX = 3,     /**< |x_i| <= half_extents[i] */
    SINEW_SHAPE_HULL = 4,    /**< the convex hull of `points` (queried with libccd MPR) */
    SINEW_SHAPE_MESH = 5     /**< triangles, counter-clockwise seen from outside (Embree) */
} sinew_shape;

/** A rigid transform from the collider's frame to the world: x = R(rotation) y + position. */
typedef struct sinew_transform {
    float position[3];
    float rotation[4]; /**< unit quaternion w, x, y, z (normalised on use; must be finite and
                          nonzero) */
} sinew_transform;

/** The identity transform. */
static inline sinew_transform sinew_transform_identity(void) {
    sinew_transform t = {{0, 0, 0}, {1, 0, 0, 0}};
    return t;
}

/** How to add a collider. The arrays are copied: the caller may free them on return. */
typedef struct sinew_collider_def {
    uint32_t struct_size; /**< sizeof(sinew_collider_def), set by the default */
    sinew_shape shape;
    float normal[3];       /**< plane: its outward normal (normalised on use) */
    float offset;          /**< plane: n . x = offset on it */
    float radius;          /**< sphere, capsule: > 0 */
    float half_height;     /**< capsule: >= 0, along the local y axis */
    float half_extents[3]; /**< box: each > 0 */
    const float *points;   /**< hull: point_count xyz triples, not all coplanar */
    uint32_t point_count;  /**< hull: 4 ..= 4096 */
    const float *vertices; /**< mesh: vertex_count xyz triples */
    uint32_t vertex_count;
    const uint32_t *indices;   /**< mesh: 3 per triangle, < vertex_count */
    uint32_t triangle_count;   /**< mesh: >= 1; triangles of zero area are rejected */
    float stiffness;           /**< penalty stiffness; 0 means the blob's contact stiffness */
    float friction;            /**< Coulomb coefficient >= 0; 0 is frictionless */
    sinew_transform transform; /**< initial placement */
} sinew_collider_def;

/** A sinew_collider_def with every field at its default (a plane y = 0 facing +y). */
static inline sinew_collider_def sinew_collider_def_default(void) {
    sinew_collider_def d;
    d.struct_size = (uint32_t)sizeof(sinew_collider_def);
    d.shape = SINEW_SHAPE_PLANE;
    d.normal[0] = 0;
    d.normal[1] = 1;
    d.normal[2] = 0;
    d.offset = 0;
    d.radius = 0;
    d.half_height = 0;
    d.half_extents[0] = d.half_extents[1] = d.half_extents[2] = 0;
    d.points = NULL;
    d.point_count = 0;
    d.vertices = NULL;
    d.vertex_count = 0;
    d.indices = NULL;
    d.triangle_count = 0;
    d.stiffness = 0;
    d.friction = 0;
    d.transform = sinew_transform_identity();
    return d;
}

/** A collider's handle: its slot and a generation, so a removed collider's id stays
 * invalid after its slot is reused. 0 is never a valid id. */
typedef uint32_t sinew_collider_id;

/** Stable log message ids of the world (sinew_logger). */
#define SINEW_MSG_WORLD_INVALID_ARGUMENT 0x0400u /**< error: bad def, shape or arguments */
#define SINEW_MSG_WORLD_OUT_OF_MEMORY 0x0401u    /**< error: the allocator returned NULL */
#define SINEW_MSG_WORLD_DEGENERATE 0x0402u       /**< error: degenerate shape (names why) */
#define SINEW_MSG_WORLD_CAPACITY 0x0403u         /**< error: max_colliders reached */
#define SINEW_MSG_WORLD_EMBREE 0x0404u           /**< error: Embree reported an error */

/** Creates an empty world (with its own Embree device, one thread). Not thread-safe
 * with respect to the new world (there is no other user yet). */
SINEW_API sinew_result sinew_world_create(const sinew_world_def *def, sinew_world **out);

/** Destroys a world. No instance may step with it any more (detach them first, or
 * destroy them). NULL is ignored. */
SINEW_API void sinew_world_destroy(sinew_world *world);

/** Adds a collider (validated: finite, positive sizes, non-degenerate hulls and meshes,
 * indices in range) and writes its id. Meshes are built into an Embree scene here.
 * Not while an instance using the world steps. */
SINEW_API sinew_result sinew_world_add_collider(sinew_world *world, const sinew_collider_def *def,
                                                sinew_collider_id *out);

/** Removes a collider; its id becomes invalid. Not while an instance using the world steps. */
SINEW_API sinew_result sinew_world_remove_collider(sinew_world *world, sinew_collider_id id);

/** Moves a collider (no rebuild: queries run in its frame). A non-finite transform or a
 * zero quaternion is rejected (NOT_FINITE / INVALID_ARGUMENT) and the old one kept.
 * Not while an instance using the world steps. */
SINEW_API sinew_result sinew_world_set_collider_transform(sinew_world *world, sinew_collider_id id,
                                                          const sinew_transform *transform);

/** The same in double precision: position (xyz) and rotation (unit quaternion w, x, y,
 * z, normalised on use), for hosts whose world is in doubles. A float placement rounds
 * at 1e-7 of its distance from the origin (8 mm at 10^5 units); this one keeps what the
 * host has, as `sinew_instance_set_actor` does for the character. */
SINEW_API sinew_result sinew_world_set_collider_transform_d(sinew_world *world,
                                                            sinew_collider_id id,
                                                            const double position[3],
                                                            const double rotation[4]);

/** Moves the vertices of mesh collider `id` (`vertex_count` xyz triples; vertex_count must
 * equal its count at creation; the triangles stay), e.g. another character's surface after
 * its step, and refits its BVH and pseudonormals. In the collider's frame. Non-finite
 * input is refused (NOT_FINITE) and the old vertices kept; a wrong count, a collider that
 * is not a mesh or a stale id is INVALID_ARGUMENT. A triangle the motion collapsed to zero
 * area is not an error (queries skip it until it opens again). Same thread contract as
 * sinew_world_set_collider_transform: never while an instance using the world steps. */
SINEW_API sinew_result sinew_world_set_mesh_vertices(sinew_world *world, sinew_collider_id id,
                                                     const float *xyz, uint32_t vertex_count);

/** Live colliders in the world. Any thread, while no change runs. */
SINEW_API uint32_t sinew_world_collider_count(const sinew_world *world);

/** Lets the instance collide with `world` from its next step on (NULL detaches). The
 * world must outlive the attachment. The world is in world units: an actor scaled by
 * sinew_instance_set_actor or a scaled pose is refused (INVALID_ARGUMENT) for now. Owner
 * thread of the instance; never while it steps. */
SINEW_API sinew_result sinew_instance_set_world(sinew_instance *inst, const sinew_world *world);

/** The instance ignores collider `id` from its next step on (its own surface in the
 * world, for contact between characters: sinew_world_set_mesh_vertices); 0 clears it.
 * One collider at a time; the id is kept across sinew_instance_set_world. An id that is
 * not live in the attached world is INVALID_ARGUMENT. Owner thread, never while it steps. */
SINEW_API sinew_result sinew_instance_ignore_collider(sinew_instance *inst, sinew_collider_id id);

/** The total force and the torque about the collider's origin (its transform's position)
 * that the instance's flesh exerted on collider `id` in its last step, in world units.
 * Zero for a collider it did not touch. Owner thread of the instance, after its step. */
SINEW_API sinew_result sinew_instance_collider_force(const sinew_instance *inst,
                                                     sinew_collider_id id, float force[3],
                                                     float torque[3]);

#ifdef __cplusplus
}
#endif
#endif /* SINEW_WORLD_H */
