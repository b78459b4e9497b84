/* The runtime against the full-space reference on HELD-OUT poses: clip frames
 * the bake did not train on, where no step starts from a stored solution. Two characters:
 * the procedural finger (about 3,000 tets, a fold with self-contact) and the real
 * elephant of ../shared/data/elephant-cd (1,502 tets, 24 bones, its own clip; skipped
 * without the folder, a failure in CI: NEED_DATA). For each, one bake (the clip's first
 * 60% trains, the rest is held out), then the correction error
 *   |x_sub - x_full|_M / |x_full - x_dqs|_M   (sw_eval_correction_opts, subspace_eval.h)
 * over the held-out frames:
 *   quasistatic  the bake's own held-out solutions (sw_fullsim quasistatic along the
 *                clip's path, sw_bake_errors: the figure sinew-bake reports);
 *   dynamic      sw_fullsim backward Euler (the blob's Rayleigh alpha and beta, the
 *                clip's frame time) and a dynamic instance, both played from rest through
 *                the whole clip, compared on the held-out frames only.
 * The bounds are the measured values (Release, x86-64, 2 bake threads) times about 1.25,
 * rounded up; the measurements are stated beside each.
 *
 * Measured: finger quasistatic 0.152 on 5 held-out poses (0.021 on its 19 training
 * poses), dynamic 0.286 on 5 held-out frames (0.171 on its 7 training frames); elephant
 * quasistatic 0.147 on 8 held-out poses (0.007 on 69 training poses), dynamic 1.049 on
 * 24 held-out frames (0.980 on its 36 training frames). After the tuning of the pose-space pairs
 * and Newton's last update (the pairs' tangential term fading away from their training pose,
 * springs tied to hubs, a 5% last Newton update): finger 0.108 (0.019), dynamic 0.281 (0.255);
 * elephant 0.143 (0.007), dynamic 1.111 (0.983). (Folding the bones under 3% of the volume into
 * their parents, sw_bake_params.fold_share, costs this sparse training set accuracy:
 * 0.171 with 11 domains instead of 24; 0.155 at a 1% share, 0.168 at 2%; the default
 * training set loses almost none: sinew-bake 0.0886 -> 0.0900 held-out.) The elephant's
 * dynamic figure
 * is a known gap, not a held-out effect: its dynamic instance misses the reference's
 * backward-Euler correction as much on the training frames as on the held-out ones (no
 * better than skinning); its bound only guards against it getting worse. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "blob_load.h"
#include "blob_write.h"
#include "character_io.h"
#include "fullsim.h"
#include "instance.h"
#include "instance_internal.h"
#include "samples.h"
#include "subspace_eval.h"
#include "sw_test.h"

typedef struct {
    sw_character ch;
    sw_bake_result res;
    void *data;
    size_t size;
    sinew_blob *blob;
    int32_t ntrain_frames; /* clip frames [0, ntrain_frames) train, the rest is held out */
} baked;

static void baked_free(baked *b) {
    sinew_blob_destroy(b->blob);
    free(b->data);
    sw_bake_result_free(&b->res);
    sw_character_free(&b->ch);
}

/* Bakes b->ch (the fixture's parameters: 3 samples a joint sweep, 8 clip frames and the
 * return path). 1 on success. */
static int bake(baked *b) {
    sw_error err;
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 3;
    p.max_train_frames = 8;
    p.return_path = 1;
    p.threads = 2;
    b->ntrain_frames = (int32_t)floor(b->ch.clip.nframes * (1.0 - p.heldout_fraction));
    if (sw_bake(&b->ch, &p, &b->res, &err) != SINEW_OK) {
        fprintf(stderr, "  bake failed: %s\n", err.msg);
        return 0;
    }
    if (sw_blob_write_memory(&b->res.view, &b->data, &b->size, &err) != SINEW_OK) return 0;
    sinew_blob_def d = sinew_blob_def_default();
    d.data = b->data;
    d.data_size = b->size;
    return sinew_blob_load(&d, &b->blob) == SINEW_OK;
}

/* Quasistatic on the bake's held-out poses; dynamic on the clip's held-out frames after
 * playing its training frames. Fails above the bounds. */
static void compare(baked *b, const char *name, double qs_bound, double dyn_bound) {
    const sw_blob_view *v = sw_blob_get_view(b->blob);
    sw_eval_result et, eh;
    sw_error err;
    ENSUREF(sw_bake_errors(b->blob, &b->res, SINEW_SELF_CONTACT_POSE_SPACE, &et, &eh, &err) ==
                SINEW_OK,
            "%s", err.msg);
    fprintf(stderr,
            "  %s (%d tets, rank %d): quasistatic correction error, %d training poses %.4f, "
            "%d held-out poses %.4f\n",
            name, b->ch.mesh.ntets, v->rank_total, et.frames, et.correction_error, eh.frames,
            eh.correction_error);
    ENSURE(eh.failed == 0 && eh.frames == b->res.nheldout && eh.frames > 0);

    /* dynamic: the reference's backward Euler through the whole clip */
    int32_t nf = b->ch.clip.nframes, nb = b->ch.skel.nbones, nv = b->ch.mesh.nverts;
    int32_t first = b->ntrain_frames;
    float dt = (float)(1.0 / (b->ch.clip.fps > 0 ? b->ch.clip.fps : 30.0));
    sw_fullsim_params fp = sw_fullsim_params_default();
    fp.integrator = SW_BACKWARD_EULER;
    fp.dt = dt;
    fp.rayleigh_alpha = v->rayleigh_alpha;
    fp.rayleigh_beta = v->rayleigh_beta;
    fp.threads = 2;
    sw_fullsim *sim;
    ENSUREF(sw_fullsim_create(&b->ch, &fp, &sim, &err) == SINEW_OK, "%s", err.msg);
    double *xref = malloc(sizeof(double) * 3 * nv * (size_t)nf);
    int unconverged = 0;
    for (int32_t f = 0; f < nf; ++f) {
        sw_fullsim_stats st;
        sinew_result r = sw_fullsim_step(sim, b->ch.clip.T + (size_t)f * 12 * nb, &st);
        unconverged += r == SINEW_ERROR_NOT_CONVERGED;
        if (r != SINEW_OK && r != SINEW_ERROR_NOT_CONVERGED) break;
        memcpy(xref + (size_t)f * 3 * nv, sw_fullsim_positions(sim), sizeof(double) * 3 * nv);
    }
    sw_fullsim_destroy(sim);
    /* the training frames too, for the record: a dynamic step never starts from a stored
       solution, so they are not much easier than the held-out ones */
    sw_eval_options o = {.mode = SINEW_STEP_DYNAMIC,
                         .dt = dt,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = SINEW_SELF_CONTACT_POSE_SPACE};
    sw_eval_result ed, edt;
    sinew_result r =
        sw_eval_correction_opts(b->blob, b->res.mass, b->ch.clip.T, xref, first, &o, &edt, &err);
    o.skip = first;
    if (r == SINEW_OK)
        r = sw_eval_correction_opts(b->blob, b->res.mass, b->ch.clip.T,
                                    xref + (size_t)first * 3 * nv, nf, &o, &ed, &err);
    free(xref);
    ENSUREF(r == SINEW_OK, "%s", err.msg);
    fprintf(stderr,
            "  %s: dynamic (dt %.4g s, alpha %g, beta %g) correction error on %d held-out "
            "frames (after %d): %.4f (training frames %.4f; reference unconverged steps: %d)\n",
            name, (double)dt, v->rayleigh_alpha, v->rayleigh_beta, ed.frames, first,
            ed.correction_error, edt.correction_error, unconverged);
    ENSURE(ed.failed == 0 && ed.frames == nf - first);
    ENSUREF(eh.correction_error <= qs_bound, "%s quasistatic held-out error %.4f > %.3f", name,
            eh.correction_error, qs_bound);
    ENSUREF(ed.correction_error <= dyn_bound, "%s dynamic held-out error %.4f > %.3f", name,
            ed.correction_error, dyn_bound);
}

/* x_c = U_c q_d of copy (domain d, local vertex lv). */
static void copy_offset(const sw_blob_view *v, int32_t d, int32_t lv, const double *q,
                        double x[3]) {
    const sw_blob_domain *D = &v->domains[d];
    const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * D->rank;
    for (int i = 0; i < 3; ++i) {
        x[i] = 0;
        for (int32_t j = 0; j < D->rank; ++j)
            x[i] += U[i * D->rank + j] * q[D->q_offset + j];
    }
}

/* The interface springs (bake_reduce.c): 1/2 q^T H_s q is k/2 sum |x_c - x_hub|^2 over
 * every copy c of a vertex but its hub, the copy whose domain's bone is nearest the
 * root (the lower domain on a tie); checked as one ratio k for two random states. A
 * vertex with three copies or more tells this from tying every pair. */
static void check_springs_follow_the_skeleton(const sinew_blob *blob) {
    const sw_blob_view *v = sw_blob_get_view(blob);
    int32_t R = v->rank_total, nd = v->ndomains;
    int32_t *ncopy = calloc((size_t)v->nverts, sizeof(int32_t)),
            *hub = malloc(sizeof(int32_t) * 2 * v->nverts), *depth = malloc(sizeof(int32_t) * nd);
    double *q = malloc(sizeof(double) * R), *Hq = malloc(sizeof(double) * R), ratio[2];
    for (int32_t d = 0; d < nd; ++d) {
        depth[d] = 0;
        for (int32_t b = v->domains[d].bone; v->bone_parent[b] >= 0; b = v->bone_parent[b])
            depth[d]++;
    }
    int32_t three = 0;
    for (int32_t d = 0; d < nd; ++d) /* hubs: domains in order, the first shallowest */
        for (int32_t lv = 0; lv < v->domains[d].vert_count; ++lv) {
            int32_t gv = v->domain_verts[v->domains[d].vert_begin + lv];
            if (ncopy[gv]++ == 0 || depth[d] < depth[hub[2 * gv]])
                hub[2 * gv] = d, hub[2 * gv + 1] = lv;
            three += ncopy[gv] == 3;
        }
    ENSUREF(three > 0, "no vertex has three copies: the test would prove less");
    uint64_t seed = 11;
    for (int k = 0; k < 2; ++k) {
        for (int32_t i = 0; i < R; ++i) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            q[i] = (double)(seed >> 11) * 0x1.0p-53 - 0.5;
        }
        double Es = 0, E1 = 0;
        for (int32_t i = 0; i < R; ++i) {
            Hq[i] = 0;
            for (int32_t j = 0; j < R; ++j)
                Hq[i] += sw_blob_reduced_entry(v, SW_BLOB_SPRINGS, i, j) * q[j];
            Es += 0.5 * q[i] * Hq[i];
        }
        for (int32_t d = 0; d < nd; ++d)
            for (int32_t lv = 0; lv < v->domains[d].vert_count; ++lv) {
                int32_t gv = v->domain_verts[v->domains[d].vert_begin + lv];
                if (ncopy[gv] < 2 || (hub[2 * gv] == d && hub[2 * gv + 1] == lv)) continue;
                double xc[3], xh[3];
                copy_offset(v, d, lv, q, xc);
                copy_offset(v, hub[2 * gv], hub[2 * gv + 1], q, xh);
                for (int i = 0; i < 3; ++i)
                    E1 += 0.5 * (xc[i] - xh[i]) * (xc[i] - xh[i]);
            }
        ENSURE(E1 > 0);
        ratio[k] = Es / E1;
    }
    ENSUREF(ratio[0] > 0 && fabs(ratio[0] - ratio[1]) <= 1e-9 * ratio[0],
            "spring energy / hub springs: %.12g and %.12g", ratio[0], ratio[1]);
    free(ncopy), free(hub), free(depth), free(q), free(Hq);
}

TEST(finger_heldout_matches_the_reference) {
    baked b;
    memset(&b, 0, sizeof b);
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 12, &b.ch, &err) == SINEW_OK);
    ENSURE(bake(&b));
    compare(&b, "finger", 0.19, 0.36); /* measured 0.152, 0.286 */
    /* the clip's first frame is the rest pose: a reference there solved to rounding (the
       rest shape moved by 1e-13) leaves no correction to miss, not a share of rounding
       (the bare hand's rest frame once read 423484) */
    int32_t nv = b.ch.mesh.nverts;
    double fe = -1, *x_rest = malloc(sizeof(double) * 3 * (size_t)nv);
    ENSURE(x_rest != NULL);
    if (!x_rest) return;
    for (int32_t i = 0; i < 3 * nv; ++i)
        x_rest[i] = b.ch.mesh.X[i] + 1e-13 * (i % 7 - 3);
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = SINEW_SELF_CONTACT_POSE_SPACE};
    sw_eval_result e;
    ENSURE(sw_eval_correction_frames(b.blob, b.res.mass, b.ch.clip.T, x_rest, 1, &o, &fe, &e,
                                     &err) == SINEW_OK);
    free(x_rest);
    ENSUREF(e.frames == 1 && e.no_correction && e.correction_error == 0 && fe == 0,
            "at rest: %d frames, no_correction %d, error %g, frame %g", e.frames, e.no_correction,
            e.correction_error, fe);
    baked_free(&b);
}

/* The Hessian's blocks outside those marked (sw_reduced.H_nz) are exact zeros after every
 * step of the clip, quasistatic and dynamic (with the damping Hessian's, Hn_nz): what lets
 * an evaluation start by copying the springs' blocks and clearing the marked ones. A
 * contact pair between domains that no spring couples (the elephant's limbs against its
 * body) writes blocks outside the springs' pattern; without its mark they would keep
 * the last evaluation's values. *marked_out: the blocks marked beyond the springs', summed. */
static void check_hessian_marks(const baked *b, sinew_step_mode mode, int64_t *marked_out) {
    const sw_blob_view *v = sw_blob_get_view(b->blob);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    sinew_instance *in;
    ENSURE(sinew_instance_create(b->blob, &d, &in) == SINEW_OK);
    const int32_t nd = v->ndomains, R = v->rank_total, nb = b->ch.skel.nbones;
    int64_t marked = 0, stray = 0;
    for (int32_t f = 0; f < b->ch.clip.nframes; ++f) {
        ENSURE(sw_instance_set_pose_d(in, b->ch.clip.T + (size_t)f * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        for (int m = 0; m < (mode == SINEW_STEP_DYNAMIC ? 2 : 1); ++m) {
            const double *H = m ? in->solver.Hn : in->red.H;
            const unsigned char *nz = m ? in->solver.Hn_nz : in->red.H_nz;
            for (int32_t a = 0; a < nd; ++a)
                for (int32_t c = 0; c < nd; ++c) {
                    if (a == c) continue;
                    marked += nz[a * nd + c] && !in->red.spring_adj[a * nd + c];
                    if (nz[a * nd + c]) continue;
                    const sw_blob_domain *Da = &v->domains[a], *Dc = &v->domains[c];
                    for (int32_t i = 0; i < Da->rank; ++i)
                        for (int32_t j = 0; j < Dc->rank; ++j)
                            stray += H[(int64_t)(Da->q_offset + i) * R + Dc->q_offset + j] != 0;
                }
        }
    }
    sinew_instance_destroy(in);
    ENSUREF(stray == 0, "%lld nonzero Hessian entries outside the marked blocks", (long long)stray);
    *marked_out = marked;
}

TEST(elephant_heldout_matches_the_reference) {
    NEED_DATA("elephant-cd/elephant.mesh");
    baked b;
    memset(&b, 0, sizeof b);
    sw_error err;
    int32_t frames = 60; /* at 100 fps: 36 train (8 of them used), 24 held out */
    ENSUREF(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "elephant-cd", frames, &b.ch, &err) ==
                SINEW_OK,
            "%s", err.msg);
    ENSURE(bake(&b));
    check_springs_follow_the_skeleton(b.blob);
    int64_t mq = 0, md = 0;
    check_hessian_marks(&b, SINEW_STEP_QUASISTATIC, &mq);
    check_hessian_marks(&b, SINEW_STEP_DYNAMIC, &md);
    fprintf(stderr,
            "  elephant-cd: Hessian blocks marked beyond the springs', summed over the clip: "
            "quasistatic %lld, dynamic %lld\n",
            (long long)mq, (long long)md);
    ENSURE(mq > 0 && md > 0); /* contact between domains no spring couples: the marks ran */
    /* The dynamic bound is above 1, worse than plain skinning: the elephant's dynamic flesh
       does not follow the reference's yet (docs/notes/placement.md). It guards that gap
       from widening, and says nothing of quality. */
    compare(&b, "elephant-cd", 0.19, 1.15);
    baked_free(&b);
}

SW_TEST_MAIN(CASE(finger_heldout_matches_the_reference),
             CASE(elephant_heldout_matches_the_reference))
