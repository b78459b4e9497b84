/* sinew-inspect FILE [--fps F] [--height H] [--tets N] [--mesher M] [--json]: what
 * sw_scene_import makes of a rigged glTF/FBX file (meshes merged, rigid and ignored, vertices,
 * triangles, the first joints, the clips, the bounding box, the weight cut to 4 influences)
 * and, with --tets, the simulation tet mesh the lattice mesher (tet_lattice.h) or TetGen
 * (tetgen_run.h) fills its render surface with and that mesh's quality. With --json the last line
 * is one JSON object. Exit 0 ok, 1 import or meshing failed (message on stderr), 2 bad arguments.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mesh_io.h"
#include "scene_import.h"
#include "mesher.h"
#include "tool_common.h"

static const char *tool = "sinew-inspect";

/* --mesher lattice | tetgen: *(int *)target = 1 for tetgen */
static int take_mesher(const char *t, const char *flag, const char *v, void *target) {
    static const char *const meshers[] = {"lattice", "tetgen", NULL};
    int k = sw_flags_choice(t, flag, v, meshers);
    if (k >= 0) *(int *)target = k;
    return k >= 0;
}

static void bbox(const sw_trimesh *m, double *size) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t v = 0; v < m->nverts; ++v)
        for (int c = 0; c < 3; ++c)
            lo[c] = fmin(lo[c], m->X[3 * v + c]), hi[c] = fmax(hi[c], m->X[3 * v + c]);
    for (int c = 0; c < 3; ++c)
        size[c] = m->nverts ? hi[c] - lo[c] : 0;
}

/* The simulation mesh of --tets and its quality. */
typedef struct {
    int on, tetgen;
    sw_tetmesh mesh;
    sw_mesher_report r;
    double surface_volume; /* the render surface's own (signed) */
    sw_quality q;
} sim_mesh;

static void print_sim_text(const sim_mesh *s) {
    if (s->tetgen)
        printf("simulation mesh: %d tets, %d vertices, by tetgen (%d run(s), volume bound %.4g, "
               "surface welded to %d vertices), volume %.4g (the surface's own %.4g), %.2f s\n",
               s->mesh.ntets, s->mesh.nverts, s->r.tetgen.runs, s->r.tetgen.max_volume,
               s->r.tetgen.welded_verts, s->r.tetgen.volume, s->surface_volume,
               s->r.tetgen.seconds);
    else
        printf("simulation mesh: %d tets, %d vertices, lattice spacing %.4g, %d component(s), "
               "volume %.4g (the surface's own %.4g), %.2f s\n",
               s->mesh.ntets, s->mesh.nverts, s->r.lattice.spacing, s->r.lattice.components,
               s->r.lattice.volume, s->surface_volume, s->r.lattice.seconds);
    printf("  quality: dihedral angles %.1f..%.1f degrees, %d inverted, %d degenerate, %d "
           "slivers\n",
           s->q.min_dihedral_deg, s->q.max_dihedral_deg, s->q.inverted, s->q.degenerate,
           s->q.slivers);
}

static void print_text(const char *path, const sw_imported_character *c, const double *size) {
    printf("%s\n", path);
    printf("meshes: %d skinned merged, %d rigid, %d ignored\n", c->nskinned, c->nrigid,
           c->nignored);
    printf("render: %d vertices, %d triangles, bounding box %.4g x %.4g x %.4g m (scale %g)\n",
           c->render.nverts, c->render.ntris, size[0], size[1], size[2], c->unit_scale);
    printf("joints: %d\n", c->skel.nbones);
    for (int32_t b = 0; b < c->skel.nbones && b < 10; ++b) {
        int32_t p = c->skel.parent[b];
        printf("  %3d %-32s parent %s\n", b, c->bone_names[b], p < 0 ? "-" : c->bone_names[p]);
    }
    if (c->skel.nbones > 10) printf("  ... %d more\n", c->skel.nbones - 10);
    printf("weights: share dropped by the 4-influence cut: max %.4g, mean %.4g\n",
           c->weight_dropped_max, c->weight_dropped_mean);
    printf("clips: %d\n", c->nclips);
    for (int32_t i = 0; i < c->nclips; ++i)
        printf("  %-24s %7.3f s %5d frames at %g fps\n", c->clips[i].name, c->clips[i].duration_s,
               c->clips[i].clip.nframes, c->clips[i].clip.fps);
}

static void print_json(const sw_imported_character *c, const double *size, const sim_mesh *s) {
    printf("{\"meshes_skinned\": %d, \"meshes_rigid\": %d, \"meshes_ignored\": %d, "
           "\"vertices\": %d, \"triangles\": %d, \"joints\": %d, \"bbox\": [%.6g, %.6g, %.6g], "
           "\"unit_scale\": %.6g, \"weight_dropped_max\": %.6g, \"weight_dropped_mean\": %.6g, "
           "\"joint_names\": [",
           c->nskinned, c->nrigid, c->nignored, c->render.nverts, c->render.ntris, c->skel.nbones,
           size[0], size[1], size[2], c->unit_scale, c->weight_dropped_max, c->weight_dropped_mean);
    for (int32_t b = 0; b < c->skel.nbones; ++b) {
        if (b) printf(", ");
        sw_tool_json_string(c->bone_names[b]);
    }
    printf("], \"parents\": [");
    for (int32_t b = 0; b < c->skel.nbones; ++b)
        printf("%s%d", b ? ", " : "", c->skel.parent[b]);
    printf("], \"clips\": [");
    for (int32_t i = 0; i < c->nclips; ++i) {
        printf("%s{\"name\": ", i ? ", " : "");
        sw_tool_json_string(c->clips[i].name);
        printf(", \"duration_s\": %.6g, \"frames\": %d}", c->clips[i].duration_s,
               c->clips[i].clip.nframes);
    }
    printf("]");
    if (s->on)
        printf(", \"sim_tets\": %d, \"sim_verts\": %d, \"sim_volume\": %.6g, \"surface_volume\": "
               "%.6g, \"sim_seconds\": %.4f, \"sim_min_dihedral_deg\": %.4g, \"sim_inverted\": %d",
               s->mesh.ntets, s->mesh.nverts, s->tetgen ? s->r.tetgen.volume : s->r.lattice.volume,
               s->surface_volume, s->tetgen ? s->r.tetgen.seconds : s->r.lattice.seconds,
               s->q.min_dihedral_deg, s->q.inverted);
    if (s->on && s->tetgen)
        printf(", \"sim_mesher\": \"tetgen\", \"sim_runs\": %d, \"sim_max_volume\": %.6g",
               s->r.tetgen.runs, s->r.tetgen.max_volume);
    else if (s->on)
        printf(", \"sim_mesher\": \"lattice\", \"sim_components\": %d, \"sim_spacing\": %.6g",
               s->r.lattice.components, s->r.lattice.spacing);
    printf("}\n");
}

int main(int argc, char **argv) {
    const char *path = NULL;
    sw_import_options o = {0};
    int json = 0, tets = 0, tetgen = 0;
    const sw_flag flags[] = {
        {SW_REAL("--fps", &o.fps, 0, 10000.0001, "in (0, 10000]", "F",
                 "clip sampling rate, in (0, 10000] (default 30)")},
        {SW_REAL("--height", &o.target_height, 0, 1e6, "in (0, 1e6)", "H",
                 "scale the render mesh to H metres tall (default: file units)")},
        {SW_INT("--tets", &tets, 100, 5000000, "N",
                "also fill the render surface with a simulation tet mesh of about N\n"
                "tets (100..5000000) and report it")},
        {SW_CALL("--mesher", take_mesher, &tetgen, "M",
                 "lattice (default: a lattice cut by the winding number, any\n"
                 "surface) or tetgen (the Debian program, closed surfaces only)")},
        {SW_SET("--json", &json, 1, "print one JSON object as the last line")},
    };
    const sw_flag_group groups[] = {{NULL, flags, SW_FLAGS_N(flags)}};
    const sw_tool_cli cli = {tool,
                             "sinew-inspect FILE [--fps F] [--height H] [--tets N] [--mesher M] "
                             "[--json]\n"
                             "  FILE             a rigged glTF 2.0 (.gltf/.glb) or FBX character\n",
                             groups,
                             1,
                             "exit status: 0 done, 1 failed, 2 bad arguments\n",
                             &path,
                             1};
    if (sw_flags_parse(&cli, argc, argv)) return 2;
    if (!path) {
        sw_flags_usage(&cli, stderr);
        return 2;
    }
    sw_imported_character c;
    sw_error err;
    sw_error_clear(&err);
    if (sw_scene_import(path, &o, &c, &err) != SINEW_OK) {
        fprintf(stderr, "%s: %s (%s)\n", tool, err.msg, sinew_result_string(err.code));
        return 1;
    }
    double size[3];
    bbox(&c.render, size);
    print_text(path, &c, size);
    sim_mesh sim = {.on = tets > 0, .tetgen = tetgen};
    if (sim.on) {
        sinew_result r;
        sw_pool *pool = tetgen ? NULL : sw_pool_create(0);
        r = sw_tetmesh_fill(&c.render, tets, tetgen ? SW_MESHER_TETGEN : SW_MESHER_LATTICE, pool,
                            &sim.mesh, &sim.r, &err);
        sw_pool_destroy(pool);
        sim.surface_volume = sw_trimesh_signed_volume(&c.render);
        if (r != SINEW_OK) {
            fprintf(stderr, "%s: %s (%s)\n", tool, err.msg, sinew_result_string(r));
            sw_imported_character_free(&c);
            return 1;
        }
        sw_tetmesh_quality(&sim.mesh, 0, &sim.q);
        print_sim_text(&sim);
    }
    if (json) print_json(&c, size, &sim);
    sw_tetmesh_free(&sim.mesh);
    sw_imported_character_free(&c);
    return 0;
}
