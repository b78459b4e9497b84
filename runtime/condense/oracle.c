/* The partition oracle of subspace condensation (condense.h; thesis §4.4.2, DESIGN.md
 * §4.6 and §8): seeds, the breadth-first growth within rho of each seed, the budget's cut,
 * the full tets and their ring copies. Its cost follows the seeds' neighbourhoods, never
 * the mesh: the per-vertex arrays are read and written only at the vertices it visits,
 * and stamps stand in for clearing them. */
#include <math.h>
#include <string.h>

#include "condense.h"
#include "dqs.h"
#include "penalty.h"

/* Seeds persist this many steps after the one that found them (the thesis's "two more
 * frames": a patch outlives its contact while the flesh recovers from it). */
#define SEED_STEPS 3

/* Largest number of tets at one vertex. */
static int32_t max_valence(const sw_blob_view *v) {
    int32_t m = 0;
    for (int32_t gv = 0; gv < v->nverts; ++gv) {
        int32_t n = v->vert_tet_ptr[gv + 1] - v->vert_tet_ptr[gv];
        if (n > m) m = n;
    }
    return m;
}

static int32_t min32(int64_t a, int64_t b) {
    return (int32_t)(a < b ? a : b);
}

sw_cond_sizes sw_cond_plan(const sw_blob_view *v, uint32_t max_verts, int32_t max_world,
                           int32_t max_pairs, int32_t max_detected, int32_t max_self_seeds) {
    sw_cond_sizes z;
    memset(&z, 0, sizeof z);
    if (max_verts == 0 || v->ntets == 0) return z;
    z.max_verts = min32(max_verts, v->nverts);
    z.max_tets = min32((int64_t)z.max_verts * max_valence(v), v->ntets);
    z.max_pairs = max_pairs + max_detected;
    z.max_detected = max_detected;
    z.max_ring = min32(4 * ((int64_t)z.max_tets + z.max_pairs), v->ndomain_verts);
    z.max_cand = min32(4 * (int64_t)z.max_verts + 64, v->nverts);
    z.max_seeds = (max_world > 0 ? max_world : 1) + max_self_seeds;
    for (int32_t k = 0; k < v->ndomains; ++k)
        if (v->domains[k].rank > z.rmax) z.rmax = v->domains[k].rank;
    return z;
}

void sw_cond_take(sw_mem_plan *p, const sw_blob_view *v, const sw_cond_sizes *cz, sw_cond *c) {
    const uint64_t R = (uint64_t)v->rank_total, nb = (uint64_t)v->nbones,
                   nd = (uint64_t)v->ndomains, nv = (uint64_t)v->nverts, nt = (uint64_t)v->ntets,
                   nf = (uint64_t)cz->max_verts, np = (uint64_t)cz->max_pairs,
                   ntf = (uint64_t)cz->max_tets + np, nr = (uint64_t)cz->max_ring, m = R + 3 * nf;
#define TAKE(ptr, count) SW_PLAN_TAKE(p, ptr, count)
    TAKE(c->seeds, 3 * (uint64_t)cz->max_seeds);
    TAKE(c->vis, nv);
    TAKE(c->in_patch, nv);
    TAKE(c->vloc, nv);
    TAKE(c->in_ring, nv);
    TAKE(c->seeded, nv);
    TAKE(c->pinned, nv);
    TAKE(c->surf_of, nv);
    TAKE(c->dev, 3 * nv);
    TAKE(c->dev_at, nv);
    TAKE(c->tvis, nt);
    TAKE(c->dom_vol, nd);
    TAKE(c->dom_fv, nd);
    TAKE(c->dom_tet_ptr, nd + 1);
    TAKE(c->dom_tets, nt);
    TAKE(c->queue, (uint64_t)cz->max_cand);
    TAKE(c->cand, (uint64_t)cz->max_cand);
    TAKE(c->cand_d, (uint64_t)cz->max_cand);
    TAKE(c->fv, nf);
    TAKE(c->pp_id, np);
    TAKE(c->pp_w, np);
    TAKE(c->pp_alpha, np);
    TAKE(c->pp_skip, np);
    TAKE(c->pp_src, np);
    TAKE(c->sc_skip, (uint64_t)cz->max_detected);
    TAKE(c->pp_active, np);
    TAKE(c->ft, ntf);
    TAKE(c->ft_slot, 4 * ntf);
    TAKE(c->ring_v, nr);
    TAKE(c->ring_d, nr);
    TAKE(c->ring_l, nr);
    TAKE(c->ring_next, nr);
    TAKE(c->ring_x0, 3 * nr);
    TAKE(c->ring_J, 3 * (uint64_t)cz->rmax * nr);
    TAKE(c->ring_x, 3 * nr);
    TAKE(c->ring_dx, 3 * nr);
    TAKE(c->ring_M, 3 * (uint64_t)cz->rmax * nr);
    TAKE(c->x, 3 * nf);
    TAKE(c->xt, 3 * nf);
    TAKE(c->dx, 3 * nf);
    TAKE(c->gf, 3 * nf);
    TAKE(c->gf_el, 3 * nf);
    TAKE(c->Kt, 144 * ntf);
    TAKE(c->Dw, 9 * nf);
    TAKE(c->Pf, 9 * nf);
    TAKE(c->cg_r, m);
    TAKE(c->cg_z, m);
    TAKE(c->cg_p, m);
    TAKE(c->cg_Ap, m);
    TAKE(c->rhs, m);
    TAKE(c->sol, m);
    TAKE(c->cub_w, (uint64_t)v->ncub);
    TAKE(c->px, 3 * nv);
    TAKE(c->pv, 3 * nv);
    TAKE(c->pdev, 3 * nv);
    TAKE(c->prate, 3 * nv);
    TAKE(c->dyn_at, nv);
    TAKE(c->xn, 3 * nf);
    TAKE(c->vn, 3 * nf);
    TAKE(c->dev_n, 3 * nf);
    TAKE(c->rate_n, 3 * nf);
    TAKE(c->mass, nf);
    TAKE(c->q_prev, R);
    TAKE(c->dq_prev, nb);
    TAKE(c->dq_prev2, nb);
    TAKE(c->keep_v, nf);
#undef TAKE
}

void sw_cond_build(sw_cond *c, const sw_blob_view *v, double rho) {
    c->v = v;
    c->rho = rho;
    c->g0_step = 0;
    memset(c->vis, 0, (size_t)v->nverts * sizeof *c->vis);
    memset(c->in_patch, 0, (size_t)v->nverts * sizeof *c->in_patch);
    memset(c->in_ring, 0, (size_t)v->nverts * sizeof *c->in_ring);
    memset(c->seeded, 0, (size_t)v->nverts * sizeof *c->seeded);
    memset(c->dev_at, 0, (size_t)v->nverts * sizeof *c->dev_at);
    memset(c->dyn_at, 0, (size_t)v->nverts * sizeof *c->dyn_at);
    memset(c->tvis, 0, (size_t)v->ntets * sizeof *c->tvis);
    memset(c->ring_M, 0, (size_t)3 * c->z.rmax * c->z.max_ring * sizeof *c->ring_M);
    for (int32_t gv = 0; gv < v->nverts; ++gv)
        c->surf_of[gv] = -1;
    for (int32_t s = 0; s < v->nsurf_verts; ++s) {
        int32_t i = v->surf_copy_ptr[s], d = v->surf_copies[2 * i];
        c->surf_of[v->domain_verts[v->domains[d].vert_begin + v->surf_copies[2 * i + 1]]] = s;
    }
    for (int32_t k = 0; k < v->ndomains; ++k)
        c->dom_vol[k] = c->dom_tet_ptr[k] = 0;
    for (int32_t t = 0; t < v->ntets; ++t) {
        c->dom_vol[v->tet_domain[t]] += v->tet_vol[t];
        c->dom_tet_ptr[v->tet_domain[t]]++;
    }
    for (int32_t k = 1; k < v->ndomains; ++k) /* each domain's end ... */
        c->dom_tet_ptr[k] += c->dom_tet_ptr[k - 1];
    c->dom_tet_ptr[v->ndomains] = v->ntets;
    for (int32_t t = v->ntets - 1; t >= 0; --t) /* ... counted down to its start */
        c->dom_tets[--c->dom_tet_ptr[v->tet_domain[t]]] = t;
    /* Kinematic vertices: the bake's bone vertices follow their bone rigidly (one-hot
     * weights, no training displacement: bake_basis.c), so every basis row of theirs is
     * exactly zero; the reference holds them too. A patch never frees them: they stay
     * ring copies at their skinned positions. */
    memset(c->pinned, 1, (size_t)v->nverts);
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        for (int32_t lv = 0; lv < D->vert_count; ++lv) {
            const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * D->rank;
            for (int32_t j = 0; j < 3 * D->rank; ++j)
                if (U[j] != 0) {
                    c->pinned[v->domain_verts[D->vert_begin + lv]] = 0;
                    break;
                }
        }
    }
    for (int32_t i = 0; i < v->ncub; ++i)
        c->cub_w[i] = v->cub_weight[i];
    c->stamp = c->vstamp = 0;
    sw_cond_forget(c);
}

void sw_cond_forget(sw_cond *c) {
    c->nseeds[0] = c->nseeds[1] = c->nseeds[2] = 0;
    c->slot = 0;
    c->nf = c->nt = c->nring = c->np = c->nrest = c->nring_patch = 0;
    for (int32_t k = 0; k < c->v->ndomains; ++k)
        c->dom_fv[k] = 0;
    c->keep = c->nkeep = 0;
    c->stamp++; /* every deviation is older than any later step */
    c->stamp++;
}

/* A fresh stamp for the per-vertex visit marks (wrapping to 1 after clearing them, so
 * that a stale mark never equals a live one). */
static uint32_t next_visit(sw_cond *c) {
    if (++c->vstamp == 0) {
        memset(c->vis, 0, (size_t)c->v->nverts * sizeof *c->vis);
        c->vstamp = 1;
    }
    return c->vstamp;
}

static double dist2(const double *a, const double *b) {
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

/* Accepts vertex gv at rest distance d (the growth's candidates: a vertex accepted twice
 * keeps its nearer distance). Returns 0 when the candidate list is full. */
static int accept(sw_cond *c, int32_t gv, double d) {
    if (c->in_patch[gv] == c->stamp) {
        double *cd = c->cand_d + c->vloc[gv];
        if (d < *cd) *cd = d;
        return 1;
    }
    if (c->ncand == c->z.max_cand) return 0;
    c->in_patch[gv] = c->stamp;
    c->vloc[gv] = c->ncand;
    c->cand[c->ncand] = gv;
    c->cand_d[c->ncand++] = d;
    return 1;
}

/* The breadth-first growth from seed s over the mesh's edges (the corners of the tets at
 * a vertex), accepting vertices within rho of s in rest space. */
static void grow(sw_cond *c, int32_t s) {
    const sw_blob_view *v = c->v;
    uint32_t mark = next_visit(c);
    const double *X0 = v->rest + 3 * (int64_t)s, rho2 = c->rho * c->rho;
    int32_t head = 0, tail = 0;
    c->vis[s] = mark;
    c->queue[tail++] = s;
    while (head < tail) {
        int32_t a = c->queue[head++];
        /* a kinematic vertex is passed through, never freed */
        if (!c->pinned[a] && !accept(c, a, sqrt(dist2(v->rest + 3 * (int64_t)a, X0)))) {
            c->dropped++;
            continue;
        }
        for (int32_t e = v->vert_tet_ptr[a]; e < v->vert_tet_ptr[a + 1]; ++e) {
            const int32_t *tv = v->tets + 4 * (int64_t)v->vert_tets[e];
            for (int k = 0; k < 4; ++k) {
                int32_t b = tv[k];
                if (c->vis[b] == mark) continue;
                c->vis[b] = mark;
                if (dist2(v->rest + 3 * (int64_t)b, X0) > rho2) continue;
                if (tail == c->z.max_cand) { /* the growth's queue is full: cut here */
                    c->dropped++;
                    continue;
                }
                c->queue[tail++] = b;
            }
        }
    }
}

/* Keeps the max_verts candidates nearest their seeds (quickselect on the distance, in
 * place; ties by vertex id, so the cut is a function of the candidates alone). */
static int before(const sw_cond *c, int32_t i, int32_t j) {
    return c->cand_d[i] < c->cand_d[j] || (c->cand_d[i] == c->cand_d[j] && c->cand[i] < c->cand[j]);
}
static void swap_cand(sw_cond *c, int32_t i, int32_t j) {
    int32_t g = c->cand[i];
    double d = c->cand_d[i];
    c->cand[i] = c->cand[j];
    c->cand_d[i] = c->cand_d[j];
    c->cand[j] = g;
    c->cand_d[j] = d;
}
static void keep_nearest(sw_cond *c, int32_t k) {
    int32_t n = c->ncand;
    int32_t lo = 0, hi = c->ncand - 1;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2, i = lo;
        swap_cand(c, mid, hi);
        for (int32_t p = lo; p < hi; ++p)
            if (before(c, p, hi)) swap_cand(c, p, i++);
        swap_cand(c, i, hi);
        if (i == k) break;
        if (i < k)
            lo = i + 1;
        else
            hi = i - 1;
    }
    for (int32_t i = k; i < n; ++i) /* out of the patch again */
        c->in_patch[c->cand[i]] = 0;
    c->dropped += n - k;
    c->ncand = k;
}

/* This step's seeds: the vertices of the candidates penetrating at q (their copies'
 * positions at q), then those of the detected self-contact pairs. */
static void find_seeds(sw_cond *c, const sw_reduced *red, const sw_world_contacts *wc,
                       const sw_self_contacts *sc, const double *q) {
    const sw_blob_view *v = c->v;
    int32_t *seeds = c->seeds + (int64_t)c->slot * c->z.max_seeds, n = 0;
    for (int32_t j = 0; sc && j < sc->npairs && n < c->z.max_seeds; ++j)
        seeds[n++] = sc->act[4 * (int64_t)j];
    for (int32_t j = 0; wc && j < wc->ncand && n < c->z.max_seeds; ++j) {
        const sw_world_cand *cd = &wc->cand[j];
        int32_t d = v->surf_copies[2 * cd->copy], lv = v->surf_copies[2 * cd->copy + 1];
        int32_t gv = v->domain_verts[v->domains[d].vert_begin + lv];
        double x[3];
        sw_cond_copy_position(red, gv, d, lv, q, x, NULL);
        double g[3] = {cd->law.a[0] - x[0], cd->law.a[1] - x[1], cd->law.a[2] - x[2]};
        if (g[0] * cd->law.n[0] + g[1] * cd->law.n[1] + g[2] * cd->law.n[2] > 0) seeds[n++] = gv;
    }
    c->nseeds[c->slot] = n;
}

/* The ring copy of (gv, domain d, local lv), added on first sight. */
static int32_t ring_copy(sw_cond *c, const sw_reduced *red, int32_t gv, int32_t d, int32_t lv) {
    int32_t i = c->in_ring[gv] == c->stamp ? -1 - c->vloc[gv] : -1;
    for (int32_t k = i; k >= 0; k = c->ring_next[k])
        if (c->ring_d[k] == d) return k;
    int32_t k = c->nring++;
    c->ring_v[k] = gv;
    c->ring_d[k] = d;
    c->ring_l[k] = lv;
    c->ring_next[k] = i;
    c->in_ring[gv] = c->stamp;
    c->vloc[gv] = -1 - k;
    double *J = c->ring_J + (int64_t)3 * c->z.rmax * k;
    sw_cond_copy_position(red, gv, d, lv, NULL, c->ring_x0 + 3 * k, J);
    return k;
}

/* The full tets (those touching a patch vertex) and their corners' slots. */
static void full_tets(sw_cond *c, const sw_reduced *red) {
    const sw_blob_view *v = c->v;
    c->nt = c->nring = 0;
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t a = c->fv[i];
        for (int32_t e = v->vert_tet_ptr[a]; e < v->vert_tet_ptr[a + 1]; ++e) {
            int32_t t = v->vert_tets[e];
            if (c->tvis[t] == c->stamp || c->nt == c->z.max_tets) continue;
            c->tvis[t] = c->stamp;
            c->ft[c->nt] = t;
            int32_t *slot = c->ft_slot + 4 * (int64_t)c->nt++;
            for (int k = 0; k < 4; ++k) {
                int32_t b = v->tets[4 * (int64_t)t + k];
                slot[k] = c->in_patch[b] == c->stamp ? c->vloc[b]
                                                     : -1 - ring_copy(c, red, b, v->tet_domain[t],
                                                                      v->tet_local[4 * t + k]);
            }
        }
    }
}

/* Eq. 4.12 where the patch covers most of a domain: the domain's cubature was fitted to
 * the whole domain, and scaled to the little volume left outside it stands for that rest
 * badly: a larger patch missed more of the correction, outside the patch
 * (docs/notes/world.md). Past SW_COND_EXACT_SHARE of
 * its volume in the patch, the domain's other tets become elements whose four corners are all ring
 * copies, evaluated exactly at q (its cubature's weights go to SW_COND_MIN_SHARE, the least a
 * domain keeps, with its volume outside): no more tets than the patch holds of that domain, so no
 * O(N) work. A domain the budget's arrays cannot hold keeps its scaled cubature. Leaves each
 * domain's volume in the patch in dom_fv (all of it for these), the scale sw_cond_weights_apply
 * reads. */
static void exact_domains(sw_cond *c, const sw_reduced *red) {
    const sw_blob_view *v = c->v;
    c->nring_patch = c->nring;
    c->nrest = 0;
    for (int32_t k = 0; k < v->ndomains; ++k)
        c->dom_fv[k] = 0;
    for (int32_t e = 0; e < c->nt; ++e)
        c->dom_fv[v->tet_domain[c->ft[e]]] += v->tet_vol[c->ft[e]];
    int64_t room = (int64_t)c->z.max_tets + c->z.max_pairs - c->nt - c->np;
    for (int32_t k = 0; k < v->ndomains; ++k) {
        int32_t b = c->dom_tet_ptr[k], n = c->dom_tet_ptr[k + 1] - b;
        if (!(c->dom_fv[k] > SW_COND_EXACT_SHARE * c->dom_vol[k])) continue;
        int32_t tets = n, copies = v->domains[k].vert_count; /* less those there already */
        for (int32_t e = 0; e < c->nt; ++e)
            tets -= v->tet_domain[c->ft[e]] == k;
        for (int32_t i = 0; i < c->nring; ++i)
            copies -= c->ring_d[i] == k;
        if (c->nrest + tets > room || c->nring + copies > c->z.max_ring) continue;
        c->dom_fv[k] = c->dom_vol[k]; /* all of it full or at q: the least cubature */
        for (int32_t i = b; i < b + n; ++i) {
            int32_t t = c->dom_tets[i];
            if (c->tvis[t] == c->stamp) continue; /* a patch tet */
            int64_t e = (int64_t)c->nt + c->np + c->nrest++;
            c->ft[e] = t;
            for (int m = 0; m < 4; ++m)
                c->ft_slot[4 * e + m] =
                    -1 - ring_copy(c, red, v->tets[4 * (int64_t)t + m], k, v->tet_local[4 * t + m]);
        }
    }
}

/* The patch's start: each vertex at its subspace position at q (the copy of its first
 * tet's domain) plus the deviation it had when last in a patch, if it was in the last
 * step's (kept in its skinning frame, so that it turns with the bones). */
static void start_positions(sw_cond *c, const sw_reduced *red, const double *q) {
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t gv = c->fv[i];
        double *x = c->x + 3 * (int64_t)i;
        sw_cond_subspace_position(c, red, i, NULL, q, x);
        if (c->dev_at[gv] != c->stamp - 1) continue;
        double R[9], t[3], *d = c->dev + 3 * (int64_t)gv; /* the deviation, in the skin frame */
        sw_dqs_blend(red->bone_dq, c->v->skin_bone + 4 * (int64_t)gv,
                     c->v->skin_weight + 4 * (int64_t)gv, 4, R, t);
        for (int j = 0; j < 3; ++j)
            x[j] += R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2];
    }
}

/* The world's candidates of the patch's surface vertices taken at their patch positions
 * (their subspace positions, where the step's detection ran, can be a dent away: a law
 * frozen there would anchor friction and the contact plane in the wrong place), new
 * ones added, as mode says (world_contact.h). Returns how many were added. */
int32_t sw_cond_detect(const sw_cond *c, sw_world_contacts *wc, sw_wc_at_mode mode) {
    const sw_blob_view *v = c->v;
    int32_t added = 0;
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t s = c->surf_of[c->fv[i]];
        if (s < 0) continue;
        for (int32_t k = v->surf_copy_ptr[s]; k < v->surf_copy_ptr[s + 1]; ++k)
            added += sw_world_contacts_at(wc, k, c->x + 3 * (int64_t)i, v->contact_k, mode);
    }
    return added;
}

void sw_cond_tag_candidates(const sw_cond *c, sw_world_contacts *wc) {
    const sw_blob_view *v = c->v;
    for (int32_t j = 0; j < wc->ncand; ++j) {
        sw_world_cand *cd = &wc->cand[j];
        int32_t d = v->surf_copies[2 * cd->copy], lv = v->surf_copies[2 * cd->copy + 1];
        int32_t gv = v->domain_verts[v->domains[d].vert_begin + lv];
        cd->patch = c->nf > 0 && c->in_patch[gv] == c->stamp ? c->vloc[gv] : -1;
    }
    wc->patch_x = c->nf > 0 ? c->x : NULL;
}

/* The pairs of one list (ids NULL: 0..n-1) with a corner in the patch become elements
 * after the full tets, evaluated at the patch's positions; skip[i] says which. Those past
 * the elements' budget stay reduced. */
static int add_pairs(sw_cond *c, const sw_reduced *red, const sw_pair_set *set, const int32_t *ids,
                     int32_t n, const double *w, const double *tan, unsigned char src,
                     unsigned char *skip) {
    const sw_blob_view *v = c->v;
    int any_in = 0;
    for (int32_t p = 0; p < n; ++p) {
        int32_t id = ids ? ids[p] : p;
        const int32_t *cv = set->verts + 8 * (int64_t)id;
        int32_t gv[4], any = 0;
        for (int m = 0; m < 4; ++m) {
            gv[m] = v->domain_verts[v->domains[cv[2 * m]].vert_begin + cv[2 * m + 1]];
            any |= c->in_patch[gv[m]] == c->stamp;
        }
        if (any && c->np == c->z.max_pairs) any = 0; /* no room: the subspace keeps it */
        skip[p] = (unsigned char)any;
        if (!any) continue;
        any_in = 1;
        int32_t *slot = c->ft_slot + 4 * ((int64_t)c->nt + c->np);
        for (int m = 0; m < 4; ++m)
            slot[m] = c->in_patch[gv[m]] == c->stamp
                          ? c->vloc[gv[m]]
                          : -1 - ring_copy(c, red, gv[m], cv[2 * m], cv[2 * m + 1]);
        c->pp_active[c->np] = -1;
        c->pp_id[c->np] = id;
        c->pp_src[c->np] = src;
        c->pp_alpha[c->np] = SW_CONTACT_ALPHA * (tan ? tan[p] : 1);
        c->pp_w[c->np++] = w ? w[p] : 1;
    }
    return any_in;
}

/* The pose-space pairs in use, then the detected pairs (sc, NULL: none), with a corner in
 * the patch: elements evaluated at the patch's positions (the rest stay reduced;
 * ps->in_patch and sc->in_patch say which). */
static void patch_pairs(sw_cond *c, const sw_reduced *red, sw_pose_space *ps,
                        sw_self_contacts *sc) {
    c->np = 0;
    ps->in_patch = NULL;
    sw_pair_set trained = sw_pose_pair_set(red);
    c->pp_sets[SW_COND_TRAINED] = trained;
    if (add_pairs(c, red, &trained, ps->pairs, ps->npairs, ps->pair_w, ps->pair_tan,
                  SW_COND_TRAINED, c->pp_skip))
        ps->in_patch = c->pp_skip;
    if (!sc) return;
    sc->in_patch = NULL;
    sw_pair_set found = sw_self_contacts_pairs(sc);
    c->pp_sets[SW_COND_DETECTED] = found;
    int32_t n = sc->npairs < c->z.max_detected ? sc->npairs : c->z.max_detected;
    if (add_pairs(c, red, &found, NULL, n, sc->w, sc->tan, SW_COND_DETECTED, c->sc_skip)) {
        for (int32_t p = n; p < sc->npairs; ++p) /* beyond the flags: reduced */
            c->sc_skip[p] = 0;
        sc->in_patch = c->sc_skip;
    }
}

int32_t sw_cond_oracle(sw_cond *c, const sw_reduced *red, sw_world_contacts *wc, sw_pose_space *ps,
                       sw_self_contacts *sc, int seed_self, const double *q) {
    c->stamp++;
    c->slot = (c->slot + 1) % SEED_STEPS;
    c->ncand = c->dropped = 0;
    c->nf = c->nt = c->nring = c->np = c->nrest = c->nring_patch = 0;
    ps->in_patch = NULL;
    if (sc) sc->in_patch = NULL;
    find_seeds(c, red, wc, seed_self ? sc : NULL, q);
    /* the oldest seeds first, this step's last; a vertex seeded twice grows once */
    for (int32_t k = 0; k < SEED_STEPS; ++k)
        for (int32_t i = 0, sl = (c->slot + 1 + k) % SEED_STEPS; i < c->nseeds[sl]; ++i) {
            int32_t s = c->seeds[(int64_t)sl * c->z.max_seeds + i];
            if (c->seeded[s] == c->stamp) continue;
            c->seeded[s] = c->stamp;
            grow(c, s);
        }
    /* the dynamics oracle's: the last patch while its flesh still moves */
    for (int32_t i = 0; c->keep && i < c->nkeep; ++i)
        if (!c->pinned[c->keep_v[i]] && !accept(c, c->keep_v[i], 0)) c->dropped++;
    c->keep = 0;
    if (c->ncand > c->z.max_verts) /* over budget: the nearest stay in the patch */
        keep_nearest(c, c->z.max_verts);
    c->nf = c->ncand;
    for (int32_t i = 0; i < c->nf; ++i) {
        c->fv[i] = c->cand[i];
        c->vloc[c->cand[i]] = i;
    }
    full_tets(c, red);
    patch_pairs(c, red, ps, sc);
    exact_domains(c, red);
    start_positions(c, red, q);
    return c->nf;
}

void sw_cond_finish(sw_cond *c, const sw_reduced *red, const double *q) {
    for (int32_t i = 0; i < c->nf; ++i) {
        int32_t gv = c->fv[i];
        double y[3];
        sw_cond_subspace_position(c, red, i, NULL, q, y);
        double R[9], t[3], e[3]; /* kept in the vertex's skin frame: it turns with the bones */
        sw_dqs_blend(red->bone_dq, c->v->skin_bone + 4 * (int64_t)gv,
                     c->v->skin_weight + 4 * (int64_t)gv, 4, R, t);
        for (int j = 0; j < 3; ++j)
            e[j] = c->x[3 * (int64_t)i + j] - y[j];
        for (int j = 0; j < 3; ++j)
            c->dev[3 * (int64_t)gv + j] = R[j] * e[0] + R[3 + j] * e[1] + R[6 + j] * e[2];
        c->dev_at[gv] = c->stamp;
    }
}

void sw_cond_subspace_position(const sw_cond *c, const sw_reduced *red, int32_t i,
                               const sw_dualquat *dq, const double *q, double x[3]) {
    const sw_blob_view *v = c->v;
    int32_t gv = c->fv[i], t = v->vert_tets[v->vert_tet_ptr[gv]];
    int k = 0;
    while (v->tets[4 * (int64_t)t + k] != gv)
        ++k;
    sw_reduced pose = *red; /* the same map, skinned by dq */
    if (dq) pose.bone_dq = dq;
    sw_cond_copy_position(&pose, gv, v->tet_domain[t], v->tet_local[4 * t + k], q, x, NULL);
}

void sw_cond_copy_position(const sw_reduced *red, int32_t gv, int32_t d, int32_t lv,
                           const double *q, double x[3], double *J) {
    const sw_blob_view *v = red->v;
    const sw_blob_domain *D = &v->domains[d];
    int32_t r = D->rank;
    double R[9], t[3];
    sw_dqs_blend(red->bone_dq, v->skin_bone + 4 * (int64_t)gv, v->skin_weight + 4 * (int64_t)gv, 4,
                 R, t);
    const double *U = v->basis + D->basis_offset + (int64_t)3 * lv * r,
                 *X = v->rest + 3 * (int64_t)gv;
    double y[3] = {X[0], X[1], X[2]};
    if (q)
        for (int i = 0; i < 3; ++i)
            for (int32_t j = 0; j < r; ++j)
                y[i] += U[i * r + j] * q[D->q_offset + j];
    for (int i = 0; i < 3; ++i)
        x[i] = R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + t[i];
    if (J)
        for (int i = 0; i < 3; ++i)
            for (int32_t j = 0; j < r; ++j)
                J[i * r + j] =
                    R[3 * i] * U[j] + R[3 * i + 1] * U[r + j] + R[3 * i + 2] * U[2 * r + j];
}
