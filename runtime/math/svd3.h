/* Robust 3x3 singular value decomposition and polar decomposition.
 * Row-major 3x3 matrices. No allocation, deterministic, branch-light. */
#ifndef SW_SVD3_H
#define SW_SVD3_H

/* A = U diag(s) V^T with U, V proper rotations (det +1) and s sorted by decreasing
 * absolute value... precisely: s[0] >= s[1] >= |s[2]|, where only s[2] may be
 * negative (when det A < 0): the "rotation-variant" SVD of Irving et al. 2004.
 * Handles rank-deficient, zero and nearly-degenerate A. */
void sw_svd3(const double A[9], double U[9], double s[3], double V[9]);

/* sw_svd3 with the Jacobi iteration started from V0, a proper rotation (e.g. the V of
 * the same element's previous evaluation): the same decomposition, reached in fewer
 * sweeps when V0 is close. It stops after a sweep whose pairs were all within 1e-8 of
 * orthogonal (sw_svd3 sweeps on until none rotates): singular values to working
 * precision; U V^T to working precision where the singular values are apart, within
 * ~1e-8 where they cluster. V may alias V0. */
void sw_svd3_warm(const double A[9], const double V0[9], double U[9], double s[3], double V[9]);

/* Polar decomposition A = R S with R a proper rotation, R = U V^T from sw_svd3
 * (so for inverted A, S is symmetric but indefinite). S may be NULL. */
void sw_polar3(const double A[9], double R[9], double S[9]);

/* The rotation R of A = R S (S symmetric positive definite) by Newton's iteration
 * X <- (X + X^-T) / 2 from X = A (Higham 1986): no SVD, a handful of 3x3 inverses,
 * quadratic convergence. Only for A safely non-inverted: returns 0 (R untouched) when
 * det A <= 1e-6 |A|_F^3 / (3 sqrt 3) or A is not finite, or the iteration has not converged
 * in its budget (stretches beyond ~100x); the caller then takes sw_svd3. Where it
 * returns 1, R equals sw_polar3's R to working precision (both are the unique polar
 * factor), not bitwise. */
int sw_polar3_newton(const double A[9], double R[9]);
#endif
