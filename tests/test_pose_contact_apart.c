/* Pose-space pairs that have come apart (pose_contact.h, SW_PAIR_APART): a training
 * pose's contact pair whose vertex lies farther from its contact point on the triangle
 * than the triangle's longest edge is left out of the step; the others stay, in order,
 * with their weights. Checked on the folding finger, the deepest fold's pairs at every
 * frame of the clip against the vertices' positions; and the step's statistics count
 * the pairs it left out. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake_fixture.h"
#include "blob_load.h"
#include "instance.h"
#include "instance_internal.h"
#include "pose_contact.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

/* The folding finger at 2,000 tets with a 12-frame clip. */
static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

/* Slot m of contact c: its simulation vertex. */
static int32_t slot_vertex(const sw_blob_view *v, int32_t c, int m) {
    const int32_t *cv = v->contact_verts + 8 * (int64_t)c;
    return v->domain_verts[v->domains[cv[2 * m]].vert_begin + cv[2 * m + 1]];
}

/* |d|^2 over the triangle's longest edge^2 for contact c with the vertices at x. */
static double gap_ratio(const sw_blob_view *v, int32_t c, const double *x) {
    const double *b = v->contact_data + 7 * (int64_t)c, *p = x + 3 * (int64_t)slot_vertex(v, c, 0);
    double d2 = 0, e2 = 0;
    for (int i = 0; i < 3; ++i) {
        double s = -p[i];
        for (int m = 1; m < 4; ++m)
            s += b[m - 1] * x[3 * (int64_t)slot_vertex(v, c, m) + i];
        d2 += s * s;
    }
    for (int a = 1; a < 4; ++a)
        for (int k = a + 1; k < 4; ++k) {
            const double *xa = x + 3 * (int64_t)slot_vertex(v, c, a),
                         *xk = x + 3 * (int64_t)slot_vertex(v, c, k);
            double l2 = 0;
            for (int i = 0; i < 3; ++i)
                l2 += (xa[i] - xk[i]) * (xa[i] - xk[i]);
            if (l2 > e2) e2 = l2;
        }
    return d2 / e2;
}

/* At every frame of the clip (straight, folding, unfolding), the deepest fold's pairs put
 * in use at the step's state, at the locality shares 1 (the pose is their sample's), 0.5
 * and 0: the kept ones are, in order and with their weights, those whose vertex is within
 * SW_PAIR_APART edges over (1 - share) of its contact point, measured here from the
 * vertices' positions (sw_instance_full_positions: the mean of a vertex's domain copies,
 * which the seam moves slightly; pairs within 10% of the limit are not judged). */
TEST(a_pair_is_kept_while_its_vertex_is_near_its_contact_point) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    sinew_instance_def d = sinew_instance_def_default();
    sinew_instance *in = NULL;
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    const int32_t nb = f->ch.skel.nbones;
    double *x = malloc(sizeof(double) * 3 * (size_t)v->nverts),
           *count = malloc(sizeof(double) * (size_t)v->nverts);
    ENSURE(x && count);
    int32_t best = 0; /* the training pose with the most pairs: the deepest fold */
    for (int32_t t = 1; t < v->ntrain; ++t)
        if (v->contact_ptr[t + 1] - v->contact_ptr[t] >
            v->contact_ptr[best + 1] - v->contact_ptr[best])
            best = t;
    sw_pose_space *ps = &in->ps;
    int32_t n = v->contact_ptr[best + 1] - v->contact_ptr[best];
    if (n > ps->max_pairs) n = ps->max_pairs;
    ENSUREF(n >= 4, "the fold has %d pairs", (int)n);
    int32_t kept_any = 0, apart_any = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        sw_instance_full_positions(in, x, count);
        for (int si = 0; si < 3; ++si) { /* at the pairs' own pose, halfway, far from it */
            double share = 0.5 * si, f2 = (1 - share) * (1 - share);
            ps->npairs = n;
            for (int32_t i = 0; i < n; ++i) {
                ps->pairs[i] = v->contact_ptr[best] + i;
                ps->pair_w[i] = 1.0 + i;
                ps->pair_tan[i] = share;
            }
            int32_t apart = sw_pose_contacts_drop_apart(ps, &in->red, sw_instance_q(in));
            ENSURE(apart + ps->npairs == n);
            if (share == 1)
                ENSUREF(apart == 0, "frame %d: %d pairs dropped at their own pose", k, (int)apart);
            int32_t at = 0; /* walks the kept list alongside */
            for (int32_t i = 0; i < n; ++i) {
                double r = f2 * gap_ratio(v, v->contact_ptr[best] + i, x) /
                           (SW_PAIR_APART * SW_PAIR_APART);
                int kept = at < ps->npairs && ps->pairs[at] == v->contact_ptr[best] + i;
                if (kept) {
                    ENSUREF(ps->pair_w[at] == 1.0 + i && ps->pair_tan[at] == share,
                            "frame %d: kept pair %d lost its weights", k, (int)i);
                    at++;
                }
                if (fabs(r - 1) < 0.1) continue;
                ENSUREF(kept == (r < 1), "frame %d, share %.1f: pair %d at %.3f of the limit %s", k,
                        share, (int)i, r, kept ? "kept" : "dropped");
                kept_any += kept && share == 0;
                apart_any += !kept;
            }
            ENSURE(at == ps->npairs);
        }
    }
    /* both outcomes occur, so a keep-all or a drop-all rule fails here */
    ENSUREF(kept_any > 0 && apart_any > 0, "%d kept and %d apart over the clip", (int)kept_any,
            (int)apart_any);
    free(count);
    free(x);
    sinew_instance_destroy(in);
}

TEST(the_step_counts_the_pairs_it_left_apart) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance_def d = sinew_instance_def_default();
    sinew_instance *in = NULL;
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    const int32_t nb = f->ch.skel.nbones;
    uint32_t used = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        ENSURE(sinew_instance_get_stats(in, &st) == SINEW_OK);
        ENSUREF(st.contact_pairs + st.self_contacts_apart == st.self_contact_tests,
                "frame %d: %u in use + %u apart != %u gathered", k, st.contact_pairs,
                st.self_contacts_apart, st.self_contact_tests);
        ENSURE(st.self_contacts == st.contact_pairs);
        used += st.contact_pairs;
    }
    ENSUREF(used > 0, "no pair in use over the clip");
    sinew_instance_destroy(in);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(a_pair_is_kept_while_its_vertex_is_near_its_contact_point),
             CASE(the_step_counts_the_pairs_it_left_apart), CASE(release_fixture))
