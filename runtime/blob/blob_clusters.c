/* The output surface's clusters, derived from the blob once at its load (blob_clusters.h). */
#include "blob_clusters.h"

#include <math.h>
#include <string.h>

int32_t sw_surface_cluster_bound(const sw_blob_view *v) {
    /* median splits of n copies into leaves of <= C give < 2n/C + 1 leaves per domain */
    return v->ndomains + 2 * (v->nsurf_copies / SW_WORLD_CLUSTER) + 2;
}

/* The rest position of surface copy i. */
static const double *copy_rest(const sw_blob_view *v, int32_t i) {
    return v->rest + 3 * (int64_t)sw_blob_surf_copy_vertex(v, i);
}

/* Orders idx[0, n) so that idx[k] is the k-th by (coordinate ax of its rest position,
 * copy index): Hoare's selection, in place, deterministic. */
static void select_kth(const sw_blob_view *v, int32_t *idx, int32_t n, int32_t k, int ax) {
    int32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        int32_t pv = idx[lo + (hi - lo) / 2];
        double pk = copy_rest(v, pv)[ax];
        int32_t i = lo, j = hi;
        while (i <= j) {
            while (copy_rest(v, idx[i])[ax] < pk || (copy_rest(v, idx[i])[ax] == pk && idx[i] < pv))
                ++i;
            while (copy_rest(v, idx[j])[ax] > pk || (copy_rest(v, idx[j])[ax] == pk && idx[j] > pv))
                --j;
            if (i <= j) {
                int32_t t = idx[i];
                idx[i++] = idx[j];
                idx[j--] = t;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

/* Splits cl_copy[b, e) at the median of its longest rest axis until every part holds at
 * most SW_WORLD_CLUSTER copies, appending the parts as clusters (an explicit stack). */
static void split_range(sw_surface_clusters *wc, const sw_blob_view *v, int32_t b, int32_t e) {
    int32_t stack[2 * 64], top = 0;
    stack[top++] = b;
    stack[top++] = e;
    while (top > 0) {
        e = stack[--top];
        b = stack[--top];
        if (e - b <= SW_WORLD_CLUSTER || top >= 2 * 64 - 4) {
            wc->cl_begin[wc->ncl++] = b;
            continue;
        }
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int32_t i = b; i < e; ++i)
            for (int k = 0; k < 3; ++k) {
                lo[k] = fmin(lo[k], copy_rest(v, wc->cl_copy[i])[k]);
                hi[k] = fmax(hi[k], copy_rest(v, wc->cl_copy[i])[k]);
            }
        int ax = 0;
        for (int k = 1; k < 3; ++k)
            if (hi[k] - lo[k] > hi[ax] - lo[ax]) ax = k;
        int32_t m = b + (e - b) / 2;
        select_kth(v, wc->cl_copy + b, e - b, m - b, ax);
        /* the right half is pushed first so clusters come out left to right */
        stack[top++] = m;
        stack[top++] = e;
        stack[top++] = b;
        stack[top++] = m;
    }
}

/* Rest area of each copy: a third of its surface vertex's triangles, shared evenly by
 * the vertex's copies (the area weight of eqs. 3.4-3.6). */
static void copy_areas(sw_surface_clusters *wc, const sw_blob_view *v) {
    memset(wc->copy_area, 0, (size_t)v->nsurf_copies * sizeof(double));
    for (int32_t t = 0; t < v->nsurf_tris; ++t) {
        const int32_t *tri = v->surf_tris + 3 * (int64_t)t;
        const double *a = copy_rest(v, v->surf_copy_ptr[tri[0]]),
                     *b = copy_rest(v, v->surf_copy_ptr[tri[1]]),
                     *c = copy_rest(v, v->surf_copy_ptr[tri[2]]);
        double u[3], w[3], n[3];
        for (int k = 0; k < 3; ++k) {
            u[k] = b[k] - a[k];
            w[k] = c[k] - a[k];
        }
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        double third = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 6;
        for (int k = 0; k < 3; ++k) {
            int32_t s = tri[k], cb = v->surf_copy_ptr[s], ce = v->surf_copy_ptr[s + 1];
            for (int32_t i = cb; i < ce; ++i)
                wc->copy_area[i] += third / (double)(ce - cb);
        }
    }
}

/* The bone with the most skinning weight over cluster c's copies (its first, on a tie). */
static int32_t dominant_bone(const sw_surface_clusters *wc, const sw_blob_view *v, int32_t c) {
    int32_t best = 0;
    double most = -1;
    for (int32_t i = wc->cl_begin[c]; i < wc->cl_begin[c + 1]; ++i)
        for (int k = 0; k < SW_BLOB_INFLUENCES; ++k) {
            int32_t bone = v->skin_bone[4 * sw_blob_surf_copy_vertex(v, wc->cl_copy[i]) + k];
            double sum = 0;
            for (int32_t j = wc->cl_begin[c]; j < wc->cl_begin[c + 1]; ++j)
                for (int m = 0; m < SW_BLOB_INFLUENCES; ++m) {
                    int32_t gv = sw_blob_surf_copy_vertex(v, wc->cl_copy[j]);
                    if (v->skin_bone[4 * gv + m] == bone) sum += v->skin_weight[4 * gv + m];
                }
            if (sum > most) most = sum, best = bone;
        }
    return best;
}

static void build_clusters(sw_surface_clusters *wc, const sw_blob_view *v) {
    int32_t n = 0;
    wc->ncl = 0;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        int32_t b = n;
        for (int32_t i = 0; i < v->nsurf_copies; ++i)
            if (v->surf_copies[2 * i] == d) wc->cl_copy[n++] = i;
        if (n > b) split_range(wc, v, b, n);
    }
    wc->cl_begin[wc->ncl] = n;
    /* clusters were appended per range start; order them by start (ranges are disjoint) */
    for (int32_t c = 1; c < wc->ncl; ++c)
        for (int32_t j = c; j > 0 && wc->cl_begin[j - 1] > wc->cl_begin[j]; --j) {
            int32_t t = wc->cl_begin[j];
            wc->cl_begin[j] = wc->cl_begin[j - 1];
            wc->cl_begin[j - 1] = t;
        }
    for (int32_t c = 0; c < wc->ncl; ++c) { /* in basis-row order within a cluster */
        int32_t *cc = wc->cl_copy + wc->cl_begin[c], m = wc->cl_begin[c + 1] - wc->cl_begin[c];
        for (int32_t i = 1; i < m; ++i)
            for (int32_t j = i;
                 j > 0 && v->surf_copies[2 * cc[j - 1] + 1] > v->surf_copies[2 * cc[j] + 1]; --j) {
                int32_t t = cc[j];
                cc[j] = cc[j - 1];
                cc[j - 1] = t;
            }
    }
    for (int32_t c = 0; c < wc->ncl; ++c) {
        uint64_t mask = 0;
        for (int32_t i = wc->cl_begin[c]; i < wc->cl_begin[c + 1]; ++i) {
            const sw_blob_domain *D = &v->domains[v->surf_copies[2 * wc->cl_copy[i]]];
            int32_t gv = v->domain_verts[D->vert_begin + v->surf_copies[2 * wc->cl_copy[i] + 1]];
            for (int k = 0; k < SW_BLOB_INFLUENCES; ++k)
                if (v->skin_weight[4 * gv + k] > 0) {
                    int32_t bone = v->skin_bone[4 * gv + k];
                    mask |= bone < 64 ? 1ull << bone : ~0ull;
                }
        }
        wc->cl_bones[c] = v->nbones > 64 ? ~0ull : mask;
        wc->cl_bone0[c] = dominant_bone(wc, v, c);
    }
    copy_areas(wc, v);
    for (int32_t d = 0; d < v->ndomains; ++d) { /* max over copies of |U rows|_F */
        const sw_blob_domain *D = &v->domains[d];
        double m = 0;
        for (int32_t i = 0; i < v->nsurf_copies; ++i) {
            if (v->surf_copies[2 * i] != d) continue;
            const double *U =
                v->basis + D->basis_offset + (int64_t)3 * v->surf_copies[2 * i + 1] * D->rank;
            double f2 = 0;
            for (int32_t k = 0; k < 3 * D->rank; ++k)
                f2 += U[k] * U[k];
            m = fmax(m, sqrt(f2));
        }
        wc->dom_umax[d] = m;
    }
}

/* Parts in mem: the doubles (copy_area, dom_umax) and cl_bones first, then the int32
 * arrays, every part 8-byte aligned. */
size_t sw_surface_clusters_bytes(const sw_blob_view *v) {
    const size_t nc = (size_t)v->nsurf_copies, ncl = (size_t)sw_surface_cluster_bound(v);
    return sizeof(double) * (nc + (size_t)v->ndomains) + sizeof(uint64_t) * ncl +
           (sizeof(int32_t) * (2 * ncl + 1 + nc) + 7) / 8 * 8;
}

void sw_surface_clusters_build(const sw_blob_view *v, void *mem, sw_surface_clusters *cl) {
    const size_t nc = (size_t)v->nsurf_copies, ncl = (size_t)sw_surface_cluster_bound(v);
    double *d = mem;
    cl->copy_area = d;
    cl->dom_umax = d + nc;
    cl->cl_bones = (uint64_t *)(void *)(d + nc + v->ndomains);
    int32_t *i = (int32_t *)(void *)(cl->cl_bones + ncl);
    cl->cl_begin = i;
    cl->cl_bone0 = i + ncl + 1;
    cl->cl_copy = i + 2 * ncl + 1;
    build_clusters(cl, v);
}
