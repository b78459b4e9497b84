/* The bake's least input: a clip too short to train on is rejected with the
 * minimum and the reason, not written as a blob with empty cubature or a useless basis;
 * sw_bake_solutions gives the very poses and solutions sw_bake keeps. Small meshes. */
#include <math.h>
#include <string.h>

#include "sw_test.h"

#include "bake.h"
#include "bake_fixture.h"
#include "samples.h"

TEST(min_frames) {
    ENSURE(sw_bake_min_frames(0.4) == 4); /* floor(0.6 F) >= 2 */
    ENSURE(sw_bake_min_frames(0.0) == 2);
    ENSURE(sw_bake_min_frames(0.5) == 4);
}

TEST(too_few_frames_rejected) {
    for (int frames = 2; frames <= 3; ++frames) {
        sw_character c;
        sw_error err;
        ENSURE(sw_sample_make("finger", 1000, frames, &c, &err) == SINEW_OK);
        sw_bake_result res;
        sinew_result r = sw_bake(&c, NULL, &res, &err);
        sw_character_free(&c);
        ENSUREF(r == SINEW_ERROR_INVALID_ARGUMENT, "%d frames: %s", frames, err.msg);
        ENSUREF(strstr(err.msg, "too few poses to train") && strstr(err.msg, "at least 4 frames"),
                "%s", err.msg);
    }
}

/* The defaults with two poses a joint sweep, on 2 threads: a bake of the 1K finger in
 * about a second. */
static sw_bake_params quick_params(void) {
    sw_bake_params p = sw_bake_params_default();
    p.sweep_samples = 2;
    p.threads = 2;
    return p;
}

TEST(solutions_match_the_bake) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    sw_bake_result a, b;
    ENSUREF(sw_bake(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    int same = a.ntrain == b.ntrain && a.nheldout == b.nheldout;
    size_t pt = (size_t)12 * c.skel.nbones * sizeof(double),
           px = (size_t)3 * c.mesh.nverts * sizeof(double);
    if (same)
        same = !memcmp(a.train_T, b.train_T, a.ntrain * pt) &&
               !memcmp(a.train_x, b.train_x, a.ntrain * px) &&
               !memcmp(a.heldout_T, b.heldout_T, a.nheldout * pt) &&
               !memcmp(a.heldout_x, b.heldout_x, a.nheldout * px) &&
               !memcmp(a.mass, b.mass, (size_t)c.mesh.nverts * sizeof(double));
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
    ENSURE(same);
}

/* Bones carrying little flesh fold into their parents' domains (bake_domains.c): the
 * finger's three bones own tets and are three domains with folding off; at a share above
 * the tip bone's (a third of the finger at most) it joins its parent, whose domain then
 * rides the parent's bone; a share out of range is an error that names it. */
TEST(small_bones_fold_into_their_parents) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 5, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    int32_t nd[2];
    for (int k = 0; k < 2; ++k) {
        p.fold_share = k == 0 ? 0 : 0.45;
        sw_bake_result r;
        ENSUREF(sw_bake(&c, &p, &r, &err) == SINEW_OK, "%s", err.msg);
        nd[k] = r.view.ndomains;
        int tip = 0; /* the bone no other bone hangs from */
        for (int32_t b = 0; b < c.skel.nbones; ++b) {
            int leaf = 1;
            for (int32_t o = 0; o < c.skel.nbones; ++o)
                leaf = leaf && c.skel.parent[o] != b;
            if (!leaf) continue;
            for (int32_t d = 0; d < r.view.ndomains; ++d)
                tip += r.view.domains[d].bone == b;
        }
        ENSUREF(tip == (k == 0), "fold share %g: %d domains ride the tip bone", p.fold_share, tip);
        sw_bake_result_free(&r);
    }
    ENSUREF(nd[0] == c.skel.nbones && nd[1] < nd[0], "domains %d unfolded, %d folded", nd[0],
            nd[1]);
    p.fold_share = 0.5;
    sw_bake_result r;
    ENSURE(sw_bake(&c, &p, &r, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(err.msg, "fold share 0.5"), "%s", err.msg);
    sw_character_free(&c);
}

/* What the progress callback saw: per stage, its calls, the last done and total, and
 * whether done ever fell or the elapsed time went back. */
typedef struct {
    int calls[2];
    int64_t done[2], total[2];
    int bad;
    double elapsed[2];
} progress_log;

static void record_progress(void *user, const char *stage, int64_t done, int64_t total,
                            double elapsed) {
    progress_log *g = user;
    int k = !strcmp(stage, "simulate") ? 0 : !strcmp(stage, "cubature") ? 1 : -1;
    if (k < 0) {
        g->bad++;
        return;
    }
    if (done != g->done[k] + 1 || done > total || elapsed < g->elapsed[k] ||
        (g->calls[k] && total != g->total[k]))
        g->bad++;
    g->calls[k]++;
    g->done[k] = done;
    g->total[k] = total;
    g->elapsed[k] = elapsed;
}

/* The progress callback (bake.h): every solved pose and every trained domain once, one
 * unit at a time up to the stage's total, on 2 threads (the bake serialises the calls). */
TEST(progress_counts_every_pose_and_domain) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 6, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    progress_log g;
    memset(&g, 0, sizeof g);
    p.on_progress = record_progress;
    p.progress_user = &g;
    sw_bake_result r;
    ENSUREF(sw_bake(&c, &p, &r, &err) == SINEW_OK, "%s", err.msg);
    fprintf(stderr, "    simulate %d calls (%lld of %lld), cubature %d (%lld of %lld)\n",
            g.calls[0], (long long)g.done[0], (long long)g.total[0], g.calls[1],
            (long long)g.done[1], (long long)g.total[1]);
    ENSURE(g.bad == 0);
    ENSURE(g.total[0] == r.ntrain + r.nheldout && g.done[0] == g.total[0]);
    ENSURE(g.total[1] == r.view.ndomains && g.done[1] == g.total[1]);
    sw_bake_result_free(&r);
    sw_character_free(&c);
}

/* Bone b's rotation relative to its parent in pose T (12 per bone): L = R_p^T R_b. */
static void local_of(const sw_skeleton *sk, const double *T, int32_t b, double L[9]) {
    const double *Rb = T + 12 * b, *Rp = T + 12 * sk->parent[b];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            L[3 * i + j] = Rp[i] * Rb[j] + Rp[3 + i] * Rb[3 + j] + Rp[6 + i] * Rb[6 + j];
}

/* Pair sweeps: the finger's tip joint swept together with its parent joint, a
 * sequence of sweep_samples poses after the single sweeps, the last of them each joint at
 * its own sweep's end; the held-out poses stay the same. */
/* Sibling sweeps (default on): the finger with its tip joint hung from the root, so the
 * middle and tip joints are siblings whose flesh meets, is trained on both swept together
 * as well, sweep_samples poses after the single sweeps, the last with each joint at its
 * own sweep's end; sibling_sweeps 0 leaves them out and the held-out poses are the same. */
TEST(sibling_sweeps_turn_two_children_of_one_joint_together) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 6, &c, &err) == SINEW_OK);
    int32_t nb = c.skel.nbones, tip = -1, root = -1, n;
    for (int32_t k = 0; k < nb; ++k) {
        if (c.skel.parent[k] < 0) root = k;
        if (c.skel.parent[k] >= 0 && c.skel.parent[c.skel.parent[k]] >= 0) tip = k;
    }
    ENSURE(tip >= 0 && root >= 0);
    if (tip < 0 || root < 0) return;
    int32_t mid = c.skel.parent[tip];
    c.skel.parent[tip] = root; /* (the clip's bone transforms are the skeleton's world ones) */
    sw_bake_params p = quick_params();
    n = p.sweep_samples;
    sw_bake_result a, b;
    p.sibling_sweeps = 0;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    p.sibling_sweeps = 1;
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(b.ntrain == a.ntrain + n, "%d training poses with sibling sweeps, %d without", b.ntrain,
            a.ntrain);
    ENSURE(b.nheldout == a.nheldout &&
           !memcmp(a.heldout_T, b.heldout_T, sizeof(double) * 12 * nb * a.nheldout));
    ENSURE(!memcmp(a.train_T, b.train_T, sizeof(double) * 12 * nb * a.ntrain));
    /* the single sweeps end a's poses in bone order (the tip's after the middle's); the
       siblings' pair sweep ends b's */
    int32_t first = tip < mid ? tip : mid, second = tip < mid ? mid : tip;
    const double *pair = b.train_T + (size_t)12 * nb * (b.ntrain - 1),
                 *second_end = a.train_T + (size_t)12 * nb * (a.ntrain - 1),
                 *first_end = a.train_T + (size_t)12 * nb * (a.ntrain - 1 - n);
    double L[9], Ls[9];
    for (int j = 0; j < 2; ++j) {
        int32_t bone = j ? second : first;
        local_of(&c.skel, pair, bone, L);
        local_of(&c.skel, j ? second_end : first_end, bone, Ls);
        for (int i = 0; i < 9; ++i)
            ENSURE_NEAR(L[i], Ls[i], 1e-12);
        ENSUREF(fabs(Ls[0] - 1) + fabs(Ls[4] - 1) + fabs(Ls[8] - 1) > 1e-3,
                "bone %d's sweep does not turn it", bone);
    }
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
}

/* The held-out frames of the character's clip are solved after its training frames on
 * one path, and measured on that path (sw_bake_heldout_path): the training frames first,
 * unmeasured; held-out clips of their own start from rest. */
TEST(heldout_frames_are_measured_on_the_reference_path) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 10, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    sw_bake_result a;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    int32_t nb = c.skel.nbones, pre = -1, n = -1;
    size_t pt = (size_t)12 * nb * sizeof(double);
    ENSURE(a.heldout_after == 6 && a.nheldout == 4);
    ENSURE(a.return_poses > 0); /* the held-out frames continue the clip: the way home too */
    double *T = sw_bake_heldout_path(&a, nb, &pre, &n);
    ENSURE(T && pre == 6 && n == 10);
    for (int32_t f = 0; f < n; ++f) /* the clip itself, frame after frame */
        ENSURE(!memcmp((char *)T + f * pt, (char *)c.clip.T + f * pt, pt));
    free(T);
    sw_bake_result_free(&a);
    /* a held-out clip of its own: from rest */
    p.train_clips = &c.clip;
    p.ntrain_clips = 1;
    p.heldout_clips = &c.clip;
    p.nheldout_clips = 1;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(a.return_poses == 0); /* named training clips: no way home unless asked for */
    T = sw_bake_heldout_path(&a, nb, &pre, &n);
    ENSURE(T && a.heldout_after == 0 && pre == 0 && n == a.nheldout &&
           !memcmp(T, a.heldout_T, (size_t)n * pt));
    free(T);
    sw_bake_result_free(&a);
    sw_character_free(&c);
}

/* Self-contact force modes (sw_bake_params.contact_modes, thesis §3.3.1) only add to
 * each domain's basis: the rank grows and no snapshot projects worse. */
TEST(contact_modes_extend_the_basis) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 3000, 12, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    sw_bake_result a, b;
    ENSUREF(sw_bake(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    p.contact_modes = 1;
    ENSUREF(sw_bake(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    fprintf(stderr, "    rank %d -> %d, projection error %.5f -> %.5f, held-out %.5f -> %.5f\n",
            a.view.rank_total, b.view.rank_total, a.train_proj_error, b.train_proj_error,
            a.heldout_proj_error, b.heldout_proj_error);
    ENSURE(b.view.rank_total > a.view.rank_total);
    ENSURE(b.train_proj_error <= a.train_proj_error + 1e-12 &&
           b.heldout_proj_error <= a.heldout_proj_error + 1e-12);
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
}

TEST(pair_sweeps_turn_a_joint_with_its_parent) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 6, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    sw_bake_result a, b;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    p.pair_sweeps = 1;
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    int32_t nb = c.skel.nbones, tip = -1, n = p.sweep_samples;
    for (int32_t k = 0; k < nb; ++k) /* the finger: a chain root -> middle -> tip */
        if (c.skel.parent[k] >= 0 && c.skel.parent[c.skel.parent[k]] >= 0) tip = k;
    ENSURE(tip >= 0);
    int32_t mid = c.skel.parent[tip];
    ENSUREF(b.ntrain == a.ntrain + n, "%d training poses with pair sweeps, %d without", b.ntrain,
            a.ntrain);
    ENSURE(b.nheldout == a.nheldout &&
           !memcmp(a.heldout_T, b.heldout_T, sizeof(double) * 12 * nb * a.nheldout));
    /* the single sweeps end the training poses: the tip's last (a's last pose), the
       middle's before it; the pair's last pose is b's last */
    const double *pair = b.train_T + (size_t)12 * nb * (b.ntrain - 1),
                 *tip_end = a.train_T + (size_t)12 * nb * (a.ntrain - 1),
                 *mid_end = a.train_T + (size_t)12 * nb * (a.ntrain - 1 - n);
    double L[9], Ls[9];
    local_of(&c.skel, pair, tip, L);
    local_of(&c.skel, tip_end, tip, Ls);
    for (int i = 0; i < 9; ++i)
        ENSURE_NEAR(L[i], Ls[i], 1e-12);
    local_of(&c.skel, pair, mid, L);
    local_of(&c.skel, mid_end, mid, Ls);
    for (int i = 0; i < 9; ++i)
        ENSURE_NEAR(L[i], Ls[i], 1e-12);
    ENSUREF(fabs(Ls[0] - 1) + fabs(Ls[4] - 1) + fabs(Ls[8] - 1) > 1e-3,
            "the middle joint's sweep does not turn it");
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
}

/* The pair sweeps are on by default where a joint range bounds the sweeps (the rig's own
 * combinations), off at the 90-degree default and whenever the caller says so. The finger
 * without its clip, its middle and tip joints turned 40 degrees by the range: one joint
 * with its parent, so one pair sweep. */
TEST(pair_sweeps_by_default_within_a_joint_range) {
    sw_character c;
    sw_error err;
    static const double turn[2 * 3] = {0, 0, 0, 0, 40, 40}; /* rest; bones 1 and 2 at 40 */
    double range_T[2 * 12 * 3];
    int made = finger_range_fixture(&c, 1000, 2, turn, range_T);
    ENSURE(made);
    if (!made) return;
    const int32_t nb = 3;
    sw_bake_params p = quick_params();
    p.random_poses = 2;
    p.heldout_steps = 1;
    const int32_t n = p.sweep_samples;
    sw_bake_result a, b, d, e;
    ENSUREF(sw_bake_solutions(&c, &p, &d, &err) == SINEW_OK, "%s", err.msg); /* no range */
    p.pair_sweeps = 1;
    ENSUREF(sw_bake_solutions(&c, &p, &e, &err) == SINEW_OK, "%s", err.msg);
    c.range = (sw_clip){nb, 2, 30.0, range_T};
    p.pair_sweeps = sw_bake_params_default().pair_sweeps;
    sinew_result ra = sw_bake_solutions(&c, &p, &a, &err);
    ENSUREF(ra == SINEW_OK, "%s", err.msg);
    p.pair_sweeps = 0;
    sinew_result rb = sw_bake_solutions(&c, &p, &b, &err);
    ENSUREF(rb == SINEW_OK, "%s", err.msg);
    c.range = (sw_clip){0, 0, 0, NULL}; /* borrowed: not the character's to free */
    ENSUREF(d.pair_sweep_poses == 0 && e.pair_sweep_poses == n && e.ntrain == d.ntrain + n,
            "without a range: %d pair poses of %d by default, %d of %d asked for",
            d.pair_sweep_poses, d.ntrain, e.pair_sweep_poses, e.ntrain);
    ENSUREF(a.pair_sweep_poses == n && b.pair_sweep_poses == 0 && a.ntrain == b.ntrain + n,
            "within the range: %d pair poses of %d by default, %d of %d turned off",
            a.pair_sweep_poses, a.ntrain, b.pair_sweep_poses, b.ntrain);
    if (a.ntrain == b.ntrain + n) { /* the pair's last pose turns both joints to the range */
        const double *T = a.train_T + (size_t)12 * nb * (a.ntrain - 1);
        double L[9];
        for (int32_t k = 1; k < nb; ++k) {
            local_of(&c.skel, T, k, L);
            ENSURE_NEAR(L[0], cos(40 * 0.017453292519943295), 1e-9);
        }
    }
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_bake_result_free(&d);
    sw_bake_result_free(&e);
    sw_character_free(&c);
}

/* The sum over joints of the squared angle of a bone in its parent (the bake's bend). */
static double bend_of(const sw_skeleton *sk, const double *T) {
    double sum = 0, L[9];
    for (int32_t b = 0; b < sk->nbones; ++b) {
        if (sk->parent[b] < 0) continue;
        local_of(sk, T, b, L);
        double c = 0.5 * (L[0] + L[4] + L[8] - 1.0);
        double a = acos(c > 1 ? 1 : c < -1 ? -1 : c);
        sum += a * a;
    }
    return sum;
}

/* The return path goes home from where the training part of the clip left the fold: the
 * finger's 30-frame clip bends to its peak at frame 15 and its 18 training frames end at
 * 17, part of the way back. Frames 16..13 are bent more than 17 (played back they would
 * re-bend the fold to the peak first); the path is frames 12..0, each bent less than the
 * one before, continuing from frame 17's solution, and no held-out pose. */
TEST(return_path_goes_home_from_the_last_training_frame) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("finger", 1000, 30, &c, &err) == SINEW_OK);
    sw_bake_params p = quick_params();
    sw_bake_result a, b;
    p.return_path = 0;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    p.return_path = -1; /* the default: on, the held-out frames continue the training clip */
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    int32_t nb = c.skel.nbones, ntf = 18, m = b.ntrain - a.ntrain;
    size_t pose = (size_t)12 * nb;
    ENSUREF(m == 13 && b.return_poses == 13 && a.return_poses == 0,
            "%d poses on the return path (%d reported), 13 wanted (frames 12..0)", m,
            b.return_poses);
    ENSURE(!memcmp(a.train_T, c.clip.T, sizeof(double) * pose * ntf)); /* frames 0..17 */
    double last = bend_of(&c.skel, c.clip.T + pose * (ntf - 1));
    ENSURE(bend_of(&c.skel, c.clip.T + pose * 13) > last); /* a frame left out: re-bent */
    for (int32_t i = 0; i < m; ++i) {
        const double *T = b.train_T + pose * (ntf + i);
        ENSUREF(!memcmp(T, c.clip.T + pose * (12 - i), sizeof(double) * pose),
                "return pose %d is not frame %d", i, 12 - i);
        double bend = bend_of(&c.skel, T);
        ENSUREF(bend < last, "return pose %d bent %.4f, the one before %.4f", i, bend, last);
        last = bend;
    }
    ENSURE(b.nheldout == a.nheldout &&
           !memcmp(a.heldout_T, b.heldout_T, sizeof(double) * pose * a.nheldout));
    sw_bake_result_free(&b);
    /* a training part that ends at rest has no way home: the bake is the one without */
    memcpy(c.clip.T + pose * (ntf - 1), c.clip.T, sizeof(double) * pose);
    p.return_path = 1;
    ENSUREF(sw_bake_solutions(&c, &p, &b, &err) == SINEW_OK, "%s", err.msg);
    sw_bake_result_free(&a);
    p.return_path = 0;
    ENSUREF(sw_bake_solutions(&c, &p, &a, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(b.ntrain == a.ntrain && !memcmp(a.train_T, b.train_T, sizeof(double) * pose * a.ntrain),
            "%d training poses with the return path, %d without", b.ntrain, a.ntrain);
    sw_bake_result_free(&a);
    sw_bake_result_free(&b);
    sw_character_free(&c);
}

SW_TEST_MAIN(CASE(min_frames), CASE(too_few_frames_rejected), CASE(solutions_match_the_bake),
             CASE(small_bones_fold_into_their_parents), CASE(progress_counts_every_pose_and_domain),
             CASE(pair_sweeps_turn_a_joint_with_its_parent),
             CASE(pair_sweeps_by_default_within_a_joint_range),
             CASE(sibling_sweeps_turn_two_children_of_one_joint_together),
             CASE(heldout_frames_are_measured_on_the_reference_path),
             CASE(contact_modes_extend_the_basis),
             CASE(return_path_goes_home_from_the_last_training_frame))
