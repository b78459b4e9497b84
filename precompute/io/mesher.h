/* What fills a render surface with simulation tets: the lattice cut by
 * the winding number (tet_lattice.h; any surface, the default) or TetGen run as a separate
 * program (tetgen_run.h; closed surfaces, boundary-conforming). docs/notes/game-assets.md ("The
 * lattice or TetGen") compares them. */
#ifndef SW_MESHER_H
#define SW_MESHER_H

#include "tet_lattice.h"
#include "tetgen_run.h"

typedef enum sw_mesher {
    SW_MESHER_LATTICE = 0, /* any surface; the default */
    SW_MESHER_TETGEN = 1   /* closed surfaces, boundary-conforming */
} sw_mesher;

/* What the mesher did: `lattice` for SW_MESHER_LATTICE, `tetgen` for SW_MESHER_TETGEN. */
typedef struct sw_mesher_report {
    sw_mesher mesher;
    sw_lattice_report lattice;
    sw_tetgen_report tetgen;
} sw_mesher_report;

/* Fills `surf` with about target_tets tets by `mesher` (pool: the lattice's threads, may be
 * NULL); report may be NULL. The errors are the mesher's; INVALID_ARGUMENT for an unknown
 * mesher. */
sinew_result sw_tetmesh_fill(const sw_trimesh *surf, int32_t target_tets, sw_mesher mesher,
                             sw_pool *pool, sw_tetmesh *out, sw_mesher_report *report,
                             sw_error *err);

#endif
