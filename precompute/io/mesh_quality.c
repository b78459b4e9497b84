/* Element quality report of a tet mesh: dihedral angles, signed volumes, and counts of
 * degenerate, inverted and sliver tets (what stiffness conditioning depends on). */
#include <math.h>
#include <string.h>

#include "mesh_io.h"
#include "vec3.h"

/* Smallest and largest of the six dihedral angles (radians). The dihedral angle at the
 * edge shared by faces k and l is pi minus the angle between their outward normals;
 * the normals of an inverted tet all point inward, which leaves every angle the same.
 * A face of zero area has no normal: its angles count as 0 (the worst). */
static void dihedrals(const double *p[4], double *lo, double *hi) {
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    double n[4][3], len[4];
    for (int k = 0; k < 4; ++k) {
        double e1[3], e2[3];
        sw_v3_sub(p[face[k][1]], p[face[k][0]], e1);
        sw_v3_sub(p[face[k][2]], p[face[k][0]], e2);
        sw_v3_cross(e1, e2, n[k]);
        len[k] = sw_v3_norm(n[k]);
    }
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int k = 0; k < 4; ++k)
        for (int l = k + 1; l < 4; ++l) {
            double a = 0.0;
            if (len[k] > 0.0 && len[l] > 0.0) {
                double c = -sw_v3_dot(n[k], n[l]) / (len[k] * len[l]);
                a = acos(c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c));
            }
            if (a < *lo) *lo = a;
            if (a > *hi) *hi = a;
        }
}

void sw_tetmesh_quality(const sw_tetmesh *m, double eps, sw_quality *q) {
    if (!q) return;
    memset(q, 0, sizeof *q);
    if (!m || m->ntets < 1 || !m->X || !m->tets) return;
    if (eps <= 0.0) eps = 1e-12;
    const double rad2deg = 180.0 / 3.14159265358979323846;
    double mean = 0.0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *v = m->tets + 4 * (size_t)t;
        mean += fabs(sw_tet_signed_volume(m->X + 3 * (size_t)v[0], m->X + 3 * (size_t)v[1],
                                          m->X + 3 * (size_t)v[2], m->X + 3 * (size_t)v[3]));
    }
    mean /= m->ntets;
    q->ntets = m->ntets;
    q->min_dihedral_deg = q->min_volume = INFINITY;
    q->max_dihedral_deg = q->max_volume = -INFINITY;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *v = m->tets + 4 * (size_t)t;
        const double *p[4] = {m->X + 3 * (size_t)v[0], m->X + 3 * (size_t)v[1],
                              m->X + 3 * (size_t)v[2], m->X + 3 * (size_t)v[3]};
        double vol = sw_tet_signed_volume(p[0], p[1], p[2], p[3]), lo, hi;
        dihedrals(p, &lo, &hi);
        lo *= rad2deg;
        hi *= rad2deg;
        if (lo < q->min_dihedral_deg) q->min_dihedral_deg = lo;
        if (hi > q->max_dihedral_deg) q->max_dihedral_deg = hi;
        if (vol < q->min_volume) q->min_volume = vol;
        if (vol > q->max_volume) q->max_volume = vol;
        if (fabs(vol) <= eps * mean)
            q->degenerate++;
        else if (vol < 0.0)
            q->inverted++;
        if (lo < 5.0) q->slivers++;
    }
}
