/* sinew-bench's baseline (dqs_bench.h). */
#include "dqs_bench.h"

#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "dqs.h"
#include "instance.h"
#include "surface_normals.h"
#include "tool_common.h"

/* What plain skinning of the output surface reads: per output vertex its rest position
 * and 4 influences. The boundary's vertices are simulation vertices with their own; a
 * render mesh's rest positions are its embedding's, and its influences those of the
 * simulation vertex it weighs most (the blob keeps no render-vertex weights; the cost,
 * what dqs_ms times, is a 4-influence blend a vertex either way). */
typedef struct dqs_surface {
    int32_t n;
    double *X, *w; /* 3 n rest positions, 4 n weights */
    int32_t *bone; /* 4 n bone ids */
} dqs_surface;

static int dqs_surface_make(const sw_blob_view *v, dqs_surface *d) {
    d->n = sw_blob_output_verts(v);
    d->X = malloc(sizeof(double) * 3 * (size_t)d->n);
    d->w = malloc(sizeof(double) * 4 * (size_t)d->n);
    d->bone = malloc(sizeof(int32_t) * 4 * (size_t)d->n);
    if (!d->X || !d->w || !d->bone) return 0;
    sw_output_from_full(v, v->rest, d->X);
    for (int32_t s = 0; s < d->n; ++s) {
        int32_t gv;
        if (v->nrender_verts > 0) {
            const double *b = v->render_bary + 4 * (int64_t)s;
            int k = 0;
            for (int j = 1; j < 4; ++j)
                k = b[j] > b[k] ? j : k;
            gv = sw_render_node_vertex(v, v->render_tets[4 * (int64_t)v->render_tet[s] + k]);
        } else {
            const int32_t *c = v->surf_copies + 2 * (int64_t)v->surf_copy_ptr[s];
            gv = v->domain_verts[v->domains[c[0]].vert_begin + c[1]];
        }
        memcpy(d->bone + 4 * s, v->skin_bone + 4 * (int64_t)gv, 4 * sizeof(int32_t));
        memcpy(d->w + 4 * s, v->skin_weight + 4 * (int64_t)gv, 4 * sizeof(double));
    }
    return 1;
}

static void dqs_surface_free(dqs_surface *d) {
    free(d->X), free(d->w), free(d->bone);
}

/* Plain DQS of the output surface (positions and area-weighted normals over its own
 * triangles): the cost a host pays today, timed per frame over the clip, each frame's least
 * time over `passes` plays of it. */
static double dqs_ms(const sw_blob_view *v, const dqs_surface *d, const sw_clip *clip, int frames,
                     int passes, double *x, double *n) {
    double *ms = malloc((size_t)frames * sizeof(double));
    sw_dualquat dq[SW_MAX_BONES];
    for (int k = 0; k < frames * passes && ms; ++k) {
        int f = k % frames;
        const double *T = clip->T + (size_t)f * 12 * clip->nbones;
        double t0 = sw_now_seconds();
        for (int32_t b = 0; b < v->nbones; ++b)
            sw_dq_from_transform(T + 12 * b, &dq[b]);
        for (int32_t s = 0; s < d->n; ++s) {
            double R[9], t[3];
            const double *X = d->X + 3 * s;
            sw_dqs_blend(dq, d->bone + 4 * s, d->w + 4 * s, 4, R, t);
            for (int i = 0; i < 3; ++i)
                x[3 * s + i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
        }
        sw_surface_normals(d->n, x, sw_blob_output_ntris(v), sw_blob_output_tris(v), n);
        double t = 1e3 * (sw_now_seconds() - t0);
        ms[f] = k < frames || t < ms[f] ? t : ms[f];
    }
    double m = sw_median(ms, frames);
    free(ms);
    return m;
}

double sw_dqs_bench_ms(const sw_blob_view *v, const sw_clip *clip, int frames, int passes) {
    dqs_surface d;
    memset(&d, 0, sizeof d);
    size_t n3 = (size_t)sw_blob_output_verts(v) * 3 * sizeof(double);
    double *x = malloc(n3 + 1), *n = malloc(n3 + 1), ms = -1;
    if (dqs_surface_make(v, &d) && x && n)
        ms = dqs_ms(v, &d, clip, frames, passes > 0 ? passes : 1, x, n);
    dqs_surface_free(&d);
    free(x);
    free(n);
    return ms;
}
