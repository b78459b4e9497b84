/* Non-negative least squares (see nnls.h): the Lawson-Hanson active-set method and
 * its normal-equation variant FNNLS (Bro & de Jong 1997), sharing one driver.
 *
 * Both keep an upper-triangular factor R of the passive columns that is updated, not
 * recomputed, when a column enters (one Gram-Schmidt/Cholesky step, O(mp) or O(p^2))
 * or leaves (Givens rotations restore the triangle, O(p^2) plus O(mp) for Q). For
 * Lawson-Hanson A_P = Q R with Q explicit (m x p, Gram-Schmidt applied twice, which
 * keeps Q orthonormal to working precision); for FNNLS R is the Cholesky factor of
 * (A^T A)_PP, i.e. the same R without Q. R is stored packed by columns (column j
 * holds rows 0..j at j(j+1)/2), so it grows with the passive set, not with n.
 * Cubature training solves eq. 2.14 with these (thesis §2.2.3). */
#include "nnls.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A column whose part orthogonal to the passive columns is below this fraction of its
 * norm is treated as dependent (rejected: it cannot lower the residual). FNNLS sees
 * the square of that fraction through cancellation in the normal equations, so it
 * needs a coarser threshold (relative to the diagonal of A^T A). */
#define LH_DEPENDENT_REL 1e-10
#define FAST_DEPENDENT_REL 1e-12

typedef struct nnls_factor {
    sw_nnls_method method;
    int64_t m, n;
    int64_t p, cap, max_cap; /* passive count, allocated columns, hard limit */
    const double *A, *b;     /* Lawson-Hanson: the problem itself */
    const double *G, *Atb;   /* FNNLS: A^T A (n x n) and A^T b */
    double *R;               /* packed upper triangle, cap(cap+1)/2 */
    double *Q;               /* Lawson-Hanson: m x cap, orthonormal columns */
    double *qtb;             /* Lawson-Hanson: Q^T b */
    int64_t *var;            /* position in the passive set -> variable */
    double *tmp;             /* cap + 1 */
    double *rot;             /* 2 cap: Givens (c, s) pairs of a removal */
    double *v;               /* Lawson-Hanson: m (Gram-Schmidt, residual) */
} nnls_factor;

static inline double *rcol(const nnls_factor *f, int64_t j) {
    return f->R + j * (j + 1) / 2;
}

static void factor_free(nnls_factor *f) {
    free(f->R);
    free(f->Q);
    free(f->qtb);
    free(f->var);
    free(f->tmp);
    free(f->rot);
    free(f->v);
}

/* Room for one more passive column (doubling). 0 when out of memory. */
static int factor_reserve(nnls_factor *f) {
    if (f->p < f->cap) return 1;
    int64_t cap = f->cap ? 2 * f->cap : 16;
    if (cap > f->max_cap) cap = f->max_cap;
    double *R = realloc(f->R, (size_t)(cap * (cap + 1) / 2) * sizeof(double));
    if (!R) return 0;
    f->R = R;
    int64_t *var = realloc(f->var, (size_t)cap * sizeof(int64_t));
    if (!var) return 0;
    f->var = var;
    double *tmp = realloc(f->tmp, (size_t)(cap + 1) * sizeof(double));
    if (!tmp) return 0;
    f->tmp = tmp;
    double *rot = realloc(f->rot, (size_t)(2 * cap) * sizeof(double));
    if (!rot) return 0;
    f->rot = rot;
    if (f->method == SW_NNLS_LAWSON_HANSON) {
        double *Q = realloc(f->Q, (size_t)(cap * f->m) * sizeof(double));
        if (!Q) return 0;
        f->Q = Q;
        double *qtb = realloc(f->qtb, (size_t)cap * sizeof(double));
        if (!qtb) return 0;
        f->qtb = qtb;
    }
    f->cap = cap;
    return 1;
}

/* Appends variable j to the passive set. Returns 1 on success, 0 when the column is
 * (numerically) dependent on the passive ones or the set is full, -1 out of memory. */
static int factor_add(nnls_factor *f, int64_t j) {
    if (f->p >= f->max_cap) return 0;
    if (!factor_reserve(f)) return -1;
    int64_t p = f->p;
    double *rc = rcol(f, p);
    if (f->method == SW_NNLS_LAWSON_HANSON) {
        const int64_t m = f->m;
        const double *a = f->A + j * m;
        double anorm = sqrt(sw_dot(a, a, m));
        if (!(anorm > 0)) return 0;
        double *v = f->v;
        memcpy(v, a, (size_t)m * sizeof(double));
        for (int64_t k = 0; k <= p; ++k)
            rc[k] = 0;
        /* Modified Gram-Schmidt, twice ("twice is enough"): one pass loses
         * orthogonality in proportion to the conditioning of A_P. */
        for (int pass = 0; pass < 2; ++pass) {
            for (int64_t k = 0; k < p; ++k) {
                const double *q = f->Q + k * m;
                double c = sw_dot(q, v, m);
                rc[k] += c;
                for (int64_t i = 0; i < m; ++i)
                    v[i] -= c * q[i];
            }
        }
        double nrm = sqrt(sw_dot(v, v, m));
        if (!(nrm > LH_DEPENDENT_REL * anorm)) return 0;
        double *q = f->Q + p * m;
        for (int64_t i = 0; i < m; ++i)
            q[i] = v[i] / nrm;
        rc[p] = nrm;
        f->qtb[p] = sw_dot(q, f->b, m);
    } else {
        const int64_t n = f->n;
        double gjj = f->G[j * n + j];
        if (!(gjj > 0)) return 0;
        /* Solve R^T l = (A^T A)_{P,j}; the new diagonal is sqrt(g_jj - |l|^2). */
        double ll = 0;
        for (int64_t k = 0; k < p; ++k) {
            const double *ck = rcol(f, k);
            double s = f->G[j * n + f->var[k]] - sw_dot(ck, rc, k);
            rc[k] = s / ck[k];
            ll += rc[k] * rc[k];
        }
        double d2 = gjj - ll;
        if (!(d2 > FAST_DEPENDENT_REL * gjj)) return 0;
        rc[p] = sqrt(d2);
    }
    f->var[p] = j;
    f->p = p + 1;
    return 1;
}

/* Removes passive position k. Shifting the later columns left leaves R upper
 * Hessenberg from column k on; one Givens rotation per column restores the triangle.
 * The rotations are applied lazily, column by column, so the packed layout never
 * needs a slot for the sub-diagonal. Lawson-Hanson rotates Q's columns and Q^T b the
 * same way (A_P = Q R = (Q G^T)(G R)). */
static void factor_remove(nnls_factor *f, int64_t k) {
    const int64_t p = f->p, m = f->m;
    double *t = f->tmp, *rot = f->rot;
    for (int64_t c = k; c < p - 1; ++c) {
        memcpy(t, rcol(f, c + 1), (size_t)(c + 2) * sizeof(double));
        for (int64_t i = k; i < c; ++i) {
            double gc = rot[2 * i], gs = rot[2 * i + 1];
            double x = t[i], y = t[i + 1];
            t[i] = gc * x + gs * y;
            t[i + 1] = -gs * x + gc * y;
        }
        double a = t[c], bb = t[c + 1], r = hypot(a, bb);
        double gc = 1, gs = 0;
        if (r > 0) {
            gc = a / r;
            gs = bb / r;
        }
        rot[2 * c] = gc;
        rot[2 * c + 1] = gs;
        t[c] = r;
        memcpy(rcol(f, c), t, (size_t)(c + 1) * sizeof(double));
        if (f->method == SW_NNLS_LAWSON_HANSON) {
            double *q0 = f->Q + c * m, *q1 = q0 + m;
            for (int64_t i = 0; i < m; ++i) {
                double x = q0[i], y = q1[i];
                q0[i] = gc * x + gs * y;
                q1[i] = -gs * x + gc * y;
            }
            double x = f->qtb[c], y = f->qtb[c + 1];
            f->qtb[c] = gc * x + gs * y;
            f->qtb[c + 1] = -gs * x + gc * y;
        }
        f->var[c] = f->var[c + 1];
    }
    f->p = p - 1;
}

/* Least squares on the passive set: z (p) = argmin |A_P z - b|. Lawson-Hanson:
 * R z = Q^T b. FNNLS: R^T R z = (A^T b)_P. */
static void factor_solve(const nnls_factor *f, double *z) {
    const int64_t p = f->p;
    if (f->method == SW_NNLS_LAWSON_HANSON) {
        memcpy(z, f->qtb, (size_t)p * sizeof(double));
    } else {
        for (int64_t j = 0; j < p; ++j) {
            const double *cj = rcol(f, j);
            z[j] = (f->Atb[f->var[j]] - sw_dot(cj, z, j)) / cj[j];
        }
    }
    for (int64_t j = p - 1; j >= 0; --j) {
        const double *cj = rcol(f, j);
        z[j] /= cj[j];
        for (int64_t i = 0; i < j; ++i)
            z[i] -= cj[i] * z[j];
    }
}

/* The dual w = A^T (b - A x) for the variables flagged in `want`. */
static void dual(const nnls_factor *f, const double *x, const unsigned char *want, double *w) {
    const int64_t n = f->n, p = f->p;
    if (f->method == SW_NNLS_LAWSON_HANSON) {
        const int64_t m = f->m;
        double *r = f->v;
        memcpy(r, f->b, (size_t)m * sizeof(double));
        for (int64_t k = 0; k < p; ++k) {
            const double *a = f->A + f->var[k] * m;
            double xk = x[f->var[k]];
            for (int64_t i = 0; i < m; ++i)
                r[i] -= xk * a[i];
        }
        for (int64_t j = 0; j < n; ++j)
            w[j] = want[j] ? sw_dot(f->A + j * m, r, m) : 0;
    } else {
        for (int64_t j = 0; j < n; ++j) {
            if (!want[j]) {
                w[j] = 0;
                continue;
            }
            const double *gj = f->G + j * n;
            double s = f->Atb[j];
            for (int64_t k = 0; k < p; ++k)
                s -= gj[f->var[k]] * x[f->var[k]];
            w[j] = s;
        }
    }
}

typedef struct nnls_work {
    double *z, *w;
    unsigned char *passive, *want; /* want: neither passive nor blocked */
    int64_t *blocked;
    int64_t nblocked;
} nnls_work;

/* Lawson-Hanson's inner loop: z = LS solution on P; while some z_k <= 0, move x
 * towards z as far as feasibility allows and drop the variables that hit zero. Each
 * pass drops at least one variable, so it ends. On return x_P = z > 0. */
static void inner_loop(nnls_factor *f, nnls_work *wk, double *x) {
    double *z = wk->z;
    for (;;) {
        factor_solve(f, z);
        double alpha = 2;
        int64_t kmin = -1;
        for (int64_t k = 0; k < f->p; ++k) {
            if (z[k] > 0) continue;
            double xk = x[f->var[k]];
            double a = xk / (xk - z[k]);
            if (a < alpha) {
                alpha = a;
                kmin = k;
            }
        }
        if (kmin < 0) {
            for (int64_t k = 0; k < f->p; ++k)
                x[f->var[k]] = z[k];
            return;
        }
        for (int64_t k = 0; k < f->p; ++k) {
            double *xk = &x[f->var[k]];
            *xk += alpha * (z[k] - *xk);
        }
        x[f->var[kmin]] = 0;
        for (int64_t k = f->p - 1; k >= 0; --k) {
            int64_t j = f->var[k];
            if (x[j] > 0) continue;
            x[j] = 0;
            wk->passive[j] = 0;
            wk->want[j] = 1;
            factor_remove(f, k);
        }
    }
}

static void unblock_all(nnls_work *wk) {
    for (int64_t i = 0; i < wk->nblocked; ++i)
        wk->want[wk->blocked[i]] = 1;
    wk->nblocked = 0;
}

/* The shared active-set driver (Lawson & Hanson 1974, ch. 23; FNNLS only changes how
 * the subproblems and the dual are computed). x0 (optional) warm-starts P = supp(x0). */
static sinew_result active_set(nnls_factor *f, const double *x0, double tol, int max_iter,
                               double *x, sw_nnls_stats *st, sw_error *err) {
    const int64_t n = f->n;
    nnls_work wk = {0};
    wk.z = malloc((size_t)n * sizeof(double));
    wk.w = malloc((size_t)n * sizeof(double));
    wk.passive = calloc((size_t)n, 1);
    wk.want = malloc((size_t)n);
    wk.blocked = malloc((size_t)n * sizeof(int64_t));
    sinew_result res = SINEW_OK;
    if (!wk.z || !wk.w || !wk.passive || !wk.want || !wk.blocked) {
        res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "nnls: out of memory (n = %lld)",
                           (long long)n);
        goto done;
    }
    memset(wk.want, 1, (size_t)n);
    for (int64_t j = 0; j < n; ++j)
        x[j] = 0;
    /* Scale of the dual: |A^T b|_inf, the dual at x = 0. */
    dual(f, x, wk.want, wk.w);
    double scale = 0;
    for (int64_t j = 0; j < n; ++j)
        scale = fmax(scale, fabs(wk.w[j]));
    const double tol_abs = (tol > 0 ? tol : 1e-10) * scale;
    if (max_iter <= 0) max_iter = (int)(n < 1000000 ? 3 * n : 3000000);

    if (x0) {
        for (int64_t j = 0; j < n; ++j) {
            if (!(x0[j] > 0)) continue;
            int ok = factor_add(f, j);
            if (ok < 0) goto oom;
            if (ok == 0) continue;
            x[j] = x0[j];
            wk.passive[j] = 1;
            wk.want[j] = 0;
        }
        if (f->p > 0) inner_loop(f, &wk, x);
    }

    int iter = 0, converged = 0, fresh = 0;
    for (;;) {
        if (!fresh) dual(f, x, wk.want, wk.w);
        fresh = 1;
        int64_t jmax = -1;
        double wmax = tol_abs;
        for (int64_t j = 0; j < n; ++j) {
            if (wk.want[j] && wk.w[j] > wmax) {
                wmax = wk.w[j];
                jmax = j;
            }
        }
        if (jmax < 0) {
            converged = 1;
            break;
        }
        if (iter >= max_iter) break;
        ++iter;
        int ok = factor_add(f, jmax);
        if (ok < 0) goto oom;
        /* A dependent column, or one whose LS coefficient is not positive (possible
         * only through rounding, since w_j > 0), is skipped until P changes. */
        if (ok == 1) {
            factor_solve(f, wk.z);
            if (!(wk.z[f->p - 1] > 0)) {
                factor_remove(f, f->p - 1);
                ok = 0;
            }
        }
        if (ok == 0) {
            wk.want[jmax] = 0;
            wk.blocked[wk.nblocked++] = jmax;
            continue;
        }
        wk.passive[jmax] = 1;
        wk.want[jmax] = 0;
        x[jmax] = 0;
        inner_loop(f, &wk, x);
        unblock_all(&wk);
        fresh = 0;
    }
    if (st) {
        st->iterations = iter;
        st->converged = converged;
    }
    if (!converged)
        res = sw_error_set(err, SINEW_ERROR_NOT_CONVERGED,
                           "nnls: dual above tolerance after %d iterations (n = %lld)", iter,
                           (long long)n);
    goto done;
oom:
    res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "nnls: out of memory (passive set %lld)",
                       (long long)f->p);
done:
    free(wk.z);
    free(wk.w);
    free(wk.passive);
    free(wk.want);
    free(wk.blocked);
    return res;
}

static int all_finite(const double *v, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static double residual_norm(const double *A, int64_t m, int64_t n, const double *b, const double *x,
                            double *r) {
    memcpy(r, b, (size_t)m * sizeof(double));
    for (int64_t j = 0; j < n; ++j) {
        if (x[j] == 0) continue;
        const double *a = A + j * m;
        for (int64_t i = 0; i < m; ++i)
            r[i] -= x[j] * a[i];
    }
    return sqrt(sw_dot(r, r, m));
}

static sinew_result check_common(int64_t n, double tol, int max_iter, const double *x,
                                 sw_error *err) {
    if (!x) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: x is NULL");
    if (n < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: n = %lld", (long long)n);
    if (!(tol >= 0) || !isfinite(tol))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: tolerance %g", tol);
    if (max_iter < 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: max_iter %d", max_iter);
    return SINEW_OK;
}

sinew_result sw_nnls(sw_nnls_method method, const double *A, int64_t m, int64_t n, const double *b,
                     double tol, int max_iter, double *x, sw_nnls_stats *stats, sw_error *err) {
    if (stats) memset(stats, 0, sizeof *stats);
    sinew_result res = check_common(n, tol, max_iter, x, err);
    if (res != SINEW_OK) return res;
    if (!A || !b) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: A or b is NULL");
    if (m < 1 || n > INT64_MAX / m / 8)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: bad size %lld x %lld",
                            (long long)m, (long long)n);
    if (method != SW_NNLS_LAWSON_HANSON && method != SW_NNLS_FAST)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: unknown method %d",
                            (int)method);
    for (int64_t j = 0; j < n; ++j)
        if (!all_finite(A + j * m, m))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "nnls: non-finite entry in column %lld of A", (long long)j);
    if (!all_finite(b, m))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: non-finite entry in b");

    nnls_factor f = {.method = method, .m = m, .n = n, .A = A, .b = b};
    double *G = NULL, *Atb = NULL;
    f.v = malloc((size_t)m * sizeof(double));
    if (!f.v) goto oom;
    if (method == SW_NNLS_FAST) {
        if (n > INT64_MAX / n / 8) goto oom;
        G = malloc((size_t)(n * n) * sizeof(double));
        Atb = malloc((size_t)n * sizeof(double));
        if (!G || !Atb) goto oom;
        for (int64_t j = 0; j < n; ++j) {
            const double *aj = A + j * m;
            Atb[j] = sw_dot(aj, b, m);
            for (int64_t i = 0; i <= j; ++i)
                G[j * n + i] = G[i * n + j] = sw_dot(A + i * m, aj, m);
        }
        f.G = G;
        f.Atb = Atb;
        f.max_cap = n;
    } else {
        f.max_cap = n < m ? n : m;
    }
    res = active_set(&f, NULL, tol, max_iter, x, stats, err);
    if (stats && res != SINEW_ERROR_OUT_OF_MEMORY)
        stats->residual = residual_norm(A, m, n, b, x, f.v);
    factor_free(&f);
    free(G);
    free(Atb);
    return res;
oom:
    factor_free(&f);
    free(G);
    free(Atb);
    return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "nnls: out of memory (%lld x %lld)",
                        (long long)m, (long long)n);
}

sinew_result sw_nnls_normal(const double *AtA, const double *Atb, double btb, int64_t n, double tol,
                            int max_iter, const double *x0, double *x, sw_nnls_stats *stats,
                            sw_error *err) {
    if (stats) memset(stats, 0, sizeof *stats);
    sinew_result res = check_common(n, tol, max_iter, x, err);
    if (res != SINEW_OK) return res;
    if (!AtA || !Atb)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: A^T A or A^T b is NULL");
    if (n > INT64_MAX / n / 8)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "nnls: n = %lld", (long long)n);
    if (!all_finite(AtA, n * n) || !all_finite(Atb, n) || !isfinite(btb))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "nnls: non-finite entry in the normal equations");
    if (x0) {
        for (int64_t j = 0; j < n; ++j)
            if (!(x0[j] >= 0) || !isfinite(x0[j]))
                return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                    "nnls: warm start x0[%lld] = %g", (long long)j, x0[j]);
    }
    nnls_factor f = {.method = SW_NNLS_FAST, .n = n, .G = AtA, .Atb = Atb, .max_cap = n};
    res = active_set(&f, x0, tol, max_iter, x, stats, err);
    if (stats && res != SINEW_ERROR_OUT_OF_MEMORY) {
        /* |Ax - b|^2 = b.b - 2 x.A^T b + x.A^T A x (cancels when the fit is tight). */
        double q = btb;
        for (int64_t j = 0; j < n; ++j) {
            if (x[j] == 0) continue;
            double gx = 0;
            for (int64_t i = 0; i < n; ++i)
                gx += AtA[j * n + i] * x[i];
            q += x[j] * (gx - 2 * Atb[j]);
        }
        stats->residual = sqrt(fmax(q, 0));
    }
    factor_free(&f);
    return res;
}
