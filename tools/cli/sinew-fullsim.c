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

#define SW_TOOL_CHARACTER_ARGS
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

/* --ground H: the ground plane at height H */
static int take_ground(const char *tool, const char *flag, const char *v, void *target) {
    sw_fullsim_params *p = target;
    char *end;
    p->ground = 1;
    p->ground_height = strtod(v, &end);
    if (*end || end == v || !isfinite(p->ground_height)) {
        fprintf(stderr, "%s: %s wants a height, got '%s'\n", tool, flag, v);
        return 0;
    }
    return 1;
}

static const char *const SYNOPSIS =
    "sinew-fullsim --scene NAME [--tets N] [--frames F] [--dynamic] [--newmark]\n"
    "                     [--no-self-contact] [--ground HEIGHT] [--world FILE.json]\n"
    "                     [--threads T]\n"
    "                     [reference options] [--data DIR] [--out DIR] [--json]\n";

/* What the command line gives besides the options: which flags were seen. */
typedef struct {
    int tets, data, dynamic, newmark;
} given;

/* Parses argv into *o; 0 for a usable command line, else the exit status 2 (the message
 * is out). */
static int parse_args(int argc, char **argv, options *o) {
    memset(o, 0, sizeof *o);
    o->params = sw_fullsim_params_default();
    o->tets = 20000;
    o->frames = -1;
    o->data_dir = sw_tool_data_dir();
    given g = {0};
    const sw_flag flags[] = {
        {SW_STR("--scene", &o->scene, "NAME",
                "cylinder | finger | capsule (procedural) | elephant-cd | hand-libigl")},
        {SW_INT("--tets", &o->tets, 1000, 2000000, "N",
                "procedural resolution, 1000..2000000 (default 20000; samples only)"),
         .given = &g.tets},
        {SW_INT("--frames", &o->frames, 1, 1000000, "F",
                "frames to simulate, 1..1000000 (default: procedural 30, assets\n"
                "their clip)")},
        {SW_INT("--threads", &o->params.threads, 0, 256, "T", "0..256 (default 0: all cores)")},
        {SW_STR("--data", &o->data_dir, "DIR", "the real assets' folder (asset scenes only)"),
         .given = &g.data},
        {SW_SET("--dynamic", &o->params.integrator, SW_BACKWARD_EULER,
                "backward Euler dynamics (default quasistatic)"),
         .given = &g.dynamic},
        {SW_SET("--newmark", &o->params.integrator, SW_NEWMARK, "Newmark dynamics"),
         .given = &g.newmark},
        {SW_SET("--no-self-contact", &o->params.self_contact, 0, "no penalty self-contact")},
        {SW_CALL("--ground", take_ground, &o->params, "HEIGHT", "a ground plane at y = HEIGHT")},
        {SW_STR("--world", &o->world, "FILE",
                "collide with a world file's colliders (JSON, schema 1; see\n"
                "samples/worlds/README.md); --frames defaults to its length")},
        {SW_STR("--out", &o->out_dir, "DIR", "write each frame's surface as DIR/frame_NNNN.obj")},
        {SW_SET("--json", &o->json, 1, "print one JSON object with the figures as the last line")},
    };
    sw_flag reference[SW_REFERENCE_NFLAGS];
    sw_flag_group groups[] = {
        {NULL, flags, SW_FLAGS_N(flags)},
        {"reference options:", reference, sw_reference_flags(&o->params, reference)}};
    sw_tool_cli cli = {"sinew-fullsim",
                       SYNOPSIS,
                       groups,
                       SW_FLAGS_N(groups),
                       "exit status: 0 done, 1 failed (a failed frame too), 2 bad arguments\n",
                       NULL,
                       0};
    if (sw_flags_parse(&cli, argc, argv)) return 2;
    if (!o->scene) {
        fprintf(stderr, "sinew-fullsim: --scene is required\n");
        return 2;
    }
    if (g.tets && !sw_character_is_sample(o->scene)) {
        fprintf(stderr,
                "sinew-fullsim: --tets does not apply to scene '%s' (a real asset with its own "
                "mesh); it sets a procedural sample's resolution\n",
                o->scene);
        return 2;
    }
    if (g.data && sw_character_is_sample(o->scene)) {
        fprintf(stderr,
                "sinew-fullsim: --data does not apply to scene '%s' (a procedural sample); it "
                "locates the real assets\n",
                o->scene);
        return 2;
    }
    if (g.dynamic && g.newmark) {
        fprintf(stderr, "sinew-fullsim: give one of --dynamic and --newmark\n");
        return 2;
    }
    return o->world && !sw_tool_format("sinew-fullsim", "--world", o->world, "json",
                                       ".json (world file)")
               ? 2
               : 0;
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

/* What the frames added up to. */
typedef struct {
    double newton_sum, pcg_sum, max_pen, max_ground, total, pen_world, ms_max, median, mean;
    int unconverged, failed, unsettled, newton_max, factors;
    int world_frames; /* frames with a vertex in contact with a collider */
    sw_linear_solver solver;
} tally;

/* Steps the reference through the frames (with --world, the colliders moved to each),
 * each frame's line on stderr and with --out its surface written; ms[f]: its time. */
static void step_frames(const options *o, sw_fullsim *sim, sw_world_scene *ws, const double *poses,
                        int nbones, int frames, double *scratch, int32_t *tris, double *ms,
                        tally *t) {
    const sw_surface *surf = sw_fullsim_surface(sim);
    sw_error err;
    sinew_result r;
    for (int f = 0; f < frames && ms; ++f) {
        sw_fullsim_stats st;
        if (o->world && (r = sw_world_scene_at(ws, f, &err)) != SINEW_OK) {
            fprintf(stderr, "sinew-fullsim: %s\n", err.msg);
            t->failed++;
            break;
        }
        r = sw_fullsim_step(sim, poses + (size_t)f * 12 * nbones, &st);
        t->pen_world = fmax(t->pen_world, st.world_penetration);
        t->world_frames += st.world_contacts > 0;
        if (r == SINEW_ERROR_NOT_CONVERGED)
            t->unconverged++;
        else if (r != SINEW_OK)
            t->failed++;
        ms[f] = 1e3 * st.seconds;
        t->total += st.seconds;
        t->newton_sum += st.newton_iters;
        t->pcg_sum += st.pcg_iters;
        t->max_pen = fmax(t->max_pen, st.max_penetration);
        t->max_ground = fmax(t->max_ground, st.ground_penetration);
        t->unsettled += st.contacts_unsettled;
        t->newton_max = st.newton_iters > t->newton_max ? st.newton_iters : t->newton_max;
        t->ms_max = fmax(t->ms_max, ms[f]);
        t->factors += st.factorizations;
        t->solver = st.solver;
        fprintf(stderr,
                "  frame %4d/%d  %8.1f ms  newton %2d  pcg %5d  factor %3d  |g| %.2e -> %.2e  "
                "contacts %5d  "
                "penetration %.3g  world %d (%.3g)  rounds %d%s%s\n",
                f + 1, frames, ms[f], st.newton_iters, st.pcg_iters, st.factorizations,
                st.grad_norm0, st.grad_norm, st.contacts, st.max_penetration, st.world_contacts,
                st.world_penetration, st.contact_rounds,
                st.contacts_unsettled ? "  (contact set t->unsettled)" : "",
                r == SINEW_OK                    ? ""
                : r == SINEW_ERROR_NOT_CONVERGED ? "  (not converged)"
                                                 : "  FAILED");
        if (o->out_dir &&
            !write_frame(o->out_dir, f, surf, sw_fullsim_positions(sim), scratch, tris, &err)) {
            fprintf(stderr, "sinew-fullsim: %s\n", err.msg);
            t->failed++;
            break;
        }
    }
}

/* The run's summary on stderr and with --json its JSON line. */
static void report(const options *o, const sw_character *ch, sw_fullsim *sim, int frames,
                   double *ms, tally *t) {
    const sw_surface *surf = sw_fullsim_surface(sim);
    t->median = 0;
    if (ms && frames > 0) {
        t->median = sw_median(ms, frames);
    }
    t->mean = frames > 0 ? 1e3 * t->total / frames : 0;
    fprintf(
        stderr,
        "sinew-fullsim: %s t->solver, ms/frame t->median %.1f t->mean %.1f max %.1f, %.2f Newton "
        "(max %d), %.1f PCG iterations and %.2f factorisations a frame, max penetration "
        "%.4g, %d t->unconverged, %d t->failed frames, %d t->unsettled frames (round cap %d); "
        "world "
        "contact in %d frames, deepest %.4g\n",
        sw_linear_solver_name(t->solver), t->median, t->mean, t->ms_max, t->newton_sum / frames,
        t->newton_max, t->pcg_sum / frames, (double)t->factors / frames, t->max_pen, t->unconverged,
        t->failed, t->unsettled, o->params.contact_rounds, t->world_frames, t->pen_world);
    if (o->json)
        printf("{\"scene\":\"%s\",\"tets\":%d,\"verts\":%d,\"driven_verts\":%d,\"surface_tris\":%d,"
               "\"frames\":%d,\"mode\":\"%s\",\"self_contact\":%s,\"threads\":%d,"
               "\"solver\":\"%s\","
               "\"ms_per_frame\":%.3f,\"ms_per_frame_mean\":%.3f,\"ms_per_frame_max\":%.3f,"
               "\"newton_iters_mean\":%.3f,\"newton_iters_max\":%d,\"pcg_iters_mean\":%.2f,"
               "\"factorizations_mean\":%.3f,\"max_penetration\":%.6g,"
               "\"max_ground_penetration\":%.6g,\"unconverged_frames\":%d,\"failed_frames\":%d,"
               "\"unsettled_frames\":%d,\"world\":%s%s%s,\"world_contact_frames\":%d,"
               "\"pen_world_full\":%.6g}\n",
               o->scene, ch->mesh.ntets, ch->mesh.nverts, sw_fullsim_driven_count(sim), surf->ntris,
               frames,
               o->params.integrator == SW_QUASISTATIC ? "quasistatic"
               : o->params.integrator == SW_NEWMARK   ? "newmark"
                                                      : "backward_euler",
               o->params.self_contact ? "true" : "false", o->params.threads,
               sw_linear_solver_name(t->solver), t->median, t->mean, t->ms_max,
               t->newton_sum / frames, t->newton_max, t->pcg_sum / frames,
               (double)t->factors / frames, t->max_pen, t->max_ground, t->unconverged, t->failed,
               t->unsettled, o->world ? "\"" : "", o->world ? o->world : "null",
               o->world ? "\"" : "", t->world_frames, t->pen_world);
}

int main(int argc, char **argv) {
    options o;
    if (parse_args(argc, argv, &o)) return 2;
    sw_error err;
    sw_error_clear(&err);
    sw_character ch;
    memset(&ch, 0, sizeof ch);
    sinew_result r;
    r = sw_scene_make(o.scene, o.tets,
                      o.frames > 0 ? o.frames : (sw_character_is_sample(o.scene) ? 30 : 60),
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
    tally t = {.solver = SW_SOLVER_AUTO};
    step_frames(&o, sim, &ws, poses, ch.skel.nbones, frames, scratch, tris, ms, &t);
    report(&o, &ch, sim, frames, ms, &t);
    free(ms);
    free(world_poses);
    sw_world_scene_free(&ws);
    free(scratch);
    free(tris);
    sw_fullsim_destroy(sim);
    sw_character_free(&ch);
    return t.failed ? 1 : 0;
}
