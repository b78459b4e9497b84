/* Two characters pressing into each other (sinew-bench --pair, pair_bench.h): two copies
 * of the 1,000-tet finger, the second pushed from 1.15 to 0.85 of the thickness away while
 * both play the clip, each the other's mesh collider in one world.
 *  - the two-body reference finds contact between them and holds them apart;
 *  - the runtime with patches (10% of the vertices) holds the penetration under a fifth of
 *    the 15% of the thickness the motion overlaps them by (measured 0.017 of 0.128; 0.031
 *    with the colliders left where they started, which fails); the subspace alone does
 *    not (0.088 with the colliders or without: reported, not held);
 *  - both exert a force on the other, in opposite directions on the whole.
 * Measured (Release): see the fprintf line; the figures at 20K tets are in
 * docs/notes/novel-contact.md. */
#include <math.h>

#include "bake_fixture.h"
#include "fullsim.h"
#include "pair_bench.h"
#include "sw_test.h"

TEST(two_fingers_pressed_together_hold_each_other_out) {
    bake_fixture f;
    ENSURE(bake_fixture_make(&f, "finger", 1000, 12, 0));
    sw_fullsim_params fp = sw_fullsim_params_default();
    fp.threads = 2;
    sw_pair_bench b;
    sw_error err;
    ENSURE(sw_pair_bench_run(f.blob, &f.ch, f.ch.clip.T, f.ch.clip.nframes, &fp, &b, &err) ==
           SINEW_OK);
    const double overlap = 0.15 * b.thickness;
    fprintf(stderr,
            "  overlap asked %.4g: deepest reference %.4g, subspace %.4g, patches %.4g; error "
            "%.3f / %.3f; force balance %.3f; pair %.2fx two lone steps\n",
            overlap, b.pen_pair_full, b.pen_pair_sub, b.pen_pair_cond, b.err_pair_sub,
            b.err_pair_cond, b.force_balance, b.pair_cost_vs_lone);
    ENSURE(b.ref_failed == 0 && b.sub_failed == 0);
    ENSUREF(b.contact_frames_full > 0 && b.contact_frames_sub > 0 && b.contact_frames_cond > 0,
            "frames touching: reference %d, subspace %d, patches %d", b.contact_frames_full,
            b.contact_frames_sub, b.contact_frames_cond);
    ENSUREF(b.pen_pair_full < 0.1 * overlap, "reference %.4g", b.pen_pair_full);
    ENSUREF(b.pen_pair_cond < 0.2 * overlap, "patches %.4g of %.4g", b.pen_pair_cond, overlap);
    ENSUREF(b.force_frames > 0 && b.force_balance < 0.8, "force balance %.3f over %d frames",
            b.force_balance, b.force_frames);
    ENSURE(isfinite(b.err_pair_sub) && isfinite(b.err_pair_cond));
    bake_fixture_free(&f);
}

SW_TEST_MAIN(CASE(two_fingers_pressed_together_hold_each_other_out))
