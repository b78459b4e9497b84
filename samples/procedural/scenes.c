/* Named scenes for the tools: procedural samples or real asset folders. */
#include <string.h>

#include "character_io.h"
#include "samples.h"

sinew_result sw_scene_make(const char *name, int32_t target_tets, int32_t nframes,
                           const char *data_dir, sw_character *out, int *computed_weights,
                           sw_error *err) {
    if (computed_weights) *computed_weights = 0;
    if (!name) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "no scene name");
    for (const char *const *n = sw_sample_names(); *n; ++n)
        if (!strcmp(*n, name))
            return sw_sample_make(name, target_tets, nframes > 0 ? nframes : 30, out, err);
    /* hand-libigl ships no weights: sw_character_from_dataset fills simple ones */
    if (computed_weights) *computed_weights = !strcmp(name, "hand-libigl");
    return sw_character_from_dataset(data_dir, name, nframes, out, err);
}
