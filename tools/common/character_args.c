#include "character_args.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "character_paint.h"
#include "mesh_io.h"
#include "samples.h"
#include "tool_args.h"
#include "tool_files.h"
#include "tool_flags.h"

void sw_character_args_init(sw_character_args *c, const char *tool) {
    memset(c, 0, sizeof *c);
    c->tool = tool;
    c->data_dir = sw_tool_data_dir();
    c->tets = 20000;
    c->poisson = NAN; /* the character's own */
}

/* --mesher lattice | tetgen */
static int take_mesher(const char *tool, const char *flag, const char *v, void *target) {
    static const char *const meshers[] = {"lattice", "tetgen", NULL};
    int k = sw_flags_choice(tool, flag, v, meshers);
    if (k >= 0) ((sw_character_args *)target)->tetgen = k == 1;
    return k >= 0;
}

size_t sw_character_flags(sw_character_args *c, sw_flag *f) {
    const sw_flag flags[SW_CHARACTER_NFLAGS] = {
        {SW_STR("--train-clips", &c->train_clips, "A,B", "FILE's clips to train on")},
        {SW_STR("--heldout-clips", &c->heldout_clips, "C",
                "FILE's clips held out (never trained on)")},
        {SW_REAL("--fps", &c->fps, 0, 1000.0000001, "in 0 < F <= 1000", "F",
                 "FILE's clip sampling rate, 0 < F <= 1000 (default 30)")},
        {SW_REAL("--height", &c->height, 0, 1e6, "in 0 < H < 1e6", "H",
                 "scale FILE to H units tall, 0 < H < 1e6 (default: the file's units)")},
        {SW_CALL("--mesher", take_mesher, c, "M",
                 "what fills FILE's or a surface .obj's render surface with tets:\n"
                 "lattice (default; any surface, a lattice cut by the winding number)\n"
                 "| tetgen (the Debian program; closed surfaces only, the boundary is\n"
                 "the surface)"),
         .given = &c->mesher_given},
        {SW_STR("--scene", &c->scene, "NAME",
                "cylinder | finger | capsule (procedural samples) | elephant-cd |\n"
                "hand-libigl (real assets under --data DIR, default $SINEW_DATA_DIR or\n"
                "the build's shared data; --data only with these)")},
        {SW_STR("--data", &c->data_dir, "DIR", "the real assets' folder (with --scene)"),
         .given = &c->data_given},
        {SW_INT("--tets", &c->tets, 1000, 2000000, "N",
                "simulation tets of a procedural sample, a surface .obj or FILE,\n"
                "1000..2000000 (default 20000)"),
         .given = &c->tets_given},
        {SW_INT("--frames", &c->frames, SW_CHARACTER_MIN_FRAMES, 1000000, "F",
                "clip frames, 4..1000000 (procedural default 30; an asset's or --clip's\n"
                "own length at most F): the bake trains on the first 60% and holds out\n"
                "the rest, and a clip starting at rest needs 2 training frames")},
        {SW_STR("--mesh", &c->mesh, "FILE",
                "a tet mesh: .mesh (MEDIT) | .node/.ele (TetGen); needs --skeleton")},
        {SW_STR("--skeleton", &c->tgf, "FILE", "a .tgf skeleton (with --mesh only)")},
        {SW_STR("--weights", &c->weights, "FILE",
                ".dmat skin weights (with --mesh only; default: computed)")},
        {SW_STR("--clip", &c->clip, "FILE",
                "a .txt bone animation or a .dmat pose (with --mesh only)")},
        {SW_STR("--joint-range", &c->joint_range, "FILE",
                "each joint's range of motion (with --mesh and no --clip): its\n"
                "largest turn in a .dmat pose or .txt bone animation bounds the\n"
                "joint sweeps and random combined poses (default: 90 degrees across\n"
                "every bone)")},
        {SW_REAL("--youngs", &c->youngs, 0, 1e15, "in 0 < E < 1e15", "E",
                 "Young's modulus of the flesh (default: a FILE's or a surface's relative\n"
                 "to its size, a scene's or tet mesh's its own)")},
        {SW_REAL("--poisson", &c->poisson, -1, 0.5, "in -1 < NU < 0.5", "NU",
                 "Poisson ratio of the flesh, -1 < NU < 0.5 (default as --youngs)")},
        {SW_REAL("--density", &c->density, 0, 1e15, "in 0 < RHO < 1e15", "RHO",
                 "mass per unit volume of the flesh (default as --youngs)")},
        {SW_STR("--stiffness-map", &c->stiffness_map, "FILE",
                "painted material: a .dmat of one multiplier of E per render vertex\n"
                "(a FILE's, in the blob's output order) or per tet-mesh vertex (--mesh,\n"
                "--scene); 0.25 is four times softer. A glTF FILE's own painting, a\n"
                "_SINEW_STIFFNESS vertex attribute, is read without it")},
    };
    memcpy(f, flags, sizeof flags);
    return SW_CHARACTER_NFLAGS;
}

int sw_character_is_sample(const char *name) {
    for (const char *const *n = sw_sample_names(); *n; ++n)
        if (!strcmp(*n, name)) return 1;
    return 0;
}

/* A glTF/FBX FILE: its format, and no option of the other inputs (each named). */
static int sw_scene_file_args_valid(const sw_character_args *c) {
    const char *opts[] = {c->tgf,
                          c->weights,
                          c->clip,
                          c->data_given ? c->data_dir : NULL,
                          c->frames ? "" : NULL,
                          c->joint_range},
               *names[] = {"--skeleton", "--weights", "--clip",
                           "--data",     "--frames",  "--joint-range"};
    for (int k = 0; k < 6; ++k)
        if (opts[k]) {
            fprintf(stderr,
                    "%s: %s does not apply to a glTF/FBX FILE (it brings its skeleton, weights "
                    "and clips; choose clips with --train-clips, --heldout-clips)\n",
                    c->tool, names[k]);
            return 0;
        }
    return sw_tool_format(c->tool, "FILE", c->file, "glb gltf fbx", ".glb, .gltf (glTF 2.0), .fbx");
}

int sw_character_args_valid(const sw_character_args *c) {
    const char *t = c->tool;
    if (!!c->scene + !!c->mesh + !!c->file != 1) {
        fprintf(stderr,
                "%s: give one character: a glTF/FBX FILE, --scene NAME or --mesh (with "
                "--skeleton)\n",
                t);
        return 0;
    }
    if (c->file) return sw_scene_file_args_valid(c);
    if (c->mesher_given && !(c->mesh && sw_tool_has_ext(c->mesh, "obj"))) {
        fprintf(stderr,
                "%s: --mesher applies only to a render surface to fill: a glTF/FBX FILE or "
                "--mesh FILE.obj\n",
                t);
        return 0;
    }
    if (c->train_clips || c->heldout_clips || c->fps > 0 || c->height > 0) {
        fprintf(stderr,
                "%s: %s applies only to a glTF/FBX FILE (the clips are chosen by name there)\n", t,
                c->train_clips     ? "--train-clips"
                : c->heldout_clips ? "--heldout-clips"
                : c->fps > 0       ? "--fps"
                                   : "--height");
        return 0;
    }
    if (c->scene) {
        const char *files[] = {c->tgf, c->weights, c->clip, c->joint_range},
                   *names[] = {"--skeleton", "--weights", "--clip", "--joint-range"};
        for (int k = 0; k < 4; ++k)
            if (files[k]) {
                fprintf(stderr,
                        "%s: %s does not apply to --scene (the scene brings its own); it "
                        "goes with --mesh\n",
                        t, names[k]);
                return 0;
            }
        int sample = sw_character_is_sample(c->scene);
        if (!sample && c->tets_given) {
            fprintf(stderr,
                    "%s: --tets does not apply to scene '%s' (a real asset with its own mesh); "
                    "it sets a procedural sample's resolution\n",
                    t, c->scene);
            return 0;
        }
        if (sample && c->data_given) {
            fprintf(stderr,
                    "%s: --data does not apply to scene '%s' (a procedural sample); it locates "
                    "the real assets\n",
                    t, c->scene);
            return 0;
        }
        return 1;
    }
    if (!c->tgf) {
        fprintf(stderr, "%s: --mesh needs --skeleton\n", t);
        return 0;
    }
    int surface = sw_tool_has_ext(c->mesh, "obj");
    if ((c->tets_given && !surface) || c->data_given) {
        fprintf(stderr, "%s: %s does not apply to --mesh %s (it goes with --scene%s)\n", t,
                c->tets_given ? "--tets" : "--data", surface ? "FILE.obj" : "with a tet mesh",
                c->tets_given ? " or a surface .obj" : "");
        return 0;
    }
    if (surface && c->weights) {
        fprintf(stderr,
                "%s: --weights does not apply to a surface --mesh (the bake computes "
                "heat-diffusion weights for the tets it generates)\n",
                t);
        return 0;
    }
    if (c->joint_range && c->clip) {
        fprintf(stderr,
                "%s: --joint-range does not apply with --clip (the clip's training frames "
                "bound the joint sweeps)\n",
                t);
        return 0;
    }
    if (c->frames && !c->clip) {
        fprintf(stderr,
                "%s: --frames does not apply to --mesh without --clip (it bounds the clip's "
                "frames)\n",
                t);
        return 0;
    }
    return sw_tool_format(t, "--mesh", c->mesh, "mesh node ele obj",
                          ".mesh (MEDIT), .node or .ele (TetGen), .obj (a render surface)") &&
           sw_tool_format(t, "--skeleton", c->tgf, "tgf", ".tgf") &&
           (!c->weights || sw_tool_format(t, "--weights", c->weights, "dmat", ".dmat")) &&
           (!c->clip || sw_tool_format(t, "--clip", c->clip, "txt dmat",
                                       ".txt (bone animation), .dmat (pose quaternions)")) &&
           (!c->joint_range || sw_tool_format(t, "--joint-range", c->joint_range, "txt dmat",
                                              ".txt (bone animation), .dmat (pose quaternions)"));
}

void sw_tool_print_scene(const char *tool, const sw_character *ch, const sw_clip_split *clips,
                         const sw_scene_character_info *in, const sw_quality *q) {
    fprintf(stderr, "%s: render mesh %d vertices, %d triangles; ", tool, in->render_verts,
            in->render_tris);
    if (in->mesh.mesher == SW_MESHER_TETGEN)
        fprintf(stderr, "tetgen: %d tets, volume bound %.4g, %d run(s), %.2f s", ch->mesh.ntets,
                in->mesh.tetgen.max_volume, in->mesh.tetgen.runs, in->mesh.tetgen.seconds);
    else
        fprintf(stderr, "lattice spacing %.4g, %d piece(s)", in->mesh.lattice.spacing,
                in->mesh.lattice.components);
    fprintf(stderr,
            " (%d anchored); size %.4g (cube root of the volume), E %.4g, nu %.3g, density %.4g; "
            "%d bone(s) skin no vertex most and drive none\n",
            in->anchored_components, in->size, ch->youngs, ch->poisson, ch->density,
            in->undriven_bones);
    fprintf(stderr,
            "%s: mesh quality: dihedral angles %.1f..%.1f degrees, %d sliver(s) under 5 degrees, "
            "%d inverted, %d degenerate\n",
            tool, q->min_dihedral_deg, q->max_dihedral_deg, q->slivers, q->inverted, q->degenerate);
    fprintf(stderr, "%s: clips: training", tool);
    for (int32_t i = 0; i < clips->ntrain; ++i)
        fprintf(stderr, "%s %s (%d frames)", i ? "," : "", clips->train_names[i],
                clips->train[i].nframes);
    fprintf(stderr, "; held out");
    for (int32_t i = 0; i < clips->nheldout; ++i)
        fprintf(stderr, "%s %s (%d frames)", i ? "," : "", clips->heldout_names[i],
                clips->heldout[i].nframes);
    if (clips->nheldout == 0) fprintf(stderr, " the last part of the training clip");
    fprintf(stderr, "\n");
}

void sw_tool_bake_clips(const sw_character_args *c, const sw_clip_split *clips, sw_bake_params *p) {
    if (clips->ntrain == 0 || (clips->nheldout == 0 && !c->train_clips)) return;
    p->train_clips = clips->train;
    p->ntrain_clips = clips->ntrain;
    p->heldout_clips = clips->heldout;
    p->nheldout_clips = clips->nheldout;
}

/* The material flags over what the character came with; on failure ch is freed. */
static sinew_result material(const sw_character_args *c, sw_character *ch, sw_error *err) {
    if (c->youngs > 0) ch->youngs = c->youngs;
    if (!isnan(c->poisson)) ch->poisson = c->poisson;
    if (c->density > 0) ch->density = c->density;
    sinew_result r =
        c->stiffness_map ? sw_character_read_stiffness(c->stiffness_map, ch, err) : SINEW_OK;
    if (r) sw_character_free(ch);
    return r;
}

sinew_result sw_character_args_make(const sw_character_args *c, sw_character *ch,
                                    sw_clip_split *clips, sw_scene_character_info *info,
                                    sw_error *err) {
    int computed = 0;
    sw_error_clear(err);
    memset(ch, 0, sizeof *ch);
    if (clips) memset(clips, 0, sizeof *clips);
    sinew_result r;
    if (c->file) {
        sw_scene_character_options o = {
            c->tets,        c->fps,           c->height,
            c->train_clips, c->heldout_clips, c->tetgen ? SW_MESHER_TETGEN : SW_MESHER_LATTICE};
        r = sw_character_from_scene(c->file, &o, ch, clips, info, err);
        return r ? r : material(c, ch, err);
    }
    r = c->scene ? sw_scene_make(c->scene, c->tets, c->frames, c->data_dir, ch, &computed, err)
        : sw_tool_has_ext(c->mesh, "obj")
            ? sw_character_from_surface(c->mesh, c->tets,
                                        c->tetgen ? SW_MESHER_TETGEN : SW_MESHER_LATTICE, c->tgf,
                                        c->clip, c->frames, ch, NULL, err)
            : sw_character_from_files(c->mesh, c->tgf, c->weights, c->clip, c->frames, ch, err);
    if (r == SINEW_OK && (computed || (c->mesh && !c->weights))) sw_weights_free(&ch->weights);
    if (r == SINEW_OK && c->joint_range && (r = sw_character_read_range(c->joint_range, ch, err)))
        sw_character_free(ch);
    return r ? r : material(c, ch, err);
}
