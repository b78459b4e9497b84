/* sinew-bench --error-gap (gap_bench.h). */
#include "gap_bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "condense.h"
#include "cubature.h"
#include "fem_corot.h"
#include "instance.h"
#include "instance_internal.h"
#include "pose_contact.h"

/* The terms of the step's energy at q (gap_bench.h's rt/proj order). */
static void terms(sinew_instance *in, const double *q, double o[4]) {
    const sw_blob_view *v = in->v;
    o[0] = sw_cubature_eval(&in->red, q, 0, 0);
    o[1] = 0;
    for (int32_t t = 0; t < v->ntets; ++t) {
        double x[12], dm[9];
        for (int k = 0; k < 4; ++k)
            sw_cond_copy_position(&in->red, v->tets[4 * (int64_t)t + k], v->tet_domain[t],
                                  v->tet_local[4 * (int64_t)t + k], q, x + 3 * k, NULL);
        const double st = sw_blob_stiffness(v->tet_stiffness, t);
        o[1] += sw_corot_eval(x, sw_blob_tet_dminv(v, t, dm), v->tet_vol[t], st * v->mu,
                              st * v->lambda, NULL, NULL, 0);
    }
    o[2] = sw_pose_contact_eval(&in->red, &in->ps, q, 0, 0);
    if (in->self_mode == SINEW_SELF_CONTACT_EXHAUSTIVE) {
        sw_pair_set set = sw_self_contacts_pairs(&in->sc);
        o[2] +=
            sw_contact_pairs_eval(&in->red, &set, NULL, NULL, in->sc.npairs, NULL, NULL, q, 0, 0);
    }
    o[3] = 0;
    for (int32_t a = 0; a < v->ndomains; ++a)
        for (int32_t b = 0; b < v->ndomains; ++b) {
            int64_t ld;
            const double *B = sw_blob_block(v, SW_BLOB_SPRINGS, a, b, &ld);
            const double *qa = q + v->domains[a].q_offset, *qb = q + v->domains[b].q_offset;
            for (int32_t i = 0; B && i < v->domains[a].rank; ++i)
                for (int32_t j = 0; j < v->domains[b].rank; ++j)
                    o[3] += 0.5 * qa[i] * B[i * ld + j] * qb[j];
        }
}

/* q = U^T d per domain, d the un-skinned displacement of x (3 nverts) at the instance's
 * pose (eq. 4.13 solved for the correction). */
static void project(const sinew_instance *in, const double *x, double *q) {
    const sw_blob_view *v = in->v;
    memset(q, 0, (size_t)v->rank_total * sizeof(double));
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank;
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            int32_t gv = v->domain_verts[D->vert_begin + lv];
            double R[9], t[3], e[3], d[3], xs[3];
            sw_dqs_blend(in->bone_dq, v->skin_bone + 4 * (int64_t)gv,
                         v->skin_weight + 4 * (int64_t)gv, 4, R, t);
            sw_instance_to_step(in, x + 3 * (int64_t)gv, 0, xs); /* the skinning's frame */
            for (int i = 0; i < 3; ++i)
                e[i] = xs[i] - t[i];
            for (int i = 0; i < 3; ++i)
                d[i] =
                    R[i] * e[0] + R[3 + i] * e[1] + R[6 + i] * e[2] - v->rest[3 * (int64_t)gv + i];
            const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r;
            for (int i = 0; i < 3; ++i)
                for (int32_t c = 0; c < r; ++c)
                    q[D->q_offset + c] += U[i * r + c] * d[i];
        }
    }
}

/* One pose set (npose poses T, solutions X of the poses after the first `skip`, which
 * are stepped but not measured) stepped in order on a fresh instance. */
static sinew_result run_set(const sinew_blob *blob, const double *mass, const double *T,
                            const double *X, int32_t npose, int32_t skip, sinew_self_contact sc,
                            sw_gap_set *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    sinew_instance_def d = sinew_instance_def_default();
    d.max_newton_iters = SW_BAKE_EVAL_NEWTON;
    d.self_contact = sc;
    sinew_instance *in;
    sinew_result r = sinew_instance_create(blob, &d, &in);
    if (r != SINEW_OK) return sw_error_set(err, r, "--error-gap: cannot create an instance");
    int32_t R = v->rank_total, nb = v->nbones, nv = v->nverts;
    double *qp = malloc(sizeof(double) * R), *qr = malloc(sizeof(double) * R);
    sw_eval_acc art, apr;
    int acc = sw_eval_acc_init(&art, blob, mass, err) == SINEW_OK;
    acc += sw_eval_acc_init(&apr, blob, mass, err) == SINEW_OK;
    if (!qp || !qr || acc < 2) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--error-gap: out of memory");
        goto done;
    }
    for (int32_t j = 0; j < npose; ++j) {
        if (sw_instance_set_pose_d(in, T + (size_t)j * 12 * nb) != SINEW_OK ||
            sinew_instance_step(in, 1.0f / 30) != SINEW_OK || j < skip)
            continue; /* the path before the measured poses, or a failed step (sinew-bench's
                         failed_steps counts it already) */
        const double *xf = X + (size_t)(j - skip) * 3 * nv;
        memcpy(qr, sw_instance_q(in), sizeof(double) * R);
        sw_eval_acc_add(&art, in, xf);
        project(in, xf, qp);
        double er = sw_instance_step_potential(in, 1.0f / 30, qr, NULL, NULL, 0),
               ep = sw_instance_step_potential(in, 1.0f / 30, qp, NULL, NULL, 0), tr[4], tp[4];
        out->projection_higher += ep > er;
        terms(in, qr, tr);
        terms(in, qp, tp);
        for (int k = 0; k < 4; ++k) {
            out->rt[k] += tr[k];
            out->proj[k] += tp[k];
        }
        sw_instance_set_q(in, qp);
        sw_eval_acc_add(&apr, in, xf);
        sw_instance_set_q(in, qr);
        out->poses++;
    }
    sw_eval_result a, b;
    sw_eval_acc_result(&art, &a);
    sw_eval_acc_result(&apr, &b);
    out->err_runtime = a.correction_error;
    out->err_projection = b.correction_error;
done: /* (a failed init leaves its sums zeroed: freeing them is a no-op) */
    sw_eval_acc_free(&art);
    sw_eval_acc_free(&apr);
    free(qp);
    free(qr);
    sinew_instance_destroy(in);
    return r;
}

sinew_result sw_gap_bench_run(const sinew_blob *blob, const sw_bake_result *res,
                              sinew_self_contact sc, sw_gap_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || v->ntets == 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "--error-gap needs a blob with the tet mesh (bake it again)");
    int32_t pre, n; /* the held-out poses on the reference's path, as sw_bake_errors */
    double *T = sw_bake_heldout_path(res, v->nbones, &pre, &n);
    if (!T) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--error-gap: out of memory");
    sinew_result r = run_set(blob, res->mass, T, res->heldout_x, n, pre, sc, &out->heldout, err);
    free(T);
    if (r == SINEW_OK)
        r = run_set(blob, res->mass, res->train_T, res->train_x, res->ntrain, 0, sc, &out->train,
                    err);
    return r;
}

void sw_gap_bench_print(const sw_gap_bench *g, FILE *f, int json) {
    static const char *const name[4] = {"cubature", "exact", "contact", "springs"};
    const sw_gap_set *set[2] = {&g->heldout, &g->train};
    static const char *const tag[2] = {"", "train_"};
    for (int k = 0; k < 2; ++k) {
        const sw_gap_set *s = set[k];
        if (json) {
            fprintf(f,
                    ",\"gap_%sposes\":%d,\"gap_%serr_runtime\":%.5f,\"gap_%serr_projection\":%.5f,"
                    "\"gap_%sprojection_higher\":%d",
                    tag[k], s->poses, tag[k], s->err_runtime, tag[k], s->err_projection, tag[k],
                    s->projection_higher);
            for (int t = 0; t < 4; ++t)
                fprintf(f, ",\"gap_%srt_%s\":%.6g,\"gap_%sproj_%s\":%.6g", tag[k], name[t],
                        s->rt[t], tag[k], name[t], s->proj[t]);
            continue;
        }
        fprintf(f,
                "sinew-bench: error gap over %d %s poses: runtime %.4f, projection %.4f; the "
                "reduced energy is higher at the projection in %d; energy terms summed (runtime / "
                "projection):",
                s->poses, k ? "training" : "held-out", s->err_runtime, s->err_projection,
                s->projection_higher);
        for (int t = 0; t < 4; ++t)
            fprintf(f, " %s %.5g / %.5g%s", name[t], s->rt[t], s->proj[t], t < 3 ? "," : "\n");
    }
}
