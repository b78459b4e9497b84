/* What the viewer draws each frame: the characters laid out on a grid (in "both", the
 * plain skinning left of sinew), a camera framing them, the colour of the correction and
 * the HUD; and the frames it captures. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "app.h"
#include "text5x7.h"

int vw_app_gl_setup(vw_app *app, char *err, size_t errlen) {
    int32_t n = app->sim.n, nv = app->asset.nverts;
    app->mesh_sinew = calloc((size_t)n, sizeof *app->mesh_sinew);
    app->mesh_skin = calloc((size_t)n, sizeof *app->mesh_skin);
    app->col_sinew = malloc(sizeof(float) * 3 * (size_t)nv);
    app->col_skin = malloc(sizeof(float) * 3 * (size_t)nv);
    if (!app->mesh_sinew || !app->mesh_skin || !app->col_sinew || !app->col_skin)
        return snprintf(err, errlen, "out of memory"), 0;
    for (int32_t i = 0; i < n; ++i)
        if (!vw_glmesh_create(&app->mesh_sinew[i], nv, app->tris, app->ntris) ||
            !vw_glmesh_create(&app->mesh_skin[i], nv, app->tris, app->ntris))
            return snprintf(err, errlen, "cannot create the GL buffers"), 0;
    int32_t most = 1;
    for (int i = 0; i < app->world.ncol; ++i) {
        vw_collider *c = &app->world.col[i];
        most = c->nverts > most ? c->nverts : most;
        if (!vw_glmesh_create(&app->mesh_col[i], c->nverts, c->tris, c->ntris))
            return snprintf(err, errlen, "cannot create the GL buffers"), 0;
    }
    app->col_collider = malloc(sizeof(float) * 3 * (size_t)most);
    if (!app->col_collider || !vw_debug_reserve(app))
        return snprintf(err, errlen, "out of memory"), 0;
    for (int32_t v = 0; v < most; ++v)
        app->col_collider[3 * v] = 0.45f, app->col_collider[3 * v + 1] = 0.6f,
                              app->col_collider[3 * v + 2] = 0.45f;
    for (int32_t v = 0; v < nv; ++v) {
        float *c = app->col_skin + 3 * v;
        c[0] = 0.55f, c[1] = 0.65f, c[2] = 0.8f;
    }
    return 1;
}

/* Correction magnitude |sinew - skinning| as a colour: warm grey at none, through orange,
 * to red at colour_scale of the character's size. */
static void correction_colours(const vw_app *app, const vw_char *c, float *col) {
    float full = (float)(app->opt.colour_scale * app->size);
    for (int32_t v = 0; v < app->asset.nverts; ++v) {
        float d2 = 0;
        for (int k = 0; k < 3; ++k)
            d2 += (c->pos[3 * v + k] - c->skin_pos[3 * v + k]) *
                  (c->pos[3 * v + k] - c->skin_pos[3 * v + k]);
        float u = app->opt.colour ? fminf(1.0f, sqrtf(d2) / full) : 0;
        col[3 * v] = 0.85f + 0.15f * u;
        col[3 * v + 1] = 0.82f - 0.62f * u;
        col[3 * v + 2] = 0.75f - 0.65f * u;
    }
}

/* Column-major perspective times look-at. */
static void view_projection(const float eye[3], const float at[3], float fovy, float aspect,
                            float znear, float zfar, float *m) {
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, up[3] = {0, 1, 0};
    float l = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; ++k)
        f[k] /= l;
    float s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                  f[0] * up[1] - f[1] * up[0]};
    l = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int k = 0; k < 3; ++k)
        s[k] /= l;
    float u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
    float V[16] = {s[0],
                   u[0],
                   -f[0],
                   0,
                   s[1],
                   u[1],
                   -f[1],
                   0,
                   s[2],
                   u[2],
                   -f[2],
                   0,
                   -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]),
                   -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]),
                   f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2],
                   1};
    float t = 1.0f / tanf(0.5f * fovy), P[16] = {0};
    P[0] = t / aspect, P[5] = t, P[10] = (zfar + znear) / (znear - zfar), P[11] = -1;
    P[14] = 2 * zfar * znear / (znear - zfar);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float x = 0;
            for (int k = 0; k < 4; ++k)
                x += P[4 * k + r] * V[4 * c + k];
            m[4 * c + r] = x;
        }
}

/* Where character i (and its skinned copy) stands: a grid whose rows run across the
 * screen. The camera looks at the character's side (across its longer horizontal
 * extent), so a fox is seen walking and a finger bending. */
static int side_on(const vw_app *app) {
    return app->rest_hi[2] - app->rest_lo[2] > app->rest_hi[0] - app->rest_lo[0];
}

void vw_layout(const vw_app *app, int32_t i, int skin, float *off) {
    int side = side_on(app), across = side ? 2 : 0;
    float e_across = app->rest_hi[across] - app->rest_lo[across];
    float cell = fmaxf(e_across, 0.3f * app->size) * 1.15f;
    int both = app->view == VW_VIEW_BOTH, cols = (int)ceil(sqrt((double)app->sim.n));
    float cw = both ? 2 * cell : cell, sign = side ? -1.0f : 1.0f; /* screen right */
    off[0] = off[1] = off[2] = 0;
    off[across] = sign * ((float)(i % cols) * cw + (both ? (skin ? -0.5f : 0.5f) * cell : 0));
    /* rows stack upwards: behind one another they would hide each other */
    off[1] = (float)(i / cols) * (app->rest_hi[1] - app->rest_lo[1]) * 1.25f;
}

static void camera(vw_app *app, int fb_w, int fb_h, float *vp) {
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < app->sim.n; ++i)
        for (int skin = 0; skin < 2; ++skin) {
            if ((skin && app->view == VW_VIEW_SINEW) || (!skin && app->view == VW_VIEW_SKIN))
                continue;
            const float *p = skin ? app->sim.ch[i].skin_pos : app->sim.ch[i].pos;
            float off[3];
            vw_layout(app, i, skin, off);
            for (int32_t v = 0; v < app->asset.nverts; ++v)
                for (int k = 0; k < 3; ++k)
                    lo[k] = fminf(lo[k], p[3 * v + k] + off[k]),
                    hi[k] = fmaxf(hi[k], p[3 * v + k] + off[k]);
        }
    float at[3], r = 0, dir[3] = {0.2f, 0.3f, 1.0f}, dl = sqrtf(0.04f + 0.09f + 1);
    if (side_on(app)) dir[0] = 1.0f, dir[2] = 0.2f;
    for (int k = 0; k < 3; ++k)
        at[k] = 0.5f * (lo[k] + hi[k]), r += 0.25f * (hi[k] - lo[k]) * (hi[k] - lo[k]);
    r = sqrtf(r);
    if (!(r > 0)) r = app->size;
    float fovy = 0.5f, aspect = (float)fb_w / (float)(fb_h ? fb_h : 1);
    float dist = r / sinf(0.5f * fovy * fminf(1.0f, aspect)) * 0.8f, eye[3];
    for (int k = 0; k < 3; ++k)
        eye[k] = at[k] + dir[k] / dl * dist;
    view_projection(eye, at, fovy, aspect, 0.01f * dist, 4 * dist, vp);
    vw_poke *p = &app->poke; /* what a mouse press is cast from */
    memcpy(p->eye, eye, sizeof eye), memcpy(p->at, at, sizeof at);
    p->fovy = fovy, p->aspect = aspect, p->valid = 1;
    vw_layout(app, 0, app->view == VW_VIEW_SKIN, p->off);
}

/* The HUD's lines: frame and step times, the first character's phases and flags. */
void vw_hud_text(const vw_app *app, double frame_ms, double step_ms, char lines[4][160]) {
    const sinew_step_stats *s = &app->sim.ch[0].stats;
    const char *view = app->view == VW_VIEW_SINEW  ? "SINEW"
                       : app->view == VW_VIEW_SKIN ? "SKIN"
                                                   : "SKIN | SINEW";
    const vw_motion *m = &app->sim.motion;
    char clip[64];
    if (m->fade_clip >= 0 && app->sim_t >= m->fade_at)
        snprintf(clip, sizeof clip, "%.24s > %.24s %.0f%%", app->asset.clip_names[m->clip],
                 app->asset.clip_names[m->fade_clip],
                 100 * (m->fade_time > 0 ? fmin(1, (app->sim_t - m->fade_at) / m->fade_time) : 1));
    else
        snprintf(clip, sizeof clip, "%.60s", app->asset.clip_names[m->clip]);
    snprintf(lines[0], 160, "FRAME %.1f MS  STEP %.2f MS (%d)  RENDER %.1f MS  %d X %.60s",
             frame_ms, step_ms, app->steps_this_frame, app->last_render_ms, app->sim.n, clip);
    snprintf(lines[1], 160,
             "SKIN %.2f CONTACT %.2f DYN %.2f SOLVE %.2f OUTPUT %.2f WORLD %.2f MS  NEWTON %u  "
             "WORLD CONTACTS %u PATCH %u",
             s->ms_skin, s->ms_contact, s->ms_dynamics, s->ms_solve, s->ms_output, s->ms_world,
             s->newton_iterations, s->world_contacts, s->patch_vertices);
    int n = snprintf(lines[2], 160, "%s%s%s%s", (s->status & SINEW_STEP_BUDGET) ? "BUDGET " : "",
                     (s->status & SINEW_STEP_TELEPORT) ? "TELEPORT " : "",
                     (s->status & SINEW_STEP_LIMITED) ? "LIMITED " : "",
                     (s->status & SINEW_STEP_FAILED) ? "FAILED " : "");
    if (s->status & SINEW_STEP_BEYOND_TRAINING)
        snprintf(lines[2] + n, 160 - (size_t)n, "BEYOND TRAINING: %u JOINTS, BONE %d +%.0f DEG",
                 s->joints_beyond_training, s->beyond_training_bone, s->beyond_training_deg);
    n = snprintf(lines[3], 160, "%s  %s  %s%s%s  1 SINEW 2 SKIN 3 BOTH", view,
                 app->sim.dynamic ? "DYNAMIC" : "QUASISTATIC", app->opt.dqs ? "DQS " : "LBS ",
                 app->paused ? "PAUSED " : "", app->slow ? "SLOW " : "");
    const vw_planar *a = &app->sim.ch[0].actor;
    if (m->root_bone >= 0 || m->walk != 0 || m->turn != 0)
        snprintf(lines[3] + n, 160 - (size_t)n, "  ACTOR %.1f %.1f %.0f DEG", a->x, a->z,
                 a->yaw * 180 / 3.14159265358979323846);
    const vw_debug *d = &app->debug;
    n = (int)strlen(lines[3]);
    if (d->flags)
        snprintf(lines[3] + n, 160 - (size_t)n, "  DRAW %u LINES %u POINTS (G)", d->lines,
                 d->points);
}

static void draw_hud(vw_app *app, int fb_w, int fb_h, double frame_ms, double step_ms) {
    char lines[4][160];
    vw_hud_text(app, frame_ms, step_ms, lines);
    int scale = fb_w >= 1200 ? 2 : 1, lh = 9 * scale, w = fb_w, h = 4 * lh + 2 * scale;
    if (app->hud_w != w || app->hud_h != h) {
        free(app->hud);
        app->hud = malloc(3 * (size_t)w * (size_t)h);
        app->hud_w = w, app->hud_h = h;
    }
    if (!app->hud) return;
    memset(app->hud, 0, 3 * (size_t)w * (size_t)h);
    static const uint8_t white[3] = {235, 235, 235}, amber[3] = {255, 190, 60};
    for (int k = 0; k < 4; ++k)
        sw_draw_text(app->hud, w, h, 2 * scale, scale + k * lh, scale, lines[k],
                     k == 2 ? amber : white);
    vw_gl_hud(app->hud, w, h, fb_w, fb_h);
    char title[200];
    snprintf(title, sizeof title, "sinew-view  %s", lines[0]);
    glfwSetWindowTitle(app->window, title);
}

void vw_draw_line(vw_app *app, const float a[3], const float b[3], uint32_t rgb) {
    vw_lines *l = &app->lines;
    if (l->n + 2 > l->cap) {
        int32_t cap = l->cap ? 2 * l->cap : 256;
        float *p = realloc(l->pos, sizeof(float) * 3 * (size_t)cap);
        if (p) l->pos = p;
        float *c = p ? realloc(l->col, sizeof(float) * 3 * (size_t)cap) : NULL;
        if (!c) return; /* (a frame without its lines, not a failure) */
        l->col = c, l->cap = cap;
    }
    const float c[3] = {(float)((rgb >> 16) & 255) / 255, (float)((rgb >> 8) & 255) / 255,
                        (float)(rgb & 255) / 255};
    memcpy(l->pos + 3 * l->n, a, 3 * sizeof(float)), memcpy(l->col + 3 * l->n, c, sizeof c);
    memcpy(l->pos + 3 * l->n + 3, b, 3 * sizeof(float)), memcpy(l->col + 3 * l->n + 3, c, sizeof c);
    l->n += 2;
}

void vw_draw_point(vw_app *app, const float p[3], float size, uint32_t rgb) {
    for (int k = 0; k < 3; ++k) {
        float a[3] = {p[0], p[1], p[2]}, b[3] = {p[0], p[1], p[2]};
        a[k] -= 0.5f * size, b[k] += 0.5f * size;
        vw_draw_line(app, a, b, rgb);
    }
}

/* A held collider: where its keys would have it, and a line to where it is held. */
static void held_colliders(vw_app *app) {
    for (int k = 0; k < app->world.ncol; ++k) {
        const vw_collider *c = &app->world.col[k];
        if (!c->held) continue;
        const float *from = c->nkeys ? c->keys[0].position : c->def.transform.position;
        vw_draw_point(app, from, 0.05f * app->size, 0xffc040);
        vw_draw_line(app, from, c->now.position, 0xffc040);
    }
}

void vw_app_draw(vw_app *app, int fb_w, int fb_h, double frame_ms, double step_ms) {
    int need_skin = app->view != VW_VIEW_SINEW || app->opt.colour;
    if (need_skin) vw_sim_skin(&app->sim, app->opt.dqs);
    float vp[16];
    camera(app, fb_w, fb_h, vp);
    vw_gl_begin(fb_w, fb_h);
    for (int32_t i = 0; i < app->sim.n; ++i) {
        vw_char *c = &app->sim.ch[i];
        float off[3];
        if (app->view != VW_VIEW_SKIN) {
            correction_colours(app, c, app->col_sinew);
            vw_glmesh_update(&app->mesh_sinew[i], c->pos, c->nrm, app->col_sinew);
            vw_layout(app, i, 0, off);
            vw_gl_draw(&app->mesh_sinew[i], vp, off);
        }
        if (app->view != VW_VIEW_SINEW) {
            vw_glmesh_update(&app->mesh_skin[i], c->skin_pos, c->skin_nrm, app->col_skin);
            vw_layout(app, i, 1, off);
            vw_gl_draw(&app->mesh_skin[i], vp, off);
        }
    }
    for (int k = 0; k < app->world.ncol; ++k) {
        vw_collider *col = &app->world.col[k];
        vw_normals(col->pos, col->nverts, col->tris, col->ntris, NULL, col->nrm);
        vw_glmesh_update(&app->mesh_col[k], col->pos, col->nrm, app->col_collider);
        /* every character has the world's copy; the plain skinning's too, which it passes
         * through */
        for (int32_t i = 0; i < app->sim.n; ++i)
            for (int skin = 0; skin < 2; ++skin) {
                if ((skin && app->view == VW_VIEW_SINEW) || (!skin && app->view == VW_VIEW_SKIN))
                    continue;
                float off[3];
                vw_layout(app, i, skin, off);
                vw_gl_draw(&app->mesh_col[k], vp, off);
            }
    }
    held_colliders(app);
    if (app->lines.n) {
        float off[3];
        vw_layout(app, 0, app->view == VW_VIEW_SKIN, off);
        vw_gl_lines(app->lines.pos, app->lines.col, app->lines.n, vp, off);
        app->lines.n = 0;
    }
    draw_hud(app, fb_w, fb_h, frame_ms, step_ms);
}

int vw_app_capture(vw_app *app, int w, int h, int last_frame) {
    if (!app->pixels) app->pixels = malloc(3 * (size_t)w * (size_t)h);
    if (!app->pixels) return 0;
    vw_gl_read(w, h, app->pixels);
    if (app->opt.record && !app->ffmpeg) {
        char cmd[1200];
        if (strchr(app->opt.record, '\'')) {
            fprintf(stderr, "sinew-view: --record: a path with a quote is not supported\n");
            return 0;
        }
        snprintf(cmd, sizeof cmd,
                 "ffmpeg -loglevel error -y -f rawvideo -pix_fmt rgb24 -s %dx%d -r %g -i - "
                 "-pix_fmt yuv420p -vf 'scale=trunc(iw/2)*2:trunc(ih/2)*2' '%s'",
                 w, h, app->opt.render_hz, app->opt.record);
        app->ffmpeg = popen(cmd, "w");
        if (!app->ffmpeg) {
            fprintf(stderr, "sinew-view: cannot start ffmpeg for %s\n", app->opt.record);
            return 0;
        }
    }
    if (app->ffmpeg && fwrite(app->pixels, 3, (size_t)w * h, app->ffmpeg) != (size_t)w * h) {
        fprintf(stderr, "sinew-view: ffmpeg stopped taking frames (is it installed?)\n");
        return 0;
    }
    if (last_frame && app->opt.screenshot &&
        !vw_write_png(app->opt.screenshot, w, h, app->pixels)) {
        fprintf(stderr, "sinew-view: cannot write %s\n", app->opt.screenshot);
        return 0;
    }
    return 1;
}
