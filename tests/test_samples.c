/* Procedural samples: mesh validity and quality, closed conforming surface, rig and
 * clip invariants, self-contact at the peak pose, error paths. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "samples.h"
#include "sw_test.h"
#include "tube_mesh.h"

#define PI 3.14159265358979323846

/* The shapes samples.c documents (length, radii, caps), to check against. */
typedef struct shape_ref {
    const char *name;
    sw_tube_profile shape;
    int32_t nbones;
    double joint_x[4];
    double peak_deg[3];
} shape_ref;

static const shape_ref refs[] = {
    {"cylinder", {4.0, 0.5, 0.5, 0, 0}, 2, {0.0, 2.0, 4.0}, {0.0, 140.0}},
    {"finger", {3.6, 0.45, 0.35, 0, 1}, 3, {0.0, 1.6, 2.7, 3.6}, {0.0, 110.0, 100.0}},
    {"capsule", {4.0, 0.5, 0.5, 1, 1}, 2, {0.0, 2.0, 4.0}, {0.0, 90.0}},
};

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* ---- topology: faces shared by <= 2 tets, boundary a closed oriented 2-manifold ---- */

typedef struct key3 {
    int32_t v[3];
    int32_t dir; /* faces: tet id; edges: +1/-1 traversal direction */
} key3;

static int cmp_key3(const void *a, const void *b) {
    const key3 *x = a, *y = b;
    for (int i = 0; i < 3; ++i)
        if (x->v[i] != y->v[i]) return x->v[i] < y->v[i] ? -1 : 1;
    return 0;
}

static void sort3(int32_t *v) {
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            if (v[j] < v[i]) {
                int32_t t = v[i];
                v[i] = v[j];
                v[j] = t;
            }
}

typedef struct topo_report {
    int ok;
    char why[200];
    int32_t nbfaces, nbedges, nbverts;
    unsigned char *on_boundary; /* nverts */
} topo_report;

static void check_topology(const sw_tetmesh *m, topo_report *rep) {
    static const int fv[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}; /* outward */
    size_t nf = 4 * (size_t)m->ntets;
    key3 *faces = malloc(nf * sizeof *faces);
    memset(rep, 0, sizeof *rep);
    rep->on_boundary = calloc((size_t)m->nverts, 1);
    if (!faces || !rep->on_boundary) {
        snprintf(rep->why, sizeof rep->why, "out of memory");
        free(faces);
        return;
    }
    for (int32_t t = 0; t < m->ntets; ++t)
        for (int f = 0; f < 4; ++f) {
            key3 *k = faces + 4 * (size_t)t + f;
            for (int i = 0; i < 3; ++i)
                k->v[i] = m->tets[4 * t + fv[f][i]];
            sort3(k->v);
            k->dir = 4 * t + f;
        }
    qsort(faces, nf, sizeof *faces, cmp_key3);
    key3 *edges = malloc(3 * nf * sizeof *edges);
    size_t ne = 0;
    rep->ok = edges != NULL;
    for (size_t i = 0; i < nf && rep->ok;) {
        size_t j = i;
        while (j < nf && cmp_key3(faces + i, faces + j) == 0)
            ++j;
        if (j - i > 2) {
            snprintf(rep->why, sizeof rep->why, "face (%d %d %d) in %zu tets", faces[i].v[0],
                     faces[i].v[1], faces[i].v[2], j - i);
            rep->ok = 0;
        } else if (j - i == 1) { /* boundary face, with its outward orientation */
            int32_t t = faces[i].dir / 4, f = faces[i].dir % 4, o[3];
            for (int a = 0; a < 3; ++a) {
                o[a] = m->tets[4 * t + fv[f][a]];
                rep->on_boundary[o[a]] = 1;
            }
            for (int a = 0; a < 3; ++a) {
                int32_t p = o[a], q = o[(a + 1) % 3];
                key3 *e = edges + ne++;
                e->v[0] = p < q ? p : q;
                e->v[1] = p < q ? q : p;
                e->v[2] = 0;
                e->dir = p < q ? 1 : -1;
            }
            rep->nbfaces++;
        }
        i = j;
    }
    if (rep->ok) qsort(edges, ne, sizeof *edges, cmp_key3);
    for (size_t i = 0; i < ne && rep->ok;) {
        size_t j = i;
        int sum = 0;
        while (j < ne && cmp_key3(edges + i, edges + j) == 0)
            sum += edges[j++].dir;
        if (j - i != 2 || sum != 0) {
            snprintf(rep->why, sizeof rep->why,
                     "boundary edge (%d %d) in %zu boundary faces (direction sum %d)",
                     edges[i].v[0], edges[i].v[1], j - i, sum);
            rep->ok = 0;
        }
        rep->nbedges++;
        i = j;
    }
    for (int32_t v = 0; v < m->nverts; ++v)
        rep->nbverts += rep->on_boundary[v];
    free(edges);
    free(faces);
}

/* ---- quality ---- */

static double min_dihedral_deg(const sw_tetmesh *m) {
    static const int e[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    double mn = 180.0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const double *p[4];
        for (int i = 0; i < 4; ++i)
            p[i] = m->X + 3 * m->tets[4 * t + i];
        for (int k = 0; k < 6; ++k) { /* angle between the faces (a,b,c) and (a,b,d) */
            const double *a = p[e[k][0]], *b = p[e[k][1]], *c = p[e[k][2]], *d = p[e[k][3]];
            double ab[3], ac[3], ad[3];
            for (int i = 0; i < 3; ++i)
                ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ad[i] = d[i] - a[i];
            double n1[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                            ab[0] * ac[1] - ab[1] * ac[0]};
            double n2[3] = {ab[1] * ad[2] - ab[2] * ad[1], ab[2] * ad[0] - ab[0] * ad[2],
                            ab[0] * ad[1] - ab[1] * ad[0]};
            double c0 = (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]) /
                        sqrt((n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]) *
                             (n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]));
            double ang = acos(fmax(-1.0, fmin(1.0, c0))) * 180.0 / PI;
            if (ang < mn) mn = ang;
        }
    }
    return mn;
}

static const shape_ref *ref_of(const char *name) {
    for (size_t i = 0; i < sizeof refs / sizeof refs[0]; ++i)
        if (strcmp(refs[i].name, name) == 0) return &refs[i];
    return NULL;
}

/* ---- one sample at one size: everything ---- */

static void check_mesh(const sw_character *c, const shape_ref *ref, int32_t target, double vol_tol,
                       topo_report *topo) {
    const sw_tetmesh *m = &c->mesh;
    sw_error err;
    ENSUREF(fabs(m->ntets - (double)target) <= 0.25 * target, "%s: %d tets for target %d",
            ref->name, m->ntets, target);
    ENSUREF(sw_tetmesh_validate(m, 0.0, &err) == SINEW_OK, "%s: %s", ref->name, err.msg);
    double vol = 0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *q = m->tets + 4 * t;
        vol += sw_tet_signed_volume(m->X + 3 * q[0], m->X + 3 * q[1], m->X + 3 * q[2],
                                    m->X + 3 * q[3]);
    }
    double exact = sw_tube_volume(&ref->shape);
    ENSUREF(fabs(vol / exact - 1.0) <= vol_tol, "%s: volume %g vs analytic %g", ref->name, vol,
            exact);
    check_topology(m, topo);
    ENSUREF(topo->ok, "%s: %s", ref->name, topo->why);
    /* Closed surface of a ball: Euler characteristic V - E + F = 2. */
    ENSUREF(topo->nbverts - topo->nbedges + topo->nbfaces == 2, "%s: surface V-E+F = %d", ref->name,
            topo->nbverts - topo->nbedges + topo->nbfaces);
    /* Every boundary vertex lies on the true surface (side, sphere cap, or flat end). */
    for (int32_t v = 0; v < m->nverts; ++v) {
        if (!topo->on_boundary[v]) continue;
        const double *X = m->X + 3 * v;
        double r = hypot(X[1], X[2]), R = sw_tube_radius(&ref->shape, X[0]);
        int flat_end = (fabs(X[0]) < 1e-12 && !ref->shape.cap_start) ||
                       (fabs(X[0] - ref->shape.length) < 1e-12 && !ref->shape.cap_end);
        /* 1e-6: sqrt(R^2 - d^2) magnifies rounding at a cap's tip */
        ENSUREF(fabs(r - R) < 1e-6 * (1 + R) || (flat_end && r <= R + 1e-12),
                "%s: boundary vertex %d at x %g r %g, surface radius %g", ref->name, v, X[0], r, R);
    }
    double dih = min_dihedral_deg(m);
    fprintf(stderr,
            "  %s %d tets (target %d), %d verts, volume error %+.2f%%, min dihedral %.2f deg\n",
            ref->name, m->ntets, target, m->nverts, 100.0 * (vol / exact - 1.0), dih);
    ENSUREF(dih > 5.0, "%s: min dihedral %g degrees", ref->name, dih);
}

static void check_rig(const sw_character *c, const shape_ref *ref, const topo_report *topo) {
    const int32_t nb = ref->nbones, nv = c->mesh.nverts;
    sw_error err;
    ENSURE(c->skel.nbones == nb && c->weights.nbones == nb && c->weights.nverts == nv);
    ENSUREF(sw_skeleton_validate(&c->skel, &err) == SINEW_OK, "%s", err.msg);
    for (int32_t b = 0; b < nb; ++b) {
        ENSURE(c->skel.parent[b] == b - 1);
        const double *h = c->skel.joints + 3 * c->skel.bones[2 * b];
        const double *t = c->skel.joints + 3 * c->skel.bones[2 * b + 1];
        ENSURE(h[0] == ref->joint_x[b] && t[0] == ref->joint_x[b + 1]);
        ENSURE(h[1] == 0 && h[2] == 0 && t[1] == 0 && t[2] == 0);
    }
    int32_t driven[3] = {0, 0, 0};
    for (int32_t v = 0; v < nv; ++v) {
        const double *w = c->weights.w + (size_t)v * nb;
        double sum = 0, x = c->mesh.X[3 * v];
        for (int32_t b = 0; b < nb; ++b) {
            ENSUREF(w[b] >= 0 && w[b] <= 1, "vertex %d weight %d = %g", v, b, w[b]);
            sum += w[b];
        }
        ENSURE_NEAR(sum, 1.0, 1e-12);
        /* Far from every joint (more than the local radius) a vertex follows one bone. */
        int far = 1, own = 0;
        for (int32_t j = 1; j < nb; ++j) {
            far &= fabs(x - ref->joint_x[j]) > sw_tube_body_radius(&ref->shape, ref->joint_x[j]);
            if (x >= ref->joint_x[j]) own = j;
        }
        if (far)
            ENSUREF(w[own] == 1.0, "vertex %d at x %g: weight %g on bone %d", v, x, w[own], own);
        int32_t b = c->bone_of_vertex[v];
        ENSURE(b >= -1 && b < nb);
        if (b >= 0) {
            ENSUREF(!topo->on_boundary[v], "boundary vertex %d is bone-driven", v);
            ENSUREF(b == own, "vertex %d at x %g driven by bone %d", v, x, b);
            driven[b]++;
        }
    }
    for (int32_t b = 0; b < nb; ++b)
        ENSUREF(driven[b] >= 4, "bone %d drives %d vertices", b, driven[b]);
    ENSURE(c->youngs == 5000.0 && c->poisson == 0.08 && c->density > 0);
    ENSURE(strcmp(c->name, ref->name) == 0);
}

/* Rotation angle of R_a^T R_b about +z, in degrees (and checks the axis is z). */
static double relative_angle_deg(const double *Ta, const double *Tb) {
    double Rr[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            Rr[3 * i + j] = Ta[i] * Tb[j] + Ta[3 + i] * Tb[3 + j] + Ta[6 + i] * Tb[6 + j];
    if (fabs(Rr[8] - 1.0) > 1e-12) return NAN;
    return atan2(Rr[3], Rr[0]) * 180.0 / PI;
}

static void check_clip(const sw_character *c, const shape_ref *ref) {
    const int32_t nb = ref->nbones, nf = c->clip.nframes;
    ENSURE(c->clip.nbones == nb && c->clip.fps == 30.0 && nf >= 2);
    for (int32_t f = 0; f < nf; ++f)
        for (int32_t b = 0; b < nb; ++b) {
            const double *T = c->clip.T + 12 * ((size_t)f * nb + b);
            for (int i = 0; i < 3; ++i) /* R R^T = I */
                for (int j = 0; j < 3; ++j) {
                    double d = T[3 * i] * T[3 * j] + T[3 * i + 1] * T[3 * j + 1] +
                               T[3 * i + 2] * T[3 * j + 2];
                    ENSURE_NEAR(d, i == j ? 1.0 : 0.0, 1e-12);
                }
            double det = T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                         T[2] * (T[3] * T[7] - T[4] * T[6]);
            ENSURE_NEAR(det, 1.0, 1e-12);
            if (f == 0)
                for (int i = 0; i < 12; ++i)
                    ENSURE_NEAR(T[i], (i % 4 == 0 && i < 9) ? 1.0 : 0.0, 1e-12);
            if (b > 0) { /* the joint stays connected: parent and child agree on it */
                const double *Tp = T - 12, *h = c->skel.joints + 3 * c->skel.bones[2 * b];
                double a[3], q[3];
                sw_transform_point(Tp, h, a);
                sw_transform_point(T, h, q);
                for (int i = 0; i < 3; ++i)
                    ENSURE_NEAR(a[i], q[i], 1e-12);
            }
        }
    const double *mid = c->clip.T + 12 * (size_t)(nf / 2) * nb;
    for (int32_t b = 1; b < nb; ++b)
        ENSURE_NEAR(relative_angle_deg(mid + 12 * (b - 1), mid + 12 * b), ref->peak_deg[b], 1e-9);
    if (nf >= 4) { /* strictly below the peak before the middle frame */
        const double *pre = c->clip.T + 12 * (size_t)(nf / 2 - 1) * nb;
        ENSURE(relative_angle_deg(pre, pre + 12) < ref->peak_deg[1] - 1e-6);
    }
}

/* At the peak frame plain LBS folds the flesh through itself: inverted tets at the inner
 * side, and (where the fold exceeds ~100 degrees, on meshes fine enough to have child
 * surface vertices just past the blend) rigid child flesh landing inside the parent's
 * rigid flesh. Returns the number of such child surface vertices, -1 if no inversion. */
static int32_t check_interpenetration(const sw_character *c, const shape_ref *ref) {
    const int32_t nb = ref->nbones, nv = c->mesh.nverts, f = c->clip.nframes / 2;
    const double *T = c->clip.T + 12 * (size_t)f * nb;
    double *x = malloc(sizeof(double) * 3 * (size_t)nv);
    if (!x) return -1;
    sw_lbs(nv, c->mesh.X, &c->weights, T, x);
    int32_t inverted = 0, inside = 0;
    for (int32_t t = 0; t < c->mesh.ntets; ++t) {
        const int32_t *q = c->mesh.tets + 4 * t;
        if (sw_tet_signed_volume(x + 3 * q[0], x + 3 * q[1], x + 3 * q[2], x + 3 * q[3]) < 0)
            inverted++;
    }
    for (int32_t j = 1; j < nb; ++j) { /* joint j: parent j-1, child j */
        double h = sw_tube_body_radius(&ref->shape, ref->joint_x[j]);
        const double *Tp = T + 12 * (j - 1);
        for (int32_t v = 0; v < nv; ++v) {
            const double *X = c->mesh.X + 3 * v;
            double r = hypot(X[1], X[2]);
            if (c->weights.w[(size_t)v * nb + j] != 1.0 ||
                fabs(r - sw_tube_radius(&ref->shape, X[0])) > 1e-9)
                continue;      /* only rigid child surface vertices */
            double d[3], p[3]; /* back to the parent's rest space: R^T (x - t) */
            for (int i = 0; i < 3; ++i)
                d[i] = x[3 * v + i] - Tp[9 + i];
            for (int i = 0; i < 3; ++i)
                p[i] = Tp[i] * d[0] + Tp[3 + i] * d[1] + Tp[6 + i] * d[2];
            double pr = hypot(p[1], p[2]);
            if (p[0] > ref->joint_x[j - 1] && p[0] < ref->joint_x[j] - h &&
                pr < 0.999 * sw_tube_radius(&ref->shape, p[0]))
                inside++;
        }
    }
    free(x);
    fprintf(stderr,
            "  %s peak frame: %d inverted tets, %d child surface vertices inside the parent\n",
            ref->name, inverted, inside);
    return inverted > 0 ? inside : -1;
}

static void check_sample(const char *name, int32_t target, double vol_tol) {
    const shape_ref *ref = ref_of(name);
    ENSURE(ref != NULL);
    sw_character c;
    sw_error err;
    double t0 = now_s();
    ENSUREF(sw_sample_make(name, target, 31, &c, &err) == SINEW_OK, "%s", err.msg);
    double dt = now_s() - t0;
    fprintf(stderr, "  %s %d tets generated in %.3f s\n", name, c.mesh.ntets, dt);
    topo_report topo;
    int before = sw_test_failed_;
    check_mesh(&c, ref, target, vol_tol, &topo);
    if (sw_test_failed_ == before) check_rig(&c, ref, &topo);
    if (sw_test_failed_ == before) check_clip(&c, ref);
    if (sw_test_failed_ == before) {
        int32_t inside = check_interpenetration(&c, ref);
        if (inside < 0) {
            fprintf(stderr, "  %s: no inverted tets at the peak frame\n", name);
            sw_test_failed_++;
        } else if (ref->peak_deg[1] > 100.0 && target >= 20000 && inside == 0) {
            fprintf(stderr, "  %s: no rigid child flesh inside the parent at the peak\n", name);
            sw_test_failed_++;
        }
    }
    free(topo.on_boundary);
    sw_character_free(&c);
}

TEST(cylinder_1k) {
    check_sample("cylinder", 1000, 0.08);
}
TEST(cylinder_20k) {
    check_sample("cylinder", 20000, 0.025);
}
TEST(finger_1k) {
    check_sample("finger", 1000, 0.08);
}
TEST(finger_20k) {
    check_sample("finger", 20000, 0.025);
}
TEST(finger_200k) {
    check_sample("finger", 200000, 0.01);
}
TEST(capsule_1k) {
    check_sample("capsule", 1000, 0.08);
}
TEST(capsule_20k) {
    check_sample("capsule", 20000, 0.025);
}

TEST(names_list_all_samples) {
    const char *const *names = sw_sample_names();
    int n = 0;
    for (; names[n]; ++n)
        ENSURE(ref_of(names[n]) != NULL);
    ENSURE(n == 3);
}

TEST(deterministic) {
    sw_character a, b;
    sw_error err;
    ENSURE(sw_sample_make("finger", 5000, 4, &a, &err) == SINEW_OK);
    ENSURE(sw_sample_make("finger", 5000, 4, &b, &err) == SINEW_OK);
    int same = a.mesh.nverts == b.mesh.nverts && a.mesh.ntets == b.mesh.ntets &&
               !memcmp(a.mesh.X, b.mesh.X, sizeof(double) * 3 * a.mesh.nverts) &&
               !memcmp(a.mesh.tets, b.mesh.tets, sizeof(int32_t) * 4 * a.mesh.ntets) &&
               !memcmp(a.clip.T, b.clip.T, sizeof(double) * 12 * 3 * 4);
    sw_character_free(&a);
    sw_character_free(&b);
    ENSURE(same);
}

/* Two frames: rest then peak; three: rest, peak, rest. */
TEST(short_clips) {
    sw_character c;
    sw_error err;
    ENSURE(sw_sample_make("cylinder", 1000, 2, &c, &err) == SINEW_OK);
    double a2 = relative_angle_deg(c.clip.T + 24, c.clip.T + 36);
    sw_character_free(&c);
    ENSURE_NEAR(a2, 140.0, 1e-9);
    ENSURE(sw_sample_make("cylinder", 1000, 3, &c, &err) == SINEW_OK);
    double a3 = relative_angle_deg(c.clip.T + 24, c.clip.T + 36);
    double e3 = relative_angle_deg(c.clip.T + 48, c.clip.T + 60);
    sw_character_free(&c);
    ENSURE_NEAR(a3, 140.0, 1e-9);
    ENSURE_NEAR(e3, 0.0, 1e-9);
}

TEST(tube_profile_volume_and_radius) {
    sw_tube_profile cap = {4.0, 0.5, 0.5, 1, 1};
    ENSURE_NEAR(sw_tube_volume(&cap), PI * 0.25 * 3.0 + 4.0 / 3.0 * PI * 0.125, 1e-12);
    ENSURE_NEAR(sw_tube_radius(&cap, 0.0), 0.0, 1e-12);
    ENSURE_NEAR(sw_tube_radius(&cap, 0.25), sqrt(0.25 - 0.0625), 1e-12);
    ENSURE_NEAR(sw_tube_radius(&cap, 2.0), 0.5, 1e-12);
    sw_tube_profile cone = {3.0, 1.0, 0.5, 0, 0};
    ENSURE_NEAR(sw_tube_radius(&cone, 1.5), 0.75, 1e-12);
    ENSURE_NEAR(sw_tube_volume(&cone), PI * 3.0 * (1.0 + 0.5 + 0.25) / 3.0, 1e-12);
}

/* A fat short tube with both caps and a strong taper still meshes cleanly. */
TEST(tube_unusual_profile) {
    sw_tube_profile p = {2.5, 1.0, 0.4, 1, 1};
    sw_tetmesh m;
    unsigned char *surf;
    sw_error err;
    ENSUREF(sw_tube_mesh(&p, 8000, &m, &surf, &err) == SINEW_OK, "%s", err.msg);
    shape_ref ref = {"fat", p, 1, {0, 2.5}, {0}};
    topo_report topo;
    check_mesh(&(sw_character){.mesh = m}, &ref, 8000, 0.05, &topo);
    int32_t flagged = 0, mismatched = 0;
    for (int32_t v = 0; v < m.nverts; ++v) {
        flagged += surf[v];
        mismatched += surf[v] != topo.on_boundary[v];
    }
    free(topo.on_boundary);
    free(surf);
    sw_tetmesh_free(&m);
    ENSURE(flagged > 0);
    ENSUREF(mismatched == 0, "%d vertices flagged wrongly as surface", mismatched);
}

/* The topology check itself rejects a mesh with a tet repeated (faces in 3 tets) and
 * one with a tet removed from the inside (a second, inner boundary: V-E+F = 4). */
TEST(topology_check_detects_defects) {
    sw_tetmesh m;
    sw_error err;
    sw_tube_profile p = {4.0, 0.5, 0.5, 0, 0};
    ENSURE(sw_tube_mesh(&p, 5000, &m, NULL, &err) == SINEW_OK);
    topo_report topo;
    int32_t *copy = m.tets;
    m.tets = malloc(sizeof(int32_t) * 4 * ((size_t)m.ntets + 1));
    ENSURE(m.tets != NULL);
    memcpy(m.tets, copy, sizeof(int32_t) * 4 * (size_t)m.ntets);
    int32_t inner = -1; /* a tet with no boundary vertex, near the middle */
    for (int32_t t = 0; t < m.ntets && inner < 0; ++t) {
        int ok = 1;
        for (int a = 0; a < 4; ++a) {
            const double *X = m.X + 3 * copy[4 * t + a];
            ok &= fabs(X[0] - 2.0) < 0.5 && hypot(X[1], X[2]) < 0.2;
        }
        if (ok) inner = t;
    }
    free(copy);
    memcpy(m.tets + 4 * (size_t)m.ntets, m.tets + 4 * (size_t)inner, 4 * sizeof(int32_t));
    m.ntets++;
    check_topology(&m, &topo);
    free(topo.on_boundary);
    int dup_ok = topo.ok;
    m.ntets--;
    memcpy(m.tets + 4 * (size_t)inner, m.tets + 4 * (size_t)(m.ntets - 1), 4 * sizeof(int32_t));
    m.ntets--;
    check_topology(&m, &topo);
    free(topo.on_boundary);
    int euler = topo.nbverts - topo.nbedges + topo.nbfaces;
    sw_tetmesh_free(&m);
    ENSURE(inner >= 0);
    ENSURE(!dup_ok);
    ENSURE(topo.ok && euler == 4);
}

TEST(bad_arguments) {
    sw_character c;
    sw_error err;
    memset(&c, 0xab, sizeof c);
    ENSURE(sw_sample_make("elbow", 5000, 10, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "elbow") != NULL);
    ENSURE(c.mesh.X == NULL && c.clip.T == NULL && c.bone_of_vertex == NULL);
    ENSURE(sw_sample_make(NULL, 5000, 10, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_sample_make("finger", 999, 10, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "999") != NULL);
    ENSURE(sw_sample_make("finger", 2000001, 10, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_sample_make("finger", -5, 10, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_sample_make("capsule", 5000, 1, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "frames") != NULL);
    ENSURE(sw_sample_make("capsule", 5000, 10, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(c.mesh.X == NULL && c.weights.w == NULL && c.skel.joints == NULL);
    sw_tetmesh m;
    sw_tube_profile bad[] = {{4.0, -0.5, 0.5, 0, 0},
                             {1.0, 0.5, 0.5, 1, 1},
                             {NAN, 0.5, 0.5, 0, 0},
                             {0.0, 0.5, 0.5, 0, 0}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        ENSURE(sw_tube_mesh(&bad[i], 5000, &m, NULL, &err) != SINEW_OK);
        ENSURE(m.X == NULL && m.tets == NULL && err.msg[0]);
    }
    sw_tube_profile ok = {4.0, 0.5, 0.5, 0, 0};
    ENSURE(sw_tube_mesh(&ok, 500, &m, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_tube_mesh(NULL, 5000, &m, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
}

SW_TEST_MAIN(CASE(cylinder_1k), CASE(cylinder_20k), CASE(finger_1k), CASE(finger_20k),
             CASE(finger_200k), CASE(capsule_1k), CASE(capsule_20k), CASE(names_list_all_samples),
             CASE(deterministic), CASE(short_clips), CASE(tube_profile_volume_and_radius),
             CASE(tube_unusual_profile), CASE(topology_check_detects_defects), CASE(bad_arguments))
