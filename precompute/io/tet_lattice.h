/* A simulation tet mesh generated from a render surface that need not be closed or
 * manifold (game characters' render meshes have holes, several primitives and
 * self-intersections). A cubic lattice over the surface's bounding box, each cube split
 * into the six Freudenthal tets that share its main diagonal (a conforming mesh: every
 * cube is split the same way); a cube is inside when the generalised winding number of
 * the surface at its centre (Jacobson et al. 2013: the sum of the triangles' solid
 * angles over 4 pi, 1 inside a closed surface, near 1 inside one with holes, 0 outside)
 * has magnitude at least 1/2 (winding.h; through its dipole tree), so an inside-out
 * surface is filled too. The lattice
 * spacing is chosen from a coarse pass's filled share so that the mesh has about the
 * requested number of tets.
 *
 * The boundary is the lattice's staircase: the render mesh is embedded in the result
 * (each render vertex in its nearest tet), not the other way round. TetGen gives a
 * boundary-conforming mesh of closed surfaces only (tetgen_run.h, `--mesher tetgen`;
 * docs/notes/game-assets.md compares the two on the shared assets). */
#ifndef SW_TET_LATTICE_H
#define SW_TET_LATTICE_H

#include "sw_mesh.h"
#include "thread_pool.h"
#include "winding.h"

typedef struct sw_lattice_report {
    double spacing;        /* lattice cube edge (surface units) */
    int32_t cells[3];      /* lattice cubes along x, y, z */
    int32_t cells_inside;  /* cubes kept */
    double volume;         /* the tet mesh's volume */
    double surface_volume; /* the surface's signed volume (divergence theorem; exact when
                              it is closed and consistently oriented) */
    int32_t components;    /* face-connected pieces of the tet mesh */
    double shell;          /* > 0: the surface encloses no volume (a flat sheet, an open
                              strip) and the mesh is a shell of this thickness around it
                              (4% of its bounding-box diagonal), which bends as a plate */
    double seconds;
} sw_lattice_report;

/* Fills `surf` (triangles over its own vertices) with about `target_tets` tets
 * (100..5,000,000; within a fifth where the shape is thick; a thin one, a few cubes
 * across, fills in steps as the spacing falls and gets the nearest count, within a factor
 * of 2, or DEGENERATE naming it). A surface that encloses none (a flat sheet, a single open strip)
 * is meshed as a shell around it instead (report->shell; at least two cubes through it, so a small
 * target may get more). pool may be NULL. Errors: INVALID_ARGUMENT for an empty surface,
 * out-of-range indices, non-finite coordinates or a target out of range; DEGENERATE when the
 * surface has no area; OUT_OF_MEMORY. */
sinew_result sw_tetmesh_from_surface(const sw_trimesh *surf, int32_t target_tets, sw_pool *pool,
                                     sw_tetmesh *out, sw_lattice_report *report, sw_error *err);

#endif
