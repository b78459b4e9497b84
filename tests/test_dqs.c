/* Dual-quaternion skinning (runtime/math/dqs.c): exact single-bone reproduction, the
 * antipodality fix, intermediate rotations, orthonormality under random blends, the
 * translation-only and candy-wrapper cases, and sw_dqs_skin against sw_dqs_blend. */
#include "sw_test.h"

#include <stdint.h>

#include "dqs.h"
#include "sw_mesh.h"

#define PI 3.14159265358979323846

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static double urand(void) { /* uniform in [0, 1) (xorshift64*) */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

static void random_axis(double a[3]) {
    double n;
    do {
        for (int i = 0; i < 3; ++i)
            a[i] = 2.0 * urand() - 1.0;
        n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    } while (n < 0.1 || n > 1.0);
    for (int i = 0; i < 3; ++i)
        a[i] /= n;
}

/* Rodrigues: R = I + sin(th) K + (1 - cos(th)) K^2 for the unit axis a. */
static void axis_angle(const double a[3], double th, double R[9]) {
    double K[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0}, K2[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            K2[3 * i + j] = K[3 * i] * K[j] + K[3 * i + 1] * K[3 + j] + K[3 * i + 2] * K[6 + j];
    for (int i = 0; i < 9; ++i)
        R[i] = (i % 4 == 0 ? 1.0 : 0.0) + sin(th) * K[i] + (1.0 - cos(th)) * K2[i];
}

static void random_transform(double T[12], double angle) {
    double a[3];
    random_axis(a);
    axis_angle(a, angle, T);
    for (int i = 0; i < 3; ++i)
        T[9 + i] = 10.0 * (2.0 * urand() - 1.0);
}

static double max_diff(const double *a, const double *b, int n) {
    double m = 0;
    for (int i = 0; i < n; ++i)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* max |R^T R - I| and det R. */
static double orthonormality_error(const double R[9]) {
    double e = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double s = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j];
            e = fmax(e, fabs(s - (i == j ? 1.0 : 0.0)));
        }
    return e;
}

static double det3(const double A[9]) {
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

static void apply(const double R[9], const double t[3], const double p[3], double out[3]) {
    for (int i = 0; i < 3; ++i)
        out[i] = R[3 * i] * p[0] + R[3 * i + 1] * p[1] + R[3 * i + 2] * p[2] + t[i];
}

TEST(single_influence_reproduces_transform) {
    /* Random angles, exact 180-degree turns about random and coordinate axes (trace -1:
     * w = 0, where a naive trace-based conversion divides by zero), and the identity. */
    double worst = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        double T[12], R[9], t[3];
        double angle = trial % 3 == 0 ? PI : (trial % 3 == 1 ? PI * urand() : 2 * PI * urand());
        random_transform(T, angle);
        if (trial < 3) { /* 180 degrees about x, y, z: diag with two -1 entries */
            for (int i = 0; i < 9; ++i)
                T[i] = 0;
            for (int i = 0; i < 3; ++i)
                T[4 * i] = i == trial ? 1.0 : -1.0;
        }
        if (trial == 3)
            for (int i = 0; i < 9; ++i)
                T[i] = (i % 4 == 0) ? 1.0 : 0.0;
        sw_dualquat dq;
        sw_dq_from_transform(T, &dq);
        double n =
            sqrt(dq.r[0] * dq.r[0] + dq.r[1] * dq.r[1] + dq.r[2] * dq.r[2] + dq.r[3] * dq.r[3]);
        ENSURE_NEAR(n, 1.0, 1e-14);
        /* A unit dual quaternion has r . d = 0. */
        ENSURE_NEAR(dq.r[0] * dq.d[0] + dq.r[1] * dq.d[1] + dq.r[2] * dq.d[2] + dq.r[3] * dq.d[3],
                    0.0, 1e-13);
        int32_t id = 0;
        double w = 0.7; /* any positive weight: the blend normalises */
        sw_dqs_blend(&dq, &id, &w, 1, R, t);
        double e = fmax(max_diff(R, T, 9), max_diff(t, T + 9, 3)); /* |t| <= 10 */
        worst = fmax(worst, e);
        ENSUREF(e <= 1e-12, "trial %d: single-bone blend differs from T by %g", trial, e);
    }
    printf("single influence: worst |T_blend - T| = %.3g\n", worst);
}

TEST(antipodal_input_matches_identical_input) {
    for (int trial = 0; trial < 200; ++trial) {
        double T0[12], T1[12];
        random_transform(T0, 2 * PI * urand());
        random_transform(T1, 2 * PI * urand());
        sw_dualquat b[3];
        sw_dq_from_transform(T0, &b[0]);
        sw_dq_from_transform(T1, &b[1]);
        /* Bone 2 is bone 1's transform given by the antipodal dual quaternion -q. */
        for (int j = 0; j < 4; ++j) {
            b[2].r[j] = -b[1].r[j];
            b[2].d[j] = -b[1].d[j];
        }
        double w[2] = {urand() + 0.01, urand() + 0.01};
        int32_t same[2] = {0, 1}, flipped[2] = {0, 2};
        double Ra[9], ta[3], Rb[9], tb[3];
        sw_dqs_blend(b, same, w, 2, Ra, ta);
        sw_dqs_blend(b, flipped, w, 2, Rb, tb);
        ENSURE(max_diff(Ra, Rb, 9) <= 1e-13);
        ENSURE(max_diff(ta, tb, 3) <= 1e-12);
        /* And q with -q of the same transform is that transform. */
        int32_t pair[2] = {1, 2};
        sw_dqs_blend(b, pair, w, 2, Ra, ta);
        ENSURE(max_diff(Ra, T1, 9) <= 1e-12);
        ENSURE(max_diff(ta, T1 + 9, 3) <= 1e-11);
    }
}

TEST(same_axis_blend_is_intermediate_rotation) {
    /* Two rotations about one axis through one point c. DQS gives a rotation about that
     * axis through c (c stays fixed) by the nlerp angle phi with
     * tan(phi/2) = (w s1 + (1-w) s2) / (w c1 + (1-w) c2), s = sin(theta/2),
     * c = cos(theta/2): between theta1 and theta2, monotone in w, and exactly the mean
     * angle at w = 1/2 (it is not exactly the weighted angle elsewhere). */
    for (int trial = 0; trial < 100; ++trial) {
        /* |th2 - th1| < pi keeps the two quaternions within 90 degrees (no flip). */
        double a[3], c[3], th1 = 0.9 * PI * (2 * urand() - 1);
        double th2 = th1 + 0.95 * PI * (2 * urand() - 1);
        random_axis(a);
        for (int i = 0; i < 3; ++i)
            c[i] = 5 * (2 * urand() - 1);
        double T[2][12];
        axis_angle(a, th1, T[0]);
        axis_angle(a, th2, T[1]);
        for (int b = 0; b < 2; ++b) { /* t = c - R c: rotation about the line through c */
            double Rc[3], zero[3] = {0, 0, 0};
            apply(T[b], zero, c, Rc);
            for (int i = 0; i < 3; ++i)
                T[b][9 + i] = c[i] - Rc[i];
        }
        sw_dualquat dq[2];
        sw_dq_from_transform(T[0], &dq[0]);
        sw_dq_from_transform(T[1], &dq[1]);
        int32_t ids[2] = {0, 1};
        double prev_phi = -INFINITY;
        for (int s = 0; s <= 10; ++s) {
            double w = s / 10.0, ws[2] = {1 - w, w}, R[9], t[3];
            sw_dqs_blend(dq, ids, ws, 2, R, t);
            double phi = 2 * atan2((1 - w) * sin(th1 / 2) + w * sin(th2 / 2),
                                   (1 - w) * cos(th1 / 2) + w * cos(th2 / 2));
            double Rexp[9], cc[3];
            axis_angle(a, phi, Rexp);
            ENSUREF(max_diff(R, Rexp, 9) <= 1e-12, "trial %d w %g: R off by %g", trial, w,
                    max_diff(R, Rexp, 9));
            apply(R, t, c, cc);
            ENSURE(max_diff(cc, c, 3) <= 1e-11);
            ENSURE(phi >= fmin(th1, th2) - 1e-12 && phi <= fmax(th1, th2) + 1e-12);
            double dir = th2 >= th1 ? phi : -phi; /* monotone from th1 to th2 */
            ENSURE(dir >= prev_phi - 1e-12);
            prev_phi = dir;
            if (s == 5) ENSURE_NEAR(phi, 0.5 * (th1 + th2), 1e-12);
        }
    }
}

TEST(random_blends_are_proper_rotations) {
    enum { NB = 6, K = 4 };
    sw_dualquat dq[NB];
    double worst = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        if (trial % 50 == 0)
            for (int b = 0; b < NB; ++b) {
                double T[12];
                random_transform(T, 2 * PI * urand());
                sw_dq_from_transform(T, &dq[b]);
            }
        int32_t ids[K];
        double w[K], R[9], t[3];
        for (int i = 0; i < K; ++i) {
            ids[i] = (int32_t)(urand() * NB);
            w[i] = urand() < 0.2 ? 0.0 : urand();
        }
        sw_dqs_blend(dq, ids, w, K, R, t);
        double e = orthonormality_error(R);
        worst = fmax(worst, e);
        ENSUREF(e <= 1e-14 && fabs(det3(R) - 1.0) <= 1e-14, "trial %d: |R^T R - I| %g det %.17g",
                trial, e, det3(R));
        ENSURE(isfinite(t[0]) && isfinite(t[1]) && isfinite(t[2]));
    }
    printf("random blends: worst |R^T R - I| = %.3g\n", worst);
}

TEST(translations_only_equal_lbs) {
    enum { NB = 4, N = 50 };
    double T[NB * 12];
    sw_dualquat dq[NB];
    for (int b = 0; b < NB; ++b) {
        for (int i = 0; i < 9; ++i)
            T[12 * b + i] = (i % 4 == 0) ? 1.0 : 0.0;
        for (int i = 0; i < 3; ++i)
            T[12 * b + 9 + i] = 4 * (2 * urand() - 1);
        sw_dq_from_transform(T + 12 * b, &dq[b]);
    }
    double X[3 * N], W[N * NB], x_lbs[3 * N], x_dqs[3 * N], wk[N * NB];
    int32_t ids[N * NB];
    for (int v = 0; v < N; ++v) {
        double s = 0;
        for (int b = 0; b < NB; ++b) {
            W[v * NB + b] = urand();
            s += W[v * NB + b];
        }
        for (int b = 0; b < NB; ++b) {
            W[v * NB + b] /= s;
            ids[v * NB + b] = b;
            wk[v * NB + b] = W[v * NB + b];
        }
        for (int i = 0; i < 3; ++i)
            X[3 * v + i] = 2 * urand() - 1;
    }
    sw_weights weights = {N, NB, W};
    sw_lbs(N, X, &weights, T, x_lbs);
    sw_dqs_skin(N, X, dq, ids, wk, NB, x_dqs);
    ENSUREF(max_diff(x_lbs, x_dqs, 3 * N) <= 1e-13, "DQS vs LBS %g", max_diff(x_lbs, x_dqs, 3 * N));
}

TEST(candy_wrapper_twist_keeps_volume) {
    /* Bone 1 twists 180 degrees about the x axis (the bone axis); a point at radius r
     * blended 0.5/0.5: LBS averages p and its mirror image onto the axis (the collapse
     * of the "candy wrapper"); DQS rotates it by 90 degrees at radius r. */
    double T0[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    double T1[12] = {1, 0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0};
    sw_dualquat dq[2];
    sw_dq_from_transform(T0, &dq[0]);
    sw_dq_from_transform(T1, &dq[1]);
    int32_t ids[2] = {0, 1};
    double w[2] = {0.5, 0.5}, R[9], t[3];
    sw_dqs_blend(dq, ids, w, 2, R, t);
    ENSURE_NEAR(fabs(det3(R)), 1.0, 1e-14);
    ENSURE(orthonormality_error(R) <= 1e-14);
    for (int k = 0; k < 8; ++k) {
        double ang = 2 * PI * k / 8, r = 0.3 + 0.1 * k;
        double p[3] = {1.5, r * cos(ang), r * sin(ang)}, q[3], lbs[3], p1[3];
        apply(R, t, p, q);
        ENSURE_NEAR(hypot(q[1], q[2]), r, 1e-13);
        ENSURE_NEAR(q[0], p[0], 1e-13);
        ENSURE_NEAR(q[1] * p[1] + q[2] * p[2], 0.0, 1e-13); /* turned by 90 degrees */
        apply(T1, T1 + 9, p, p1);
        for (int i = 0; i < 3; ++i)
            lbs[i] = 0.5 * p[i] + 0.5 * p1[i];
        ENSURE(hypot(lbs[1], lbs[2]) <= 1e-15); /* LBS: collapsed onto the axis */
    }
}

TEST(zero_weights_give_identity) {
    double T[12];
    random_transform(T, 1.0);
    sw_dualquat dq;
    sw_dq_from_transform(T, &dq);
    int32_t ids[3] = {0, 0, 0};
    double w[3] = {0, 0, 0}, R[9], t[3], I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, z[3] = {0, 0, 0};
    sw_dqs_blend(&dq, ids, w, 3, R, t);
    ENSURE(max_diff(R, I, 9) == 0 && max_diff(t, z, 3) == 0);
    sw_dqs_blend(&dq, ids, w, 0, R, t); /* no influences at all */
    ENSURE(max_diff(R, I, 9) == 0 && max_diff(t, z, 3) == 0);
    /* Zero weights ahead of a real influence are skipped (it becomes the pivot). */
    w[2] = 0.25;
    sw_dqs_blend(&dq, ids, w, 3, R, t);
    ENSURE(max_diff(R, T, 9) <= 1e-12 && max_diff(t, T + 9, 3) <= 1e-11);
}

TEST(skin_matches_per_point_blend) {
    enum { NB = 5, N = 300, K = 3 };
    sw_dualquat dq[NB];
    for (int b = 0; b < NB; ++b) {
        double T[12];
        random_transform(T, 2 * PI * urand());
        sw_dq_from_transform(T, &dq[b]);
    }
    double X[3 * N], x[3 * N], w[N * K];
    int32_t ids[N * K];
    for (int v = 0; v < N; ++v) {
        for (int i = 0; i < 3; ++i)
            X[3 * v + i] = 3 * (2 * urand() - 1);
        for (int i = 0; i < K; ++i) {
            ids[v * K + i] = (int32_t)(urand() * NB);
            w[v * K + i] = (v % 17 == 0) ? 0.0 : urand();
        }
    }
    sw_dqs_skin(N, X, dq, ids, w, K, x);
    for (int v = 0; v < N; ++v) {
        double R[9], t[3], y[3];
        sw_dqs_blend(dq, ids + v * K, w + v * K, K, R, t);
        apply(R, t, X + 3 * v, y);
        ENSURE(max_diff(y, x + 3 * v, 3) == 0.0);
        if (v % 17 == 0) ENSURE(max_diff(X + 3 * v, x + 3 * v, 3) == 0.0); /* identity */
    }
    /* In place (x aliasing X) gives the same. */
    double Y[3 * N];
    memcpy(Y, X, sizeof X);
    sw_dqs_skin(N, Y, dq, ids, w, K, Y);
    ENSURE(max_diff(Y, x, 3 * N) == 0.0);
}

SW_TEST_MAIN(CASE(single_influence_reproduces_transform),
             CASE(antipodal_input_matches_identical_input),
             CASE(same_axis_blend_is_intermediate_rotation),
             CASE(random_blends_are_proper_rotations), CASE(translations_only_equal_lbs),
             CASE(candy_wrapper_twist_keeps_volume), CASE(zero_weights_give_identity),
             CASE(skin_matches_per_point_blend))
