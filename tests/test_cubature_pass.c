/* The runtime's cubature pass (runtime/fem/cubature.c): each tet corner placed once for
 * all its tets, the forces summed on the corners and projected a corner at a time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_fixture.h"
#include "cubature.h"
#include "fem_corot.h"
#include "instance.h"
#include "instance_internal.h"
#include "sw_test.h"

static bake_fixture fx;
static int fx_ok = -1;

static const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 3000, 12, 1);
    return fx_ok ? &fx : NULL;
}

/* An instance of the fixture at the clip's most bent frame, its active vertices skinned. */
static sinew_instance *bent_instance(sinew_newton_hessian h) {
    const bake_fixture *f = fixture();
    if (!f) return NULL;
    sinew_instance_def d = sinew_instance_def_default();
    d.newton_hessian = h;
    sinew_instance *in;
    if (sinew_instance_create(f->blob, &d, &in) != SINEW_OK) return NULL;
    const double *T =
        f->ch.clip.T + (size_t)(f->ch.clip.nframes / 2) * 12 * (size_t)f->ch.skel.nbones;
    if (sw_instance_set_pose_d(in, T) != SINEW_OK) {
        sinew_instance_destroy(in);
        return NULL;
    }
    sw_reduced_skin(&in->red, in->bone_dq);
    return in;
}

static int cmp_int(const void *a, const void *b) {
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Every cubature tet corner names a corner of its own domain with its local vertex and
 * active index, and each domain lists each of its tets' vertices once, ascending. */
TEST(corners_list_each_cubature_vertex_once_in_its_domain) {
    sinew_instance *in = bent_instance(SINEW_NEWTON_HESSIAN_AUTO);
    ENSURE(in);
    const sw_reduced *m = &in->red;
    const sw_blob_view *v = in->v;
    int32_t refs = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t n = 4 * D->cub_count, b = m->corner_begin[k], e = m->corner_begin[k + 1];
        int32_t *lv = malloc(sizeof(int32_t) * (size_t)(n > 0 ? n : 1)), uniq = 0;
        ENSURE(lv);
        memcpy(lv, v->cub_tets + 4 * (int64_t)D->cub_begin, sizeof(int32_t) * (size_t)n);
        qsort(lv, (size_t)n, sizeof(int32_t), cmp_int);
        for (int32_t i = 0; i < n; ++i)
            uniq += i == 0 || lv[i] != lv[i - 1];
        free(lv);
        ENSUREF(e - b == uniq, "domain %d: %d corners for %d distinct vertices", k, e - b, uniq);
        for (int32_t i = b + 1; i < e; ++i)
            ENSURE(m->corner_lv[i] > m->corner_lv[i - 1]);
        for (int32_t i = 4 * D->cub_begin; i < 4 * (D->cub_begin + D->cub_count); ++i) {
            int32_t c = m->cub_corner[i];
            ENSURE(c >= b && c < e);
            ENSURE(m->corner_lv[c] == v->cub_tets[i] && m->corner_act[c] == m->cub_act[i]);
        }
        refs += n;
    }
    ENSURE(m->corner_begin[v->ndomains] == m->ncorner);
    fprintf(stderr, "    %d tet corners on %d corners\n", refs, m->ncorner);
    ENSURE(m->ncorner < refs); /* the fixture's tets share vertices: the test can tell */
    sinew_instance_destroy(in);
}

/* The gradient pass (forces summed on the corners, then projected a corner at a time)
 * against each tet's own w J^T f with J from sw_reduced_position, at a bent pose and a
 * state away from 0: the same energy, the same gradient to rounding. */
TEST(corner_gradient_equals_the_tets_own_projection) {
    sinew_instance *in = bent_instance(SINEW_NEWTON_HESSIAN_AUTO);
    ENSURE(in);
    sw_reduced *m = &in->red;
    const sw_blob_view *v = in->v;
    int32_t R = v->rank_total;
    double *q = malloc(sizeof(double) * (size_t)R), *g = calloc((size_t)R, sizeof(double)),
           *J = malloc(sizeof(double) * 12 * (size_t)m->rmax);
    ENSURE(q && g && J);
    uint64_t seed = 7;
    for (int32_t i = 0; i < R; ++i) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        q[i] = 0.02 * ((double)(seed >> 11) * 0x1.0p-53 - 0.5);
    }
    double E = 0;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        int32_t r = D->rank, o = D->q_offset;
        for (int32_t c = D->cub_begin; c < D->cub_begin + D->cub_count; ++c) {
            double x[12], f[12];
            for (int n = 0; n < 4; ++n)
                sw_reduced_position(m, D, v->cub_tets[4 * c + n], m->cub_act[4 * c + n], q + o,
                                    x + 3 * n, J + 3 * n * r);
            double w = m->cub_w[c];
            E += w * sw_corot_eval(x, v->cub_dminv + 9 * c, v->cub_vol[c], v->mu, v->lambda, f,
                                   NULL, SW_COROT_PROJECT_PSD);
            for (int32_t j = 0; j < r; ++j)
                for (int row = 0; row < 12; ++row)
                    g[o + j] -= w * J[row * r + j] * f[row];
        }
    }
    memset(m->g, 0, sizeof(double) * (size_t)R);
    double Ep = sw_cubature_eval(m, q, 1, 0), gap = 0, top = 0;
    for (int32_t i = 0; i < R; ++i) {
        gap = fmax(gap, fabs(m->g[i] - g[i]));
        top = fmax(top, fabs(g[i]));
    }
    fprintf(stderr, "    energy %.12g against %.12g; gradient %.2e of its largest entry %.3g\n", Ep,
            E, gap / top, top);
    ENSUREF(fabs(Ep - E) <= 1e-12 * fabs(E), "energy %.17g, the tets' own %.17g", Ep, E);
    ENSUREF(top > 0 && gap <= 1e-11 * top, "gradient %g from the tets' own (largest %g)", gap, top);
    free(q), free(g), free(J);
    sinew_instance_destroy(in);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(corners_list_each_cubature_vertex_once_in_its_domain),
             CASE(corner_gradient_equals_the_tets_own_projection), CASE(release_fixture))
