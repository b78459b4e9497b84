/* The patch in a dynamic step (condense.h; thesis §4.4.2's dynamics oracle): backward
 * Euler for the patch vertices with their lumped masses, in the world frame where the
 * reduced part carries the bones' inertial forces, and the oracle that keeps a patch
 * until its flesh has settled. */
#include <math.h>
#include <string.h>

#include "condense.h"
#include "dqs.h"

void sw_cond_dynamics_start(sw_cond *c, const sw_reduced *red, const sw_solver *s,
                            const sw_dyn_coef *dc, const sw_dualquat *dq_prev,
                            const sw_dualquat *dq_prev2) {
    const sw_blob_view *v = c->v;
    int32_t R = red->R;
    for (int32_t j = 0; j < R; ++j) /* q one step before q_n, from its velocity */
        c->q_prev[j] = s->qn[j] - dc->h * s->qdot[j];
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t gv = c->fv[i];
        double *xn = c->xn + 3 * (int64_t)i, *vn = c->vn + 3 * (int64_t)i;
        double *dn = c->dev_n + 3 * (int64_t)i, *rn = c->rate_n + 3 * (int64_t)i;
        int was = c->dyn_at[gv] == c->stamp - 1;
        for (int k = 0; k < 3; ++k) { /* its deviation from the subspace and its rate */
            dn[k] = was ? c->pdev[3 * (int64_t)gv + k] : 0;
            rn[k] = was ? c->prate[3 * (int64_t)gv + k] : 0;
        }
        if (was) { /* in the last step's patch: its own state */
            memcpy(xn, c->px + 3 * (int64_t)gv, 3 * sizeof(double));
            memcpy(vn, c->pv + 3 * (int64_t)gv, 3 * sizeof(double));
        } else if (dq_prev) { /* entering: where and how fast the subspace carried it */
            double x1[3];
            sw_cond_subspace_position(c, red, i, dq_prev, s->qn, xn);
            if (dq_prev2) {
                sw_cond_subspace_position(c, red, i, dq_prev2, c->q_prev, x1);
                for (int k = 0; k < 3; ++k)
                    vn[k] = (xn[k] - x1[k]) / dc->h;
            } else {
                vn[0] = vn[1] = vn[2] = 0;
            }
        } else { /* no pose history: at rest where the subspace has it now */
            sw_cond_subspace_position(c, red, i, NULL, s->qn, xn);
            vn[0] = vn[1] = vn[2] = 0;
        }
        for (int k = 0; k < 3; ++k) /* the start: the inertial prediction */
            c->x[3 * i + k] = xn[k] + dc->h * vn[k];
        c->mass[i] = v->vert_mass[gv];
    }
}

double sw_cond_inertia(sw_cond *c, const sw_dyn_coef *dc, const double *x, int want_hess) {
    double E = 0;
    for (int32_t i = 0; i < c->nf; ++i) {
        const double *xn = c->xn + 3 * (int64_t)i, *vn = c->vn + 3 * (int64_t)i,
                     *xi = x + 3 * (int64_t)i;
        double m = c->mass[i], a = dc->cm * m, b = dc->cd * dc->alpha * m;
        for (int k = 0; k < 3; ++k) {
            double e = xi[k] - xn[k] - dc->h * vn[k], d = xi[k] - xn[k];
            E += 0.5 * (a * e * e + b * d * d);
            c->gf[3 * i + k] += a * e + b * d;
        }
        if (want_hess)
            for (int k = 0; k < 3; ++k)
                c->Dw[9 * (int64_t)i + 4 * k] += a + b;
    }
    return E;
}

/* The dynamics oracle's thresholds, in units of the rest diagonal L: a patch folds back
 * once the mean speed of its flesh relative to the subspace falls below 0.05 L/s and its
 * mean acceleration below 1 L/s^2 (the thesis's test, both applied). */
#define SW_COND_SETTLED_SPEED 0.05
#define SW_COND_SETTLED_ACCEL 1.0

void sw_cond_dynamics_finish(sw_cond *c, const sw_reduced *red, const double *q,
                             const sw_dyn_coef *dc, double size) {
    double speed = 0, accel = 0;
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t gv = c->fv[i];
        const double *x = c->x + 3 * (int64_t)i, *xn = c->xn + 3 * (int64_t)i,
                     *vn = c->vn + 3 * (int64_t)i;
        double sp = 0, ac = 0, y[3];
        sw_cond_subspace_position(c, red, i, NULL, q, y);
        for (int k = 0; k < 3; ++k) {
            /* relative to the subspace (the bones' own motion is no reason to keep a
               patch): the deviation's rate and the rate's change */
            double dev = x[k] - y[k], rate = (dev - c->dev_n[3 * (int64_t)i + k]) / dc->h;
            double acc = (rate - c->rate_n[3 * (int64_t)i + k]) / dc->h;
            sp += rate * rate;
            ac += acc * acc;
            c->px[3 * (int64_t)gv + k] = x[k];
            c->pv[3 * (int64_t)gv + k] = (x[k] - xn[k]) / dc->h;
            c->pdev[3 * (int64_t)gv + k] = dev;
            c->prate[3 * (int64_t)gv + k] = rate;
        }
        (void)vn;
        speed += sqrt(sp) / c->nf;
        accel += sqrt(ac) / c->nf;
        c->dyn_at[gv] = c->stamp;
    }
    c->keep =
        c->nf > 0 && (speed > SW_COND_SETTLED_SPEED * size || accel > SW_COND_SETTLED_ACCEL * size);
    c->nkeep = 0;
    for (int32_t i = 0; c->keep && i < c->nf; ++i)
        c->keep_v[c->nkeep++] = c->fv[i];
}
