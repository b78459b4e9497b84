/* Cubature training (thesis §2.2.2-2.2.3, eqs. 2.11-2.19): choose a small set of
 * candidates (tets) and non-negative weights so that sum_e w_e a_e ~ b, where column
 * a_e stacks candidate e's reduced force over T normalised training samples (rows
 * m = r*T) and b stacks the full reduced forces. Columns are produced on demand by a
 * callback, so the m x ncandidates matrix is never formed. */
#ifndef SW_CUBATURE_TRAIN_H
#define SW_CUBATURE_TRAIN_H

#include <stdint.h>

#include "nnls.h"

/* Writes column `candidate` (m doubles) into `col`. Must be thread-safe when
 * `threads` > 1 in the params (called concurrently for different candidates). */
typedef void (*sw_cubature_column_fn)(void *ctx, int64_t candidate, double *col);

typedef struct sw_cubature_problem {
    int64_t m;           /* rows */
    int64_t ncandidates; /* columns */
    const double *b;     /* m */
    sw_cubature_column_fn column;
    void *ctx;
} sw_cubature_problem;

typedef enum sw_cubature_selector {
    SW_CUBATURE_GREEDY = 0,     /* Algorithm 1 (An et al. 2008) */
    SW_CUBATURE_IMPORTANCE = 1, /* Algorithm 2 (Kim & Delaney 2013) */
    SW_CUBATURE_NNHTP = 2       /* Algorithm 3 (NN-HTP, von Tycowicz et al. 2013) */
} sw_cubature_selector;

typedef struct sw_cubature_params {
    sw_cubature_selector selector;
    double tol;            /* target relative residual |A w - b| / |b| (default 0.05) */
    int32_t max_points;    /* upper bound on the set size (default 1000) */
    int32_t candidates;    /* random candidates examined per iteration (0: automatic) */
    int32_t per_iteration; /* points added per iteration (importance; 0: automatic) */
    uint64_t seed;         /* fixed seed: the result is deterministic */
    sw_nnls_method nnls;
    int threads; /* column evaluation threads (0/1: serial) */
} sw_cubature_params;

sw_cubature_params sw_cubature_params_default(void);

typedef struct sw_cubature_result {
    int32_t n;        /* chosen points */
    int64_t *ids;     /* n candidate ids, ascending */
    double *weights;  /* n, > 0 */
    double rel_error; /* |A w - b| / |b| */
    int iterations;
    double seconds;
    int64_t columns_evaluated;
} sw_cubature_result;

/* Trains a cubature. Fails with NOT_CONVERGED (result still filled with the best set)
 * when max_points is reached above tol. */
sinew_result sw_cubature_train(const sw_cubature_problem *prob, const sw_cubature_params *params,
                               sw_cubature_result *out, sw_error *err);
void sw_cubature_result_free(sw_cubature_result *r);
/* sw_cubature_train with a column-cache budget in bytes (0: 256 MiB). The support and
 * the current batch are always kept, so a tiny budget may be exceeded; evicting
 * changes columns_evaluated (a column may be computed again), never the result. */
sinew_result sw_cubature_train_cache(const sw_cubature_problem *prob,
                                     const sw_cubature_params *params, uint64_t cache_bytes,
                                     sw_cubature_result *out, sw_error *err);
#endif
