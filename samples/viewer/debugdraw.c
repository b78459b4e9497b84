/* sinew's debug draw in the viewer: after each frame's steps, every instance shown hands
 * its contacts, patch, colliders and bones to callbacks that put them in the frame's line
 * buffer (draw.c), moved from the actor's frame into the world's and onto the instance's
 * place on the grid. The buffer is reserved at setup; a frame that needs more than any
 * before grows it once. */
#include <stdlib.h>
#include <string.h>

#include "app.h"

typedef struct dd_host {
    vw_app *app;
    int32_t inst;
    float off[3];      /* the instance's place relative to the first one's */
    uint32_t contacts; /* world-contact lines handed over */
} dd_host;

static uint32_t rgb(uint32_t rgba) {
    return rgba >> 8;
}

/* The actor's frame to the lines' (the world's, the first character's place on the grid). */
static void place(const dd_host *h, const float p[3], float out[3]) {
    memcpy(out, p, 3 * sizeof(float));
    vw_sim_actor_point(&h->app->sim, h->inst, out);
    for (int k = 0; k < 3; ++k)
        out[k] += h->off[k];
}

static void dd_line(const float p0[3], const float p1[3], uint32_t rgba, void *context) {
    dd_host *h = context;
    float a[3], b[3];
    place(h, p0, a), place(h, p1, b);
    vw_draw_line(h->app, a, b, rgb(rgba));
    h->app->debug.lines++;
    if (rgba == SINEW_DEBUG_COLOR_WORLD_CONTACT) h->contacts++;
}

static void dd_point(const float p[3], float size, uint32_t rgba, void *context) {
    dd_host *h = context;
    float a[3];
    place(h, p, a);
    vw_draw_point(h->app, a, size, rgb(rgba));
    h->app->debug.points++;
}

static void dd_triangle(const float p0[3], const float p1[3], const float p2[3], uint32_t rgba,
                        void *context) {
    dd_line(p0, p1, rgba, context), dd_line(p1, p2, rgba, context), dd_line(p2, p0, rgba, context);
}

int vw_debug_parse(const char *list, uint32_t *flags) {
    static const struct {
        const char *name;
        uint32_t bit;
    } kinds[] = {{"contacts", SINEW_DEBUG_DRAW_CONTACTS},
                 {"patch", SINEW_DEBUG_DRAW_PATCH},
                 {"colliders", SINEW_DEBUG_DRAW_COLLIDERS},
                 {"bones", SINEW_DEBUG_DRAW_BONES}};
    *flags = 0;
    if (!list) return 0; /* (the caller says a value is needed) */
    for (const char *s = list; s && *s;) {
        size_t n = strcspn(s, ","), k = 0;
        while (k < 4 && !(strlen(kinds[k].name) == n && !strncmp(s, kinds[k].name, n)))
            k++;
        if (k == 4) {
            fprintf(stderr,
                    "sinew-view: --debug-draw takes a comma-separated list of contacts, patch, "
                    "colliders and bones; got '%.*s'\n",
                    (int)n, s);
            return 0;
        }
        *flags |= kinds[k].bit;
        s += n + (s[n] == ',');
    }
    if (!*flags) fprintf(stderr, "sinew-view: --debug-draw needs at least one kind\n");
    return *flags != 0;
}

void vw_debug_cycle(vw_app *app) {
    const uint32_t all = SINEW_DEBUG_DRAW_CONTACTS | SINEW_DEBUG_DRAW_PATCH |
                         SINEW_DEBUG_DRAW_COLLIDERS | SINEW_DEBUG_DRAW_BONES;
    const uint32_t some = SINEW_DEBUG_DRAW_CONTACTS | SINEW_DEBUG_DRAW_PATCH;
    uint32_t *f = &app->debug.flags;
    *f = *f == 0 ? some : *f == some ? all : 0;
}

int vw_debug_reserve(vw_app *app) {
    vw_lines *l = &app->lines;
    int32_t cap = 1 << 16; /* vertices: a patch of 2000 and a Fox's bones with room */
    l->pos = malloc(sizeof(float) * 3 * (size_t)cap);
    l->col = malloc(sizeof(float) * 3 * (size_t)cap);
    if (!l->pos || !l->col) return 0;
    l->cap = cap;
    return 1;
}

void vw_debug_collect(vw_app *app) {
    vw_debug *d = &app->debug;
    d->lines = d->points = 0;
    if (!d->flags || app->view == VW_VIEW_SKIN) {
        d->contact_lines = 0;
        return;
    }
    float off0[3];
    vw_layout(app, 0, 0, off0);
    for (int32_t i = 0; i < app->sim.n; ++i) {
        dd_host h = {app, i, {0, 0, 0}, 0};
        vw_layout(app, i, 0, h.off);
        for (int k = 0; k < 3; ++k)
            h.off[k] -= off0[k];
        sinew_debug_draw dd = {dd_line, dd_point, dd_triangle, d->flags, 0, &h};
        sinew_instance_debug_draw(app->sim.ch[i].inst, &dd);
        if (i == 0) d->contact_lines = h.contacts;
    }
    /* the figures of the first character: its contact lines against its world contacts */
    uint32_t wc = app->sim.ch[0].stats.world_contacts;
    if (d->contact_lines > d->contact_lines_max) d->contact_lines_max = d->contact_lines;
    if (app->poke.first_press_s < 0 && d->contact_lines > d->contact_lines_before_press)
        d->contact_lines_before_press = d->contact_lines;
    if ((d->flags & SINEW_DEBUG_DRAW_CONTACTS) && d->contact_lines != wc) d->mismatch_frames++;
    if (d->lines > d->lines_max) d->lines_max = d->lines;
}
