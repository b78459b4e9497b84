/* sinew — the collision world (DESIGN.md §4.5): static triangle meshes in an Embree
 * scene and convex shapes through libccd or closed forms, shared read-only by the
 * instances that step against it.
 *
 * This version has no world yet: the handle type is declared (sinew_types.h) so that
 * hosts and later versions agree on it, and the world's functions arrive here with the
 * collision-world issue. Nothing in this header is callable today. */
#ifndef SINEW_WORLD_H
#define SINEW_WORLD_H

#include "sinew_types.h"

#endif /* SINEW_WORLD_H */
