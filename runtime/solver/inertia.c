#include "inertia.h"

#include <math.h>
#include <string.h>

/* Body-frame angular velocity of the rotation from Ra to Rb over h: log(Ra^T Rb) / h. */
static void angular_velocity(const double *Ta, const double *Tb, double h, double w[3]) {
    double M[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            M[3 * i + j] = Ta[i] * Tb[j] + Ta[3 + i] * Tb[3 + j] + Ta[6 + i] * Tb[6 + j];
    double c = 0.5 * (M[0] + M[4] + M[8] - 1.0);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    double th = acos(c), s = sin(th);
    double k = th < 1e-8 ? 0.5 : (s > 1e-8 ? th / (2 * s) : 0.0);
    w[0] = k * (M[7] - M[5]) / h;
    w[1] = k * (M[2] - M[6]) / h;
    w[2] = k * (M[3] - M[1]) / h;
}

void sw_inertial_forces(const sw_blob_view *v, const sw_pose_history *ph, sw_solver *s, double h) {
    memset(s->fin, 0, (size_t)v->rank_total * sizeof(double));
    if (ph->history < 1) return;
    const double hp = ph->history >= 2 ? ph->h_prev : h;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t b = D->bone, r = D->rank, o = D->q_offset;
        const double *Tc = ph->T_cur + 12 * b, *Tp = ph->T_prev + 12 * b,
                     *Tq = ph->T_prev2 + 12 * b;
        double acc[3], c[3], w1[3], w0[3], al[3];
        for (int i = 0; i < 3; ++i) {
            if (ph->history < 2)
                acc[i] = 0.0;
            else if (hp == h) /* the uniform formula, bitwise as before */
                acc[i] = (Tc[9 + i] - 2 * Tp[9 + i] + Tq[9 + i]) / (h * h);
            else
                acc[i] = ((Tc[9 + i] - Tp[9 + i]) / h - (Tp[9 + i] - Tq[9 + i]) / hp) / h;
        }
        for (int i = 0; i < 3; ++i)
            c[i] = Tc[i] * acc[0] + Tc[3 + i] * acc[1] + Tc[6 + i] * acc[2];
        angular_velocity(Tp, Tc, h, w1);
        if (ph->history >= 2)
            angular_velocity(Tq, Tp, hp, w0);
        else
            memcpy(w0, w1, sizeof w0);
        for (int i = 0; i < 3; ++i)
            al[i] = (w1[i] - w0[i]) / h;
        double W[9] = {0, -w1[2], w1[1], w1[2], 0, -w1[0], -w1[1], w1[0], 0};
        double A[9] = {0, -al[2], al[1], al[2], 0, -al[0], -al[1], al[0], 0};
        for (int i = 0; i < 3; ++i) /* A = [alpha]x + [w]x^2 */
            for (int j = 0; j < 3; ++j)
                A[3 * i + j] += W[3 * i] * W[j] + W[3 * i + 1] * W[3 + j] + W[3 * i + 2] * W[6 + j];
        const double *P = v->inertia_u + D->inertia_offset;
        for (int32_t i = 0; i < r; ++i) {
            double f = 0;
            for (int a = 0; a < 3; ++a)
                f += v->inertia_s[3 * (o + i) + a] * c[a];
            for (int ab = 0; ab < 9; ++ab) {
                if (A[ab] == 0 && W[ab] == 0) continue;
                const double *Pab = P + (int64_t)ab * r * r + (int64_t)i * r;
                double pq = 0, pqd = 0;
                for (int32_t j = 0; j < r; ++j) {
                    pq += Pab[j] * s->qn[o + j];
                    pqd += Pab[j] * s->qdot[o + j];
                }
                f += A[ab] * (v->inertia_x[9 * (o + i) + ab] + pq) + 2 * W[ab] * pqd;
            }
            s->fin[o + i] = -f;
        }
    }
}

unsigned sw_pose_jump(const sw_blob_view *v, const sw_pose_history *ph, const double *ball,
                      double size, double h) {
    unsigned why = 0;
    for (int32_t b = 0; b < v->nbones; ++b) {
        const double *Tc = ph->T_cur + 12 * b, *Tp = ph->T_prev + 12 * b, *c = ball + 4 * b;
        if (c[3] < 0) continue; /* skins nothing */
        double s2 = 0, m[3];
        for (int i = 0; i < 9; ++i) /* |R_cur - R_prev|_F^2 = 8 sin^2(theta / 2) */
            s2 += (Tc[i] - Tp[i]) * (Tc[i] - Tp[i]);
        for (int i = 0; i < 3; ++i) /* the ball centre's motion */
            m[i] = (Tc[3 * i] - Tp[3 * i]) * c[0] + (Tc[3 * i + 1] - Tp[3 * i + 1]) * c[1] +
                   (Tc[3 * i + 2] - Tp[3 * i + 2]) * c[2] + Tc[9 + i] - Tp[9 + i];
        double sh = sqrt(s2 / 8), theta = 2 * asin(sh < 1 ? sh : 1), /* |dR|_2 = 2 sin */
            d = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) + 2 * sh * c[3];
        if (s2 > 6.0) why |= SW_JUMP_ANGLE; /* cos theta < -1/2: > 120 degrees */
        if (d > 0.5 * size) why |= SW_JUMP_DISTANCE;
        if (theta > SW_JUMP_MAX_SPIN * h || d > SW_JUMP_MAX_SPIN * size * h) why |= SW_JUMP_SPEED;
    }
    return why;
}

void sw_pose_history_advance(sw_pose_history *ph, int32_t nbones, double h) {
    memcpy(ph->T_prev2, ph->T_prev, 12 * (size_t)nbones * sizeof(double));
    memcpy(ph->T_prev, ph->T_cur, 12 * (size_t)nbones * sizeof(double));
    if (ph->history < 2) ph->history++;
    ph->h_prev = h;
}
