/* Generalised winding numbers, exact and through a dipole tree (winding.h). */
#include "winding.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vec3.h"

/* Clusters farther than this many radii count as one dipole (the error falls as
 * 1 / beta^2; docs/notes/outside-the-harness.md has the test sphere's figures). */
#define SW_WINDING_BETA 4.0
#define SW_WINDING_LEAF 8

/* Solid angle of triangle (a, b, c) seen from p (Van Oosterom and Strackee). */
static double solid_angle(const double *xa, const double *xb, const double *xc, const double p[3]) {
    double a[3], b[3], c[3];
    sw_v3_sub(xa, p, a);
    sw_v3_sub(xb, p, b);
    sw_v3_sub(xc, p, c);
    double la = sw_v3_norm(a), lb = sw_v3_norm(b), lc = sw_v3_norm(c);
    double den = la * lb * lc + sw_v3_dot(a, b) * lc + sw_v3_dot(b, c) * la + sw_v3_dot(c, a) * lb;
    return 2.0 * atan2(sw_v3_triple(a, b, c), den);
}

static double four_pi(void) {
    return 16.0 * atan(1.0);
}

double sw_winding_number(const sw_trimesh *surf, const double p[3]) {
    double sum = 0;
    for (int32_t t = 0; t < surf->ntris; ++t) {
        const int32_t *f = surf->tris + 3 * t;
        sum += solid_angle(surf->X + 3 * (size_t)f[0], surf->X + 3 * (size_t)f[1],
                           surf->X + 3 * (size_t)f[2], p);
    }
    return sum / four_pi();
}

typedef struct {
    double c[3];   /* area centroid */
    double N[3];   /* sum of the triangles' area vectors (1/2 (b - a) x (c - a)) */
    double r;      /* largest distance from c to a vertex of the cluster */
    int32_t begin; /* triangles order[begin, end) */
    int32_t end;
    int32_t child; /* first of two children (child + 1 the second), -1 for a leaf */
} wnode;

struct sw_winding_tree {
    const sw_trimesh *surf;
    int32_t *order;
    double *centroid; /* 3 per triangle */
    wnode *node;
    int32_t nnodes, depth;
};

static const double *vert(const sw_winding_tree *t, int32_t tri, int k) {
    return t->surf->X + 3 * (size_t)t->surf->tris[3 * (size_t)tri + k];
}

/* Fills node n's moments from its triangles. */
static void node_moments(sw_winding_tree *t, wnode *n) {
    double area = 0, c[3] = {0, 0, 0};
    memset(n->N, 0, sizeof n->N);
    for (int32_t i = n->begin; i < n->end; ++i) {
        int32_t tri = t->order[i];
        double e1[3], e2[3], A[3];
        sw_v3_sub(vert(t, tri, 1), vert(t, tri, 0), e1);
        sw_v3_sub(vert(t, tri, 2), vert(t, tri, 0), e2);
        sw_v3_cross(e1, e2, A);
        double a = 0.5 * sw_v3_norm(A);
        for (int k = 0; k < 3; ++k) {
            n->N[k] += 0.5 * A[k];
            c[k] += a * t->centroid[3 * (size_t)tri + k];
        }
        area += a;
    }
    for (int k = 0; k < 3; ++k) /* degenerate clusters: the plain centroid of the first */
        n->c[k] = area > 0 ? c[k] / area : t->centroid[3 * (size_t)t->order[n->begin] + k];
    n->r = 0;
    for (int32_t i = n->begin; i < n->end; ++i)
        for (int k = 0; k < 3; ++k)
            n->r = fmax(n->r, sw_v3_dist(vert(t, t->order[i], k), n->c));
}

/* Splits order[begin, end) at its middle by centroid along `axis` (quickselect). */
static void select_median(sw_winding_tree *t, int32_t begin, int32_t end, int axis) {
    int32_t mid = begin + (end - begin) / 2, lo = begin, hi = end - 1;
    while (lo < hi) {
        double pivot = t->centroid[3 * (size_t)t->order[lo + (hi - lo) / 2] + axis];
        int32_t i = lo, j = hi;
        while (i <= j) {
            while (t->centroid[3 * (size_t)t->order[i] + axis] < pivot)
                ++i;
            while (t->centroid[3 * (size_t)t->order[j] + axis] > pivot)
                --j;
            if (i <= j) {
                int32_t s = t->order[i];
                t->order[i++] = t->order[j];
                t->order[j--] = s;
            }
        }
        if (mid <= j)
            hi = j;
        else if (mid >= i)
            lo = i;
        else
            break;
    }
}

/* Builds node `at` over order[begin, end) and its subtree; returns the tree depth. */
static int build(sw_winding_tree *t, int32_t at, int32_t begin, int32_t end) {
    wnode *n = &t->node[at];
    n->begin = begin;
    n->end = end;
    n->child = -1;
    node_moments(t, n);
    if (end - begin <= SW_WINDING_LEAF) return 1;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = begin; i < end; ++i)
        for (int k = 0; k < 3; ++k) {
            double v = t->centroid[3 * (size_t)t->order[i] + k];
            lo[k] = fmin(lo[k], v);
            hi[k] = fmax(hi[k], v);
        }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    select_median(t, begin, end, axis);
    int32_t mid = begin + (end - begin) / 2, child = t->nnodes;
    t->nnodes += 2;
    t->node[at].child = child; /* n may not be used after the recursion (same array) */
    int dl = build(t, child, begin, mid), dr = build(t, child + 1, mid, end);
    return 1 + (dl > dr ? dl : dr);
}

sw_winding_tree *sw_winding_tree_create(const sw_trimesh *surf) {
    sw_winding_tree *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    int32_t nt = surf->ntris;
    t->surf = surf;
    t->order = malloc((size_t)(nt > 0 ? nt : 1) * sizeof(int32_t));
    t->centroid = malloc((size_t)(nt > 0 ? nt : 1) * 3 * sizeof(double));
    t->node = malloc((size_t)(2 * (nt > 0 ? nt : 1)) * sizeof(wnode)); /* a binary tree */
    if (!t->order || !t->centroid || !t->node) {
        sw_winding_tree_destroy(t);
        return NULL;
    }
    for (int32_t i = 0; i < nt; ++i) {
        t->order[i] = i;
        for (int k = 0; k < 3; ++k)
            t->centroid[3 * (size_t)i + k] =
                (vert(t, i, 0)[k] + vert(t, i, 1)[k] + vert(t, i, 2)[k]) / 3.0;
    }
    t->nnodes = 1;
    t->depth = nt > 0 ? build(t, 0, 0, nt) : 0;
    return t;
}

void sw_winding_tree_destroy(sw_winding_tree *t) {
    if (!t) return;
    free(t->order);
    free(t->centroid);
    free(t->node);
    free(t);
}

double sw_winding_tree_eval(const sw_winding_tree *t, const double p[3]) {
    if (t->surf->ntris == 0) return 0;
    int32_t stack[128];
    int top = 0;
    double sum = 0;
    stack[top++] = 0;
    while (top > 0) {
        const wnode *n = &t->node[stack[--top]];
        double d[3];
        sw_v3_sub(n->c, p, d);
        double dist = sw_v3_norm(d);
        if (dist > SW_WINDING_BETA * n->r) { /* the cluster as one dipole */
            sum += sw_v3_dot(d, n->N) / (dist * dist * dist);
        } else if (n->child < 0 || top + 2 > 128) {
            for (int32_t i = n->begin; i < n->end; ++i) {
                int32_t tri = t->order[i];
                sum += solid_angle(vert(t, tri, 0), vert(t, tri, 1), vert(t, tri, 2), p);
            }
        } else {
            stack[top++] = n->child;
            stack[top++] = n->child + 1;
        }
    }
    return sum / four_pi();
}
