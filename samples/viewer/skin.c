/* Plain skinning on the CPU, as the engine draws a character without sinew: linear blend
 * or dual quaternions of the bones' transforms, from the asset's own weights. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "viewer.h"

/* Unit quaternion (w, x, y, z) of a bone transform's rotation (its uniform scale removed). */
static void mat_quat(const float *T, float *q) {
    double s = cbrt(fabs((double)T[0] * (T[4] * T[8] - T[5] * T[7]) -
                         (double)T[1] * (T[3] * T[8] - T[5] * T[6]) +
                         (double)T[2] * (T[3] * T[7] - T[4] * T[6])));
    double R[9], qd[4];
    for (int k = 0; k < 9; ++k)
        R[k] = s > 0 ? T[k] / s : (k % 4 == 0);
    vw_quat_from_matrix(R, qd);
    for (int k = 0; k < 4; ++k)
        q[k] = (float)qd[k];
}

static void qrot(const float *q, const float *v, float *o) {
    /* v + 2 w (u x v) + 2 u x (u x v) */
    float u[3] = {q[1], q[2], q[3]}, t[3];
    t[0] = 2 * (u[1] * v[2] - u[2] * v[1]);
    t[1] = 2 * (u[2] * v[0] - u[0] * v[2]);
    t[2] = 2 * (u[0] * v[1] - u[1] * v[0]);
    o[0] = v[0] + q[0] * t[0] + (u[1] * t[2] - u[2] * t[1]);
    o[1] = v[1] + q[0] * t[1] + (u[2] * t[0] - u[0] * t[2]);
    o[2] = v[2] + q[0] * t[2] + (u[0] * t[1] - u[1] * t[0]);
}

static void skin_dqs(const vw_asset *a, const float *T, float *pos) {
    float q[VW_MAX_BONES][4], scale[VW_MAX_BONES];
    for (int32_t b = 0; b < a->nbones; ++b) {
        const float *M = T + 12 * b;
        scale[b] =
            cbrtf(fabsf(M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                        M[2] * (M[3] * M[7] - M[4] * M[6])));
        mat_quat(M, q[b]);
    }
    for (int32_t v = 0; v < a->nverts; ++v) {
        const int32_t *wb = a->wbone + 4 * v;
        const float *ww = a->wgt + 4 * v, *q0 = q[wb[0]];
        float r[4] = {0}, d[4] = {0}, s = 0; /* real and dual parts */
        for (int k = 0; k < 4; ++k) {
            if (ww[k] == 0) continue;
            const float *qb = q[wb[k]], *t = T + 12 * wb[k] + 9;
            float sg =
                qb[0] * q0[0] + qb[1] * q0[1] + qb[2] * q0[2] + qb[3] * q0[3] < 0 ? -ww[k] : ww[k];
            /* dual part: 0.5 (0, t) q */
            float dq[4] = {0.5f * (-t[0] * qb[1] - t[1] * qb[2] - t[2] * qb[3]),
                           0.5f * (t[0] * qb[0] + t[1] * qb[3] - t[2] * qb[2]),
                           0.5f * (-t[0] * qb[3] + t[1] * qb[0] + t[2] * qb[1]),
                           0.5f * (t[0] * qb[2] - t[1] * qb[1] + t[2] * qb[0])};
            for (int c = 0; c < 4; ++c)
                r[c] += sg * qb[c], d[c] += sg * dq[c];
            s += ww[k] * scale[wb[k]];
        }
        float n = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
        if (!(n > 0)) n = 1;
        for (int c = 0; c < 4; ++c)
            r[c] /= n, d[c] /= n;
        /* translation 2 d r*, rotation r applied to the scaled rest position */
        float tt[3] = {2 * (-d[0] * r[1] + d[1] * r[0] - d[2] * r[3] + d[3] * r[2]),
                       2 * (-d[0] * r[2] + d[1] * r[3] + d[2] * r[0] - d[3] * r[1]),
                       2 * (-d[0] * r[3] - d[1] * r[2] + d[2] * r[1] + d[3] * r[0])};
        float x[3] = {s * a->rest[3 * v], s * a->rest[3 * v + 1], s * a->rest[3 * v + 2]}, o[3];
        qrot(r, x, o);
        for (int c = 0; c < 3; ++c)
            pos[3 * v + c] = o[c] + tt[c];
    }
}

void vw_skin(const vw_asset *a, const float *T, int dqs, float *pos, float *nrm) {
    if (dqs) {
        skin_dqs(a, T, pos);
    } else {
        for (int32_t v = 0; v < a->nverts; ++v) {
            const float *x = a->rest + 3 * v;
            float o[3] = {0, 0, 0};
            for (int k = 0; k < 4; ++k) {
                float w = a->wgt[4 * v + k];
                if (w == 0) continue;
                const float *M = T + 12 * a->wbone[4 * v + k];
                for (int r = 0; r < 3; ++r)
                    o[r] += w * (M[3 * r] * x[0] + M[3 * r + 1] * x[1] + M[3 * r + 2] * x[2] +
                                 M[9 + r]);
            }
            memcpy(pos + 3 * v, o, sizeof o);
        }
    }
    if (nrm) vw_normals(pos, a->nverts, a->tris, a->ntris, a->weld, nrm);
}

static const float *weld_pos;

static int by_position(const void *pa, const void *pb) {
    const float *a = weld_pos + 3 * *(const int32_t *)pa, *b = weld_pos + 3 * *(const int32_t *)pb;
    for (int k = 0; k < 3; ++k)
        if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
    return *(const int32_t *)pa - *(const int32_t *)pb;
}

int vw_asset_weld(vw_asset *a) {
    int32_t *order = malloc(sizeof(int32_t) * (size_t)a->nverts);
    a->weld = malloc(sizeof(int32_t) * (size_t)a->nverts);
    if (!order || !a->weld) return free(order), 0;
    for (int32_t v = 0; v < a->nverts; ++v)
        order[v] = v;
    weld_pos = a->rest; /* (load time, one thread) */
    qsort(order, (size_t)a->nverts, sizeof *order, by_position);
    for (int32_t k = 0, first = 0; k < a->nverts; ++k) {
        if (k && memcmp(a->rest + 3 * order[k], a->rest + 3 * order[k - 1], 3 * sizeof(float)))
            first = k;
        a->weld[order[k]] = order[first];
    }
    free(order);
    return 1;
}

void vw_normals(const float *pos, int32_t nverts, const uint32_t *tris, int32_t ntris,
                const int32_t *weld, float *nrm) {
    memset(nrm, 0, sizeof(float) * 3 * (size_t)nverts);
    for (int32_t t = 0; t < ntris; ++t) {
        const float *p0 = pos + 3 * tris[3 * t], *p1 = pos + 3 * tris[3 * t + 1],
                    *p2 = pos + 3 * tris[3 * t + 2];
        float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]},
              e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k)
                nrm[3 * (weld ? weld[tris[3 * t + c]] : (int32_t)tris[3 * t + c]) + k] += n[k];
    }
    for (int32_t v = 0; weld && v < nverts; ++v)
        if (weld[v] != v) memcpy(nrm + 3 * v, nrm + 3 * weld[v], 3 * sizeof(float));
    for (int32_t v = 0; v < nverts; ++v) {
        float *n = nrm + 3 * v, l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (l > 0) n[0] /= l, n[1] /= l, n[2] /= l;
    }
}
