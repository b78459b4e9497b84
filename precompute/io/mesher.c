/* The meshers behind one call (mesher.h). */
#include "mesher.h"

#include <string.h>

sinew_result sw_tetmesh_fill(const sw_trimesh *surf, int32_t target_tets, sw_mesher mesher,
                             sw_pool *pool, sw_tetmesh *out, sw_mesher_report *report,
                             sw_error *err) {
    sw_mesher_report local, *rep = report ? report : &local;
    memset(rep, 0, sizeof *rep);
    rep->mesher = mesher;
    if (mesher == SW_MESHER_TETGEN)
        return sw_tetmesh_by_tetgen(surf, target_tets, NULL, out, &rep->tetgen, err);
    if (mesher == SW_MESHER_LATTICE)
        return sw_tetmesh_from_surface(surf, target_tets, pool, out, &rep->lattice, err);
    if (out) memset(out, 0, sizeof *out);
    return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "unknown mesher %d", (int)mesher);
}
