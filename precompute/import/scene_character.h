/* A simulation character from a rigged glTF 2.0 / FBX file: the assimp import
 * (scene_import.h), a tet mesh the lattice mesher (tet_lattice.h) or TetGen (tetgen_run.h,
 * closed surfaces only) fills the render surface with, skin weights transferred from the artist's
 * render weights (sw_weights_from_surface), bone-driven vertices, a material relative to the
 * character's size, the render mesh kept for embedding (sw_character.render), and the
 * file's clips split into training and held-out clips by name.
 *
 * Units: the file's, after assimp's unit conversion (or scaled to target_height): the
 * render mesh a host draws and the bone transforms it feeds stay in its own units. The
 * material is chosen relative to the size instead, so that a 1.5 m and a 155 m
 * character bake alike (see sw_scene_material). */
#ifndef SW_SCENE_CHARACTER_H
#define SW_SCENE_CHARACTER_H

#include "scene_import.h"
#include "sw_mesh.h"
#include "mesher.h"

/* Zero or NULL in a field means its default. */
typedef struct sw_scene_character_options {
    int32_t target_tets;       /* simulation tets (about; 100..5,000,000); 0: 20,000 */
    double fps;                /* clip sampling rate; 0: 30 */
    double target_height;      /* > 0: scale to this height; 0: the file's units */
    const char *train_clips;   /* comma-separated clip names; NULL: the default split */
    const char *heldout_clips; /* comma-separated clip names; NULL: the default split */
    sw_mesher mesher;          /* what fills the render surface with tets */
} sw_scene_character_options;

/* The file's clips as the bake uses them: training and held-out clips never share one. */
typedef struct sw_clip_split {
    int32_t ntrain, nheldout;
    sw_clip *train, *heldout; /* owned copies */
    char (*train_names)[64], (*heldout_names)[64];
} sw_clip_split;

void sw_clip_split_free(sw_clip_split *s);

/* What the import and the meshing did (for the bake's messages and its report). */
typedef struct sw_scene_character_info {
    sw_mesher_report mesh; /* what filled the render surface */
    int32_t render_verts, render_tris, nclips;
    int32_t anchored_components; /* mesh pieces with no driven vertex, anchored */
    int32_t undriven_bones;      /* bones that dominate no vertex: they drive none */
    double size;                 /* cube root of the tet mesh's volume (file units) */
    double unit_scale;           /* the importer's scale of the file's coordinates */
    double weight_dropped_max;   /* share of weight the importer's 4-influence cut dropped */
} sw_scene_character_info;

/* Chooses the split of the clips names[0..n) (lengths frames[]) by the comma-separated
 * lists train and heldout (NULL: default). Default: the two longest clips train (ties:
 * file order), the longest other one is held out; one clip alone trains (the bake then
 * holds out its last part). A list given alone takes the others' default from the clips
 * it leaves. Writes clip indices to train_idx / heldout_idx (n each at most).
 * INVALID_ARGUMENT naming the clip and listing the file's clips for an unknown name, a
 * name in both lists or twice in one, an empty name, or no clip left to train on. */
sinew_result sw_clip_split_choose(const char (*names)[64], const int32_t *frames, int32_t n,
                                  const char *train, const char *heldout, int32_t *train_idx,
                                  int32_t *ntrain, int32_t *heldout_idx, int32_t *nheldout,
                                  sw_error *err);

/* Young's modulus and density for a character of size L (the cube root of its volume,
 * in its own units): the samples' material (E 5000, nu 0.08, density 1, the thesis's
 * hand) as it would be at the finger sample's size L0, expressed at size L. Every
 * dimensionless group of the bake then matches the finger's: the contact penalty
 * against elasticity (k_c L / E, with the fixed k_c of the reference and the blob) and
 * the dynamics' time scale (rho L^2 / E), so E = 5000 L / L0 and rho = L0 / L. */
void sw_scene_material(double size, double *youngs, double *poisson, double *density);

/* The character of the file at `path`. out->clip is the first held-out clip (else the
 * first training clip, else one rest frame): what sinew-bench times. `clips` (may be
 * NULL) receives the split; `info` may be NULL. On failure everything is freed and the
 * message names the file. */
sinew_result sw_character_from_scene(const char *path, const sw_scene_character_options *o,
                                     sw_character *out, sw_clip_split *clips,
                                     sw_scene_character_info *info, sw_error *err);

#endif
