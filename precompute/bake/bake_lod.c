/* The pose-space level of detail (sinew_lod, SINEW_LOD_POSE_SPACE): each output vertex
 * skinned on its own, displaced in its rest frame by a blend of what the training poses'
 * solutions put there. The displacement that makes the vertex's own skinning land on the
 * blob's full-level surface at each training pose, d_s(t) = R_s(t)^T (x_s(t) - t_s(t)) -
 * X_s, is a training-poses-by-output matrix; its leading right singular vectors are the
 * level's modes and the poses' coordinates on them its coefficients, which the runtime
 * blends at the pose as it blends the reduced solutions (pose_space.h). Then every level's
 * held-out error on the output surface, for the report. */
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_eval.h"
#include "bake_state.h"
#include "blob_load.h"
#include "dqs.h"
#include "instance.h"

/* The modes kept: the fewest whose dropped singular values hold at most this share of the
 * displacements' norm (their squares' sum), at most SINEW_BLOB_LOD_MAX_RANK. */
#define SW_LOD_TOL 0.1

/* Output vertex s's four influences: a boundary vertex's own; a render vertex's its
 * embedding tet's corners' weights blended by its barycentrics (clamped at 0), the four
 * largest kept, renormalised. */
static void output_influences(const sw_blob_view *v, int32_t s, int32_t bone[4], double w[4]) {
    double acc[SW_MAX_BONES];
    memset(acc, 0, sizeof(double) * (size_t)v->nbones);
    if (v->nrender_verts == 0) {
        int32_t gv = sw_blob_surf_copy_vertex(v, v->surf_copy_ptr[s]);
        for (int k = 0; k < 4; ++k)
            acc[v->skin_bone[4 * (int64_t)gv + k]] += v->skin_weight[4 * (int64_t)gv + k];
    } else {
        const double *b = v->render_bary + 4 * (int64_t)s;
        for (int j = 0; j < 4; ++j) {
            int32_t gv =
                sw_render_node_vertex(v, v->render_tets[4 * (int64_t)v->render_tet[s] + j]);
            for (int k = 0; k < 4; ++k)
                acc[v->skin_bone[4 * (int64_t)gv + k]] +=
                    fmax(b[j], 0) * v->skin_weight[4 * (int64_t)gv + k];
        }
    }
    double sum = 0;
    for (int k = 0; k < 4; ++k) { /* the four largest, first the strongest (ties: lowest id) */
        int32_t best = 0;
        for (int32_t b = 1; b < v->nbones; ++b)
            if (acc[b] > acc[best]) best = b;
        bone[k] = best;
        w[k] = acc[best] > 0 ? acc[best] : 0;
        acc[best] = -1;
        sum += w[k];
    }
    for (int k = 0; k < 4; ++k)
        w[k] = sum > 0 ? w[k] / sum : (k == 0);
}

/* Row t of D: the displacements of every output vertex at training pose t. */
static void displacement_row(const sw_blob_view *v, const double *T, const double *x,
                             const double *rest, const int32_t *bone, const double *w,
                             double *row) {
    sw_dualquat dq[SW_MAX_BONES];
    for (int32_t b = 0; b < v->nbones; ++b)
        sw_dq_from_transform(T + 12 * b, &dq[b]);
    for (int32_t s = 0; s < sw_blob_output_verts(v); ++s) {
        double R[9], t[3], e[3];
        sw_dqs_blend(dq, bone + 4 * s, w + 4 * s, 4, R, t);
        for (int k = 0; k < 3; ++k)
            e[k] = x[3 * s + k] - t[k];
        for (int i = 0; i < 3; ++i)
            row[3 * s + i] = R[i] * e[0] + R[3 + i] * e[1] + R[6 + i] * e[2] - rest[3 * s + i];
    }
}

/* D (T rows of 3 n) from the blob at every training pose, each the full level's surface
 * at the pose's own reduced solution. */
static sinew_result displacements(const sinew_blob *blob, const sw_bake_result *out,
                                  const double *rest, const int32_t *bone, const double *w,
                                  double *D, double *F, sw_error *err) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    const size_t n3 = 3 * (size_t)sw_blob_output_verts(v);
    sinew_instance_def def = sinew_instance_def_default();
    sinew_instance *inst = NULL;
    sinew_result r = sinew_instance_create(blob, &def, &inst);
    if (r != SINEW_OK)
        return sw_error_set(err, r, "pose-space level: cannot create an instance: %s",
                            sinew_result_string(r));
    for (int32_t t = 0; t < v->ntrain && r == SINEW_OK; ++t) {
        const double *T = out->train_T + (size_t)12 * v->nbones * t;
        if ((r = sw_instance_set_pose_d(inst, T)) != SINEW_OK) {
            r = sw_error_set(err, r, "pose-space level: training pose %d does not set", t);
            break;
        }
        sw_instance_surface_at(inst, v->train_q + (size_t)v->rank_total * t);
        displacement_row(v, T, sw_instance_surface(inst), rest, bone, w, D + n3 * t);
        sw_pose_rotation_feature(T, v->bone_parent, v->nbones,
                                 F + (size_t)SW_POSE_ROTATION_FEATURES(v->nbones) * t);
    }
    sinew_instance_destroy(inst);
    return r;
}

/* The ridge regression's normal equations of training poses [t0, t1): A += F^T F (nf x
 * nf), B += F^T C (nf x m), sign -1 to take them out again. */
static void normal_equations(const double *F, const double *C, int32_t t0, int32_t t1, int32_t nf,
                             int32_t m, double sign, double *A, double *B) {
    for (int32_t t = t0; t < t1; ++t) {
        const double *f = F + (size_t)t * nf, *c = C + (size_t)t * m;
        for (int32_t i = 0; i < nf; ++i) {
            for (int32_t j = 0; j < nf; ++j)
                A[(size_t)i * nf + j] += sign * f[i] * f[j];
            for (int32_t j = 0; j < m; ++j)
                B[(size_t)i * m + j] += sign * f[i] * c[j];
        }
    }
}

/* X (nf x m) = (A + lambda I)^-1 B; 0 when the system is singular. */
static int ridge_solve(const double *A, const double *B, int32_t nf, int32_t m, double lambda,
                       double *work, double *X) {
    memcpy(work, A, sizeof(double) * (size_t)nf * nf);
    memcpy(X, B, sizeof(double) * (size_t)nf * m);
    for (int32_t i = 0; i < nf; ++i)
        work[(size_t)i * nf + i] += lambda;
    return LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', nf, m, work, nf, X, m) == 0;
}

/* The squared misfit |C - F X| over training poses [t0, t1). */
static double misfit(const double *F, const double *C, const double *X, int32_t t0, int32_t t1,
                     int32_t nf, int32_t m) {
    double e = 0;
    for (int32_t t = t0; t < t1; ++t)
        for (int32_t j = 0; j < m; ++j) {
            double y = C[(size_t)t * m + j];
            for (int32_t i = 0; i < nf; ++i)
                y -= F[(size_t)t * nf + i] * X[(size_t)i * m + j];
            e += y * y;
        }
    return e;
}

/* The ridge candidates (shares of the features' mean square) and the validation's folds:
 * contiguous blocks of the training poses, which come as clips and sweeps, so that a
 * fold's poses are not the neighbours of the poses fitted. */
static const double k_ridges[] = {1e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0};
#define SW_LOD_FOLDS 5

/* W (m x nf) of the ridge regression C ~ F W^T of the training poses' coefficients C
 * (T x m) on their joint-rotation features F (T x nf), the ridge chosen by the folds'
 * validation misfit, into W and *ridge. */
static sinew_result regress(const double *F, const double *C, int32_t T, int32_t nf, int32_t m,
                            double *W, double *ridge, sw_error *err) {
    const size_t a = (size_t)nf * nf, b = (size_t)nf * m;
    double *A = calloc(a, sizeof(double)), *B = calloc(b, sizeof(double));
    double *Af = malloc(a * sizeof(double)), *Bf = malloc(b * sizeof(double));
    double *work = malloc(a * sizeof(double)), *X = malloc(b * sizeof(double));
    sinew_result r = SINEW_OK;
    if (!A || !B || !Af || !Bf || !work || !X) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    normal_equations(F, C, 0, T, nf, m, 1, A, B);
    double scale = 0;
    for (int32_t i = 0; i < nf; ++i)
        scale += A[(size_t)i * nf + i] / nf;
    double best = INFINITY;
    *ridge = k_ridges[0];
    for (size_t l = 0; l < sizeof k_ridges / sizeof k_ridges[0] && T >= SW_LOD_FOLDS; ++l) {
        double e = 0;
        for (int32_t f = 0; f < SW_LOD_FOLDS; ++f) {
            int32_t t0 = (int32_t)((int64_t)T * f / SW_LOD_FOLDS);
            int32_t t1 = (int32_t)((int64_t)T * (f + 1) / SW_LOD_FOLDS);
            memcpy(Af, A, a * sizeof(double));
            memcpy(Bf, B, b * sizeof(double));
            normal_equations(F, C, t0, t1, nf, m, -1, Af, Bf);
            e += ridge_solve(Af, Bf, nf, m, k_ridges[l] * scale, work, X)
                     ? misfit(F, C, X, t0, t1, nf, m)
                     : INFINITY;
        }
        if (e < best) best = e, *ridge = k_ridges[l];
    }
    if (!ridge_solve(A, B, nf, m, *ridge * scale + 1e-300, work, X)) {
        r = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                         "pose-space level: the regression's system is singular");
        goto done;
    }
    for (int32_t j = 0; j < m; ++j)
        for (int32_t i = 0; i < nf; ++i)
            W[(size_t)j * nf + i] = X[(size_t)i * m + j];
done:
    free(A), free(B), free(Af), free(Bf), free(work), free(X);
    return r;
}

/* The modes of D (T x n3, destroyed) and their map from the training poses' features F
 * (T x nf) into the view. */
static sinew_result modes(sw_bake_result *out, double *D, const double *F, int32_t T, size_t n3,
                          int32_t nf, sw_error *err) {
    sw_blob_view *view = &out->view;
    const int32_t k = (int32_t)((size_t)T < n3 ? (size_t)T : n3);
    double *S = malloc(sizeof(double) * (size_t)k), *U = malloc(sizeof(double) * (size_t)T * k);
    double *VT = malloc(sizeof(double) * (size_t)k * n3);
    if (!S || !U || !VT) {
        free(S), free(U), free(VT);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    lapack_int info = LAPACKE_dgesdd(LAPACK_ROW_MAJOR, 'S', T, (lapack_int)n3, D, (lapack_int)n3, S,
                                     U, k, VT, (lapack_int)n3);
    sinew_result r = SINEW_OK;
    if (info != 0) {
        r = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                         "pose-space level: the displacements' SVD failed (info %d)", (int)info);
    } else {
        double total = 0, kept = 0;
        for (int32_t j = 0; j < k; ++j)
            total += S[j] * S[j];
        const double tol = SW_LOD_TOL;
        int32_t m = 0;
        while (m < k && m < SINEW_BLOB_LOD_MAX_RANK &&
               (m == 0 || total - kept > tol * tol * total)) {
            kept += S[m] * S[m];
            ++m;
        }
        out->lod_kept = total > 0 ? sqrt(fmax(total - kept, 0) / total) : 0;
        float *B = sw_bake_own(out, malloc(sizeof(float) * n3 * (size_t)m + 1));
        double *W = sw_bake_own(out, malloc(sizeof(double) * (size_t)nf * m + 1));
        double *C = malloc(sizeof(double) * (size_t)T * m + 1);
        if (!B || !W || !C) {
            r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
        } else {
            for (size_t i = 0; i < n3 * (size_t)m; ++i) /* the modes, one after another */
                B[i] = (float)VT[i];
            for (int32_t t = 0; t < T; ++t)
                for (int32_t j = 0; j < m; ++j)
                    C[(size_t)t * m + j] = U[(size_t)t * k + j] * S[j];
            r = regress(F, C, T, nf, m, W, &out->lod_ridge, err);
            view->lod_rank = m;
            view->lod_basis = B;
            view->lod_map = W;
        }
        free(C);
    }
    free(S), free(U), free(VT);
    return r;
}

/* The held-out error of every level on the output surface (sw_eval_result.surface_error). */
static sinew_result level_errors(sw_bake_result *out, sw_error *err) {
    void *mem = NULL;
    sinew_blob *blob = NULL;
    sinew_result r = sw_bake_result_blob(out, &mem, &blob, err);
    for (int l = 0; l < SW_BAKE_LODS && r == SINEW_OK; ++l) {
        sw_eval_result e;
        r = sw_bake_heldout_level_error(blob, out, (sinew_lod)l, &e, err);
        out->lod_heldout[l] = e.failed > 0 || e.frames == 0 ? NAN : e.surface_error;
    }
    sinew_blob_destroy(blob);
    free(mem);
    return r;
}

sinew_result sw_bake_lod(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    (void)s;
    sw_blob_view *view = &out->view;
    for (int l = 0; l < SW_BAKE_LODS; ++l)
        out->lod_heldout[l] = NAN;
    view->lod_rank = view->nlod_verts = 0; /* the blob the table is measured on: none yet */
    const int32_t n = sw_blob_output_verts(view), T = view->ntrain;
    if (out->ntrain < T || T < 1) return SINEW_OK; /* no transform for every training pose */
    const size_t n3 = 3 * (size_t)n;
    double *rest = sw_bake_own(out, malloc(sizeof(double) * n3 + 1));
    double *w = sw_bake_own(out, malloc(sizeof(double) * 4 * (size_t)n + 1));
    int32_t *bone = sw_bake_own(out, malloc(sizeof(int32_t) * 4 * (size_t)n + 1));
    const int32_t nf = SW_POSE_ROTATION_FEATURES(view->nbones);
    double *D = malloc(sizeof(double) * n3 * (size_t)T + 1);
    double *F = malloc(sizeof(double) * (size_t)nf * T + 1);
    if (!rest || !w || !bone || !D || !F) {
        free(D), free(F);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    sw_output_from_full(view, view->rest, rest);
    for (int32_t i = 0; i < n; ++i)
        output_influences(view, i, bone + 4 * i, w + 4 * i);
    void *mem = NULL;
    sinew_blob *blob = NULL;
    sinew_result r = sw_bake_result_blob(out, &mem, &blob, err);
    if (r == SINEW_OK) r = displacements(blob, out, rest, bone, w, D, F, err);
    sinew_blob_destroy(blob);
    free(mem);
    if (r == SINEW_OK) r = modes(out, D, F, T, n3, nf, err);
    free(D), free(F);
    if (r != SINEW_OK) return r;
    view->nlod_verts = n;
    view->lod_rest = rest;
    view->lod_bone = bone;
    view->lod_weight = w;
    return level_errors(out, err);
}
