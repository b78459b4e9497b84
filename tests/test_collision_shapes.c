/* The closed-form colliders (runtime/collision/shapes.c) under random transforms: the
 * signed distance against an independent formula (a box as its six face rectangles, a
 * capsule as a segment's endpoints and line), the closest point on the surface, the
 * normal unit and outward (for a convex shape: the support function in the normal's
 * direction is reached at the closest point), inside and outside, at the special
 * points (centres, axes, faces, edges, corners) too; a moved collider answers as the
 * point transformed by hand, with no rebuild; the world box holds the solid. */
#include "sw_test.h"

#include "collision_ref.h"

/* A world with one collider of def `d`; the collider through collision.h. */
static const sw_collider *one(sinew_world **w, const sinew_collider_def *d, sinew_collider_id *id) {
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, w) != SINEW_OK) return NULL;
    if (sinew_world_add_collider(*w, d, id) != SINEW_OK) return NULL;
    return sw_world_slot(*w, (uint32_t)sw_world_slot_of(*w, *id));
}

/* Reference signed distance and support function, in the collider's frame. */
typedef struct ref_shape {
    sinew_shape shape;
    double r, hh, e[3];
} ref_shape;

static double box_face_dist(const double *e, const double y[3]) {
    double best = HUGE_VAL;
    for (int k = 0; k < 3; ++k)
        for (int s = -1; s <= 1; s += 2) { /* face x_k = s e_k, a clamped rectangle */
            double q[3];
            for (int i = 0; i < 3; ++i)
                q[i] = i == k ? s * e[k] : fmin(fmax(y[i], -e[i]), e[i]);
            best = fmin(best, ref_dist(y, q));
        }
    return best;
}

static double ref_phi(const ref_shape *s, const double y[3]) {
    static const double o[3] = {0, 0, 0};
    switch (s->shape) {
    case SINEW_SHAPE_SPHERE:
        return ref_dist(y, o) - s->r;
    case SINEW_SHAPE_CAPSULE: {
        double a[3] = {0, -s->hh, 0}, b[3] = {0, s->hh, 0};
        double d = fmin(ref_dist(y, a), ref_dist(y, b));
        if (fabs(y[1]) <= s->hh) d = fmin(d, hypot(y[0], y[2]));
        return d - s->r;
    }
    default: {
        double d = box_face_dist(s->e, y);
        int in = fabs(y[0]) < s->e[0] && fabs(y[1]) < s->e[1] && fabs(y[2]) < s->e[2];
        return in ? -d : d;
    }
    }
}

static double support(const ref_shape *s, const double n[3]) {
    if (s->shape == SINEW_SHAPE_SPHERE) return s->r;
    if (s->shape == SINEW_SHAPE_CAPSULE) return s->r + s->hh * fabs(n[1]);
    return s->e[0] * fabs(n[0]) + s->e[1] * fabs(n[1]) + s->e[2] * fabs(n[2]);
}

/* Worst deviations over a set of points. */
typedef struct errs {
    double phi, on_surface, consistency, unit, support;
    int n;
} errs;

/* One query at local point y; folds its errors into e. Returns 0 when nothing came back. */
static int check_point(const sw_collider *c, const sinew_transform *tf, const ref_shape *s,
                       const double y[3], errs *e) {
    double x[3], p[3], n[3];
    to_world(tf, y, x);
    sw_collider_hit h;
    if (!sw_collider_query(c, x, 100.0, &h)) return 0;
    to_local(tf, h.point, 1, p);
    to_local(tf, h.normal, 0, n);
    e->phi = fmax(e->phi, fabs(h.phi - ref_phi(s, y)));
    e->on_surface = fmax(e->on_surface, fabs(ref_phi(s, p)));
    double back[3] = {p[0] + h.phi * n[0], p[1] + h.phi * n[1], p[2] + h.phi * n[2]};
    e->consistency = fmax(e->consistency, ref_dist(back, y));
    e->unit = fmax(e->unit, fabs(sqrt(ref_dot(n, n)) - 1) + (isfinite(n[0]) ? 0 : 1));
    e->support = fmax(e->support, fabs(support(s, n) - ref_dot(n, p)));
    e->n++;
    return 1;
}

/* Random points in [-2L, 2L]^3, on random surface-near shells, and the special points. */
static void run_shape(const sinew_collider_def *d, const ref_shape *s, const double (*special)[3],
                      int nspecial, errs *e) {
    for (int trial = 0; trial < 20; ++trial) {
        sinew_collider_def dd = *d;
        dd.transform = random_transform();
        sinew_world *w = NULL;
        sinew_collider_id id;
        const sw_collider *c = one(&w, &dd, &id);
        if (!c) {
            e->n = -1;
            sinew_world_destroy(w);
            return;
        }
        double L = s->r + s->hh + s->e[0] + s->e[1] + s->e[2];
        for (int k = 0; k < 500; ++k) {
            double y[3] = {2 * L * srand1(), 2 * L * srand1(), 2 * L * srand1()};
            check_point(c, &dd.transform, s, y, e);
        }
        for (int k = 0; k < nspecial; ++k)
            check_point(c, &dd.transform, s, special[k], e);
        sinew_world_destroy(w);
    }
}

#define TOL 2e-6 /* float transforms of magnitude 5 rounded once more: about 1e-6 */

static void expect(const errs *e, const char *name) {
    fprintf(stderr,
            "    %s: %d points: |dphi| %.2e, off surface %.2e, p + phi n - x %.2e, "
            "|n| - 1 %.2e, support %.2e\n",
            name, e->n, e->phi, e->on_surface, e->consistency, e->unit, e->support);
}

TEST(sphere_matches_reference) {
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_SPHERE;
    d.radius = 0.75f;
    ref_shape s = {SINEW_SHAPE_SPHERE, 0.75, 0, {0, 0, 0}};
    static const double sp[][3] = {{0, 0, 0}, {0.75, 0, 0}, {0, -0.75, 0}, {1e-300, 0, 0}};
    errs e = {0};
    run_shape(&d, &s, sp, 4, &e);
    expect(&e, "sphere");
    ENSURE(e.n == 20 * 504);
    ENSURE(e.phi < TOL && e.on_surface < TOL && e.consistency < TOL && e.unit < 1e-12 &&
           e.support < TOL);
}

TEST(capsule_matches_reference) {
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_CAPSULE;
    d.radius = 0.5f;
    d.half_height = 1.25f;
    ref_shape s = {SINEW_SHAPE_CAPSULE, 0.5, 1.25, {0, 0, 0}};
    static const double sp[][3] = {{0, 0, 0},     {0, 1.25, 0},   {0, -1.25, 0}, {0, 0.7, 0},
                                   {0, 1.75, 0},  {0.5, 1.25, 0}, {0, 0, 0.5},   {0.5, 0.3, 0},
                                   {0, -1.75, 0}, {0.3, 1.5, 0.2}};
    errs e = {0};
    run_shape(&d, &s, sp, 10, &e);
    expect(&e, "capsule");
    ENSURE(e.n == 20 * 510);
    ENSURE(e.phi < TOL && e.on_surface < TOL && e.consistency < TOL && e.unit < 1e-12 &&
           e.support < TOL);
}

TEST(box_matches_reference_with_edges_and_corners) {
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_BOX;
    d.half_extents[0] = 0.5f;
    d.half_extents[1] = 1.0f;
    d.half_extents[2] = 1.5f;
    ref_shape s = {SINEW_SHAPE_BOX, 0, 0, {0.5, 1.0, 1.5}};
    double sp[64][3];
    int ns = 0;
    for (int a = -1; a <= 1; ++a) /* centre, face centres, edge midpoints, corners */
        for (int b = -1; b <= 1; ++b)
            for (int c = -1; c <= 1; ++c) {
                sp[ns][0] = 0.5 * a, sp[ns][1] = 1.0 * b, sp[ns][2] = 1.5 * c;
                ns++;
            }
    double more[][3] = {{0.5, 1.0, 0.3},  {0.6, 1.1, 0.3}, {0.4, 0.9, 0.3}, {0.6, 1.1, 1.6},
                        {0, 0.5, 0},      {0, 0, 1.0},     {0.25, 0.75, 0}, {0.5, 1.0, 1.5},
                        {-0.5, -1, -1.5}, {0, 0.5, 1.0}};
    for (int k = 0; k < 10; ++k, ++ns)
        for (int i = 0; i < 3; ++i)
            sp[ns][i] = more[k][i];
    errs e = {0};
    run_shape(&d, &s, (const double(*)[3])sp, ns, &e);
    expect(&e, "box");
    ENSURE(e.n == 20 * (500 + ns));
    ENSURE(e.phi < TOL && e.on_surface < TOL && e.consistency < TOL && e.unit < 1e-12 &&
           e.support < TOL);
}

TEST(plane_matches_reference_and_bounds) {
    sinew_collider_def d = sinew_collider_def_default();
    d.normal[0] = 1, d.normal[1] = 2, d.normal[2] = -2; /* |n| = 3 */
    d.offset = 1.5f;                                    /* n . x = 1.5 / 3 for unit n */
    double max_err = 0;
    for (int trial = 0; trial < 20; ++trial) {
        d.transform = random_transform();
        sinew_world *w = NULL;
        sinew_collider_id id;
        const sw_collider *c = one(&w, &d, &id);
        ENSURE(c);
        for (int k = 0; k < 500; ++k) {
            double y[3] = {10 * srand1(), 10 * srand1(), 10 * srand1()}, x[3], n[3];
            double ref = (y[0] + 2 * y[1] - 2 * y[2] - 1.5) / 3.0;
            to_world(&d.transform, y, x);
            sw_collider_hit h;
            int got = sw_collider_query(c, x, 0.5, &h);
            ENSURE(got == (ref <= 0.5));
            if (!got) continue;
            to_local(&d.transform, h.normal, 0, n);
            max_err = fmax(max_err, fabs(h.phi - ref));
            max_err =
                fmax(max_err, fabs(n[0] - 1.0 / 3) + fabs(n[1] - 2.0 / 3) + fabs(n[2] + 2.0 / 3));
        }
        sinew_world_destroy(w);
    }
    fprintf(stderr, "    plane: max error %.2e\n", max_err);
    ENSURE(max_err < 1e-5);
    /* A plane facing +y at y = 2: its solid's box ends at y = 2 (plus the margin) and is
     * unbounded elsewhere. */
    sinew_collider_def f = sinew_collider_def_default();
    f.offset = 2;
    sinew_world *w = NULL;
    sinew_collider_id id;
    const sw_collider *c = one(&w, &f, &id);
    ENSURE(c);
    double lo[3], hi[3];
    sw_collider_bounds(c, 0.25, lo, hi);
    ENSURE(hi[1] == 2.25 && lo[1] == -HUGE_VAL && lo[0] == -HUGE_VAL && hi[2] == HUGE_VAL);
    sinew_world_destroy(w);
}

/* Transforms of the box: set_transform moves it; the answers equal the point moved by
 * hand into the box's frame and the answer moved back. */
TEST(moved_box_answers_as_transformed_by_hand) {
    sinew_collider_def d = sinew_collider_def_default();
    d.shape = SINEW_SHAPE_BOX;
    d.half_extents[0] = d.half_extents[1] = d.half_extents[2] = 1;
    sinew_world *w = NULL;
    sinew_collider_id id;
    const sw_collider *c = one(&w, &d, &id);
    ENSURE(c);
    double x[3] = {1.5, 0.2, 0.1};
    sw_collider_hit h0, h;
    ENSURE(sw_collider_query(c, x, 1.0, &h0));
    ENSURE_NEAR(h0.phi, 0.5, 1e-12);
    double worst = 0;
    for (int k = 0; k < 200; ++k) {
        sinew_transform t = random_transform();
        ENSURE(sinew_world_set_collider_transform(w, id, &t) == SINEW_OK);
        ENSURE(sw_world_slot(w, (uint32_t)sw_world_slot_of(w, id)) == c); /* same collider */
        double xw[3], y[3] = {srand1() * 2, srand1() * 2, srand1() * 2};
        to_world(&t, y, xw);
        ENSURE(sw_collider_query(c, xw, 3.0, &h));
        /* By hand: the axis-aligned unit box at the origin, answered in closed form. */
        double q[3], ph, best = -HUGE_VAL;
        int out = 0;
        for (int i = 0; i < 3; ++i) {
            q[i] = fmin(fmax(y[i], -1), 1);
            out |= fabs(y[i]) > 1;
            best = fmax(best, fabs(y[i]) - 1);
        }
        ph = out ? ref_dist(y, q) : best;
        double p[3];
        to_local(&t, h.point, 1, p);
        worst = fmax(worst, fabs(h.phi - ph));
        if (out) worst = fmax(worst, ref_dist(p, q));
        double R[9], tt[3];
        sw_collider_transform(c, R, tt);
        for (int i = 0; i < 3; ++i)
            worst = fmax(worst, fabs(tt[i] - t.position[i]));
    }
    fprintf(stderr, "    moved box: max deviation %.2e\n", worst);
    ENSURE(worst < 1e-5);
    sinew_world_destroy(w);
}

/* The world box of every shape holds the points the query finds within the margin. */
TEST(bounds_hold_the_solid_within_the_margin) {
    sinew_collider_def d = sinew_collider_def_default();
    sinew_shape shapes[3] = {SINEW_SHAPE_SPHERE, SINEW_SHAPE_CAPSULE, SINEW_SHAPE_BOX};
    for (int si = 0; si < 3; ++si) {
        d.shape = shapes[si];
        d.radius = 0.5f;
        d.half_height = 1.0f;
        d.half_extents[0] = 0.3f, d.half_extents[1] = 0.6f, d.half_extents[2] = 0.9f;
        d.transform = random_transform();
        sinew_world *w = NULL;
        sinew_collider_id id;
        const sw_collider *c = one(&w, &d, &id);
        ENSURE(c);
        double lo[3], hi[3], m = 0.1;
        sw_collider_bounds(c, m, lo, hi);
        for (int k = 0; k < 20000; ++k) {
            double x[3], y[3] = {3 * srand1(), 3 * srand1(), 3 * srand1()};
            to_world(&d.transform, y, x);
            sw_collider_hit h;
            if (!sw_collider_query(c, x, m, &h)) continue;
            for (int i = 0; i < 3; ++i)
                ENSUREF(x[i] >= lo[i] - 1e-9 && x[i] <= hi[i] + 1e-9, "shape %d axis %d",
                        (int)d.shape, i);
        }
        sinew_world_destroy(w);
    }
}

SW_TEST_MAIN(CASE(sphere_matches_reference), CASE(capsule_matches_reference),
             CASE(box_matches_reference_with_edges_and_corners),
             CASE(plane_matches_reference_and_bounds),
             CASE(moved_box_answers_as_transformed_by_hand),
             CASE(bounds_hold_the_solid_within_the_margin))
