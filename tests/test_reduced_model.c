/* The reduced model the step minimises (runtime/solver/potential.c): its gradient against
 * finite differences with the pose-space contact pairs engaged, a quasistatic shape
 * that depends on the pose and the direction it was arrived at alone, the branch of
 * the reference's path it follows, and its accuracy against the full-space training
 * solutions it was baked from. */
#include <lapacke.h>
#include <math.h>

#include "bake_fixture.h"
#include "blob_pose_index.h"
#include "cubature.h"
#include "dqs.h"
#include "instance.h"
#include "instance_internal.h"
#include "solver.h"
#include "subspace_eval.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 3000, 12, 1);
    return fx_ok ? &fx : NULL;
}

static double urand(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * 0x1.0p-53;
}

/* g (the gradient at q for the pose last set) against central finite differences of
 * the potential, coordinate by coordinate; what and t name the pose in a failure. */
static void check_gradient(sinew_instance *inst, double *q, const double *g, int32_t R,
                           const char *what, int32_t t) {
    double gmax = 0;
    for (int32_t i = 0; i < R; ++i)
        gmax = fmax(gmax, fabs(g[i]));
    for (int32_t i = 0; i < R; ++i) {
        double h = 1e-6, qi = q[i];
        q[i] = qi + h;
        double ep = sw_instance_potential(inst, q, NULL, NULL);
        q[i] = qi - h;
        double em = sw_instance_potential(inst, q, NULL, NULL);
        q[i] = qi;
        ENSUREF(fabs((ep - em) / (2 * h) - g[i]) <= 1e-5 * gmax + 1e-8,
                "%s %d coordinate %d: finite difference %.9g, gradient %.9g", what, t, i,
                (ep - em) / (2 * h), g[i]);
    }
}

TEST(gradient_matches_finite_differences_with_contact_pairs) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    ENSUREF(v->ncontacts > 0, "the fixture's fold has no contact pairs: the test would prove less");
    int32_t R = v->rank_total;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    double *q = malloc(sizeof(double) * R), *g = malloc(sizeof(double) * R),
           *H = malloc(sizeof(double) * R * R);
    uint64_t seed = 7;
    int checked = 0;
    /* the most folded training poses: the ones with the most contact pairs */
    for (int32_t t = 0; t < v->ntrain; ++t) {
        if (v->contact_ptr[t + 1] - v->contact_ptr[t] < 3) continue;
        ENSURE(sw_instance_set_pose_d(inst, f->res.train_T + (size_t)t * 12 * v->nbones) ==
               SINEW_OK);
        for (int32_t i = 0; i < R; ++i)
            q[i] = v->train_q[(size_t)t * R + i] * (1 + 0.02 * (urand(&seed) - 0.5));
        double e = sw_instance_potential(inst, q, g, H);
        ENSURE(isfinite(e));
        check_gradient(inst, q, g, R, "training pose", t);
        /* the Newton matrix: symmetric and positive semi-definite */
        for (int32_t i = 0; i < R; ++i)
            for (int32_t j = 0; j < i; ++j)
                ENSURE(fabs(H[i * R + j] - H[j * R + i]) <= 1e-9 * (fabs(H[i * R + j]) + 1));
        for (int k = 0; k < 20; ++k) {
            double vHv = 0, vv = 0;
            for (int32_t i = 0; i < R; ++i)
                g[i] = urand(&seed) - 0.5;
            for (int32_t i = 0; i < R; ++i)
                for (int32_t j = 0; j < R; ++j)
                    vHv += g[i] * H[i * R + j] * g[j];
            for (int32_t i = 0; i < R; ++i)
                vv += g[i] * g[i];
            ENSURE(vHv >= -1e-9 * vv);
        }
        checked++;
    }
    ENSURE(checked > 0);
    free(q);
    free(g);
    free(H);
    sinew_instance_destroy(inst);
}

/* Halfway between poses A and B (12 per bone): each bone's rotation the normalised
 * mean of its two quaternions, its translation the mean. */
static void halfway_pose(const double *A, const double *B, int32_t nbones, double *T) {
    for (int32_t b = 0; b < nbones; ++b) {
        sw_dualquat qa, qb;
        sw_dq_from_transform(A + 12 * b, &qa);
        sw_dq_from_transform(B + 12 * b, &qb);
        double s = qa.r[0] * qb.r[0] + qa.r[1] * qb.r[1] + qa.r[2] * qb.r[2] + qa.r[3] * qb.r[3],
               r[4], n = 0;
        for (int i = 0; i < 4; ++i) {
            r[i] = qa.r[i] + (s < 0 ? -qb.r[i] : qb.r[i]);
            n += r[i] * r[i];
        }
        for (int i = 0; i < 4; ++i)
            r[i] /= sqrt(n);
        sw_quat_to_matrix(r, T + 12 * b);
        for (int i = 0; i < 3; ++i)
            T[12 * b + 9 + i] = 0.5 * (A[12 * b + 9 + i] + B[12 * b + 9 + i]);
    }
}

/* The pairs' tangential term (pose_space.c): the reference's whole law at a training
 * pose, a share of it between two, none far from every sample; the gradient stays the
 * energy's at a share in between. */
TEST(contact_tangential_share_fades_from_the_training_poses) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    int32_t R = v->rank_total, nb = v->nbones;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    double *q = malloc(sizeof(double) * R), *g = malloc(sizeof(double) * R),
           *T = malloc(sizeof(double) * 12 * nb);
    int checked = 0;
    for (int32_t t = 0; t + 1 < v->ntrain; ++t) {
        const double *Ta = f->res.train_T + (size_t)t * 12 * nb, *Tb = Ta + 12 * nb;
        if (v->contact_ptr[t + 1] - v->contact_ptr[t] < 3) continue;
        ENSURE(sw_instance_set_pose_d(inst, Ta) == SINEW_OK);
        ENSURE(isfinite(sw_instance_potential(inst, v->train_q + (size_t)t * R, NULL, NULL)));
        ENSUREF(inst->ps.tangent[0] == 1.0, "training pose %d: share %g", t, inst->ps.tangent[0]);
        halfway_pose(Ta, Tb, nb, T);
        ENSURE(sw_instance_set_pose_d(inst, T) == SINEW_OK);
        for (int32_t i = 0; i < R; ++i)
            q[i] = v->train_q[(size_t)t * R + i];
        double e = sw_instance_potential(inst, q, g, NULL);
        ENSURE(isfinite(e));
        if (inst->ps.npairs == 0) continue;
        if (!(inst->ps.tangent[0] > 0 && inst->ps.tangent[0] < 1))
            continue; /* a pose stored twice, or far apart */
        check_gradient(inst, q, g, R, "halfway after training pose", t);
        checked++;
    }
    ENSUREF(checked > 0, "no pose between two training poses with pairs in use");
    /* the first training pose with its bones turned 2 rad about x, alternately either
     * way: beyond every sample's reach */
    for (int32_t b = 0; b < nb; ++b) {
        const double *A = f->res.train_T + 12 * b;
        double a = b % 2 ? 2.0 : -2.0, c = cos(a), sn = sin(a);
        for (int i = 0; i < 3; ++i) { /* A R_x(a) */
            T[12 * b + 3 * i] = A[3 * i];
            T[12 * b + 3 * i + 1] = A[3 * i + 1] * c + A[3 * i + 2] * sn;
            T[12 * b + 3 * i + 2] = -A[3 * i + 1] * sn + A[3 * i + 2] * c;
        }
        for (int i = 9; i < 12; ++i)
            T[12 * b + i] = A[i];
    }
    double *feat = malloc(sizeof(double) * 4 * nb), far = INFINITY, reach = 0;
    sw_pose_feature(T, v->bone_parent, nb, feat);
    for (int32_t t = 0; t < v->ntrain; ++t) {
        far = fmin(far, sqrt(sw_pose_distance(feat, v->train_pose + (size_t)4 * nb * t, nb)));
        reach = fmax(reach, inst->ps.reach[t]);
    }
    free(feat);
    ENSUREF(far > reach, "the turned pose is %g from a sample, within reach %g", far, reach);
    ENSURE(sw_instance_set_pose_d(inst, T) == SINEW_OK);
    ENSURE(isfinite(sw_instance_potential(inst, v->train_q, NULL, NULL)));
    ENSUREF(inst->ps.tangent[0] == 0 && inst->ps.tangent[1] == 0, "far pose: shares %g %g",
            inst->ps.tangent[0], inst->ps.tangent[1]);
    free(q);
    free(g);
    free(T);
    sinew_instance_destroy(inst);
}

/* Steps inst to clip frame k (float transforms, as a host sets them). */
static void step_to_frame(const bake_fixture *f, sinew_instance *inst, int k, float *pose) {
    bake_fixture_pose(f, k, pose);
    ENSURE(sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
}

TEST(quasistatic_shape_depends_on_the_pose_and_its_last_motion_alone) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    sinew_instance *a, *b;
    ENSURE(sinew_instance_create(f->blob, NULL, &a) == SINEW_OK);
    ENSURE(sinew_instance_create(f->blob, NULL, &b) == SINEW_OK);
    float *pose = malloc(sizeof(float) * 12 * f->ch.skel.nbones),
          *xa = malloc(sizeof(float) * 3 * ns), *xb = malloc(sizeof(float) * 3 * ns);
    int nf = f->ch.clip.nframes;
    int32_t R = sw_blob_get_view(f->blob)->rank_total;
    double worst_share = 0;
    for (int k = 0; k < nf; ++k) { /* a plays the clip; b comes from frame k - 1 after a reset */
        step_to_frame(f, a, k, pose);
        ENSURE(sinew_instance_reset(b) == SINEW_OK);
        if (k > 0) step_to_frame(f, b, k - 1, pose);
        step_to_frame(f, b, k, pose);
        sinew_instance_read_surface(a, xa, NULL, ns);
        sinew_instance_read_surface(b, xb, NULL, ns);
        /* The reference Hessian Newton starts on is the last one evaluated (newton.c), so
         * the two take different paths to the pose's stationary point: each ends within
         * the solve's last update, SW_NEWTON_LAST_UPDATE |q| (a displacement norm: the
         * basis is orthonormal), of it. Another minimum would be far beyond. */
        double worst = 0, qn = sqrt(sw_dot(sw_instance_q(a), sw_instance_q(a), R));
        for (uint32_t i = 0; i < 3 * ns; ++i)
            worst = fmax(worst, fabs((double)xa[i] - xb[i]));
        worst_share = fmax(worst_share, qn > 0 ? worst / qn : worst);
        ENSUREF(worst <= 2 * SW_NEWTON_LAST_UPDATE * qn + 1e-9,
                "frame %d: played and arrived-at shapes differ by %g (|q| %g)", k, worst, qn);
    }
    fprintf(stderr, "    played and arrived-at shapes differ by %.2e |q| at most\n", worst_share);
    /* a reset forgets the motion: jumping to the last frame then matches a new instance */
    sinew_instance *c;
    ENSURE(sinew_instance_create(f->blob, NULL, &c) == SINEW_OK);
    ENSURE(sinew_instance_reset(a) == SINEW_OK);
    step_to_frame(f, a, nf - 1, pose);
    step_to_frame(f, c, nf - 1, pose);
    sinew_instance_read_surface(a, xa, NULL, ns);
    sinew_instance_read_surface(c, xb, NULL, ns);
    for (uint32_t i = 0; i < 3 * ns; ++i)
        ENSUREF(xa[i] == xb[i], "after a reset, coordinate %u differs from a new instance's", i);
    sinew_instance_destroy(c);
    free(pose);
    free(xa);
    free(xb);
    sinew_instance_destroy(a);
    sinew_instance_destroy(b);
}

/* The prediction of a step's pose: the blend of its two nearest training solutions. */
static void prediction(const sinew_instance *in, double *p) {
    const sw_blob_view *v = in->v;
    int32_t R = v->rank_total, a = in->ps.nearest;
    int32_t b = in->ps.blend == 0 ? a : in->ps.second;
    for (int32_t i = 0; i < R; ++i)
        p[i] = (1 - in->ps.blend) * v->train_q[(size_t)R * a + i] +
               in->ps.blend * v->train_q[(size_t)R * b + i];
}

/* A quasistatic step starts from its pose's prediction plus the last step's offset from
 * its own (step.c); after a pose jump, a reset or a failed step, from the prediction
 * alone. */
TEST(quasistatic_start_is_the_prediction_plus_the_last_offset) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int32_t R = sw_blob_get_view(f->blob)->rank_total, nb = f->ch.skel.nbones;
    int k = f->ch.clip.nframes / 2;
    sinew_instance *in;
    ENSURE(sinew_instance_create(f->blob, NULL, &in) == SINEW_OK);
    /* poses halfway between the clip's frames: not training poses, so the solutions are
     * off their predictions */
    double *T = malloc(sizeof(double) * 12 * (size_t)nb), *qa = malloc(sizeof(double) * (size_t)R),
           *pa = malloc(sizeof(double) * (size_t)R), *pk = malloc(sizeof(double) * (size_t)R);
    ENSURE(T && qa && pa && pk);
    const double *clip = f->ch.clip.T;
    for (int j = 0; j < k; ++j) {
        halfway_pose(clip + (size_t)j * 12 * nb, clip + (size_t)(j + 1) * 12 * nb, nb, T);
        ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    }
    memcpy(qa, sw_instance_q(in), sizeof(double) * (size_t)R);
    prediction(in, pa);
    double off = 0, qn = 0;
    for (int32_t i = 0; i < R; ++i) {
        off = fmax(off, fabs(qa[i] - pa[i]));
        qn = fmax(qn, fabs(qa[i]));
    }
    ENSUREF(off > 1e-3 * qn, "no offset from the prediction (%g of %g)", off, qn);
    /* the next pose: prediction plus offset */
    halfway_pose(clip + (size_t)k * 12 * nb, clip + (size_t)(k + 1) * 12 * nb, nb, T);
    ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK);
    sw_instance_step_prepare(in, 1.0f / 30);
    prediction(in, pk);
    double gap = 0;
    for (int32_t i = 0; i < R; ++i)
        gap = fmax(gap, fabs(sw_instance_q(in)[i] - (pk[i] + (qa[i] - pa[i]))));
    ENSUREF(gap <= 1e-12 * qn, "start %g from the prediction plus the offset", gap);
    /* the same pose declared a cut: the prediction alone */
    ENSURE(sinew_instance_mark_teleport(in) == SINEW_OK);
    memcpy((double *)sw_instance_q(in), qa, sizeof(double) * (size_t)R);
    sw_instance_step_prepare(in, 1.0f / 30);
    gap = 0;
    for (int32_t i = 0; i < R; ++i)
        gap = fmax(gap, fabs(sw_instance_q(in)[i] - pk[i]));
    ENSUREF(gap == 0, "after a cut the start is %g from the prediction", gap);
    /* and after a reset, from a state with an offset */
    ENSURE(sinew_instance_reset(in) == SINEW_OK);
    memcpy((double *)sw_instance_q(in), qa, sizeof(double) * (size_t)R);
    ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK);
    sw_instance_step_prepare(in, 1.0f / 30);
    prediction(in, pk); /* (the lookup follows the motion: a reset forgot it) */
    gap = 0;
    for (int32_t i = 0; i < R; ++i)
        gap = fmax(gap, fabs(sw_instance_q(in)[i] - pk[i]));
    fprintf(stderr, "    offset %.3g (|q| up to %.3g) carried to the next pose's start\n", off, qn);
    ENSUREF(gap == 0, "after a reset the start is %g from the prediction", gap);
    /* and after a failed step (a non-finite state: the start carries it, the solve fails) */
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    for (int32_t i = 0; i < R; ++i)
        ((double *)sw_instance_q(in))[i] = 1e300;
    ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK); /* held: nearer than any sample */
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_ERROR_NOT_FINITE);
    sw_instance_step_prepare(in, 1.0f / 30);
    prediction(in, pk);
    gap = 0;
    for (int32_t i = 0; i < R; ++i)
        gap = fmax(gap, fabs(sw_instance_q(in)[i] - pk[i]));
    ENSUREF(gap == 0, "after a failed step the start is %g from the prediction", gap);
    free(T);
    free(qa);
    free(pa);
    free(pk);
    sinew_instance_destroy(in);
}

/* Every step over the clip in Newton mode `mode` must end where a full Newton update from
 * its solution, on the exact potential's own gradient and (projected) Hessian, moves the
 * shape by less than the solve's convergence test allows (steps the update cap ended are
 * skipped: in the fold, plain Newton takes more than five updates too). Counts the
 * updates, factorisations and rest-Hessian updates of the steps. */
static void ends_at_newton_stationary_points(sinew_newton_hessian mode, uint32_t *updates,
                                             uint32_t *factors, uint32_t *rest, uint32_t *probed) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int32_t R = sw_blob_get_view(f->blob)->rank_total;
    sinew_instance_def d = sinew_instance_def_default();
    d.newton_hessian = mode;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
    float *pose = malloc(sizeof(float) * 12 * f->ch.skel.nbones);
    double *q = malloc(sizeof(double) * R), *g = malloc(sizeof(double) * R),
           *H = malloc(sizeof(double) * R * R);
    *updates = *factors = *rest = *probed = 0;
    int converged = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        step_to_frame(f, inst, k, pose);
        sinew_step_stats st = {.struct_size = sizeof st};
        ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK);
        *updates += st.newton_iterations;
        *factors += st.factorizations;
        *rest += st.rest_updates;
        /* a step whose updates were all on the reference and one of them on the factor of
           the iterate before (newton.c's probe after a fast update) */
        *probed += st.rest_updates == st.newton_iterations && st.factorizations < st.rest_updates;
        if (!(st.status & SINEW_STEP_CONVERGED)) continue; /* the update cap ended it */
        converged++;
        memcpy(q, sw_instance_q(inst), sizeof(double) * R);
        sw_instance_potential(inst, q, g, H);
        /* g <- H^-1 g: the Newton update, negated */
        ENSURE(LAPACKE_dposv(LAPACK_ROW_MAJOR, 'L', R, 1, H, R, g, 1) == 0);
        double dq = 0, qn = 0;
        for (int32_t i = 0; i < R; ++i) {
            dq += g[i] * g[i];
            qn += q[i] * q[i];
        }
        dq = sqrt(dq);
        qn = sqrt(qn);
        /* the solve's own test is SW_NEWTON_LAST_UPDATE |q| on its last update; one more
         * Newton update from there is smaller when the iterate is near the stationary
         * point */
        ENSUREF(dq <= SW_NEWTON_LAST_UPDATE * qn + 1e-9,
                "frame %d: a Newton update from the solution moves %g of %g", k, dq, qn);
    }
    ENSUREF(2 * converged >= f->ch.clip.nframes, "%d of %d steps converged", converged,
            f->ch.clip.nframes);
    free(pose);
    free(q);
    free(g);
    free(H);
    sinew_instance_destroy(inst);
}

/* Chord updates (newton.c) reuse an earlier iterate's factor: the steps still end at
 * Newton stationary points, and chord updates were taken. */
TEST(chord_updates_end_at_a_newton_stationary_point) {
    uint32_t updates, factors, rest, probed;
    ends_at_newton_stationary_points(SINEW_NEWTON_HESSIAN_CURRENT, &updates, &factors, &rest,
                                     &probed);
    ENSUREF(factors < updates, "no chord update taken: %u factorisations for %u updates", factors,
            updates);
    ENSURE(rest == 0);
}

/* Updates on the rest Hessian (newton.c) end with a shorter last update than Newton's,
 * since their error is not quadratic in its length: the steps end at Newton stationary
 * points all the same, and the rest updates were taken, some steps ending on the factor
 * of the iterate before a fast update (the probe). */
TEST(rest_first_updates_end_at_a_newton_stationary_point) {
    uint32_t updates, factors, rest, probed;
    ends_at_newton_stationary_points(SINEW_NEWTON_HESSIAN_REST_FIRST, &updates, &factors, &rest,
                                     &probed);
    fprintf(stderr,
            "    %u updates, %u of them on the rest Hessian, %u factorisations; %u steps "
            "ended on the factor of the iterate before\n",
            updates, rest, factors, probed);
    ENSUREF(rest > 0, "no rest update taken (%u updates)", updates);
    ENSUREF(probed > 0, "no step ended on the factor of the iterate before (%u updates)", updates);
}

/* The largest difference between domain blocks (sw_cubature_rest_hessian's layout), over
 * the largest entry of B. */
static double blocks_gap(const sw_blob_view *v, const double *A, const double *B) {
    double gap = 0, top = 0;
    for (int64_t i = 0; i < sw_cubature_rest_hessian_size(v); ++i) {
        gap = fmax(gap, fabs(A[i] - B[i]));
        top = fmax(top, fabs(B[i]));
    }
    return top > 0 ? gap / top : INFINITY;
}

/* The largest difference between the cubature's domain blocks of H at q = 0 (the pose
 * set on inst) and the rest Hessian's, over the largest entry of the rest Hessian. */
static double rest_hessian_gap(sinew_instance *inst) {
    const sw_blob_view *v = inst->v;
    int32_t R = v->rank_total;
    double *q = calloc((size_t)R, sizeof(double)),
           *B = malloc(sizeof(double) * (size_t)sw_cubature_rest_hessian_size(v));
    if (!q || !B) {
        free(q);
        free(B);
        return INFINITY;
    }
    sw_cubature_rest_hessian(&inst->red, B);
    sw_reduced_skin(&inst->red, inst->bone_dq);
    memset(inst->red.g, 0, sizeof(double) * (size_t)R);
    memset(inst->red.H, 0, sizeof(double) * (size_t)R * R);
    sw_cubature_eval(&inst->red, q, 1, 1);
    double gap = 0, top = 0;
    const double *B0 = B;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        int32_t r = v->domains[k].rank, o = v->domains[k].q_offset;
        for (int32_t i = 0; i < r; ++i)
            for (int32_t j = 0; j < r; ++j) {
                double h = inst->red.H[(int64_t)(o + i) * R + o + j], b = B[(int64_t)i * r + j];
                gap = fmax(gap, fabs(h - b));
                top = fmax(top, fabs(b));
            }
        B += (int64_t)r * r;
    }
    free(q);
    free((double *)B0);
    return top > 0 ? gap / top : INFINITY;
}

/* The rest Hessian (cubature.h) is the cubature's Hessian at q = 0 of the rest shape and
 * of the whole character turned and moved rigidly (each tet's corners turn together: U^T
 * R^T (R K0 R^T) R U = U^T K0 U); at a bent pose of the clip the tets across the joint
 * turn apart and it is not. */
TEST(rest_hessian_is_the_hessian_of_the_rigidly_moved_rest_shape) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    int32_t nb = f->ch.skel.nbones;
    sinew_instance_def d = sinew_instance_def_default();
    d.newton_hessian = SINEW_NEWTON_HESSIAN_REST_FIRST;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK && inst->red.h_ref);
    double *T = malloc(sizeof(double) * 12 * (size_t)nb);
    ENSURE(T);
    const double c = cos(0.9), s = sin(0.9), axis[3] = {0.48, 0.6, 0.64}; /* unit */
    double Rm[9]; /* Rodrigues: turned by 0.9 rad about the axis */
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double cross = (i == j) ? 0 : ((j == (i + 1) % 3) ? -axis[3 - i - j] : axis[3 - i - j]);
            Rm[3 * i + j] = (i == j ? c : 0) + (1 - c) * axis[i] * axis[j] + s * cross;
        }
    for (int32_t b = 0; b < nb; ++b) {
        memcpy(T + 12 * b, Rm, sizeof Rm);
        T[12 * b + 9] = 1.5;
        T[12 * b + 10] = -2;
        T[12 * b + 11] = 0.25;
    }
    double rest = rest_hessian_gap(inst); /* the pose of a fresh instance: rest */
    ENSURE(sw_instance_set_pose_d(inst, T) == SINEW_OK);
    double moved = rest_hessian_gap(inst);
    int k = f->ch.clip.nframes / 2; /* the clip bends the finger most half way */
    ENSURE(sw_instance_set_pose_d(inst, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
    double bent = rest_hessian_gap(inst);
    fprintf(stderr,
            "    largest difference over the largest entry: rest %.2e, moved %.2e, bent %.2e\n",
            rest, moved, bent);
    ENSUREF(rest <= 1e-12 && moved <= 1e-9, "rest %g, rigidly moved %g", rest, moved);
    ENSUREF(bent >= 1e-3, "bent %g: the test cannot tell the poses apart", bent);
    free(T);
    sinew_instance_destroy(inst);
}

/* Newton's reference Hessian (cubature.h) is the rest Hessian after creation and after a
 * reset, and a pass with the Hessian at a pose leaves that pose's blocks in it: the same
 * as the blocks an instance without a reference gets from the same pass. */
TEST(reference_hessian_is_the_last_evaluated_and_reset_restores_the_rest_one) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    int32_t nb = f->ch.skel.nbones, R = v->rank_total;
    int64_t n = sw_cubature_rest_hessian_size(v);
    sinew_instance_def d = sinew_instance_def_default();
    d.newton_hessian = SINEW_NEWTON_HESSIAN_REST_FIRST;
    sinew_instance *inst, *plain;
    ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK && inst->red.h_ref);
    d.newton_hessian = SINEW_NEWTON_HESSIAN_CURRENT;
    ENSURE(sinew_instance_create(f->blob, &d, &plain) == SINEW_OK && !plain->red.h_ref);
    double *rest = malloc(sizeof(double) * (size_t)n), *bent = malloc(sizeof(double) * (size_t)n),
           *q = calloc((size_t)R, sizeof(double));
    ENSURE(rest && bent && q);
    sw_cubature_rest_hessian(&inst->red, rest);
    double fresh = blocks_gap(v, inst->red.h_ref, rest);
    /* the cubature's blocks at a bent pose, from an instance that keeps no reference */
    const double *T = f->ch.clip.T + (size_t)(f->ch.clip.nframes / 2) * 12 * nb;
    sinew_instance *both[2] = {inst, plain};
    for (int k = 0; k < 2; ++k) {
        ENSURE(sw_instance_set_pose_d(both[k], T) == SINEW_OK);
        sw_reduced_skin(&both[k]->red, both[k]->bone_dq);
        memset(both[k]->red.g, 0, sizeof(double) * (size_t)R);
        memset(both[k]->red.H, 0, sizeof(double) * (size_t)R * R);
        sw_cubature_eval(&both[k]->red, q, 1, 1);
    }
    const double *H = plain->red.H;
    int64_t at = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        int32_t r = v->domains[k].rank, o = v->domains[k].q_offset;
        for (int32_t i = 0; i < r; ++i)
            for (int32_t j = 0; j < r; ++j)
                bent[at++] = H[(int64_t)(o + i) * R + o + j];
    }
    double kept = blocks_gap(v, inst->red.h_ref, bent), apart = blocks_gap(v, bent, rest);
    ENSURE(sinew_instance_reset(inst) == SINEW_OK);
    double after_reset = blocks_gap(v, inst->red.h_ref, rest);
    fprintf(stderr,
            "    reference against rest: fresh %.2e, after a bent pass %.2e from the bent "
            "blocks (%.2e from rest), after reset %.2e\n",
            fresh, kept, apart, after_reset);
    ENSUREF(fresh == 0 && after_reset == 0, "fresh %g, after reset %g", fresh, after_reset);
    ENSUREF(kept <= 1e-12, "the reference is %g from the bent pass's blocks", kept);
    ENSUREF(apart >= 1e-3, "bent %g: the test cannot tell the poses apart", apart);
    free(rest);
    free(bent);
    free(q);
    sinew_instance_destroy(inst);
    sinew_instance_destroy(plain);
}

/* The bake stores the training clip's frames twice, on the way in and on the way back
 * (its return path), with the reference's solution on each branch. Played in the order
 * solved, the instance must land on the branch it arrived along: nearer that branch's
 * reference shape than the twin's, wherever the two differ. */
TEST(branches_follow_the_motion) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    size_t n3 = 3 * (size_t)v->nverts, fs = 4 * (size_t)v->nbones;
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    double *xs = malloc(sizeof(double) * n3), *cnt = malloc(sizeof(double) * v->nverts);
    int twins = 0, distinct = 0;
    double big = 0; /* the largest squared correction |x - rest|_M^2 of a training pose */
    for (int32_t t = 0; t < v->ntrain; ++t) {
        double c = 0;
        for (size_t i = 0; i < n3; ++i) {
            double d = f->res.train_x[n3 * t + i] - v->rest[i];
            c += f->res.mass[i / 3] * d * d;
        }
        big = fmax(big, c);
    }
    for (int32_t t = 0; t < v->ntrain; ++t) {
        ENSURE(sw_instance_set_pose_d(inst, f->res.train_T + (size_t)t * 12 * v->nbones) ==
               SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
        int32_t u = -1;
        for (int32_t w = 0; w < v->ntrain && u < 0; ++w)
            if (w != t && sw_pose_distance(v->train_pose + fs * t, v->train_pose + fs * w,
                                           v->nbones) <= 1e-14)
                u = w;
        if (u < 0) continue;
        twins++;
        const double *xt = f->res.train_x + n3 * t, *xu = f->res.train_x + n3 * u;
        double apart = 0, own = 0, other = 0;
        sw_instance_full_positions(inst, xs, cnt);
        for (size_t i = 0; i < n3; ++i) {
            double m = f->res.mass[i / 3];
            apart += m * (xt[i] - xu[i]) * (xt[i] - xu[i]);
            own += m * (xs[i] - xt[i]) * (xs[i] - xt[i]);
            other += m * (xs[i] - xu[i]) * (xs[i] - xu[i]);
        }
        if (apart < 1e-4 * big)
            continue; /* the branches meet here (1% of the largest shape change) */
        distinct++;
        ENSUREF(own < other, "training pose %d: nearer its twin %d's shape (%g) than its own (%g)",
                t, u, sqrt(other), sqrt(own));
    }
    fprintf(stderr, "    %d training poses stored on two branches, %d of them apart\n", twins,
            distinct);
    ENSURE(twins > 0 && distinct > 0);
    free(xs);
    free(cnt);
    sinew_instance_destroy(inst);
}

/* Twins are poses within 1e-14 of each other (feature distance), which a hostile blob can
 * chain without closing: 0 ~ 1 ~ 2 but 0 !~ 2. Every pose must still lie on exactly one
 * cycle of twin_next, or the branch lookup walking from it never ends (a fuzzed blob did
 * that). Three one-bone poses 1.5e-7 rad apart: neighbours at 5.6e-15, the ends 2.2e-14. */
TEST(twins_form_cycles_on_any_poses) {
    double pose[4 * 4];
    int32_t next[4];
    for (int k = 0; k < 4; ++k) {
        double h = (k < 3 ? 1.5e-7 * k : 1.0) / 2; /* the last: far from every other */
        double q[4] = {cos(h), sin(h), 0, 0};
        memcpy(pose + 4 * k, q, sizeof q);
    }
    sw_blob_view v = {0};
    v.nbones = 1;
    v.ntrain = 4;
    v.train_pose = pose;
    sw_pose_index_link_twins(&v, next);
    for (int32_t t = 0; t < 4; ++t) {
        int32_t w = next[t], steps = 1;
        while (w != t && steps <= 4)
            w = next[w], steps++;
        ENSUREF(w == t, "pose %d is not on a cycle of twin_next", t);
    }
    /* one cycle: 1 joins 0 (0 -> 1 -> 0), then 2 (not within 1e-14 of 0) joins 1, before it */
    ENSURE(next[0] == 2 && next[2] == 1 && next[1] == 0);
    ENSURE(next[3] == 3);
}

TEST(training_poses_are_reproduced) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sw_eval_result e;
    sw_error err;
    ENSURE(sw_eval_correction(f->blob, f->res.mass, f->res.train_T, f->res.train_x, f->res.ntrain,
                              20, &e, &err) == SINEW_OK);
    fprintf(stderr, "    correction error on %d training poses: %.4f (projection %.4f)\n", e.frames,
            e.correction_error, f->res.train_proj_error);
    ENSURE(e.failed == 0 && e.frames == f->res.ntrain);
    ENSUREF(e.correction_error < 0.1, "correction error %.4f on the training poses",
            e.correction_error);
}

/* The seams between domains (sw_instance_copy_spread) at the rest pose with one basis
 * coordinate of one domain set: that domain's copy of a shared vertex v moves by its
 * basis row u_v and the n_v - 1 other copies stay at rest, so the copies' squared
 * distances from their mean sum to |u_v|^2 (n_v - 1) / n_v, and the largest distance is
 * the largest |u_v| (n_v - 1) / n_v. */
TEST(copy_spread_measures_the_seams) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    ENSURE(v->ndomains >= 2);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    double *T = calloc(12 * (size_t)v->nbones, sizeof(double));
    double *x = malloc(sizeof(double) * 3 * v->nverts), *cnt = malloc(sizeof(double) * v->nverts);
    double *spread = malloc(sizeof(double) * v->nverts), *q = calloc(v->rank_total, sizeof(double));
    double *u2 = calloc(v->nverts, sizeof(double)); /* |u_v|^2 of domain a's copies */
    for (int32_t b = 0; b < v->nbones; ++b)
        T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
    ENSURE(sw_instance_set_pose_d(inst, T) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    int32_t a = 1, shared = 0; /* a domain next to another */
    const sw_blob_domain *D = &v->domains[a];
    int32_t j = D->rank - 1;
    q[D->q_offset + j] = 1; /* orthonormal columns: a unit displacement field */
    sw_instance_set_q(inst, q);
    sw_instance_full_positions(inst, x, cnt);
    double gap = sw_instance_copy_spread(inst, x, spread), want_gap = 0;
    for (int32_t lv = 0; lv < D->vert_count; ++lv) {
        const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * D->rank;
        int32_t gv = v->domain_verts[D->vert_begin + lv];
        u2[gv] =
            U[j] * U[j] + U[D->rank + j] * U[D->rank + j] + U[2 * D->rank + j] * U[2 * D->rank + j];
    }
    for (int32_t gv = 0; gv < v->nverts; ++gv) {
        double n = cnt[gv], want = n >= 2 ? u2[gv] * (n - 1) / n : 0;
        shared += n >= 2 && u2[gv] > 0;
        if (n >= 2) want_gap = fmax(want_gap, sqrt(u2[gv]) * (n - 1) / n);
        ENSUREF(fabs(spread[gv] - want) <= 1e-12 * (1 + want), "vertex %d: spread %g, want %g", gv,
                spread[gv], want);
    }
    ENSUREF(shared > 0 && fabs(gap - want_gap) <= 1e-12 * (1 + want_gap),
            "%d shared vertices moved; largest gap %g, want %g", shared, gap, want_gap);
    sinew_instance_destroy(inst);
    free(T);
    free(x);
    free(cnt);
    free(spread);
    free(q);
    free(u2);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(gradient_matches_finite_differences_with_contact_pairs),
             CASE(contact_tangential_share_fades_from_the_training_poses),
             CASE(chord_updates_end_at_a_newton_stationary_point),
             CASE(rest_first_updates_end_at_a_newton_stationary_point),
             CASE(reference_hessian_is_the_last_evaluated_and_reset_restores_the_rest_one),
             CASE(quasistatic_start_is_the_prediction_plus_the_last_offset),
             CASE(rest_hessian_is_the_hessian_of_the_rigidly_moved_rest_shape),
             CASE(quasistatic_shape_depends_on_the_pose_and_its_last_motion_alone),
             CASE(branches_follow_the_motion), CASE(twins_form_cycles_on_any_poses),
             CASE(training_poses_are_reproduced), CASE(copy_spread_measures_the_seams),
             CASE(release_fixture))
