/* Small static-inline 3x3 helpers for the material kernels (svd3.c, fem_corot.c).
 * Row-major 3x3 matrices; the 3-vector helpers (sw_v3_dot, sw_v3_cross, ...) are vec3.h's.
 * Private to the runtime. */
#ifndef SW_MAT3_H
#define SW_MAT3_H

#include "vec3.h"

/* C = A B (C may not alias A or B). */
static inline void sw_m3_mul(const double A[9], const double B[9], double C[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* C = A B^T (C may not alias A or B). */
static inline void sw_m3_mul_nt(const double A[9], const double B[9], double C[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] =
                A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
}

/* C = A^T B (C may not alias A or B). */
static inline void sw_m3_mul_tn(const double A[9], const double B[9], double C[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
}

static inline double sw_m3_det(const double A[9]) {
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* The cofactor matrix C of A: A^-1 = C^T / det A, and det A = A[0] C[0] + A[1] C[1] +
 * A[2] C[2]. */
static inline void sw_m3_cofactor(const double A[9], double C[9]) {
    C[0] = A[4] * A[8] - A[5] * A[7];
    C[1] = A[5] * A[6] - A[3] * A[8];
    C[2] = A[3] * A[7] - A[4] * A[6];
    C[3] = A[2] * A[7] - A[1] * A[8];
    C[4] = A[0] * A[8] - A[2] * A[6];
    C[5] = A[1] * A[6] - A[0] * A[7];
    C[6] = A[1] * A[5] - A[2] * A[4];
    C[7] = A[2] * A[3] - A[0] * A[5];
    C[8] = A[0] * A[4] - A[1] * A[3];
}

static inline void sw_m3_identity(double A[9]) {
    for (int i = 0; i < 9; ++i)
        A[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

/* The rotation by `angle` radians about the unit axis k (Rodrigues), row-major. */
static inline void sw_m3_axis_angle(const double k[3], double angle, double R[9]) {
    double c = cos(angle), s = sin(angle), C = 1 - c;
    R[0] = c + k[0] * k[0] * C;
    R[1] = k[0] * k[1] * C - k[2] * s;
    R[2] = k[0] * k[2] * C + k[1] * s;
    R[3] = k[1] * k[0] * C + k[2] * s;
    R[4] = c + k[1] * k[1] * C;
    R[5] = k[1] * k[2] * C - k[0] * s;
    R[6] = k[2] * k[0] * C - k[1] * s;
    R[7] = k[2] * k[1] * C + k[0] * s;
    R[8] = c + k[2] * k[2] * C;
}

#endif
