/* Exhaustive subspace self-contact (self_contact.h): every vertex mapped, the tets'
 * boxes refit, every boundary vertex queried with the reference's rule. */
#include "self_contact.h"

#include <math.h>
#include <string.h>

#include "dqs.h"
#include "sorted.h"
#include "vec3.h"

void sw_self_contacts_take(sw_mem_plan *p, const sw_blob_view *v, sw_self_contacts *sc) {
    const uint64_t nv = (uint64_t)v->nverts, ns = (uint64_t)v->nsurf_verts,
                   nf = (uint64_t)v->nsurf_tris;
    memset(sc, 0, sizeof *sc);
#define TAKE(ptr, count) SW_PLAN_TAKE(p, ptr, count)
    TAKE(sc->tris, 3 * nf);
    TAKE(sc->surf, ns);
    TAKE(sc->m.ring, ns);
    TAKE(sc->m.tri_area, nf);
    TAKE(sc->m.tri_edge, nf);
    TAKE(sc->home, 2 * nv);
    TAKE(sc->x, 3 * nv);
    TAKE(sc->vR, 9 * nv);
    TAKE(sc->vt, 3 * nv);
    TAKE(sc->found, ns);
    TAKE(sc->verts, 8 * ns);
    TAKE(sc->data, 7 * ns);
    TAKE(sc->act, 4 * ns);
    TAKE(sc->w, ns);
    TAKE(sc->tan, ns);
    TAKE(sc->vstamp, nv);
    TAKE(sc->tstamp, (uint64_t)v->ntets);
    TAKE(sc->cand, SW_RETEST_CANDIDATES);
#undef TAKE
    sw_bvh_take(p, (int32_t)nf, &sc->m.tri_bvh);
    sw_bvh_take(p, v->ntets, &sc->m.tet_bvh);
    /* the builds' boxes and the larger tree's scratch (creation only) */
    uint64_t nbox = nf > (uint64_t)v->ntets ? nf : (uint64_t)v->ntets;
    sc->bvh_scratch =
        sw_plan_take(p, 1, 6 * nbox * sizeof(double) + sw_bvh_scratch_size((int32_t)nbox));
}

/* Global vertex of boundary vertex s (its first copy's). */
static int32_t surf_vertex(const sw_blob_view *v, int32_t s) {
    int32_t i = v->surf_copy_ptr[s], d = v->surf_copies[2 * i];
    return v->domain_verts[v->domains[d].vert_begin + v->surf_copies[2 * i + 1]];
}

sinew_result sw_self_contacts_build(sw_self_contacts *sc, const sw_blob_view *v, sw_error *err) {
    sw_self_mesh *m = &sc->m;
    m->nverts = v->nverts;
    m->ntets = v->ntets;
    m->ntris = v->nsurf_tris;
    m->X = v->rest;
    m->tets = v->tets;
    m->neighbour_factor = SW_SELF_NEIGHBOUR_FACTOR;
    /* the boundary's vertices ascending, by marking them (x is free until a detection) */
    memset(sc->x, 0, 3 * (size_t)v->nverts * sizeof(double));
    for (int32_t s = 0; s < v->nsurf_verts; ++s)
        sc->x[3 * (int64_t)surf_vertex(v, s)] = 1;
    m->nsurf = 0;
    for (int32_t gv = 0; gv < v->nverts; ++gv)
        if (sc->x[3 * (int64_t)gv] != 0) sc->surf[m->nsurf++] = gv;
    for (int32_t t = 0; t < v->nsurf_tris; ++t)
        for (int k = 0; k < 3; ++k)
            sc->tris[3 * t + k] = surf_vertex(v, v->surf_tris[3 * t + k]);
    m->tris = sc->tris;
    m->surf = sc->surf;
    if (m->nsurf < 3 || m->ntris < 1 || m->ntets < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "exhaustive self-contact: the blob has no tet mesh or boundary");
    sw_self_mesh_measures(m);
    for (int32_t t = 0; t < m->ntris; ++t)
        if (!(m->tri_area[t] > 0))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "exhaustive self-contact: boundary triangle %d has zero rest area",
                                (int)t);
    /* each vertex's home copy: its corner in its first tet */
    for (int32_t gv = 0; gv < v->nverts; ++gv) {
        sc->home[2 * gv] = sc->home[2 * gv + 1] = -1;
        if (v->vert_tet_ptr[gv] == v->vert_tet_ptr[gv + 1]) continue;
        int32_t t = v->vert_tets[v->vert_tet_ptr[gv]];
        for (int k = 0; k < 4; ++k)
            if (v->tets[4 * (int64_t)t + k] == gv) {
                sc->home[2 * gv] = v->tet_domain[t];
                sc->home[2 * gv + 1] = v->tet_local[4 * (int64_t)t + k];
            }
    }
    int64_t nbox = m->ntris > m->ntets ? m->ntris : m->ntets;
    double *box = (double *)sc->bvh_scratch;
    void *tree_scratch = box + 6 * nbox;
    sw_bvh_element_boxes(m->tris, 3, m->X, 0, m->ntris, box);
    sinew_result r = sw_bvh_build_in(m->ntris, box, &m->tri_bvh, tree_scratch, err);
    if (r != SINEW_OK) return r;
    sw_bvh_element_boxes(m->tets, 4, m->X, 0, m->ntets, box);
    r = sw_bvh_build_in(m->ntets, box, &m->tet_bvh, tree_scratch, err);
    if (r != SINEW_OK) return r;
    sw_self_contacts_clear(sc);
    return SINEW_OK;
}

void sw_self_contacts_clear(sw_self_contacts *sc) {
    sc->npairs = 0;
    sc->tests = 0;
}

/* A fresh stamp for the vertices and tets of a detection (all cleared on wrap-around). */
static void next_stamp(sw_self_contacts *sc, const sw_blob_view *v) {
    if (sc->stamp == INT32_MAX || sc->stamp <= 0) {
        memset(sc->vstamp, 0, (size_t)v->nverts * sizeof(int32_t));
        memset(sc->tstamp, 0, (size_t)v->ntets * sizeof(int32_t));
        sc->stamp = 0;
    }
    sc->stamp++;
}

/* Vertex gv at the state q: its skinning transform, then x = R (X + U q) + t (eq. 4.13,
 * sw_reduced_position with these transforms) through its home copy (copies differ by the
 * interface springs' stretch only); a vertex in no tet at its skinned rest. `map` is red
 * with the transforms indexed by vertex (sc->vR, sc->vt). */
static void map_vertex(sw_self_contacts *sc, const sw_reduced *map, const double *q, int32_t gv) {
    const sw_blob_view *v = map->v;
    double *R = sc->vR + 9 * (int64_t)gv, *t = sc->vt + 3 * (int64_t)gv,
           *x = sc->x + 3 * (int64_t)gv;
    sw_dqs_blend(map->bone_dq, v->skin_bone + 4 * (int64_t)gv, v->skin_weight + 4 * (int64_t)gv, 4,
                 R, t);
    int32_t d = sc->home[2 * gv];
    if (d >= 0) {
        const sw_blob_domain *D = &v->domains[d];
        sw_reduced_position(map, D, sc->home[2 * gv + 1], gv, q + D->q_offset, x, NULL);
        return;
    }
    const double *X = v->rest + 3 * (int64_t)gv;
    for (int i = 0; i < 3; ++i)
        x[i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
}

static sw_reduced vertex_map(const sw_self_contacts *sc, const sw_reduced *red) {
    sw_reduced map = *red; /* the same map, transforms indexed by vertex */
    map.act_R = sc->vR;
    map.act_t = sc->vt;
    return map;
}

/* Every vertex at the state q. */
static void map_vertices(sw_self_contacts *sc, const sw_reduced *red, const double *q) {
    sw_reduced map = vertex_map(sc, red);
    for (int32_t gv = 0; gv < red->v->nverts; ++gv)
        map_vertex(sc, &map, q, gv);
}

/* Makes contact c pair i of the pairs in use: its slots' home copies, the law's data
 * with the normal in p's un-skinned frame (R_p^T n), the slots' transforms. */
static void make_pair(sw_self_contacts *sc, const sw_contact *c, int32_t i) {
    const int32_t slot[4] = {c->p, c->tri[0], c->tri[1], c->tri[2]};
    for (int k = 0; k < 4; ++k) {
        sc->verts[8 * i + 2 * k] = sc->home[2 * slot[k]];
        sc->verts[8 * i + 2 * k + 1] = sc->home[2 * slot[k] + 1];
        sc->act[4 * i + k] = slot[k];
    }
    const double *R = sc->vR + 9 * (int64_t)c->p;
    double *d = sc->data + 7 * (int64_t)i;
    for (int k = 0; k < 3; ++k) {
        d[k] = c->beta[k];
        d[3 + k] = R[k] * c->n[0] + R[3 + k] * c->n[1] + R[6 + k] * c->n[2];
    }
    d[6] = c->ka;
}

int32_t sw_self_contacts_detect(sw_self_contacts *sc, const sw_reduced *red, const double *q) {
    return sw_self_contacts_detect_pairs(sc, red, q, NULL);
}

/* Vertex gv's home domain has a pair in mask's row (mask NULL: every vertex). */
static int row_set(const sw_self_contacts *sc, const unsigned char *mask, int32_t nd, int32_t gv) {
    if (!mask) return 1;
    int32_t a = sc->home[2 * gv];
    if (a < 0) return 0;
    for (int32_t b = 0; b < nd; ++b)
        if (mask[a * nd + b]) return 1;
    return 0;
}

int32_t sw_self_contacts_detect_pairs(sw_self_contacts *sc, const sw_reduced *red, const double *q,
                                      const unsigned char *mask) {
    sw_self_mesh *m = &sc->m;
    const int32_t nd = red->v->ndomains;
    map_vertices(sc, red, q);
    sw_bvh_refit_elements(&m->tet_bvh, m->tets, 4, sc->x, 0, m->ntets);
    sw_bvh_refit_nodes(&m->tet_bvh);
    int32_t n = 0;
    sc->tests = 0;
    for (int32_t si = 0; si < m->nsurf; ++si) {
        if (!row_set(sc, mask, nd, m->surf[si])) continue;
        int32_t tested = 0;
        /* a vertex in no tet has no home copy: the detection never returns it as p, but a
           triangle corner always lies in a tet */
        int32_t k = sw_self_detect_vertex(m, sc->x, si, &sc->found[n], &tested);
        sc->tests += tested;
        if (k > 0 && mask &&
            !mask[sc->home[2 * sc->found[n].p] * nd + sc->home[2 * sc->found[n].tri[0]]])
            k = 0;
        n += k;
    }
    /* the new pairs: their vertex had none before (both lists ascend in p) */
    int32_t fresh = 0, j = 0;
    for (int32_t i = 0; i < n; ++i) {
        while (j < sc->npairs && sc->act[4 * j] < sc->found[i].p)
            ++j;
        fresh += !(j < sc->npairs && sc->act[4 * j] == sc->found[i].p);
    }
    for (int32_t i = 0; i < n; ++i) {
        make_pair(sc, &sc->found[i], i);
        sc->w[i] = sc->tan[i] = 1;
    }
    sc->npairs = n;
    return fresh;
}

/* Maps vertex gv once per detection (stamp). */
static void map_once(sw_self_contacts *sc, const sw_reduced *map, const double *q, int32_t gv) {
    if (sc->vstamp[gv] == sc->stamp) return;
    sc->vstamp[gv] = sc->stamp;
    map_vertex(sc, map, q, gv);
}

/* The tets incident to triangle tv's corners into sc->cand, their corners mapped;
 * returns how many (at most SW_RETEST_CANDIDATES). A second ring (the tets incident to
 * those tets' corners, about 160 a pair against 30) found the same contacts on the
 * finger, the hand and the Fox at three times the cost (docs/notes/accuracy.md). */
static int32_t ring_tets(sw_self_contacts *sc, const sw_blob_view *v, const sw_reduced *map,
                         const double *q, const int32_t tv[3]) {
    int32_t n = 0;
    for (int k = 0; k < 3; ++k)
        for (int32_t i = v->vert_tet_ptr[tv[k]]; i < v->vert_tet_ptr[tv[k] + 1]; ++i) {
            int32_t t = v->vert_tets[i];
            if (sc->tstamp[t] == sc->stamp || n == SW_RETEST_CANDIDATES) continue;
            sc->tstamp[t] = sc->stamp;
            sc->cand[n++] = t;
        }
    for (int32_t j = 0; j < n; ++j) {
        for (int c = 0; c < 4; ++c)
            map_once(sc, map, q, v->tets[4 * (int64_t)sc->cand[j] + c]);
        sc->tstamp[sc->cand[j]] = 0; /* the next pair's ring starts afresh */
    }
    return n;
}

int32_t sw_self_contacts_retest(sw_self_contacts *sc, const sw_reduced *red, const double *q,
                                sw_pose_space *ps) {
    const sw_blob_view *v = red->v;
    sw_self_mesh *m = &sc->m;
    sw_reduced map = vertex_map(sc, red);
    int32_t kept = 0, moved = 0;
    next_stamp(sc, v);
    for (int32_t i = 0; i < ps->npairs; ++i) {
        const int32_t c = ps->pairs[i], *ca = red->contact_act + 4 * (int64_t)c;
        int32_t p = red->act_vert[ca[0]], si = sw_sorted_index(m->surf, m->nsurf, p);
        int32_t tv[3] = {red->act_vert[ca[1]], red->act_vert[ca[2]], red->act_vert[ca[3]]};
        sw_self_hit hit;
        int found = 0;
        if (si >= 0 && sc->home[2 * p] >= 0 && sc->npairs < m->nsurf) {
            int32_t n = ring_tets(sc, v, &map, q, tv);
            map_once(sc, &map, q, p);
            sc->tests += n;
            found = sw_self_detect_among(m, sc->x, si, sc->cand, n, &hit);
        }
        if (!found) { /* keeps its trained triangle */
            ps->pairs[kept] = c;
            ps->pair_w[kept] = ps->pair_w[i];
            ps->pair_tan[kept++] = ps->pair_tan[i];
            continue;
        }
        const int32_t *ht = sw_self_hit_triangle(m, &hit);
        for (int k = 0; k < 3; ++k)
            map_once(sc, &map, q, ht[k]);
        sw_contact con;
        sw_self_detect_finish(m, sc->x, &hit, &con);
        make_pair(sc, &con, sc->npairs);
        sc->w[sc->npairs] = ps->pair_w[i];
        sc->tan[sc->npairs++] = ps->pair_tan[i];
        moved++;
    }
    ps->npairs = kept;
    return moved;
}

void sw_self_contacts_begin(sw_self_contacts *sc, const sw_reduced *red) {
    next_stamp(sc, red->v);
    sc->map = vertex_map(sc, red);
}

const double *sw_self_contacts_map(sw_self_contacts *sc, const double *q, int32_t gv) {
    map_once(sc, &sc->map, q, gv);
    return sc->x + 3 * (int64_t)gv;
}

int32_t sw_self_contacts_add(sw_self_contacts *sc, const sw_contact *c, double w, double tan) {
    if (sc->npairs >= sc->m.nsurf) return 0;
    make_pair(sc, c, sc->npairs);
    sc->w[sc->npairs] = w;
    sc->tan[sc->npairs++] = tan;
    return 1;
}

sw_pair_set sw_self_contacts_pairs(const sw_self_contacts *sc) {
    sw_pair_set set = {sc->verts, sc->data, sc->act, sc->vR, sc->vt};
    return set;
}
