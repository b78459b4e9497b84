/* Skinning-correction basis (thesis §4.4.1, eq. 4.13): each full-space solution x is
 * pulled back through the skinning transform, d_v = R_v^T (x_v - t_v) - rest_v, and
 * each domain gets the uncentred PCA of its vertices' d over the training poses:
 * the leading eigenvectors of the snapshot Gram matrix D^T D, lifted back to
 * U = D V S^-1 and re-orthonormalised. Rows of bone-driven vertices are zero, so in
 * the subspace those vertices follow their bone exactly, as in the reference. */
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_internal.h"

/* Un-skinned displacements of one pose: d (3 nv) from positions x and transforms T. */
static void unskin(const sw_bake_state *s, const double *T, const double *x, double *R, double *t,
                   double *d) {
    sw_bake_skin_transforms(s, T, R, t);
    for (int32_t v = 0; v < s->nv; ++v) {
        const double *Rv = R + 9 * v, *xv = x + 3 * v, *tv = t + 3 * v, *X = s->ch.mesh.X + 3 * v;
        double w[3] = {xv[0] - tv[0], xv[1] - tv[1], xv[2] - tv[2]};
        for (int i = 0; i < 3; ++i)
            d[3 * v + i] = Rv[i] * w[0] + Rv[3 + i] * w[1] + Rv[6 + i] * w[2] - X[i];
        if (s->ch.bone_of_vertex[v] >= 0) d[3 * v] = d[3 * v + 1] = d[3 * v + 2] = 0;
    }
}

/* Modified Gram-Schmidt on the columns of U (m x r, row-major); returns the number of
 * independent columns kept (dependent ones are dropped, later columns shift left). */
static int32_t orthonormalise(double *U, int64_t m, int32_t r) {
    int32_t kept = 0;
    for (int32_t j = 0; j < r; ++j) {
        for (int pass = 0; pass < 2; ++pass) /* twice is enough (Kahan) */
            for (int32_t k = 0; k < kept; ++k) {
                double dot = 0;
                for (int64_t i = 0; i < m; ++i)
                    dot += U[i * r + k] * U[i * r + j];
                for (int64_t i = 0; i < m; ++i)
                    U[i * r + j] -= dot * U[i * r + k];
            }
        double n = 0;
        for (int64_t i = 0; i < m; ++i)
            n += U[i * r + j] * U[i * r + j];
        n = sqrt(n);
        if (n < 1e-10) continue;
        for (int64_t i = 0; i < m; ++i)
            U[i * r + kept] = U[i * r + j] / n;
        kept++;
    }
    return kept;
}

/* OpenBLAS (linked explicitly, precompute/CMakeLists.txt). The Gram matrices are small
 * and the bake's parallelism is across training poses, so its own worker threads only
 * add contention (and races a thread sanitizer cannot see through). */
void openblas_set_num_threads(int num_threads);

/* Rank-r basis (row-major 3n x r) of a domain from snapshots D (T x 3n, row per pose). */
static double *domain_pca(const double *D, int32_t T, int64_t m, int32_t max_rank, double energy,
                          int32_t *rank_out) {
    double *G = calloc((size_t)T * T, sizeof(double)), *ev = malloc((size_t)T * sizeof(double));
    double *U = NULL;
    if (!G || !ev) goto done;
    for (int32_t a = 0; a < T; ++a)
        for (int32_t b = a; b < T; ++b) {
            double g = 0;
            for (int64_t i = 0; i < m; ++i)
                g += D[(size_t)a * m + i] * D[(size_t)b * m + i];
            G[(size_t)a * T + b] = G[(size_t)b * T + a] = g;
        }
    openblas_set_num_threads(1);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', T, G, T, ev) != 0) goto done;
    double total = 0;
    for (int32_t k = 0; k < T; ++k)
        total += fmax(ev[k], 0.0);
    int32_t r = 0;
    double acc = 0;
    /* eigenvalues ascend: take from the top */
    while (r < T && r < max_rank && (r == 0 || acc < energy * total) &&
           ev[T - 1 - r] > 1e-14 * total) {
        acc += ev[T - 1 - r];
        r++;
    }
    if (r == 0) r = 1;
    U = calloc((size_t)m * r, sizeof(double));
    if (!U) goto done;
    if (total > 0) {
        for (int32_t k = 0; k < r; ++k) {
            int32_t col = T - 1 - k; /* eigenvector column in G (row-major: G[a*T + col]) */
            double sig = sqrt(fmax(ev[col], 1e-300));
            for (int32_t a = 0; a < T; ++a) {
                double c = G[(size_t)a * T + col] / sig;
                if (c == 0) continue;
                for (int64_t i = 0; i < m; ++i)
                    U[i * r + k] += c * D[(size_t)a * m + i];
            }
        }
        r = orthonormalise(U, m, r);
    }
    if (r == 0) { /* no deformation at all: one harmless unit mode */
        r = 1;
        memset(U, 0, (size_t)m * sizeof(double));
        U[0] = 1;
    }
    *rank_out = r;
done:
    free(G);
    free(ev);
    return U;
}

/* q_d = U_d^T d restricted to domain dm's copies (q: rank[dm] doubles). */
static void project(const sw_bake_state *s, int32_t dm, const double *d, double *q) {
    int32_t base = s->dom_vert_ptr[dm], n = s->dom_vert_ptr[dm + 1] - base, r = s->rank[dm];
    const double *U = s->basis[dm];
    for (int32_t k = 0; k < r; ++k) {
        double acc = 0;
        for (int32_t j = 0; j < n; ++j)
            for (int i = 0; i < 3; ++i)
                acc += U[(size_t)(3 * j + i) * r + k] * d[3 * s->dom_verts[base + j] + i];
        q[k] = acc;
    }
}

/* Relative projection error accumulators for the snapshots d (3 nv) of one pose. */
static void projection_error(const sw_bake_state *s, const double *d, double *num, double *den) {
    for (int32_t dm = 0; dm < s->nd; ++dm) {
        int32_t base = s->dom_vert_ptr[dm], n = s->dom_vert_ptr[dm + 1] - base, r = s->rank[dm];
        const double *U = s->basis[dm];
        double q[1024];
        project(s, dm, d, q);
        for (int32_t j = 0; j < n; ++j)
            for (int i = 0; i < 3; ++i) {
                double p = 0;
                for (int32_t k = 0; k < r; ++k)
                    p += U[(size_t)(3 * j + i) * r + k] * q[k];
                double dv = d[3 * s->dom_verts[base + j] + i];
                *num += (dv - p) * (dv - p);
                *den += dv * dv;
            }
    }
}

sinew_result sw_bake_basis(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    int32_t T = 0;
    for (int32_t i = 0; i < s->ntrain_seq; ++i)
        T += s->train[i].npose;
    int64_t n3 = 3 * (int64_t)s->nv;
    double *dall = malloc((size_t)T * n3 * sizeof(double));
    double *R = malloc((size_t)s->nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->nv * 3 * sizeof(double));
    double *dtmp = malloc((size_t)n3 * sizeof(double));
    s->rank = calloc((size_t)s->nd, sizeof(int32_t));
    s->basis = calloc((size_t)s->nd, sizeof(double *));
    if (!dall || !R || !t || !dtmp || !s->rank || !s->basis) goto oom;
    int32_t k = 0;
    for (int32_t i = 0; i < s->ntrain_seq; ++i)
        for (int32_t j = 0; j < s->train[i].npose; ++j, ++k)
            unskin(s, s->train[i].T + (size_t)j * 12 * s->nb, s->train[i].x + (size_t)j * n3, R, t,
                   dall + (size_t)k * n3);
    s->rank_total = 0;
    for (int32_t dm = 0; dm < s->nd; ++dm) {
        int32_t base = s->dom_vert_ptr[dm], n = s->dom_vert_ptr[dm + 1] - base;
        double *D = malloc((size_t)T * 3 * n * sizeof(double));
        if (!D) goto oom;
        for (int32_t a = 0; a < T; ++a)
            for (int32_t j = 0; j < n; ++j)
                memcpy(D + (size_t)a * 3 * n + 3 * j,
                       dall + (size_t)a * n3 + 3 * s->dom_verts[base + j], 3 * sizeof(double));
        s->basis[dm] =
            domain_pca(D, T, 3 * (int64_t)n, s->p->max_rank, s->p->pca_energy, &s->rank[dm]);
        free(D);
        if (!s->basis[dm]) goto oom;
        s->rank_total += s->rank[dm];
    }
    /* the pose-space warm start: every training pose's feature and projected solution */
    s->ntrain = T;
    s->train_q = malloc((size_t)T * s->rank_total * sizeof(double));
    s->train_pose = malloc((size_t)T * 4 * s->nb * sizeof(double));
    if (!s->train_q || !s->train_pose) goto oom;
    k = 0;
    for (int32_t i = 0; i < s->ntrain_seq; ++i)
        for (int32_t j = 0; j < s->train[i].npose; ++j, ++k)
            sw_pose_feature(s->train[i].T + (size_t)j * 12 * s->nb, s->ch.skel.parent, s->nb,
                            s->train_pose + (size_t)k * 4 * s->nb);
    for (int32_t a = 0; a < T; ++a) {
        int32_t off = 0;
        for (int32_t dm = 0; dm < s->nd; ++dm) {
            project(s, dm, dall + (size_t)a * n3, s->train_q + (size_t)a * s->rank_total + off);
            off += s->rank[dm];
        }
    }
    double num = 0, den = 0;
    for (int32_t a = 0; a < T; ++a)
        projection_error(s, dall + (size_t)a * n3, &num, &den);
    out->train_proj_error = den > 0 ? sqrt(num / den) : 0;
    num = den = 0;
    for (int32_t j = 0; j < s->heldout.npose; ++j) {
        unskin(s, s->heldout.T + (size_t)j * 12 * s->nb, s->heldout.x + (size_t)j * n3, R, t, dtmp);
        projection_error(s, dtmp, &num, &den);
    }
    out->heldout_proj_error = den > 0 ? sqrt(num / den) : 0;
    free(dall);
    free(R);
    free(t);
    free(dtmp);
    return SINEW_OK;
oom:
    free(dall);
    free(R);
    free(t);
    free(dtmp);
    return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the basis");
}
