/* A tet mesher for solids of revolution about the +x axis: a (linearly tapered)
 * round tube with optional hemispherical caps, at any resolution. The sample
 * characters (samples.c) are built on it. */
#ifndef SW_TUBE_MESH_H
#define SW_TUBE_MESH_H

#include "sw_mesh.h"

/* The shape: x runs over [0, length]. The body's radius tapers linearly from r0 to r1;
 * a cap replaces the body's last r0 (start) or r1 (end) units of length by a hemisphere
 * of that radius, so `length` always includes the caps. */
typedef struct sw_tube_profile {
    double length;
    double r0, r1;
    int cap_start, cap_end; /* 1: rounded end, 0: flat end */
} sw_tube_profile;

/* Checks the profile: finite, positive radii, caps shorter than the length. */
sinew_result sw_tube_validate(const sw_tube_profile *p, sw_error *err);

/* Radius of the surface at x (0 outside [0, length]). */
double sw_tube_radius(const sw_tube_profile *p, double x);

/* Radius of the body at x, clamped into the body: the radius a cap continues. */
double sw_tube_body_radius(const sw_tube_profile *p, double x);

/* Exact volume of the shape (frustum plus hemispheres). */
double sw_tube_volume(const sw_tube_profile *p);

/* Meshes the tube with about `target_tets` tets (1,000 to 2,000,000; within ~25%) into
 * `out`: all tets positively oriented, conforming, closed surface, every boundary
 * vertex on the true surface. When `on_surface` is not NULL it receives a malloc'd
 * array of nverts flags (1 = boundary vertex). On error `out` is zeroed and nothing is allocated.
 */
sinew_result sw_tube_mesh(const sw_tube_profile *p, int32_t target_tets, sw_tetmesh *out,
                          unsigned char **on_surface, sw_error *err);

#endif
