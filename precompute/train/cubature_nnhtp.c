/* The NN-HTP cubature selector (Algorithm 3, thesis §2.2.3, eqs. 2.17-2.19): a
 * growing support bound, then bisection down to the smallest bound that meets tol. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cubature_internal.h"

#define NNHTP_FIRST_SIZE 8 /* first support bound s; grown by NNHTP_GROWTH */
#define NNHTP_GROWTH 2.0
#define NNHTP_STALL 4 /* iterations without 0.1% progress end a stage */
#define NNHTP_STAGE_ITERATIONS 40
#define NNHTP_REFINE 16 /* bisect the bound down to ~1/16 of the size */

/* Restores the best set found so far as the current support (NN-HTP is not
 * monotone; every stage starts from the best, not the last, iterate). */
static sinew_result restore_best(trainer *t, select_buf *sb, sw_error *err) {
    if (t->current_is_best) return SINEW_OK;
    memcpy(sb->list, t->best_ids, (size_t)t->best_n * sizeof(int64_t));
    memcpy(sb->x0, t->best_w, (size_t)t->best_n * sizeof(double));
    return sw_cubature_solve_on(t, sb->list, t->best_n, sb->x0, err);
}

/* The gradient step left the support unchanged: in a coherent dictionary (all
 * columns alike, e.g. all positive) HTP's step mu h is then too short to swap any
 * entry, however poor the support. Escape as subspace pursuit / CoSaMP do: NNLS on
 * the merged set S (support + new entries, list[0..nS)), keep the sb_s largest
 * contributions w_e |a_e|, re-solve. Sets *done when the support still repeats. */
static sinew_result nnhtp_merge_step(trainer *t, select_buf *sb, int64_t sb_s, int64_t nS,
                                     int *done, sw_error *err) {
    const int64_t s_old = t->s;
    int64_t *old = sb->batch; /* the sample is consumed: reuse as scratch */
    memcpy(old, t->ids, (size_t)s_old * sizeof(int64_t));
    int64_t *nl = sb->list + nS;
    double *nx = sb->x0 + nS;
    memcpy(nl, sb->list, (size_t)nS * sizeof(int64_t));
    for (int64_t i = 0; i < nS; ++i)
        nx[i] = i < s_old ? t->w[i] : 0;
    sinew_result res = sw_cubature_solve_on(t, nl, nS, nx, err);
    if (res != SINEW_OK) return res;
    if (t->s > sb_s) {
        int64_t k = 0;
        for (int64_t i = 0; i < t->s; ++i)
            sb->keys[k++] = (keyed){t->w[i] * t->cc.norm[t->ids[i]], i};
        qsort(sb->keys, (size_t)k, sizeof(keyed), sw_cubature_by_key_desc);
        for (int64_t i = 0; i < sb_s; ++i) {
            nl[i] = t->ids[sb->keys[i].i];
            nx[i] = t->w[sb->keys[i].i];
        }
        res = sw_cubature_solve_on(t, nl, sb_s, nx, err);
        if (res != SINEW_OK) return res;
    }
    int same = t->s == s_old;
    for (int64_t i = 0; same && i < s_old; ++i)
        same = t->pos[old[i]] >= 0;
    *done = same;
    t->iterations++;
    return SINEW_OK;
}

/* One NN-HTP iteration (Algorithm 3, eqs. 2.17-2.19) with support bound sb_s and a
 * lazy gradient on K random outside candidates. With h = A^T r = -grad g / 2, the
 * step w + mu h (mu from eq. 2.19, where the factor 2 cancels) is thresholded to its
 * sb_s largest positive entries. Sets *done when the support would not change (2:
 * when no outside candidate correlates with r at all). */
static sinew_result nnhtp_step(trainer *t, select_buf *sb, int64_t sb_s, int *done, sw_error *err) {
    const int64_t m = t->m, s = t->s;
    int64_t K = t->par.candidates > 0 ? t->par.candidates : NNHTP_CANDIDATE_FACTOR * sb_s;
    K = sw_cubature_sample(t, K, sb->batch);
    sinew_result res = sw_cubature_cache_fetch(&t->cc, sb->batch, K, t->r, sb->score, err);
    if (res != SINEW_OK) return res;
    /* eq. 2.18: the support plus the sb_s outside entries of largest -grad. */
    int64_t npos = 0;
    for (int64_t i = 0; i < K; ++i)
        if (sb->score[i] > 0) sb->keys[npos++] = (keyed){sb->score[i], i};
    if (npos == 0) { /* 2: every outside candidate was examined */
        *done = K == t->nc - t->s ? 2 : 1;
        return SINEW_OK;
    }
    qsort(sb->keys, (size_t)npos, sizeof(keyed), sw_cubature_by_key_desc);
    if (npos > sb_s) npos = sb_s;
    int64_t nS = s + npos;
    double *h = sb->x0; /* h on S: support first, then the new entries */
    for (int64_t i = 0; i < s; ++i) {
        sb->list[i] = t->ids[i];
        h[i] = sw_dot(t->cc.col[t->ids[i]], t->r, m);
    }
    for (int64_t i = 0; i < npos; ++i) {
        sb->list[s + i] = sb->batch[sb->keys[i].i];
        h[s + i] = sb->keys[i].key;
    }
    /* eq. 2.19: mu = |h_S|^2 / |A h_S|^2. */
    double hh = 0, *Ah = sb->score + K; /* room: see train() */
    memset(Ah, 0, (size_t)m * sizeof(double));
    for (int64_t i = 0; i < nS; ++i) {
        const double *a = t->cc.col[sb->list[i]];
        hh += h[i] * h[i];
        for (int64_t q = 0; q < m; ++q)
            Ah[q] += h[i] * a[q];
    }
    double AhAh = sw_dot(Ah, Ah, m);
    double mu = AhAh > 0 ? hh / AhAh : 0;
    /* eq. 2.17: H_s^+ keeps the sb_s largest positive entries of w + mu h. */
    int64_t nv = 0;
    for (int64_t i = 0; i < nS; ++i) {
        double v = (i < s ? t->w[i] : 0) + mu * h[i];
        if (v > 0) sb->keys[nv++] = (keyed){v, i};
    }
    qsort(sb->keys, (size_t)nv, sizeof(keyed), sw_cubature_by_key_desc);
    if (nv > sb_s) nv = sb_s;
    /* Algorithm 3 line 9: stop when the support repeats. */
    int64_t kept_old = 0;
    for (int64_t i = 0; i < nv; ++i)
        kept_old += sb->keys[i].i < s;
    int64_t *nl = sb->list + nS;
    double *nx = sb->x0 + nS;
    if (kept_old == s && nv == s) return nnhtp_merge_step(t, sb, sb_s, nS, done, err);
    /* Gather list/x0 in selection order into the tail scratch, then solve. */
    for (int64_t i = 0; i < nv; ++i) {
        nl[i] = sb->list[sb->keys[i].i];
        double wi = sb->keys[i].i < s ? t->w[sb->keys[i].i] : 0;
        nx[i] = wi + mu * h[sb->keys[i].i];
    }
    res = sw_cubature_solve_on(t, nl, nv, nx, err);
    if (res == SINEW_OK) t->iterations++;
    return res;
}

/* One NN-HTP stage with support bound `bound`, from the best set so far; ends when a
 * set of at most `bound` points meets tol (*ok = 1), the support repeats, the error
 * stalls, or after NNHTP_STAGE_ITERATIONS. */
static sinew_result nnhtp_stage(trainer *t, select_buf *sb, int64_t bound, int *ok, sw_error *err) {
    sinew_result res = restore_best(t, sb, err);
    if (res != SINEW_OK) return res;
    double stage_best = INFINITY;
    int stall = 0;
    *ok = 0;
    for (int it = 0; it < NNHTP_STAGE_ITERATIONS; ++it) {
        if (t->s <= bound && t->rel <= t->par.tol) {
            *ok = 1;
            return SINEW_OK;
        }
        int done = 0;
        res = nnhtp_step(t, sb, bound, &done, err);
        if (res != SINEW_OK) return res;
        if (done == 2) break;
        /* Algorithm 3 stops when the support repeats. With a lazy gradient that only
         * means this sample held nothing better: count it as a stalled iteration. */
        if (!done && t->rel < stage_best * (1 - 1e-3)) {
            stage_best = t->rel;
            stall = 0;
        } else if (++stall >= NNHTP_STALL) {
            break;
        }
    }
    *ok = t->s <= bound && t->rel <= t->par.tol;
    return SINEW_OK;
}

/* NN-HTP with a growing support bound: s = 8, 16, 32, ... (capped by max_points)
 * until a stage meets tol; then bisection on the bound between the last failing and
 * the succeeding size, since doubling can overshoot the needed size by up to 2x. */
sinew_result sw_cubature_run_nnhtp(trainer *t, select_buf *sb, sw_error *err) {
    const int64_t max_points = t->par.max_points;
    int64_t lo = 0, bound = max_points < NNHTP_FIRST_SIZE ? max_points : NNHTP_FIRST_SIZE;
    int ok = 0;
    for (;;) {
        sinew_result res = nnhtp_stage(t, sb, bound, &ok, err);
        if (res != SINEW_OK) return res;
        if (ok || t->best_rel <= t->par.tol) break;
        if (bound >= max_points) return restore_best(t, sb, err);
        lo = bound;
        int64_t next = (int64_t)ceil((double)bound * NNHTP_GROWTH);
        bound = next > max_points ? max_points : next;
    }
    for (int64_t hi = t->best_n; hi - lo > 1 + hi / NNHTP_REFINE;) {
        int64_t mid = lo + (hi - lo) / 2;
        sinew_result res = nnhtp_stage(t, sb, mid, &ok, err);
        if (res != SINEW_OK) return res;
        if (ok)
            hi = t->best_n;
        else
            lo = mid;
    }
    return restore_best(t, sb, err);
}
