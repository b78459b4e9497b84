/* Where the character is does not change its flesh (DESIGN.md §3): a pose carried by a
 * rigid motion G gives G applied to the surface, in every step mode and self-contact
 * mode, with a world whose colliders (every shape: box, sphere, capsule, plane, mesh,
 * hull) move with G and condensation patches, also with the moved instance stepping in
 * workspaces as a crowd's does; an actor 10^5 units from the origin keeps the origin's
 * shape; a uniformly scaled pose gives the scaled shape; dt = 0 is a pause; a bone scaled
 * unlike the others is refused naming it. The measure is invariance.h's, the bound 1e-5 of
 * the character's size. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bake_fixture.h"
#include "character_io.h"
#include "instance.h"
#include "instance_internal.h"
#include "invariance.h"
#include "mat3.h"
#include "props_fixture.h"
#include "sw_mesh.h"
#include "sinew/sinew_world.h"
#include "sw_test.h"

#define BOUND 1e-5

static bake_fixture fx;
static int fx_ok = -1;

/* The finger (along +x from 0 to 3.6), folding into self-contact over 12 frames. */
static const bake_fixture *finger(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

static const double PI = 3.14159265358979323846;

/* Turned 150 degrees about a skew axis and carried far away. */
static sw_move far_rigid(void) {
    sw_move m = {SW_MOVE_RIGID, {0.3, -0.8, 0.5}, 150 * PI / 180, {7e4, -3e4, 1e5}, 0, 0, 0};
    return m;
}

static sw_invariance_result measure_on(const bake_fixture *f, const sw_invariance_run *run,
                                       const sw_move *m) {
    sw_invariance_result res = {0};
    if (!f) return res;
    sinew_result r = sw_invariance_measure(f->blob, f->ch.clip.T, f->ch.skel.nbones,
                                           f->ch.clip.nframes, run, m, &res);
    if (r != SINEW_OK) res.failed = -1;
    return res;
}

static sw_invariance_result measure(const sw_invariance_run *run, const sw_move *m) {
    return measure_on(finger(), run, m);
}

#define ENSURE_INVARIANT(res, what)                                                                \
    ENSUREF((res).failed == 0 && (res).size > 0 && (res).err <= BOUND,                             \
            "%s: %.3e of the size at frame %d (%d failed steps)", what, (res).err,                 \
            (res).worst_frame, (res).failed)

TEST(a_rigid_motion_of_the_pose_moves_the_surface_rigidly_in_every_self_contact_mode) {
    ENSURE(finger());
    const sinew_self_contact modes[] = {SINEW_SELF_CONTACT_POSE_SPACE,
                                        SINEW_SELF_CONTACT_POSE_PAIRS,
                                        SINEW_SELF_CONTACT_EXHAUSTIVE};
    const char *names[] = {"pose-space", "pose-pairs", "exhaustive"};
    sw_move m = far_rigid();
    for (int k = 0; k < 3; ++k) {
        sw_invariance_run run = {SINEW_STEP_QUASISTATIC, modes[k], NULL, NULL, 0, 0, 0, 0};
        sw_invariance_result res = measure(&run, &m);
        ENSURE_INVARIANT(res, names[k]);
        ENSUREF(res.self_contacts > 0, "%s: the fold never touched", names[k]);
    }
}

static double urand(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * 0x1.0p-53;
}

/* GT = G T for rigid transforms (12: R row-major, t). */
static void compose(const double *G, const double *T, double *GT) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            GT[3 * i + j] = G[3 * i] * T[j] + G[3 * i + 1] * T[3 + j] + G[3 * i + 2] * T[6 + j];
        GT[9 + i] = G[3 * i] * T[9] + G[3 * i + 1] * T[10] + G[3 * i + 2] * T[11] + G[9 + i];
    }
}

/* The mechanism (pose.c, sw_pose_snap): a pose carried by any rigid motion reaches the
 * step bit for bit, so the reduced state (bone-relative, free of the frame) is the same
 * bits in every mode, quasistatic and dynamic: motions about random axes, up to 180
 * degrees, up to 10^5 away. Detections on the edge of contact then decide alike. */
TEST(the_step_sees_a_rigidly_moved_pose_bit_for_bit) {
    const bake_fixture *f = finger();
    ENSURE(f);
    if (!f) return;
    const int32_t nb = f->ch.skel.nbones, R = sw_blob_get_view(f->blob)->rank_total;
    const struct {
        sinew_step_mode mode;
        sinew_self_contact sc;
    } modes[] = {{SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_POSE_SPACE},
                 {SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_POSE_PAIRS},
                 {SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_EXHAUSTIVE},
                 {SINEW_STEP_DYNAMIC, SINEW_SELF_CONTACT_EXHAUSTIVE}};
    double Tb[12 * 8];
    ENSURE(nb <= 8);
    uint64_t seed = 0x5eedu;
    for (int k = 0; k < 4; ++k)
        for (int trial = 0; trial < 3; ++trial) {
            sw_move m = {SW_MOVE_RIGID, {0, 0, 0}, 0, {0, 0, 0}, 0, 0, 0};
            for (int i = 0; i < 3; ++i) {
                m.axis[i] = 2 * urand(&seed) - 1 + 1e-3;
                m.shift[i] = 2e5 * urand(&seed) - 1e5;
            }
            m.angle = PI * (0.05 + 0.95 * urand(&seed));
            double G[12];
            sw_move_transform(&m, 0, G);
            sinew_instance_def d = sinew_instance_def_default();
            d.mode = modes[k].mode;
            d.self_contact = modes[k].sc;
            sinew_instance *a = NULL, *b = NULL;
            ENSURE(sinew_instance_create(f->blob, &d, &a) == SINEW_OK &&
                   sinew_instance_create(f->blob, &d, &b) == SINEW_OK);
            int same = 1, frame = 0;
            for (; same && frame < f->ch.clip.nframes; ++frame) {
                const double *T = f->ch.clip.T + (size_t)12 * nb * frame;
                for (int32_t j = 0; j < nb; ++j)
                    compose(G, T + 12 * j, Tb + 12 * j);
                ENSURE(sw_instance_set_pose_d(a, T) == SINEW_OK &&
                       sw_instance_set_pose_d(b, Tb) == SINEW_OK);
                ENSURE(sinew_instance_step(a, 1.0f / 30) == SINEW_OK &&
                       sinew_instance_step(b, 1.0f / 30) == SINEW_OK);
                same = memcmp(sw_instance_q(a), sw_instance_q(b), (size_t)R * sizeof(double)) == 0;
            }
            ENSUREF(same, "mode %d, motion %d: the moved instance's state differs at frame %d", k,
                    trial, frame - 1);
            sinew_instance_destroy(a);
            sinew_instance_destroy(b);
        }
}

TEST(a_character_turning_every_frame_deforms_as_one_standing_still) {
    sw_move m = {SW_MOVE_TURNING, {0.1, 1, 0.2}, 4 * PI / 180, {0.05, 0, 0.08}, 0, 0, 0};
    sw_invariance_run run = {SINEW_STEP_QUASISTATIC, 0, NULL, NULL, 0, 0, 0, 0};
    sw_invariance_result res = measure(&run, &m);
    ENSURE_INVARIANT(res, "turning");
}

TEST(dynamic_flesh_carried_by_a_constant_rigid_motion_is_the_same_motion) {
    sw_move m = far_rigid();
    sw_invariance_run run = {SINEW_STEP_DYNAMIC, 0, NULL, NULL, 1.0f / 30, 0, 0, 0};
    sw_invariance_result res = measure(&run, &m);
    ENSURE_INVARIANT(res, "dynamic");
}

TEST(an_actor_far_from_the_origin_keeps_the_origins_shape_in_its_frame) {
    sw_move m = far_rigid();
    m.kind = SW_MOVE_ACTOR;
    m.float_poses = m.float_output = 1; /* as a host hands them in and reads them */
    sw_invariance_run run = {SINEW_STEP_QUASISTATIC, 0, NULL, NULL, 0, 0, 0, 0};
    sw_invariance_result res = measure(&run, &m);
    ENSURE_INVARIANT(res, "far actor");
    m.scale = 0.01; /* an actor scaled as well: its frame holds the unscaled shape */
    res = measure(&run, &m);
    ENSURE_INVARIANT(res, "far actor scaled 0.01");
}

TEST(a_uniformly_scaled_pose_gives_the_scaled_shape) {
    const double scales[] = {0.01, 100, 1.0005};
    for (int k = 0; k < 3; ++k) {
        sw_move m = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, scales[k], 1, 1};
        sw_invariance_run run = {SINEW_STEP_QUASISTATIC, 0, NULL, NULL, 0, 0, 0, 0};
        sw_invariance_result res = measure(&run, &m);
        char what[32];
        snprintf(what, sizeof what, "scale %g", scales[k]);
        ENSURE_INVARIANT(res, what);
    }
}

/* ---- self-contact nobody trained ------------------------------------------------- */

enum { FOLD_STEPS = 16 };

/* The finger folded on past its training into self-contact the bake never saw
 * (test_novel_contact's fold): every joint bent about its sweep axis from rest to 2.6
 * times the largest trained bend (at most 170 degrees) in FOLD_STEPS frames, into T. */
static void deep_fold_clip(const bake_fixture *f, double *T) {
    const sw_skeleton *sk = &f->ch.skel;
    double trained = 0, local[9 * 8];
    for (int32_t b = 0; b < sk->nbones; ++b)
        trained = fmax(trained, f->blob->poses.joint_bend[b]);
    const double fold = fmin(2.6 * trained, 170 * PI / 180);
    for (int k = 1; k <= FOLD_STEPS; ++k) {
        for (int32_t b = 0; b < sk->nbones; ++b)
            sw_m3_axis_angle(f->res.sweep_axis + 3 * b,
                             sk->parent[b] >= 0 ? fold * k / FOLD_STEPS : 0, local + 9 * b);
        sw_forward_kinematics(sk, local, NULL, T + (size_t)12 * sk->nbones * (k - 1));
    }
}

/* The novel contact's broad phase (boxes carried by the dominant bones, a sweep on one
 * axis), its narrow phase and the contact it applies through the subspace give the same
 * flesh turned and far away, walking and turning, as a far actor and scaled; and both
 * instances did find novel contact (else nothing was checked). */
TEST(self_contact_nobody_trained_is_found_and_held_alike_wherever_the_finger_is) {
    const bake_fixture *f = finger();
    ENSURE(f && f->ch.skel.nbones <= 8);
    double T[12 * 8 * FOLD_STEPS];
    deep_fold_clip(f, T);
    sw_move rigid = far_rigid(), actor = far_rigid(),
            turning = {SW_MOVE_TURNING, {0.1, 1, 0.2}, 4 * PI / 180, {0.05, 0, 0.08}, 0, 0, 0},
            small = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, 0.01, 1, 1},
            big = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, 100, 1, 1};
    actor.kind = SW_MOVE_ACTOR;
    actor.float_poses = actor.float_output = 1;
    const struct {
        const char *name;
        const sw_move *m;
    } cases[] = {{"rigid", &rigid},
                 {"turning", &turning},
                 {"far actor", &actor},
                 {"scale 0.01", &small},
                 {"scale 100", &big}};
    for (int k = 0; k < 5; ++k) {
        sw_invariance_run run = {SINEW_STEP_QUASISTATIC, 0, NULL, NULL, 0, 0, 1, 0};
        sw_invariance_result res = {0};
        ENSURE(sw_invariance_measure(f->blob, T, f->ch.skel.nbones, FOLD_STEPS, &run, cases[k].m,
                                     &res) == SINEW_OK);
        fprintf(stderr, "  novel, %s: %.3e of the size, %lld / %lld novel contacts\n",
                cases[k].name, res.err, (long long)res.novel_contacts, (long long)res.novel_moved);
        ENSURE_INVARIANT(res, cases[k].name);
        ENSUREF(res.novel_contacts > 0 && res.novel_moved > 0,
                "%s: novel contacts %lld and %lld: the fold found none", cases[k].name,
                (long long)res.novel_contacts, (long long)res.novel_moved);
    }
}

/* ---- a world of every collider shape, and the same world carried by G ------------- */

/* Colliders pressing the folding finger from every side, carried by G (NULL: as they
 * are). Each kind of shape is there once: box (a table), sphere, capsule, a plane, a
 * triangle mesh (a tent) and a convex hull. */
static sinew_world *shape_world(const double *G) {
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, &w) != SINEW_OK) return NULL;
    sinew_collider_def c[6];
    for (int k = 0; k < 6; ++k)
        c[k] = sinew_collider_def_default();
    c[0].shape = SINEW_SHAPE_BOX;
    c[0].half_extents[0] = 2.5f, c[0].half_extents[1] = 0.2f, c[0].half_extents[2] = 1.0f;
    c[0].transform.position[0] = 1.8f, c[0].transform.position[1] = -0.59f;
    c[1].shape = SINEW_SHAPE_SPHERE;
    c[1].radius = 0.3f;
    c[1].transform.position[0] = 2.9f, c[1].transform.position[2] = 0.6f;
    c[2].shape = SINEW_SHAPE_CAPSULE;
    c[2].radius = 0.2f, c[2].half_height = 0.6f;
    c[2].transform.position[0] = 1.2f, c[2].transform.position[2] = -0.55f;
    c[3].shape = SINEW_SHAPE_PLANE; /* a wall at the finger's root: n . x = offset */
    c[3].normal[0] = 1, c[3].normal[1] = 0, c[3].normal[2] = 0, c[3].offset = -0.05f;
    c[4] = props_def(0, props_at(2.2f, 0.65f)); /* props_fixture.h: the tent */
    c[5] = props_def(1, props_at(0.6f, 0));     /* and the wedge, beside the root */
    c[5].transform.position[2] = 0.6f;
    for (int k = 0; k < 6; ++k) {
        double pos[3], rot[4]; /* carried in doubles, as a host with a double world */
        int placed = G && sw_move_placement(G, &c[k], pos, rot);
        if (G) sw_move_collider(G, &c[k]);
        sinew_collider_id id;
        if (sinew_world_add_collider(w, &c[k], &id) != SINEW_OK ||
            (placed && sinew_world_set_collider_transform_d(w, id, pos, rot) != SINEW_OK)) {
            fprintf(stderr, "  collider %d (shape %d) refused\n", k, (int)c[k].shape);
            sinew_world_destroy(w);
            return NULL;
        }
    }
    return w;
}

TEST(with_every_collider_shape_and_patches_a_world_moved_with_the_pose_gives_the_moved_flesh) {
    ENSURE(finger());
    /* the placements carried in doubles; the plane's normal and offset are floats, and a
       modest move keeps their rounding below the bound */
    sw_move m = {SW_MOVE_RIGID, {0.3, -0.8, 0.5}, 120 * PI / 180, {3, -2, 5}, 0, 0, 0};
    double G[12];
    sw_move_transform(&m, 0, G);
    sinew_world *w = shape_world(NULL), *wg = shape_world(G);
    ENSURE(w && wg);
    /* the last: the moved instance steps as a crowd's does, in workspaces taken in turn */
    const uint32_t budgets[] = {0, 400, 400};
    const sinew_step_mode modes[] = {SINEW_STEP_QUASISTATIC, SINEW_STEP_DYNAMIC};
    for (int b = 0; b < 3; ++b)
        for (int k = 0; k < 2; ++k) {
            sw_invariance_run run = {modes[k], 0, w, wg, 1.0f / 30, budgets[b], 0, b == 2};
            sw_invariance_result res = measure(&run, &m);
            char what[80];
            snprintf(what, sizeof what, "world, %s, patch budget %u%s",
                     k ? "dynamic" : "quasistatic", budgets[b], b == 2 ? ", in workspaces" : "");
            fprintf(stderr, "  %s: %.3e of the size, patch %u\n", what, res.err,
                    res.patch_vertices);
            ENSURE_INVARIANT(res, what);
            /* the colliders do press, and with a budget a patch grows */
            ENSUREF(res.world_contacts > 0 && res.self_contacts > 0 &&
                        (budgets[b] == 0 || res.patch_vertices > 0),
                    "%s: %lld world contacts, %lld self, patch %u", what,
                    (long long)res.world_contacts, (long long)res.self_contacts,
                    res.patch_vertices);
        }
    sinew_world_destroy(w);
    sinew_world_destroy(wg);
}

/* The finger baked with inertia modes: a quasistatic step holds them at the pose-space
 * prediction except in the domains the world or a detected pair touches (solver.h), a
 * choice made from the moved world's candidates and the moved pose's pairs, which must be
 * the unmoved ones. */
TEST(inertia_modes_held_where_nothing_untrained_touches_wherever_the_finger_is) {
    bake_fixture held;
    sw_bake_params p = bake_fixture_params(0, 2);
    p.inertia_modes = 1;
    ENSURE(bake_fixture_make_params(&held, "finger", 2000, 12, &p));
    const sw_blob_view *v = sw_blob_get_view(held.blob);
    int32_t marked = 0;
    for (int32_t d = 0; d < v->ndomains; ++d)
        marked += v->domains[d].inertia_count;
    ENSUREF(marked > 0, "no inertia mode marked (rank %d)", v->rank_total);
    sw_move far = far_rigid(),
            near = {SW_MOVE_RIGID, {0.3, -0.8, 0.5}, 120 * PI / 180, {3, -2, 5}, 0, 0, 0};
    sw_invariance_run alone = {
        SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_EXHAUSTIVE, NULL, NULL, 0, 0, 0, 0};
    sw_invariance_result res = measure_on(&held, &alone, &far);
    ENSURE_INVARIANT(res, "held, exhaustive, far and turned");
    ENSUREF(res.self_contacts > 0, "the fold never touched");
    double G[12];
    sw_move_transform(&near, 0, G);
    sinew_world *w = shape_world(NULL), *wg = shape_world(G);
    ENSURE(w && wg);
    sw_invariance_run pressed = {SINEW_STEP_QUASISTATIC, 0, w, wg, 1.0f / 30, 400, 0, 0};
    res = measure_on(&held, &pressed, &near);
    fprintf(stderr, "  held, every collider shape, patches: %.3e of the size, patch %u\n", res.err,
            res.patch_vertices);
    ENSURE_INVARIANT(res, "held, every collider shape, patches");
    ENSURE(res.world_contacts > 0);
    sinew_world_destroy(w);
    sinew_world_destroy(wg);
    bake_fixture_free(&held);
}

/* ---- engine inputs ------------------------------------------------------------------ */

typedef struct {
    char msg[512];
    uint32_t id;
} kept_log;

static void keep_log(sinew_log_level level, uint32_t id, const char *message, void *user) {
    kept_log *k = user;
    if (level != SINEW_LOG_ERROR) return;
    k->id = id;
    snprintf(k->msg, sizeof k->msg, "%s", message);
}

static sinew_instance *make(const bake_fixture *f, kept_log *log) {
    sinew_instance_def d = sinew_instance_def_default();
    d.logger.log = keep_log;
    d.logger.user = log;
    d.logger.max_level = SINEW_LOG_ERROR;
    sinew_instance *in = NULL;
    return sinew_instance_create(f->blob, &d, &in) == SINEW_OK ? in : NULL;
}

TEST(dt_zero_is_a_paused_frame) {
    const bake_fixture *f = finger();
    ENSURE(f);
    kept_log log = {{0}, 0};
    sinew_instance *in = make(f, &log);
    ENSURE(in);
    uint32_t nb = f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    float pose[12 * 8], before[3 * 4096], after[3 * 4096];
    ENSURE(nb <= 8 && ns <= 4096);
    bake_fixture_pose(f, 8, pose);
    ENSURE(sinew_instance_set_pose(in, pose, nb) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(in, before, NULL, ns) == SINEW_OK);
    bake_fixture_pose(f, 11, pose); /* a new pose, then a pause: nothing moves yet */
    ENSURE(sinew_instance_set_pose(in, pose, nb) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 0.0f) == SINEW_OK);
    ENSURE(sinew_instance_read_surface(in, after, NULL, ns) == SINEW_OK);
    ENSURE(memcmp(before, after, (size_t)3 * ns * sizeof(float)) == 0);
    sinew_step_stats st = {.struct_size = sizeof st};
    ENSURE(sinew_instance_get_stats(in, &st) == SINEW_OK && st.status == 0);
    ENSURE(sinew_instance_step(in, -1.0f / 30) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK); /* the pose set comes on */
    ENSURE(sinew_instance_read_surface(in, after, NULL, ns) == SINEW_OK);
    ENSURE(memcmp(before, after, (size_t)3 * ns * sizeof(float)) != 0);
    sinew_instance_destroy(in);
}

TEST(a_bone_scaled_unlike_the_others_or_sheared_is_refused_naming_it) {
    const bake_fixture *f = finger();
    ENSURE(f);
    kept_log log = {{0}, 0};
    sinew_instance *in = make(f, &log);
    ENSURE(in);
    uint32_t nb = f->ch.skel.nbones;
    float pose[12 * 8], bad[12 * 8];
    ENSURE(nb >= 2 && nb <= 8);
    bake_fixture_pose(f, 4, pose);
    ENSURE(sinew_instance_set_pose(in, pose, nb) == SINEW_OK);
    memcpy(bad, pose, sizeof pose);
    for (int i = 0; i < 9; ++i) /* squash and stretch of bone 1 alone */
        bad[12 + i] *= 1.2f;
    ENSURE(sinew_instance_set_pose(in, bad, nb) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(log.id == SINEW_MSG_INSTANCE_POSE && strstr(log.msg, "bone 1 is scaled 1.2"), "'%s'",
            log.msg);
    memcpy(bad, pose, sizeof pose);
    bad[12 + 1] += 0.3f; /* a shear */
    ENSURE(sinew_instance_set_pose(in, bad, nb) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(log.msg, "bone 1 is not a rotation times a uniform scale"), "'%s'", log.msg);
    memcpy(bad, pose, sizeof pose);
    for (uint32_t b = 0; b < nb; ++b) /* absurd: 10^7 */
        for (int i = 0; i < 9; ++i)
            bad[12 * b + i] *= 1e7f;
    ENSURE(sinew_instance_set_pose(in, bad, nb) == SINEW_ERROR_INVALID_ARGUMENT);
    double A[12] = {2, 0, 0, 0, 2, 0, 0, 0, 2, 1e5, 0, 0}, S[12] = {1, 0.5, 0, 0, 1, 0, 0, 0, 1};
    ENSURE(sinew_instance_set_actor(in, A) == SINEW_OK);
    ENSURE(sinew_instance_set_actor(in, S) == SINEW_ERROR_INVALID_ARGUMENT);
    A[0] = NAN;
    ENSURE(sinew_instance_set_actor(in, A) == SINEW_ERROR_NOT_FINITE);
    /* a scaled actor with a world: refused until the world's queries scale (pose.c) */
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &w) == SINEW_OK);
    double I[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    ENSURE(sinew_instance_set_world(in, w) == SINEW_ERROR_INVALID_ARGUMENT); /* scaled 2 */
    ENSURE(sinew_instance_set_actor(in, I) == SINEW_OK);
    ENSURE(sinew_instance_set_world(in, w) == SINEW_OK);
    A[0] = 2;
    ENSURE(sinew_instance_set_actor(in, A) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    sinew_instance_destroy(in);
    sinew_world_destroy(w);
}

/* A real character: the elephant (24 bones, its own clip), baked quickly, turned and carried
 * 10^5 units away, quasistatic (every self-contact mode) and dynamic, as a far actor and
 * scaled. Its exhaustive mode finds contacts on the edge of touching, where the rounding
 * of a turned pose once decided which (docs/notes/placement.md). */
TEST(the_elephant_moved_rigidly_far_and_scaled_keeps_its_flesh) {
    NEED_DATA("elephant-cd/elephant.mesh");
    bake_fixture e;
    memset(&e, 0, sizeof e);
    sw_error err;
    ENSUREF(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "elephant-cd", 40, &e.ch, &err) ==
                SINEW_OK,
            "%s", err.msg);
    sw_bake_params p = bake_fixture_params(1, 2);
    ENSURE(bake_fixture_bake(&e, &p));
    sw_move rigid = far_rigid(), actor = far_rigid(),
            scaled = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, 0.01, 1, 1};
    actor.kind = SW_MOVE_ACTOR;
    actor.float_poses = actor.float_output = 1;
    const struct {
        const char *name;
        sinew_step_mode mode;
        sinew_self_contact sc;
        const sw_move *m;
    } cases[] = {{"quasistatic", SINEW_STEP_QUASISTATIC, 0, &rigid},
                 {"pose-pairs", SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_POSE_PAIRS, &rigid},
                 {"exhaustive", SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_EXHAUSTIVE, &rigid},
                 {"exhaustive, dynamic", SINEW_STEP_DYNAMIC, SINEW_SELF_CONTACT_EXHAUSTIVE, &rigid},
                 {"dynamic", SINEW_STEP_DYNAMIC, 0, &rigid},
                 {"far actor", SINEW_STEP_QUASISTATIC, 0, &actor},
                 {"scale 0.01", SINEW_STEP_QUASISTATIC, 0, &scaled}};
    for (int k = 0; k < (int)(sizeof cases / sizeof cases[0]); ++k) {
        sw_invariance_run run = {cases[k].mode, cases[k].sc, NULL, NULL, 0.01f, 0, 0, 0};
        sw_invariance_result res;
        ENSURE(sw_invariance_measure(e.blob, e.ch.clip.T, e.ch.skel.nbones, e.ch.clip.nframes, &run,
                                     cases[k].m, &res) == SINEW_OK);
        fprintf(stderr, "  elephant, %s: %.3e of its size\n", cases[k].name, res.err);
        ENSURE_INVARIANT(res, cases[k].name);
    }
    bake_fixture_free(&e);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
    fx_ok = -1;
}

SW_TEST_MAIN(
    CASE(a_rigid_motion_of_the_pose_moves_the_surface_rigidly_in_every_self_contact_mode),
    CASE(the_step_sees_a_rigidly_moved_pose_bit_for_bit),
    CASE(a_character_turning_every_frame_deforms_as_one_standing_still),
    CASE(dynamic_flesh_carried_by_a_constant_rigid_motion_is_the_same_motion),
    CASE(an_actor_far_from_the_origin_keeps_the_origins_shape_in_its_frame),
    CASE(a_uniformly_scaled_pose_gives_the_scaled_shape),
    CASE(self_contact_nobody_trained_is_found_and_held_alike_wherever_the_finger_is),
    CASE(with_every_collider_shape_and_patches_a_world_moved_with_the_pose_gives_the_moved_flesh),
    CASE(inertia_modes_held_where_nothing_untrained_touches_wherever_the_finger_is),
    CASE(dt_zero_is_a_paused_frame),
    CASE(a_bone_scaled_unlike_the_others_or_sheared_is_refused_naming_it),
    CASE(the_elephant_moved_rigidly_far_and_scaled_keeps_its_flesh), CASE(release_fixture))
