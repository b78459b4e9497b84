/* Stage "cubature" (bake.c, sw_bake_stages): reads s->rig, s->domains, s->poses, s->basis; writes
 * s->cubature, the result's cubature_error_max and selector_*. */
/* Material cubature per domain (thesis eqs. 2.11-2.14). Training samples are the
 * reduced coordinates of the training snapshots, q = U^T d, and as many perturbed
 * copies (q + 0.5 * rms(q) * gaussian): at the snapshots themselves the reduced force
 * nearly balances, so the perturbations are what shows the force's shape (and with
 * inertia modes a third set, train_domain). Column e of
 * the fit matrix stacks tet e's reduced elastic force over the samples,
 *   a_e = sum_k (R_k U_k)^T f_{e,k}(x(q)),  x_k = R_k (rest_k + U_k q) + t_k,
 * each sample's block divided by the norm of the domain's full reduced force. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"

typedef struct {
    const sw_bake_state *s;
    int32_t dom, r, nsamples;
    const double *U;           /* domain basis, 3 n_d x r */
    const int32_t *tet_local;  /* 4 per domain tet: local copy index */
    const double *dminv, *vol; /* per domain tet */
    const double *q;           /* nsamples x r */
    const sw_dualquat *dq;     /* nsamples x nb (pose of each sample) */
    const double *inv_norm;    /* nsamples: 1 / |b_s| (0 drops the sample) */
    const double *mode_w;      /* r: weight of each reduced force component, or NULL */
    double mu, lambda;
} cub_ctx;

/* Reduced elastic force of domain tet i for sample s into a (r), unscaled. */
static void tet_reduced_force(const cub_ctx *c, int64_t i, int32_t smp, double *a) {
    const sw_bake_state *s = c->s;
    int32_t r = c->r, base = s->domains.dom_vert_ptr[c->dom];
    double xe[12], R[4][9], f[12];
    for (int k = 0; k < 4; ++k) {
        int32_t loc = c->tet_local[4 * i + k], v = s->domains.dom_verts[base + loc];
        double t[3], y[3];
        sw_dqs_blend(c->dq + (size_t)smp * s->rig.nb, s->rig.skin_bone + 4 * v,
                     s->rig.skin_weight + 4 * v, 4, R[k], t);
        const double *Uv = c->U + (size_t)3 * loc * r, *q = c->q + (size_t)smp * r;
        for (int d = 0; d < 3; ++d) {
            double acc = s->rig.ch.mesh.X[3 * v + d];
            for (int32_t j = 0; j < r; ++j)
                acc += Uv[d * r + j] * q[j];
            y[d] = acc;
        }
        for (int d = 0; d < 3; ++d)
            xe[3 * k + d] =
                R[k][3 * d] * y[0] + R[k][3 * d + 1] * y[1] + R[k][3 * d + 2] * y[2] + t[d];
    }
    sw_corot_eval(xe, c->dminv + 9 * i, c->vol[i], c->mu, c->lambda, f, NULL, 0);
    for (int32_t j = 0; j < r; ++j)
        a[j] = 0;
    for (int k = 0; k < 4; ++k) {
        const double *fk = f + 3 * k;
        double g[3]; /* R_k^T f_k */
        for (int d = 0; d < 3; ++d)
            g[d] = R[k][d] * fk[0] + R[k][3 + d] * fk[1] + R[k][6 + d] * fk[2];
        const double *Uv = c->U + (size_t)3 * c->tet_local[4 * i + k] * r;
        for (int d = 0; d < 3; ++d)
            for (int32_t j = 0; j < r; ++j)
                a[j] += Uv[d * r + j] * g[d];
    }
    if (c->mode_w)
        for (int32_t j = 0; j < r; ++j)
            a[j] *= c->mode_w[j];
}

/* Per mode j, 1 / sqrt(u_j^T K u_j) with K the domain's rest stiffness: a force error
 * along a mode moves the solution by the error over its stiffness, so weighting each
 * reduced force component by this asks the fit for the same displacement accuracy in
 * every mode (soft inertia modes otherwise get a share of the error they cannot bear). */
static void mode_weights(const cub_ctx *c, int32_t ntd, double *w) {
    const sw_bake_state *s = c->s;
    int32_t r = c->r, base = s->domains.dom_vert_ptr[c->dom];
    for (int32_t j = 0; j < r; ++j)
        w[j] = 0;
    for (int32_t i = 0; i < ntd; ++i) {
        double xe[12], K[144], f[12];
        for (int k = 0; k < 4; ++k)
            memcpy(xe + 3 * k,
                   s->rig.ch.mesh.X +
                       3 * (int64_t)s->domains.dom_verts[base + c->tet_local[4 * i + k]],
                   24);
        sw_corot_eval(xe, c->dminv + 9 * i, c->vol[i], c->mu, c->lambda, f, K, 0);
        for (int32_t j = 0; j < r; ++j) {
            double u[12], ku = 0;
            for (int k = 0; k < 4; ++k)
                for (int d = 0; d < 3; ++d)
                    u[3 * k + d] = c->U[(size_t)(3 * c->tet_local[4 * i + k] + d) * r + j];
            for (int a = 0; a < 12; ++a)
                for (int b = 0; b < 12; ++b)
                    ku += u[a] * K[12 * a + b] * u[b];
            w[j] += ku;
        }
    }
    for (int32_t j = 0; j < r; ++j)
        w[j] = w[j] > 0 ? 1.0 / sqrt(w[j]) : 1.0;
}

static void column(void *vctx, int64_t cand, double *col) {
    const cub_ctx *c = vctx;
    for (int32_t smp = 0; smp < c->nsamples; ++smp) {
        double *a = col + (size_t)smp * c->r;
        tet_reduced_force(c, cand, smp, a);
        for (int32_t j = 0; j < c->r; ++j)
            a[j] *= c->inv_norm[smp];
    }
}

/* The domain's tets are summed in fixed chunks of SUM_CHUNK tets, each chunk into its
 * own slot, and the chunks then in order: the sum's rounding is the same for any number
 * of bake threads (per-worker partial sums were not: their split follows the pool's
 * size, and the cubature weights moved with it). */
#define SUM_CHUNK 64

typedef struct {
    const cub_ctx *c;
    int64_t ntets;
    double *partial; /* chunks x nsamples x r */
} sum_ctx;

static void sum_worker(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)worker;
    sum_ctx *sc = vctx;
    const cub_ctx *c = sc->c;
    size_t block = (size_t)c->nsamples * c->r;
    double a[1024];
    for (int64_t k = begin; k < end; ++k) {
        double *acc = sc->partial + (size_t)k * block;
        int64_t last = (k + 1) * SUM_CHUNK < sc->ntets ? (k + 1) * SUM_CHUNK : sc->ntets;
        for (int64_t i = k * SUM_CHUNK; i < last; ++i)
            for (int32_t smp = 0; smp < c->nsamples; ++smp) {
                tet_reduced_force(c, i, smp, a);
                for (int32_t j = 0; j < c->r; ++j)
                    acc[(size_t)smp * c->r + j] += a[j];
            }
    }
}

static double gauss(uint64_t *state) {
    uint64_t z1 = (*state += 0x9e3779b97f4a7c15ULL), z2 = (*state += 0x9e3779b97f4a7c15ULL);
    z1 = (z1 ^ (z1 >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z1 = (z1 ^ (z1 >> 27)) * 0x94d049bb133111ebULL;
    z2 = (z2 ^ (z2 >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z2 = (z2 ^ (z2 >> 27)) * 0x94d049bb133111ebULL;
    double u1 = ((double)((z1 ^ (z1 >> 31)) >> 11) + 0.5) * 0x1.0p-53;
    double u2 = (double)((z2 ^ (z2 >> 31)) >> 11) * 0x1.0p-53;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* The training samples of domain dom (sets of T each, q: sets T x r zeroed; dq: their
 * poses): the snapshots projected, q = U^T d; perturbed copies; with inertia modes a third
 * set moving those. 0 out of memory. */
static int training_samples(const sw_bake_state *s, int32_t dom, const double *dsnap, int32_t T,
                            const sw_dualquat *pose_dq, int32_t sets, double *q, sw_dualquat *dq) {
    int32_t r = s->basis.rank[dom], base = s->domains.dom_vert_ptr[dom],
            nvd = s->domains.dom_vert_ptr[dom + 1] - base;
    const double *U = s->basis.U[dom];
    double *rms = calloc((size_t)r, sizeof(double));
    if (!rms) return 0;
    for (int32_t a = 0; a < T; ++a) {
        for (int32_t j = 0; j < r; ++j) {
            double acc = 0;
            for (int32_t k = 0; k < nvd; ++k)
                for (int d = 0; d < 3; ++d)
                    acc +=
                        U[(size_t)(3 * k + d) * r + j] *
                        dsnap[(size_t)a * 3 * s->rig.nv + 3 * s->domains.dom_verts[base + k] + d];
            q[(size_t)a * r + j] = acc;
            rms[j] += acc * acc / T;
        }
        for (int k = 0; k < sets; ++k)
            memcpy(dq + (size_t)(k * T + a) * s->rig.nb, pose_dq + (size_t)a * s->rig.nb,
                   (size_t)s->rig.nb * sizeof(sw_dualquat));
    }
    uint64_t seed = s->p->seed ^ (0x9e37ULL * (uint64_t)(dom + 1));
    for (int32_t a = 0; a < T; ++a)
        for (int32_t j = 0; j < r; ++j)
            q[(size_t)(T + a) * r + j] = q[(size_t)a * r + j] + 0.5 * sqrt(rms[j]) * gauss(&seed);
    if (sets == 3) {
        /* inertia modes (bake_basis.c) are barely in the snapshots, so the perturbations
           above hardly move them, and a fit blind to their force leaves them wrongly stiff
           or soft: a third set moves them, each at the largest mode's amplitude, from the
           snapshots (moving the trained modes so far too costs the trained poses' fit:
           docs/notes/jiggle.md, Modes that swing) */
        double rmax = 0;
        for (int32_t j = 0; j < r; ++j)
            rmax = fmax(rmax, sqrt(rms[j]));
        for (int32_t a = 0; a < T; ++a)
            for (int32_t j = 0; j < r; ++j)
                q[(size_t)(2 * T + a) * r + j] =
                    q[(size_t)a * r + j] +
                    (j >= s->basis.rank_dynamic[dom] ? 0.5 * rmax * gauss(&seed) : 0);
    }
    free(rms);
    return 1;
}

/* b (nsamples x r): the domain's full reduced force per sample (Krysl projection), summed
 * in parallel per chunk of tets and then in chunk order (SUM_CHUNK), each sample's
 * normalised (c->inv_norm its 1 / |b_s|; 0 drops a force-free sample). 0 out of memory. */
static int sample_forces(const sw_bake_state *s, cub_ctx *c, int32_t ntd, double *inv_norm,
                         double *b) {
    size_t block = (size_t)c->nsamples * c->r;
    int64_t nchunks = ((int64_t)ntd + SUM_CHUNK - 1) / SUM_CHUNK;
    double *partial = calloc((size_t)nchunks * block, sizeof(double));
    if (!partial) return 0;
    sum_ctx sc = {c, ntd, partial};
    sw_pool_parallel_for(s->pool, nchunks, sum_worker, &sc);
    for (int64_t k = 0; k < nchunks; ++k)
        for (size_t i = 0; i < block; ++i)
            b[i] += partial[(size_t)k * block + i];
    free(partial);
    double bmax = 0;
    for (int32_t smp = 0; smp < c->nsamples; ++smp) {
        double n2 = 0;
        for (int32_t j = 0; j < c->r; ++j)
            n2 += b[(size_t)smp * c->r + j] * b[(size_t)smp * c->r + j];
        inv_norm[smp] = sqrt(n2);
        bmax = fmax(bmax, inv_norm[smp]);
    }
    for (int32_t smp = 0; smp < c->nsamples; ++smp) { /* normalise; drop force-free samples */
        double n = inv_norm[smp];
        inv_norm[smp] = n > 1e-9 * bmax && n > 0 ? 1.0 / n : 0.0;
        for (int32_t j = 0; j < c->r; ++j)
            b[(size_t)smp * c->r + j] *= inv_norm[smp];
    }
    return 1;
}

/* The fit of the samples' forces b by cubature points, the chosen selector's result in cr
 * (the others first, with compare_selectors, for the report). */
static sinew_result fit_points(sw_bake_state *s, int32_t dom, cub_ctx *c, int32_t ntd, double *b,
                               sw_cubature_result *cr, sw_bake_result *out, sw_error *err) {
    sw_cubature_problem prob = {(int64_t)c->nsamples * c->r, ntd, b, column, c};
    sw_cubature_params cp = sw_cubature_params_default();
    cp.tol = s->p->cubature_tol;
    cp.max_points = s->p->cubature_max < ntd ? s->p->cubature_max : ntd;
    cp.seed = s->p->seed + (uint64_t)dom;
    cp.threads = sw_pool_size(s->pool);
    for (int sel = 0; sel < 3; ++sel) { /* the chosen selector last: its result is kept */
        int which = sel == 2 ? (int)s->p->selector : (sel + (int)s->p->selector + 1) % 3;
        if (sel < 2 && !s->p->compare_selectors) continue;
        cp.selector = (sw_cubature_selector)which;
        sw_cubature_result_free(cr);
        sinew_result res = sw_cubature_train(&prob, &cp, cr, err);
        if (res == SINEW_ERROR_NOT_CONVERGED && cr->n > 0) res = SINEW_OK; /* best set, reported */
        if (res != SINEW_OK) return res;
        out->selector_points[which] += cr->n;
        out->selector_seconds[which] += cr->seconds;
        out->selector_error[which] = fmax(out->selector_error[which], cr->rel_error);
    }
    return SINEW_OK;
}

/* s->cubature's points and weights of domain dom from the fit. */
static sinew_result keep_points(sw_bake_state *s, int32_t dom, int32_t ntd,
                                const sw_cubature_result *cr, sw_bake_result *out) {
    /* No training pose deforms a domain whose fit chose nothing (a short bone of a coarse
       generated mesh, its flesh all driven or moving rigidly with it): its snapshots carry
       no force to fit. One tet standing for all of them keeps its unit mode's stiffness in
       the reduced system instead of leaving the domain without cubature. */
    int32_t n = cr->n > 0 ? (int32_t)cr->n : 1;
    s->cubature.n[dom] = n;
    s->cubature.local[dom] = malloc((size_t)n * sizeof(int32_t));
    s->cubature.w[dom] = malloc((size_t)n * sizeof(double));
    if (!s->cubature.local[dom] || !s->cubature.w[dom]) return SINEW_ERROR_OUT_OF_MEMORY;
    if (cr->n == 0) {
        s->cubature.local[dom][0] = 0;
        s->cubature.w[dom][0] = (double)ntd;
        return SINEW_OK;
    }
    for (int32_t i = 0; i < n; ++i) {
        s->cubature.local[dom][i] = (int32_t)cr->ids[i];
        s->cubature.w[dom][i] = cr->weights[i];
    }
    out->cubature_error_max = fmax(out->cubature_error_max, cr->rel_error);
    return SINEW_OK;
}

/* Trains domain dom's cubature; fills s->cubature.n/local/w[dom]. */
static sinew_result train_domain(sw_bake_state *s, int32_t dom, const double *dsnap, int32_t T,
                                 const sw_dualquat *pose_dq, sw_bake_result *out, sw_error *err) {
    int32_t r = s->basis.rank[dom];
    int32_t t0 = s->domains.dom_tet_ptr[dom], ntd = s->domains.dom_tet_ptr[dom + 1] - t0,
            sets = s->p->inertia_modes ? 3 : 2, ns = sets * T;
    sinew_result res = SINEW_ERROR_OUT_OF_MEMORY;
    int32_t *local_of = malloc((size_t)s->rig.nv * sizeof(int32_t));
    int32_t *tet_local = malloc((size_t)ntd * 4 * sizeof(int32_t));
    double *dminv = malloc((size_t)ntd * 9 * sizeof(double)),
           *vol = malloc((size_t)ntd * sizeof(double));
    double *q = calloc((size_t)ns * r, sizeof(double)),
           *inv_norm = malloc((size_t)ns * sizeof(double)),
           *b = calloc((size_t)ns * r, sizeof(double)), *mode_w = NULL;
    sw_dualquat *dq = malloc((size_t)ns * s->rig.nb * sizeof(sw_dualquat));
    sw_cubature_result cr;
    memset(&cr, 0, sizeof cr);
    if (!local_of || !tet_local || !dminv || !vol || !q || !inv_norm || !b || !dq) goto done;
    sw_bake_domain_tets(s, dom, local_of, tet_local, dminv, vol);
    if (!training_samples(s, dom, dsnap, T, pose_dq, sets, q, dq)) goto done;
    for (int32_t smp = 0; smp < ns; ++smp)
        inv_norm[smp] = 1.0;
    cub_ctx c = {s,        dom,  r, ns, s->basis.U[dom], tet_local, dminv, vol, q, dq,
                 inv_norm, NULL, 0, 0};
    sw_lame(s->rig.ch.youngs, s->rig.ch.poisson, &c.mu, &c.lambda);
    /* the force weighted by each mode's stiffness (mode_weights) where some modes are far
       softer than others: the inertia modes, and painted flesh, whose soft modes turn the
       same force error into a larger displacement (docs/notes/blender.md, Painted material) */
    if (s->p->inertia_modes || s->rig.ch.tet_stiffness) {
        if (!(mode_w = malloc((size_t)r * sizeof(double)))) goto done;
        mode_weights(&c, ntd, mode_w);
        c.mode_w = mode_w;
    }
    if (!sample_forces(s, &c, ntd, inv_norm, b)) goto done;
    if ((res = fit_points(s, dom, &c, ntd, b, &cr, out, err)) != SINEW_OK) goto done;
    res = keep_points(s, dom, ntd, &cr, out);
done:
    if (res == SINEW_ERROR_OUT_OF_MEMORY)
        sw_error_set(err, res, "out of memory training domain %d's cubature", dom);
    sw_cubature_result_free(&cr);
    free(local_of);
    free(tet_local);
    free(dminv);
    free(vol);
    free(q);
    free(inv_norm);
    free(dq);
    free(b);
    free(mode_w);
    return res;
}

sinew_result sw_bake_cubature(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    int32_t T = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        T += s->poses.train[i].npose;
    int64_t n3 = 3 * (int64_t)s->rig.nv;
    s->cubature.n = calloc((size_t)s->domains.nd, sizeof(int32_t));
    s->cubature.local = calloc((size_t)s->domains.nd, sizeof(int32_t *));
    s->cubature.w = calloc((size_t)s->domains.nd, sizeof(double *));
    double *dsnap = malloc((size_t)T * n3 * sizeof(double));
    double *R = malloc((size_t)s->rig.nv * 9 * sizeof(double)),
           *t = malloc((size_t)s->rig.nv * 3 * sizeof(double));
    sw_dualquat *pose_dq = malloc((size_t)T * s->rig.nb * sizeof(sw_dualquat));
    sinew_result res = SINEW_OK;
    if (!s->cubature.n || !s->cubature.local || !s->cubature.w || !dsnap || !R || !t || !pose_dq) {
        res = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for cubature");
        goto done;
    }
    /* the un-skinned snapshots again (cheap next to the simulations) */
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j, ++k) {
            const double *T12 = s->poses.train[i].T + (size_t)j * 12 * s->rig.nb,
                         *x = s->poses.train[i].x + (size_t)j * n3;
            double *d = dsnap + (size_t)k * n3;
            sw_bake_skin_transforms(s, T12, R, t);
            for (int32_t v = 0; v < s->rig.nv; ++v) {
                const double *Rv = R + 9 * v, *tv = t + 3 * v, *X = s->rig.ch.mesh.X + 3 * v;
                double w[3] = {x[3 * v] - tv[0], x[3 * v + 1] - tv[1], x[3 * v + 2] - tv[2]};
                for (int a = 0; a < 3; ++a)
                    d[3 * v + a] = Rv[a] * w[0] + Rv[3 + a] * w[1] + Rv[6 + a] * w[2] - X[a];
            }
            for (int32_t b = 0; b < s->rig.nb; ++b)
                sw_dq_from_transform(T12 + 12 * b, &pose_dq[(size_t)k * s->rig.nb + b]);
        }
    out->cubature_error_max = 0;
    sw_bake_progress_begin(s, "cubature", s->domains.nd);
    for (int32_t d = 0; d < s->domains.nd && res == SINEW_OK; ++d) {
        res = train_domain(s, d, dsnap, T, pose_dq, out, err);
        sw_bake_progress(s, 1);
    }
    for (int32_t d = 0; d < s->domains.nd && res == SINEW_OK; ++d)
        if (s->cubature.n[d] < 1) /* a blob needs one at least: say why here, not at the write */
            res = sw_error_set(err, SINEW_ERROR_DEGENERATE,
                               "domain %d: no cubature tets (rank %d): the training poses do not "
                               "deform it; give a clip that bends its joint",
                               d, s->basis.rank[d]);
done:
    free(dsnap);
    free(R);
    free(t);
    free(pose_dq);
    return res;
}
