/* Exhaustive subspace self-contact (runtime/contact/self_contact.h): the
 * runtime detects the very pairs the full-space reference detects at the same positions
 * (the blob's tet boundary, rest measures and area weights against the reference's own,
 * built from the character's mesh); the step's potential with those pairs matches its
 * finite differences; a blob without the tet mesh is refused with a message. The step's
 * real-time contract in this mode is test_step_contract's "exhaustive" path. */
#include <math.h>
#include <stdint.h>

#include "bake_fixture.h"
#include "instance.h"
#include "instance_internal.h"
#include "mesh_io.h"
#include "selfcontact.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

/* The folding finger at 2,000 tets with a 12-frame clip. */
static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

static sinew_instance *exhaustive_instance(const bake_fixture *f) {
    sinew_instance_def d = sinew_instance_def_default();
    d.self_contact = SINEW_SELF_CONTACT_EXHAUSTIVE;
    sinew_instance *in = NULL;
    return sinew_instance_create(f->blob, &d, &in) == SINEW_OK ? in : NULL;
}

TEST(the_runtime_detects_the_references_pairs) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *in = exhaustive_instance(f);
    ENSURE(in);
    sw_surface surf;
    sw_selfcontact *ref = NULL;
    sw_error err;
    ENSURE(sw_tetmesh_surface(&f->ch.mesh, &surf, &err) == SINEW_OK);
    ENSURE(sw_selfcontact_create(&f->ch.mesh, &surf, SW_SELF_NEIGHBOUR_FACTOR, 0, &ref, &err) ==
           SINEW_OK);
    const sw_self_contacts *sc = &in->sc;
    int32_t total = 0, nb = f->ch.skel.nbones;
    for (int k = 0; k < f->ch.clip.nframes; ++k) {
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        /* the step's last detection ran at its solution, x; the reference at the same x */
        int32_t n = sw_selfcontact_detect(ref, sc->x, NULL);
        const sw_contact *c = sw_selfcontact_list(ref, NULL);
        ENSUREF(n == sc->npairs, "frame %d: the reference finds %d pairs, the runtime %d", k, n,
                sc->npairs);
        for (int32_t i = 0; i < n; ++i) {
            const int32_t *act = sc->act + 4 * i;
            const double *d = sc->data + 7 * i, *R = sc->vR + 9 * (int64_t)c[i].p;
            ENSUREF(act[0] == c[i].p && act[1] == c[i].tri[0] && act[2] == c[i].tri[1] &&
                        act[3] == c[i].tri[2],
                    "frame %d pair %d: vertex %d triangle (%d %d %d) against the reference's "
                    "%d (%d %d %d)",
                    k, i, act[0], act[1], act[2], act[3], c[i].p, c[i].tri[0], c[i].tri[1],
                    c[i].tri[2]);
            for (int j = 0; j < 3; ++j) {
                ENSURE_NEAR(d[j], c[i].beta[j], 1e-12);
                /* the stored normal is in p's un-skinned frame: R_p of it is the reference's */
                double n_world = R[3 * j] * d[3] + R[3 * j + 1] * d[4] + R[3 * j + 2] * d[5];
                ENSURE_NEAR(n_world, c[i].n[j], 1e-12);
            }
            ENSURE_NEAR(d[6], c[i].ka, 1e-12 * c[i].ka);
            /* each slot's copy is a copy of its vertex */
            for (int m = 0; m < 4; ++m) {
                const int32_t *cv = sc->verts + 8 * i + 2 * m;
                const sw_blob_domain *D = &in->v->domains[cv[0]];
                ENSURE(in->v->domain_verts[D->vert_begin + cv[1]] == act[m]);
            }
        }
        total += n;
    }
    fprintf(stderr, "    %d pairs over the clip, each the reference's\n", total);
    ENSUREF(total > 0, "the fold never touched: the test proves nothing");
    sw_selfcontact_destroy(ref);
    sw_surface_free(&surf);
    sinew_instance_destroy(in);
}

TEST(the_potential_with_detected_pairs_matches_finite_differences) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *in = exhaustive_instance(f);
    ENSURE(in);
    int32_t nb = f->ch.skel.nbones, R = in->red.R, best = -1, most = 0;
    for (int k = 0; k < f->ch.clip.nframes; ++k) { /* the frame with the most pairs */
        ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)k * 12 * nb) == SINEW_OK);
        ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
        if (in->sc.npairs > most) most = in->sc.npairs, best = k;
    }
    ENSUREF(best >= 0, "no frame with self-contact");
    ENSURE(sw_instance_set_pose_d(in, f->ch.clip.T + (size_t)best * 12 * nb) == SINEW_OK);
    ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
    double *q = malloc(sizeof(double) * R), *g = malloc(sizeof(double) * R);
    ENSURE(q && g);
    memcpy(q, in->solver.q, sizeof(double) * R);
    /* the pairs' energy at the solution: some pair still presses (penalty contact) */
    sw_pair_set set = sw_self_contacts_pairs(&in->sc);
    double e_pairs =
        sw_contact_pairs_eval(&in->red, &set, NULL, NULL, in->sc.npairs, NULL, NULL, q, 0, 0);
    ENSUREF(e_pairs > 0, "frame %d: %d pairs, none pressing", best, in->sc.npairs);
    double e = sw_instance_step_potential(in, 1.0f / 30, q, g, NULL, 0), gmax = 0;
    ENSURE(isfinite(e));
    for (int32_t i = 0; i < R; ++i)
        gmax = fmax(gmax, fabs(g[i]));
    for (int32_t i = 0; i < R; ++i) {
        double h = 1e-6, qi = q[i];
        q[i] = qi + h;
        double ep = sw_instance_step_potential(in, 1.0f / 30, q, NULL, NULL, 0);
        q[i] = qi - h;
        double em = sw_instance_step_potential(in, 1.0f / 30, q, NULL, NULL, 0);
        q[i] = qi;
        ENSUREF(fabs((ep - em) / (2 * h) - g[i]) <= 1e-5 * gmax + 1e-8,
                "coordinate %d: finite difference %.9g, gradient %.9g", i, (ep - em) / (2 * h),
                g[i]);
    }
    fprintf(stderr, "    frame %d: %d pairs, their energy %.3g of %.3g\n", best, in->sc.npairs,
            e_pairs, e);
    free(q);
    free(g);
    sinew_instance_destroy(in);
}

TEST(a_blob_without_the_tet_mesh_is_refused) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sw_blob_view v = f->res.view; /* the same character, written without its tet mesh */
    v.ntets = v.nvert_tets = 0;
    v.tets = v.tet_domain = v.tet_local = v.vert_tet_ptr = v.vert_tets = v.cub_tet_id = NULL;
    v.tet_dminv = v.tet_vol = v.vert_mass = NULL;
    void *data = NULL;
    size_t size = 0;
    sw_error err;
    ENSURE(sw_blob_write_memory(&v, &data, &size, &err) == SINEW_OK);
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = data;
    bd.data_size = size;
    sinew_blob *blob = NULL;
    ENSURE(sinew_blob_load(&bd, &blob) == SINEW_OK);
    sinew_instance_def d = sinew_instance_def_default();
    d.self_contact = SINEW_SELF_CONTACT_EXHAUSTIVE;
    sinew_instance *in = NULL;
    size_t bytes = 0;
    ENSURE(sinew_instance_memory_size(blob, &d, &bytes) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_instance_create(blob, &d, &in) == SINEW_ERROR_INVALID_ARGUMENT && !in);
    d.self_contact = (sinew_self_contact)7; /* no such mode, on any blob */
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_ERROR_INVALID_ARGUMENT && !in);
    d.self_contact = SINEW_SELF_CONTACT_POSE_SPACE; /* the default mode needs no tet mesh */
    ENSURE(sinew_instance_create(blob, &d, &in) == SINEW_OK);
    sinew_instance_destroy(in);
    sinew_blob_destroy(blob);
    free(data);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(the_runtime_detects_the_references_pairs),
             CASE(the_potential_with_detected_pairs_matches_finite_differences),
             CASE(a_blob_without_the_tet_mesh_is_refused), CASE(release_fixture))
