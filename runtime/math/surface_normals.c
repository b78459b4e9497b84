#include "surface_normals.h"

#include <math.h>
#include <string.h>

void sw_surface_normals(int32_t nverts, const double *x, int32_t ntris, const int32_t *tris,
                        double *n) {
    memset(n, 0, 3 * (size_t)nverts * sizeof(double));
    for (int32_t t = 0; t < ntris; ++t) {
        const int32_t *tri = tris + 3 * t;
        const double *a = x + 3 * tri[0], *b = x + 3 * tri[1], *c = x + 3 * tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
               e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double f[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]}; /* twice the area, along the normal */
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                n[3 * tri[k] + j] += f[j];
    }
    for (int32_t s = 0; s < nverts; ++s) {
        double *q = n + 3 * s, l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        if (l > 0)
            for (int k = 0; k < 3; ++k)
                q[k] /= l;
    }
}
