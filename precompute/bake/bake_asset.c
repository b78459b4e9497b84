/* The asset description's blob sections (sinew_blob_format.h, ids 52..56), written by the
 * stage "render" after the render mesh: the bones' names and bind poses, each output
 * vertex's source in the file, and what the blob was baked from, so that a host importing
 * the asset itself can map its skeleton and vertex buffers and tell a stale blob. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "hash.h"

#define MIX(h, x) ((h) = sw_fnv1a((h), &(x), sizeof(x)))

/* The options that shape the blob, field by field (the struct has pointers and padding).
 * Not the springs' stiffness: 0 asks the bake to choose one, and the blob baked with the
 * chosen one given is the same blob (its SPRING_HESSIAN holds it). Not the damping: META
 * holds it, and no other section depends on it. Not the thread count:
 * the blob is the same for any. */
static uint64_t options_hash(const sw_bake_params *p) {
    uint64_t h = SW_FNV_START;
    MIX(h, p->max_rank), MIX(h, p->fold_share), MIX(h, p->pca_energy), MIX(h, p->pca_strain);
    MIX(h, p->cubature_tol), MIX(h, p->cubature_max), MIX(h, p->selector);
    MIX(h, p->sweep_samples), MIX(h, p->pair_sweeps), MIX(h, p->sibling_sweeps);
    MIX(h, p->max_train_frames), MIX(h, p->return_path), MIX(h, p->pose_force);
    MIX(h, p->contact_modes), MIX(h, p->contact_cubature_tol), MIX(h, p->inertia_modes);
    MIX(h, p->heldout_fraction), MIX(h, p->ship_split), MIX(h, p->random_poses);
    MIX(h, p->heldout_steps), MIX(h, p->self_contact), MIX(h, p->seed);
    MIX(h, p->ntrain_clips), MIX(h, p->nheldout_clips), MIX(h, p->nextra_poses);
    MIX(h, p->extra_chain);
    return h;
}

/* nbones zero-terminated names back to back: the file's, or "bone N" where it had none. */
static char *bone_names(const sw_character *ch, int32_t nb, int32_t *nbytes) {
    char *names = malloc(64 * (size_t)nb);
    if (!names) return NULL;
    int32_t at = 0;
    for (int32_t b = 0; b < nb; ++b) {
        char one[64];
        if (ch->bone_names && ch->bone_names[b][0])
            snprintf(one, sizeof one, "%s", ch->bone_names[b]);
        else
            snprintf(one, sizeof one, "bone %d", (int)b);
        const size_t len = strlen(one) + 1;
        memcpy(names + at, one, len);
        at += (int32_t)len;
    }
    *nbytes = at;
    return names;
}

sinew_result sw_bake_asset(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    const sw_character *ch = &s->rig.ch;
    sw_blob_view *v = &out->view;
    const int32_t nb = s->rig.nb, nout = sw_blob_output_verts(v);
    const int embedded = v->nrender_verts > 0 && ch->render_source && ch->nsource_meshes > 0;
    int32_t nbytes = 0;
    char *names = sw_bake_own(out, bone_names(ch, nb, &nbytes));
    double *bind = sw_bake_own(out, malloc(12 * sizeof(double) * (size_t)nb));
    int32_t *mesh_verts =
        sw_bake_own(out, malloc(sizeof(int32_t) * (size_t)(embedded ? ch->nsource_meshes : 1)));
    int32_t *src = sw_bake_own(out, malloc(2 * sizeof(int32_t) * (size_t)nout));
    if (!names || !bind || !mesh_verts || !src)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the asset sections");
    static const double identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    for (int32_t b = 0; b < nb; ++b)
        memcpy(bind + 12 * b, ch->bone_bind ? ch->bone_bind + 12 * b : identity, sizeof identity);
    if (embedded) {
        memcpy(mesh_verts, ch->source_mesh_verts, sizeof(int32_t) * (size_t)ch->nsource_meshes);
        memcpy(src, ch->render_source, 2 * sizeof(int32_t) * (size_t)nout);
    } else {
        for (int32_t i = 0; i < 2 * nout; ++i)
            src[i] = -1;
    }
    v->nname_bytes = nbytes;
    v->nsource_meshes = embedded ? ch->nsource_meshes : 0;
    v->noutput_verts = nout;
    v->sinew_version = SINEW_VERSION;
    v->source_hash = ch->source_hash;
    v->options_hash = options_hash(s->p);
    v->bone_names = names;
    v->bone_bind = bind;
    v->source_mesh_verts = mesh_verts;
    v->output_source = src;
    return SINEW_OK;
}
