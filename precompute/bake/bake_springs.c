/* Stage "springs" (bake.c, sw_bake_stages): reads s->reduce, the view, the training poses; writes
 * the view's spring Hessian (through s->reduce.spring) and the result's spring_*. */
/* The interface springs' stiffness (thesis eq. 4.20): k/2 |x_c - x_hub|^2 ties every copy
 * of a vertex to its hub copy (bake_reduce.c). Too stiff, and the domains' bases, which
 * cannot match exactly at an interface, lock each other: the reduced model holds only
 * the motions both sides share there. Too soft, and the copies part (the output takes
 * their mean, but each side of the seam follows its own domain: a crease) and the
 * domains drift apart. Where between depends on the character: the
 * training error is lowest at 10 E h on the hand, the fingers, the elephant and the
 * robot, at 2.5-5 E h on the Fox (docs/notes/game-assets.md).
 *
 * So, unless the caller gives k, the bake measures the training error (the bake's own
 * figure: pose-space self-contact, sw_bake_train_error) of the blob at each of
 * SW_SPRING_CHOICES stiffnesses, stiffest first, and keeps the one with the lowest; a
 * softer one must lower it by SW_SPRING_GAIN to be taken (the seams grow as k falls),
 * and the search stops at the first one that does not lower it at all. The held-out
 * poses are never looked at. The spring Hessian is linear in k: the choices scale the
 * unit Hessian of bake_reduce.c, so a blob baked with sw_bake_params.spring_k = the chosen
 * k is the very blob chosen. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"

double sw_bake_spring_mult(int i) {
    static const double mult[SW_SPRING_CHOICES] = {20, 10, 5, 2.5};
    return i >= 0 && i < SW_SPRING_CHOICES ? mult[i] : 0;
}

/* A softer stiffness is taken when its training error is below this share of the best
 * so far. */
#define SW_SPRING_GAIN 0.98

/* A stiffness above this many E h swamps the flesh in Newton's matrix (its elastic part
 * is lost to rounding next to the springs') and overflows the potential long before
 * a double does; no choice comes near it. */
#define SW_SPRING_MAX_EH 1e8

/* The blob's springs at stiffness k; an error for an absurd sw_bake_params.spring_k
 * (above SW_SPRING_MAX_EH E h, or springs that overflow). */
static sinew_result set_springs(const sw_bake_state *s, sw_bake_result *out, double k,
                                sw_error *err) {
    double *spring = s->reduce.spring; /* the view's, owned by out (bake_reduce.c) */
    int finite = 1;
    for (int64_t i = 0; i < s->reduce.nspring; ++i) {
        spring[i] = k * s->reduce.spring_unit_packed[i];
        finite &= isfinite(spring[i]) != 0;
    }
    out->spring_k = k;
    if (finite && !(k > SW_SPRING_MAX_EH * s->reduce.spring_eh)) return SINEW_OK;
    return sw_error_set(
        err, SINEW_ERROR_INVALID_ARGUMENT,
        "interface springs: stiffness %g is %g E h (E h = %g for this mesh), above the %g E h "
        "where they swamp the flesh (or overflow); without --spring-k the bake chooses among "
        "2.5-20 E h",
        k, s->reduce.spring_eh > 0 ? k / s->reduce.spring_eh : 0, s->reduce.spring_eh,
        SW_SPRING_MAX_EH);
}

sinew_result sw_bake_springs(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    out->nspring_tried = 0;
    out->spring_eh = s->reduce.spring_eh;
    if (s->p->spring_k > 0) return set_springs(s, out, s->p->spring_k, err);
    int best = -1;
    for (int c = 0; c < SW_SPRING_CHOICES; ++c) {
        double mult = sw_bake_spring_mult(c);
        void *mem = NULL;
        sinew_blob *blob = NULL;
        sw_eval_result e;
        sinew_result r = set_springs(s, out, mult * s->reduce.spring_eh, err);
        if (r == SINEW_OK) r = sw_bake_result_blob(out, &mem, &blob, err);
        if (r == SINEW_OK)
            r = sw_bake_train_error(blob, out, SINEW_SELF_CONTACT_POSE_SPACE, &e, NULL, err);
        sinew_blob_destroy(blob);
        free(mem);
        if (r != SINEW_OK) return r;
        out->spring_tried_mult[c] = mult;
        /* a step that failed counts as no better than skinning */
        out->spring_tried_err[c] = e.failed > 0 ? 1.0 : e.correction_error;
        out->nspring_tried = c + 1;
        double eb = best >= 0 ? out->spring_tried_err[best] : 0;
        if (best < 0 || out->spring_tried_err[c] < SW_SPRING_GAIN * eb)
            best = c;
        else if (out->spring_tried_err[c] >= eb)
            break; /* past the lowest */
    }
    return set_springs(s, out, sw_bake_spring_mult(best) * s->reduce.spring_eh, err);
}
