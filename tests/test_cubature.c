/* Cubature training (precompute/train/cubature_train.c) on synthetic problems: exact
 * recovery of a sparse non-negative combination, a smooth FEM-like quadrature
 * problem, determinism over seeds, thread counts and cache evictions, the
 * max_points limit, and error paths. Prints a table of the three selectors. */
#include "cubature_train.h"
#include "sw_test.h"

#include <stdint.h>

static const char *const selector_name[] = {"greedy", "importance", "nn-htp"};

/* Columns are pure functions of (problem seed, candidate): thread-safe, and the same
 * values whenever a column is evaluated again. */
static uint64_t mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double hash_unit(uint64_t a, uint64_t b) {
    return (double)(mix(a * 0x9E3779B97F4A7C15ull + mix(b + 0x632BE59BD9B4E019ull)) >> 11) *
           0x1.0p-53;
}

typedef struct synth {
    int kind; /* 0: sparse random non-negative, 1: smooth */
    int64_t m, nc;
    int T, r;
    double *freq;  /* smooth: (T r) x 4: 3 frequencies and a phase per row */
    double *scale; /* smooth: T row-block normalisations (1 / |b^t|) */
    double *b;
    int *calls; /* per candidate: callback count (distinct candidates run concurrently) */
    int nan_candidate;
} synth;

static void sparse_column(const synth *p, int64_t e, double *col) {
    for (int64_t i = 0; i < p->m; ++i)
        col[i] = hash_unit((uint64_t)e, (uint64_t)i);
}

/* A candidate is a random point x in the unit cube; row (t, k) samples a smooth
 * function sin(f . x + phase) at it, scaled per training sample t so that every
 * sample block of b has unit norm (the normalisation of eq. 2.14). */
static void smooth_column(const synth *p, int64_t e, double *col) {
    double x[3];
    for (int d = 0; d < 3; ++d)
        x[d] = hash_unit((uint64_t)e, 1000003u + (uint64_t)d);
    for (int64_t i = 0; i < p->m; ++i) {
        const double *f = p->freq + 4 * i;
        double s = p->scale ? p->scale[i / p->r] : 1;
        col[i] = s * sin(f[0] * x[0] + f[1] * x[1] + f[2] * x[2] + f[3]);
    }
}

static void column_cb(void *ctx, int64_t e, double *col) {
    synth *p = ctx;
    if (p->calls) p->calls[e]++;
    if (p->kind == 0)
        sparse_column(p, e, col);
    else
        smooth_column(p, e, col);
    if (e == p->nan_candidate) col[p->m / 2] = NAN;
}

/* b = sum of 15 random columns with weights in [0.5, 1.5]. */
static void make_sparse(synth *p, int64_t m, int64_t nc) {
    memset(p, 0, sizeof *p);
    p->kind = 0;
    p->m = m;
    p->nc = nc;
    p->nan_candidate = -1;
    p->b = calloc((size_t)m, sizeof(double));
    double *col = malloc((size_t)m * sizeof(double));
    for (int k = 0; k < 15; ++k) {
        int64_t e = (int64_t)(hash_unit(77, (uint64_t)k) * (double)nc);
        double w = 0.5 + hash_unit(78, (uint64_t)k);
        sparse_column(p, e, col);
        for (int64_t i = 0; i < m; ++i)
            p->b[i] += w * col[i];
    }
    free(col);
}

/* b = the mean over all candidates (the full "force" sums every tet), rows in T
 * blocks of r, frequencies up to `freq` per axis (12: ~150 points for 5%). */
static void make_smooth(synth *p, int T, int r, int64_t nc, double freq) {
    memset(p, 0, sizeof *p);
    p->kind = 1;
    p->T = T;
    p->r = r;
    p->m = (int64_t)T * r;
    p->nc = nc;
    p->nan_candidate = -1;
    p->freq = malloc((size_t)(4 * p->m) * sizeof(double));
    for (int64_t i = 0; i < p->m; ++i) {
        for (int d = 0; d < 3; ++d)
            p->freq[4 * i + d] = freq * (2 * hash_unit(5, 4 * (uint64_t)i + d) - 1);
        p->freq[4 * i + 3] = 6.283185307179586 * hash_unit(5, 4 * (uint64_t)i + 3);
    }
    p->b = calloc((size_t)p->m, sizeof(double));
    double *col = malloc((size_t)p->m * sizeof(double));
    for (int64_t e = 0; e < nc; ++e) {
        smooth_column(p, e, col);
        for (int64_t i = 0; i < p->m; ++i)
            p->b[i] += col[i] / (double)nc;
    }
    free(col);
    p->scale = malloc((size_t)T * sizeof(double));
    for (int t = 0; t < T; ++t) {
        double s = 0;
        for (int k = 0; k < r; ++k)
            s += p->b[t * r + k] * p->b[t * r + k];
        p->scale[t] = 1 / sqrt(s);
        for (int k = 0; k < r; ++k)
            p->b[t * r + k] *= p->scale[t];
    }
}

static void synth_free(synth *p) {
    free(p->freq);
    free(p->scale);
    free(p->b);
    free(p->calls);
}

static sw_cubature_problem problem_of(synth *p) {
    return (sw_cubature_problem){p->m, p->nc, p->b, column_cb, p};
}

/* |A w - b| / |b| recomputed from the callback: the reported error must be true. */
static double true_error(synth *p, const sw_cubature_result *res) {
    double *r = malloc((size_t)p->m * sizeof(double)), *col = malloc((size_t)p->m * sizeof(double));
    int *calls = p->calls;
    p->calls = NULL;
    double bb = 0, rr = 0;
    for (int64_t i = 0; i < p->m; ++i)
        r[i] = p->b[i];
    for (int32_t k = 0; k < res->n; ++k) {
        column_cb(p, res->ids[k], col);
        for (int64_t i = 0; i < p->m; ++i)
            r[i] -= res->weights[k] * col[i];
    }
    for (int64_t i = 0; i < p->m; ++i) {
        bb += p->b[i] * p->b[i];
        rr += r[i] * r[i];
    }
    p->calls = calls;
    free(r);
    free(col);
    return sqrt(rr / bb);
}

/* ids strictly ascending, in range; weights positive and finite. */
static int well_formed(const synth *p, const sw_cubature_result *res) {
    for (int32_t k = 0; k < res->n; ++k) {
        if (res->ids[k] < 0 || res->ids[k] >= p->nc) return 0;
        if (k && res->ids[k] <= res->ids[k - 1]) return 0;
        if (!(res->weights[k] > 0) || !isfinite(res->weights[k])) return 0;
    }
    return 1;
}

TEST(sparse_recovery_all_selectors) {
    synth p;
    make_sparse(&p, 200, 2000);
    p.calls = calloc((size_t)p.nc, sizeof(int));
    sw_cubature_problem prob = problem_of(&p);
    static const double tols[] = {0.05, 1e-3};
    for (int sel = 0; sel < 3; ++sel) {
        for (int ti = 0; ti < 2; ++ti) {
            sw_cubature_params par = sw_cubature_params_default();
            par.selector = (sw_cubature_selector)sel;
            par.tol = tols[ti];
            par.max_points = 200;
            memset(p.calls, 0, (size_t)p.nc * sizeof(int));
            sw_cubature_result res;
            sw_error err;
            sinew_result rc = sw_cubature_train(&prob, &par, &res, &err);
            double te = rc == SINEW_OK ? true_error(&p, &res) : INFINITY;
            /* Importance sampling draws ~ a_e . r, which is nearly flat over these
             * columns: at 5% it stops with ~50-60 points (any 5% fit will do); at 1e-3
             * only the 15 true columns remain after NNLS and pruning. */
            int max_n = (sel == SW_CUBATURE_IMPORTANCE && ti == 0) ? 80 : 20;
            int maxcalls = 0;
            int64_t calls = 0;
            for (int64_t e = 0; e < p.nc; ++e) {
                maxcalls = p.calls[e] > maxcalls ? p.calls[e] : maxcalls;
                calls += p.calls[e];
            }
            fprintf(stderr,
                    "  %-10s tol %-6g: %3d points, error %.3g, %lld columns, %d it, %.3f s\n",
                    selector_name[sel], tols[ti], res.n, res.rel_error,
                    (long long)res.columns_evaluated, res.iterations, res.seconds);
            int ok = rc == SINEW_OK && well_formed(&p, &res) && res.rel_error <= tols[ti] &&
                     fabs(te - res.rel_error) <= 1e-9 + 1e-6 * te && res.n <= max_n &&
                     maxcalls == 1 && calls == res.columns_evaluated;
            int n = res.n;
            sw_cubature_result_free(&res);
            if (!ok) synth_free(&p);
            ENSUREF(ok, "%s tol %g: result %d (%s), %d points, error %g (true %g), max calls %d",
                    selector_name[sel], tols[ti], (int)rc, rc ? err.msg : "", n, te, te, maxcalls);
        }
    }
    synth_free(&p);
}

/* The smooth FEM-like problem; the full size (m = 3000, 10,000 candidates) only in
 * optimised builds without sanitizers, to keep Debug/ASan runs short. */
#if defined(NDEBUG) && !defined(__SANITIZE_ADDRESS__)
#define SMOOTH_T 100
#define SMOOTH_NC 10000
#else
#define SMOOTH_T 20
#define SMOOTH_NC 3000
#endif

TEST(smooth_problem_table) {
    synth p;
    make_smooth(&p, SMOOTH_T, 30, SMOOTH_NC, 12);
    sw_cubature_problem prob = problem_of(&p);
    fprintf(stderr, "  smooth problem: m = %lld (r 30, T %d), %lld candidates, tol 0.05\n",
            (long long)p.m, SMOOTH_T, (long long)p.nc);
    fprintf(stderr, "  %-10s %-7s %6s %10s %8s %8s %5s\n", "selector", "nnls", "points",
            "rel.error", "seconds", "columns", "iters");
    for (int sel = 0; sel < 3; ++sel) {
        for (int meth = 1; meth >= 0; --meth) {
            if (meth == 0 && sel != 2) continue; /* LH only for the default selector */
            sw_cubature_params par = sw_cubature_params_default();
            par.selector = (sw_cubature_selector)sel;
            par.nnls = (sw_nnls_method)meth;
            par.threads = 2;
            sw_cubature_result res;
            sw_error err;
            sinew_result rc = sw_cubature_train(&prob, &par, &res, &err);
            double te = rc == SINEW_OK ? true_error(&p, &res) : INFINITY;
            fprintf(stderr, "  %-10s %-7s %6d %10.4f %8.3f %8lld %5d\n", selector_name[sel],
                    meth ? "fnnls" : "lawson", res.n, res.rel_error, res.seconds,
                    (long long)res.columns_evaluated, res.iterations);
            int ok = rc == SINEW_OK && well_formed(&p, &res) && res.rel_error <= 0.05 &&
                     fabs(te - res.rel_error) <= 1e-9 + 1e-6 * te && res.n > 0;
            sw_cubature_result_free(&res);
            if (!ok) synth_free(&p);
            ENSUREF(ok, "%s: result %d (%s), true error %g", selector_name[sel], (int)rc,
                    rc ? err.msg : "", te);
        }
    }
    synth_free(&p);
}

static int same_result(const sw_cubature_result *a, const sw_cubature_result *b) {
    if (a->n != b->n || a->rel_error != b->rel_error) return 0;
    for (int32_t k = 0; k < a->n; ++k)
        if (a->ids[k] != b->ids[k] || a->weights[k] != b->weights[k]) return 0;
    return 1;
}

/* Same seed: bit-identical ids and weights, whatever the thread count or cache size;
 * a different seed is still a valid answer. */
TEST(determinism) {
    synth p;
    make_smooth(&p, 10, 30, 2000, 6);
    sw_cubature_problem prob = problem_of(&p);
    for (int sel = 0; sel < 3; ++sel) {
        sw_cubature_params par = sw_cubature_params_default();
        par.selector = (sw_cubature_selector)sel;
        par.tol = 0.02;
        par.seed = 42;
        par.max_points = 60;
        par.candidates = sel == SW_CUBATURE_NNHTP ? 0 : 200;
        sw_cubature_result r1, r1b, r2, rsmall, rseed;
        par.threads = 1;
        sinew_result c1 = sw_cubature_train(&prob, &par, &r1, NULL);
        sinew_result c1b = sw_cubature_train(&prob, &par, &r1b, NULL);
        par.threads = 2;
        sinew_result c2 = sw_cubature_train(&prob, &par, &r2, NULL);
        /* A 64 KiB budget: the cache shrinks to its floor (one batch plus max_points
         * columns), evicting and re-evaluating columns. */
        sinew_result cs = sw_cubature_train_cache(&prob, &par, 64 << 10, &rsmall, NULL);
        par.seed = 43;
        sinew_result cd = sw_cubature_train(&prob, &par, &rseed, NULL);
        int ok = c1 == SINEW_OK && c1b == SINEW_OK && c2 == SINEW_OK && cs == SINEW_OK &&
                 cd == SINEW_OK && same_result(&r1, &r1b) && same_result(&r1, &r2) &&
                 same_result(&r1, &rsmall) && rsmall.columns_evaluated > r1.columns_evaluated &&
                 rseed.rel_error <= 0.02;
        fprintf(stderr,
                "  %-10s %d points; evaluated %lld columns, %lld with a 64 KiB cache; "
                "seed 43: %d points\n",
                selector_name[sel], r1.n, (long long)r1.columns_evaluated,
                (long long)rsmall.columns_evaluated, rseed.n);
        sw_cubature_result_free(&r1);
        sw_cubature_result_free(&r1b);
        sw_cubature_result_free(&r2);
        sw_cubature_result_free(&rsmall);
        sw_cubature_result_free(&rseed);
        if (!ok) synth_free(&p);
        ENSUREF(ok, "%s: results %d %d %d %d %d or results differ", selector_name[sel], (int)c1,
                (int)c1b, (int)c2, (int)cs, (int)cd);
    }
    synth_free(&p);
}

TEST(max_points_not_converged) {
    synth p;
    make_smooth(&p, 10, 30, 2000, 6);
    sw_cubature_problem prob = problem_of(&p);
    for (int sel = 0; sel < 3; ++sel) {
        sw_cubature_params par = sw_cubature_params_default();
        par.selector = (sw_cubature_selector)sel;
        par.tol = 1e-6;
        par.max_points = 12;
        sw_cubature_result res;
        sw_error err;
        sinew_result rc = sw_cubature_train(&prob, &par, &res, &err);
        double te = res.n > 0 ? true_error(&p, &res) : INFINITY;
        int ok = rc == SINEW_ERROR_NOT_CONVERGED && res.n > 0 && res.n <= 12 &&
                 well_formed(&p, &res) && res.rel_error < 0.5 && res.rel_error > 1e-6 &&
                 fabs(te - res.rel_error) <= 1e-9 && strstr(err.msg, "max_points 12");
        fprintf(stderr, "  %-10s: %d points, error %.3g: %s\n", selector_name[sel], res.n,
                res.rel_error, err.msg);
        sw_cubature_result_free(&res);
        if (!ok) synth_free(&p);
        ENSUREF(ok, "%s: result %d", selector_name[sel], (int)rc);
    }
    synth_free(&p);
}

TEST(bad_parameters) {
    synth p;
    make_sparse(&p, 50, 100);
    sw_cubature_problem prob = problem_of(&p);
    sw_cubature_params par = sw_cubature_params_default();
    sw_cubature_result res;
    sw_error err;
    par.tol = 0;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(res.ids == NULL && strstr(err.msg, "tolerance"));
    par.tol = -0.1;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    par.tol = NAN;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    par = sw_cubature_params_default();
    par.max_points = -1;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    par = sw_cubature_params_default();
    par.selector = (sw_cubature_selector)9;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    par = sw_cubature_params_default();
    sw_cubature_problem bad = prob;
    bad.m = 0;
    ENSURE(sw_cubature_train(&bad, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    bad = prob;
    bad.ncandidates = 0;
    ENSURE(sw_cubature_train(&bad, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    bad = prob;
    bad.column = NULL;
    ENSURE(sw_cubature_train(&bad, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "callback"));
    bad = prob;
    bad.b = NULL;
    ENSURE(sw_cubature_train(&bad, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_cubature_train(NULL, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_cubature_train(&prob, NULL, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    p.b[3] = INFINITY;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "b[3]"));
    p.b[3] = 1;
    /* A callback that returns NaN for one candidate: named, nothing leaks. */
    p.nan_candidate = 37;
    par.candidates = 100; /* examine every candidate */
    for (int sel = 0; sel < 3; ++sel) {
        par.selector = (sw_cubature_selector)sel;
        for (int threads = 1; threads <= 2; ++threads) {
            par.threads = threads;
            ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_NOT_FINITE);
            ENSURE(strstr(err.msg, "candidate 37") && res.ids == NULL && res.n == 0);
        }
    }
    synth_free(&p);
}

/* b = 0: the empty cubature is exact. One candidate: its best multiple. */
TEST(edge_cases) {
    synth p;
    make_sparse(&p, 20, 5);
    sw_cubature_problem prob = problem_of(&p);
    sw_cubature_params par = sw_cubature_params_default();
    sw_cubature_result res;
    memset(p.b, 0, 20 * sizeof(double));
    ENSURE(sw_cubature_train(&prob, &par, &res, NULL) == SINEW_OK);
    ENSURE(res.n == 0 && res.rel_error == 0);
    sw_cubature_result_free(&res);
    sparse_column(&p, 3, p.b);
    for (int i = 0; i < 20; ++i)
        p.b[i] *= 2.5;
    for (int sel = 0; sel < 3; ++sel) {
        par.selector = (sw_cubature_selector)sel;
        par.tol = 1e-9;
        ENSURE(sw_cubature_train(&prob, &par, &res, NULL) == SINEW_OK);
        int ok = res.n == 1 && res.ids[0] == 3 && fabs(res.weights[0] - 2.5) < 1e-9;
        sw_cubature_result_free(&res);
        ENSURE(ok);
    }
    /* b pointing away from every (non-negative) column: nothing helps. */
    for (int i = 0; i < 20; ++i)
        p.b[i] = -1;
    par.selector = SW_CUBATURE_GREEDY;
    sw_error err;
    ENSURE(sw_cubature_train(&prob, &par, &res, &err) == SINEW_ERROR_NOT_CONVERGED);
    ENSURE(res.n == 0 && res.rel_error == 1 && strstr(err.msg, "correlates"));
    sw_cubature_result_free(&res);
    synth_free(&p);
}

SW_TEST_MAIN(CASE(sparse_recovery_all_selectors), CASE(smooth_problem_table), CASE(determinism),
             CASE(max_points_not_converged), CASE(bad_parameters), CASE(edge_cases))
