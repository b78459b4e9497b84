/* sinew-fullsim: the full-space reference simulator on a procedural sample or a real
 * asset, frame by frame along the character's clip.
 *
 *   sinew-fullsim --scene NAME [--tets N] [--frames F] [--dynamic] [--newmark]
 *                 [--no-self-contact] [--ground H] [--world FILE.json] [--threads T]
 *                 [--data DIR] [--out DIR] [--json]
 *
 * NAME is a procedural sample (cylinder, finger, capsule) or a folder of the real
 * assets (elephant-cd, hand-libigl). With --world the character collides with the
 * world file's colliders, moved to their keyframes every frame (samples/worlds); the
 * file says whether the character plays its clip or holds its rest pose. Progress goes
 * to stderr; with --json the last line of stdout is one JSON object with the run's
 * figures. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define SW_TOOL_REFERENCE_ARGS
#include "tool_common.h"
#include "character_io.h"
#include "fullsim.h"
#include "mesh_io.h"
#include "samples.h"
#include "world_scene.h"

typedef struct {
    const char *scene, *out_dir, *data_dir, *world;
    int tets, frames, json, threads;
    sw_fullsim_params params;
} options;

static void usage(FILE *f) {
    fprintf(f,
            "usage: sinew-fullsim --scene NAME [--tets N] [--frames F] [--dynamic] [--newmark]\n"
            "                     [--no-self-contact] [--ground HEIGHT] [--world FILE.json]\n"
            "                     [--threads T]\n"
            "                     [reference options] [--data DIR] [--out DIR] [--json]\n"
            "  NAME: cylinder | finger | capsule (procedural) | elephant-cd | hand-libigl\n"
            "  --tets N      procedural resolution, 1000..2000000 (default 20000; samples only)\n"
            "  --frames F    frames to simulate, 1..1000000 (default: procedural 30, assets\n"
            "                their clip)\n"
            "  --threads T   0..256 (default 0: all cores)\n"
            "  --data DIR    the real assets' folder (asset scenes only)\n"
            "  --dynamic     backward Euler dynamics (default quasistatic); --newmark: "
            "Newmark\n"
            "  --world FILE  collide with a world file's colliders (JSON, schema 1; see\n"
            "                samples/worlds/README.md); --frames defaults to its "
            "length\n" SW_REFERENCE_USAGE
            "  --out DIR     write each frame's surface as DIR/frame_NNNN.obj\n"
            "  --json        print one JSON object with the figures as the last line\n"
            "exit status: 0 done, 1 failed (a failed frame too), 2 bad arguments\n");
}

static int is_sample(const char *name) {
    for (const char *const *n = sw_sample_names(); *n; ++n)
        if (!strcmp(*n, name)) return 1;
    return 0;
}

static int parse_args(int argc, char **argv, options *o) {
    memset(o, 0, sizeof *o);
    o->params = sw_fullsim_params_default();
    o->tets = 20000;
    o->frames = -1;
    o->data_dir = sw_tool_data_dir();
    const sw_tool_opt opts[] = {{"--scene", &o->scene, NULL, 0},
                                {"--out", &o->out_dir, NULL, 0},
                                {"--data", &o->data_dir, NULL, 0},
                                {"--world", &o->world, NULL, 0},
                                {"--no-self-contact", NULL, &o->params.self_contact, 0},
                                {"--json", NULL, &o->json, 1}};
    int ok = 1, tets_given = 0, data_given = 0, integrators = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        tets_given |= !strcmp(a, "--tets");
        data_given |= !strcmp(a, "--data");
        if (sw_tool_take(opts, sizeof opts / sizeof opts[0], argc, argv, &i)) {
            /* taken */
        } else if (!strcmp(a, "--tets") && next) {
            if (!sw_parse_int(argv[++i], 1000, 2000000, &o->tets)) {
                fprintf(stderr, "sinew-fullsim: --tets wants 1000..2000000, got '%s'\n", argv[i]);
                return 0;
            }
        } else if (!strcmp(a, "--frames") && next) {
            if (!sw_parse_int(argv[++i], 1, 1000000, &o->frames)) {
                fprintf(stderr,
                        "sinew-fullsim: --frames wants an integer in 1..1000000, got '%s'\n",
                        argv[i]);
                return 0;
            }
        } else if (!strcmp(a, "--threads") && next) {
            if (!sw_parse_int(argv[++i], 0, 256, &o->params.threads)) {
                fprintf(stderr, "sinew-fullsim: --threads wants 0..256, got '%s'\n", argv[i]);
                return 0;
            }
        } else if (!strcmp(a, "--ground") && next) {
            char *end;
            o->params.ground = 1;
            o->params.ground_height = strtod(argv[++i], &end);
            if (*end || !isfinite(o->params.ground_height)) {
                fprintf(stderr, "sinew-fullsim: --ground wants a height, got '%s'\n", argv[i]);
                return 0;
            }
        } else if (sw_reference_args_take(&o->params, argc, argv, &i, &ok)) {
            if (!ok) return 0;
        } else if (!strcmp(a, "--dynamic")) {
            o->params.integrator = SW_BACKWARD_EULER;
            integrators++;
        } else if (!strcmp(a, "--newmark")) {
            o->params.integrator = SW_NEWMARK;
            integrators++;
        } else if (!sw_tool_help(a, usage)) {
            return sw_tool_unknown_arg("sinew-fullsim", a);
        }
    }
    if (!o->scene) {
        fprintf(stderr, "sinew-fullsim: --scene is required\n");
        return 0;
    }
    if (tets_given && !is_sample(o->scene)) {
        fprintf(stderr,
                "sinew-fullsim: --tets does not apply to scene '%s' (a real asset with its own "
                "mesh); it sets a procedural sample's resolution\n",
                o->scene);
        return 0;
    }
    if (data_given && is_sample(o->scene)) {
        fprintf(stderr,
                "sinew-fullsim: --data does not apply to scene '%s' (a procedural sample); it "
                "locates the real assets\n",
                o->scene);
        return 0;
    }
    if (integrators > 1) {
        fprintf(stderr, "sinew-fullsim: give one of --dynamic and --newmark\n");
        return 0;
    }
    return !o->world ||
           sw_tool_format("sinew-fullsim", "--world", o->world, "json", ".json (world file)");
}

/* Writes the simulator's surface at positions x as an OBJ of the surface vertices. */
static int write_frame(const char *dir, int frame, const sw_surface *s, const double *x,
                       double *scratch, int32_t *tris, sw_error *err) {
    char path[4096];
    snprintf(path, sizeof path, "%s/frame_%04d.obj", dir, frame);
    for (int32_t i = 0; i < s->nverts; ++i)
        memcpy(scratch + 3 * i, x + 3 * s->verts[i], 24);
    /* s->verts is ascending: map tet-mesh ids to surface ids by binary search */
    for (int32_t t = 0; t < 3 * s->ntris; ++t) {
        int32_t lo = 0, hi = s->nverts - 1, id = s->tris[t];
        while (lo < hi) {
            int32_t mid = (lo + hi) / 2;
            if (s->verts[mid] < id)
                lo = mid + 1;
            else
                hi = mid;
        }
        tris[t] = lo;
    }
    return sw_write_obj(path, s->nverts, scratch, s->ntris, tris, err) == SINEW_OK;
}

int main(int argc, char **argv) {
    options o;
    if (!parse_args(argc, argv, &o)) {
        usage(stderr);
        return 2;
    }
    sw_error err;
    sw_error_clear(&err);
    sw_character ch;
    memset(&ch, 0, sizeof ch);
    sinew_result r;
    r = sw_scene_make(o.scene, o.tets, o.frames > 0 ? o.frames : (is_sample(o.scene) ? 30 : 60),
                      o.data_dir, &ch, NULL, &err);
    if (r != SINEW_OK)
        return sw_tool_failed(r, &err, "sinew-fullsim: cannot make scene '%s': ", o.scene);
    int frames = ch.clip.nframes;
    if (o.frames > 0 && o.frames < frames) frames = o.frames;
    const double *poses = ch.clip.T;
    double *world_poses = NULL;
    sw_world_scene ws;
    memset(&ws, 0, sizeof ws);
    if (o.world) {
        if ((r = sw_world_scene_load(o.world, &ws, &err)) != SINEW_OK) {
            sw_character_free(&ch);
            return sw_tool_failed(r, &err, "sinew-fullsim: ");
        }
        world_poses = sw_world_scene_poses(&ws, ch.clip.T, ch.clip.nframes, ch.skel.nbones,
                                           o.frames, &frames);
        if (!world_poses) {
            fprintf(stderr, "sinew-fullsim: out of memory\n");
            return 1;
        }
        poses = world_poses;
        o.params.world = ws.world;
    }
    sw_fullsim *sim = NULL;
    if ((r = sw_fullsim_create(&ch, &o.params, &sim, &err)) != SINEW_OK) {
        fprintf(stderr, "sinew-fullsim: %s (%s)\n", err.msg, sinew_result_string(r));
        sw_character_free(&ch);
        return 1;
    }
    const sw_surface *surf = sw_fullsim_surface(sim);
    double *scratch = NULL;
    int32_t *tris = NULL;
    if (o.out_dir) {
        if (!sw_tool_make_dirs(o.out_dir)) {
            fprintf(stderr, "sinew-fullsim: cannot create output folder '%s': %s\n", o.out_dir,
                    strerror(errno));
            sw_fullsim_destroy(sim);
            sw_character_free(&ch);
            return 1;
        }
        scratch = malloc((size_t)surf->nverts * 3 * sizeof(double));
        tris = malloc((size_t)surf->ntris * 3 * sizeof(int32_t));
        if (!scratch || !tris) {
            fprintf(stderr, "sinew-fullsim: out of memory\n");
            return 1;
        }
    }
    fprintf(stderr, "sinew-fullsim: %s, %d tets, %d vertices (%d bone-driven), %d frames, %s%s\n",
            ch.name, ch.mesh.ntets, ch.mesh.nverts, sw_fullsim_driven_count(sim), frames,
            o.params.integrator == SW_QUASISTATIC ? "quasistatic"
            : o.params.integrator == SW_NEWMARK   ? "dynamic (Newmark)"
                                                  : "dynamic (backward Euler)",
            o.params.self_contact ? ", self-contact on" : ", self-contact off");
    double *ms = malloc((size_t)(frames > 0 ? frames : 1) * sizeof(double));
    if (!ms) {
        fprintf(stderr, "sinew-fullsim: out of memory\n");
        return 1;
    }
    double newton_sum = 0, pcg_sum = 0, max_pen = 0, max_ground = 0, total = 0, pen_world = 0;
    int unconverged = 0, failed = 0, unsettled = 0, newton_max = 0, factors = 0;
    int world_frames = 0; /* frames with a vertex in contact with a collider */
    double ms_max = 0;
    sw_linear_solver solver = SW_SOLVER_AUTO;
    for (int f = 0; f < frames && ms; ++f) {
        sw_fullsim_stats st;
        if (o.world && (r = sw_world_scene_at(&ws, f, &err)) != SINEW_OK) {
            fprintf(stderr, "sinew-fullsim: %s\n", err.msg);
            failed++;
            break;
        }
        r = sw_fullsim_step(sim, poses + (size_t)f * 12 * ch.skel.nbones, &st);
        pen_world = fmax(pen_world, st.world_penetration);
        world_frames += st.world_contacts > 0;
        if (r == SINEW_ERROR_NOT_CONVERGED)
            unconverged++;
        else if (r != SINEW_OK)
            failed++;
        ms[f] = 1e3 * st.seconds;
        total += st.seconds;
        newton_sum += st.newton_iters;
        pcg_sum += st.pcg_iters;
        max_pen = fmax(max_pen, st.max_penetration);
        max_ground = fmax(max_ground, st.ground_penetration);
        unsettled += st.contacts_unsettled;
        newton_max = st.newton_iters > newton_max ? st.newton_iters : newton_max;
        ms_max = fmax(ms_max, ms[f]);
        factors += st.factorizations;
        solver = st.solver;
        fprintf(stderr,
                "  frame %4d/%d  %8.1f ms  newton %2d  pcg %5d  factor %3d  |g| %.2e -> %.2e  "
                "contacts %5d  "
                "penetration %.3g  world %d (%.3g)  rounds %d%s%s\n",
                f + 1, frames, ms[f], st.newton_iters, st.pcg_iters, st.factorizations,
                st.grad_norm0, st.grad_norm, st.contacts, st.max_penetration, st.world_contacts,
                st.world_penetration, st.contact_rounds,
                st.contacts_unsettled ? "  (contact set unsettled)" : "",
                r == SINEW_OK                    ? ""
                : r == SINEW_ERROR_NOT_CONVERGED ? "  (not converged)"
                                                 : "  FAILED");
        if (o.out_dir &&
            !write_frame(o.out_dir, f, surf, sw_fullsim_positions(sim), scratch, tris, &err)) {
            fprintf(stderr, "sinew-fullsim: %s\n", err.msg);
            failed++;
            break;
        }
    }
    double median = 0;
    if (ms && frames > 0) {
        median = sw_median(ms, frames);
    }
    double mean = frames > 0 ? 1e3 * total / frames : 0;
    fprintf(stderr,
            "sinew-fullsim: %s solver, ms/frame median %.1f mean %.1f max %.1f, %.2f Newton "
            "(max %d), %.1f PCG iterations and %.2f factorisations a frame, max penetration "
            "%.4g, %d unconverged, %d failed frames, %d unsettled frames (round cap %d); world "
            "contact in %d frames, deepest %.4g\n",
            sw_linear_solver_name(solver), median, mean, ms_max, newton_sum / frames, newton_max,
            pcg_sum / frames, (double)factors / frames, max_pen, unconverged, failed, unsettled,
            o.params.contact_rounds, world_frames, pen_world);
    if (o.json)
        printf("{\"scene\":\"%s\",\"tets\":%d,\"verts\":%d,\"driven_verts\":%d,\"surface_tris\":%d,"
               "\"frames\":%d,\"mode\":\"%s\",\"self_contact\":%s,\"threads\":%d,"
               "\"solver\":\"%s\","
               "\"ms_per_frame\":%.3f,\"ms_per_frame_mean\":%.3f,\"ms_per_frame_max\":%.3f,"
               "\"newton_iters_mean\":%.3f,\"newton_iters_max\":%d,\"pcg_iters_mean\":%.2f,"
               "\"factorizations_mean\":%.3f,\"max_penetration\":%.6g,"
               "\"max_ground_penetration\":%.6g,\"unconverged_frames\":%d,\"failed_frames\":%d,"
               "\"unsettled_frames\":%d,\"world\":%s%s%s,\"world_contact_frames\":%d,"
               "\"pen_world_full\":%.6g}\n",
               o.scene, ch.mesh.ntets, ch.mesh.nverts, sw_fullsim_driven_count(sim), surf->ntris,
               frames,
               o.params.integrator == SW_QUASISTATIC ? "quasistatic"
               : o.params.integrator == SW_NEWMARK   ? "newmark"
                                                     : "backward_euler",
               o.params.self_contact ? "true" : "false", o.params.threads,
               sw_linear_solver_name(solver), median, mean, ms_max, newton_sum / frames, newton_max,
               pcg_sum / frames, (double)factors / frames, max_pen, max_ground, unconverged, failed,
               unsettled, o.world ? "\"" : "", o.world ? o.world : "null", o.world ? "\"" : "",
               world_frames, pen_world);
    free(ms);
    free(world_poses);
    sw_world_scene_free(&ws);
    free(scratch);
    free(tris);
    sw_fullsim_destroy(sim);
    sw_character_free(&ch);
    return failed ? 1 : 0;
}
