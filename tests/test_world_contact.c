/* Contact with the collision world in the step and in the reference: the shared law's
 * derivatives, the reduced gradient and Hessian, the real-time contract with world
 * contact, the force readback, and the flesh pushed out of a collider in the subspace
 * (as far as it can: it locks) and in full space. Instances sharing one world across
 * threads: test_world_threads.c (run under TSan). */
#include <math.h>
#include <stdint.h>

#include "world_fixture.h"
#include "world_scene.h"
#include "collision.h"
#include "fullsim.h"
#include "instance.h"
#include "instance_internal.h"
#include "rt_interpose.h"
#include "sinew/sinew_world.h"
#include "sw_test.h"
#include "world_penalty.h"

static double urand(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static float *rest_pose(int nb) {
    float *p = calloc((size_t)12 * nb, sizeof(float));
    for (int b = 0; b < nb; ++b)
        p[12 * b] = p[12 * b + 4] = p[12 * b + 8] = 1;
    return p;
}

/* ---- the law ------------------------------------------------------------------- */

TEST(world_penalty_derivatives_match_finite_differences) {
    uint64_t seed = 7;
    int regimes[4] = {0};
    for (int trial = 0; trial < 400; ++trial) {
        sw_world_pair p;
        double n2 = 0;
        for (int k = 0; k < 3; ++k) {
            p.a[k] = urand(&seed) - 0.5;
            p.n[k] = urand(&seed) - 0.5;
            n2 += p.n[k] * p.n[k];
        }
        for (int k = 0; k < 3; ++k)
            p.n[k] /= sqrt(n2);
        p.k = 10 + 100 * urand(&seed);
        p.cap = trial % 4 == 0 ? 0 : p.k * 0.05 * urand(&seed);
        double x[3], f[3], H[9];
        for (int k = 0; k < 3; ++k)
            x[k] = p.a[k] + 0.3 * (urand(&seed) - 0.5);
        sw_world_penalty(&p, x, f, H);
        double d[3] = {p.a[0] - x[0], p.a[1] - x[1], p.a[2] - x[2]}, g = sw_penalty_gap(p.n, d);
        double dt2 = 0;
        for (int k = 0; k < 3; ++k)
            dt2 += (d[k] - g * p.n[k]) * (d[k] - g * p.n[k]);
        double s = p.cap / (SW_CONTACT_ALPHA * p.k);
        /* stay off the kinks of max(g, 0) and of the stick/slide switch */
        if (fabs(g) < 1e-3 || fabs(sqrt(dt2) - s) < 1e-3) continue;
        regimes[(g > 0) + 2 * (p.cap > 0 && sqrt(dt2) > s)]++;
        const double h = 1e-6;
        for (int j = 0; j < 3; ++j) {
            double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]}, fp[3], fm[3];
            xp[j] += h;
            xm[j] -= h;
            double Ep = sw_world_penalty(&p, xp, fp, NULL), Em = sw_world_penalty(&p, xm, fm, NULL);
            ENSURE_NEAR(-(Ep - Em) / (2 * h), f[j], 1e-6 * p.k);
            for (int i = 0; i < 3; ++i) /* H = d2E/dx2 = -df/dx */
                ENSURE_NEAR(-(fp[i] - fm[i]) / (2 * h), H[3 * i + j], 1e-5 * p.k);
        }
        /* convex: x^T H x >= 0 */
        for (int i = 0; i < 3; ++i)
            ENSURE(H[4 * i] >= -1e-12 * p.k);
    }
    fprintf(stderr, "    regimes: apart %d, pressed %d, sliding apart %d, sliding pressed %d\n",
            regimes[0], regimes[1], regimes[2], regimes[3]);
    ENSURE(regimes[1] > 10 && regimes[3] > 10 && regimes[0] > 10);
}

/* ---- the step ------------------------------------------------------------------ */

TEST(reduced_world_gradient_and_hessian_match_finite_differences) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.5f, &id);
    ENSURE(w);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_world(inst, w) == SINEW_OK);
    float *pose = rest_pose(f->ch.skel.nbones);
    ENSURE(sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    sinew_instance_get_stats(inst, &st);
    fprintf(stderr, "    candidates %u, in contact %u, queries %u\n", st.world_candidates,
            st.world_contacts, st.world_queries);
    ENSURE(st.world_candidates > 10 && st.world_contacts > 10);
    sw_reduced *red = &inst->red;
    int32_t R = red->R;
    double *q = malloc(sizeof(double) * R), *g = malloc(sizeof(double) * R),
           *H = malloc(sizeof(double) * R * R), *gp = malloc(sizeof(double) * R),
           *gm = malloc(sizeof(double) * R);
    memcpy(q, inst->solver.q, sizeof(double) * R);
    /* the world part alone, at the solution and with it pushed deeper */
    for (int32_t i = 0; i < R; ++i)
        q[i] *= 0.8;
    memset(red->g, 0, sizeof(double) * R);
    memset(red->H, 0, sizeof(double) * R * R);
    sw_world_contact_eval(red, &inst->wc, q, 1, 1);
    memcpy(g, red->g, sizeof(double) * R);
    memcpy(H, red->H, sizeof(double) * R * R);
    double gmax = 0, hmax = 0;
    for (int32_t i = 0; i < R; ++i) {
        gmax = fmax(gmax, fabs(g[i]));
        for (int32_t j = 0; j < R; ++j)
            hmax = fmax(hmax, fabs(H[(int64_t)i * R + j]));
    }
    ENSURE(gmax > 0 && hmax > 0);
    const double h = 1e-6;
    for (int32_t j = 0; j < R; ++j) {
        double qj = q[j];
        q[j] = qj + h;
        memset(red->g, 0, sizeof(double) * R);
        double Ep = sw_world_contact_eval(red, &inst->wc, q, 1, 0);
        memcpy(gp, red->g, sizeof(double) * R);
        q[j] = qj - h;
        memset(red->g, 0, sizeof(double) * R);
        double Em = sw_world_contact_eval(red, &inst->wc, q, 1, 0);
        memcpy(gm, red->g, sizeof(double) * R);
        q[j] = qj;
        ENSURE_NEAR((Ep - Em) / (2 * h), g[j], 1e-5 * gmax + 1e-9);
        for (int32_t i = 0; i < R; ++i)
            ENSURE_NEAR((gp[i] - gm[i]) / (2 * h), H[(int64_t)i * R + j], 1e-4 * hmax);
    }
    free(q), free(g), free(H), free(gp), free(gm), free(pose);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

/* The lowest output surface vertex (the finger's underside). */
static double surface_min_y(const sinew_instance *inst) {
    double y = INFINITY;
    const double *x = sw_instance_surface(inst);
    for (int32_t i = 0; i < inst->v->nsurf_verts; ++i)
        y = fmin(y, x[3 * i + 1]);
    return y;
}

/* Deepest penetration of the output surface into the world's colliders. */
static double surface_penetration(const sinew_instance *inst, const sinew_world *w) {
    return sw_world_max_penetration(w, inst->v->nsurf_verts, sw_instance_surface(inst), NULL, NULL,
                                    NULL);
}

TEST(world_contact_pushes_the_flesh_out_and_readback_sums_the_forces) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.0f, &id);
    ENSURE(w);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    float *pose = rest_pose(f->ch.skel.nbones);
    sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    double pen_free = surface_penetration(inst, w); /* not attached: the flesh goes through */
    double low_free = surface_min_y(inst);
    ENSURE(sinew_instance_set_world(inst, w) == SINEW_OK);
    for (int k = 0; k < 3; ++k)
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    double pen = surface_penetration(inst, w), low = surface_min_y(inst);
    /* In the subspace alone the flesh locks (thesis Fig. 4.2): a basis trained on folds
     * cannot flatten the underside, so the solve lowers the contact energy as far as it
     * can while the deepest vertex stays where it was (measured at 2K tets: 0.067 deep
     * without the world, 0.070 with it; condensation is what removes it). The contact
     * must still act: the world energy at the solution is below that of the skinned
     * shape (q = 0), by a clear margin. */
    int32_t R = inst->red.R;
    double *zero = calloc((size_t)R, sizeof(double));
    double e_skin = sw_world_contact_eval(&inst->red, &inst->wc, zero, 0, 0),
           e_sol = sw_world_contact_eval(&inst->red, &inst->wc, inst->solver.q, 0, 0);
    free(zero);
    fprintf(stderr,
            "    penetration without the world %.4f, with it %.4f; lowest point %.4f -> %.4f; "
            "world energy skinned %.2f, solved %.2f\n",
            pen_free, pen, low_free, low, e_skin, e_sol);
    ENSURE(pen_free > 0.06);
    ENSURE(e_sol < 0.95 * e_skin);
    /* readback: minus the sum of the copies' forces, torque about the box centre */
    float F[3], M[3];
    ENSURE(sinew_instance_collider_force(inst, id, F, M) == SINEW_OK);
    double Fs[3] = {0, 0, 0}, Ms[3] = {0, 0, 0}, o[3] = {1.8, -0.44 + 0.08 - 0.2, 0};
    for (int32_t j = 0; j < inst->wc.ncand; ++j) {
        const sw_world_cand *cd = &inst->wc.cand[j];
        double r[3], fc[3] = {-cd->f[0], -cd->f[1], -cd->f[2]};
        for (int k = 0; k < 3; ++k) {
            Fs[k] += fc[k];
            r[k] = cd->law.a[k] - o[k];
        }
        Ms[0] += r[1] * fc[2] - r[2] * fc[1];
        Ms[1] += r[2] * fc[0] - r[0] * fc[2];
        Ms[2] += r[0] * fc[1] - r[1] * fc[0];
    }
    for (int k = 0; k < 3; ++k) {
        ENSURE_NEAR(F[k], Fs[k], 1e-5 * fabs(Fs[1]) + 1e-6);
        ENSURE_NEAR(M[k], Ms[k], 1e-4 * (fabs(Ms[0]) + fabs(Ms[2])) + 1e-5);
    }
    /* frictionless, on the top face: the flesh pushes the table down */
    ENSURE(F[1] < 0 && fabs(F[0]) < 1e-3 * fabs(F[1]) && fabs(F[2]) < 1e-3 * fabs(F[1]));
    /* a collider that is not touched, and a stale id */
    sinew_collider_def far = sinew_collider_def_default();
    far.shape = SINEW_SHAPE_SPHERE;
    far.radius = 0.1f;
    far.transform.position[1] = 50;
    sinew_collider_id fid;
    ENSURE(sinew_world_add_collider(w, &far, &fid) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    ENSURE(sinew_instance_collider_force(inst, fid, F, M) == SINEW_OK);
    ENSURE(F[0] == 0 && F[1] == 0 && F[2] == 0 && M[0] == 0);
    ENSURE(sinew_world_remove_collider(w, fid) == SINEW_OK);
    ENSURE(sinew_instance_collider_force(inst, fid, F, M) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_collider_force(inst, id, NULL, M) == SINEW_ERROR_INVALID_ARGUMENT);
    /* detached: no candidates, the flesh goes through again */
    ENSURE(sinew_instance_set_world(inst, NULL) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
    sinew_step_stats st;
    st.struct_size = sizeof st;
    sinew_instance_get_stats(inst, &st);
    ENSURE(st.world_candidates == 0 && st.world_queries == 0);
    free(pose);
    sinew_instance_destroy(inst);
    sinew_world_destroy(w);
}

TEST(world_steps_allocate_and_lock_nothing) {
    moving_scene m;
    ENSURE(moving_scene_make(&m));
    unsigned active = sw_rt_interpose_active();
    const bake_fixture *f = m.f;
    uint32_t nb = (uint32_t)f->ch.skel.nbones, ns = sinew_blob_surface_vertex_count(f->blob);
    int frames = f->ch.clip.nframes;
    for (int mode = 0; mode < 2; ++mode) {
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = mode ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        sinew_instance *inst;
        ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
        ENSURE(sinew_instance_set_world(inst, m.w) == SINEW_OK);
        float *poses = malloc(sizeof(float) * 12 * nb * frames),
              *x = malloc(sizeof(float) * 3 * ns);
        for (int k = 0; k < frames; ++k)
            bake_fixture_pose(f, k, poses + (size_t)12 * nb * k);
        sinew_step_stats st;
        st.struct_size = sizeof st;
        uint64_t contacts = 0, queries = 0;
        float F[3], M[3];
        sw_rt_count_begin();
        for (int s = 0; s < 10000; ++s) {
            sinew_transform t;
            ball_at(s, &t);
            sinew_world_set_collider_transform(m.w, m.ball, &t);
            sinew_instance_set_pose(inst, poses + (size_t)12 * nb * (s % frames), nb);
            sinew_instance_step(inst, 1.0f / 30);
            sinew_instance_read_surface(inst, x, NULL, ns);
            sinew_instance_get_stats(inst, &st);
            sinew_instance_collider_force(inst, m.ball, F, M);
            contacts += st.world_contacts;
            queries += st.world_queries;
        }
        sw_rt_counts c = sw_rt_count_end();
        char buf[512];
        fprintf(stderr, "    %s, 10000 steps: %s; %.1f contacts, %.1f queries a step\n",
                mode ? "dynamic" : "quasistatic", sw_rt_counts_describe(&c, buf, sizeof buf),
                contacts / 1e4, queries / 1e4);
        ENSURE(contacts > 10000); /* world contact really was active */
        if (active & SW_RT_CAT_ALLOCS) ENSUREF(c.allocs == 0, "%s", buf);
        if (active & SW_RT_CAT_FREES) ENSUREF(c.frees == 0, "%s", buf);
        if (active & SW_RT_CAT_MAPS) ENSUREF(c.maps == 0, "%s", buf);
        if (active & SW_RT_CAT_LOCKS) ENSUREF(c.locks == 0, "%s", buf);
        free(poses);
        free(x);
        sinew_instance_destroy(inst);
    }
    sinew_world_destroy(m.w);
}

/* ---- the reference ------------------------------------------------------------- */

TEST(reference_pushes_the_flesh_out_of_a_box) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    ENSURE(w);
    sw_fullsim_params p = sw_fullsim_params_default();
    p.world = w;
    p.threads = 2;
    sw_fullsim *sim;
    sw_error err;
    ENSURE(sw_fullsim_create(&f->ch, &p, &sim, &err) == SINEW_OK);
    int nb = f->ch.skel.nbones;
    double *T = calloc((size_t)12 * nb, sizeof(double));
    for (int b = 0; b < nb; ++b)
        T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
    sw_fullsim_stats st;
    sinew_result r = sw_fullsim_step(sim, T, &st);
    fprintf(stderr,
            "    reference: %s, %d Newton, %d rounds, %d candidates, %d in contact, "
            "penetration %.5f\n",
            sinew_result_string(r), st.newton_iters, st.contact_rounds, st.world_candidates,
            st.world_contacts, st.world_penetration);
    ENSURE(r == SINEW_OK);
    ENSURE(st.world_contacts > 10);
    /* the finger's thickness is 0.9: within 1% of it */
    ENSURE(st.world_penetration < 0.009);
    ENSURE(!st.contacts_unsettled);
    free(T);
    sw_fullsim_destroy(sim);
    sinew_world_destroy(w);
}

/* The shipped world files build their worlds, and the finger's table scene runs in the
 * step and in the reference: contact once the table has risen, no failed step. */
TEST(sample_worlds_run_in_the_step_and_the_reference) {
    static const char *names[] = {"finger_table", "capsule_pipe", "hand_handle", "finger_props"};
    for (int i = 0; i < 4; ++i) {
        char path[1024];
        snprintf(path, sizeof path, "%s/samples/worlds/%s.json", SINEW_SOURCE_DIR, names[i]);
        sw_world_scene ws;
        sw_error err;
        ENSUREF(sw_world_scene_load(path, &ws, &err) == SINEW_OK, "%s", err.msg);
        ENSURE(sinew_world_collider_count(ws.world) == (uint32_t)ws.file.ncolliders);
        sw_world_scene_free(&ws);
    }
    const bake_fixture *f = fixture();
    ENSURE(f);
    char path[1024];
    snprintf(path, sizeof path, "%s/samples/worlds/finger_table.json", SINEW_SOURCE_DIR);
    sw_world_scene ws;
    sw_error err;
    ENSURE(sw_world_scene_load(path, &ws, &err) == SINEW_OK);
    int nf;
    double *T =
        sw_world_scene_poses(&ws, f->ch.clip.T, f->ch.clip.nframes, f->ch.skel.nbones, 0, &nf);
    ENSURE(T && nf == 30); /* "pose": "rest", "frames": 30 */
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_world(inst, ws.world) == SINEW_OK);
    sw_fullsim_params p = sw_fullsim_params_default();
    p.world = ws.world;
    p.threads = 2;
    sw_fullsim *sim;
    ENSURE(sw_fullsim_create(&f->ch, &p, &sim, &err) == SINEW_OK);
    uint32_t sub_touch = 0;
    double pen_full = 0;
    int full_touch = 0;
    for (int k = 0; k < nf; k += 4) {
        ENSURE(sw_world_scene_at(&ws, k, &err) == SINEW_OK);
        sw_instance_set_pose_d(inst, T + (size_t)k * 12 * f->ch.skel.nbones);
        ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
        sinew_step_stats st;
        st.struct_size = sizeof st;
        sinew_instance_get_stats(inst, &st);
        sw_fullsim_stats fs;
        sinew_result r = sw_fullsim_step(sim, T + (size_t)k * 12 * f->ch.skel.nbones, &fs);
        ENSURE(r == SINEW_OK || r == SINEW_ERROR_NOT_CONVERGED);
        if (k >= 20) {
            sub_touch += st.world_contacts;
            full_touch += fs.world_contacts;
        }
        pen_full = fmax(pen_full, fs.world_penetration);
    }
    fprintf(stderr,
            "    finger_table: contacts after the rise: step %u, reference %d; reference "
            "penetration %.5f\n",
            sub_touch, full_touch, pen_full);
    ENSURE(sub_touch > 0 && full_touch > 0);
    ENSURE(pen_full < 0.009); /* 1% of the finger's thickness */
    free(T);
    sw_fullsim_destroy(sim);
    sinew_instance_destroy(inst);
    sw_world_scene_free(&ws);
}

/* The sample world of a mesh and a hull (finger_props.json) moving along the finger while
 * it plays its clip: both colliders press it, with and without a condensation patch, no
 * step fails, and the patch keeps the tent's apex out of the flesh where the subspace
 * cannot dent it (thesis §4.3). */
TEST(a_sample_world_of_a_mesh_and_a_hull_presses_the_finger) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    char path[1024];
    snprintf(path, sizeof path, "%s/samples/worlds/finger_props.json", SINEW_SOURCE_DIR);
    sw_world_scene ws;
    sw_error err;
    ENSUREF(sw_world_scene_load(path, &ws, &err) == SINEW_OK, "%s", err.msg);
    int nf;
    double *T =
        sw_world_scene_poses(&ws, f->ch.clip.T, f->ch.clip.nframes, f->ch.skel.nbones, 0, &nf);
    ENSURE(T && nf > 0); /* the clip's frames, played round while the colliders move */
    uint32_t ns = sinew_blob_surface_vertex_count(f->blob);
    double *x = malloc(sizeof(double) * 3 * ns);
    ENSURE(x);
    double pen_of[2] = {0, 0};
    for (int patch = 0; patch < 2; ++patch) {
        sinew_instance_def d = sinew_instance_def_default();
        d.max_patch_vertices = patch ? 300 : 0;
        sinew_instance *inst;
        ENSURE(sinew_instance_create(f->blob, &d, &inst) == SINEW_OK);
        ENSURE(sinew_instance_set_world(inst, ws.world) == SINEW_OK);
        double push[2] = {0, 0}, pen = 0;
        uint32_t largest = 0;
        for (int k = 0; k < nf; ++k) {
            ENSURE(sw_world_scene_at(&ws, k, &err) == SINEW_OK);
            ENSURE(sw_instance_set_pose_d(inst, T + (size_t)k * 12 * f->ch.skel.nbones) ==
                   SINEW_OK);
            ENSURE(sinew_instance_step(inst, 1.0f / 30) == SINEW_OK);
            for (int c = 0; c < 2; ++c) {
                float F[3], M[3];
                ENSURE(sinew_instance_collider_force(inst, ws.ids[c], F, M) == SINEW_OK);
                push[c] += fabsf(F[0]) + fabsf(F[1]) + fabsf(F[2]);
            }
            sinew_step_stats st = {.struct_size = sizeof st};
            ENSURE(sinew_instance_get_stats(inst, &st) == SINEW_OK);
            if (st.patch_vertices > largest) largest = st.patch_vertices;
            memcpy(x, sw_instance_surface(inst), sizeof(double) * 3 * ns);
            pen = fmax(pen, sw_world_max_penetration(ws.world, (int32_t)ns, x, NULL, NULL, NULL));
        }
        fprintf(stderr,
                "  patch budget %d: forces on the tent %g, the wedge %g; deepest %.4f; "
                "largest patch %u\n",
                d.max_patch_vertices, push[0], push[1], pen, largest);
        ENSUREF(push[0] > 0 && push[1] > 0, "the tent felt %g, the wedge %g", push[0], push[1]);
        pen_of[patch] = pen;
        ENSURE(!patch || largest > 0);
        sinew_instance_destroy(inst);
    }
    /* the tent's apex dents the flesh where the subspace cannot: the patch holds it to 2%
       of the finger's thickness, and a third of the subspace's depth at most */
    ENSUREF(pen_of[1] < 0.018 && pen_of[1] < pen_of[0] / 3,
            "deepest: %g in the subspace, %g with the patch", pen_of[0], pen_of[1]);
    free(x);
    free(T);
    sw_world_scene_free(&ws);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
    fx_ok = -1;
}

SW_TEST_MAIN(CASE(world_penalty_derivatives_match_finite_differences),
             CASE(reduced_world_gradient_and_hessian_match_finite_differences),
             CASE(world_contact_pushes_the_flesh_out_and_readback_sums_the_forces),
             CASE(world_steps_allocate_and_lock_nothing),
             CASE(reference_pushes_the_flesh_out_of_a_box),
             CASE(sample_worlds_run_in_the_step_and_the_reference),
             CASE(a_sample_world_of_a_mesh_and_a_hull_presses_the_finger), CASE(release_fixture))
