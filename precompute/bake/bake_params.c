/* The bake's parameters' defaults and its result's memory (bake_params.h). */
#include "bake_params.h"

#include <stdlib.h>
#include <string.h>

sw_bake_params sw_bake_params_default(void) {
    sw_bake_params p;
    memset(&p, 0, sizeof p);
    p.max_rank = 30;
    p.fold_share = 0;
    p.pca_energy = 0.9999;
    p.pca_strain = 0;
    p.cubature_tol = 0.05;
    p.cubature_max = 1000;
    p.selector = SW_CUBATURE_NNHTP;
    p.sweep_samples = 6;
    p.pair_sweeps = -1;
    p.sibling_sweeps = 1;
    p.max_train_frames = 40;
    p.return_path = -1;
    p.pose_force = 1;
    p.inertia_modes = 0;
    p.contact_cubature_tol = 0.05;
    p.heldout_fraction = 0.4;
    p.random_poses = 10;
    p.heldout_steps = 4;
    p.self_contact = 1;
    p.rayleigh_alpha = 0.01;
    p.rayleigh_beta = 0.001;
    p.spring_k = 0;
    p.cache_dir = NULL;
    p.threads = 0;
    p.seed = 0x5eed5eedULL;
    p.progress = 0;
    p.on_progress = NULL;
    p.progress_user = NULL;
    return p;
}

void *sw_bake_own(sw_bake_result *out, void *p) {
    if (!p) return NULL;
    if (out->nowned == out->owned_cap) { /* the list grows: a view has no fixed section count */
        int32_t cap = out->owned_cap ? 2 * out->owned_cap : 64;
        void **grown = realloc(out->owned, (size_t)cap * sizeof *grown);
        if (!grown) { /* the caller sees out of memory and the array is not leaked */
            free(p);
            return NULL;
        }
        out->owned = grown;
        out->owned_cap = cap;
    }
    out->owned[out->nowned++] = p;
    return p;
}

void sw_bake_result_free(sw_bake_result *r) {
    if (!r) return;
    for (int32_t i = 0; i < r->nowned; ++i)
        free(r->owned[i]);
    free(r->owned);
    free(r->heldout_x);
    free(r->heldout_T);
    free(r->train_x);
    free(r->train_T);
    free(r->mass);
    free(r->basis_energy);
    free(r->train_clip);
    free(r->train_frame);
    free(r->heldout_clip);
    free(r->heldout_frame);
    memset(r, 0, sizeof *r);
}
