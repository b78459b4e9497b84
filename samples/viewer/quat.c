/* Unit quaternions (w, x, y, z) and rotation matrices (3x3 row-major), once for the
 * viewer: clip keys, cross-fades, dual-quaternion skinning and colliders use these. */
#include <math.h>

#include "viewer.h"

void vw_quat_from_matrix(const double *R, double *q) {
    double tr = R[0] + R[4] + R[8], k4;
    if (tr > 0) {
        k4 = 2 * sqrt(tr + 1);
        q[0] = 0.25 * k4, q[1] = (R[7] - R[5]) / k4, q[2] = (R[2] - R[6]) / k4,
        q[3] = (R[3] - R[1]) / k4;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[0] - R[4] - R[8]));
        q[0] = (R[7] - R[5]) / k4, q[1] = 0.25 * k4, q[2] = (R[1] + R[3]) / k4,
        q[3] = (R[2] + R[6]) / k4;
    } else if (R[4] > R[8]) {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[4] - R[0] - R[8]));
        q[0] = (R[2] - R[6]) / k4, q[1] = (R[1] + R[3]) / k4, q[2] = 0.25 * k4,
        q[3] = (R[5] + R[7]) / k4;
    } else {
        k4 = 2 * sqrt(fmax(0.0, 1 + R[8] - R[0] - R[4]));
        q[0] = (R[3] - R[1]) / k4, q[1] = (R[2] + R[6]) / k4, q[2] = (R[5] + R[7]) / k4,
        q[3] = 0.25 * k4;
    }
}

void vw_quat_matrix(const double *q, double *R) {
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

/* Along the shorter arc (a and -a are one rotation), normalised; near-parallel
 * quaternions are blended linearly, where slerp's sin(th) would divide by nearly 0. */
void vw_quat_slerp(const double *a, const double *b, double u, double *o) {
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], wa = 1 - u, wb = u;
    const double sg = d < 0 ? -1 : 1;
    d = fabs(d);
    if (d < 0.9995) {
        const double th = acos(fmin(1.0, d)), s = sin(th);
        wa = sin((1 - u) * th) / s, wb = sin(u * th) / s;
    }
    double nrm = 0;
    for (int c = 0; c < 4; ++c)
        o[c] = wa * a[c] + wb * sg * b[c], nrm += o[c] * o[c];
    nrm = sqrt(nrm);
    for (int c = 0; c < 4; ++c)
        o[c] = nrm > 1e-12 ? o[c] / nrm : (c == 0);
}
