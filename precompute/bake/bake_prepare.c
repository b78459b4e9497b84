/* The bake's first stages (bake.c, sw_bake_stages).
 *   prepare  reads the character; writes s->rig: the bake's own weights (heat diffusion
 *            when the asset has none), one-hot at bone-driven vertices, the top-4
 *            influences the runtime blends, lumped masses
 *   embed    reads the character's render mesh and the tets; writes s->embed and the
 *            result's render_* figures: the render mesh's embedding, computed right after
 *            prepare (a mesh that does not fit fails before the long stages) and written
 *            as the blob's render sections by the render stage (bake_render.c) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"
#include "weights_heat.h"

/* Keeps each vertex's 4 strongest influences, renormalised (the runtime blends 4). */
static void top4(const double *w, int32_t nb, int32_t *ids, double *ws) {
    for (int k = 0; k < 4; ++k) {
        ids[k] = 0;
        ws[k] = 0;
    }
    for (int32_t b = 0; b < nb; ++b) {
        if (!(w[b] > 0)) continue;
        int k = 4;
        while (k > 0 && w[b] > ws[k - 1])
            --k; /* insertion position */
        if (k == 4) continue;
        for (int j = 3; j > k; --j) {
            ids[j] = ids[j - 1];
            ws[j] = ws[j - 1];
        }
        ids[k] = b;
        ws[k] = w[b];
    }
    double sum = ws[0] + ws[1] + ws[2] + ws[3];
    if (sum > 0)
        for (int k = 0; k < 4; ++k)
            ws[k] /= sum;
    else
        ws[0] = 1.0;
}

/* prepare: the bake's own copy of the weights (heat diffusion when the character has
 * none), one-hot at bone-driven vertices so that skinning moves them exactly with their
 * bone, as the full-space reference does; top-4 influences; lumped masses. */
sinew_result sw_bake_prepare(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    (void)out;
    const sw_character *c = s->c;
    const int heat = c->weights.w == NULL;
    s->rig.ch = *c;
    s->rig.nv = c->mesh.nverts;
    s->rig.nt = c->mesh.ntets;
    s->rig.nb = c->skel.nbones;
    if (s->rig.nb > SW_MAX_BONES)
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED, "%d bones (at most %d)", s->rig.nb,
                            SW_MAX_BONES);
    size_t nw = (size_t)s->rig.nv * s->rig.nb;
    s->rig.weights = malloc(nw * sizeof(double));
    s->rig.skin_bone = malloc((size_t)s->rig.nv * 4 * sizeof(int32_t));
    s->rig.skin_weight = malloc((size_t)s->rig.nv * 4 * sizeof(double));
    s->rig.mass = calloc((size_t)s->rig.nv, sizeof(double));
    if (!s->rig.weights || !s->rig.skin_bone || !s->rig.skin_weight || !s->rig.mass)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for weights");
    if (heat) {
        sw_weights hw;
        memset(&hw, 0, sizeof hw);
        sinew_result r = sw_weights_heat(&c->mesh, &c->skel, 0, &hw, err);
        if (r != SINEW_OK) return r;
        memcpy(s->rig.weights, hw.w, nw * sizeof(double));
        sw_weights_free(&hw);
    } else {
        memcpy(s->rig.weights, c->weights.w, nw * sizeof(double));
    }
    for (int32_t v = 0; v < s->rig.nv; ++v) {
        int32_t b = c->bone_of_vertex[v];
        double *w = s->rig.weights + (size_t)v * s->rig.nb;
        if (b >= 0)
            for (int32_t k = 0; k < s->rig.nb; ++k)
                w[k] = k == b ? 1.0 : 0.0;
        top4(w, s->rig.nb, s->rig.skin_bone + 4 * v, s->rig.skin_weight + 4 * v);
    }
    s->rig.ch.weights.w = s->rig.weights;
    s->rig.ch.weights.nverts = s->rig.nv;
    s->rig.ch.weights.nbones = s->rig.nb;
    for (int32_t t = 0; t < s->rig.nt; ++t) {
        double Xe[12], Dm[9], vol;
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, c->mesh.X + 3 * (int64_t)c->mesh.tets[4 * t + k], 24);
        if (!sw_tet_rest(Xe, Dm, &vol))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tet %d is degenerate at rest", t);
        sw_lumped_mass_add(c->mesh.tets + 4 * t, c->density, vol, s->rig.mass);
    }
    return SINEW_OK;
}

/* embed: the render mesh in the tets (embed.h), its figures into the report; nothing
 * without a render mesh. */
sinew_result sw_bake_embed(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    const sw_character *c = s->c;
    if (c->render.nverts == 0) return SINEW_OK;
    sinew_result r = sw_embed_render(&c->mesh, &c->render, &s->embed, err);
    if (r != SINEW_OK) return r;
    out->render_outside = s->embed.outside;
    out->render_welded = s->embed.nwelded;
    out->render_max_outside = s->embed.max_outside;
    out->render_max_bary = s->embed.max_bary;
    out->embed_seconds = s->embed.seconds;
    return SINEW_OK;
}
