/* Pose-space self-contact per pair of domains (deliverable 2; bake_pairs.c,
 * pair_space.c): the pair feature ignores a rigid motion of the whole character and
 * is, at every training pose, the feature the bake stored; a pair cubature reproduces the
 * reduced contact force it was fitted to within its tolerance; two identical samples
 * blended are one; a joint bent far beyond every sample is novel contact that the
 * exhaustive detection takes over; a corrupted pair section is refused. The step's
 * real-time contract in this mode is test_step_contract's "pose pairs" path. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake_fixture.h"
#include "bake.h"
#include "bake_state.h"
#include "bbox.h"
#include "blob_load.h"
#include "instance.h"
#include "instance_internal.h"
#include "mat3.h"
#include "self_contact.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

/* The folding finger at 2,000 tets with a 12-frame clip. */
static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

static sinew_instance *pairs_instance(const bake_fixture *f) {
    sinew_instance_def d = sinew_instance_def_default();
    d.self_contact = SINEW_SELF_CONTACT_POSE_PAIRS;
    sinew_instance *in = NULL;
    return sinew_instance_create(f->blob, &d, &in) == SINEW_OK ? in : NULL;
}

/* T' = G T for every bone: a rotation by `angle` about the axis (1, 2, 3) and a shift. */
static void move_rigidly(const double *T, int32_t nb, double angle, double *out) {
    double a[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)}, c = cos(angle), s = sin(angle),
           G[9], sh[3] = {3.5, -1.25, 7};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            G[3 * i + j] = (i == j ? c : 0) + (1 - c) * a[i] * a[j] +
                           s * (i == j ? 0 : ((j == (i + 1) % 3) ? -a[3 - i - j] : a[3 - i - j]));
    for (int32_t b = 0; b < nb; ++b) {
        const double *R = T + 12 * b, *t = R + 9;
        double *Ro = out + 12 * b, *to = Ro + 9;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                Ro[3 * i + j] = G[3 * i] * R[j] + G[3 * i + 1] * R[3 + j] + G[3 * i + 2] * R[6 + j];
            to[i] = G[3 * i] * t[0] + G[3 * i + 1] * t[1] + G[3 * i + 2] * t[2] + sh[i];
        }
    }
}

TEST(the_pair_feature_ignores_rigid_motion_and_matches_the_bake) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    ENSUREF(v->npair_groups > 0, "the finger's training poses touch themselves: groups expected");
    const int32_t nb = v->nbones;
    double *moved = malloc(sizeof(double) * 12 * (size_t)nb),
           *snapped = malloc(sizeof(double) * 12 * (size_t)nb), lo[3], hi[3];
    ENSURE(moved && snapped);
    sw_bbox_empty(lo, hi); /* the step's size: the rest diagonal */
    sw_bbox_add(lo, hi, v->nverts, v->rest);
    const double grid = sw_pose_grid(sw_bbox_diagonal(lo, hi));
    int32_t checked = 0;
    for (int32_t g = 0; g < v->npair_groups; ++g) {
        if (v->pair_domains[2 * g] == v->pair_domains[2 * g + 1]) continue;
        for (int32_t t = 0; t < v->ntrain; ++t, ++checked) {
            const double *T = f->res.train_T + (size_t)t * 12 * nb;
            double c[6], cm[6], cs[6], size = 0;
            sw_pair_space_feature(v, g, T, c);
            move_rigidly(T, nb, 0.7, moved);
            sw_pair_space_feature(v, g, moved, cm);
            /* the bake stores the pose as the step sees it (sw_pose_snap) */
            sw_pose_snap(T, T, nb, grid, snapped);
            sw_pair_space_feature(v, g, snapped, cs);
            const double *stored = v->pair_feature + 6 * ((int64_t)g * v->ntrain + t);
            for (int k = 0; k < 6; ++k)
                size += c[k] * c[k];
            size = sqrt(size);
            for (int k = 0; k < 6; ++k) {
                ENSUREF(fabs(c[k] - cm[k]) <= 1e-10 * size,
                        "group %d pose %d coordinate %d: %g "
                        "moved %g",
                        g, t, k, c[k], cm[k]);
                ENSUREF(fabs(cs[k] - stored[k]) <= 1e-12 * size,
                        "group %d pose %d coordinate %d: "
                        "%.17g, the bake stored %.17g",
                        g, t, k, cs[k], stored[k]);
            }
        }
    }
    ENSURE(checked > 0);
    free(moved);
    free(snapped);
}

TEST(a_pair_cubature_reproduces_its_reduced_force_within_tolerance) {
    enum { M = 24, N = 80 };
    double *A = calloc((size_t)M * N, sizeof(double)), w[N], b[M] = {0}, r[M];
    ENSURE(A);
    uint64_t seed = 12345;
    for (int j = 0; j < N; ++j) {
        if (j % 9 == 4) continue; /* a pair apart: no force */
        for (int i = 0; i < M; ++i) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(seed >> 11) / 9007199254740992.0;
            /* forces of one contact region: alike, with some spread */
            A[(size_t)j * M + i] = (i % 3 == 0 ? 1.0 : 0.2) + 0.8 * (u - 0.5);
        }
    }
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < M; ++i)
            b[i] += A[(size_t)j * M + i];
    double bn = 0;
    for (int i = 0; i < M; ++i)
        bn += b[i] * b[i];
    bn = sqrt(bn);
    const double tols[3] = {0.2, 0.05, 1e-6};
    int kept_last = N + 1;
    for (int k = 0; k < 3; ++k) {
        sw_error err;
        ENSUREF(sw_bake_pair_cubature(A, M, N, tols[k], w, &err) == SINEW_OK, "%s", err.msg);
        int kept = 0;
        memcpy(r, b, sizeof r);
        for (int j = 0; j < N; ++j) {
            ENSUREF(w[j] >= 0, "pair %d weight %g", j, w[j]);
            if (j % 9 == 4) ENSUREF(w[j] == 0, "pair %d has no force, weight %g", j, w[j]);
            kept += w[j] > 0;
            for (int i = 0; i < M; ++i)
                r[i] -= w[j] * A[(size_t)j * M + i];
        }
        double rn = 0;
        for (int i = 0; i < M; ++i)
            rn += r[i] * r[i];
        ENSUREF(sqrt(rn) <= tols[k] * bn * (1 + 1e-9), "tol %g: residual %g of %g", tols[k],
                sqrt(rn), bn);
        ENSUREF(kept < N && kept <= kept_last + M, "tol %g: %d pairs kept of %d", tols[k], kept, N);
        if (k == 0) ENSUREF(kept < 10, "a loose tolerance keeps few pairs: %d", kept);
        kept_last = kept;
    }
    free(A);
}

TEST(two_identical_samples_blended_are_one) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *in = NULL;
    sinew_instance_def d = sinew_instance_def_default();
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    const int32_t nb = f->ch.skel.nbones, R = in->red.R;
    const int32_t *cp = in->v->contact_ptr;
    int32_t frame = -1;
    /* a frame whose nearest sample has pairs */
    for (int k = 0; k < f->ch.clip.nframes && frame < 0; ++k) {
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        int32_t t = in->ps.nearest, n = t >= 0 ? cp[t + 1] - cp[t] : 0;
        if (n > 0) frame = k;
    }
    ENSUREF(frame >= 0, "no clip frame uses a contact pair");
    /* the whole pose's gather (pose_space.c) of the nearest sample alone, then blended
       at 0.3 with itself as the second: the blend must give the same pairs' energy */
    sw_pose_space *ps = &in->ps;
    ps->second = ps->nearest;
    ps->blend = 0;
    ps->tangent[1] = ps->tangent[0];
    sw_pose_space_gather_pairs(ps, in->v);
    const int32_t n = ps->npairs;
    ENSUREF(n > 0 && ps->dropped == 0, "the nearest sample holds %d pairs", n);
    double *q = malloc(sizeof(double) * (size_t)R), *g1 = malloc(sizeof(double) * (size_t)R),
           e1 = 0;
    ENSURE(q && g1);
    sw_pair_set set = sw_pose_pair_set(&in->red);
    for (int k = 0; k < 8 && !(e1 > 0); ++k) { /* a state where the pairs press */
        for (int32_t i = 0; i < R; ++i)
            q[i] = in->solver.q[i] * (k < 4 ? 1 + 0.5 * k : -0.5 * (k - 3));
        memset(in->red.g, 0, sizeof(double) * (size_t)R);
        e1 = sw_contact_pairs_eval(&in->red, &set, ps->pairs, NULL, n, ps->pair_w, ps->pair_tan, q,
                                   1, 0);
    }
    memcpy(g1, in->red.g, sizeof(double) * (size_t)R);
    ps->blend = 0.3; /* into arrays that hold both (the budget holds the two fullest) */
    int32_t *pairs = malloc(sizeof(int32_t) * 2 * (size_t)n);
    double *pw = malloc(sizeof(double) * 2 * (size_t)n),
           *pt = malloc(sizeof(double) * 2 * (size_t)n);
    ENSURE(pairs && pw && pt);
    ps->pairs = pairs, ps->pair_w = pw, ps->pair_tan = pt, ps->max_pairs = 2 * n;
    sw_pose_space_gather_pairs(ps, in->v);
    ENSUREF(ps->npairs == 2 * n && ps->dropped == 0, "blended: %d pairs of %d, %d dropped",
            ps->npairs, 2 * n, ps->dropped);
    memset(in->red.g, 0, sizeof(double) * (size_t)R);
    double e2 = sw_contact_pairs_eval(&in->red, &set, ps->pairs, NULL, ps->npairs, ps->pair_w,
                                      ps->pair_tan, q, 1, 0);
    ENSUREF(e1 > 0, "the pairs never press: energy %g", e1);
    ENSUREF(fabs(e1 - e2) <= 1e-12 * e1, "one sample %.17g, blended with itself %.17g", e1, e2);
    double gn = 0;
    for (int32_t i = 0; i < R; ++i)
        gn = fmax(gn, fabs(g1[i]));
    for (int32_t i = 0; i < R; ++i)
        ENSUREF(fabs(g1[i] - in->red.g[i]) <= 1e-11 * gn, "gradient %d: %g against %g", i, g1[i],
                in->red.g[i]);
    free(g1);
    free(q);
    free(pairs);
    free(pw);
    free(pt);
    sinew_instance_destroy(in);
}

/* Bone b is a descendant of bone a (or a itself). */
static int descends(const sw_skeleton *sk, int32_t b, int32_t a) {
    for (int32_t x = b; x >= 0; x = sk->parent[x])
        if (x == a) return 1;
    return 0;
}

/* The axis bone b bends about in the clip: that of its rotation in the frame where it is
 * turned furthest (the finger's joints all bend about one axis). */
static void bend_axis(const bake_fixture *f, int32_t b, double axis[3]) {
    const int32_t nb = f->ch.skel.nbones;
    double best = -1;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        const double *R = f->ch.clip.T + ((size_t)k * nb + b) * 12;
        double w[3] = {R[7] - R[5], R[2] - R[6], R[3] - R[1]},
               n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (n > best && n > 0) {
            best = n;
            for (int i = 0; i < 3; ++i)
                axis[i] = w[i] / n;
        }
    }
}

/* The clip's frame k with the bone of domain 1 and its descendants turned by `angle` about
 * the axis that bone bends about in the clip, through its head joint: the two domains'
 * relative motion, past anything the clip does for |angle| well beyond its bend. */
static void bent_joint(const bake_fixture *f, int k, double angle, double *T) {
    const sw_skeleton *sk = &f->ch.skel;
    const int32_t nb = sk->nbones, bone = sw_blob_get_view(f->blob)->domains[1].bone;
    memcpy(T, f->ch.clip.T + (size_t)k * 12 * nb, sizeof(double) * 12 * (size_t)nb);
    const double *X = sk->joints + 3 * sk->bones[2 * bone], *R0 = T + 12 * bone;
    double p[3], axis[3] = {1, 0, 0}, Q[9];
    bend_axis(f, bone, axis);
    sw_m3_axis_angle(axis, angle, Q);
    for (int i = 0; i < 3; ++i) /* the joint where the pose put it */
        p[i] = R0[3 * i] * X[0] + R0[3 * i + 1] * X[1] + R0[3 * i + 2] * X[2] + R0[9 + i];
    for (int32_t b = 0; b < nb; ++b) {
        if (!descends(sk, b, bone)) continue;
        double *R = T + 12 * b, *t = R + 9, Rn[9], tn[3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                Rn[3 * i + j] = Q[3 * i] * R[j] + Q[3 * i + 1] * R[3 + j] + Q[3 * i + 2] * R[6 + j];
            tn[i] = p[i] + Q[3 * i] * (t[0] - p[0]) + Q[3 * i + 1] * (t[1] - p[1]) +
                    Q[3 * i + 2] * (t[2] - p[2]);
        }
        memcpy(R, Rn, sizeof Rn);
        memcpy(t, tn, sizeof tn);
    }
}

TEST(a_pose_far_from_every_sample_falls_back_to_detection) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *in = pairs_instance(f);
    ENSURE(in);
    const int32_t nb = f->ch.skel.nbones;
    double *T = malloc(sizeof(double) * 12 * (size_t)nb);
    ENSURE(T);
    /* the clip's own frames are near their samples */
    uint32_t novel_clip = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        ENSURE(sinew_instance_get_stats(in, &st) == SINEW_OK);
        novel_clip += st.self_contact_novel;
    }
    ENSUREF(novel_clip == 0, "%u novel pairs of domains on the training clip", novel_clip);
    /* the joint between the two domains bent far past the clip's bend, either way */
    uint32_t novel = 0, detected = 0;
    for (int sign = -1; sign <= 1; sign += 2) {
        bent_joint(f, f->ch.clip.nframes - 1, sign * 2.6, T);
        ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        ENSURE(sinew_instance_get_stats(in, &st) == SINEW_OK);
        novel += st.self_contact_novel;
        /* the detection's contacts join the pose-space pairs (step.c, phase_self) */
        if (st.self_contact_novel > 0) detected += st.self_contacts - st.contact_pairs;
    }
    ENSUREF(novel > 0, "no pair of domains was novel at a joint bent by 150 degrees more");
    ENSUREF(detected > 0, "novel contact, but the exhaustive detection found none");
    free(T);
    sinew_instance_destroy(in);
}

/* Thesis §3.3.1: a cubature vertex is tested against the flesh around its trained
 * triangle, since on a fine mesh it may enter a nearby triangle instead. At a clip frame's
 * solution every pair whose vertex lies in a tet of those rings takes the triangle the
 * reference's rule gives (self_detect.h), and the full-mesh detection at the same state
 * finds a contact for that vertex too, most often the same triangle; the others keep
 * their trained triangle, and the gathered weights are all kept. */
TEST(cubature_vertices_are_tested_against_the_flesh_around_their_triangles) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *in = pairs_instance(f);
    ENSURE(in);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    const int32_t nb = f->ch.skel.nbones, ns = v->nsurf_verts;
    int32_t *p_moved = malloc(sizeof(int32_t) * (size_t)ns),
            *tri_moved = malloc(sizeof(int32_t) * 3 * (size_t)ns);
    ENSURE(p_moved && tri_moved);
    int32_t moved_total = 0, same = 0, frames = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        const double *T = f->ch.clip.T + (size_t)k * 12 * nb;
        ENSURE(sw_instance_set_pose_d(in, T) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        /* the frame's gathered pairs again, tested at its solution */
        sw_pair_space_gather(&in->ps, v, T);
        if (in->ps.novel > 0 || in->ps.npairs == 0) continue;
        double w_before = 0, w_after = 0;
        for (int32_t i = 0; i < in->ps.npairs; ++i)
            w_before += in->ps.pair_w[i];
        sw_self_contacts_clear(&in->sc);
        int32_t moved = sw_self_contacts_retest(&in->sc, &in->red, in->solver.q, &in->ps);
        ENSURE(moved == in->sc.npairs && in->sc.tests > 0);
        for (int32_t i = 0; i < in->ps.npairs; ++i)
            w_after += in->ps.pair_w[i];
        for (int32_t i = 0; i < moved; ++i) {
            w_after += in->sc.w[i];
            p_moved[i] = in->sc.act[4 * i];
            for (int c = 0; c < 3; ++c)
                tri_moved[3 * i + c] = in->sc.act[4 * i + 1 + c];
        }
        ENSUREF(fabs(w_after - w_before) <= 1e-12 * w_before, "weights %.17g before, %.17g after",
                w_before, w_after);
        /* the whole mesh's detection at the same state */
        sw_self_contacts_detect(&in->sc, &in->red, in->solver.q);
        for (int32_t i = 0; i < moved; ++i) {
            int32_t j = 0;
            while (j < in->sc.npairs && in->sc.act[4 * j] != p_moved[i])
                ++j;
            ENSUREF(j < in->sc.npairs,
                    "frame %d: vertex %d entered a ring tet, but the whole "
                    "mesh's detection finds no contact for it",
                    k, p_moved[i]);
            same += !memcmp(in->sc.act + 4 * j + 1, tri_moved + 3 * i, 3 * sizeof(int32_t));
        }
        moved_total += moved;
        frames += moved > 0;
    }
    fprintf(stderr,
            "    %d pairs moved on %d frames, %d of them to the triangle the whole mesh's "
            "detection gives\n",
            moved_total, frames, same);
    ENSUREF(moved_total > 0, "no cubature vertex entered the flesh around its triangle");
    ENSURE(2 * same >= moved_total);
    free(p_moved);
    free(tri_moved);
    sinew_instance_destroy(in);
}

TEST(a_blob_with_a_corrupt_pair_section_is_refused) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *good = sw_blob_get_view(f->blob);
    ENSURE(good->npair_groups > 0);
    char msg[512];
    sw_blob_view v = *good;
    double *wt = malloc(sizeof(double) * (size_t)v.ncontacts);
    int32_t *dom = malloc(sizeof(int32_t) * 2 * (size_t)v.npair_groups);
    ENSURE(wt && dom);
    memcpy(wt, v.pair_weight, sizeof(double) * (size_t)v.ncontacts);
    wt[0] = -1;
    v.pair_weight = wt;
    ENSURE(sw_blob_validate_view(&v, msg, sizeof msg) == SINEW_ERROR_CORRUPT);
    ENSUREF(strstr(msg, "PAIR_WEIGHT") && strstr(msg, "contact 0"), "%s", msg);
    v = *good;
    memcpy(dom, v.pair_domains, sizeof(int32_t) * 2 * (size_t)v.npair_groups);
    dom[0] = v.ndomains;
    v.pair_domains = dom;
    ENSURE(sw_blob_validate_view(&v, msg, sizeof msg) == SINEW_ERROR_CORRUPT);
    ENSUREF(strstr(msg, "PAIR_DOMAINS"), "%s", msg);
    /* a group whose contacts are another pair of domains' */
    v = *good;
    memcpy(dom, v.pair_domains, sizeof(int32_t) * 2 * (size_t)v.npair_groups);
    dom[1] = (dom[1] + 1) % v.ndomains;
    v.pair_domains = dom;
    sinew_result r = sw_blob_validate_view(&v, msg, sizeof msg);
    ENSUREF(r == SINEW_ERROR_CORRUPT && strstr(msg, "PAIR_"), "%s", msg);
    v = *good;
    v.pair_ptr = NULL;
    ENSURE(sw_blob_validate_view(&v, msg, sizeof msg) == SINEW_ERROR_INVALID_ARGUMENT);
    free(wt);
    free(dom);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(the_pair_feature_ignores_rigid_motion_and_matches_the_bake),
             CASE(a_pair_cubature_reproduces_its_reduced_force_within_tolerance),
             CASE(two_identical_samples_blended_are_one),
             CASE(a_pose_far_from_every_sample_falls_back_to_detection),
             CASE(cubature_vertices_are_tested_against_the_flesh_around_their_triangles),
             CASE(a_blob_with_a_corrupt_pair_section_is_refused), CASE(release_fixture))
