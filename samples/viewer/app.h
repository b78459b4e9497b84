/* The viewer's state between its main loop (main.c) and the rest: options, the blob,
 * the imported character, the instances, the view and the timings. */
#ifndef SW_VIEWER_APP_H
#define SW_VIEWER_APP_H

#include <stdint.h>
#include <stdio.h>

#include "gl.h"
#include "sim.h"
#include "world.h"

enum { VW_VIEW_SINEW = 1, VW_VIEW_SKIN = 2, VW_VIEW_BOTH = 3 };

typedef struct vw_options {
    const char *blob, *asset, *scene, *clip, *world, *screenshot, *record, *script;
    const char *fade_to, *root_bone;
    const char *record_calls; /* --record-calls: the first instance's recording */
    int instances, threads, frames, width, height, json, view, dqs, dynamic, colour;
    double step_hz, render_hz, colour_scale, fade_at, fade_time, walk, turn_deg;
} vw_options;

/* A scripted event: a key, or the mouse (x, y: fractions of the window, top left 0). */
enum { VW_EV_KEY, VW_EV_PRESS, VW_EV_MOVE, VW_EV_RELEASE };
typedef struct vw_event {
    double t;
    int kind;
    char key;
    float x, y;
} vw_event;

/* Lines to draw this frame, in world space (the first character's frame), colours packed
 * 0xRRGGBB as debug-draw callbacks hand them over: a debug-draw hook's lines and points
 * go here. */
typedef struct vw_lines {
    float *pos, *col; /* 3 a vertex, 2 vertices a segment */
    int32_t n, cap;
} vw_lines;

/* sinew's debug draw (debugdraw.c): what it draws, and its figures this frame and over
 * the run (contact lines: the first character's, SINEW_DEBUG_COLOR_WORLD_CONTACT). */
typedef struct vw_debug {
    uint32_t flags; /* SINEW_DEBUG_DRAW_*; 0 off */
    uint32_t lines, points, contact_lines;
    uint32_t lines_max, contact_lines_max, contact_lines_before_press;
    int64_t mismatch_frames; /* contact lines other than the step's world contacts */
} vw_debug;

/* The camera as last drawn, and the collider being dragged. */
typedef struct vw_poke {
    int valid; /* a frame was drawn: the camera is known */
    float eye[3], at[3], fovy, aspect;
    float off[3];            /* the first character's (and its world's) drawn offset */
    int col;                 /* the dragged collider, or -1 */
    float plane[3], grab[3]; /* the drag plane's point (facing the camera); grab offset */
    double first_press_s;    /* simulation time of the first press, or -1 */
} vw_poke;

typedef struct vw_app {
    vw_options opt;
    sinew_blob *blob;
    vw_asset asset;
    vw_sim sim;
    void *window;
    vw_glmesh *mesh_sinew, *mesh_skin; /* per instance */
    vw_world world;                    /* --world: its colliders */
    vw_glmesh mesh_col[VW_WORLD_MAX_COLLIDERS];
    float *col_collider;
    float *col_sinew, *col_skin; /* scratch colours */
    uint32_t *tris;
    int32_t ntris;
    float size; /* the rest surface's bounding-box diagonal */
    float rest_lo[3], rest_hi[3];
    vw_motion motion;
    /* controls */
    int paused, single, slow, reinit, view, teleport_pending;
    double step_dt, acc, sim_t;
    vw_event *events;
    int nevents, next_event;
    vw_poke poke;
    vw_lines lines;
    vw_debug debug;
    uint32_t contacts_max;  /* the first character's world contacts: the most in a step */
    double first_contact_s; /* and the simulation time of the first, or -1 */
    /* figures */
    int steps_this_frame;
    int64_t steps, frames, step_frames;
    double step_ms_sum, render_ms_sum, last_render_ms, wall_s;
    uint8_t *hud, *pixels;
    int hud_w, hud_h;
    FILE *ffmpeg;
} vw_app;

/* -1: go on; otherwise the exit code (help printed, or bad arguments). */
int vw_app_parse(vw_app *app, int argc, char **argv);
int vw_app_load(vw_app *app, char *err, size_t errlen);
int vw_app_gl_setup(vw_app *app, char *err, size_t errlen);
int vw_app_reinit(vw_app *app);
void vw_app_key(vw_app *app, char key);
void vw_app_script(vw_app *app, double clock);
/* Mouse: a press picks the collider nearest the ray under (x, y) (fractions of the
 * window), a move drags it in the plane through it facing the camera (poke.c). */
void vw_poke_press(vw_app *app, float x, float y);
void vw_poke_move(vw_app *app, float x, float y);
void vw_poke_release(vw_app *app);
void vw_app_draw(vw_app *app, int fb_w, int fb_h, double frame_ms, double step_ms);
/* A segment or a point (a cross of three segments `size` across) drawn with this frame. */
void vw_draw_line(vw_app *app, const float a[3], const float b[3], uint32_t rgb);
void vw_draw_point(vw_app *app, const float p[3], float size, uint32_t rgb);
/* Where character i (skin 1: its plain skinning) is drawn on the grid: its offset. */
void vw_layout(const vw_app *app, int32_t i, int skin, float *off);
/* --debug-draw's list (contacts,patch,colliders,bones) as SINEW_DEBUG_DRAW_* bits; 0 and a
 * message for a bad one. */
int vw_debug_parse(const char *list, uint32_t *flags);
/* The g key: off, contacts and patch, everything. */
void vw_debug_cycle(vw_app *app);
/* The line buffer, reserved once at setup. */
int vw_debug_reserve(vw_app *app);
/* After a frame's steps: each shown instance's debug draw into the frame's lines. */
void vw_debug_collect(vw_app *app);
int vw_app_capture(vw_app *app, int w, int h, int last_frame);
/* The HUD's four lines of text (the figures drawn on screen). */
void vw_hud_text(const vw_app *app, double frame_ms, double step_ms, char lines[4][160]);
/* The run's figures as one JSON line; with the HUD's phases line and the first
 * character's stats read again from the library, so a test can hold one to the other. */
void vw_app_print_json(const vw_app *app);
void vw_app_free(vw_app *app);

#endif
