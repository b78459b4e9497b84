/* The penalty of a flesh vertex against a collider surface (thesis eqs. 3.4-3.6 with a
 * collider's surface point as v_s), the one law the step (world_contact.c) and the
 * full-space reference (precompute/reference/worldcontact.c) share.
 *
 * Detection freezes, per (vertex, collider) candidate, the closest surface point a, the
 * outward normal n there, the pair stiffness k (collider stiffness times the vertex's
 * rest area) and the friction cap c = mu * lambda, lambda = k * max(0, -phi) the normal
 * force at detection (lagged friction: the cap of this step is the force of the last
 * detection). At a vertex position x, with d = a - x, g = n . d and d_t = d - g n:
 *   normal      E_n = 1/2 k max(g, 0)^2             (C1 across activation: no Heaviside
 *                                                    jump of eq. 3.12's force)
 *   tangential  E_t = 1/2 kt |d_t|^2                 |d_t| <= s  (sticking)
 *               E_t = c (|d_t| - s/2)               |d_t| >  s  (sliding, |f_t| = c)
 * with kt = alpha k (eq. 3.5's N = (1 - alpha) n n^T + alpha I: while sticking, E is
 * exactly eq. 3.4's 1/2 k d^T N d) and s = c / kt. Frictionless (c = 0) leaves E_n.
 * Both parts are convex in x, so the Hessian below is positive semi-definite. */
#ifndef SW_WORLD_PENALTY_H
#define SW_WORLD_PENALTY_H

#include <math.h>

#include "penalty.h"

/* One frozen candidate of the law above. */
typedef struct sw_world_pair {
    double a[3]; /* the collider's surface point at detection (world) */
    double n[3]; /* outward unit normal there */
    double k;    /* stiffness * rest area */
    double cap;  /* mu * lambda: the largest tangential force */
} sw_world_pair;

/* The law at x: returns E, writes the force on the vertex f = -dE/dx and, when H is not
 * NULL, the 3x3 Hessian d2E/dx2 (row-major). */
static inline double sw_world_penalty(const sw_world_pair *p, const double x[3], double f[3],
                                      double *H) {
    double d[3] = {p->a[0] - x[0], p->a[1] - x[1], p->a[2] - x[2]};
    double g = sw_penalty_gap(p->n, d), gp = g > 0 ? g : 0;
    double E = 0.5 * p->k * gp * gp;
    for (int i = 0; i < 3; ++i)
        f[i] = p->k * gp * p->n[i];
    if (H)
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                H[3 * r + c] = g > 0 ? p->k * p->n[r] * p->n[c] : 0;
    if (!(p->cap > 0)) return E;
    double dt[3] = {d[0] - g * p->n[0], d[1] - g * p->n[1], d[2] - g * p->n[2]};
    double kt = SW_CONTACT_ALPHA * p->k, s = p->cap / kt;
    double len = sqrt(dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2]);
    if (len <= s) { /* sticking: a tangential spring to the anchor */
        E += 0.5 * kt * len * len;
        for (int i = 0; i < 3; ++i)
            f[i] += kt * dt[i];
        if (H)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    H[3 * r + c] += kt * ((r == c) - p->n[r] * p->n[c]);
        return E;
    }
    /* sliding: the Coulomb force c along the tangential offset; its Hessian is the
     * curvature of |d_t| in the tangent plane, c / |d_t| (P - t t^T) */
    double t[3] = {dt[0] / len, dt[1] / len, dt[2] / len};
    E += p->cap * (len - 0.5 * s);
    for (int i = 0; i < 3; ++i)
        f[i] += p->cap * t[i];
    if (H)
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                H[3 * r + c] += p->cap / len * ((r == c) - p->n[r] * p->n[c] - t[r] * t[c]);
    return E;
}

#endif
