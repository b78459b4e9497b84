/* The contact penalty of thesis eqs. 3.4-3.6, the one law the reference's self-contact
 * (precompute/reference/selfcontact.c) and the step's pose-space contact share, so the
 * bake trains on the physics the frame computes.
 *
 * For a vertex p and its contact point v_s = sum_i beta_i x_ti on a surface triangle,
 * with the unit normal n and the area weight ka frozen:
 *   d = v_s - x_p,  N = (1 - alpha) n n^T + alpha I  (eq. 3.5, alpha = SW_CONTACT_ALPHA),
 *   E = 1/2 k ka d^T N d,  f_p = k ka N d (eq. 3.4),  f_ti = -beta_i k ka N d (eq. 3.6).
 * The pair acts while it collides, n . d > 0 (p behind the surface: the Heaviside of
 * eq. 3.12). */
#ifndef SW_PENALTY_H
#define SW_PENALTY_H

/* The anisotropy alpha of N (eq. 3.5): pushes along the normal at full stiffness and
 * tangentially at half (thesis §3.3.1). */
#define SW_CONTACT_ALPHA 0.5

/* o = N u with N = (1 - alpha) n n^T + alpha I (eq. 3.5); o may alias u. */
static inline void sw_penalty_apply_N(const double n[3], double alpha, const double u[3],
                                      double o[3]) {
    double s = (1 - alpha) * (n[0] * u[0] + n[1] * u[1] + n[2] * u[2]);
    for (int j = 0; j < 3; ++j)
        o[j] = s * n[j] + alpha * u[j];
}

/* N = (1 - alpha) n n^T + alpha I (eq. 3.5) as a row-major 3x3 matrix. */
static inline void sw_penalty_N(const double n[3], double alpha, double N[9]) {
    for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q)
            N[3 * r + q] = (1 - alpha) * n[r] * n[q] + (r == q ? alpha : 0);
}

/* n . d: positive while the pair collides (p behind the surface, eq. 3.12's Heaviside). */
static inline double sw_penalty_gap(const double n[3], const double d[3]) {
    return n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
}

/* E = 1/2 k d^T Nd for the pair's stiffness k (= k_contact ka) and Nd = N d. */
static inline double sw_penalty_energy(double k, const double d[3], const double Nd[3]) {
    return 0.5 * k * (d[0] * Nd[0] + d[1] * Nd[1] + d[2] * Nd[2]);
}

#endif
