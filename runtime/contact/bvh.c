/* AABB tree: median-split build, backward-sweep refit, fixed-stack queries. */
#include "bvh.h"
#include "vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double c; /* centroid coordinate along the split axis */
    int32_t id;
} sort_key;

typedef struct {
    const double *boxes;
    double *centroid; /* 3*n */
    sort_key *keys;   /* n scratch */
    sw_bvh *bvh;
    int32_t next; /* next free node */
    int depth;    /* deepest node so far */
} builder;

static int key_cmp(const void *pa, const void *pb) {
    const sort_key *a = pa, *b = pb;
    if (a->c < b->c) return -1;
    if (a->c > b->c) return 1;
    return (a->id > b->id) - (a->id < b->id); /* ties by id: the tree depends only on input */
}

static int key_less(const sort_key *a, const sort_key *b) {
    return a->c < b->c || (a->c == b->c && a->id < b->id);
}

static void key_swap(sort_key *a, int32_t i, int32_t j) {
    sort_key t = a[i];
    a[i] = a[j];
    a[j] = t;
}

/* Puts the k smallest of the n keys (key_cmp's order, total: ids are distinct) first, in
 * any order, and the rest after: quickselect (Hoare partitions around a median of
 * three), O(n) expected, where a full sort at every level made the build O(n log^2 n)
 * and 35% of a pose-pairs instance's creation (perf, the Fox). Input that keeps the
 * partitions lopsided (a hostile blob's) runs out of rounds and is sorted instead. */
static void select_keys(sort_key *a, int32_t n, int32_t k) {
    int32_t lo = 0, hi = n - 1, rounds = 64;
    while (hi > lo) {
        if (rounds-- == 0) {
            qsort(a + lo, (size_t)(hi - lo + 1), sizeof *a, key_cmp);
            return;
        }
        int32_t mid = lo + (hi - lo) / 2;
        if (key_less(&a[mid], &a[lo])) key_swap(a, lo, mid);
        if (key_less(&a[hi], &a[lo])) key_swap(a, lo, hi);
        if (key_less(&a[hi], &a[mid])) key_swap(a, mid, hi);
        const sort_key p = a[mid];
        int32_t i = lo, j = hi;
        while (i <= j) {
            while (key_less(&a[i], &p))
                i++;
            while (key_less(&p, &a[j]))
                j--;
            if (i <= j) key_swap(a, i++, j--);
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return; /* a[k] is the pivot, in place */
    }
}

static void box_empty(double *b) {
    for (int k = 0; k < 3; ++k) {
        b[k] = INFINITY;
        b[3 + k] = -INFINITY;
    }
}

static void box_grow(double *b, const double *o) {
    for (int k = 0; k < 3; ++k) {
        if (o[k] < b[k]) b[k] = o[k];
        if (o[3 + k] > b[3 + k]) b[3 + k] = o[3 + k];
    }
}

/* Pre-order build of prims[lo, hi): returns the node index. Recursion depth is the
 * tree depth, below 34 for any int32 n (median splits halve the range). */
static int32_t build_range(builder *B, int32_t lo, int32_t hi, int depth) {
    sw_bvh *t = B->bvh;
    int32_t node = B->next++;
    if (depth > B->depth) B->depth = depth;
    double *box = t->box + 6 * (size_t)node;
    box_empty(box);
    for (int32_t i = lo; i < hi; ++i)
        box_grow(box, B->boxes + 6 * (size_t)t->prims[i]);
    if (hi - lo <= SW_BVH_LEAF_SIZE) {
        t->node[2 * node] = lo;
        t->node[2 * node + 1] = hi - lo;
        return node;
    }
    /* Split axis: the longest extent of the centroids (not the boxes), so long thin
     * primitives do not hide the direction along which they are spread. */
    double cb[6];
    box_empty(cb);
    for (int32_t i = lo; i < hi; ++i) {
        const double *c = B->centroid + 3 * (size_t)t->prims[i];
        double cc[6] = {c[0], c[1], c[2], c[0], c[1], c[2]};
        box_grow(cb, cc);
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (cb[3 + k] - cb[k] > cb[3 + axis] - cb[axis]) axis = k;
    for (int32_t i = lo; i < hi; ++i) {
        int32_t id = t->prims[i];
        B->keys[i - lo].c = B->centroid[3 * (size_t)id + axis];
        B->keys[i - lo].id = id;
    }
    /* the median split: the halves' sets are those of a full sort; a child that is a leaf
       keeps its primitives in sorted order (an inner child sorts its own range again),
       so the tree is the one a full sort at every level builds */
    const int32_t m = hi - lo, half = m / 2;
    select_keys(B->keys, m, half);
    if (half <= SW_BVH_LEAF_SIZE) qsort(B->keys, (size_t)half, sizeof(sort_key), key_cmp);
    if (m - half <= SW_BVH_LEAF_SIZE)
        qsort(B->keys + half, (size_t)(m - half), sizeof(sort_key), key_cmp);
    for (int32_t i = lo; i < hi; ++i)
        t->prims[i] = B->keys[i - lo].id;
    int32_t mid = lo + half;
    build_range(B, lo, mid, depth + 1); /* left child is node + 1 */
    int32_t right = build_range(B, mid, hi, depth + 1);
    t->node[2 * node] = right;
    t->node[2 * node + 1] = 0;
    return node;
}

/* The checks of a build's input (n and every box). */
static sinew_result check_boxes(int32_t n, const double *boxes, sw_error *err) {
    if (n < 1 || !boxes)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_bvh_build: need at least one primitive box (n = %d)", (int)n);
    if (n > INT32_MAX / 2)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sw_bvh_build: too many primitives (%d)", (int)n);
    for (int32_t i = 0; i < n; ++i) {
        const double *b = boxes + 6 * (size_t)i;
        for (int k = 0; k < 6; ++k)
            if (!isfinite(b[k]))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "sw_bvh_build: box of primitive %d is not finite", (int)i);
        for (int k = 0; k < 3; ++k)
            if (b[k] > b[3 + k])
                return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                    "sw_bvh_build: box of primitive %d has min > max on axis %d",
                                    (int)i, k);
    }
    return SINEW_OK;
}

/* A binary tree whose leaves hold >= 1 primitive has at most 2n - 1 nodes. */
static size_t max_nodes(int32_t n) {
    return n > 0 ? 2 * (size_t)n - 1 : 0;
}

size_t sw_bvh_scratch_size(int32_t n) {
    return (size_t)(n > 0 ? n : 0) * (3 * sizeof(double) + sizeof(sort_key));
}

void sw_bvh_take(sw_mem_plan *p, int32_t n, sw_bvh *out) {
    memset(out, 0, sizeof *out);
    size_t maxnodes = max_nodes(n);
    out->box = sw_plan_take(p, 6 * maxnodes, sizeof(double));
    out->node = sw_plan_take(p, 2 * maxnodes, sizeof(int32_t));
    out->prims = sw_plan_take(p, (uint64_t)n, sizeof(int32_t));
    out->pbox = sw_plan_take(p, 6 * (uint64_t)n, sizeof(double));
}

sinew_result sw_bvh_build_in(int32_t n, const double *boxes, sw_bvh *t, void *scratch,
                             sw_error *err) {
    sinew_result r = check_boxes(n, boxes, err);
    if (r != SINEW_OK) return r;
    double *centroid = scratch;
    sort_key *keys = (sort_key *)(centroid + 3 * (size_t)n);
    t->nprims = n;
    for (int32_t i = 0; i < n; ++i) {
        t->prims[i] = i;
        for (int k = 0; k < 3; ++k)
            centroid[3 * (size_t)i + k] =
                0.5 * (boxes[6 * (size_t)i + k] + boxes[6 * (size_t)i + 3 + k]);
    }
    builder B = {boxes, centroid, keys, t, 0, 0};
    build_range(&B, 0, n, 0);
    t->nnodes = B.next;
    for (int32_t j = 0; j < n; ++j)
        memcpy(t->pbox + 6 * (size_t)j, boxes + 6 * (size_t)t->prims[j], 6 * sizeof(double));
    if (B.depth + 2 > SW_BVH_STACK) /* cannot happen with median splits; guard the stack */
        return sw_error_set(err, SINEW_ERROR_CAPACITY,
                            "sw_bvh_build: tree depth %d exceeds the stack", B.depth);
    return SINEW_OK;
}

sinew_result sw_bvh_build(int32_t n, const double *boxes, sw_bvh *out, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_bvh_build: out is NULL");
    memset(out, 0, sizeof *out);
    sinew_result r = check_boxes(n, boxes, err);
    if (r != SINEW_OK) return r;
    size_t maxnodes = max_nodes(n);
    sw_bvh t = {0};
    t.box = malloc(6 * maxnodes * sizeof(double));
    t.node = malloc(2 * maxnodes * sizeof(int32_t));
    t.prims = malloc((size_t)n * sizeof(int32_t));
    t.pbox = malloc(6 * (size_t)n * sizeof(double));
    void *scratch = malloc(sw_bvh_scratch_size(n));
    if (!t.box || !t.node || !t.prims || !t.pbox || !scratch) {
        free(scratch);
        sw_bvh_free(&t);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "sw_bvh_build: out of memory (%d primitives)", (int)n);
    }
    r = sw_bvh_build_in(n, boxes, &t, scratch, err);
    free(scratch);
    if (r != SINEW_OK) {
        sw_bvh_free(&t);
        return r;
    }
    *out = t;
    return SINEW_OK;
}

void sw_bvh_free(sw_bvh *bvh) {
    if (!bvh) return;
    free(bvh->box);
    free(bvh->node);
    free(bvh->prims);
    free(bvh->pbox);
    memset(bvh, 0, sizeof *bvh);
}

void sw_bvh_refit_nodes(sw_bvh *bvh) {
    /* Pre-order storage: children follow their parent, so a backward sweep sees both
     * children of a node before the node itself. */
    for (int32_t i = bvh->nnodes - 1; i >= 0; --i) {
        double *box = bvh->box + 6 * (size_t)i;
        int32_t a = bvh->node[2 * i], cnt = bvh->node[2 * i + 1];
        if (cnt > 0) {
            memcpy(box, bvh->pbox + 6 * (size_t)a, 6 * sizeof(double));
            for (int32_t j = a + 1; j < a + cnt; ++j)
                box_grow(box, bvh->pbox + 6 * (size_t)j);
        } else {
            memcpy(box, bvh->box + 6 * (size_t)(i + 1), 6 * sizeof(double));
            box_grow(box, bvh->box + 6 * (size_t)a);
        }
    }
}

void sw_bvh_refit(sw_bvh *bvh, const double *boxes) {
    for (int32_t j = 0; j < bvh->nprims; ++j)
        memcpy(bvh->pbox + 6 * (size_t)j, boxes + 6 * (size_t)bvh->prims[j], 6 * sizeof(double));
    sw_bvh_refit_nodes(bvh);
}

static void element_box(const int32_t *e, int k, const double *x, double *b) {
    const double *p0 = x + 3 * (size_t)e[0];
    for (int c = 0; c < 3; ++c)
        b[c] = b[3 + c] = p0[c];
    for (int j = 1; j < k; ++j) {
        const double *p = x + 3 * (size_t)e[j];
        for (int c = 0; c < 3; ++c) {
            if (p[c] < b[c]) b[c] = p[c];
            if (p[c] > b[3 + c]) b[3 + c] = p[c];
        }
    }
}

void sw_bvh_refit_elements(sw_bvh *bvh, const int32_t *elems, int k, const double *x, int32_t begin,
                           int32_t end) {
    for (int32_t j = begin; j < end; ++j)
        element_box(elems + (size_t)k * bvh->prims[j], k, x, bvh->pbox + 6 * (size_t)j);
}

void sw_bvh_element_boxes(const int32_t *elems, int k, const double *x, int32_t begin, int32_t end,
                          double *boxes) {
    for (int32_t i = begin; i < end; ++i)
        element_box(elems + (size_t)k * i, k, x, boxes + 6 * (size_t)i);
}

static int box_has_point(const double *b, const double *p) {
    return p[0] >= b[0] && p[0] <= b[3] && p[1] >= b[1] && p[1] <= b[4] && p[2] >= b[2] &&
           p[2] <= b[5];
}

static int box_overlaps(const double *a, const double *b) {
    return a[0] <= b[3] && b[0] <= a[3] && a[1] <= b[4] && b[1] <= a[4] && a[2] <= b[5] &&
           b[2] <= a[5];
}

/* Shared walk of the two overlap queries: mode 0 tests a point, 1 a box. */
static int32_t query(const sw_bvh *bvh, const double *q, int mode, sw_bvh_visit_fn visit,
                     void *ctx) {
    if (!bvh || bvh->nnodes == 0) return 0;
    int32_t stack[SW_BVH_STACK];
    int top = 0;
    int32_t visits = 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t i = stack[--top];
        const double *box = bvh->box + 6 * (size_t)i;
        if (mode == 0 ? !box_has_point(box, q) : !box_overlaps(box, q)) continue;
        int32_t a = bvh->node[2 * i], cnt = bvh->node[2 * i + 1];
        if (cnt > 0) {
            for (int32_t j = a; j < a + cnt; ++j) {
                const double *pb = bvh->pbox + 6 * (size_t)j;
                if (mode == 0 ? !box_has_point(pb, q) : !box_overlaps(pb, q)) continue;
                ++visits;
                if (visit(ctx, bvh->prims[j])) return visits;
            }
        } else {
            stack[top++] = a;     /* right, popped second */
            stack[top++] = i + 1; /* left, popped first */
        }
    }
    return visits;
}

int32_t sw_bvh_query_point(const sw_bvh *bvh, const double p[3], sw_bvh_visit_fn visit, void *ctx) {
    return query(bvh, p, 0, visit, ctx);
}

int32_t sw_bvh_query_box(const sw_bvh *bvh, const double box[6], sw_bvh_visit_fn visit, void *ctx) {
    return query(bvh, box, 1, visit, ctx);
}

static double box_dist2(const double *b, const double *p) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
        double d = 0;
        if (p[k] < b[k])
            d = b[k] - p[k];
        else if (p[k] > b[3 + k])
            d = p[k] - b[3 + k];
        d2 += d * d;
    }
    return d2;
}

void sw_closest_point_triangle(const double p[3], const double a[3], const double b[3],
                               const double c[3], double beta[3], double q[3]) {
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    sw_v3_sub(b, a, ab);
    sw_v3_sub(c, a, ac);
    sw_v3_sub(p, a, ap);
    sw_v3_sub(p, b, bp);
    sw_v3_sub(p, c, cp);
    double d1 = sw_v3_dot(ab, ap), d2 = sw_v3_dot(ac, ap);
    double d3 = sw_v3_dot(ab, bp), d4 = sw_v3_dot(ac, bp);
    double d5 = sw_v3_dot(ab, cp), d6 = sw_v3_dot(ac, cp);
    double u, v, w; /* weights of a, b, c */
    double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) { /* vertex region a */
        u = 1, v = 0, w = 0;
    } else if (d3 >= 0 && d4 <= d3) { /* vertex region b */
        u = 0, v = 1, w = 0;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) { /* edge ab */
        v = d1 / (d1 - d3);
        u = 1 - v, w = 0;
    } else if (d6 >= 0 && d5 <= d6) { /* vertex region c */
        u = 0, v = 0, w = 1;
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) { /* edge ac */
        w = d2 / (d2 - d6);
        u = 1 - w, v = 0;
    } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) { /* edge bc */
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        u = 0, v = 1 - w;
    } else { /* face interior */
        double s = 1.0 / (va + vb + vc);
        v = vb * s;
        w = vc * s;
        u = 1 - v - w;
    }
    beta[0] = u, beta[1] = v, beta[2] = w;
    for (int k = 0; k < 3; ++k)
        q[k] = u * a[k] + v * b[k] + w * c[k];
}

int sw_bvh_closest_triangle(const sw_bvh *bvh, const double *X, const int32_t *tris,
                            const double p[3], double max_dist, sw_bvh_closest *out) {
    out->tri = -1;
    out->dist = max_dist;
    if (!bvh || bvh->nnodes == 0 || !(max_dist >= 0)) return 0;
    double best = max_dist * max_dist;
    int32_t stack[SW_BVH_STACK];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t i = stack[--top];
        /* Prune with '>' (not '>='): an equally distant triangle with a lower id wins. */
        if (box_dist2(bvh->box + 6 * (size_t)i, p) > best) continue;
        int32_t a = bvh->node[2 * i], cnt = bvh->node[2 * i + 1];
        if (cnt > 0) {
            for (int32_t j = a; j < a + cnt; ++j) {
                if (box_dist2(bvh->pbox + 6 * (size_t)j, p) > best) continue;
                int32_t t = bvh->prims[j];
                const int32_t *v = tris + 3 * (size_t)t;
                double beta[3], q[3];
                sw_closest_point_triangle(p, X + 3 * (size_t)v[0], X + 3 * (size_t)v[1],
                                          X + 3 * (size_t)v[2], beta, q);
                double d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                            (q[2] - p[2]) * (q[2] - p[2]);
                if (d2 < best || (d2 == best && (out->tri < 0 || t < out->tri))) {
                    best = d2;
                    out->tri = t;
                    memcpy(out->beta, beta, sizeof beta);
                    memcpy(out->point, q, sizeof q);
                }
            }
        } else {
            /* Nearer child on top of the stack: it shrinks `best` early. */
            int32_t l = i + 1, r = a;
            double dl = box_dist2(bvh->box + 6 * (size_t)l, p),
                   dr = box_dist2(bvh->box + 6 * (size_t)r, p);
            if (dl <= dr) {
                stack[top++] = r;
                stack[top++] = l;
            } else {
                stack[top++] = l;
                stack[top++] = r;
            }
        }
    }
    if (out->tri < 0) return 0;
    out->dist = sqrt(best);
    return 1;
}
