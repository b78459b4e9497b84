/* Procedural sample characters, generated at any resolution: a tube of round
 * cross-section along +x, meshed with good-quality tets, with a bone chain on its
 * axis, smooth skin weights, bone-driven interior vertices and a bending clip that
 * folds the joints far enough to cause self-contact.
 *   cylinder: 2 bones, 1 joint (thesis Fig. 3.3)
 *   finger:   3 bones, 2 joints, tapered with a rounded tip (Fig. 3.4)
 *   capsule:  2 bones, rounded ends (Fig. 4.4; later pressed against a pipe) */
#ifndef SW_SAMPLES_H
#define SW_SAMPLES_H

#include "sw_mesh.h"

/* Makes sample `name` with about `target_tets` tets (within ~25%; 1,000 to 2,000,000)
 * and a bending clip of `nframes` frames (>= 2) at 30 fps. */
sinew_result sw_sample_make(const char *name, int32_t target_tets, int32_t nframes,
                            sw_character *out, sw_error *err);

/* NULL-terminated list of sample names. */
const char *const *sw_sample_names(void);
#endif

#ifndef SW_SAMPLES_SCENE_DECL
#define SW_SAMPLES_SCENE_DECL
/* A named scene: a procedural sample (resolution target_tets, a clip of nframes) or a
 * folder of real assets under data_dir ("elephant-cd", "hand-libigl"; nframes bounds
 * the clip, 0 keeps the asset's own). *computed_weights is set when the asset has no
 * skin weights of its own (the bake then computes heat-diffusion weights). */
sinew_result sw_scene_make(const char *name, int32_t target_tets, int32_t nframes,
                           const char *data_dir, sw_character *out, int *computed_weights,
                           sw_error *err);
#endif
