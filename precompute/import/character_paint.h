/* Painted material: an artist's per-vertex stiffness multiplier (a glTF attribute, a
 * Blender vertex group, a .dmat) carried onto the simulation tets, which the reference,
 * the bake and the runtime all weigh by it (sw_character.tet_stiffness). */
#ifndef SW_CHARACTER_PAINT_H
#define SW_CHARACTER_PAINT_H

#include "sw_error.h"
#include "sw_mesh.h"

/* c->tet_stiffness from the painting: c->render_stiffness (one per render vertex) carried to
 * the simulation vertices at their closest points on the render surface, or, without a
 * render mesh, vert_stiffness (one per simulation vertex; may be NULL); a tet takes the mean
 * of its corners'. Nothing painted (both NULL): c is left uniform. Errors name the first
 * multiplier outside [SW_STIFFNESS_MIN, SW_STIFFNESS_MAX] (INVALID_ARGUMENT). */
sinew_result sw_character_paint(sw_character *c, const double *vert_stiffness, sw_error *err);

/* Reads a .dmat of one column: one multiplier per render vertex when c has a render mesh
 * (in the blob's output order, which is the import's; it replaces what the file painted),
 * else one per simulation vertex; then paints c (sw_character_paint). */
sinew_result sw_character_read_stiffness(const char *path, sw_character *c, sw_error *err);

/* A bake report's lines on the painting: painted tets (multiplier not 1), the range and
 * the volume share below 1, into buf (always terminated); "" when nothing is painted. */
void sw_character_paint_summary(const sw_character *c, char *buf, size_t n);

#endif
