#include "tet_rest.h"

#include <math.h>

#include "mat3.h"

int sw_tet_rest(const double X[12], double DmInv[9], double *vol) {
    double Dm[9];
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            Dm[3 * a + k] = X[3 * (k + 1) + a] - X[a];
    double det = sw_m3_det(Dm);
    if (!isfinite(det) || !(fabs(det) >= 1e-300)) return 0;
    double C[9], inv[9];
    sw_m3_cofactor(Dm, C);
    for (int i = 0; i < 3; ++i) /* Dm^-1 = C^T / det */
        for (int j = 0; j < 3; ++j)
            inv[3 * i + j] = C[3 * j + i] / det;
    for (int i = 0; i < 9; ++i)
        if (!isfinite(inv[i])) return 0;
    for (int i = 0; i < 9; ++i)
        DmInv[i] = inv[i];
    *vol = fabs(det) / 6.0;
    return 1;
}
