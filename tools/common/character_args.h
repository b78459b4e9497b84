/* The character inputs sinew-bake and sinew-bench share: a named scene, a tet mesh
 * with its skeleton, a surface to fill, or a rigged glTF/FBX file. */
#ifndef SW_CHARACTER_ARGS_H
#define SW_CHARACTER_ARGS_H

#include "bake.h"
#include "character_io.h"
#include "mesh_io.h"
#include "scene_character.h"
#include "tool_flags.h"

typedef struct sw_character_args {
    const char *tool; /* for messages */
    const char *scene, *mesh, *tgf, *weights, *clip, *data_dir;
    const char *joint_range;                 /* --joint-range: a pose or animation */
    const char *file;                        /* a rigged glTF/FBX character (positional) */
    const char *train_clips, *heldout_clips; /* its clips by name */
    double fps, height;                      /* its clip rate and scale (0: defaults) */
    int tets, frames;
    int tets_given, data_given;
    int tetgen, mesher_given; /* --mesher tetgen; --mesher at all (surfaces only) */
    /* the material: --youngs, --poisson, --density (0 / NAN: the character's own), and
     * --stiffness-map, painted multipliers of E */
    double youngs, poisson, density;
    const char *stiffness_map;
} sw_character_args;

/* The least --frames: the fewest clip frames a bake trains on (bake.h). */
#define SW_CHARACTER_MIN_FRAMES 4
#define SW_CHARACTER_NFLAGS 18
/* The usage's lines before the character flags: what FILE is (the first bare argument). */
#define SW_CHARACTER_FILE_USAGE                                                                    \
    "  FILE             a rigged glTF 2.0 (.gltf, .glb) or FBX character: its render surface\n"    \
    "                   filled with about --tets N tets, weights from the artist's, clips by\n"    \
    "                   name (default: the two longest train, the next longest is held out)"

/* 1 when name is a procedural sample (samples.h), 0 for a real asset's folder. */
int sw_character_is_sample(const char *name);

void sw_character_args_init(sw_character_args *c, const char *tool);

/* The character flags, bound to c, into f[0..SW_CHARACTER_NFLAGS); returns their count.
 * FILE is the tool's first bare argument (sw_tool_cli.positional = &c->file). */
size_t sw_character_flags(sw_character_args *c, sw_flag *f);

/* Exactly one of FILE, --scene and --mesh, --mesh needs --skeleton, and no option that
 * does not apply to the chosen input (each named on stderr); 1 when valid. */
int sw_character_args_valid(const sw_character_args *c);

/* What a glTF/FBX FILE became (the mesher's lattice, the material, the clip split). */
void sw_tool_print_scene(const char *tool, const sw_character *ch, const sw_clip_split *clips,
                         const sw_scene_character_info *in, const sw_quality *q);

/* A FILE's clips for the bake: its training and held-out clips, each its own path
 * (bake.h). A file of one clip (nothing held out, no --train-clips) is split as a
 * single clip is (the character's clip then): its last part held out. */
void sw_tool_bake_clips(const sw_character_args *c, const sw_clip_split *clips, sw_bake_params *p);

/* Builds the character into *ch (zeroed first; err cleared first); a FILE's clip split
 * into *clips and what its import did into *info (both may be NULL; zeroed for the other
 * inputs). When the asset has no
 * skin weights of its own (files without --weights, or an asset folder that ships none)
 * they are dropped, so that the bake computes heat-diffusion weights. */
sinew_result sw_character_args_make(const sw_character_args *c, sw_character *ch,
                                    sw_clip_split *clips, sw_scene_character_info *info,
                                    sw_error *err);

#endif
