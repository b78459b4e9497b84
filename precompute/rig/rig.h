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

/* sw_select_bone_vertices for the bones with drives[b] != 0 only (drives NULL: every
 * bone). A game character's skeleton has bones that skin nothing (a root on the ground
 * between the feet, a helper): forced to drive their nearest flesh, they would pin it to
 * a bone that does not follow it. */
sinew_result sw_select_bone_vertices_of(const sw_tetmesh *m, const sw_skeleton *s,
                                        const sw_weights *w, const unsigned char *drives,
                                        int32_t *bone_of_vertex, sw_error *err);

/* A generated mesh can fall into pieces (an ear or a tail tip thinner than the lattice
 * joins the body only through a vertex, or not at all): a piece without a driven vertex
 * would float (a singular quasistatic problem). Drives the four vertices of each such
 * piece's tet nearest the bone that dominates it by that bone; *anchored (may be NULL)
 * counts the pieces. */
sinew_result sw_anchor_free_components(const sw_tetmesh *m, const sw_skeleton *s,
                                       const sw_weights *w, int32_t *bone_of_vertex,
                                       int32_t *anchored, sw_error *err);

/* Per-vertex data of a render surface carried onto tet mesh m: out[v * ncols ..] is the
 * barycentric interpolation of vals' rows (one per surf vertex, ncols each) at v's closest
 * point on the surface, zero-area triangles skipped. The inputs are those
 * sw_weights_from_surface checks. */
sinew_result sw_surface_interpolate(const sw_tetmesh *m, const sw_trimesh *surf, int32_t ncols,
                                    const double *vals, double *out, sw_error *err);

/* Skin weights of tet mesh m transferred from a render surface's (surf_w: one row per
 * surf vertex): each vertex takes the barycentric interpolation of the weights at its
 * closest point on the surface (zero-area triangles skipped). Rows sum to 1. */
sinew_result sw_weights_from_surface(const sw_tetmesh *m, const sw_trimesh *surf,
                                     const sw_weights *surf_w, sw_weights *out, sw_error *err);

/* The bounding-box diagonal of a mesh and its skeleton's joints: the scale the weights'
 * distance clamps are relative to. */
double sw_rig_diagonal(const sw_tetmesh *m, const sw_skeleton *s);

#endif
