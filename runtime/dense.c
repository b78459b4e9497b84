/* Small dense kernels (see dense.h). */
#include "dense.h"

#include <math.h>

int sw_cholesky(double *A, int32_t n) {
    for (int32_t j = 0; j < n; ++j) {
        double d = A[(int64_t)j * n + j];
        for (int32_t k = 0; k < j; ++k) d -= A[(int64_t)j * n + k] * A[(int64_t)j * n + k];
        if (!(d > 0)) return 0;
        d = sqrt(d);
        A[(int64_t)j * n + j] = d;
        for (int32_t i = j + 1; i < n; ++i) {
            double s = A[(int64_t)i * n + j];
            for (int32_t k = 0; k < j; ++k) s -= A[(int64_t)i * n + k] * A[(int64_t)j * n + k];
            A[(int64_t)i * n + j] = s / d;
        }
    }
    return 1;
}

void sw_cholesky_solve(const double *L, int32_t n, double *x) {
    for (int32_t i = 0; i < n; ++i) { /* L y = b */
        double s = x[i];
        for (int32_t k = 0; k < i; ++k) s -= L[(int64_t)i * n + k] * x[k];
        x[i] = s / L[(int64_t)i * n + i];
    }
    for (int32_t i = n - 1; i >= 0; --i) { /* L^T x = y */
        double s = x[i];
        for (int32_t k = i + 1; k < n; ++k) s -= L[(int64_t)k * n + i] * x[k];
        x[i] = s / L[(int64_t)i * n + i];
    }
}
