/* The step cannot blow up ( sinew_types.h, status flags): one-step rotation
 * snaps of a bone (5, 30, 90 degrees) at dt = 1e-9, 1e-6, 1e-3 and 1/60, each followed
 * by 300 steps at that dt, translation jumps and dt spikes leave a finite output within
 * the instance's displacement bound, and every snap that implies a joint spin above
 * SW_JUMP_MAX_SPIN is flagged TELEPORT; the clip's normal motion is never flagged; bad
 * poses are rejected with the state kept; a step at rest converges. */
#include <math.h>
#include <stdint.h>

#include "bake_fixture.h"
#include "inertia.h"
#include "snap_probe.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 1);
    return fx_ok ? &fx : NULL;
}

static sinew_instance *make(const bake_fixture *f, sinew_step_mode mode) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = mode;
    sinew_instance *inst = NULL;
    return sinew_instance_create(f->blob, &d, &inst) == SINEW_OK ? inst : NULL;
}

static const double *clip_pose(const bake_fixture *f, int frame) {
    return f->ch.clip.T + (size_t)(frame % f->ch.clip.nframes) * 12 * f->ch.skel.nbones;
}

TEST(the_clips_motion_is_never_flagged_or_limited) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    for (int mode = 0; mode < 2; ++mode) {
        sinew_instance *inst = make(f, mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC);
        ENSURE(inst);
        double use = 0;
        uint32_t flagged = 0;
        for (int s = 0; s < 4 * f->ch.clip.nframes; ++s) {
            ENSURE(sw_instance_set_pose_d(inst, clip_pose(f, s)) == SINEW_OK);
            ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(inst, &st);
            flagged |= st.status & (SINEW_STEP_TELEPORT | SINEW_STEP_LIMITED);
            use = fmax(use, sw_instance_bound_usage(inst));
        }
        fprintf(stderr, "    %s: largest |q_k| / bound %.3f, displacement bound %.4g\n",
                mode ? "dynamic" : "quasistatic", use, sw_instance_displacement_bound(inst));
        ENSUREF(flagged == 0, "the clip's motion was flagged 0x%x", flagged);
        ENSURE(use < 1);
        sinew_instance_destroy(inst);
    }
}

TEST(rotation_snaps_stay_bounded_and_are_flagged) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    sinew_instance *inst = make(f, SINEW_STEP_DYNAMIC);
    ENSURE(inst);
    int32_t nb = v->nbones, bone = nb > 1 ? 1 : 0;
    double *T1 = malloc(sizeof(double) * 12 * nb),
           *skin = malloc(sizeof(double) * 3 * v->nsurf_verts);
    const double *T0 = clip_pose(f, f->ch.clip.nframes / 2);
    static const double angles[] = {5, 30, 90};
    static const float dts[] = {1e-9f, 1e-6f, 1e-3f, 1.0f / 60};
    int declared = 0;
    fprintf(stderr,
            "    bone %d snap: angle  dt        max dev/bound  dev/size  snap flags  "
            "limited after\n",
            bone);
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 4; ++k) {
            snap_rotate(v, T0, bone, angles[a] * 3.14159265358979323846 / 180, T1);
            snap_result r = snap_run(inst, v, T0, T1, dts[k], 3, 300, 0, skin);
            fprintf(stderr, "    %17.0f  %-8.3g  %13.3f  %8.3f  0x%02x        %d\n", angles[a],
                    (double)dts[k], r.max_ratio, r.max_size, r.snap_status, r.limited_steps);
            ENSURE(r.nonfinite == 0);
            ENSUREF(r.max_ratio <= 1 + 1e-6, "%g deg at dt %g: %.3g of the bound", angles[a],
                    (double)dts[k], r.max_ratio);
            if (angles[a] * 3.14159265358979323846 / 180 > SW_JUMP_MAX_SPIN * dts[k])
                ENSUREF(r.snap_status & SINEW_STEP_TELEPORT, "%g deg at dt %g not flagged",
                        angles[a], (double)dts[k]);
            if (r.snap_status & SINEW_STEP_TELEPORT) continue;
            /* taken for motion (slower than SW_JUMP_MAX_SPIN, a bone's points moving less
             * than half the size): the same snap as a host declares it */
            snap_result cut = snap_run(inst, v, T0, T1, dts[k], 3, 300, 1, skin);
            fprintf(stderr, "    %17s  declared  %13.3f  %8.3f  0x%02x        %d\n", "",
                    cut.max_ratio, cut.max_size, cut.snap_status, cut.limited_steps);
            ENSURE(cut.nonfinite == 0 && cut.max_ratio <= 1 + 1e-6);
            ENSUREF(cut.snap_status & SINEW_STEP_TELEPORT, "%g deg at dt %g declared, unflagged",
                    angles[a], (double)dts[k]);
            declared++;
        }
    ENSURE(declared >= 3); /* 5 deg at 1e-3 and 1/60, 30 deg at 1/60 look like motion */
    free(T1);
    free(skin);
    sinew_instance_destroy(inst);
}

/* A declared cut takes no velocity and no inertia from the pose history: from rest, a
 * 30 degree snap at 1/60 s declared after steps at the rest pose gives bitwise the output
 * of a step with no history at all (right after a reset); undeclared, the bone's motion
 * acts on the flesh and the output differs. The mark holds for the next step only, and a
 * reset drops it. */
TEST(a_declared_cut_takes_no_inertia) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    int32_t nb = v->nbones, ns = v->nsurf_verts;
    double *T0 = calloc(12 * (size_t)nb, sizeof(double)), *T1 = malloc(sizeof(double) * 12 * nb);
    for (int32_t b = 0; b < nb; ++b) /* the rest pose */
        T0[12 * b] = T0[12 * b + 4] = T0[12 * b + 8] = 1;
    snap_rotate(v, T0, nb > 1 ? 1 : 0, 30 * 3.14159265358979323846 / 180, T1);
    float *x[3];
    uint32_t status[3];
    for (int run = 0; run < 3; ++run) { /* no history, declared cut, undeclared snap */
        sinew_instance *inst = make(f, SINEW_STEP_DYNAMIC);
        ENSURE(inst);
        for (int s = 0; run > 0 && s < 3; ++s) {
            ENSURE(sw_instance_set_pose_d(inst, T0) == SINEW_OK);
            ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
        }
        if (run == 1) ENSURE(sinew_instance_mark_teleport(inst) == SINEW_OK);
        ENSURE(sw_instance_set_pose_d(inst, T1) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        sinew_instance_get_stats(inst, &st);
        status[run] = st.status;
        x[run] = malloc(sizeof(float) * 3 * (size_t)ns);
        ENSURE(sinew_instance_read_surface(inst, x[run], NULL, (uint32_t)ns) == SINEW_OK);
        if (run == 1) { /* the mark was used up; a reset drops a pending one */
            ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
            sinew_instance_get_stats(inst, &st);
            ENSURE(!(st.status & SINEW_STEP_TELEPORT));
            ENSURE(sinew_instance_mark_teleport(inst) == SINEW_OK);
            sinew_instance_reset(inst);
            ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
            sinew_instance_get_stats(inst, &st);
            ENSURE(!(st.status & SINEW_STEP_TELEPORT));
        }
        sinew_instance_destroy(inst);
    }
    double diff = 0;
    for (int32_t i = 0; i < 3 * ns; ++i)
        diff = fmax(diff, fabs((double)x[2][i] - x[0][i]));
    fprintf(stderr, "    flags 0x%02x 0x%02x 0x%02x; undeclared differs by %.3g\n", status[0],
            status[1], status[2], diff);
    ENSURE(status[1] & SINEW_STEP_TELEPORT);
    ENSURE(!(status[2] & SINEW_STEP_TELEPORT));
    ENSURE(memcmp(x[0], x[1], sizeof(float) * 3 * (size_t)ns) == 0);
    ENSURE(diff > 0);
    ENSURE(sinew_instance_mark_teleport(NULL) == SINEW_ERROR_INVALID_ARGUMENT);
    for (int run = 0; run < 3; ++run)
        free(x[run]);
    free(T0);
    free(T1);
}

TEST(translation_jumps_and_dt_spikes_stay_bounded) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    sinew_instance *inst = make(f, SINEW_STEP_DYNAMIC);
    ENSURE(inst);
    int32_t nb = v->nbones;
    double *T1 = malloc(sizeof(double) * 12 * nb),
           *skin = malloc(sizeof(double) * 3 * v->nsurf_verts);
    const double *T0 = clip_pose(f, f->ch.clip.nframes / 2);
    double bound = sw_instance_displacement_bound(inst), size = 0;
    for (int32_t b = 0; b < nb; ++b) /* the skeleton's extent stands in for the size */
        for (int i = 0; i < 3; ++i)
            size = fmax(size, fabs(v->bone_joints[6 * b + 3 + i] - v->bone_joints[6 * b + i]));
    static const double jumps[] = {10.0, 0.01};
    static const float dts[] = {1.0f / 30, 1e-9f};
    for (int j = 0; j < 2; ++j) {
        memcpy(T1, T0, sizeof(double) * 12 * nb);
        for (int32_t b = 0; b < nb; ++b)
            T1[12 * b + 9] += jumps[j] * size;
        snap_result r = snap_run(inst, v, T0, T1, dts[j], 3, 100, 0, skin);
        fprintf(stderr,
                "    translation %.3g x bone extent at dt %g: %.3f of the bound, flags 0x%02x\n",
                jumps[j], (double)dts[j], r.max_ratio, r.snap_status);
        ENSURE(r.nonfinite == 0 && r.max_ratio <= 1 + 1e-6);
        ENSURE(r.snap_status & SINEW_STEP_TELEPORT);
    }
    /* dt spikes: the clip at alternating dt = 1e-9 and 1 */
    sinew_instance_reset(inst);
    double worst = 0;
    uint32_t seen = 0;
    for (int s = 0; s < 200; ++s) {
        ENSURE(sw_instance_set_pose_d(inst, clip_pose(f, s)) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, s % 2 ? 1.0f : 1e-9f) == SINEW_OK);
        sinew_step_stats st = {.struct_size = sizeof st};
        sinew_instance_get_stats(inst, &st);
        seen |= st.status;
        double d = snap_deviation(inst, v, skin);
        ENSURE(d >= 0);
        worst = fmax(worst, d / bound);
    }
    fprintf(stderr, "    dt spikes 1e-9 / 1: %.3f of the bound, flags seen 0x%02x\n", worst, seen);
    ENSURE(worst <= 1 + 1e-6);
    ENSURE(seen & SINEW_STEP_TELEPORT); /* a clip frame's change in 1e-9 s is a jump */
    free(T1);
    free(skin);
    sinew_instance_destroy(inst);
}

TEST(bad_poses_are_rejected_and_the_state_kept) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    const sw_blob_view *v = sw_blob_get_view(f->blob);
    sinew_instance *inst = make(f, SINEW_STEP_DYNAMIC);
    ENSURE(inst);
    uint32_t nb = (uint32_t)v->nbones, ns = (uint32_t)v->nsurf_verts;
    float *pose = malloc(sizeof(float) * 12 * nb), *x0 = malloc(sizeof(float) * 3 * ns),
          *x1 = malloc(sizeof(float) * 3 * ns);
    for (int s = 0; s < 8; ++s) {
        bake_fixture_pose(f, s, pose);
        ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    }
    ENSURE(sinew_instance_read_surface(inst, x0, NULL, ns) == SINEW_OK);
    /* each bad pose: the error, and the next step of the last good pose as before */
    for (int bad = 0; bad < 6; ++bad) {
        bake_fixture_pose(f, 7, pose);
        float *T = pose + 12 * (nb - 1);
        sinew_result want = SINEW_ERROR_INVALID_ARGUMENT;
        switch (bad) {
        case 0:
            T[4] = NAN, want = SINEW_ERROR_NOT_FINITE;
            break;
        case 1:
            T[10] = INFINITY, want = SINEW_ERROR_NOT_FINITE;
            break;
        case 2: /* scaled by 1.1 */
            for (int i = 0; i < 9; ++i)
                T[i] *= 1.1f;
            break;
        case 3:
            T[1] += 0.2f;
            break; /* sheared */
        case 4:    /* a reflection */
            for (int i = 0; i < 3; ++i)
                T[3 * i] = -T[3 * i];
            break;
        default:
            memset(T, 0, 9 * sizeof(float));
            break; /* degenerate */
        }
        ENSUREF(sinew_instance_set_pose(inst, pose, nb) == want, "bad pose %d", bad);
    }
    ENSURE(sinew_instance_read_surface(inst, x1, NULL, ns) == SINEW_OK);
    ENSURE(memcmp(x0, x1, sizeof(float) * 3 * ns) == 0);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK); /* frame 7 held */
    ENSURE(sinew_instance_read_surface(inst, x1, NULL, ns) == SINEW_OK);
    for (uint32_t i = 0; i < 3 * ns; ++i)
        ENSURE(isfinite(x1[i]));
    free(pose);
    free(x0);
    free(x1);
    sinew_instance_destroy(inst);
}

TEST(a_step_at_rest_converges) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    for (int mode = 0; mode < 2; ++mode) {
        sinew_instance *inst = make(f, mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC);
        ENSURE(inst);
        uint32_t guard = 0, unconverged = 0;
        for (int s = 0; s < 200; ++s) { /* the rest pose, then a bent pose held */
            ENSURE(sw_instance_set_pose_d(inst, clip_pose(f, s < 50 ? 0 : 4)) == SINEW_OK);
            ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(inst, &st);
            if ((s >= 10 && s < 50) || s >= 150) {
                guard += !!(st.status & SINEW_STEP_GUARD);
                unconverged += !(st.status & SINEW_STEP_CONVERGED);
            }
        }
        fprintf(stderr, "    %s at rest: %u GUARD, %u not CONVERGED of 90 steps\n",
                mode ? "dynamic" : "quasistatic", guard, unconverged);
        ENSURE(unconverged == 0 && guard == 0);
        sinew_instance_destroy(inst);
    }
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
    fx_ok = -1;
}

SW_TEST_MAIN(CASE(the_clips_motion_is_never_flagged_or_limited),
             CASE(rotation_snaps_stay_bounded_and_are_flagged),
             CASE(a_declared_cut_takes_no_inertia),
             CASE(translation_jumps_and_dt_spikes_stay_bounded),
             CASE(bad_poses_are_rejected_and_the_state_kept), CASE(a_step_at_rest_converges),
             CASE(release_fixture))
