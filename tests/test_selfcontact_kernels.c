/* Self-contact's building blocks: BVH point, box and closest-triangle queries against
 * brute force (with refits), the build against a full-sort reference, the closest point on a
 * triangle, the BVH's argument checks, and the penalty's forces, Hessian and energy against finite
 * differences. Detection on structured blocks is in test_selfcontact.c; the random numbers in
 * selfcontact_fixture.h. */
#include <stdint.h>

#include "bvh.h"
#include "selfcontact.h"
#include "sw_test.h"

#include "selfcontact_fixture.h"

/* ---- BVH -------------------------------------------------------------------------- */

typedef struct {
    char *hit;
    int32_t n;
} mark_ctx;
static int mark_visit(void *ctx, int32_t prim) {
    mark_ctx *m = ctx;
    m->hit[prim]++;
    m->n++;
    return 0;
}

static int stop_visit(void *ctx, int32_t prim) {
    (void)ctx;
    (void)prim;
    return 1;
}

static int box_has(const double *b, const double *p) {
    return p[0] >= b[0] && p[0] <= b[3] && p[1] >= b[1] && p[1] <= b[4] && p[2] >= b[2] &&
           p[2] <= b[5];
}

static void random_boxes(int32_t n, double *boxes, double scale) {
    for (int32_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            double c = srand1(), r = scale * urand();
            boxes[6 * i + k] = c - r;
            boxes[6 * i + 3 + k] = c + r;
        }
    }
}

TEST(bvh_point_and_box_queries_match_brute_force) {
    enum { N = 700 };
    static double boxes[6 * N];
    static char hit[N];
    random_boxes(N, boxes, 0.15);
    sw_bvh t;
    sw_error err;
    ENSURE(sw_bvh_build(N, boxes, &t, &err) == SINEW_OK);
    ENSURE(t.nnodes >= 2 && t.nnodes <= 2 * N - 1);
    for (int round = 0; round < 2; ++round) {
        if (round == 1) { /* move every box, refit, and query again */
            random_boxes(N, boxes, 0.3);
            sw_bvh_refit(&t, boxes);
        }
        for (int q = 0; q < 300; ++q) {
            double p[3] = {1.1 * srand1(), 1.1 * srand1(), 1.1 * srand1()};
            if (q < 20) /* a box corner: the boundary counts as inside */
                for (int k = 0; k < 3; ++k)
                    p[k] = boxes[6 * q + 3 * (k == 1) + k];
            memset(hit, 0, sizeof hit);
            mark_ctx m = {hit, 0};
            int32_t nv = sw_bvh_query_point(&t, p, mark_visit, &m);
            ENSURE(nv == m.n);
            int32_t expect = 0;
            for (int32_t i = 0; i < N; ++i) {
                int in = box_has(boxes + 6 * i, p);
                expect += in;
                ENSUREF(hit[i] == in, "round %d query %d prim %d: visited %d, inside %d", round, q,
                        i, hit[i], in);
            }
            ENSURE(nv == expect);
            if (q < 20) ENSURE(hit[q] == 1);
            /* box query: a small box around p */
            double qb[6] = {p[0] - 0.05, p[1] - 0.02, p[2] - 0.07,
                            p[0] + 0.03, p[1] + 0.06, p[2] + 0.01};
            memset(hit, 0, sizeof hit);
            m.n = 0;
            sw_bvh_query_box(&t, qb, mark_visit, &m);
            for (int32_t i = 0; i < N; ++i) {
                const double *b = boxes + 6 * i;
                int ov = b[0] <= qb[3] && qb[0] <= b[3] && b[1] <= qb[4] && qb[1] <= b[4] &&
                         b[2] <= qb[5] && qb[2] <= b[5];
                ENSURE(hit[i] == ov);
            }
        }
    }
    /* early stop: a visitor returning nonzero ends the walk after one visit */
    double c0[3] = {0.5 * (boxes[0] + boxes[3]), 0.5 * (boxes[1] + boxes[4]),
                    0.5 * (boxes[2] + boxes[5])};
    ENSURE(sw_bvh_query_point(&t, c0, stop_visit, NULL) == 1);
    sw_bvh_free(&t);
    sw_bvh_free(&t); /* zeroed: no-op */
}

/* The tree a median split by a full sort at every level builds (the build's definition):
 * prims[lo, hi) sorted along the longest extent of their centroids, ties by id, halved. */
typedef struct {
    double c;
    int32_t id;
} ref_key;
static int ref_cmp(const void *pa, const void *pb) {
    const ref_key *a = pa, *b = pb;
    return a->c < b->c ? -1 : a->c > b->c ? 1 : (a->id > b->id) - (a->id < b->id);
}
static int32_t ref_build(const double *boxes, int32_t *prims, int32_t *node, int32_t *next,
                         int32_t lo, int32_t hi) {
    int32_t at = (*next)++;
    if (hi - lo <= SW_BVH_LEAF_SIZE) {
        node[2 * at] = lo, node[2 * at + 1] = hi - lo;
        return at;
    }
    double mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = lo; i < hi; ++i)
        for (int k = 0; k < 3; ++k) {
            double c = 0.5 * (boxes[6 * prims[i] + k] + boxes[6 * prims[i] + 3 + k]);
            mn[k] = fmin(mn[k], c), mx[k] = fmax(mx[k], c);
        }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (mx[k] - mn[k] > mx[axis] - mn[axis]) axis = k;
    ref_key *key = malloc(sizeof *key * (size_t)(hi - lo));
    for (int32_t i = lo; i < hi; ++i)
        key[i - lo] = (ref_key){0.5 * (boxes[6 * prims[i] + axis] + boxes[6 * prims[i] + 3 + axis]),
                                prims[i]};
    qsort(key, (size_t)(hi - lo), sizeof *key, ref_cmp);
    for (int32_t i = lo; i < hi; ++i)
        prims[i] = key[i - lo].id;
    free(key);
    int32_t mid = lo + (hi - lo) / 2;
    ref_build(boxes, prims, node, next, lo, mid);
    node[2 * at] = ref_build(boxes, prims, node, next, mid, hi), node[2 * at + 1] = 0;
    return at;
}

/* The build selects each median instead of sorting (bvh.c): the same tree, node for node
 * and leaf order for leaf order, on spread boxes and on boxes whose centroids tie. */
TEST(bvh_build_is_the_full_sort_median_split) {
    enum { N = 1500 };
    static double boxes[6 * N];
    static int32_t prims[N], node[4 * N];
    for (int pass = 0; pass < 2; ++pass) {
        random_boxes(N, boxes, 0.05);
        if (pass == 1) /* centroids on a coarse grid: many ties, broken by id */
            for (int32_t i = 0; i < 6 * N; ++i)
                boxes[i] = round(4 * boxes[i]) / 4;
        sw_bvh t;
        ENSURE(sw_bvh_build(N, boxes, &t, NULL) == SINEW_OK);
        int32_t next = 0;
        for (int32_t i = 0; i < N; ++i)
            prims[i] = i;
        ref_build(boxes, prims, node, &next, 0, N);
        ENSURE(t.nnodes == next);
        ENSURE(memcmp(t.prims, prims, sizeof(int32_t) * N) == 0);
        ENSURE(memcmp(t.node, node, sizeof(int32_t) * 2 * (size_t)next) == 0);
        sw_bvh_free(&t);
    }
}

TEST(bvh_closest_triangle_matches_brute_force) {
    enum { NT = 400, NV = 3 * NT };
    static double X[3 * NV];
    static int32_t tris[3 * NT];
    static double boxes[6 * NT];
    for (int32_t t = 0; t < NT; ++t) {
        double c[3] = {srand1(), srand1(), srand1()};
        for (int v = 0; v < 3; ++v) {
            for (int k = 0; k < 3; ++k)
                X[3 * (3 * t + v) + k] = c[k] + 0.1 * srand1();
            tris[3 * t + v] = 3 * t + v;
        }
    }
    sw_bvh_element_boxes(tris, 3, X, 0, NT, boxes);
    sw_bvh t;
    ENSURE(sw_bvh_build(NT, boxes, &t, NULL) == SINEW_OK);
    for (int q = 0; q < 400; ++q) {
        if (q == 200) { /* deform the triangles and refit from the elements, in two ranges */
            for (int i = 0; i < 3 * NV; ++i)
                X[i] += 0.2 * srand1();
            sw_bvh_refit_elements(&t, tris, 3, X, 0, NT / 3);
            sw_bvh_refit_elements(&t, tris, 3, X, NT / 3, NT);
            sw_bvh_refit_nodes(&t);
        }
        double p[3] = {1.3 * srand1(), 1.3 * srand1(), 1.3 * srand1()};
        double best = INFINITY;
        int32_t bt = -1;
        for (int32_t i = 0; i < NT; ++i) {
            double beta[3], r[3];
            sw_closest_point_triangle(p, X + 9 * i, X + 9 * i + 3, X + 9 * i + 6, beta, r);
            double d = sqrt((r[0] - p[0]) * (r[0] - p[0]) + (r[1] - p[1]) * (r[1] - p[1]) +
                            (r[2] - p[2]) * (r[2] - p[2]));
            if (d < best) best = d, bt = i;
        }
        sw_bvh_closest c;
        ENSURE(sw_bvh_closest_triangle(&t, X, tris, p, 10.0, &c) == 1);
        ENSURE_NEAR(c.dist, best, 1e-14);
        ENSURE(c.tri == bt || fabs(c.dist - best) < 1e-14);
        double s = c.beta[0] + c.beta[1] + c.beta[2];
        ENSURE_NEAR(s, 1, 1e-14);
        for (int k = 0; k < 3; ++k) {
            ENSURE(c.beta[k] >= -1e-15);
            double pk = 0;
            for (int v = 0; v < 3; ++v)
                pk += c.beta[v] * X[3 * tris[3 * c.tri + v] + k];
            ENSURE_NEAR(c.point[k], pk, 1e-14);
        }
        /* a radius below the true distance finds nothing */
        ENSURE(sw_bvh_closest_triangle(&t, X, tris, p, 0.99 * best, &c) == 0);
        ENSURE(c.tri == -1);
    }
    sw_bvh_free(&t);
}

TEST(closest_point_triangle_is_the_minimum) {
    /* Against a dense barycentric scan: no sample point of the triangle is closer. */
    for (int trial = 0; trial < 200; ++trial) {
        double a[3], b[3], c[3], p[3];
        for (int k = 0; k < 3; ++k)
            a[k] = srand1(), b[k] = srand1(), c[k] = srand1(), p[k] = 2 * srand1();
        double beta[3], q[3];
        sw_closest_point_triangle(p, a, b, c, beta, q);
        double dq = sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                         (q[2] - p[2]) * (q[2] - p[2]));
        for (int k = 0; k < 3; ++k)
            ENSURE_NEAR(q[k], beta[0] * a[k] + beta[1] * b[k] + beta[2] * c[k], 1e-14);
        enum { S = 40 };
        for (int i = 0; i <= S; ++i)
            for (int j = 0; i + j <= S; ++j) {
                double u = (double)i / S, v = (double)j / S, w = 1 - u - v, r[3];
                for (int k = 0; k < 3; ++k)
                    r[k] = u * a[k] + v * b[k] + w * c[k];
                double dr = sqrt((r[0] - p[0]) * (r[0] - p[0]) + (r[1] - p[1]) * (r[1] - p[1]) +
                                 (r[2] - p[2]) * (r[2] - p[2]));
                ENSUREF(dr >= dq - 1e-12, "trial %d: sample %.17g closer than %.17g", trial, dr,
                        dq);
            }
    }
}

TEST(bvh_rejects_bad_boxes) {
    sw_bvh t;
    sw_error err;
    double good[6] = {0, 0, 0, 1, 1, 1};
    ENSURE(sw_bvh_build(0, good, &t, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(t.nnodes == 0 && t.box == NULL);
    double inv[12] = {0, 0, 0, 1, 1, 1, 0, 2, 0, 1, 1, 1};
    ENSURE(sw_bvh_build(2, inv, &t, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "primitive 1") != NULL);
    double nan[6] = {0, 0, 0, 1, NAN, 1};
    ENSURE(sw_bvh_build(1, nan, &t, &err) == SINEW_ERROR_NOT_FINITE);
    ENSURE(sw_bvh_build(1, good, &t, &err) == SINEW_OK);
    ENSURE(t.nnodes == 1);
    sw_bvh_free(&t);
}

/* ---- penalty ---------------------------------------------------------------------- */

enum { PV = 10, PC = 7 };

static void random_contacts(sw_contact *c, int n, int allow_repeat) {
    for (int i = 0; i < n; ++i) {
        memset(&c[i], 0, sizeof c[i]);
        c[i].p = (int32_t)(urand() * PV);
        for (int k = 0; k < 3; ++k) {
            int32_t v;
            int ok;
            do { /* distinct triangle vertices, distinct from p (unless repeats allowed) */
                v = (int32_t)(urand() * PV);
                ok = allow_repeat || v != c[i].p;
                for (int j = 0; j < k; ++j)
                    ok = ok && v != c[i].tri[j];
            } while (!ok);
            c[i].tri[k] = v;
        }
        double b0 = urand(), b1 = urand();
        if (b0 + b1 > 1) b0 = 1 - b0, b1 = 1 - b1;
        c[i].beta[0] = b0, c[i].beta[1] = b1, c[i].beta[2] = 1 - b0 - b1;
        double n[3] = {srand1(), srand1(), srand1() + 0.1},
               l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k)
            c[i].n[k] = n[k] / l;
        c[i].ka = 0.1 + urand();
        c[i].depth = urand();
    }
}

TEST(penalty_derivatives_match_finite_differences) {
    for (int trial = 0; trial < 6; ++trial) {
        sw_contact c[PC];
        random_contacts(c, PC, trial >= 4); /* the last trials let p repeat a triangle vertex */
        double kc = 1 + 10 * urand(), alpha = trial == 0 ? 0.5 : urand();
        double x[3 * PV], f[3 * PV] = {0};
        for (int i = 0; i < 3 * PV; ++i)
            x[i] = srand1();
        sw_contact_add_forces(c, PC, x, kc, alpha, f);
        /* forces == -grad E (E is quadratic: central differences are exact to round-off) */
        const double h = 1e-4;
        for (int i = 0; i < 3 * PV; ++i) {
            double xs = x[i];
            x[i] = xs + h;
            double ep = sw_contact_energy(c, PC, x, kc, alpha);
            x[i] = xs - h;
            double em = sw_contact_energy(c, PC, x, kc, alpha);
            x[i] = xs;
            ENSURE_NEAR(-(ep - em) / (2 * h), f[i], 1e-8 * (1 + fabs(f[i])));
        }
        /* H v == directional derivative of -f */
        double H[3 * PV][3 * PV];
        for (int dir = 0; dir < 3; ++dir) {
            double v[3 * PV], xp[3 * PV], xm[3 * PV], fp[3 * PV] = {0}, fm[3 * PV] = {0},
                                                             Hv[3 * PV] = {0};
            for (int i = 0; i < 3 * PV; ++i)
                v[i] = srand1(), xp[i] = x[i] + h * v[i], xm[i] = x[i] - h * v[i];
            sw_contact_add_forces(c, PC, xp, kc, alpha, fp);
            sw_contact_add_forces(c, PC, xm, kc, alpha, fm);
            sw_contact_apply_hessian(c, PC, kc, alpha, v, Hv);
            for (int i = 0; i < 3 * PV; ++i)
                ENSURE_NEAR(-(fp[i] - fm[i]) / (2 * h), Hv[i], 1e-8 * (1 + fabs(Hv[i])));
        }
        /* column by column: symmetric, diagonal blocks == add_diag */
        for (int j = 0; j < 3 * PV; ++j) {
            double e[3 * PV] = {0}, col[3 * PV] = {0};
            e[j] = 1;
            sw_contact_apply_hessian(c, PC, kc, alpha, e, col);
            for (int i = 0; i < 3 * PV; ++i)
                H[i][j] = col[i];
        }
        for (int i = 0; i < 3 * PV; ++i)
            for (int j = 0; j < i; ++j)
                ENSURE_NEAR(H[i][j], H[j][i], 1e-12 * (1 + fabs(H[i][j])));
        double diag[9 * PV] = {0};
        sw_contact_add_diag(c, PC, kc, alpha, diag);
        for (int v = 0; v < PV; ++v)
            for (int r = 0; r < 3; ++r)
                for (int s = 0; s < 3; ++s)
                    ENSURE_NEAR(diag[9 * v + 3 * r + s], H[3 * v + r][3 * v + s], 1e-12);
        /* PSD */
        for (int k = 0; k < 50; ++k) {
            double v[3 * PV], Hv[3 * PV] = {0}, vHv = 0, vv = 0;
            for (int i = 0; i < 3 * PV; ++i)
                v[i] = srand1();
            sw_contact_apply_hessian(c, PC, kc, alpha, v, Hv);
            for (int i = 0; i < 3 * PV; ++i)
                vHv += v[i] * Hv[i], vv += v[i] * v[i];
            ENSURE(vHv >= -1e-12 * vv);
        }
        /* E == 1/2 x^T H x (a pure quadratic in x) and f == -H x */
        double Hx[3 * PV] = {0}, xHx = 0;
        sw_contact_apply_hessian(c, PC, kc, alpha, x, Hx);
        for (int i = 0; i < 3 * PV; ++i) {
            xHx += x[i] * Hx[i];
            ENSURE_NEAR(f[i], -Hx[i], 1e-12 * (1 + fabs(f[i])));
        }
        ENSURE_NEAR(sw_contact_energy(c, PC, x, kc, alpha), 0.5 * xHx, 1e-12 * (1 + xHx));
    }
    /* eq. 3.4 directly: f_p = kc ka N (v_s - v_p) for one contact */
    sw_contact one;
    random_contacts(&one, 1, 0);
    double x[3 * PV], f[3 * PV] = {0}, kc = 3, alpha = 0.5;
    for (int i = 0; i < 3 * PV; ++i)
        x[i] = srand1();
    sw_contact_add_forces(&one, 1, x, kc, alpha, f);
    double d[3];
    for (int k = 0; k < 3; ++k)
        d[k] = one.beta[0] * x[3 * one.tri[0] + k] + one.beta[1] * x[3 * one.tri[1] + k] +
               one.beta[2] * x[3 * one.tri[2] + k] - x[3 * one.p + k];
    double nd = one.n[0] * d[0] + one.n[1] * d[1] + one.n[2] * d[2];
    for (int k = 0; k < 3; ++k) {
        double fp = kc * one.ka * ((1 - alpha) * one.n[k] * nd + alpha * d[k]);
        ENSURE_NEAR(f[3 * one.p + k], fp, 1e-12);
        ENSURE_NEAR(f[3 * one.tri[1] + k], -one.beta[1] * fp, 1e-12);
    }
}

SW_TEST_MAIN(CASE(bvh_point_and_box_queries_match_brute_force),
             CASE(bvh_build_is_the_full_sort_median_split),
             CASE(bvh_closest_triangle_matches_brute_force),
             CASE(closest_point_triangle_is_the_minimum), CASE(bvh_rejects_bad_boxes),
             CASE(penalty_derivatives_match_finite_differences))
