/* Small dense kernels (see dense.h). */
#include "dense.h"

#include <math.h>

#include "lanes.h"

int sw_cholesky(double *A, int32_t n) {
    for (int32_t j = 0; j < n; ++j) {
        double d = A[(int64_t)j * n + j];
        for (int32_t k = 0; k < j; ++k)
            d -= A[(int64_t)j * n + k] * A[(int64_t)j * n + k];
        if (!(d > 0)) return 0;
        d = sqrt(d);
        A[(int64_t)j * n + j] = d;
        for (int32_t i = j + 1; i < n; ++i) {
            double s = A[(int64_t)i * n + j];
            for (int32_t k = 0; k < j; ++k)
                s -= A[(int64_t)i * n + k] * A[(int64_t)j * n + k];
            A[(int64_t)i * n + j] = s / d;
        }
    }
    return 1;
}

void sw_cholesky_solve(const double *L, int32_t n, double *x) {
    for (int32_t i = 0; i < n; ++i) { /* L y = b */
        double s = x[i];
        for (int32_t k = 0; k < i; ++k)
            s -= L[(int64_t)i * n + k] * x[k];
        x[i] = s / L[(int64_t)i * n + i];
    }
    for (int32_t i = n - 1; i >= 0; --i) { /* L^T x = y */
        double s = x[i];
        for (int32_t k = i + 1; k < n; ++k)
            s -= L[(int64_t)k * n + i] * x[k];
        x[i] = s / L[(int64_t)i * n + i];
    }
}

/* Block (i, j) of a dense row-major n x n matrix, element (r, c) inside it. */
#define BLK(M, i, j, r, c) (M)[(int64_t)(off[i] + (r)) * n + off[j] + (c)]

void sw_block_pattern(const double *A, int32_t n, int32_t nb, const int32_t *off,
                      const int32_t *size, const int32_t *order, unsigned char *nz) {
    for (int32_t a = 0; a < nb; ++a)
        for (int32_t b = 0; b < a; ++b) {
            int32_t i = order[a], j = order[b], any = 0;
            for (int32_t r = 0; r < size[i] && !any; ++r)
                for (int32_t c = 0; c < size[j]; ++c)
                    if (BLK(A, i, j, r, c) != 0.0) {
                        any = 1;
                        break;
                    }
            nz[a * nb + b] = (unsigned char)any;
        }
}

size_t sw_block_cholesky_pack_size(int32_t max_size) {
    return (size_t)((max_size + 7) / 8 * 8) * (size_t)max_size;
}

/* The Schur update of block column b (position) into the blocks of row positions a >= e
 * in column position e: L_ik -= L_ij L_kj^T, i = order[a], j = order[b], k = order[e].
 * L_kj is first packed eight of its rows side by side (pack[c0 sj + 8 m + t] = L_kj(c0 +
 * t, m)), so that a row of L_ij meets eight columns of the product in four vector
 * operations. Every entry is still its own sum over m from 0, subtracted once: bitwise
 * what one loop per entry gives, whatever the vector width. */
static void schur_update(double *L, int32_t n, int32_t nb, const int32_t *off, const int32_t *size,
                         const int32_t *order, unsigned char *nz, int32_t b, int32_t e,
                         double *pack) {
    const int32_t j = order[b], sj = size[j], k = order[e], sk = size[k];
    for (int32_t c0 = 0; c0 < sk; c0 += 8)
        for (int32_t m = 0; m < sj; ++m)
            for (int t = 0; t < 8; ++t)
                pack[(int64_t)c0 * sj + 8 * m + t] = c0 + t < sk ? BLK(L, k, j, c0 + t, m) : 0.0;
    for (int32_t a = e; a < nb; ++a) {
        if (!nz[a * nb + b]) continue;
        const int32_t i = order[a];
        if (e < a && !nz[a * nb + e]) { /* fill: a zero block becomes nonzero */
            nz[a * nb + e] = 1;
            for (int32_t r = 0; r < size[i]; ++r)
                for (int32_t c = 0; c < sk; ++c)
                    BLK(L, i, k, r, c) = 0.0;
        }
        for (int32_t r = 0; r < size[i]; ++r) {
            const double *Lr = &BLK(L, i, j, r, 0);
            double *Out = &BLK(L, i, k, r, 0);
            const int32_t nc = e == a ? r + 1 : sk; /* a diagonal block: its lower triangle */
            for (int32_t c0 = 0; c0 < nc; c0 += 8) {
                const double *P = pack + (int64_t)c0 * sj;
                sw_v2d s0 = {0, 0}, s1 = {0, 0}, s2 = {0, 0}, s3 = {0, 0};
                for (int32_t m = 0; m < sj; ++m) {
                    const sw_v2d x = {Lr[m], Lr[m]};
                    const sw_v2d *pm = (const sw_v2d *)(const void *)(P + 8 * m);
                    s0 += x * pm[0];
                    s1 += x * pm[1];
                    s2 += x * pm[2];
                    s3 += x * pm[3];
                }
                const double sv[8] = {s0[0], s0[1], s1[0], s1[1], s2[0], s2[1], s3[0], s3[1]};
                for (int t = 0; t < 8 && c0 + t < nc; ++t)
                    Out[c0 + t] -= sv[t];
            }
        }
    }
}

int sw_block_cholesky(const double *A, int32_t n, int32_t nb, const int32_t *off,
                      const int32_t *size, const int32_t *order, unsigned char *nz, double *L,
                      double *pack) {
    /* copy the blocks we will use: diagonal blocks and nonzero lower blocks */
    for (int32_t a = 0; a < nb; ++a) {
        int32_t i = order[a];
        for (int32_t r = 0; r < size[i]; ++r)
            for (int32_t c = 0; c <= r; ++c)
                BLK(L, i, i, r, c) = BLK(A, i, i, r, c);
        for (int32_t b = 0; b < a; ++b) {
            int32_t j = order[b];
            if (!nz[a * nb + b]) continue;
            for (int32_t r = 0; r < size[i]; ++r)
                for (int32_t c = 0; c < size[j]; ++c)
                    BLK(L, i, j, r, c) = BLK(A, i, j, r, c);
        }
    }
    /* right-looking block elimination */
    for (int32_t b = 0; b < nb; ++b) {
        int32_t j = order[b], sj = size[j];
        /* L_jj = chol(block) */
        for (int32_t c = 0; c < sj; ++c) {
            double d = BLK(L, j, j, c, c);
            for (int32_t k = 0; k < c; ++k)
                d -= BLK(L, j, j, c, k) * BLK(L, j, j, c, k);
            if (!(d > 0)) return 0;
            d = sqrt(d);
            BLK(L, j, j, c, c) = d;
            for (int32_t r = c + 1; r < sj; ++r) {
                double s = BLK(L, j, j, r, c);
                for (int32_t k = 0; k < c; ++k)
                    s -= BLK(L, j, j, r, k) * BLK(L, j, j, c, k);
                BLK(L, j, j, r, c) = s / d;
            }
        }
        /* L_ij = A_ij L_jj^-T for the later blocks coupled to j */
        for (int32_t a = b + 1; a < nb; ++a) {
            if (!nz[a * nb + b]) continue;
            int32_t i = order[a], r = 0;
            /* four rows at a time (independent; each in its own order as before) */
            for (; r + 4 <= size[i]; r += 4) {
                double *R0 = &BLK(L, i, j, r, 0), *R1 = R0 + n, *R2 = R1 + n, *R3 = R2 + n;
                for (int32_t c = 0; c < sj; ++c) {
                    const double *Dc = &BLK(L, j, j, c, 0);
                    double s0 = R0[c], s1 = R1[c], s2 = R2[c], s3 = R3[c];
                    for (int32_t k = 0; k < c; ++k) {
                        double d = Dc[k];
                        s0 -= R0[k] * d;
                        s1 -= R1[k] * d;
                        s2 -= R2[k] * d;
                        s3 -= R3[k] * d;
                    }
                    R0[c] = s0 / Dc[c];
                    R1[c] = s1 / Dc[c];
                    R2[c] = s2 / Dc[c];
                    R3[c] = s3 / Dc[c];
                }
            }
            for (; r < size[i]; ++r)
                for (int32_t c = 0; c < sj; ++c) {
                    double s = BLK(L, i, j, r, c);
                    for (int32_t k = 0; k < c; ++k)
                        s -= BLK(L, i, j, r, k) * BLK(L, j, j, c, k);
                    BLK(L, i, j, r, c) = s / BLK(L, j, j, c, c);
                }
        }
        /* Schur update of the later blocks: A_ik -= L_ij L_kj^T (fill marked in nz) */
        for (int32_t e = b + 1; e < nb; ++e)
            if (nz[e * nb + b]) schur_update(L, n, nb, off, size, order, nz, b, e, pack);
    }
    return 1;
}

void sw_block_cholesky_solve(const double *L, int32_t n, int32_t nb, const int32_t *off,
                             const int32_t *size, const int32_t *order, const unsigned char *nz,
                             double *x) {
    for (int32_t a = 0; a < nb; ++a) { /* L y = b in elimination order */
        int32_t i = order[a];
        for (int32_t b = 0; b < a; ++b) {
            if (!nz[a * nb + b]) continue;
            int32_t j = order[b];
            for (int32_t r = 0; r < size[i]; ++r) {
                double s = 0;
                for (int32_t c = 0; c < size[j]; ++c)
                    s += BLK(L, i, j, r, c) * x[off[j] + c];
                x[off[i] + r] -= s;
            }
        }
        for (int32_t r = 0; r < size[i]; ++r) {
            double s = x[off[i] + r];
            for (int32_t c = 0; c < r; ++c)
                s -= BLK(L, i, i, r, c) * x[off[i] + c];
            x[off[i] + r] = s / BLK(L, i, i, r, r);
        }
    }
    for (int32_t a = nb - 1; a >= 0; --a) { /* L^T x = y */
        int32_t i = order[a];
        for (int32_t r = size[i] - 1; r >= 0; --r) {
            double s = x[off[i] + r];
            for (int32_t c = r + 1; c < size[i]; ++c)
                s -= BLK(L, i, i, c, r) * x[off[i] + c];
            x[off[i] + r] = s / BLK(L, i, i, r, r);
        }
        for (int32_t b = 0; b < a; ++b) {
            if (!nz[a * nb + b]) continue;
            int32_t j = order[b];
            for (int32_t c = 0; c < size[j]; ++c) {
                double s = 0;
                for (int32_t r = 0; r < size[i]; ++r)
                    s += BLK(L, i, j, r, c) * x[off[i] + r];
                x[off[j] + c] -= s;
            }
        }
    }
}
#undef BLK

void sw_block_order_min_degree(int32_t nb, const unsigned char *coupled, unsigned char *adj,
                               int32_t *order) {
    for (int32_t i = 0; i < nb; ++i)
        for (int32_t j = 0; j < nb; ++j)
            adj[i * nb + j] = (unsigned char)(i != j && coupled[i * nb + j]);
    /* 2 on the diagonal: eliminated */
    for (int32_t step = 0; step < nb; ++step) {
        int32_t best = -1, bestdeg = 0;
        for (int32_t i = 0; i < nb; ++i) {
            if (adj[i * nb + i] == 2) continue;
            int32_t deg = 0;
            for (int32_t j = 0; j < nb; ++j)
                deg += j != i && adj[i * nb + j] == 1 && adj[j * nb + j] != 2;
            if (best < 0 || deg < bestdeg) best = i, bestdeg = deg;
        }
        order[step] = best;
        for (int32_t j = 0; j < nb; ++j) /* the neighbours of best become a clique */
            for (int32_t k = 0; k < nb; ++k)
                if (j != k && adj[best * nb + j] == 1 && adj[best * nb + k] == 1 &&
                    adj[j * nb + j] != 2 && adj[k * nb + k] != 2)
                    adj[j * nb + k] = 1;
        adj[best * nb + best] = 2;
    }
}
