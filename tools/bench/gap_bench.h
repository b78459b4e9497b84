/* sinew-bench --error-gap (issue 16, item 4): why the runtime misses more of the
 * correction than its basis does. On every held-out pose of the bake (and, as gap_train_*,
 * on every training pose, stepped in the bake's order as sw_bake_errors does), one
 * quasistatic instance (the bake's evaluation: SW_BAKE_EVAL_NEWTON iterations a step, in
 * self-contact mode `sc`) gives the runtime's state q_rt; the projection q_p = U^T d of the
 * reference's un-skinned displacement d (per domain, over its copies) is what the basis alone
 * holds. Both are measured by the one correction-error formula (sw_eval_acc), and the step's
 * reduced energy and its terms are evaluated at both:
 *   err_runtime, err_projection  the correction error of q_rt and of q_p
 *   projection_higher            poses where the reduced energy is higher at q_p than at
 *                                q_rt (all of them: the runtime is not stuck in a worse
 *                                minimum of the reduced energy; its minimum lies elsewhere)
 *   rt[4], proj[4]               the terms summed over the poses: the cubature's elastic
 *                                energy, the exact elastic energy of every tet through its
 *                                domain's copies, self-contact, interface springs
 * The exact energy against the cubature's at the same states says what the cubature
 * costs; the contact and spring terms what the other terms do. */
#ifndef SW_GAP_BENCH_H
#define SW_GAP_BENCH_H

#include <stdio.h>

#include "bake.h"

typedef struct sw_gap_set {
    int poses, projection_higher;
    double err_runtime, err_projection;
    double rt[4], proj[4]; /* cubature, exact, contact, springs */
} sw_gap_set;

typedef struct sw_gap_bench {
    sw_gap_set heldout, train; /* the held-out poses (gap_*), the training ones (gap_train_*) */
} sw_gap_bench;

sinew_result sw_gap_bench_run(const sinew_blob *blob, const sw_bake_result *res,
                              sinew_self_contact sc, sw_gap_bench *out, sw_error *err);

/* The figures as JSON members (each preceded by a comma: gap_* of the held-out poses,
 * gap_train_* of the training poses) or two lines for people. */
void sw_gap_bench_print(const sw_gap_bench *g, FILE *f, int json);

#endif
