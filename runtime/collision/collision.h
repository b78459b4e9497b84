/* The collision world inside the runtime (sinew_world.h): colliders in their own
 * frames, and the one query the step and the reference make of them.
 *
 * A query takes a world-space point, maps it into the collider's frame (no rebuild when
 * the host moves a collider), and returns the closest point of the collider's surface,
 * the outward unit normal there and the signed distance (negative inside):
 *   plane, sphere, capsule, box   closed form
 *   hull                          libccd MPR (ccdMPRPenetration; never GJK/EPA, which
 *                                 reallocs on every overlapping call, STYLE.md §6)
 *   mesh                          Embree rtcPointQuery with a finite radius on the
 *                                 scene committed when the mesh was added; inside or
 *                                 outside from the angle-weighted pseudonormal of the
 *                                 closest feature (face, edge or vertex)
 * Queries never allocate, lock or commit, and any number of threads may query one world
 * at once while no one changes it. */
#ifndef SW_COLLISION_H
#define SW_COLLISION_H

#include <stdint.h>

#include "sinew/sinew_world.h"

/* The answer of one query, in world space. */
typedef struct sw_collider_hit {
    double phi;       /* signed distance of the point to the surface, < 0 inside */
    double point[3];  /* the closest surface point */
    double normal[3]; /* outward unit normal of the surface at `point` */
} sw_collider_hit;

/* One live collider as the step reads it (the world owns it; opaque beyond these). */
typedef struct sw_collider sw_collider;

/* The world's collider slots: [0, sw_world_slot_count) with NULL for empty slots. */
uint32_t sw_world_slot_count(const sinew_world *w);
const sw_collider *sw_world_slot(const sinew_world *w, uint32_t slot);

/* The id of the collider in `slot` (as sinew_world_add_collider returned it), and the
 * slot of a valid id (or -1). */
sinew_collider_id sw_collider_id_of(const sinew_world *w, uint32_t slot);
int32_t sw_world_slot_of(const sinew_world *w, sinew_collider_id id);

/* Its penalty stiffness (0: the blob's) and Coulomb friction coefficient. */
double sw_collider_stiffness(const sw_collider *c);
double sw_collider_friction(const sw_collider *c);

/* Its world-space rigid transform: x_world = R y + t (R row-major). */
void sw_collider_transform(const sw_collider *c, double R[9], double t[3]);

/* A world-space axis-aligned box holding every point within `margin` of the solid
 * (for a plane, the half-space's box: infinite along the plane, +-HUGE_VAL). */
void sw_collider_bounds(const sw_collider *c, double margin, double lo[3], double hi[3]);

/* The def it was added with, at the host's last transform (sinew_transform as given), its
 * arrays NULL: the hull's points or the mesh's vertices are sw_collider_points (3 each,
 * doubles holding the def's floats exactly), the mesh's triangles sw_collider_triangles
 * (3 each); NULL and 0 for the other shapes. */
void sw_collider_source(const sw_collider *c, sinew_collider_def *d);
/* The host's last placement as given, in doubles (a float one exactly). */
void sw_collider_placement(const sw_collider *c, double position[3], double rotation[4]);
const double *sw_collider_points(const sw_collider *c, uint32_t *count);
const uint32_t *sw_collider_triangles(const sw_collider *c, uint32_t *count);

/* How many times sinew_world_set_mesh_vertices has moved a mesh's vertices since it was
 * added (wrapping; 0 for the other shapes): a recorder writes the vertices again when it
 * differs from the count it saw last. Only a move writes it, so any thread may read it
 * in a step. */
uint32_t sw_collider_vertex_moves(const sw_collider *c);

/* Its outline in the world for a debug draw: the 8 corners of its local box placed by its
 * transform (corner j takes hi on axis k when bit k of j is set), returning 8; or for a
 * plane the 4 corners, in order round, of a square of half-side `extent` centred where
 * the plane is closest to `around`, returning 4. */
int sw_collider_outline(const sw_collider *c, const double around[3], double extent,
                        double corners[8][3]);

/* The world's capacity (sinew_world_def.max_colliders as resolved). */
uint32_t sw_world_capacity(const sinew_world *w);

/* The query: returns 1 and fills `hit` when x is inside the collider or within
 * `radius` (> 0, finite) of its surface, else 0 (hit untouched). */
int sw_collider_query(const sw_collider *c, const double x[3], double radius, sw_collider_hit *hit);

/* Whether x lies in the box [lo, hi] (boundary included). */
static inline int sw_box_contains(const double lo[3], const double hi[3], const double x[3]) {
    return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1] && x[2] >= lo[2] &&
           x[2] <= hi[2];
}

/* The deepest penetration into any of the world's colliders of the n points x (3 each),
 * only those with mask[i] > 0 when mask is not NULL (a measurement, not for the step:
 * O(points x colliders)). With inside, also counts the points inside a collider whose
 * known[i] is 0 (known NULL: all of them). */
double sw_world_max_penetration(const sinew_world *w, int32_t n, const double *x,
                                const double *mask, const unsigned char *known, int32_t *inside);

#endif
