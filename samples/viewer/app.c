/* The viewer's options, loading, controls, scripted sessions and figures. */
#include "app.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *usage =
    "usage: sinew-view --blob B (--asset FILE | --scene NAME) [options]\n"
    "  plays a baked character in real time: sinew, plain skinning, or both side by side\n"
    "  --blob B            the baked blob (sinew-bake --out)\n"
    "  --asset FILE        the glTF/FBX file it was baked from (assimp imports it)\n"
    "  --scene NAME        a procedural sample it was baked from (finger, cylinder, capsule)\n"
    "  --clip NAME         the clip to play (default: the file's first)\n"
    "  --fade-to NAME      cross-fade into this clip (local transforms blended, slerp)\n"
    "  --fade-at S         when the fade starts, seconds of the clock (default 1)\n"
    "  --fade-time S       how long it takes (0.5)\n"
    "  --root-motion BONE  take BONE's ground motion and heading out of the clip into the actor\n"
    "  --walk U            the actor walks U asset units a second along its +z (0)\n"
    "  --turn DEG          and turns DEG degrees a second (0); the camera follows\n"
    "  --instances N       characters (default 1)\n"
    "  --threads T         stepped on T threads (default 1)\n"
    "  --world FILE        a world file (samples/worlds/): its colliders, moving on their keys\n"
    "  --view V            sinew, skin or both (default both)\n"
    "  --dqs               dual-quaternion plain skinning (default linear blend)\n"
    "  --dynamic           dynamic steps (default quasistatic)\n"
    "  --no-colour         no colouring by correction magnitude\n"
    "  --colour-scale F    correction drawn full red, as a fraction of the size (0.03)\n"
    "  --step-hz H         simulation steps a second (60)\n"
    "  --render-hz H       frames a second of the --frames clock (60)\n"
    "  --width W           window width (960)\n"
    "  --height H          window height (540)\n"
    "  --frames N          render N frames, then exit (the clock advances 1/render-hz a frame)\n"
    "  --screenshot OUT    write the last frame to OUT, a PNG file (with --frames)\n"
    "  --record OUT        pipe every frame to ffmpeg, writing OUT (.mp4)\n"
    "  --debug-draw LIST   draw sinew's debug draw over its view: a comma-separated list of\n"
    "                      contacts, patch, colliders and bones (key g cycles)\n"
    "  --record-calls FILE record every call the first instance receives into FILE, for\n"
    "                      sinew-replay --blob B --recording FILE\n"
    "  --script FILE       timed events, one a line: SECONDS KEY (space, period or a key's\n"
    "                      letter), SECONDS press|move X Y (X, Y fractions of the window: a\n"
    "                      press picks a world collider, a move drags it), SECONDS release\n"
    "  --json              print frames, steps, mean step and render ms, fps, the first\n"
    "                      character's world contacts (most in a step, first time), where\n"
    "                      its actor stands (x, z, heading in degrees) at exit and the debug\n"
    "                      draw's figures (its contact lines: most, before the first press,\n"
    "                      frames where they differ from the step's world contacts)\n"
    "keys: space pause, . single step, s slow motion, d dynamic/quasistatic, t teleport,\n"
    "      1 sinew, 2 skinning, 3 both, c colour by correction, l linear/dual-quaternion,\n"
    "      g debug draw (off, contacts and patch, everything), q quit;\n"
    "      left drag: a world collider\n";

static int arg_int(const char *flag, const char *v, int lo, int hi, int *out) {
    char *end;
    long x = v ? strtol(v, &end, 10) : 0;
    if (!v || *end || x < lo || x > hi) {
        fprintf(stderr, "sinew-view: %s takes an integer in [%d, %d]\n", flag, lo, hi);
        return 0;
    }
    *out = (int)x;
    return 1;
}

static int arg_double(const char *flag, const char *v, double lo, double hi, double *out) {
    char *end;
    double x = v ? strtod(v, &end) : 0;
    if (!v || *end || !(x >= lo && x <= hi)) {
        fprintf(stderr, "sinew-view: %s takes a number in [%g, %g]\n", flag, lo, hi);
        return 0;
    }
    *out = x;
    return 1;
}

int vw_app_parse(vw_app *app, int argc, char **argv) {
    memset(app, 0, sizeof *app);
    vw_options *o = &app->opt;
    o->instances = o->threads = 1, o->width = 960, o->height = 540, o->view = VW_VIEW_BOTH;
    o->step_hz = o->render_hz = 60, o->colour = 1, o->colour_scale = 0.03;
    o->fade_at = 1, o->fade_time = 0.5;
    app->poke.col = -1, app->poke.first_press_s = app->first_contact_s = -1;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1, used = 1;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--blob"))
            o->blob = v;
        else if (!strcmp(a, "--asset"))
            o->asset = v;
        else if (!strcmp(a, "--scene"))
            o->scene = v;
        else if (!strcmp(a, "--clip"))
            o->clip = v;
        else if (!strcmp(a, "--fade-to"))
            o->fade_to = v;
        else if (!strcmp(a, "--root-motion"))
            o->root_bone = v;
        else if (!strcmp(a, "--fade-at"))
            ok = arg_double(a, v, 0, 1e6, &o->fade_at);
        else if (!strcmp(a, "--fade-time"))
            ok = arg_double(a, v, 0, 1e6, &o->fade_time);
        else if (!strcmp(a, "--walk"))
            ok = arg_double(a, v, -1e6, 1e6, &o->walk);
        else if (!strcmp(a, "--turn"))
            ok = arg_double(a, v, -3600, 3600, &o->turn_deg);
        else if (!strcmp(a, "--world"))
            o->world = v;
        else if (!strcmp(a, "--screenshot"))
            o->screenshot = v;
        else if (!strcmp(a, "--record"))
            o->record = v;
        else if (!strcmp(a, "--script"))
            o->script = v;
        else if (!strcmp(a, "--record-calls"))
            o->record_calls = v;
        else if (!strcmp(a, "--debug-draw"))
            ok = vw_debug_parse(v, &app->debug.flags);
        else if (!strcmp(a, "--instances"))
            ok = arg_int(a, v, 1, 4096, &o->instances);
        else if (!strcmp(a, "--threads"))
            ok = arg_int(a, v, 1, 64, &o->threads);
        else if (!strcmp(a, "--frames"))
            ok = arg_int(a, v, 1, 100000000, &o->frames);
        else if (!strcmp(a, "--width"))
            ok = arg_int(a, v, 64, 8192, &o->width);
        else if (!strcmp(a, "--height"))
            ok = arg_int(a, v, 64, 8192, &o->height);
        else if (!strcmp(a, "--step-hz"))
            ok = arg_double(a, v, 1, 10000, &o->step_hz);
        else if (!strcmp(a, "--render-hz"))
            ok = arg_double(a, v, 1, 10000, &o->render_hz);
        else if (!strcmp(a, "--colour-scale"))
            ok = arg_double(a, v, 1e-6, 1e3, &o->colour_scale);
        else if (!strcmp(a, "--view")) {
            o->view = v && !strcmp(v, "sinew")  ? VW_VIEW_SINEW
                      : v && !strcmp(v, "skin") ? VW_VIEW_SKIN
                      : v && !strcmp(v, "both") ? VW_VIEW_BOTH
                                                : 0;
            if (!o->view) fprintf(stderr, "sinew-view: --view takes sinew, skin or both\n");
            ok = o->view != 0;
        } else {
            used = 0;
            if (!strcmp(a, "--json"))
                o->json = 1;
            else if (!strcmp(a, "--dqs"))
                o->dqs = 1;
            else if (!strcmp(a, "--dynamic"))
                o->dynamic = 1;
            else if (!strcmp(a, "--no-colour"))
                o->colour = 0;
            else {
                fprintf(stderr, "sinew-view: unknown or incomplete argument '%s'\n%s", a, usage);
                return 2;
            }
        }
        if (used && !v) {
            fprintf(stderr, "sinew-view: %s needs a value\n", a);
            return 2;
        }
        if (!ok) return 2;
        i += used;
    }
    const char *bad = !o->blob                      ? "--blob is required"
                      : !o->asset == !o->scene      ? "give one of --asset FILE and --scene NAME"
                      : o->screenshot && !o->frames ? "--screenshot needs --frames N"
                      : o->record && !o->frames     ? "--record needs --frames N"
                                                    : NULL;
    if (bad) {
        fprintf(stderr, "sinew-view: %s\n", bad);
        return 2;
    }
    app->view = o->view;
    app->step_dt = 1.0 / o->step_hz;
    return -1;
}

static void log_stderr(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    (void)user;
    fprintf(stderr, "sinew-view: sinew %s %u: %s\n", level == SINEW_LOG_ERROR ? "error" : "warning",
            id, msg);
}

/* The blob's surface at rest: an instance starts at rest in the rest pose. */
static int blob_rest_surface(const sinew_blob *blob, float *pos, uint32_t nv) {
    sinew_instance *inst;
    sinew_instance_def d = sinew_instance_def_default();
    if (sinew_instance_create(blob, &d, &inst) != SINEW_OK) return 0;
    uint32_t nb = sinew_blob_bone_count(blob);
    float *I = calloc(12 * (size_t)nb, sizeof(float));
    int ok = I != NULL;
    for (uint32_t b = 0; ok && b < nb; ++b)
        I[12 * b] = I[12 * b + 4] = I[12 * b + 8] = 1;
    ok = ok && sinew_instance_set_pose(inst, I, nb) == SINEW_OK &&
         sinew_instance_step(inst, 1.0f / 60) == SINEW_OK &&
         sinew_instance_read_surface(inst, pos, NULL, nv) == SINEW_OK;
    free(I);
    sinew_instance_destroy(inst);
    return ok;
}

/* A script line after its time: a key's name, or a mouse event. */
static int parse_event(const char *line, const char *word, vw_event *ev) {
    float x, y;
    if (!strcmp(word, "press") || !strcmp(word, "move")) {
        if (sscanf(line, "%*f %*s %f %f", &x, &y) != 2 || !(x >= 0 && x <= 1 && y >= 0 && y <= 1))
            return 0;
        ev->kind = word[0] == 'p' ? VW_EV_PRESS : VW_EV_MOVE, ev->x = x, ev->y = y;
        return 1;
    }
    if (!strcmp(word, "release")) return ev->kind = VW_EV_RELEASE, 1;
    ev->key = !strcmp(word, "space") ? ' ' : !strcmp(word, "period") ? '.' : 0;
    if (!ev->key && strlen(word) == 1 && strchr(" .sdt123clgq", word[0])) ev->key = word[0];
    return ev->key != 0;
}

static int load_script(vw_app *app, char *err, size_t errlen) {
    FILE *f = fopen(app->opt.script, "r");
    if (!f) return snprintf(err, errlen, "%s: cannot open", app->opt.script), 0;
    char line[256], key[64];
    int n = 0, cap = 0, ok = 1;
    while (ok && fgets(line, sizeof line, f)) {
        n++;
        double t;
        char *s = line + strspn(line, " \t");
        if (*s == '#' || *s == '\n' || !*s) continue;
        if (sscanf(s, "%lf %63s", &t, key) != 2 || !(t >= 0)) {
            ok = 0, snprintf(err, errlen, "%s:%d: expected SECONDS KEY", app->opt.script, n);
            break;
        }
        vw_event ev = {t, VW_EV_KEY, 0, 0, 0};
        if (!parse_event(s, key, &ev)) {
            ok = 0, snprintf(err, errlen,
                             "%s:%d: expected SECONDS KEY, SECONDS press|move X Y (fractions of "
                             "the window) or SECONDS release; got '%s'",
                             app->opt.script, n, key);
            break;
        }
        if (app->nevents == cap) {
            cap = cap ? 2 * cap : 16;
            vw_event *e = realloc(app->events, sizeof *e * (size_t)cap);
            if (!e) {
                ok = 0, snprintf(err, errlen, "out of memory");
                break;
            }
            app->events = e;
        }
        app->events[app->nevents++] = ev;
    }
    fclose(f);
    return ok;
}

static int find_clip(const vw_asset *a, const char *name, int *clip, char *err, size_t errlen) {
    for (int k = 0; k < a->nclips; ++k)
        if (!strcmp(a->clip_names[k], name)) return *clip = k, 1;
    int n = snprintf(err, errlen, "no clip '%s'; the file has:", name);
    for (int k = 0; k < a->nclips && n > 0 && (size_t)n < errlen; ++k)
        n += snprintf(err + n, errlen - (size_t)n, " %s", a->clip_names[k]);
    return 0;
}

/* What the characters play: the clip, the fade, root motion and the actor's walk. */
static int pick_motion(vw_app *app, char *err, size_t errlen) {
    const vw_asset *a = &app->asset;
    const vw_options *o = &app->opt;
    vw_motion *m = &app->motion;
    *m = (vw_motion){.fade_clip = -1,
                     .root_bone = -1,
                     .fade_at = o->fade_at,
                     .fade_time = o->fade_time,
                     .walk = o->walk,
                     .turn = o->turn_deg * 3.14159265358979323846 / 180};
    if (a->nclips == 0) return snprintf(err, errlen, "%s has no clip to play", o->asset), 0;
    if (o->clip && !find_clip(a, o->clip, &m->clip, err, errlen)) return 0;
    if (o->fade_to && !a->sample)
        return snprintf(err, errlen, "--fade-to: a procedural scene has one clip"), 0;
    if (o->fade_to && !find_clip(a, o->fade_to, &m->fade_clip, err, errlen)) return 0;
    if (o->root_bone) {
        double bind[12];
        m->root_bone = sinew_blob_find_bone(app->blob, o->root_bone);
        if (m->root_bone < 0)
            return snprintf(err, errlen, "--root-motion: the blob has no bone '%s'", o->root_bone),
                   0;
        if (sinew_blob_bone_bind(app->blob, (uint32_t)m->root_bone, bind) != SINEW_OK)
            return snprintf(err, errlen, "--root-motion: the blob has no bind pose"), 0;
        for (int k = 0; k < 3; ++k)
            m->root_bind[k] = bind[9 + k];
    }
    return 1;
}

/* The blob's rest surface against the asset's: equal counts are not the same character. */
static int check_rest(vw_app *app, uint32_t nv, char *err, size_t errlen) {
    float *rest = malloc(sizeof(float) * 3 * (size_t)nv), lo = INFINITY, hi = -INFINITY;
    if (!rest || !blob_rest_surface(app->blob, rest, nv)) {
        free(rest);
        return snprintf(err, errlen, "%s: cannot step it in the rest pose", app->opt.blob), 0;
    }
    double worst = 0;
    uint32_t at = 0;
    for (uint32_t v = 0; v < nv; ++v) {
        double d2 = 0;
        for (int c = 0; c < 3; ++c) {
            double d = rest[3 * v + c] - app->asset.rest[3 * v + c];
            d2 += d * d;
            lo = fminf(lo, app->asset.rest[3 * v + c]), hi = fmaxf(hi, app->asset.rest[3 * v + c]);
        }
        if (d2 > worst) worst = d2, at = v;
    }
    free(rest);
    double size = hi > lo ? hi - lo : 1;
    /* (the bake may move a vertex outside the tets a little: a tolerance, not equality) */
    if (sqrt(worst) > 1e-3 * size)
        return snprintf(err, errlen,
                        "%s: render vertex %u rests %g from the blob's (the character is %g "
                        "across): not the file it was baked from",
                        app->opt.asset, at, sqrt(worst), size),
               0;
    return 1;
}

int vw_app_load(vw_app *app, char *err, size_t errlen) {
    const vw_options *o = &app->opt;
    sinew_blob_def bd = sinew_blob_def_default();
    bd.path = o->blob;
    bd.logger.log = log_stderr; /* the default logger is silent: say why a blob is refused */
    sinew_result r = sinew_blob_load(&bd, &app->blob);
    if (r != SINEW_OK)
        return snprintf(err, errlen, "%s: cannot load the blob: %s", o->blob,
                        sinew_result_string(r)),
               0;
    uint32_t nb = sinew_blob_bone_count(app->blob), nv = sinew_blob_surface_vertex_count(app->blob);
    uint32_t nt = sinew_blob_surface_triangle_count(app->blob);
    app->tris = malloc(sizeof(uint32_t) * 3 * (size_t)(nt ? nt : 1));
    if (!app->tris || sinew_blob_surface_triangles(app->blob, app->tris, 3 * nt) != SINEW_OK)
        return snprintf(err, errlen, "%s: cannot read its surface's triangles", o->blob), 0;
    app->ntris = (int32_t)nt;
    if (o->scene) {
        float *rest = malloc(sizeof(float) * 3 * (size_t)nv);
        int ok = rest && blob_rest_surface(app->blob, rest, nv);
        if (!ok) snprintf(err, errlen, "%s: cannot step it in the rest pose", o->blob);
        ok = ok && vw_scene_asset(o->scene, rest, (int32_t)nv, app->tris, (int32_t)nt, nb,
                                  &app->asset, err, errlen);
        free(rest);
        if (!ok) return 0;
    } else {
        /* bones by name and vertices by the output map (asset.c): a file that is not
         * the blob's is refused naming what it lacks */
        if (!vw_asset_import(o->asset, app->blob, &app->asset, err, errlen)) return 0;
        if (!check_rest(app, nv, err, errlen)) return 0;
    }
    if (!pick_motion(app, err, errlen)) return 0;
    if (o->script && !load_script(app, err, errlen)) return 0;
    const vw_asset *a = &app->asset;
    for (int c = 0; c < 3; ++c)
        app->rest_lo[c] = INFINITY, app->rest_hi[c] = -INFINITY;
    for (int32_t v = 0; v < a->nverts; ++v)
        for (int c = 0; c < 3; ++c)
            app->rest_lo[c] = fminf(app->rest_lo[c], a->rest[3 * v + c]),
            app->rest_hi[c] = fmaxf(app->rest_hi[c], a->rest[3 * v + c]);
    float d2 = 0;
    for (int c = 0; c < 3; ++c)
        d2 += (app->rest_hi[c] - app->rest_lo[c]) * (app->rest_hi[c] - app->rest_lo[c]);
    app->size = sqrtf(d2) > 0 ? sqrtf(d2) : 1;
    if (o->world && !vw_world_load(o->world, &app->world, err, errlen)) return 0;
    if (!vw_sim_create(&app->sim, app->blob, a, &app->motion, o->instances, o->threads, o->dynamic,
                       app->world.world, app->world.rest_pose, err, errlen))
        return 0;
    if (o->record_calls && !vw_sim_record(&app->sim, o->record_calls, err, errlen)) return 0;
    if (app->world.world) vw_world_move(&app->world, 0);
    vw_sim_step(&app->sim, 0, (float)app->step_dt); /* a surface to draw before the first step */
    return 1;
}

int vw_app_reinit(vw_app *app) {
    char err[256];
    app->reinit = 0;
    if (!vw_sim_set_mode(&app->sim, !app->sim.dynamic, err, sizeof err)) {
        fprintf(stderr, "sinew-view: %s\n", err);
        return 0;
    }
    vw_sim_step(&app->sim, app->sim_t, (float)app->step_dt);
    return 1;
}

void vw_app_key(vw_app *app, char key) {
    switch (key) {
    case ' ':
        app->paused = !app->paused;
        break;
    case '.':
        app->paused = 1, app->single = 1;
        break;
    case 's':
        app->slow = !app->slow;
        break;
    case 'd':
        app->reinit = 1;
        break;
    case 't': /* a cut: half the clip ahead, declared so no inertia is taken from the jump */
        app->sim_t += 0.5 * app->asset.clip_duration[app->motion.clip];
        vw_sim_teleport(&app->sim);
        break;
    case '1':
        app->view = VW_VIEW_SINEW;
        break;
    case '2':
        app->view = VW_VIEW_SKIN;
        break;
    case '3':
        app->view = VW_VIEW_BOTH;
        break;
    case 'c':
        app->opt.colour = !app->opt.colour;
        break;
    case 'l':
        app->opt.dqs = !app->opt.dqs;
        break;
    case 'g':
        vw_debug_cycle(app);
        break;
    case 'q':
        app->opt.frames = (int)app->frames + 1;
        break;
    default:
        break;
    }
}

void vw_app_script(vw_app *app, double clock) {
    while (app->next_event < app->nevents && app->events[app->next_event].t <= clock + 1e-9) {
        const vw_event *e = &app->events[app->next_event++];
        if (e->kind == VW_EV_KEY) vw_app_key(app, e->key);
        if (e->kind == VW_EV_PRESS) vw_poke_press(app, e->x, e->y);
        if (e->kind == VW_EV_MOVE) vw_poke_move(app, e->x, e->y);
        if (e->kind == VW_EV_RELEASE) vw_poke_release(app);
    }
}

void vw_app_print_json(const vw_app *app) {
    const vw_planar *a = &app->sim.ch[0].actor; /* the first actor: x, z, heading in degrees */
    const vw_debug *d = &app->debug;
    double fps = app->wall_s > 0 ? (double)app->frames / app->wall_s : 0;
    printf("{\"frames\": %lld, \"steps\": %lld, \"instances\": %d, \"threads\": %d, "
           "\"mean_step_ms\": %.3f, \"mean_render_ms\": %.3f, \"mean_frame_ms\": %.3f, "
           "\"fps\": %.1f, \"world_contacts_max\": %u, \"first_contact_s\": %.3f, "
           "\"first_press_s\": %.3f, \"actor\": [%.4g, %.4g, %.4g], \"debug_lines_max\": %u, "
           "\"debug_contact_lines_max\": %u, \"debug_contact_lines_before_press\": %u, "
           "\"debug_contact_mismatch_frames\": %lld, ",
           (long long)app->frames, (long long)app->steps, app->sim.n, app->sim.threads,
           app->step_frames ? app->step_ms_sum / (double)app->step_frames : 0,
           app->frames ? app->render_ms_sum / (double)app->frames : 0,
           app->frames ? 1000 * app->wall_s / (double)app->frames : 0, fps, app->contacts_max,
           app->first_contact_s, app->poke.first_press_s, a->x, a->z,
           a->yaw * 180 / 3.14159265358979323846, d->lines_max, d->contact_lines_max,
           d->contact_lines_before_press, (long long)d->mismatch_frames);
    char hud[4][160];
    vw_hud_text(app, 0, 0, hud);
    sinew_step_stats st = {.struct_size = sizeof st};
    if (app->sim.n > 0) sinew_instance_get_stats(app->sim.ch[0].inst, &st);
    printf("\"hud_phases\": \"%s\", \"stats\": {\"newton_iterations\": %u, "
           "\"world_contacts\": %u, \"patch_vertices\": %u, \"ms_solve\": %.2f}}\n",
           hud[1], st.newton_iterations, st.world_contacts, st.patch_vertices, st.ms_solve);
}

void vw_app_free(vw_app *app) {
    for (int32_t i = 0; app->mesh_sinew && i < app->sim.n; ++i)
        vw_glmesh_destroy(&app->mesh_sinew[i]), vw_glmesh_destroy(&app->mesh_skin[i]);
    free(app->mesh_sinew), free(app->mesh_skin), free(app->col_sinew), free(app->col_skin);
    for (int i = 0; i < app->world.ncol; ++i)
        vw_glmesh_destroy(&app->mesh_col[i]);
    free(app->col_collider);
    vw_sim_destroy(&app->sim);
    vw_world_free(&app->world);
    vw_asset_free(&app->asset);
    sinew_blob_destroy(app->blob);
    free(app->tris), free(app->events), free(app->hud), free(app->pixels);
    free(app->lines.pos), free(app->lines.col);
    if (app->ffmpeg && pclose(app->ffmpeg) != 0)
        fprintf(stderr, "sinew-view: ffmpeg failed writing %s\n", app->opt.record);
    memset(app, 0, sizeof *app);
}
