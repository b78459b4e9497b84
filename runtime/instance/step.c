/* The per-frame step (DESIGN.md §4) as the list of its phases, each a function of the
 * step context:
 *   skin      dual-quaternion skinning of the active vertices (eq. 4.13)
 *   contact   the training poses nearest to the pose, their contact pairs (§3.2.3), and
 *             the joints the pose bends beyond every training pose
 *   dynamics  teleports, inertial forces, the start state, the frozen damping Hessian
 *   self      exhaustive self-contact: the pairs touching at the start state
 *             (self_contact.h); either mode: the Hessian's block pattern
 *   world     the surface copies near colliders at the start state (world_contact.h)
 *   oracle    with a patch budget: the full-space patch around the novel contact
 *             (condense.h, thesis §4.4.2)
 *   solve     Newton on the step's potential (eqs. 2.11-2.12, 3.4-3.6, 4.20), coupled to
 *             the patch when there is one (eqs. 4.11-4.12); when it ran into colliders
 *             (or, exhaustive, into flesh) the start state did not touch, one more
 *             detection round and solve from there
 *   advance   the velocity and the pose history
 *   output    the output surface and its normals
 * Nothing here allocates, locks or touches a vertex that is not active: the cost follows
 * the cubature, contact and surface sizes, not the tet count. Each phase's wall time
 * and counts land in the step's stats. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "clock.h"
#include "cubature.h"
#include "instance.h"
#include "instance_internal.h"
#include "log.h"
#include "recording.h"

typedef struct sw_step_ctx {
    sinew_instance *in;
    sw_dyn_coef dc;      /* quasistatic, or backward Euler over dt */
    sinew_step_stats st; /* this step's figures */
    double t;            /* the clock at the last phase boundary */
    int written;         /* the output surface holds this step's solution */
} sw_step_ctx;

/* Milliseconds since the last phase boundary, which moves here. */
static double lap(sw_step_ctx *c) {
    double now = sw_now_seconds(), ms = 1e3 * (now - c->t);
    c->t = now;
    return ms;
}

/* The time discretisation of a step of dt seconds in the instance's mode. */
static sw_dyn_coef step_coef(const sinew_instance *in, float dt) {
    const sw_blob_view *v = in->v;
    sw_dyn_coef dc = {
        dt, 0, 0, v->rayleigh_alpha, v->rayleigh_beta, in->mode == SINEW_STEP_DYNAMIC};
    if (dc.dynamic) {
        dc.cm = 1.0 / ((double)dt * dt);
        dc.cd = 1.0 / dt;
    }
    return dc;
}

/* The last dynamic patch's state (patch_dynamics.c: positions, velocities, deviations
 * and their rates, in the frame of the step that left them) moved into this step's
 * frame: E = F^-1 F_last. O(last patch). */
static void reframe_patch(sinew_instance *in) {
    sw_cond *cd = &in->cond;
    const double *F = in->frame, *G = in->frame_last;
    if (cd->z.max_verts == 0 || cd->nf == 0 || memcmp(F, G, sizeof in->frame) == 0) return;
    double E[12];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            E[3 * i + j] = F[i] * G[j] + F[3 + i] * G[3 + j] + F[6 + i] * G[6 + j];
        E[9 + i] = F[i] * (G[9] - F[9]) + F[3 + i] * (G[10] - F[10]) + F[6 + i] * (G[11] - F[11]);
    }
    for (int32_t i = 0; i < cd->nf; ++i) {
        int64_t gv = cd->fv[i];
        if (cd->dyn_at[gv] != cd->stamp) continue;
        double *vec[4] = {cd->px + 3 * gv, cd->pv + 3 * gv, cd->pdev + 3 * gv, cd->prate + 3 * gv};
        for (int a = 0; a < 4; ++a) {
            double y[3];
            for (int k = 0; k < 3; ++k)
                y[k] = E[3 * k] * vec[a][0] + E[3 * k + 1] * vec[a][1] + E[3 * k + 2] * vec[a][2] +
                       (a == 0 ? E[9 + k] : 0);
            memcpy(vec[a], y, sizeof y);
        }
    }
}

static void step_begin(sw_step_ctx *c, sinew_instance *in, float dt) {
    memset(c, 0, sizeof *c);
    c->in = in;
    c->st.struct_size = sizeof c->st;
    c->dc = step_coef(in, dt);
    sw_instance_frame(in); /* the history moved on since the pose was set */
    if (c->dc.dynamic) reframe_patch(in);
    memcpy(in->solver.qn, in->solver.q, (size_t)in->red.R * sizeof(double));
    in->solver.mat_at_start = 0;
    in->solver.fallback_qn = 0;
    c->t = sw_now_seconds();
}

static void phase_skin(sw_step_ctx *c) {
    sw_reduced_skin(&c->in->red, c->in->bone_dq);
    c->st.active_vertices = (uint32_t)c->in->red.nact;
    c->st.ms_skin = lap(c);
}

static int exhaustive(const sinew_instance *in) {
    return in->self_mode == SINEW_SELF_CONTACT_EXHAUSTIVE;
}

sw_step_contacts sw_instance_contacts(sinew_instance *in, double *self_seconds) {
    sw_step_contacts ct = {&in->ps, in->wc.world && in->lod_run == SINEW_LOD_FULL ? &in->wc : NULL,
                           sw_instance_detects(in) ? &in->sc : NULL, self_seconds};
    return ct;
}

/* The training poses near the pose (the quasistatic start, either mode) and, pose-space
 * mode, their pairs. */
static void phase_contact(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_pose_space_lookup(&in->ps, in->v, in->loc.T_cur);
    c->st.joints_beyond_training = (uint32_t)sw_pose_space_beyond(
        &in->ps, in->v, &c->st.beyond_training_bone, &c->st.beyond_training_deg);
    if (c->st.joints_beyond_training > 0) c->st.status |= SINEW_STEP_BEYOND_TRAINING;
    if (exhaustive(in)) {
        in->ps.npairs = in->ps.dropped = 0;
    } else {
        if (in->self_mode == SINEW_SELF_CONTACT_POSE_PAIRS)
            sw_pair_space_gather(&in->ps, in->v, in->loc.T_cur);
        else
            sw_pose_space_gather_pairs(&in->ps, in->v);
        c->st.self_contact_tests = c->st.self_contacts = (uint32_t)in->ps.npairs;
        c->st.self_contact_novel = (uint32_t)in->ps.novel;
    }
    if (in->ps.dropped > 0) {
        c->st.status |= SINEW_STEP_BUDGET;
        c->st.budget_exceeded |= SINEW_BUDGET_CONTACT_PAIRS;
        c->st.contact_pairs_dropped = (uint32_t)in->ps.dropped;
    }
    c->st.contact_pairs = (uint32_t)in->ps.npairs;
    c->st.ms_contact = lap(c);
    c->st.ms_self_contact = c->st.ms_contact;
}

/* Novel self-contact (novel_contact.h) at the start state, beside the pose-space pairs
 * still in use; the broad phase reads the last output's boxes when the last step's pose
 * is the one before this. */
static void novel_self(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    double t = sw_now_seconds();
    const double *T_last = in->pose.history >= 1 ? in->L_last : NULL;
    sw_novel_detect(&in->novel, &in->sc, &in->wc, &in->red, in->solver.q, &in->ps, in->loc.T_cur,
                    T_last, c->st.joints_beyond_training > 0);
    if (in->sc.npairs > 0)
        in->solver.mat_at_start = 0; /* a dynamic step's material part lacks them */
    c->st.novel_contacts = (uint32_t)in->sc.npairs;
    c->st.novel_cluster_pairs = (uint32_t)in->novel.cluster_pairs;
    c->st.self_contact_tests += (uint32_t)in->novel.tests;
    c->st.self_contacts += (uint32_t)in->sc.npairs;
    c->st.ms_novel = 1e3 * (sw_now_seconds() - t);
}

/* Exhaustive mode: the pairs touching at the start state. Pose-space modes: the pairs
 * that have come apart there dropped (pose_contact.h). Either mode: the pairs in use
 * fix the Hessian's block pattern for the step (the factorisations add their fill). */
static void phase_self(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    int32_t apart =
        exhaustive(in) ? 0 : sw_pose_contacts_drop_apart(&in->ps, &in->red, in->solver.q);
    if (apart > 0) {
        in->solver.mat_at_start = 0; /* a dynamic step's material part held them */
        c->st.contact_pairs = c->st.self_contacts = (uint32_t)in->ps.npairs;
        c->st.self_contacts_apart = (uint32_t)apart;
    }
    if (exhaustive(in)) {
        sw_self_contacts_detect(&in->sc, &in->red, in->solver.q);
        c->st.self_contact_tests = (uint32_t)in->sc.tests;
    } else if (in->ps.novel_mask) { /* pose-pairs: pairs of domains no sample is near */
        sw_self_contacts_clear(&in->sc);
        if (in->ps.novel > 0) {
            sw_self_contacts_detect_pairs(&in->sc, &in->red, in->solver.q, in->ps.novel_mask);
            c->st.self_contact_tests += (uint32_t)in->sc.tests;
            c->st.self_contacts += (uint32_t)in->sc.npairs;
        }
        /* the cubature vertices against the flesh around their trained triangles */
        int64_t tests = in->sc.tests;
        /* a dynamic step's material part (phase_dynamics) held the moved pairs */
        if (sw_self_contacts_retest(&in->sc, &in->red, in->solver.q, &in->ps) > 0)
            in->solver.mat_at_start = 0;
        c->st.self_contact_tests += (uint32_t)(in->sc.tests - tests);
    }
    if (in->novel_on && in->lod_run == SINEW_LOD_FULL) novel_self(c);
    sw_step_contacts ct = sw_instance_contacts(in, NULL);
    sw_solver_block_pattern(&in->solver, in->v, &ct);
    double ms = lap(c);
    c->st.ms_contact += ms;
    c->st.ms_self_contact += ms;
}

/* s->q = p + (q_n - p_n) with offset, else p: p the blend of the two nearest training
 * poses' reduced solutions, p_n the last step's (s->q_pred). O(R). */
static void predicted_start(sinew_instance *in, int offset) {
    sw_solver *s = &in->solver;
    int32_t R = in->red.R;
    double *p = s->tmp;
    sw_pose_space_blend(&in->ps, in->v->train_q, R, p);
    for (int32_t i = 0; i < R; ++i) {
        s->q[i] = offset ? p[i] + (s->q[i] - s->q_pred[i]) : p[i];
        s->q_pred[i] = p[i];
    }
    s->pred_valid = 1;
}

/* Pose-space start of a quasistatic step: the prediction p = the blend of the two
 * nearest training poses' reduced solutions, plus, when the pose moved on continuously
 * from the last step's and that pose is nearer to it than every training pose, how far
 * that step's solution ended from its own prediction: q = p + (q_n - p_n) (after a pose
 * jump, a reset, a failed step or one the energy guard stopped: p alone). The reduced
 * energy has several minima once a fold buckles or a contact engages, and a warm start
 * from the previous frame can converge to one the full-space solution does not take (on
 * a folding finger, a minimum with half the correction wrong). The prediction picks the
 * minimum, so the shape is a function of the pose (no drift); the last step's offset
 * from its prediction is what the training poses do not predict and changes little from
 * frame to frame, so it starts Newton nearer, saving cubature passes (at a training pose
 * the offset is never taken; figures: docs/notes/runtime-constants.md). The shape depends on the
 * frames before within the solve's tolerance: a step ends within its last update,
 * SW_NEWTON_LAST_UPDATE |q|, of the stationary point (test_reduced_model). O(R). */
static void pose_space_start(sinew_instance *in) {
    /* the last pose nearer than every training pose (s->q holds q_n). Not where the step
       detects self-contact (exhaustive, pose-pairs): a vertex on the edge of contact makes
       the step's answer jump with rounding, and the offset would carry every such jump
       into all later frames, so that a character turned by 1e-12 degrees ends a clip with
       another shape; from the prediction alone the shape is the pose's. */
    sw_solver *s = &in->solver;
    predicted_start(in, s->pred_valid && in->pose.history >= 1 &&
                            in->ps.d_last < in->ps.d_nearest &&
                            in->self_mode == SINEW_SELF_CONTACT_POSE_SPACE);
}

/* Start of a dynamic step: q_n moved by the change of the pose-space prediction, q_s =
 * p + (q_n - p_n), the quasistatic start's offset taken always (a dynamic state is its
 * history's: the offset holds its lag and swing). Newton from q_n spends its first
 * updates following the pose; from q_s it is left with the dynamics' own change over a
 * frame, and the rest-first updates serve it as they serve a quasistatic step
 * (docs/notes/jiggle.md, The dynamic step's start). After a jump, a reset or
 * a failed step, p alone; where Newton finds no descent from q_s it starts again from q_n
 * (newton.c). The Rayleigh stiffness is frozen at q_s, where Newton's first evaluation is
 * anyway: K(q_s) differs from the backward-Euler K(q_n) by a frame's motion, in a term
 * that is beta / h (0.03 at the defaults and 30 Hz) of the stiffness. */
static void dynamic_start(sinew_instance *in) {
    sw_solver *s = &in->solver;
    predicted_start(in, s->pred_valid && in->pose.history >= 1);
    s->fallback_qn = 1;
}

/* A jump of the pose (sw_pose_jump: teleport, snap, or a small dt that implies a speed no
 * joint makes; or one the host declared, sinew_instance_mark_teleport) starts the pose history
 * afresh in either mode: no velocity and no inertia are taken from it, and the world's broad phase
 * does not reuse the last boxes. Dynamic: the inertial forces of the bones' motion, the
 * predicted start and the Rayleigh stiffness frozen there for the step. Quasistatic: the
 * pose-space start. */
static void phase_dynamics(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_solver *s = &in->solver;
    int32_t R = in->red.R;
    if (in->pose.declared_jump ||
        (in->pose.history >= 1 &&
         sw_pose_jump(in->v, &in->loc, in->bone_ball, in->size, c->dc.h))) {
        memset(s->qdot, 0, (size_t)R * sizeof(double));
        in->pose.history = in->loc.history = 0;
        in->pose.declared_jump = 0;
        c->st.status |= SINEW_STEP_TELEPORT;
    }
    if (c->dc.dynamic) {
        sw_inertial_forces(in->v, &in->loc, s, c->dc.h);
        if (in->ps.nearest >= 0) dynamic_start(in);
        /* H(q_s): the material and pose-space self-contact (the exhaustive mode's pairs are
           detected after the start state, phase_self); Newton's first evaluation, at q_s,
           starts from the same part instead of another cubature pass */
        s->mat_hess = s->rest_first && in->red.h_ref ? SW_CUB_HESSIAN_REF : 1;
        s->phi_mat = sw_potential_material(&in->red, &in->ps, s->q, 1, s->mat_hess, NULL);
        c->st.potential_evals++;
        sw_reduced_blocks_copy(in->v, s->Hn, s->Hn_nz, SW_DENSE_BLOCKS(in->red.H), in->red.H_nz);
        memcpy(s->g_mat, in->red.g, (size_t)R * sizeof(double));
        memcpy(s->q_mat, s->q, (size_t)R * sizeof(double));
        s->mat_at_start = 1;
    } else if (in->ps.nearest >= 0) {
        pose_space_start(in);
        c->st.status |= SINEW_STEP_POSE_SPACE;
    }
    if (!(c->st.status & SINEW_STEP_POSE_SPACE) && !(c->dc.dynamic && in->ps.nearest >= 0))
        s->pred_valid = 0;
    c->st.ms_dynamics = lap(c);
}

/* World candidates at the start state; the broad phase starts from the last output's
 * boxes when the last step's pose is the one before this (pose history). */
static void phase_world(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_world_contacts *wc = &in->wc;
    if (!wc->world || in->lod_run != SINEW_LOD_FULL) return;
    const double *T_last = in->pose.history >= 1 ? in->L_last : NULL;
    sw_world_contacts_detect(wc, &in->red, in->solver.q, in->loc.T_cur, T_last);
    c->st.world_rounds = 1;
    c->st.ms_world = lap(c);
}

/* The partition oracle (condense.h): the patch of this step, from the world contact at
 * the start state and the seeds of the two steps before. A pose jump forgets them. */
static void phase_oracle(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_cond *cd = &in->cond;
    if (cd->z.max_verts == 0) return;
    if (c->st.status & SINEW_STEP_TELEPORT) sw_cond_forget(cd);
    sw_world_contacts *wc = in->wc.world && in->lod_run == SINEW_LOD_FULL ? &in->wc : NULL;
    sw_self_contacts *sc = sw_instance_detects(in) ? &in->sc : NULL;
    if ((!wc && !in->novel_on) || in->lod_run != SINEW_LOD_FULL) { /* nothing seeds a patch */
        if (in->lod_run != SINEW_LOD_FULL) sw_cond_forget(cd);     /* nor later, from here */
        cd->nf = cd->np = 0;
        in->ps.in_patch = NULL;
        if (sc) sc->in_patch = NULL;
        return;
    }
    cd->pcg_iters = 0;
    cd->g0_step = 0;
    if (sw_cond_oracle(cd, &in->red, wc, &in->ps, sc, in->novel_on, in->solver.q) > 0) {
        if (c->dc.dynamic) {
            const sw_pose_history *ph = &in->loc;
            for (int32_t b = 0; b < in->v->nbones; ++b) {
                sw_dq_from_transform(ph->T_prev + 12 * b, &cd->dq_prev[b]);
                sw_dq_from_transform(ph->T_prev2 + 12 * b, &cd->dq_prev2[b]);
            }
            sw_cond_dynamics_start(cd, &in->red, &in->solver, &c->dc,
                                   ph->history >= 1 ? cd->dq_prev : NULL,
                                   ph->history >= 2 ? cd->dq_prev2 : NULL);
        }
        if (wc) sw_cond_detect(cd, wc, SW_WC_AT_DETECT);
    }
    if (wc) sw_cond_tag_candidates(cd, wc);
    c->st.patch_vertices = (uint32_t)cd->nf;
    c->st.patch_tets = (uint32_t)cd->nt;
    if (cd->dropped > 0) {
        c->st.status |= SINEW_STEP_BUDGET;
        c->st.budget_exceeded |= SINEW_BUDGET_PATCH;
        c->st.patch_dropped = (uint32_t)cd->dropped;
    }
    c->st.ms_oracle = lap(c);
}

/* Newton on the step's potential: reduced, or coupled to the patch. */
static sinew_result solve(sw_step_ctx *c, const sw_step_contacts *ct) {
    sinew_instance *in = c->in;
    if (in->cond.nf > 0)
        return sw_cond_solve(&in->cond, &in->red, ct, ct->wc ? &in->wc : NULL, &in->solver, &c->dc,
                             &c->st);
    return sw_newton_solve(&in->red, ct, &in->solver, &c->dc, &c->st);
}

/* The output surface (and the copies' positions the world's second round reads),
 * timed as the output phase. */
static void write_output(sw_step_ctx *c) {
    double t = sw_now_seconds();
    sw_instance_write_surface(c->in);
    c->st.ms_output += 1e3 * (sw_now_seconds() - t);
    c->written = 1;
}

/* Newton; with a world, a second round when the solution entered colliders at copies
 * that were not candidates (they join with their law frozen there). The check reads
 * the copies' positions the output computes anyway, so the output is written here. */
static sinew_result phase_solve(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_world_contacts *wc = &in->wc;
    double self_s = 0; /* the self-contact terms' share of the evaluations */
    sw_step_contacts ct = sw_instance_contacts(in, &self_s);
    sinew_result r = solve(c, &ct);
    /* the solution pressed into flesh it did not touch (not under a patch, whose pair
       elements are the detection's pairs of the start state) */
    if (r == SINEW_OK && exhaustive(in) && in->cond.nf == 0) {
        double t = sw_now_seconds();
        int32_t fresh = sw_self_contacts_detect(&in->sc, &in->red, in->solver.q);
        c->st.self_contact_tests += (uint32_t)in->sc.tests;
        self_s += sw_now_seconds() - t;
        if (fresh > 0) {
            sw_solver_block_pattern(&in->solver, in->v, &ct);
            r = solve(c, &ct);
        }
    }
    double ms_aside = 0; /* the second detection and the output, counted as theirs */
    if (r == SINEW_OK && ct.wc) {
        write_output(c);
        double t = sw_now_seconds();
        int32_t added = sw_world_contacts_add_missed(wc, &in->red, in->solver.q);
        if (in->cond.nf > 0) added += sw_cond_detect(&in->cond, wc, SW_WC_AT_MISSED);
        double ms_missed = 1e3 * (sw_now_seconds() - t);
        c->st.ms_world += ms_missed;
        if (added > 0) { /* (a failed second solve leaves the first round's surface) */
            c->st.world_rounds = 2;
            if (in->cond.nf > 0) sw_cond_tag_candidates(&in->cond, wc);
            r = solve(c, &ct);
            if (r == SINEW_OK) write_output(c);
        }
        ms_aside = c->st.ms_output + ms_missed;
        if (r == SINEW_OK) sw_world_contacts_finish(wc, &in->red, in->solver.q);
        c->st.world_queries = wc->queries;
        c->st.world_candidates = (uint32_t)wc->ncand;
        for (int32_t j = 0; j < wc->ncand; ++j)
            c->st.world_contacts += (uint32_t)wc->cand[j].active;
        if (wc->dropped > 0) {
            c->st.status |= SINEW_STEP_BUDGET;
            c->st.budget_exceeded |= SINEW_BUDGET_WORLD_CONTACTS;
            c->st.world_contacts_dropped = (uint32_t)wc->dropped;
        }
    }
    c->st.cubature_tets = (uint32_t)in->v->ncub;
    if (in->cond.nf > 0) {
        if (r == SINEW_OK) sw_cond_finish(&in->cond, &in->red, in->solver.q);
        if (r == SINEW_OK && c->dc.dynamic)
            sw_cond_dynamics_finish(&in->cond, &in->red, in->solver.q, &c->dc, in->size);
        c->st.pcg_iterations = in->cond.pcg_iters;
    }
    c->st.ms_solve = lap(c) - ms_aside;
    c->st.ms_self_contact += 1e3 * self_s;
    if (exhaustive(in)) c->st.self_contacts = (uint32_t)in->sc.npairs;
    return r;
}

/* |x| of n doubles. */
static double norm(const double *x, int32_t n) {
    double s = 0;
    for (int32_t i = 0; i < n; ++i)
        s += x[i] * x[i];
    return sqrt(s);
}

/* The state's bounds (instance_internal.h), the velocity of the step (dynamic) and the
 * pose history. A domain whose |q_k| exceeds its bound is scaled back onto it (radially:
 * the shape of the correction is kept, its size limited) and its velocity zeroed; a
 * velocity beyond the speed bound is scaled down to it. Either flags LIMITED, and the
 * output is written from the limited state. O(R). */
static void phase_advance(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    sw_solver *s = &in->solver;
    const sw_blob_view *v = in->v;
    double vmax = SW_JUMP_MAX_SPIN * in->size;
    int limited = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        int32_t o = v->domains[k].q_offset, r = v->domains[k].rank;
        double *q = s->q + o, *qd = s->qdot + o, n = norm(q, r), B = in->q_bound[k];
        int at_bound = !(n <= B);
        if (at_bound) {
            for (int32_t j = 0; j < r; ++j)
                q[j] = n > 0 ? q[j] * (B / n) : 0;
            limited = 1;
        }
        if (!c->dc.dynamic) continue;
        for (int32_t j = 0; j < r; ++j)
            qd[j] = at_bound ? 0 : (q[j] - s->qn[o + j]) / c->dc.h;
        double u = in->u_max[k] * norm(qd, r);
        if (u > vmax) {
            for (int32_t j = 0; j < r; ++j)
                qd[j] *= vmax / u;
            limited = 1;
        }
    }
    if (limited) {
        c->st.status |= SINEW_STEP_LIMITED;
        c->written = 0;
        /* a patch solved against a state that ran to its bound is no solution: its
           vertices go back to their subspace positions (the output's), and no later patch
           starts from where they were */
        if (in->cond.nf > 0) {
            sw_cond_forget(&in->cond);
            in->ps.in_patch = NULL;
            in->sc.in_patch = NULL;
        }
    }
    sw_pose_history_advance(&in->pose, v->nbones, c->dc.h);
    memcpy(in->L_last, in->loc.T_cur, 12 * (size_t)v->nbones * sizeof(double));
    memcpy(in->frame_last, in->frame, sizeof in->frame);
    c->st.ms_dynamics += lap(c);
}

static void phase_output(sw_step_ctx *c) {
    if (!c->written) sw_instance_write_surface(c->in);
    c->st.ms_output += lap(c);
}

/* The output within float range (what sinew_instance_read_surface hands out). A blob
 * whose values are finite but absurd (a hostile one passes validation so) can still
 * overflow it from a finite state: the step then fails as a non-finite solve does, with
 * the state back at the step's start, no velocity, and the surface written again from
 * that state at this pose (so the host never reads the overflowed one). O(surface), as
 * the output itself. */
static sinew_result check_output(sw_step_ctx *c) {
    sinew_instance *in = c->in;
    for (int64_t i = 0; i < 3 * (int64_t)sw_blob_output_verts(in->v); ++i)
        if (!(fabs(in->surf_x[i]) <= FLT_MAX) || !(fabs(in->surf_n[i]) <= FLT_MAX)) {
            memcpy(in->solver.q, in->solver.qn, (size_t)in->red.R * sizeof(double));
            memset(in->solver.qdot, 0, (size_t)in->red.R * sizeof(double));
            in->cond.nf = in->cond.np = 0; /* no patch: the subspace state alone */
            in->ps.in_patch = NULL;
            in->sc.in_patch = NULL;
            sw_instance_write_surface(in);
            c->st.status |= SINEW_STEP_FAILED;
            return SINEW_ERROR_NOT_FINITE;
        }
    return SINEW_OK;
}

/* A phase inside the host's profiler zone `name` (a static string); without a profiler,
 * one test. */
#define ZONE(in, name, call)                                                                       \
    do {                                                                                           \
        const sinew_profiler *zp_ = &(in)->profiler;                                               \
        if (zp_->zone_begin) zp_->zone_begin(name, zp_->user);                                     \
        call;                                                                                      \
        if (zp_->zone_begin) zp_->zone_end(name, zp_->user);                                       \
    } while (0)

/* The phases before the solve: what the step's potential needs. */
static void phases_to_solve(sw_step_ctx *c, sinew_instance *inst, float dt) {
    step_begin(c, inst, dt);
    ZONE(inst, "skin", phase_skin(c));
    ZONE(inst, "contact", phase_contact(c));
    ZONE(inst, "dynamics", phase_dynamics(c));
    ZONE(inst, "self_contact", phase_self(c));
    ZONE(inst, "world", phase_world(c));
    ZONE(inst, "oracle", phase_oracle(c));
}

/* The step of a solving level `run` (sinew_lod): the phases; the reduced level with one
 * Newton update. */
static sinew_result step_solve(sinew_instance *inst, float dt, sinew_lod run, sw_step_ctx *c) {
    inst->lod_run = run;
    sw_solver *s = &inst->solver;
    uint32_t max_newton = s->max_newton;
    if (run == SINEW_LOD_REDUCED) s->max_newton = 1;
    phases_to_solve(c, inst, dt);
    sinew_result r;
    ZONE(inst, "solve", r = phase_solve(c)); /* a non-finite state is undone: nothing advances */
    if (r == SINEW_OK) {
        ZONE(inst, "advance", phase_advance(c));
        ZONE(inst, "output", phase_output(c); r = check_output(c));
    }
    s->max_newton = max_newton;
    /* a failed step's state, or the iterate the energy guard kept, is not its prediction's
       solution: the next step starts from its own prediction alone */
    if (r != SINEW_OK || (c->st.status & SINEW_STEP_GUARD)) s->pred_valid = 0;
    return r;
}

/* The step proper (sinew_instance_step records it when a recorder is attached) at the
 * level set (lod.c): at a change to the pose-space level the old level's step runs, so
 * that its surface shows at the change; a change fades (sw_lod_finish). */
static sinew_result step(sinew_instance *inst, float dt) {
    if (dt == 0) { /* a paused frame (an engine's pause passes dt = 0): nothing moves */
        memset(&inst->stats, 0, sizeof inst->stats);
        inst->stats.struct_size = sizeof inst->stats;
        inst->stats.lod = (uint32_t)inst->lod_last;
        return SINEW_OK;
    }
    const sinew_lod from = inst->lod_last, to = inst->lod;
    const sinew_lod run = to == SINEW_LOD_POSE_SPACE && from != to ? from : to;
    if (from == SINEW_LOD_POSE_SPACE && run != from) sw_lod_leave_pose_space(inst);
    sw_step_ctx c;
    sinew_result r;
    if (run == SINEW_LOD_POSE_SPACE) {
        memset(&c, 0, sizeof c);
        c.st.struct_size = sizeof c.st;
        ZONE(inst, "output", r = sw_lod_pose_step(inst, dt, &c.st));
    } else {
        r = step_solve(inst, dt, run, &c);
    }
    if (r == SINEW_OK) {
        sw_lod_finish(inst, from, to, run);
        inst->lod_last = to;
        inst->stepped = 1;
    }
    c.st.lod = (uint32_t)inst->lod_last;
    c.st.lod_blend = (float)inst->lod_w;
    inst->stats = c.st;
    return r;
}

sinew_result sw_instance_step_bound(sinew_instance *inst, float dt) {
    if (!(dt >= 0) || !(dt <= 1.0f)) return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_result r = step(inst, dt);
    inst->touched = 1;
    sw_rec_step(inst, dt, r);
    return r;
}

SINEW_API sinew_result sinew_instance_step(sinew_instance *inst, float dt) {
    if (!inst) return SINEW_ERROR_INVALID_ARGUMENT;
    if (inst->shared) {
        sw_log(&inst->logger, SINEW_LOG_ERROR, SINEW_MSG_INSTANCE_INVALID_ARGUMENT,
               "sinew_instance_step: the instance has no scratch of its own "
               "(def.shared_workspace): step it with sinew_instance_step_in");
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    return sw_instance_step_bound(inst, dt);
}

void sw_instance_step_prepare(sinew_instance *inst, float dt) {
    sw_step_ctx c;
    phases_to_solve(&c, inst, dt);
}

double sw_instance_step_potential(sinew_instance *inst, float dt, const double *q, double *g,
                                  double *H, int exact_hessian) {
    sw_dyn_coef dc = step_coef(inst, dt);
    size_t R = (size_t)inst->red.R;
    sw_step_contacts ct = sw_instance_contacts(inst, NULL);
    int want_hess = H ? (exact_hessian ? SW_CUB_HESSIAN_EXACT : 1) : 0;
    double phi = sw_potential(&inst->red, &ct, &inst->solver, q, &dc, g || H, want_hess);
    if (g) memcpy(g, inst->red.g, R * sizeof(double));
    if (H) memcpy(H, inst->red.H, R * R * sizeof(double));
    return phi;
}

double sw_instance_step_start_potential(sinew_instance *inst, float dt, double *g, double *H,
                                        int *cubature_pass) {
    sw_dyn_coef dc = step_coef(inst, dt);
    size_t R = (size_t)inst->red.R;
    sw_step_contacts ct = sw_instance_contacts(inst, NULL);
    double phi = sw_potential_start(&inst->red, &ct, &inst->solver, &dc, inst->solver.mat_hess,
                                    cubature_pass);
    memcpy(g, inst->red.g, R * sizeof(double));
    memcpy(H, inst->red.H, R * R * sizeof(double));
    return phi;
}
