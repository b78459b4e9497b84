/* Rigging a tet mesh when an asset leaves it out: simple skin weights and the vertices
 * each bone drives kinematically (heat-diffusion weights: weights_heat.h). */
#ifndef SW_RIG_H
#define SW_RIG_H

#include "sw_mesh.h"

/* Simple skin weights when an asset has none: inverse distance to bone segments
 * (w ~ 1/d^4), normalised. (The bake owns heat-diffusion weights.) */
sinew_result sw_weights_inverse_distance(const sw_tetmesh *m, const sw_skeleton *s, sw_weights *out,
                                         sw_error *err);

/* Chooses the vertices driven kinematically by each bone ("inside the bone"): those
 * close to the bone's segment relative to the flesh thickness around it, at least a
 * few per bone so the problem is never singular. Writes bone_of_vertex (nverts). */
sinew_result sw_select_bone_vertices(const sw_tetmesh *m, const sw_skeleton *s, const sw_weights *w,
                                     int32_t *bone_of_vertex, sw_error *err);

/* The bounding-box diagonal of a mesh and its skeleton's joints: the scale the weights'
 * distance clamps are relative to. */
double sw_rig_diagonal(const sw_tetmesh *m, const sw_skeleton *s);

#endif
