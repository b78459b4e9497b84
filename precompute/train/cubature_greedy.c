/* The additive cubature selectors: greedy (Algorithm 1) and importance sampling
 * (Algorithm 2), thesis §2.2.3. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cubature_internal.h"

/* The support followed by `extra` new ids: the NNLS warm start keeps the old weights. */
static sinew_result grow_support(trainer *t, select_buf *sb, const int64_t *extra, int64_t nextra,
                                 sw_error *err) {
    memcpy(sb->list, t->ids, (size_t)t->s * sizeof(int64_t));
    memcpy(sb->x0, t->w, (size_t)t->s * sizeof(double));
    for (int64_t i = 0; i < nextra; ++i) {
        sb->list[t->s + i] = extra[i];
        sb->x0[t->s + i] = 0;
    }
    return sw_cubature_solve_on(t, sb->list, t->s + nextra, sb->x0, err);
}

/* Algorithm 1 (An et al. 2008) and Algorithm 2 (Kim & Delaney 2013): add the best
 * correlated candidate of a random subset, or sample `per_iteration` of them with
 * probability proportional to a_e . r (eq. 2.15). Only the positive part counts:
 * under w >= 0 a column pointing away from the residual gets weight zero and would
 * be pruned right after the NNLS. Sets *stuck when no candidate can help. */
sinew_result sw_cubature_run_greedy(trainer *t, select_buf *sb, int *stuck, sw_error *err) {
    const int importance = t->par.selector == SW_CUBATURE_IMPORTANCE;
    const int64_t max_points = t->par.max_points;
    int64_t max_iter = 4 * max_points + 100, misses = 0;
    while (t->rel > t->par.tol && t->s < max_points && t->iterations < max_iter) {
        int64_t K = sw_cubature_sample(t, t->par.candidates, sb->batch);
        if (K == 0) break;
        sinew_result res = sw_cubature_cache_fetch(&t->cc, sb->batch, K, t->r, sb->score, err);
        if (res != SINEW_OK) return res;
        int64_t npos = 0;
        for (int64_t i = 0; i < K; ++i) {
            double sc = sb->score[i], nrm = t->cc.norm[sb->batch[i]];
            if (!(sc > 0 && nrm > 0)) continue;
            /* Greedy: cosine with r (Algorithm 1, line 5). Importance: Efraimidis-
             * Spirakis keys log(u)/p pick without replacement with probability ~ p. */
            double key = importance ? log(rng_unit(&t->rng)) / sc : sc / nrm;
            sb->keys[npos++] = (keyed){key, i};
        }
        if (npos == 0) {
            /* No candidate correlates with r: with all of them examined, the NNLS
             * over every candidate is optimal already and nothing can improve it. */
            if (K == t->nc - t->s || ++misses > 20) {
                *stuck = 1;
                break;
            }
            continue;
        }
        misses = 0;
        int64_t nadd = importance ? t->par.per_iteration : 1;
        if (nadd > max_points - t->s) nadd = max_points - t->s;
        if (nadd > npos) nadd = npos;
        qsort(sb->keys, (size_t)npos, sizeof(keyed), sw_cubature_by_key_desc);
        int64_t add[1];
        int64_t *extra = nadd == 1 ? add : sb->batch + K; /* room: see train() */
        for (int64_t i = 0; i < nadd; ++i)
            extra[i] = sb->batch[sb->keys[i].i];
        /* The chosen columns are still cached: nothing evicts before solve_on. */
        res = grow_support(t, sb, extra, nadd, err);
        if (res != SINEW_OK) return res;
        t->iterations++;
    }
    return SINEW_OK;
}
