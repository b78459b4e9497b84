#include "worldcontact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "collision.h"

static int push(sw_ref_world *w, const sw_ref_world_cand *c) {
    if (w->ncand == w->cap) {
        int32_t cap = w->cap ? 2 * w->cap : 1024;
        sw_ref_world_cand *n = realloc(w->cand, (size_t)cap * sizeof *n);
        if (!n) return 0;
        w->cand = n;
        w->cap = cap;
    }
    w->cand[w->ncand++] = *c;
    return 1;
}

int32_t sw_ref_world_detect(sw_ref_world *w, int32_t nv, const double *x, const double *area) {
    if (!w->world) return 0;
    if (!w->is_cand && !(w->is_cand = calloc((size_t)nv, 1))) return -1;
    int32_t fresh = 0;
    uint32_t ns = sw_world_slot_count(w->world);
    w->ncand = 0;
    /* the previous round's candidate vertices stay marked until the new set is built */
    for (uint32_t s = 0; s < ns; ++s) {
        const sw_collider *c = sw_world_slot(w->world, s);
        if (!c) continue;
        double lo[3], hi[3], ks = sw_collider_stiffness(c), mu = sw_collider_friction(c);
        sw_collider_bounds(c, w->radius, lo, hi);
        for (int32_t v = 0; v < nv; ++v) {
            sw_collider_hit hit;
            if (!(area[v] > 0) || !sw_box_contains(lo, hi, x + 3 * v) ||
                !sw_collider_query(c, x + 3 * v, w->radius, &hit))
                continue;
            sw_ref_world_cand cd;
            cd.law.k = (ks > 0 ? ks : w->blob_k) * area[v];
            memcpy(cd.law.a, hit.point, sizeof hit.point);
            memcpy(cd.law.n, hit.normal, sizeof hit.normal);
            cd.law.cap = mu * cd.law.k * fmax(0.0, -hit.phi);
            cd.v = v;
            cd.slot = (int32_t)s;
            if (!push(w, &cd)) return -1;
            if (hit.phi < 0 && !w->is_cand[v]) fresh++;
        }
    }
    memset(w->is_cand, 0, (size_t)nv);
    for (int32_t i = 0; i < w->ncand; ++i)
        w->is_cand[w->cand[i].v] = 1;
    return fresh;
}

double sw_ref_world_eval(const sw_ref_world *w, const double *x, double *f) {
    double E = 0;
    for (int32_t i = 0; i < w->ncand; ++i) {
        const sw_ref_world_cand *c = &w->cand[i];
        double fv[3];
        E += sw_world_penalty(&c->law, x + 3 * c->v, fv, NULL);
        if (f)
            for (int k = 0; k < 3; ++k)
                f[3 * c->v + k] += fv[k];
    }
    return E;
}

void sw_ref_world_free(sw_ref_world *w) {
    free(w->cand);
    free(w->is_cand);
    memset(w, 0, sizeof *w);
}
