/* Self-contact detection on two structured blocks pushed into each other (contacts
 * against the exact signed distance to the other block, none without overlap), the
 * neighbour rule, the penalty pushing the blocks apart, thread-count independence, the
 * contact cap, create's argument checks and the cost of one detect call. The BVH and
 * penalty kernels are in test_selfcontact_kernels.c; the random numbers in
 * selfcontact_fixture.h. */
#include <stdint.h>
#include <time.h>

#include "selfcontact.h"
#include "sw_test.h"

#include "selfcontact_fixture.h"

/* ---- small helpers -------------------------------------------------------------- */

static double now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

typedef struct {
    int nx, ny, nz;
    double o[3], h;
} block;

static int32_t block_nverts(const block *b) {
    return (b->nx + 1) * (b->ny + 1) * (b->nz + 1);
}
static int32_t block_ntets(const block *b) {
    return 6 * b->nx * b->ny * b->nz;
}

/* Structured blocks, each cell split into the 6 Freudenthal tets around its main
 * diagonal (conforming across cells), all positively oriented. */
static int make_blocks(const block *bs, int nb, sw_tetmesh *m) {
    memset(m, 0, sizeof *m);
    for (int b = 0; b < nb; ++b) {
        m->nverts += block_nverts(&bs[b]);
        m->ntets += block_ntets(&bs[b]);
    }
    m->X = malloc(3 * (size_t)m->nverts * sizeof(double));
    m->tets = malloc(4 * (size_t)m->ntets * sizeof(int32_t));
    if (!m->X || !m->tets) return 0;
    int32_t vbase = 0, t = 0;
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int b = 0; b < nb; ++b) {
        const block *B = &bs[b];
        int sx = B->nx + 1, sy = B->ny + 1;
        for (int k = 0; k <= B->nz; ++k)
            for (int j = 0; j <= B->ny; ++j)
                for (int i = 0; i <= B->nx; ++i) {
                    double *X = m->X + 3 * (size_t)(vbase + i + sx * (j + sy * k));
                    X[0] = B->o[0] + i * B->h;
                    X[1] = B->o[1] + j * B->h;
                    X[2] = B->o[2] + k * B->h;
                }
        for (int k = 0; k < B->nz; ++k)
            for (int j = 0; j < B->ny; ++j)
                for (int i = 0; i < B->nx; ++i)
                    for (int p = 0; p < 6; ++p) {
                        int c[4] = {0, 1 << perm[p][0], (1 << perm[p][0]) | (1 << perm[p][1]), 7};
                        int32_t *tv = m->tets + 4 * (size_t)t++;
                        for (int q = 0; q < 4; ++q)
                            tv[q] = vbase + (i + (c[q] & 1)) +
                                    sx * ((j + ((c[q] >> 1) & 1)) + sy * (k + ((c[q] >> 2) & 1)));
                        double vol = sw_tet_signed_volume(m->X + 3 * tv[0], m->X + 3 * tv[1],
                                                          m->X + 3 * tv[2], m->X + 3 * tv[3]);
                        if (vol < 0) {
                            int32_t s = tv[2];
                            tv[2] = tv[3];
                            tv[3] = s;
                        }
                    }
        vbase += block_nverts(B);
    }
    return 1;
}

typedef struct {
    int32_t k[3], tri[3];
} face_rec;

static int face_cmp(const void *pa, const void *pb) {
    const face_rec *a = pa, *b = pb;
    for (int i = 0; i < 3; ++i)
        if (a->k[i] != b->k[i]) return a->k[i] < b->k[i] ? -1 : 1;
    return 0;
}

/* Boundary faces (owned by exactly one tet), outward CCW; an in-test stand-in for
 * sw_tetmesh_surface so this test does not depend on it. */
static int make_surface(const sw_tetmesh *m, sw_surface *s) {
    static const int F[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    memset(s, 0, sizeof *s);
    size_t nf = 4 * (size_t)m->ntets;
    face_rec *f = malloc(nf * sizeof *f);
    char *used = calloc((size_t)m->nverts, 1);
    s->tris = malloc(3 * nf * sizeof(int32_t));
    s->verts = malloc((size_t)m->nverts * sizeof(int32_t));
    if (!f || !used || !s->tris || !s->verts) {
        free(f);
        free(used);
        return 0;
    }
    for (int32_t t = 0; t < m->ntets; ++t)
        for (int q = 0; q < 4; ++q) {
            face_rec *r = &f[4 * (size_t)t + q];
            for (int c = 0; c < 3; ++c)
                r->tri[c] = r->k[c] = m->tets[4 * (size_t)t + F[q][c]];
            for (int a = 0; a < 2; ++a) /* sort the key */
                for (int c = 0; c < 2 - a; ++c)
                    if (r->k[c] > r->k[c + 1]) {
                        int32_t tmp = r->k[c];
                        r->k[c] = r->k[c + 1];
                        r->k[c + 1] = tmp;
                    }
        }
    qsort(f, nf, sizeof *f, face_cmp);
    for (size_t i = 0; i < nf;) {
        size_t j = i + 1;
        while (j < nf && face_cmp(&f[i], &f[j]) == 0)
            ++j;
        if (j - i == 1) {
            memcpy(s->tris + 3 * (size_t)s->ntris++, f[i].tri, sizeof f[i].tri);
            for (int c = 0; c < 3; ++c)
                used[f[i].tri[c]] = 1;
        }
        i = j;
    }
    for (int32_t v = 0; v < m->nverts; ++v)
        if (used[v]) s->verts[s->nverts++] = v;
    free(f);
    free(used);
    return 1;
}

/* Signed distance to an axis-aligned box (negative inside) and, inside, the gap
 * between the nearest and second-nearest face (to know when the normal is unique). */
static double box_sdf(const double lo[3], const double hi[3], const double *p, double n[3],
                      double *gap) {
    double inside = 1, out2 = 0;
    for (int k = 0; k < 3; ++k) {
        double d = 0;
        if (p[k] < lo[k]) d = lo[k] - p[k];
        if (p[k] > hi[k]) d = p[k] - hi[k];
        if (d > 0) inside = 0;
        out2 += d * d;
    }
    if (!inside) return sqrt(out2);
    double best = INFINITY, second = INFINITY;
    for (int k = 0; k < 3; ++k)
        for (int s = 0; s < 2; ++s) {
            double d = s ? hi[k] - p[k] : p[k] - lo[k];
            if (d < best) {
                second = best;
                best = d;
                n[0] = n[1] = n[2] = 0;
                n[k] = s ? 1 : -1;
            } else if (d < second) {
                second = d;
            }
        }
    *gap = second - best;
    return -best;
}

/* ---- detection -------------------------------------------------------------------- */

/* Block A = [0,1]^3; block B = [1+GAP, 1.5+GAP] x [0.25,0.75]^2 at rest, translated by
 * -shift along x in the deformed state. The rest gap is wider than the neighbour
 * radius (1.8 longest edges), else the two blocks would be rest-space neighbours. */
#define GAP 1.25
typedef struct {
    sw_tetmesh m;
    sw_surface s;
    int32_t nA; /* vertices of A come first */
} two_blocks;

static int two_blocks_make(two_blocks *tb, int na, int nbk) {
    block bs[2] = {{na, na, na, {0, 0, 0}, 1.0 / na},
                   {nbk, nbk, nbk, {1 + GAP, 0.25, 0.25}, 0.5 / nbk}};
    tb->nA = block_nverts(&bs[0]);
    return make_blocks(bs, 2, &tb->m) && make_surface(&tb->m, &tb->s);
}

static void two_blocks_free(two_blocks *tb) {
    sw_tetmesh_free(&tb->m);
    sw_surface_free(&tb->s);
}

static void deform_shift(const two_blocks *tb, double shift, double *x) {
    memcpy(x, tb->m.X, 3 * (size_t)tb->m.nverts * sizeof(double));
    for (int32_t v = tb->nA; v < tb->m.nverts; ++v)
        x[3 * v] -= shift;
}

TEST(detect_overlapping_blocks) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 4, 2));
    sw_selfcontact *sc = NULL;
    sw_error err;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_OK);
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    ENSURE(x);
    const double pen = 0.1;
    deform_shift(&tb, GAP + pen, x);
    double Alo[3] = {0, 0, 0}, Ahi[3] = {1, 1, 1};
    double Blo[3] = {1 - pen, 0.25, 0.25}, Bhi[3] = {1.5 - pen, 0.75, 0.75};
    int32_t n = sw_selfcontact_detect(sc, x, NULL);
    int32_t count = -1;
    const sw_contact *c = sw_selfcontact_list(sc, &count);
    ENSURE(count == n);
    /* the truth: surface vertices strictly inside the other block */
    int32_t expected = 0, maxi = 0;
    for (int32_t i = 0; i < tb.s.nverts; ++i) {
        int32_t v = tb.s.verts[i];
        int inA = v < tb.nA;
        double nn[3], gap;
        double sdf = box_sdf(inA ? Blo : Alo, inA ? Bhi : Ahi, x + 3 * v, nn, &gap);
        if (sdf < -1e-6) {
            ++expected;
            while (maxi < n && c[maxi].p < v)
                ++maxi;
            ENSUREF(maxi < n && c[maxi].p == v, "vertex %d at depth %g has no contact", (int)v,
                    -sdf);
        }
    }
    ENSUREF(n == expected, "%d contacts, %d vertices inside the other block", (int)n,
            (int)expected);
    ENSURE(n == 9 + 1); /* B's -x face (3x3) and A's vertex at (1, .5, .5) */
    double maxd = 0;
    for (int32_t i = 0; i < n; ++i) {
        int inA = c[i].p < tb.nA;
        const double *lo = inA ? Blo : Alo, *hi = inA ? Bhi : Ahi;
        const double *xp = x + 3 * c[i].p;
        double nn[3], gap;
        double sdf = box_sdf(lo, hi, xp, nn, &gap);
        ENSURE_NEAR(c[i].depth, -sdf, 1e-9);
        ENSURE_NEAR(c[i].depth, pen, 1e-9);
        ENSURE(i == 0 || c[i].p > c[i - 1].p); /* surface vertex order */
        for (int k = 0; k < 3; ++k)
            ENSURE(inA ? c[i].tri[k] >= tb.nA : c[i].tri[k] < tb.nA);
        /* v_s = v_p + depth n lies on the other block's surface */
        double vs[3], dummy[3], g2;
        for (int k = 0; k < 3; ++k)
            vs[k] = xp[k] + c[i].depth * c[i].n[k];
        ENSURE(fabs(box_sdf(lo, hi, vs, dummy, &g2)) < 1e-9);
        if (gap > 1e-6) /* unique nearest face: n is its outward normal */
            for (int k = 0; k < 3; ++k)
                ENSURE_NEAR(c[i].n[k], nn[k], 1e-9);
        ENSURE_NEAR(c[i].n[0], inA ? -1 : 1, 1e-9);
        double bs = c[i].beta[0] + c[i].beta[1] + c[i].beta[2];
        ENSURE_NEAR(bs, 1, 1e-12);
        ENSURE(c[i].ka > 0);
        if (c[i].depth > maxd) maxd = c[i].depth;
    }
    ENSURE_NEAR(sw_selfcontact_max_depth(sc), maxd, 0);
    /* ka = (one-ring area + triangle area) / 4; every surface triangle of both blocks
     * is half a 0.25 x 0.25 cell here. */
    for (int32_t i = 0; i < n; ++i) {
        int ring = 0;
        for (int32_t t = 0; t < tb.s.ntris; ++t)
            ring += tb.s.tris[3 * t] == c[i].p || tb.s.tris[3 * t + 1] == c[i].p ||
                    tb.s.tris[3 * t + 2] == c[i].p;
        ENSURE(ring >= 3);
        ENSURE_NEAR(c[i].ka, (ring + 1) * 0.03125 / 4, 1e-12);
    }
    free(x);
    sw_selfcontact_destroy(sc);
    two_blocks_free(&tb);
}

TEST(no_contacts_without_overlap) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 4, 2));
    sw_selfcontact *sc = NULL;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, NULL) == SINEW_OK);
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    ENSURE(x);
    const double shifts[3] = {0, GAP - 0.05, GAP}; /* rest pose, a gap, exactly touching */
    for (int s = 0; s < 3; ++s) {
        deform_shift(&tb, shifts[s], x);
        ENSUREF(sw_selfcontact_detect(sc, x, NULL) == 0, "shift %g", shifts[s]);
        ENSURE(sw_selfcontact_max_depth(sc) == 0);
    }
    /* and a sanity check that the same mesh does see the overlap */
    deform_shift(&tb, GAP + 0.05, x);
    ENSURE(sw_selfcontact_detect(sc, x, NULL) > 0);
    free(x);
    sw_selfcontact_destroy(sc);
    two_blocks_free(&tb);
}

TEST(neighbour_rule_skips_own_fold) {
    /* One 8^3 block; push the top-face centre vertex into the block, through its own
     * incident tets, so that it lands inside tets of its own neighbourhood. */
    block b = {8, 8, 8, {0, 0, 0}, 1.0 / 8};
    sw_tetmesh m;
    sw_surface s;
    ENSURE(make_blocks(&b, 1, &m) && make_surface(&m, &s));
    double h = b.h;
    int32_t p = 4 + 9 * (4 + 9 * 8);
    ENSURE(fabs(m.X[3 * p] - 0.5) < 1e-15 && fabs(m.X[3 * p + 2] - 1) < 1e-15);
    double *x = malloc(3 * (size_t)m.nverts * sizeof(double));
    ENSURE(x);
    const double moves[2][3] = {{0, 0, -1.2 * h},
                                {2 * h, 0, -1.2 * h}}; /* straight in; in and aside */
    for (int mv = 0; mv < 2; ++mv) {
        memcpy(x, m.X, 3 * (size_t)m.nverts * sizeof(double));
        for (int k = 0; k < 3; ++k)
            x[3 * p + k] += moves[mv][k];
        sw_selfcontact *sc = NULL;
        ENSURE(sw_selfcontact_create(&m, &s, 1.8, 0, &sc, NULL) == SINEW_OK);
        int32_t n = sw_selfcontact_detect(sc, x, NULL);
        sw_selfcontact_destroy(sc);
        ENSUREF(n == 0, "move %d: %d contacts from the vertex's own fold", mv, (int)n);
        if (mv == 1) {
            /* Without the rule (factor 0) the sideways move is a contact with the top
             * face 2h away: the rule, not a detection miss, removed it. */
            ENSURE(sw_selfcontact_create(&m, &s, 0.0, 0, &sc, NULL) == SINEW_OK);
            n = sw_selfcontact_detect(sc, x, NULL);
            int32_t cnt;
            const sw_contact *c = sw_selfcontact_list(sc, &cnt);
            int found = 0;
            for (int32_t i = 0; i < cnt; ++i)
                if (c[i].p == p) {
                    found = 1;
                    ENSURE_NEAR(c[i].depth, 1.2 * h, 1e-9);
                    ENSURE_NEAR(c[i].n[2], 1, 1e-9);
                }
            sw_selfcontact_destroy(sc);
            ENSUREF(found, "factor 0: %d contacts, none for the moved vertex", (int)n);
        }
    }
    free(x);
    sw_tetmesh_free(&m);
    sw_surface_free(&s);
}

static double total_depth(const sw_selfcontact *sc) {
    int32_t n;
    const sw_contact *c = sw_selfcontact_list(sc, &n);
    double t = 0;
    for (int32_t i = 0; i < n; ++i)
        t += c[i].depth;
    return t;
}

TEST(penalty_pushes_blocks_apart) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 4, 2));
    sw_selfcontact *sc = NULL;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, NULL) == SINEW_OK);
    size_t nv = (size_t)tb.m.nverts;
    double *x = malloc(3 * nv * sizeof(double)), *f = malloc(3 * nv * sizeof(double));
    ENSURE(x && f);
    deform_shift(&tb, GAP + 0.1, x);
    const double kc = 1, alpha = 0.5;
    ENSURE(sw_selfcontact_detect(sc, x, NULL) > 0);
    double first = total_depth(sc), prev = first;
    for (int step = 0; step < 6; ++step) {
        int32_t n;
        const sw_contact *c = sw_selfcontact_list(sc, &n);
        double kmax = 0;
        for (int32_t i = 0; i < n; ++i)
            kmax = fmax(kmax, kc * c[i].ka);
        memset(f, 0, 3 * nv * sizeof(double));
        sw_contact_add_forces(c, n, x, kc, alpha, f);
        double eta = 0.3 / kmax; /* explicit step well inside stability */
        for (size_t i = 0; i < 3 * nv; ++i)
            x[i] += eta * f[i];
        sw_selfcontact_detect(sc, x, NULL);
        double now = total_depth(sc);
        ENSUREF(now < prev, "step %d: total depth %g -> %g", step, prev, now);
        prev = now;
    }
    ENSUREF(prev < 0.5 * first, "total depth %g -> %g", first, prev);
    free(x);
    free(f);
    sw_selfcontact_destroy(sc);
    two_blocks_free(&tb);
}

/* A larger, messier overlap: B (rotated slightly, jittered) inside A. */
static void messy_overlap(const two_blocks *tb, double *x, uint64_t seed) {
    rng_state = seed;
    memcpy(x, tb->m.X, 3 * (size_t)tb->m.nverts * sizeof(double));
    double c = cos(0.3), s = sin(0.3);
    for (int32_t v = tb->nA; v < tb->m.nverts; ++v) {
        double *p = x + 3 * v, y = p[1] - 0.5, z = p[2] - 0.5;
        p[0] -= GAP + 0.5;
        p[1] = 0.5 + c * y - s * z;
        p[2] = 0.5 + s * y + c * z;
    }
    for (int32_t v = 0; v < tb->m.nverts; ++v)
        for (int k = 0; k < 3; ++k)
            x[3 * v + k] += 0.01 * srand1();
}

TEST(detect_is_independent_of_thread_count) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 8, 6));
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    sw_contact *ref = malloc((size_t)tb.s.nverts * sizeof(sw_contact));
    ENSURE(x && ref);
    messy_overlap(&tb, x, 42);
    sw_selfcontact *sc = NULL;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, NULL) == SINEW_OK);
    int32_t n0 = sw_selfcontact_detect(sc, x, NULL);
    ENSURE(n0 > 20);
    memcpy(ref, sw_selfcontact_list(sc, NULL), (size_t)n0 * sizeof(sw_contact));
    double d0 = sw_selfcontact_max_depth(sc);
    for (int threads = 2; threads <= 3; ++threads) {
        sw_pool *pool = sw_pool_create(threads);
        ENSURE(pool);
        for (int rep = 0; rep < 3; ++rep) {
            int32_t n = sw_selfcontact_detect(sc, x, pool);
            int32_t cnt;
            const sw_contact *c = sw_selfcontact_list(sc, &cnt);
            int same = n == n0 && cnt == n0 &&
                       memcmp(c, ref, (size_t)n0 * sizeof(sw_contact)) == 0 &&
                       sw_selfcontact_max_depth(sc) == d0;
            if (!same) sw_pool_destroy(pool);
            ENSUREF(same, "%d threads: %d contacts vs %d serially", threads, (int)n, (int)n0);
        }
        sw_pool_destroy(pool);
    }
    free(x);
    free(ref);
    sw_selfcontact_destroy(sc);
    two_blocks_free(&tb);
}

TEST(max_contacts_keeps_the_deepest) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 8, 6));
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    sw_contact *all = malloc((size_t)tb.s.nverts * sizeof(sw_contact));
    ENSURE(x && all);
    messy_overlap(&tb, x, 7);
    sw_selfcontact *sc = NULL, *capped = NULL;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, NULL) == SINEW_OK);
    const int32_t cap = 15;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, cap, &capped, NULL) == SINEW_OK);
    int32_t n = sw_selfcontact_detect(sc, x, NULL);
    ENSURE(n > cap);
    memcpy(all, sw_selfcontact_list(sc, NULL), (size_t)n * sizeof(sw_contact));
    sw_pool *pool = sw_pool_create(2);
    ENSURE(pool);
    int32_t m = sw_selfcontact_detect(capped, x, pool);
    sw_pool_destroy(pool);
    ENSURE(m == cap);
    const sw_contact *c = sw_selfcontact_list(capped, NULL);
    /* the kept ones: in vertex order, each identical to the full list's entry, and no
     * dropped contact deeper than the shallowest kept one */
    double shallowest = INFINITY;
    for (int32_t i = 0; i < m; ++i) {
        ENSURE(i == 0 || c[i].p > c[i - 1].p);
        int32_t j = 0;
        while (j < n && all[j].p != c[i].p)
            ++j;
        ENSURE(j < n && memcmp(&all[j], &c[i], sizeof c[i]) == 0);
        shallowest = fmin(shallowest, c[i].depth);
    }
    int32_t deeper = 0;
    for (int32_t j = 0; j < n; ++j)
        deeper += all[j].depth > shallowest;
    ENSURE(deeper <= cap - 1);
    ENSURE_NEAR(sw_selfcontact_max_depth(capped), sw_selfcontact_max_depth(sc), 0);
    free(x);
    free(all);
    sw_selfcontact_destroy(sc);
    sw_selfcontact_destroy(capped);
    two_blocks_free(&tb);
}

TEST(create_rejects_bad_input) {
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 2, 1));
    sw_selfcontact *sc = (sw_selfcontact *)&tb; /* must be reset to NULL on error */
    sw_error err;
    ENSURE(sw_selfcontact_create(NULL, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sc == NULL);
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, -1, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, NAN, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, -3, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    int32_t keep = tb.s.tris[4];
    tb.s.tris[4] = tb.m.nverts + 5; /* not a surface vertex */
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "triangle 1") != NULL);
    tb.s.tris[4] = keep;
    int32_t kv = tb.s.verts[1];
    tb.s.verts[1] = tb.s.verts[0]; /* not ascending */
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    tb.s.verts[1] = kv;
    keep = tb.m.tets[7];
    tb.m.tets[7] = -1;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "tet 1") != NULL);
    tb.m.tets[7] = keep;
    /* a zero-area rest triangle: collapse one surface triangle's vertex onto another */
    int32_t a = tb.s.tris[0], b = tb.s.tris[1];
    double save[3];
    memcpy(save, tb.m.X + 3 * b, sizeof save);
    memcpy(tb.m.X + 3 * b, tb.m.X + 3 * a, sizeof save);
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_DEGENERATE);
    memcpy(tb.m.X + 3 * b, save, sizeof save);
    tb.m.X[5] = NAN;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_ERROR_NOT_FINITE);
    ENSURE(strstr(err.msg, "vertex 1") != NULL);
    tb.m.X[5] = 0;
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, &err) == SINEW_OK);
    /* NULL-tolerant accessors and a NaN state: no crash, no contacts */
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    ENSURE(x);
    for (int32_t i = 0; i < 3 * tb.m.nverts; ++i)
        x[i] = NAN;
    ENSURE(sw_selfcontact_detect(sc, x, NULL) == 0);
    ENSURE(sw_selfcontact_detect(sc, NULL, NULL) == 0);
    ENSURE(sw_selfcontact_detect(NULL, x, NULL) == 0);
    free(x);
    sw_selfcontact_destroy(sc);
    sw_selfcontact_destroy(NULL);
    two_blocks_free(&tb);
}

TEST(detect_cost_on_50k_tets) {
    /* Two 16^3-cell blocks (49152 tets), B pushed deep into A and jittered. */
    two_blocks tb;
    ENSURE(two_blocks_make(&tb, 16, 16));
    ENSURE(tb.m.ntets == 2 * 6 * 16 * 16 * 16);
    double *x = malloc(3 * (size_t)tb.m.nverts * sizeof(double));
    ENSURE(x);
    messy_overlap(&tb, x, 99);
    sw_selfcontact *sc = NULL;
    double t0 = now_ms();
    ENSURE(sw_selfcontact_create(&tb.m, &tb.s, 1.8, 0, &sc, NULL) == SINEW_OK);
    double t1 = now_ms();
    const int reps = 5;
    int32_t n = 0;
    for (int r = 0; r < reps; ++r)
        n = sw_selfcontact_detect(sc, x, NULL);
    double t2 = now_ms();
    sw_pool *pool = sw_pool_create(2);
    ENSURE(pool);
    int32_t n2 = 0;
    for (int r = 0; r < reps; ++r)
        n2 = sw_selfcontact_detect(sc, x, pool);
    double t3 = now_ms();
    sw_pool_destroy(pool);
    ENSURE(n > 100 && n2 == n);
    printf("selfcontact: %d tets, %d surface verts, %d contacts: create %.1f ms, detect %.2f ms (1 "
           "thread), "
           "%.2f ms (2 threads)\n",
           (int)tb.m.ntets, (int)tb.s.nverts, (int)n, t1 - t0, (t2 - t1) / reps, (t3 - t2) / reps);
    ENSURE((t2 - t1) / reps < 2000); /* generous: ASan on a slow machine */
    free(x);
    sw_selfcontact_destroy(sc);
    two_blocks_free(&tb);
}

SW_TEST_MAIN(CASE(detect_overlapping_blocks), CASE(no_contacts_without_overlap),
             CASE(neighbour_rule_skips_own_fold), CASE(penalty_pushes_blocks_apart),
             CASE(detect_is_independent_of_thread_count), CASE(max_contacts_keeps_the_deepest),
             CASE(create_rejects_bad_input), CASE(detect_cost_on_50k_tets))
