#include "reduced_map.h"

#include <string.h>

void sw_reduced_bind_active(sw_reduced *m, const sw_active_map *a) {
    m->nact = a->nact;
    m->nact_step = a->nact_step;
    m->act_vert = a->act_vert;
    m->cub_act = a->cub_act;
    m->ncorner = a->ncorner;
    m->corner_begin = a->corner_begin;
    m->corner_lv = a->corner_lv;
    m->corner_act = a->corner_act;
    m->cub_corner = a->cub_corner;
    m->copy_act = a->copy_act;
    m->contact_act = a->contact_act;
    m->node_copy_act = a->node_copy_act;
}

void sw_reduced_skin(sw_reduced *m, const sw_dualquat *bone_dq) {
    const sw_blob_view *v = m->v;
    m->bone_dq = bone_dq;
    for (int32_t a = 0; a < (m->skin_surface ? m->nact : m->nact_step); ++a) {
        int32_t gv = m->act_vert[a];
        sw_dqs_blend(bone_dq, v->skin_bone + 4 * gv, v->skin_weight + 4 * gv, 4, m->act_R + 9 * a,
                     m->act_t + 3 * a);
    }
}

void sw_reduced_jacobian(const sw_reduced *m, const sw_blob_domain *D, int32_t lv, int32_t a,
                         double *J) {
    int32_t r = D->rank;
    const double *U = m->v->basis + D->basis_offset + (int64_t)3 * lv * r;
    const double *Rm = m->act_R + 9 * a;
    for (int i = 0; i < 3; ++i)
        for (int32_t j = 0; j < r; ++j)
            J[i * r + j] =
                Rm[3 * i] * U[j] + Rm[3 * i + 1] * U[r + j] + Rm[3 * i + 2] * U[2 * r + j];
}

/* x = R y + t with the skinning transform of active vertex a. */
static void skin_point(const sw_reduced *m, int32_t a, const double y[3], double x[3]) {
    const double *Rm = m->act_R + 9 * a, *t = m->act_t + 3 * a;
    for (int i = 0; i < 3; ++i)
        x[i] = Rm[3 * i] * y[0] + Rm[3 * i + 1] * y[1] + Rm[3 * i + 2] * y[2] + t[i];
}

/* The copy's basis rows and its rest position. */
static const double *copy_rows(const sw_blob_view *v, const sw_blob_domain *D, int32_t lv,
                               double y[3]) {
    const double *X = v->rest + 3 * (int64_t)v->domain_verts[D->vert_begin + lv];
    y[0] = X[0], y[1] = X[1], y[2] = X[2];
    return v->basis + D->basis_offset + (int64_t)3 * lv * D->rank;
}

void sw_reduced_position(const sw_reduced *m, const sw_blob_domain *D, int32_t lv, int32_t a,
                         const double *qd, double x[3], double *J) {
    int32_t r = D->rank;
    double y[3];
    const double *U = copy_rows(m->v, D, lv, y);
    /* the three rows' sums run side by side: three independent add chains instead of one
     * after another (each row still sums in j order, so the result is bitwise the same) */
    const double *U0 = U, *U1 = U + r, *U2 = U + 2 * r;
    for (int32_t j = 0; qd && j < r; ++j) { /* qd NULL: q = 0 */
        y[0] += U0[j] * qd[j];
        y[1] += U1[j] * qd[j];
        y[2] += U2[j] * qd[j];
    }
    skin_point(m, a, y, x);
    if (J) sw_reduced_jacobian(m, D, lv, a, J);
}

void sw_reduced_position_pair(const sw_reduced *m, const sw_blob_domain *D, const int32_t lv[2],
                              const int32_t a[2], const double *qd, double x0[3], double x1[3]) {
    int32_t r = D->rank;
    double y[3], z[3];
    const double *U = copy_rows(m->v, D, lv[0], y), *V = copy_rows(m->v, D, lv[1], z);
    const double *U0 = U, *U1 = U + r, *U2 = U + 2 * r, *V0 = V, *V1 = V + r, *V2 = V + 2 * r;
    for (int32_t j = 0; j < r; ++j) {
        y[0] += U0[j] * qd[j];
        y[1] += U1[j] * qd[j];
        y[2] += U2[j] * qd[j];
        z[0] += V0[j] * qd[j];
        z[1] += V1[j] * qd[j];
        z[2] += V2[j] * qd[j];
    }
    skin_point(m, a[0], y, x0);
    skin_point(m, a[1], z, x1);
}

/* Block (a, b) of A and its row step; NULL for a block the blob does not store. */
static const double *src_block(const sw_blob_view *v, sw_block_src A, int32_t a, int32_t b,
                               int64_t *ld) {
    if (!A.dense) return sw_blob_block(v, A.blob_matrix, a, b, ld);
    *ld = v->rank_total;
    return A.dense + (int64_t)v->domains[a].q_offset * v->rank_total + v->domains[b].q_offset;
}

void sw_reduced_blocks_matvec(const sw_blob_view *v, sw_block_src A, const unsigned char *A_nz,
                              const double *x, double *y) {
    const int32_t nd = v->ndomains;
    for (int32_t a = 0; a < nd; ++a) {
        const sw_blob_domain *Da = &v->domains[a];
        for (int32_t i = 0; i < Da->rank; ++i) {
            double acc = 0;
            for (int32_t b = 0; b < nd; ++b) {
                if (a != b && (!A_nz || !A_nz[a * nd + b])) continue;
                int64_t ld;
                const double *B = src_block(v, A, a, b, &ld);
                if (!B) continue;
                const double *Bi = B + i * ld, *xb = x + v->domains[b].q_offset;
                for (int32_t j = 0; j < v->domains[b].rank; ++j)
                    acc += Bi[j] * xb[j];
            }
            y[Da->q_offset + i] = acc;
        }
    }
}

void sw_reduced_blocks_copy(const sw_blob_view *v, double *dst, unsigned char *dst_nz,
                            sw_block_src src, const unsigned char *src_nz) {
    const int32_t nd = v->ndomains;
    const int64_t R = v->rank_total;
    for (int32_t a = 0; a < nd; ++a) {
        const sw_blob_domain *Da = &v->domains[a];
        for (int32_t b = 0; b < nd; ++b) {
            int from = a == b || src_nz[a * nd + b];
            if (!from && !dst_nz[a * nd + b]) continue;
            const sw_blob_domain *Db = &v->domains[b];
            int64_t ld = 0;
            const double *B = from ? src_block(v, src, a, b, &ld) : NULL;
            size_t bytes = (size_t)Db->rank * sizeof(double);
            for (int32_t i = 0; i < Da->rank; ++i) {
                double *d = dst + (Da->q_offset + i) * R + Db->q_offset;
                if (B)
                    memcpy(d, B + i * ld, bytes);
                else
                    memset(d, 0, bytes);
            }
        }
    }
    memcpy(dst_nz, src_nz, (size_t)nd * nd);
}

void sw_reduced_take(sw_mem_plan *p, const sw_blob_view *v, int32_t rmax, int32_t nworkers,
                     sw_reduced *m) {
    const uint64_t rm = (uint64_t)rmax;
    SW_PLAN_TAKE(p, m->g, (uint64_t)v->rank_total);
    SW_PLAN_TAKE(p, m->hm, 10 * rm * (uint64_t)nworkers);
    SW_PLAN_TAKE(p, m->Jc, 12 * rm);
    SW_PLAN_TAKE(p, m->hc, 12 * rm);
    SW_PLAN_TAKE(p, m->svd_V, 9 * (uint64_t)v->ncub);
}
