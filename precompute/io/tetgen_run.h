/* A simulation tet mesh from a closed render surface by TetGen.
 *
 * TetGen is AGPL-3 (Debian `tetgen`): it is only ever run as a separate program, never
 * linked. The surface is welded (render meshes split their vertices at UV seams), checked
 * to be closed (every edge shared by exactly two triangles), written as OFF to a fresh
 * temporary folder, and meshed with `tetgen -pq1.414/10 -a V` (a constrained Delaunay
 * mesh of the surface, refined until no tet's radius-edge ratio exceeds 1.414 or its
 * dihedral angles fall below 10 degrees, none larger than V); the .node/.ele it writes are
 * read back by sw_read_tetgen (mesh_io.h) and the folder removed. The boundary is then the
 * render surface itself (subdivided where TetGen added points on it), so the render mesh
 * sits on the simulation mesh instead of around a staircase.
 *
 * The lattice mesher (tet_lattice.h) stays the default: it takes any surface (holes,
 * several intersecting primitives, open sheets), its count follows the request, and its
 * angles are 45-90 degrees by construction. docs/notes/game-assets.md, "The lattice or TetGen",
 * compares the two on the shared characters. */
#ifndef SW_TETGEN_RUN_H
#define SW_TETGEN_RUN_H

#include "sw_mesh.h"

typedef struct sw_tetgen_report {
    int32_t welded_verts; /* the surface's vertices after welding equal positions */
    int32_t runs;         /* TetGen runs (up to 4, steering the volume bound to the count) */
    double max_volume;    /* the volume bound (-a) of the run kept (the nearest the count) */
    double volume;        /* the tet mesh's volume */
    double seconds;       /* wall time, both runs and the files */
} sw_tetgen_report;

/* Fills the closed surface `surf` with about `target_tets` tets (100..5,000,000; the
 * quality refinement around the surface's sharp features sets a floor: the low-poly Fox
 * takes no fewer than about 14,000) by the program `program` (NULL: "tetgen" on
 * PATH). Errors, each naming what is wrong: INVALID_ARGUMENT for an empty surface,
 * out-of-range indices, non-finite coordinates, a target out of range, or a surface that
 * is not closed (the count of open and non-manifold edges: the lattice mesher takes such
 * surfaces); IO when the program cannot be started, fails (its last message quoted:
 * TetGen refuses self-intersecting surfaces) or its files cannot be read; the readers'
 * errors for what it wrote; OUT_OF_MEMORY. report may be NULL. */
sinew_result sw_tetmesh_by_tetgen(const sw_trimesh *surf, int32_t target_tets, const char *program,
                                  sw_tetmesh *out, sw_tetgen_report *report, sw_error *err);

/* The surface's vertices welded where their positions are equal (*weld_of: nverts ids into
 * the welded set, the caller frees it) and the count of its edges that are not shared by
 * exactly two triangles (open: one, non-manifold: three or more), degenerate triangles
 * (two corners welded) skipped and counted in *degenerate. */
sinew_result sw_surface_closure(const sw_trimesh *surf, int32_t **weld_of, int32_t *nwelded,
                                int32_t *open_edges, int32_t *nonmanifold_edges,
                                int32_t *degenerate, sw_error *err);

#endif
