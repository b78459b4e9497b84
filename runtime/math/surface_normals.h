/* Vertex normals of a triangle surface: the area-weighted sum of the incident faces'
 * normals, normalised (what the step outputs and what plain skinning pays for). */
#ifndef SW_SURFACE_NORMALS_H
#define SW_SURFACE_NORMALS_H

#include <stdint.h>

/* n (3 per vertex) = the unit area-weighted normals of positions x (3 per vertex) under
 * the CCW triangles tris (3 per triangle); a vertex in no non-degenerate triangle gets 0. */
void sw_surface_normals(int32_t nverts, const double *x, int32_t ntris, const int32_t *tris,
                        double *n);

#endif
