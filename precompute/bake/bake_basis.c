/* Stage "basis" (bake.c, sw_bake_stages): reads s->rig, s->domains, s->poses; writes s->basis, the
 * result's *_proj_error and basis_energy. */
/* Skinning-correction basis (thesis §4.4.1, eq. 4.13): each full-space solution x is
 * pulled back through the skinning transform, d_v = R_v^T (x_v - t_v) - rest_v, and
 * each domain gets the uncentred PCA of its vertices' d over the training poses:
 * the leading eigenvectors of the snapshots' Gram matrix, lifted back to
 * U = D V S^-1 and re-orthonormalised. With sw_bake_params.pca_strain the Gram matrix
 * mixes the plain products D D^T with the snapshots' rest strain-energy products D K D^T:
 * the step finds the reduced energy's minimum, which for a linear model is the reference
 * projected in the energy norm (the Galerkin projection, bake_galerkin.c), so that span
 * is chosen for what this projection keeps of the training snapshots. Measured, it keeps
 * more modes at the same energy share, and its held-out gains come from those: at the
 * plain PCA's ranks it is no better (docs/notes/generalisation.md), so it is off by default. Rows
 * of bone-driven vertices are zero, so in the subspace those vertices follow their bone exactly, as
 * in the reference. A bake for dynamics appends inertia modes (add_inertia_modes). */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"
#include "fullsim.h"
#include "penalty.h"
#include "selfcontact.h"
#include "vec3.h"

/* Removes from the column c (m entries, stride cs) its components along the columns
 * lo..hi-1 of the orthonormal B (m rows, stride bs), twice (twice is enough, Kahan);
 * returns the norm of what is left. */
static double project_out(double *c, int64_t cs, const double *B, int64_t bs, int64_t m, int32_t lo,
                          int32_t hi) {
    for (int pass = 0; pass < 2; ++pass)
        for (int32_t k = lo; k < hi; ++k) {
            double dot = 0;
            for (int64_t i = 0; i < m; ++i)
                dot += B[i * bs + k] * c[i * cs];
            for (int64_t i = 0; i < m; ++i)
                c[i * cs] -= dot * B[i * bs + k];
        }
    double n = 0;
    for (int64_t i = 0; i < m; ++i)
        n += c[i * cs] * c[i * cs];
    return sqrt(n);
}

/* Modified Gram-Schmidt on the columns of U (m x r, row-major); returns the number of
 * independent columns kept (dependent ones are dropped, later columns shift left). */
static int32_t orthonormalise(double *U, int64_t m, int32_t r) {
    int32_t kept = 0;
    for (int32_t j = 0; j < r; ++j) {
        double n = project_out(U + j, r, U, r, m, 0, kept);
        if (n < 1e-10) continue;
        for (int64_t i = 0; i < m; ++i)
            U[i * r + kept] = U[i * r + j] / n;
        kept++;
    }
    return kept;
}

/* G (T x T) = D D^T, the plain products of the snapshots D (T rows of m). */
static void plain_gram(const double *D, int32_t T, int64_t m, double *G) {
    for (int32_t a = 0; a < T; ++a)
        for (int32_t b = a; b < T; ++b) {
            double g = 0;
            for (int64_t i = 0; i < m; ++i)
                g += D[(size_t)a * m + i] * D[(size_t)b * m + i];
            G[(size_t)a * T + b] = G[(size_t)b * T + a] = g;
        }
}

/* The Gram matrix G (T x T) domain dm's PCA takes (sw_bake_params.pca_strain = w): the
 * plain and the strain-energy products, each scaled to unit trace, mixed 1 - w : w.
 * 0 when out of memory. */
static int snapshot_gram(const sw_bake_state *s, int32_t dm, const double *D, int32_t T, int64_t m,
                         double *G) {
    double w = s->p->pca_strain;
    plain_gram(D, T, m, G);
    if (w <= 0) return 1;
    double *GK = malloc((size_t)T * T * sizeof(double));
    if (!GK || !sw_bake_strain_products(s, dm, D, T, NULL, 0, GK)) {
        free(GK);
        return 0;
    }
    double trp = 0, trk = 0;
    for (int32_t a = 0; a < T; ++a) {
        trp += G[(size_t)a * T + a];
        trk += GK[(size_t)a * T + a];
    }
    for (size_t i = 0; i < (size_t)T * T; ++i)
        G[i] = (trp > 0 ? (1 - w) * G[i] / trp : 0) + (trk > 0 ? w * GK[i] / trk : 0);
    free(GK);
    return 1;
}

/* Rank-r basis (row-major 3n x r) of a domain from snapshots D (T x 3n, row per pose) and
 * their Gram matrix G (T x T, overwritten). */
static double *domain_pca(const double *D, int32_t T, int64_t m, double *G, int32_t max_rank,
                          double energy, int64_t unit_row, int32_t *rank_out, double *kept_out) {
    double *ev = malloc((size_t)T * sizeof(double));
    double *U = NULL;
    if (!ev) goto done;
    openblas_set_num_threads(1);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', T, G, T, ev) != 0) goto done;
    double total = 0;
    for (int32_t k = 0; k < T; ++k)
        total += fmax(ev[k], 0.0);
    int32_t r = 0;
    double acc = 0;
    /* eigenvalues ascend: take from the top */
    while (r < T && r < max_rank && (r == 0 || acc < energy * total) &&
           ev[T - 1 - r] > 1e-14 * total) {
        acc += ev[T - 1 - r];
        r++;
    }
    *kept_out = total > 0 ? acc / total : 1.0;
    U = calloc((size_t)m * (r > 0 ? r : 1), sizeof(double));
    if (!U) goto done;
    if (r > 0) {
        for (int32_t k = 0; k < r; ++k) {
            int32_t col = T - 1 - k; /* eigenvector column in G (row-major: G[a*T + col]) */
            double sig = sqrt(fmax(ev[col], 1e-300));
            for (int32_t a = 0; a < T; ++a) {
                double c = G[(size_t)a * T + col] / sig;
                if (c == 0) continue;
                for (int64_t i = 0; i < m; ++i)
                    U[i * r + k] += c * D[(size_t)a * m + i];
            }
        }
        r = orthonormalise(U, m, r);
    }
    if (r == 0) { /* no deformation at all: one harmless unit mode (a zero column would
                     give the domain a zero reduced mass), on a free vertex when the domain
                     has one */
        r = 1;
        memset(U, 0, (size_t)m * sizeof(double));
        U[unit_row] = 1;
    }
    *rank_out = r;
done:
    free(ev);
    return U;
}

/* q_d = U_d^T d restricted to domain dm's copies (q: rank[dm] doubles). */
static void project(const sw_bake_state *s, int32_t dm, const double *d, double *q) {
    int32_t base = s->domains.dom_vert_ptr[dm], n = s->domains.dom_vert_ptr[dm + 1] - base,
            r = s->basis.rank[dm];
    const double *U = s->basis.U[dm];
    for (int32_t k = 0; k < r; ++k) {
        double acc = 0;
        for (int32_t j = 0; j < n; ++j)
            for (int i = 0; i < 3; ++i)
                acc += U[(size_t)(3 * j + i) * r + k] * d[3 * s->domains.dom_verts[base + j] + i];
        q[k] = acc;
    }
}

/* Relative projection error accumulators for the snapshots d (3 nv) of one pose, onto each
 * domain's first cols[dm] columns (orthonormal, so the projection onto a leading set is
 * the truncated sum), or onto all of them when cols is NULL. */
static void projection_error(const sw_bake_state *s, const double *d, const int32_t *cols,
                             double *num, double *den) {
    for (int32_t dm = 0; dm < s->domains.nd; ++dm) {
        int32_t base = s->domains.dom_vert_ptr[dm], n = s->domains.dom_vert_ptr[dm + 1] - base,
                r = cols ? cols[dm] : s->basis.rank[dm], ld = s->basis.rank[dm];
        const double *U = s->basis.U[dm];
        double q[1024];
        project(s, dm, d, q);
        for (int32_t j = 0; j < n; ++j)
            for (int i = 0; i < 3; ++i) {
                double p = 0;
                for (int32_t k = 0; k < r; ++k)
                    p += U[(size_t)(3 * j + i) * ld + k] * q[k];
                double dv = d[3 * s->domains.dom_verts[base + j] + i];
                *num += (dv - p) * (dv - p);
                *den += dv * dv;
            }
    }
}

/* Appends to U (m x r, row-major, orthonormal columns) up to `most` of the candidates C
 * (nc columns of m, one after another), greedily: each time the one that lies farthest
 * outside the span so far, measured against its own reference size ref[j], as long as
 * that is at least `tol`. Returns the new U (m x r'), orthonormal, and sets *r; NULL
 * when out of memory (U then untouched). */
static double *append_columns(const double *U, int64_t m, int32_t *r, const double *C, int32_t nc,
                              const double *ref, double tol, int32_t most) {
    int32_t r0 = *r, rn = r0 + (nc < most ? nc : most);
    double *W = calloc((size_t)m * rn, sizeof(double)),
           *R = malloc((size_t)nc * m * sizeof(double));
    double *score = malloc((size_t)nc * sizeof(double));
    if (!W || !R || !score) {
        free(W);
        free(R);
        free(score);
        return NULL;
    }
    for (int64_t i = 0; i < m; ++i)
        memcpy(W + i * rn, U + i * r0, (size_t)r0 * sizeof(double));
    memcpy(R, C, (size_t)nc * m * sizeof(double));
    /* R: the candidates' residuals outside the span of W's first `kept` columns */
    int32_t kept = 0;
    for (;; ++kept) {
        int32_t lo = kept ? r0 + kept - 1 : 0, hi = r0 + kept, best = -1;
        double top = tol;
        for (int32_t j = 0; j < nc; ++j) {
            double n = project_out(R + (size_t)j * m, 1, W, rn, m, lo, hi);
            score[j] = ref[j] > 0 ? n / ref[j] : 0;
            if (score[j] >= top) top = score[j], best = j;
        }
        if (best < 0 || r0 + kept == rn) break;
        const double *c = R + (size_t)best * m;
        double n = score[best] * ref[best];
        for (int64_t i = 0; i < m; ++i)
            W[i * rn + r0 + kept] = c[i] / n;
    }
    free(R);
    free(score);
    int32_t rk = r0 + kept; /* compact to m x rk */
    for (int64_t i = 0; i < m; ++i)
        memmove(W + i * rk, W + i * rn, (size_t)rk * sizeof(double));
    *r = rk;
    return W;
}

/* Inertia modes (sw_bake_params.inertia_modes): the snapshots are quasistatic shapes,
 * but a domain riding an accelerating bone is loaded by its own inertia, -M (a + alpha x
 * r) in the bone's frame (the inertial forces of blob_view.h), and the static response
 * to that lies largely outside them: the subspace bends too little under inertia and
 * overshoots too little when the motion stops (docs/notes/jiggle.md). The loads are each domain's
 * six rigid accelerations (its copies' masses times a unit translation, or a unit rotation about
 * its centroid); their static responses of the rest shape are the first load-dependent Ritz vectors
 * of structural dynamics (Wilson, Yuan & Dickens 1982). Every domain takes the restriction of every
 * response, not of its own loads' only: a response crosses the interface, and unless
 * both domains' copies can follow it there the interface springs (eq. 4.20) stiffen it,
 * and the overshoot stays short of the reference's. A restriction joins
 * the basis as far as it lies outside it by SW_INERTIA_MODE_TOL of its response's whole
 * norm (a far domain's sliver of a response is no mode of its own), largest first, at
 * most max_rank of them a domain.
 *
 * The 6 nd responses are first reduced to the SW_INERTIA_RITZ_PER_DOMAIN nd lowest
 * vibration modes in their span (a Rayleigh-Ritz step: K and M projected on the
 * responses, u_i^T K u_j = u_i^T f_j needing no K, and the small generalised eigenproblem
 * solved): the flesh's free motion after the skeleton stops is dominated by its lowest
 * modes, and the higher combinations of the responses, which every domain took as well,
 * cost rank without holding that motion (docs/notes/jiggle.md, Inertia Ritz modes). Of
 * those, only the modes that swing at the clips' time step join (sw_bake_ritz_swinging): a
 * stiff character's modes (the hand's) are gone within a frame of backward Euler, and far
 * above the lowest one a mode holds little of the free motion (docs/notes/jiggle.md, Modes
 * that swing). */
#define SW_INERTIA_MODE_TOL 0.05

/* Directions of the responses' mass matrix below this share of its largest eigenvalue are
 * no part of their span: responses dependent to rounding, or the zero response to a
 * domain whose vertices all ride bones. */
#define SW_RITZ_DEPENDENT 1e-12

/* sw_bake_ritz_modes (bake_state.h). */
int32_t sw_bake_ritz_modes(double *U, const double *F, const double *m, int32_t nl, int64_t n3,
                           int32_t ritz, double *lambda) {
    double *A = malloc((size_t)nl * nl * sizeof(double)),
           *B = malloc((size_t)nl * nl * sizeof(double)),
           *W = malloc((size_t)nl * nl * sizeof(double)),
           *P = malloc((size_t)nl * nl * sizeof(double)), *l = malloc((size_t)nl * sizeof(double)),
           *Y = calloc((size_t)ritz * n3, sizeof(double));
    int32_t got = -1;
    if (!A || !B || !W || !P || !l || !Y) goto done;
    for (int32_t i = 0; i < nl; ++i)
        for (int32_t j = 0; j <= i; ++j) {
            const double *ui = U + (size_t)i * n3, *uj = U + (size_t)j * n3;
            const double *fi = F + (size_t)i * n3, *fj = F + (size_t)j * n3;
            double a = 0, b = 0;
            for (int64_t t = 0; t < n3; ++t) {
                a += ui[t] * fj[t] + uj[t] * fi[t];
                b += ui[t] * m[t / 3] * uj[t];
            }
            A[i * nl + j] = A[j * nl + i] = 0.5 * a; /* K symmetric: the two agree to rounding */
            B[i * nl + j] = B[j * nl + i] = b;
        }
    got = 0;
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', nl, B, nl, l) != 0 || !(l[nl - 1] > 0)) goto done;
    int32_t kept = 0; /* W: nl x kept, row-major */
    for (int32_t c = 0; c < nl; ++c)
        if (l[c] > SW_RITZ_DEPENDENT * l[nl - 1]) {
            for (int32_t i = 0; i < nl; ++i)
                W[i * nl + kept] = B[i * nl + c] / sqrt(l[c]);
            ++kept;
        }
    for (int32_t a = 0; a < kept; ++a) /* P = W^T A W, kept x kept */
        for (int32_t b = 0; b <= a; ++b) {
            double acc = 0;
            for (int32_t i = 0; i < nl; ++i) {
                double ai = 0;
                for (int32_t j = 0; j < nl; ++j)
                    ai += A[i * nl + j] * W[j * nl + b];
                acc += W[i * nl + a] * ai;
            }
            P[a * kept + b] = P[b * kept + a] = acc;
        }
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', kept, P, kept, l) != 0) goto done;
    got = ritz < kept ? ritz : kept;
    if (lambda) memcpy(lambda, l, (size_t)got * sizeof(double));
    for (int32_t k = 0; k < got; ++k) /* eigenvalues ascending; column k of P its vector */
        for (int32_t i = 0; i < nl; ++i) {
            double c = 0;
            for (int32_t a = 0; a < kept; ++a)
                c += W[i * nl + a] * P[a * kept + k];
            const double *ui = U + (size_t)i * n3;
            for (int64_t t = 0; t < n3; ++t)
                Y[(size_t)k * n3 + t] += c * ui[t];
        }
    memcpy(U, Y, (size_t)got * n3 * sizeof(double));
done:
    free(A), free(B), free(W), free(P), free(l), free(Y);
    return got;
}

/* sw_bake_ritz_swinging (bake_state.h). */
int32_t sw_bake_ritz_swinging(const double *lambda, int32_t n, double h) {
    double top = SW_INERTIA_MAX_OMEGA_H / h;
    top *= top;
    int32_t k = 0;
    while (k < n && lambda[k] <= top &&
           lambda[k] <= SW_INERTIA_OMEGA_SPREAD * SW_INERTIA_OMEGA_SPREAD * lambda[0])
        ++k;
    return k;
}

/* The static responses of the rest shape to nl loads F (3 nverts each), reduced to the
 * `ritz` lowest vibration modes in their span when 0 < ritz < nl (sw_bake_ritz_modes), and of
 * those to the ones that swing at time step h (sw_bake_ritz_swinging) when h > 0, every
 * domain taking the restriction of every response (or mode) as far as it lies outside its
 * basis by `tol` of its whole norm, largest first, at most max_rank of them a domain. */
static sinew_result add_responses(sw_bake_state *s, int32_t nl, const double *F, double tol,
                                  int32_t ritz, double h, sw_error *err) {
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    sw_fullsim_params fp = sw_fullsim_params_default();
    fp.self_contact = 0;
    fp.pcg_rtol = 1e-8;
    fp.pcg_max = 100000;
    fp.threads = sw_pool_size(s->pool);
    sw_fullsim *sim = NULL;
    double *Uf = malloc((size_t)nl * n3 * sizeof(double)), *C = NULL, *gnorm = NULL,
           *lambda = malloc((size_t)nl * sizeof(double));
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!Uf || !lambda) goto done;
    if ((r = sw_fullsim_create(&s->rig.ch, &fp, &sim, err)) != SINEW_OK ||
        (r = sw_fullsim_rest_response(sim, nl, F, Uf, err)) != SINEW_OK)
        goto done;
    r = SINEW_ERROR_OUT_OF_MEMORY;
    if (ritz > 0 && ritz < nl) {
        int32_t got = sw_bake_ritz_modes(Uf, F, sw_fullsim_masses(sim), nl, n3, ritz, lambda);
        if (got < 0) goto done;
        nl = h > 0 ? sw_bake_ritz_swinging(lambda, got, h) : got;
        if (nl == 0) { /* the responses span nothing: no mode joins */
            r = SINEW_OK;
            goto done;
        }
    }
    if (!(gnorm = malloc((size_t)nl * sizeof(double)))) goto done;
    for (int32_t j = 0; j < nl; ++j) {
        double g = 0;
        for (int64_t i = 0; i < n3; ++i)
            g += Uf[(size_t)j * n3 + i] * Uf[(size_t)j * n3 + i];
        gnorm[j] = sqrt(g);
    }
    for (int32_t d = 0; d < s->domains.nd; ++d) {
        int32_t base = s->domains.dom_vert_ptr[d], n = s->domains.dom_vert_ptr[d + 1] - base;
        int64_t m = 3 * (int64_t)n;
        free(C);
        if (!(C = malloc((size_t)nl * m * sizeof(double)))) goto done;
        for (int32_t j = 0; j < nl; ++j)
            for (int32_t k = 0; k < n; ++k)
                memcpy(C + (size_t)j * m + 3 * k,
                       Uf + (size_t)j * n3 + 3 * s->domains.dom_verts[base + k],
                       3 * sizeof(double));
        double *W =
            append_columns(s->basis.U[d], m, &s->basis.rank[d], C, nl, gnorm, tol, s->p->max_rank);
        if (!W) goto done;
        free(s->basis.U[d]);
        s->basis.U[d] = W;
    }
    r = SINEW_OK;
done:
    if (r == SINEW_ERROR_OUT_OF_MEMORY) sw_error_set(err, r, "out of memory for response modes");
    sw_fullsim_destroy(sim);
    free(Uf);
    free(C);
    free(gnorm);
    free(lambda);
    return r;
}

static sinew_result add_inertia_modes(sw_bake_state *s, sw_error *err) {
    int32_t nd = s->domains.nd, nl = 6 * nd;
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    double *F = calloc((size_t)nl * n3, sizeof(double));
    if (!F) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for inertia modes");
    for (int32_t d = 0; d < nd; ++d) {
        int32_t b = s->domains.dom_vert_ptr[d], e = s->domains.dom_vert_ptr[d + 1];
        double c[3] = {0, 0, 0}, mt = 0;
        for (int32_t k = b; k < e; ++k)
            for (int i = 0; i < 3; ++i) {
                c[i] += s->domains.copy_mass[k] * s->rig.ch.mesh.X[3 * s->domains.dom_verts[k] + i];
                mt += i == 0 ? s->domains.copy_mass[k] : 0;
            }
        for (int i = 0; i < 3; ++i)
            c[i] = mt > 0 ? c[i] / mt : 0;
        for (int32_t k = b; k < e; ++k) {
            int32_t v = s->domains.dom_verts[k];
            double m = s->domains.copy_mass[k], x[3];
            for (int i = 0; i < 3; ++i)
                x[i] = s->rig.ch.mesh.X[3 * v + i] - c[i];
            for (int a = 0; a < 3; ++a) {
                double *ft = F + (size_t)(6 * d + a) * n3 + 3 * v,
                       *fr = F + (size_t)(6 * d + 3 + a) * n3 + 3 * v;
                double w[3] = {0, 0, 0}, rot[3];
                w[a] = 1;
                sw_v3_cross(w, x, rot);
                for (int i = 0; i < 3; ++i) {
                    ft[i] += m * w[i];
                    fr[i] += m * rot[i];
                }
            }
        }
    }
    /* the step the clips play at: the runtime's, unless a host steps otherwise */
    double fps = s->rig.ch.clip.fps > 0 ? s->rig.ch.clip.fps : 30.0;
    sinew_result r = add_responses(s, nl, F, SW_INERTIA_MODE_TOL, SW_INERTIA_RITZ_PER_DOMAIN * nd,
                                   1.0 / fps, err);
    free(F);
    return r;
}

/* Self-contact force modes (thesis §3.3.1; sw_bake_params.contact_modes): the flesh
 * pressed by flesh deforms locally, in shapes the snapshots show only at the training
 * poses; between them the contact forces of the runtime push the subspace where it has
 * no such shape. The loads are the training solutions' contact forces (the reference's
 * own, sw_contact_add_forces: eqs. 3.4-3.6 at unit stiffness, each vertex's force pulled
 * back to the rest frame by its skinning rotation), reduced to their SW_CONTACT_LOADS
 * principal loads (uncentred PCA, 99.99% of their energy); their static responses of the
 * rest shape join every domain's basis as the inertia modes do. */
#define SW_CONTACT_LOADS 12
#define SW_CONTACT_MODE_TOL 0.05
static sinew_result add_contact_modes(sw_bake_state *s, sw_error *err) {
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    int32_t T = 0, nl = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j)
            T += s->poses.train[i].contact_ptr[j + 1] > s->poses.train[i].contact_ptr[j];
    if (T == 0) return SINEW_OK; /* no training pose touches itself */
    double *L = calloc((size_t)T * n3, sizeof(double)), *f = malloc((size_t)n3 * sizeof(double));
    double *R = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->rig.nv * 3 * sizeof(double)), *P = NULL, *F = NULL, kept;
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!L || !f || !R || !t) goto done;
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i) {
        const sw_pose_seq *q = &s->poses.train[i];
        for (int32_t j = 0; j < q->npose; ++j) {
            if (q->contact_ptr[j + 1] == q->contact_ptr[j]) continue;
            const double *x = q->x + (size_t)j * n3;
            memset(f, 0, (size_t)n3 * sizeof(double));
            sw_contact_add_forces(q->contacts + q->contact_ptr[j],
                                  q->contact_ptr[j + 1] - q->contact_ptr[j], x, 1.0,
                                  SW_CONTACT_ALPHA, f);
            sw_bake_skin_transforms(s, q->T + (size_t)j * 12 * s->rig.nb, R, t);
            double *g = L + (size_t)k++ * n3;
            for (int32_t v = 0; v < s->rig.nv; ++v) {
                if (s->rig.ch.bone_of_vertex[v] >= 0) continue; /* held by its bone */
                const double *Rv = R + 9 * v, *fv = f + 3 * v;
                for (int a = 0; a < 3; ++a)
                    g[3 * v + a] = Rv[a] * fv[0] + Rv[3 + a] * fv[1] + Rv[6 + a] * fv[2];
            }
        }
    }
    double *G = malloc((size_t)T * T * sizeof(double));
    if (G) {
        plain_gram(L, T, n3, G);
        P = domain_pca(L, T, n3, G, SW_CONTACT_LOADS, 0.9999, 0, &nl, &kept);
    }
    free(G);
    if (!P) goto done;
    if (nl > 0 && !(F = malloc((size_t)nl * n3 * sizeof(double)))) goto done;
    for (int32_t j = 0; j < nl; ++j) /* P is n3 x nl, row-major: load j is its column */
        for (int64_t e = 0; e < n3; ++e)
            F[(size_t)j * n3 + e] = P[e * nl + j];
    r = nl > 0 ? add_responses(s, nl, F, SW_CONTACT_MODE_TOL, 0, 0, err) : SINEW_OK;
done:
    if (r == SINEW_ERROR_OUT_OF_MEMORY) sw_error_set(err, r, "out of memory for contact modes");
    free(L);
    free(f);
    free(R);
    free(t);
    free(P);
    free(F);
    return r;
}

/* Every training pose's solution with its skinning taken out (T poses, 3 nv each, in dall). */
static void unskinned_snapshots(sw_bake_state *s, double *dall, double *R, double *t) {
    const int64_t n3 = 3 * (int64_t)s->rig.nv;
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j, ++k)
            sw_bake_unskin(s, s->poses.train[i].T + (size_t)j * 12 * s->rig.nb,
                           s->poses.train[i].x + (size_t)j * n3, R, t, dall + (size_t)k * n3);
}

/* Each domain's trained modes: PCA of its vertices' snapshots (thesis §4.4.1); 0 when out
 * of memory. */
static int trained_modes(sw_bake_state *s, const double *dall, int32_t T, sw_bake_result *out) {
    const int64_t n3 = 3 * (int64_t)s->rig.nv;
    for (int32_t dm = 0; dm < s->domains.nd; ++dm) {
        int32_t base = s->domains.dom_vert_ptr[dm], n = s->domains.dom_vert_ptr[dm + 1] - base;
        double *D = malloc((size_t)T * 3 * n * sizeof(double));
        if (!D) return 0;
        for (int32_t a = 0; a < T; ++a)
            for (int32_t j = 0; j < n; ++j)
                memcpy(D + (size_t)a * 3 * n + 3 * j,
                       dall + (size_t)a * n3 + 3 * s->domains.dom_verts[base + j],
                       3 * sizeof(double));
        int32_t free0 = 0; /* the domain's first free vertex (0 when it has none) */
        while (free0 < n && s->rig.ch.bone_of_vertex[s->domains.dom_verts[base + free0]] >= 0)
            free0++;
        double *G = malloc((size_t)T * T * sizeof(double));
        if (G && snapshot_gram(s, dm, D, T, 3 * (int64_t)n, G))
            s->basis.U[dm] = domain_pca(D, T, 3 * (int64_t)n, G, s->p->max_rank, s->p->pca_energy,
                                        free0 < n ? 3 * (int64_t)free0 : 0, &s->basis.rank[dm],
                                        &out->basis_energy[dm]);
        free(G);
        free(D);
        if (!s->basis.U[dm]) return 0;
    }
    return 1;
}

/* The modes from physics after the trained ones in each domain's columns: contact, then
 * inertia; where each starts (rank_trained, rank_dynamic) and the total rank. */
static sinew_result physics_modes(sw_bake_state *s, sw_error *err) {
    const size_t rank_bytes = (size_t)s->domains.nd * sizeof(int32_t);
    s->basis.rank_trained = malloc(rank_bytes);
    s->basis.rank_dynamic = malloc(rank_bytes);
    if (!s->basis.rank_trained || !s->basis.rank_dynamic)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the basis");
    memcpy(s->basis.rank_trained, s->basis.rank, rank_bytes);
    sinew_result r = s->p->contact_modes ? add_contact_modes(s, err) : SINEW_OK;
    memcpy(s->basis.rank_dynamic, s->basis.rank, rank_bytes);
    if (r == SINEW_OK && s->p->inertia_modes) r = add_inertia_modes(s, err);
    s->basis.rank_total = 0;
    for (int32_t dm = 0; dm < s->domains.nd; ++dm)
        s->basis.rank_total += s->basis.rank[dm];
    return r;
}

/* The pose-space warm start: every training pose's feature and projected solution; 0
 * when out of memory. */
static int warm_start_table(sw_bake_state *s, const double *dall, int32_t T) {
    const int64_t n3 = 3 * (int64_t)s->rig.nv;
    s->basis.ntrain = T;
    s->basis.train_q = malloc((size_t)T * s->basis.rank_total * sizeof(double));
    s->basis.train_pose = malloc((size_t)T * 4 * s->rig.nb * sizeof(double));
    double *L = malloc((size_t)12 * s->rig.nb * sizeof(double));
    if (!s->basis.train_q || !s->basis.train_pose || !L) {
        free(L);
        return 0;
    }
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j, ++k) {
            sw_bake_pose_snapped(s, s->poses.train[i].T + (size_t)j * 12 * s->rig.nb, L);
            sw_pose_feature(L, s->rig.ch.skel.parent, s->rig.nb,
                            s->basis.train_pose + (size_t)k * 4 * s->rig.nb);
        }
    free(L);
    for (int32_t a = 0; a < T; ++a) {
        int32_t off = 0;
        for (int32_t dm = 0; dm < s->domains.nd; ++dm) {
            project(s, dm, dall + (size_t)a * n3,
                    s->basis.train_q + (size_t)a * s->basis.rank_total + off);
            off += s->basis.rank[dm];
        }
    }
    return 1;
}

/* How much of the training and held-out corrections the basis can hold at all (with and
 * without the modes from physics, held out). */
static void projection_errors(sw_bake_state *s, const double *dall, int32_t T, double *R, double *t,
                              double *dtmp, sw_bake_result *out) {
    const int64_t n3 = 3 * (int64_t)s->rig.nv;
    double num = 0, den = 0;
    for (int32_t a = 0; a < T; ++a)
        projection_error(s, dall + (size_t)a * n3, NULL, &num, &den);
    out->train_proj_error = den > 0 ? sqrt(num / den) : 0;
    num = den = 0;
    double num_t = 0, den_t = 0;
    out->rank_trained = 0;
    for (int32_t dm = 0; dm < s->domains.nd; ++dm)
        out->rank_trained += s->basis.rank_trained[dm];
    for (int32_t j = 0; j < s->poses.heldout.npose; ++j) {
        sw_bake_unskin(s, s->poses.heldout.T + (size_t)j * 12 * s->rig.nb,
                       s->poses.heldout.x + (size_t)j * n3, R, t, dtmp);
        projection_error(s, dtmp, NULL, &num, &den);
        projection_error(s, dtmp, s->basis.rank_trained, &num_t, &den_t);
    }
    out->heldout_proj_error = den > 0 ? sqrt(num / den) : 0;
    out->heldout_proj_error_trained = den_t > 0 ? sqrt(num_t / den_t) : 0;
}

sinew_result sw_bake_basis(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sinew_result r = SINEW_OK;
    int32_t T = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        T += s->poses.train[i].npose;
    const int64_t n3 = 3 * (int64_t)s->rig.nv;
    double *dall = malloc((size_t)T * n3 * sizeof(double));
    double *R = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->rig.nv * 3 * sizeof(double));
    double *dtmp = malloc((size_t)n3 * sizeof(double));
    s->basis.rank = calloc((size_t)s->domains.nd, sizeof(int32_t));
    s->basis.U = calloc((size_t)s->domains.nd, sizeof(double *));
    out->basis_energy = calloc((size_t)s->domains.nd + 1, sizeof(double));
    if (!dall || !R || !t || !dtmp || !s->basis.rank || !s->basis.U || !out->basis_energy) goto oom;
    unskinned_snapshots(s, dall, R, t);
    s->basis.rank_total = 0;
    if (!trained_modes(s, dall, T, out)) goto oom;
    if ((r = physics_modes(s, err)) != SINEW_OK) goto done;
    if (!warm_start_table(s, dall, T)) goto oom;
    projection_errors(s, dall, T, R, t, dtmp, out);
    goto done;
oom:
    r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the basis");
done:
    free(dall);
    free(R);
    free(t);
    free(dtmp);
    return r;
}
