/* Triangle-mesh colliders: validated at add time (finite, indices in range, no
 * zero-area triangle, each undirected edge on at most two triangles and oriented
 * oppositely by them), their angle-weighted pseudonormals precomputed (Bærentzen and
 * Aanæs 2005: the sign of (x - c) . n_feature is the inside/outside test for the closest
 * feature of a closed mesh), and an Embree scene committed at add time and again when
 * the host moves the vertices (mesh_update.c; a triangle a move collapsed is skipped
 * here). Queries pick the closest triangle exactly, whatever the BVH, so a moved mesh
 * answers as one added where it is now. The query is one rtcPointQuery with a finite radius: Embree
 * culls the BVH, our callback computes the exact closest point on each candidate triangle (Ericson,
 * Real-Time Collision Detection §5.1.5) in double precision and shrinks the radius. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "collision_internal.h"

/* The closest feature of a triangle: its face, a corner or an edge (from corner e). */
enum { FEAT_FACE = 0, FEAT_VERTEX = 1, FEAT_EDGE = 4 };

/* The closest point c of triangle (a, b, d) to p, and its feature: FEAT_FACE,
 * FEAT_VERTEX + corner, FEAT_EDGE + edge (edge e runs from corner e to e + 1). */
static int closest_on_triangle(const double p[3], const double a[3], const double b[3],
                               const double d[3], double c[3]) {
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    sw_v3_sub(b, a, ab);
    sw_v3_sub(d, a, ac);
    sw_v3_sub(p, a, ap);
    double d1 = sw_v3_dot(ab, ap), d2 = sw_v3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return memcpy(c, a, 3 * sizeof(double)), FEAT_VERTEX + 0;
    sw_v3_sub(p, b, bp);
    double d3 = sw_v3_dot(ab, bp), d4 = sw_v3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return memcpy(c, b, 3 * sizeof(double)), FEAT_VERTEX + 1;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int i = 0; i < 3; ++i)
            c[i] = a[i] + v * ab[i];
        return FEAT_EDGE + 0;
    }
    sw_v3_sub(p, d, cp);
    double d5 = sw_v3_dot(ab, cp), d6 = sw_v3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return memcpy(c, d, 3 * sizeof(double)), FEAT_VERTEX + 2;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int i = 0; i < 3; ++i)
            c[i] = a[i] + w * ac[i];
        return FEAT_EDGE + 2;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int i = 0; i < 3; ++i)
            c[i] = b[i] + w * (d[i] - b[i]);
        return FEAT_EDGE + 1;
    }
    double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int i = 0; i < 3; ++i)
        c[i] = a[i] + ab[i] * v + ac[i] * w;
    return FEAT_FACE;
}

/* The best triangle so far of one query (the callback's user data, on the stack). */
typedef struct closest {
    const sw_mesh *m;
    double p[3];
    double d2;     /* squared distance of the best, HUGE_VAL before any */
    double c[3];   /* its closest point */
    uint32_t tri;  /* its triangle */
    int feature;   /* and feature */
    double margin; /* added to the radius for Embree's float boxes */
} closest;

static bool on_triangle(struct RTCPointQueryFunctionArguments *args) {
    closest *q = args->userPtr;
    const sw_mesh *m = q->m;
    uint32_t t = args->primID;
    if (m->dead[t]) return false; /* collapsed by a move (mesh_update.c) */
    const uint32_t *v = m->tris + 3 * t;
    double c[3];
    int f = closest_on_triangle(q->p, m->X + 3 * v[0], m->X + 3 * v[1], m->X + 3 * v[2], c);
    double d2 = 0;
    for (int i = 0; i < 3; ++i)
        d2 += (q->p[i] - c[i]) * (q->p[i] - c[i]);
    /* Ties go to the lower triangle index, so the answer does not depend on the order in
     * which Embree visits the leaves. */
    if (d2 > q->d2 || (d2 == q->d2 && t > q->tri)) return false;
    q->d2 = d2;
    q->tri = t;
    q->feature = f;
    memcpy(q->c, c, sizeof c);
    float r = (float)(sqrt(d2) + q->margin);
    if (!(r < args->query->radius)) return false;
    args->query->radius = r;
    return true;
}

/* The pseudonormal of the best feature (unit). */
static const double *feature_normal(const sw_mesh *m, uint32_t t, int f) {
    if (f == FEAT_FACE) return m->face_n + 3 * t;
    if (f < FEAT_EDGE) return m->vert_n + 3 * m->tris[3 * t + (uint32_t)(f - FEAT_VERTEX)];
    return m->edge_n + 9 * t + 3 * (f - FEAT_EDGE);
}

/* One point query of radius r; 1 when a triangle was within it. */
static int nearest(const sw_mesh *m, closest *q, double r) {
    struct RTCPointQuery pq;
    pq.x = (float)q->p[0];
    pq.y = (float)q->p[1];
    pq.z = (float)q->p[2];
    pq.time = 0;
    pq.radius = (float)(r + q->margin);
    struct RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    q->d2 = HUGE_VAL;
    q->tri = UINT32_MAX;
    rtcPointQuery(m->scene, &pq, &ctx, on_triangle, q);
    return q->tri != UINT32_MAX && sqrt(q->d2) <= r;
}

/* Within `radius`, or deep inside: when nothing is that near and y is in the mesh's box,
 * a second query with the box's diagonal (still finite) finds the closest triangle, and
 * its pseudonormal says whether y is inside. */
int sw_mesh_query(const sw_collider *c, const double y[3], double radius, sw_collider_hit *h) {
    const sw_mesh *m = &c->mesh;
    closest q = {m, {y[0], y[1], y[2]}, HUGE_VAL, {0, 0, 0}, 0, 0, 0};
    double ymax = fmax(fmax(fabs(y[0]), fabs(y[1])), fabs(y[2]));
    q.margin = 8 * FLT_EPSILON * (m->diagonal + ymax) + 1e-30;
    int near = nearest(m, &q, radius);
    if (!near) {
        for (int i = 0; i < 3; ++i)
            if (!(y[i] >= c->lo[i] && y[i] <= c->hi[i])) return 0;
        if (!nearest(m, &q, m->diagonal)) return 0;
    }
    const double *pn = feature_normal(m, q.tri, q.feature);
    double v[3];
    sw_v3_sub(y, q.c, v);
    double s = sw_v3_dot(v, pn) < 0 ? -1.0 : 1.0, d = sw_v3_normalize(v);
    if (!near && s > 0) return 0; /* outside and farther than the radius */
    h->phi = s * d;
    for (int i = 0; i < 3; ++i) {
        h->point[i] = q.c[i];
        /* On the surface (or so close that v has no direction): the feature's normal. */
        h->normal[i] = d > 1e-12 * (m->diagonal + ymax) ? s * v[i] : pn[i];
    }
    return 1;
}
