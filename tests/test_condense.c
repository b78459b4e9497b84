/* Subspace condensation (runtime/condense): the coupled potential's gradient
 * against finite differences and its Hessian symmetric and PSD; the partition oracle
 * against a brute-force growth; the budget's cut; the flesh denting where the subspace
 * locks, closer to the reference; bitwise the subspace without contact; the real-time
 * contract; the def's checks. The finger of world_fixture.h pressed into a table. */
#include <math.h>
#include <stdint.h>

#include "collision.h"
#include "condense.h"
#include "fem_corot.h"
#include "fullsim.h"
#include "instance.h"
#include "instance_internal.h"
#include "rt_interpose.h"
#include "sw_test.h"
#include "world_fixture.h"

#define RHO 0.08 /* of the diagonal: about 0.3 on the 3.6-long finger */
/* A radius whose patch covers most of a domain: its other tets are evaluated at q */
#define RHO_WIDE 0.35

static float *rest_pose(int nb) {
    float *p = calloc((size_t)12 * nb, sizeof(float));
    for (int b = 0; b < nb; ++b)
        p[12 * b] = p[12 * b + 4] = p[12 * b + 8] = 1;
    return p;
}

/* A condensed instance of the fixture on world w at the rest pose, patch radius rho,
 * stepped `steps` times. */
static sinew_instance *pressed_rho(const bake_fixture *f, sinew_world *w, uint32_t budget,
                                   int steps, double rho) {
    sinew_instance_def d = sinew_instance_def_default();
    d.max_patch_vertices = budget;
    d.patch_radius = (float)rho;
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return NULL;
    if (w) sinew_instance_set_world(inst, w);
    float *pose = rest_pose(f->ch.skel.nbones);
    sinew_instance_set_pose(inst, pose, (uint32_t)f->ch.skel.nbones);
    for (int k = 0; k < steps; ++k)
        if (sinew_instance_step(inst, 1.0f / 30) != SINEW_OK) break;
    free(pose);
    return inst;
}

static sinew_instance *pressed(const bake_fixture *f, sinew_world *w, uint32_t budget, int steps) {
    return pressed_rho(f, w, budget, steps, RHO);
}

/* An instance whose patch may hold every vertex (radius the whole mesh), stepped steps times. */
static sinew_instance *whole_mesh_patch(const bake_fixture *f, sinew_world *w, int steps) {
    return pressed_rho(f, w, (uint32_t)f->ch.mesh.nverts, steps, 1.0);
}

/* An instance pressed onto the table for one step and prepared for the next, its patch
 * of radius rho set (the world into *w). */
static sinew_instance *prepared_on_table(sinew_world **w, double rho) {
    const bake_fixture *f = fixture();
    if (!f) return NULL;
    sinew_collider_id id;
    *w = table_world(0.08, 0.3f, &id);
    sinew_instance *in = *w ? pressed_rho(f, *w, 2000, 1, rho) : NULL;
    if (in) sw_instance_step_prepare(in, 1.0f / 30);
    return in;
}

/* At both radii: with a wide patch, the rest of the domains it mostly covers is part of
 * the potential (at q), and its Hessian is in the reduced block of the product. */
TEST(coupled_gradient_matches_finite_differences_and_its_hessian_is_psd) {
    for (int wide = 0; wide < 2; ++wide) {
        sinew_world *w = NULL;
        sinew_instance *in = prepared_on_table(&w, wide ? RHO_WIDE : RHO);
        ENSURE(in);
        sw_cond *c = &in->cond;
        ENSURE(c->nf > 10 && c->nt > c->nf && c->nring > 0);
        ENSURE((c->nrest > 0) == wide);
        int32_t R = in->red.R, nx = 3 * c->nf;
        sw_step_contacts ct = {&in->ps, &in->wc, NULL, NULL};
        sw_dyn_coef dc = {1.0 / 30, 0, 0, 0, 0, 0};
        sw_cond_weights_apply(c);
        double *q = malloc(sizeof(double) * R), *x = malloc(sizeof(double) * nx);
        double *g = malloc(sizeof(double) * (R + nx));
        memcpy(q, in->solver.q, sizeof(double) * R);
        for (int32_t i = 0; wide && i < R; ++i) /* the rest strained (at the step's q it rests) */
            q[i] += 0.05 * cos(2.3 * i);
        for (int32_t i = 0; i < nx; ++i) /* off the start: some tets stretched, some contact */
            x[i] = c->x[i] + 0.01 * sin(1.7 * i);
        sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 1);
        memcpy(g, in->red.g, sizeof(double) * R);
        memcpy(g + R, c->gf, sizeof(double) * nx);
        double gmax = 0;
        for (int32_t i = 0; i < R + nx; ++i)
            gmax = fmax(gmax, fabs(g[i]));
        int checked = 0;
        for (int32_t i = 0; i < R + nx; i += (i < R ? 1 : 1 + nx / 40)) {
            double *p = i < R ? q + i : x + (i - R), keep = *p, h = 1e-6;
            *p = keep + h;
            double ep = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
            *p = keep - h;
            double em = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
            *p = keep;
            ENSURE_NEAR((ep - em) / (2 * h), g[i], 1e-5 * gmax + 1e-4 * fabs(g[i]));
            checked++;
        }
        ENSURE(checked > R + 20);
        if (wide) { /* the rest's part of Phi: its tets' energies at their subspace positions */
            const sw_blob_view *v = c->v;
            double with = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
            int32_t nrest = c->nrest;
            c->nrest = 0;
            double without = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
            c->nrest = nrest;
            double brute = 0;
            for (int32_t e = c->nt + c->np; e < c->nt + c->np + nrest; ++e) {
                int32_t t = c->ft[e];
                double x12[12], f12[12], dm[9];
                for (int k = 0; k < 4; ++k)
                    sw_cond_copy_position(&in->red, v->tets[4 * t + k], v->tet_domain[t],
                                          v->tet_local[4 * t + k], q, x12 + 3 * k, NULL);
                brute += sw_corot_eval(x12, sw_blob_tet_dminv(v, t, dm), v->tet_vol[t], v->mu,
                                       v->lambda, f12, NULL, SW_COROT_PROJECT_PSD);
            }
            fprintf(stderr, "    Phi %.9g, of it the rest's %d tets %.9g (by brute force %.9g)\n",
                    with, nrest, with - without, brute);
            ENSURE(brute > 0);
            ENSURE_NEAR(with - without, brute, 1e-9 * (fabs(with) + brute));
        }
        /* the Hessian of the last evaluation with Hessian: symmetric, positive semi-definite */
        sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 1);
        sw_cond_system S = {c, &in->red, &in->solver};
        double *a = malloc(sizeof(double) * (R + nx)), *b = malloc(sizeof(double) * (R + nx));
        double *Ha = malloc(sizeof(double) * (R + nx)), *Hb = malloc(sizeof(double) * (R + nx));
        for (int32_t i = 0; i < R + nx; ++i) {
            a[i] = cos(0.3 * i + 1);
            b[i] = sin(0.7 * i);
        }
        sw_cond_hessian_apply(&S, a, Ha);
        sw_cond_hessian_apply(&S, b, Hb);
        double bHa = 0, aHb = 0, aHa = 0, scale = 0;
        for (int32_t i = 0; i < R + nx; ++i) {
            bHa += b[i] * Ha[i];
            aHb += a[i] * Hb[i];
            aHa += a[i] * Ha[i];
            scale += fabs(a[i] * Ha[i]) + fabs(b[i] * Hb[i]);
        }
        fprintf(
            stderr,
            "    patch %d vertices, %d tets (%d more at q), %d ring copies; b'Ha %.6g a'Hb %.6g "
            "a'Ha %.6g\n",
            c->nf, c->nt, c->nrest, c->nring, bHa, aHb, aHa);
        ENSURE_NEAR(bHa, aHb, 1e-10 * scale);
        ENSURE(aHa > 0);
        sw_cond_weights_restore(c);
        free(q), free(x), free(g), free(a), free(b), free(Ha), free(Hb);
        sinew_instance_destroy(in);
        sinew_world_destroy(w);
    }
}

/* Eq. 4.12 against a brute-force projection of full-space forces. Tet t of domain d with
 * its corners at x12 (a patch vertex at its patch position when `patch` is set, any other
 * at its domain copy's subspace position): its corot forces, times w, projected through
 * the free corners' rows J = R U into g (rank_total). */
static void project_tet(sinew_instance *in, const double *q, const double *x, int32_t t, double w,
                        int patch, double *g) {
    const sw_cond *c = &in->cond;
    const sw_blob_view *v = c->v;
    const int32_t d = v->tet_domain[t], r = v->domains[d].rank;
    double x12[12], f12[12], J[4][3 * 128];
    int free_corner[4];
    for (int k = 0; k < 4; ++k) {
        int32_t gv = v->tets[4 * t + k];
        int in_patch = patch && sw_cond_position(c, gv);
        free_corner[k] = !in_patch;
        if (in_patch)
            memcpy(x12 + 3 * k, x + 3 * (int64_t)c->vloc[gv], 3 * sizeof(double));
        else
            sw_cond_copy_position(&in->red, gv, d, v->tet_local[4 * t + k], q, x12 + 3 * k, J[k]);
    }
    double dm[9];
    sw_corot_eval(x12, sw_blob_tet_dminv(v, t, dm), v->tet_vol[t], v->mu, v->lambda, f12, NULL,
                  SW_COROT_PROJECT_PSD);
    for (int k = 0; k < 4; ++k)
        for (int32_t j = 0; free_corner[k] && j < r; ++j)
            g[v->domains[d].q_offset + j] -=
                w * (J[k][j] * f12[3 * k] + J[k][r + j] * f12[3 * k + 1] +
                     J[k][2 * r + j] * f12[3 * k + 2]);
}

/* |a - b| / |b| over n. */
static double rel_gap(const double *a, const double *b, int32_t n) {
    double d2 = 0, n2 = 0;
    for (int32_t i = 0; i < n; ++i) {
        d2 += (a[i] - b[i]) * (a[i] - b[i]);
        n2 += b[i] * b[i];
    }
    return n2 > 0 ? sqrt(d2 / n2) : INFINITY;
}

/* The coupled potential's reduced gradient at (q, x) less the springs' (H_s q): its
 * material part, eq. 4.12 (no contact and no equilibrium force), into g (rank_total). */
static void eq_412_gradient(sinew_instance *in, const double *q, const double *x, double *g) {
    sw_cond *c = &in->cond;
    const sw_blob_view *v = c->v;
    const int32_t R = in->red.R;
    sw_pose_space ps0 = in->ps;
    ps0.npairs = 0;
    ps0.force = NULL;
    sw_step_contacts ct = {&ps0, NULL, NULL, NULL};
    sw_dyn_coef dc = {1.0 / 30, 0, 0, 0, 0, 0};
    sw_cond_weights_apply(c);
    sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
    sw_cond_weights_restore(c);
    for (int32_t i = 0; i < R; ++i) {
        g[i] = in->red.g[i];
        for (int32_t j = 0; j < R; ++j)
            g[i] -= sw_blob_reduced_entry(v, SW_BLOB_SPRINGS, i, j) * q[j];
    }
}

/* Eq. 4.12 (the coupled potential's reduced gradient) is the boundary tets' full-space
 * forces projected through their ring copies' rows, plus the renormalised cubature of the
 * subspace, plus (a domain the patch mostly covers) the rest of its tets exactly:
 * assembled here by brute force from every such tet's corot forces and the copies' own
 * rows, on a strained state, it agrees to rounding. (How well the cubature stands for the
 * rest of the mesh is the bake's fit, tested with the cubature.) */
TEST(eq_4_12_matches_a_brute_force_projection_of_the_full_force) {
    for (int wide = 0; wide < 2; ++wide) {
        sinew_world *w = NULL;
        sinew_instance *in = prepared_on_table(&w, wide ? RHO_WIDE : RHO);
        ENSURE(in);
        sw_cond *c = &in->cond;
        const sw_blob_view *v = c->v;
        ENSURE(c->nf > 10 && c->nring > 0 && (c->nrest > 0) == wide);
        const int32_t R = in->red.R, nx = 3 * c->nf;
        double *q = malloc(sizeof(double) * R), *x = malloc(sizeof(double) * nx),
               *g = malloc(sizeof(double) * R), *gb = calloc((size_t)R, sizeof(double));
        ENSURE(q && x && g && gb);
        for (int32_t i = 0; i < R; ++i) /* strained along the modes, the patch off its start */
            q[i] = in->solver.q[i] + 0.05 * cos(2.3 * i);
        for (int32_t i = 0; i < nx; ++i)
            x[i] = c->x[i] + 0.01 * sin(1.7 * i);
        eq_412_gradient(in, q, x, g);
        sw_cond_weights_apply(c); /* the brute force: the same three sums, tet by tet */
        for (int32_t e = 0; e < c->nt; ++e)
            project_tet(in, q, x, c->ft[e], 1, 1, gb);
        for (int32_t i = 0; i < v->ncub; ++i)
            if (c->cub_w[i] > 0) project_tet(in, q, x, v->cub_tet_id[i], c->cub_w[i], 0, gb);
        for (int32_t e = c->nt + c->np; e < c->nt + c->np + c->nrest; ++e)
            project_tet(in, q, x, c->ft[e], 1, 0, gb);
        sw_cond_weights_restore(c);
        double gap = rel_gap(g, gb, R);
        fprintf(stderr,
                "    radius %g: patch %d vertices, %d full tets, %d at q; eq. 4.12 against its "
                "brute-force assembly %.2e\n",
                wide ? RHO_WIDE : RHO, c->nf, c->nt, c->nrest, gap);
        ENSUREF(gap < 1e-9, "eq. 4.12 is %g from its brute-force assembly", gap);
        free(q), free(x), free(g), free(gb);
        sinew_instance_destroy(in);
        sinew_world_destroy(w);
    }
}

/* Eq. 4.12's subspace part: each domain the patch reaches keeps its cubature scaled to
 * its volume outside the patch (the tets touching a patch vertex, found here by a scan
 * of every tet), the others keep theirs, and the solve's end restores them. */
TEST(cubature_weights_follow_each_domains_volume_outside_the_patch) {
    for (int wide = 0; wide < 2; ++wide) {
        sinew_world *w = NULL;
        sinew_instance *in = prepared_on_table(&w, wide ? RHO_WIDE : RHO);
        ENSURE(in);
        sw_cond *c = &in->cond;
        const sw_blob_view *v = c->v;
        ENSURE(c->nf > 0);
        double *vol = calloc((size_t)v->ndomains, sizeof(double));
        double *in_vol = calloc((size_t)v->ndomains, sizeof(double));
        unsigned char *touches = calloc((size_t)v->ntets, 1);
        for (int32_t t = 0; t < v->ntets; ++t) {
            for (int k = 0; k < 4; ++k)
                touches[t] |= sw_cond_position(c, v->tets[4 * t + k]) != NULL;
            vol[v->tet_domain[t]] += v->tet_vol[t];
            if (touches[t]) in_vol[v->tet_domain[t]] += v->tet_vol[t];
        }
        /* a domain more than SW_COND_EXACT_SHARE in the patch: each of its other tets is a
           rest element once, its four corners the ring copies of its own vertices */
        int32_t *seen = calloc((size_t)v->ntets, sizeof(int32_t)), nexact = 0, nrest = 0;
        for (int32_t e = c->nt + c->np; e < c->nt + c->np + c->nrest; ++e) {
            int32_t t = c->ft[e];
            seen[t]++;
            for (int k = 0; k < 4; ++k) {
                int32_t slot = c->ft_slot[4 * e + k];
                ENSURE(slot < 0 && c->ring_v[-1 - slot] == v->tets[4 * t + k] &&
                       c->ring_d[-1 - slot] == v->tet_domain[t]);
            }
        }
        for (int32_t k = 0; k < v->ndomains; ++k)
            nexact += in_vol[k] > SW_COND_EXACT_SHARE * vol[k];
        for (int32_t t = 0; t < v->ntets; ++t) {
            int32_t k = v->tet_domain[t];
            int rest = !touches[t] && in_vol[k] > SW_COND_EXACT_SHARE * vol[k];
            ENSURE(seen[t] == rest);
            nrest += rest;
        }
        ENSURE(nrest == c->nrest && (nexact > 0) == wide);
        /* the cubature of the others scaled to their volume outside, of these the least share */
        sw_cond_weights_apply(c);
        int reached = 0;
        for (int32_t k = 0; k < v->ndomains; ++k) {
            const sw_blob_domain *D = &v->domains[k];
            double s = in_vol[k] > 0 ? (vol[k] - in_vol[k]) / vol[k] : 1;
            if (in_vol[k] > SW_COND_EXACT_SHARE * vol[k]) s = 0;
            if (in_vol[k] > 0 && s < SW_COND_MIN_SHARE) s = SW_COND_MIN_SHARE;
            reached += in_vol[k] > 0;
            for (int32_t i = D->cub_begin; i < D->cub_begin + D->cub_count; ++i)
                ENSURE_NEAR(c->cub_w[i], s * v->cub_weight[i], 1e-12 * v->cub_weight[i]);
        }
        fprintf(stderr, "    radius %g: %d of %d domains reached, %d evaluated at q (%d tets)\n",
                wide ? RHO_WIDE : RHO, reached, v->ndomains, nexact, nrest);
        ENSURE(reached > 0);
        sw_cond_weights_restore(c);
        for (int32_t i = 0; i < v->ncub; ++i)
            ENSURE(c->cub_w[i] == v->cub_weight[i]);
        free(vol), free(in_vol), free(touches), free(seen);
        sinew_instance_destroy(in);
        sinew_world_destroy(w);
    }
}

/* Brute force: the vertices a breadth-first growth over the whole mesh reaches from seed s
 * through vertices within rho of s, marked in m. */
static void brute_grow(const sw_blob_view *v, const unsigned char *pinned, int32_t s, double rho,
                       unsigned char *m, int32_t *queue) {
    unsigned char *seen = calloc((size_t)v->nverts, 1);
    int32_t head = 0, tail = 0;
    queue[tail++] = s;
    seen[s] = 1;
    while (head < tail) {
        int32_t a = queue[head++];
        if (!pinned[a]) m[a] = 1; /* a bone vertex is passed through, never freed */
        for (int32_t t = 0; t < v->ntets; ++t) {
            const int32_t *tv = v->tets + 4 * (int64_t)t;
            if (tv[0] != a && tv[1] != a && tv[2] != a && tv[3] != a) continue;
            for (int k = 0; k < 4; ++k) {
                int32_t b = tv[k];
                double d2 = 0;
                for (int i = 0; i < 3; ++i)
                    d2 += (v->rest[3 * b + i] - v->rest[3 * s + i]) *
                          (v->rest[3 * b + i] - v->rest[3 * s + i]);
                if (seen[b] || d2 > rho * rho) continue;
                seen[b] = 1;
                queue[tail++] = b;
            }
        }
    }
    free(seen);
}

TEST(oracle_patch_is_the_growth_of_its_seeds_and_the_budget_keeps_the_nearest) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    sinew_instance *in = pressed(f, w, 5000, 1); /* one step: only its own seeds */
    ENSURE(in);
    const sw_cond *c = &in->cond;
    const sw_blob_view *v = in->v;
    int32_t n = v->nverts, ns = c->nseeds[c->slot];
    ENSURE(ns > 0 && c->nf > ns);
    unsigned char *m = calloc((size_t)n, 1);
    int32_t *queue = malloc(sizeof(int32_t) * n);
    for (int32_t i = 0; i < ns; ++i)
        brute_grow(v, c->pinned, c->seeds[(int64_t)c->slot * c->z.max_seeds + i], c->rho, m, queue);
    int32_t nm = 0;
    for (int32_t gv = 0; gv < n; ++gv) {
        nm += m[gv];
        ENSURE((sw_cond_position(c, gv) != NULL) == m[gv]);
    }
    ENSURE(nm == c->nf);
    int32_t npinned = 0; /* the fixture's bone vertices: the kinematic ones */
    for (int32_t gv = 0; gv < n; ++gv) {
        npinned += c->pinned[gv];
        ENSURE(c->pinned[gv] == (f->ch.bone_of_vertex[gv] >= 0));
    }
    ENSURE(npinned > 0);
    /* the full tets: exactly those with a patch corner */
    int32_t nfull = 0;
    for (int32_t t = 0; t < v->ntets; ++t) {
        const int32_t *tv = v->tets + 4 * (int64_t)t;
        nfull += m[tv[0]] || m[tv[1]] || m[tv[2]] || m[tv[3]];
    }
    ENSURE(nfull == c->nt);
    fprintf(stderr, "    %d seeds, %d patch vertices, %d full tets, %d ring copies\n", ns, c->nf,
            c->nt, c->nring);
    int32_t nf_all = c->nf;
    sinew_instance_destroy(in);
    /* a budget of a fifth: the nearest stay, the step flags it and stays finite */
    uint32_t budget = (uint32_t)(nf_all / 5);
    in = pressed(f, w, budget, 1);
    ENSURE(in);
    sinew_step_stats st = {.struct_size = sizeof st};
    sinew_instance_get_stats(in, &st);
    ENSURE(st.patch_vertices == budget);
    ENSURE(st.patch_dropped == (uint32_t)(nf_all - (int32_t)budget));
    ENSURE((st.status & SINEW_STEP_BUDGET) && (st.budget_exceeded & SINEW_BUDGET_PATCH));
    const double *xs = sw_instance_surface(in);
    for (int32_t i = 0; i < 3 * v->nsurf_verts; ++i)
        ENSURE(isfinite(xs[i]));
    /* nearest: no kept vertex is further from every seed than a dropped one */
    c = &in->cond;
    double kept_max = 0, dropped_min = INFINITY;
    for (int32_t gv = 0; gv < n; ++gv) {
        if (!m[gv]) continue;
        double d = INFINITY;
        for (int32_t i = 0; i < ns; ++i) {
            int32_t s = c->seeds[(int64_t)c->slot * c->z.max_seeds + i];
            double d2 = 0;
            for (int k = 0; k < 3; ++k)
                d2 += (v->rest[3 * gv + k] - v->rest[3 * s + k]) *
                      (v->rest[3 * gv + k] - v->rest[3 * s + k]);
            d = fmin(d, sqrt(d2));
        }
        if (sw_cond_position(c, gv))
            kept_max = fmax(kept_max, d);
        else
            dropped_min = fmin(dropped_min, d);
    }
    ENSURE(kept_max <= dropped_min + 1e-12);
    free(m), free(queue);
    sinew_instance_destroy(in);
    sinew_world_destroy(w);
}

/* Mass-weighted correction error of x against the reference xr (skinned xd). */
static double correction_error(const sinew_instance *in, const double *xr, const double *mass) {
    const sw_blob_view *v = in->v;
    double *x = malloc(sizeof(double) * 3 * v->nverts), *cnt = malloc(sizeof(double) * v->nverts),
           *xd = malloc(sizeof(double) * 3 * v->nverts);
    sw_instance_full_positions(in, x, cnt);
    sw_instance_dqs_positions(in, xd);
    double num = 0, den = 0;
    for (int32_t i = 0; i < 3 * v->nverts; ++i) {
        num += mass[i / 3] * (x[i] - xr[i]) * (x[i] - xr[i]);
        den += mass[i / 3] * (xr[i] - xd[i]) * (xr[i] - xd[i]);
    }
    free(x), free(cnt), free(xd);
    return sqrt(num / den);
}

/* The full-space reference with world w, stepped once at the rest pose (NULL on failure;
 * *fs its figures). */
static sw_fullsim *reference_at_rest(const bake_fixture *f, sinew_world *w, sw_fullsim_stats *fs) {
    sw_fullsim_params p = sw_fullsim_params_default();
    p.world = w;
    sw_fullsim *sim;
    sw_error err;
    if (sw_fullsim_create(&f->ch, &p, &sim, &err) != SINEW_OK) return NULL;
    int nb = f->ch.skel.nbones;
    double *T = calloc((size_t)12 * nb, sizeof(double));
    for (int b = 0; T && b < nb; ++b)
        T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
    sinew_result r = T ? sw_fullsim_step(sim, T, fs) : SINEW_ERROR_OUT_OF_MEMORY;
    free(T);
    if (r != SINEW_OK) {
        sw_fullsim_destroy(sim);
        return NULL;
    }
    return sim;
}

TEST(condensation_dents_where_the_subspace_locks_closer_to_the_reference) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.0f, &id);
    sinew_instance *sub = pressed(f, w, 0, 3), *cond = pressed(f, w, 3000, 3);
    ENSURE(sub && cond);
    sw_fullsim_stats fs;
    sw_fullsim *sim = reference_at_rest(f, w, &fs);
    ENSURE(sim);
    const double *xr = sw_fullsim_positions(sim), *mass = sw_fullsim_masses(sim);
    double e_sub = correction_error(sub, xr, mass), e_cond = correction_error(cond, xr, mass);
    int32_t ns = sub->v->nsurf_verts;
    double pen_sub = sw_world_max_penetration(w, ns, sw_instance_surface(sub), NULL, NULL, NULL),
           pen_cond = sw_world_max_penetration(w, ns, sw_instance_surface(cond), NULL, NULL, NULL);
    sinew_step_stats st = {.struct_size = sizeof st};
    sinew_instance_get_stats(cond, &st);
    fprintf(stderr,
            "    error vs reference: subspace %.3f, condensed %.3f; penetration %.4f -> %.4f "
            "(reference %.4f); patch %u vertices, %u PCG iterations\n",
            e_sub, e_cond, pen_sub, pen_cond, fs.world_penetration, st.patch_vertices,
            st.pcg_iterations);
    ENSURE(st.patch_vertices > 0 && st.pcg_iterations > 0);
    ENSURE(e_cond < 0.6 * e_sub);
    ENSURE(pen_cond < 0.3 * pen_sub);
    sw_fullsim_destroy(sim);
    sinew_instance_destroy(sub);
    sinew_instance_destroy(cond);
    sinew_world_destroy(w);
}

/* A patch that covers the whole mesh (radius the whole diagonal, a budget of every vertex)
 * is the full-space problem: pressed into the table, its solution converges to the
 * reference's, where the subspace alone misses much of the dent. */
TEST(a_whole_mesh_patch_converges_to_the_reference) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.0f, &id);
    const uint32_t nv = (uint32_t)f->ch.mesh.nverts;
    sinew_instance *sub = pressed(f, w, 0, 3), *whole = whole_mesh_patch(f, w, 3);
    ENSURE(sub && whole);
    sw_fullsim_stats fs;
    sw_fullsim *sim = reference_at_rest(f, w, &fs);
    ENSURE(sim);
    const double *xr = sw_fullsim_positions(sim), *mass = sw_fullsim_masses(sim);
    double e_sub = correction_error(sub, xr, mass), e_whole = correction_error(whole, xr, mass);
    sinew_step_stats st = {.struct_size = sizeof st};
    sinew_instance_get_stats(whole, &st);
    int32_t pinned = 0;
    for (uint32_t v = 0; v < nv; ++v)
        pinned += f->ch.bone_of_vertex[v] >= 0;
    fprintf(stderr,
            "    error vs reference: subspace %.4f, whole-mesh patch %.4f (%u of %u vertices, "
            "%d pinned to bones; %s)\n",
            e_sub, e_whole, st.patch_vertices, nv, pinned,
            st.status & SINEW_STEP_CONVERGED ? "converged" : "not converged");
    ENSURE(st.patch_vertices + (uint32_t)pinned == nv); /* every free vertex */
    ENSURE(e_whole < 0.02 && e_whole < 0.1 * e_sub);
    sw_fullsim_destroy(sim);
    sinew_instance_destroy(sub);
    sinew_instance_destroy(whole);
    sinew_world_destroy(w);
}

/* A patch that holds whole domains: their vertices no longer depend on q, so only the
 * cubature share a domain keeps (SW_COND_MIN_SHARE) holds the modes that move them. Over
 * the clip, pressed by the table, no step may run a domain's coordinates to its bound. */
TEST(a_patch_holding_whole_domains_keeps_their_coordinates_in_bounds) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.0f, &id);
    sinew_instance *whole = whole_mesh_patch(f, w, 0);
    ENSURE(whole);
    const sw_blob_view *v = whole->v;
    int nb = f->ch.skel.nbones, limited = 0, patched = 0;
    double worst = 0; /* the largest |q_k| / bound_k over the clip */
    for (int fr = 0; fr < f->ch.clip.nframes; ++fr) {
        sw_instance_set_pose_d(whole, f->ch.clip.T + (size_t)fr * 12 * nb);
        ENSURE(sinew_instance_step(whole, 1.0f / 30) == SINEW_OK);
        limited += (whole->stats.status & SINEW_STEP_LIMITED) != 0;
        patched += whole->stats.patch_vertices > 0;
        for (int32_t k = 0; k < v->ndomains; ++k) {
            const double *q = whole->solver.q + v->domains[k].q_offset;
            double n = 0;
            for (int32_t j = 0; j < v->domains[k].rank; ++j)
                n += q[j] * q[j];
            worst = fmax(worst, sqrt(n) / whole->q_bound[k]);
        }
    }
    fprintf(stderr,
            "    %d of %d frames with a patch, %d limited; largest |q_k| %.3g of its bound\n",
            patched, f->ch.clip.nframes, limited, worst);
    ENSURE(patched > 0 && limited == 0 && worst < 0.9);
    sinew_instance_destroy(whole);
    sinew_world_destroy(w);
}

TEST(without_contact_a_condensed_instance_is_bitwise_the_subspace) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(-1.0, 0.3f, &id); /* a table far below */
    sinew_instance *sub = pressed(f, w, 0, 0), *cond = pressed(f, w, 500, 0);
    ENSURE(sub && cond);
    int nb = f->ch.skel.nbones;
    for (int fr = 0; fr < f->ch.clip.nframes; ++fr) {
        const double *T = f->ch.clip.T + (size_t)fr * 12 * nb;
        sw_instance_set_pose_d(sub, T);
        sw_instance_set_pose_d(cond, T);
        ENSURE(sinew_instance_step(sub, 1.0f / 30) == SINEW_OK);
        ENSURE(sinew_instance_step(cond, 1.0f / 30) == SINEW_OK);
        ENSURE(memcmp(sw_instance_surface(sub), sw_instance_surface(cond),
                      sizeof(double) * 3 * sub->v->nsurf_verts) == 0);
        ENSURE(cond->stats.patch_vertices == 0);
    }
    sinew_instance_destroy(sub);
    sinew_instance_destroy(cond);
    sinew_world_destroy(w);
}

TEST(condensed_steps_allocate_and_lock_nothing_while_the_patch_moves) {
    moving_scene ms;
    ENSURE(moving_scene_make(&ms));
    for (int wide = 0; wide < 2; ++wide) { /* wide: with the rest of mostly covered domains */
        sinew_instance *in = pressed_rho(ms.f, ms.w, 800, 0, wide ? RHO_WIDE : RHO);
        ENSURE(in);
        int nb = ms.f->ch.skel.nbones, nfr = ms.f->ch.clip.nframes;
        unsigned active = sw_rt_interpose_active();
        uint32_t with_patch = 0, without = 0, with_rest = 0;
        sw_rt_count_begin();
        for (int s = 0; s < 60; ++s) {
            sinew_transform t;
            ball_at(s, &t);
            sinew_world_set_collider_transform(ms.w, ms.ball, &t);
            sw_instance_set_pose_d(in, ms.f->ch.clip.T + (size_t)(s % nfr) * 12 * nb);
            ENSURE(sinew_instance_step(in, 1.0f / 30) == SINEW_OK);
            with_patch += in->stats.patch_vertices > 0;
            without += in->stats.patch_vertices == 0;
            with_rest += in->cond.nrest > 0;
        }
        sw_rt_counts cnt = sw_rt_count_end();
        fprintf(stderr,
                "    radius %g: %u steps with a patch (%u with tets at q), %u without; allocs %lu "
                "locks %lu\n",
                wide ? RHO_WIDE : RHO, with_patch, with_rest, without, (unsigned long)cnt.allocs,
                (unsigned long)cnt.locks);
        ENSURE(with_patch > 10 && (with_rest > 0) == wide);
        if (active & SW_RT_CAT_ALLOCS) ENSURE(cnt.allocs == 0 && cnt.frees == 0);
        if (active & SW_RT_CAT_LOCKS) ENSURE(cnt.locks == 0);
        sinew_instance_destroy(in);
    }
    sinew_world_destroy(ms.w);
}

/* 10^4 steps of a ball that sweeps along the folding finger and in and out of it, dynamic
 * and quasistatic in turn: the patch grows, moves, shrinks and vanishes again and again;
 * every step succeeds with a finite surface, and none allocates or locks. */
enum { SOAK_STEPS = 10000 };
TEST(a_patch_grows_moves_and_shrinks_for_ten_thousand_steps_allocating_nothing) {
    moving_scene ms; /* its ball alone: no table to hold a patch when the ball is out */
    ENSURE((ms.f = fixture()) != NULL);
    sinew_world_def wd = sinew_world_def_default();
    ENSURE(sinew_world_create(&wd, &ms.w) == SINEW_OK);
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_SPHERE;
    c.radius = 0.2f;
    ball_at(0, &c.transform);
    ENSURE(sinew_world_add_collider(ms.w, &c, &ms.ball) == SINEW_OK);
    sinew_instance *in[2];
    for (int k = 0; k < 2; ++k) {
        sinew_instance_def d = sinew_instance_def_default();
        d.max_patch_vertices = 800;
        d.mode = k ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        ENSURE(sinew_instance_create(ms.f->blob, &d, &in[k]) == SINEW_OK);
        ENSURE(sinew_instance_set_world(in[k], ms.w) == SINEW_OK);
    }
    const int nb = ms.f->ch.skel.nbones, nfr = ms.f->ch.clip.nframes;
    const uint32_t ns = sinew_blob_surface_vertex_count(ms.f->blob);
    float *x = malloc(sizeof(float) * 3 * ns);
    ENSURE(x);
    unsigned active = sw_rt_interpose_active();
    uint32_t with = 0, grew = 0, shrank = 0, vanished = 0, last[2] = {0, 0}, failed = 0, bad = 0;
    sw_rt_count_begin();
    for (int s = 0; s < SOAK_STEPS; ++s) {
        sinew_transform t;
        ball_at(s, &t);
        t.position[1] = (float)(-0.45 - 0.3 * (1 + sin(0.21 * s))); /* in and out */
        sinew_world_set_collider_transform(ms.w, ms.ball, &t);
        sinew_instance *i = in[s % 2];
        sw_instance_set_pose_d(i, ms.f->ch.clip.T + (size_t)((s / 2) % nfr) * 12 * nb);
        failed += sinew_instance_step(i, 1.0f / 30) != SINEW_OK;
        uint32_t n = i->stats.patch_vertices, *l = &last[s % 2];
        with += n > 0;
        grew += n > *l;
        shrank += n < *l && n > 0;
        vanished += n == 0 && *l > 0;
        *l = n;
        sinew_instance_read_surface(i, x, NULL, ns);
        for (uint32_t v = 0; v < 3 * ns; ++v)
            bad += !isfinite(x[v]);
    }
    sw_rt_counts cnt = sw_rt_count_end();
    fprintf(stderr,
            "    %d steps: %u with a patch, grew %u, shrank %u, vanished %u times; %u failed; "
            "allocs %lu locks %lu\n",
            SOAK_STEPS, with, grew, shrank, vanished, failed, (unsigned long)cnt.allocs,
            (unsigned long)cnt.locks);
    ENSURE(failed == 0 && bad == 0);
    ENSURE(with > SOAK_STEPS / 10 && grew > 10 && shrank > 10 && vanished > 2);
    if (active & SW_RT_CAT_ALLOCS) ENSURE(cnt.allocs == 0 && cnt.frees == 0);
    if (active & SW_RT_CAT_LOCKS) ENSURE(cnt.locks == 0);
    free(x);
    sinew_instance_destroy(in[0]);
    sinew_instance_destroy(in[1]);
    sinew_world_destroy(ms.w);
}

TEST(dynamic_patch_gradient_and_the_dynamics_oracle) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_collider_id id;
    sinew_world *w = table_world(0.08, 0.3f, &id);
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    d.max_patch_vertices = 2000;
    d.patch_radius = (float)RHO;
    sinew_instance *in;
    ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
    sinew_instance_set_world(in, w);
    float *pose = rest_pose(f->ch.skel.nbones);
    sinew_instance_set_pose(in, pose, (uint32_t)f->ch.skel.nbones);
    const float h = 1.0f / 60;
    for (int k = 0; k < 4; ++k)
        ENSURE(sinew_instance_step(in, h) == SINEW_OK);
    /* the backward-Euler potential's gradient in (q, x) */
    sw_instance_step_prepare(in, h);
    sw_cond *c = &in->cond;
    ENSURE(c->nf > 10);
    int32_t R = in->red.R, nx = 3 * c->nf;
    sw_step_contacts ct = {&in->ps, &in->wc, NULL, NULL};
    sw_dyn_coef dc = {
        h, 1.0 / ((double)h * h), 1.0 / h, in->v->rayleigh_alpha, in->v->rayleigh_beta, 1};
    sw_cond_weights_apply(c);
    double *q = malloc(sizeof(double) * R), *x = malloc(sizeof(double) * nx),
           *g = malloc(sizeof(double) * (R + nx));
    memcpy(q, in->solver.q, sizeof(double) * R);
    for (int32_t i = 0; i < nx; ++i)
        x[i] = c->x[i] + 0.005 * cos(0.9 * i);
    sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
    memcpy(g, in->red.g, sizeof(double) * R);
    memcpy(g + R, c->gf, sizeof(double) * nx);
    double gmax = 0;
    for (int32_t i = 0; i < R + nx; ++i)
        gmax = fmax(gmax, fabs(g[i]));
    for (int32_t i = 0; i < R + nx; i += (i < R ? 1 : 1 + nx / 30)) {
        double *p = i < R ? q + i : x + (i - R), keep = *p, e = 1e-7;
        *p = keep + e;
        double ep = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
        *p = keep - e;
        double em = sw_cond_potential(c, &in->red, &ct, &in->solver, q, x, &dc, 0);
        *p = keep;
        ENSURE_NEAR((ep - em) / (2 * e), g[i], 1e-5 * gmax + 1e-4 * fabs(g[i]));
    }
    sw_cond_weights_restore(c);
    free(q), free(x), free(g);
    /* the table drops away: no seed after three steps, but the patch stays while its
       flesh springs back, and folds back once settled */
    sinew_instance_set_pose(in, pose, (uint32_t)f->ch.skel.nbones);
    ENSURE(sinew_instance_step(in, h) == SINEW_OK);
    sinew_transform far = sinew_transform_identity();
    far.position[1] = -5;
    sinew_world_set_collider_transform(w, id, &far);
    int last_patch = -1, kept_beyond_seeds = 0;
    for (int k = 0; k < 400; ++k) {
        ENSURE(sinew_instance_step(in, h) == SINEW_OK);
        if (in->stats.patch_vertices > 0) {
            last_patch = k;
            kept_beyond_seeds += k >= 3;
        }
    }
    fprintf(stderr, "    patch kept %d steps after the seeds expired, the last at step %d\n",
            kept_beyond_seeds, last_patch);
    ENSURE(kept_beyond_seeds >= 1); /* moving: kept */
    ENSURE(last_patch < 399);       /* settled: released */
    const double *xs = sw_instance_surface(in);
    for (int32_t i = 0; i < 3 * in->v->nsurf_verts; ++i)
        ENSURE(isfinite(xs[i]));
    free(pose);
    sinew_instance_destroy(in);
    sinew_world_destroy(w);
}

TEST(patch_def_is_checked_and_sized) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance_def d = sinew_instance_def_default();
    size_t off = 0, on = 0;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &off) == SINEW_OK);
    d.max_patch_vertices = 100;
    ENSURE(sinew_instance_memory_size(f->blob, &d, &on) == SINEW_OK);
    ENSURE(on > off);
    sinew_instance *in;
    float bad[] = {-0.1f, 1.5f, NAN, INFINITY};
    for (int i = 0; i < 4; ++i) {
        d.patch_radius = bad[i];
        ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_ERROR_INVALID_ARGUMENT);
    }
    /* a patch evaluates detected self-contact at its own positions: every mode may have one */
    d.patch_radius = 0;
    sinew_self_contact modes[] = {SINEW_SELF_CONTACT_POSE_SPACE, SINEW_SELF_CONTACT_EXHAUSTIVE,
                                  SINEW_SELF_CONTACT_POSE_PAIRS};
    for (int k = 0; k < 3; ++k) {
        d.self_contact = modes[k];
        ENSURE(sinew_instance_create(f->blob, &d, &in) == SINEW_OK);
        sinew_instance_destroy(in);
    }
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(coupled_gradient_matches_finite_differences_and_its_hessian_is_psd),
             CASE(cubature_weights_follow_each_domains_volume_outside_the_patch),
             CASE(oracle_patch_is_the_growth_of_its_seeds_and_the_budget_keeps_the_nearest),
             CASE(condensation_dents_where_the_subspace_locks_closer_to_the_reference),
             CASE(without_contact_a_condensed_instance_is_bitwise_the_subspace),
             CASE(condensed_steps_allocate_and_lock_nothing_while_the_patch_moves),
             CASE(dynamic_patch_gradient_and_the_dynamics_oracle),
             CASE(patch_def_is_checked_and_sized),
             CASE(a_whole_mesh_patch_converges_to_the_reference),
             CASE(a_patch_holding_whole_domains_keeps_their_coordinates_in_bounds),
             CASE(eq_4_12_matches_a_brute_force_projection_of_the_full_force),
             CASE(a_patch_grows_moves_and_shrinks_for_ten_thousand_steps_allocating_nothing),
             CASE(release_fixture))
