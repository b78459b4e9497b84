/* Poking the flesh: one world collider dragged by the mouse, or by a script's mouse
 * lines (the same path, so a poke is testable without a person). The drag moves the
 * collider in the plane through it that faces the camera, as editors do: depth stays,
 * the collider follows the pointer. */
#include <math.h>
#include <string.h>

#include "app.h"

static void sub(const float *a, const float *b, float *o) {
    o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2];
}

static float dot(const float *a, const float *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalise(float *v) {
    float l = sqrtf(dot(v, v));
    if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
}

/* The ray from the eye through (x, y) of the window; f: the view direction. */
static void ray(const vw_poke *p, float x, float y, float *dir, float *f) {
    float s[3], u[3];
    sub(p->at, p->eye, f);
    normalise(f);
    s[0] = -f[2], s[1] = 0, s[2] = f[0]; /* f x (0, 1, 0) */
    normalise(s);
    u[0] = s[1] * f[2] - s[2] * f[1], u[1] = s[2] * f[0] - s[0] * f[2],
    u[2] = s[0] * f[1] - s[1] * f[0];
    const float h = tanf(0.5f * p->fovy), sx = (2 * x - 1) * h * p->aspect, sy = (1 - 2 * y) * h;
    for (int k = 0; k < 3; ++k)
        dir[k] = f[k] + sx * s[k] + sy * u[k];
    normalise(dir);
}

void vw_poke_press(vw_app *app, float x, float y) {
    vw_poke *p = &app->poke;
    if (!p->valid || !app->world.world) return;
    if (p->first_press_s < 0) p->first_press_s = app->sim_t;
    float dir[3], f[3], best = INFINITY;
    ray(p, x, y, dir, f);
    p->col = -1;
    for (int i = 0; i < app->world.ncol; ++i) {
        if (app->world.col[i].def.shape == SINEW_SHAPE_PLANE) continue; /* (a plane has no place) */
        float c[3], e[3];
        vw_world_position(&app->world, i, c);
        for (int k = 0; k < 3; ++k)
            c[k] += p->off[k];
        sub(c, p->eye, e);
        const float along = dot(e, dir), d2 = dot(e, e) - along * along;
        if (along > 0 && d2 < best) best = d2, p->col = i, memcpy(p->plane, c, sizeof c);
    }
    if (p->col < 0) return;
    /* grab where the ray meets the plane, so the collider does not jump to the pointer */
    float e[3];
    sub(p->plane, p->eye, e);
    const float lambda = dot(e, f) / dot(dir, f);
    for (int k = 0; k < 3; ++k)
        p->grab[k] = p->plane[k] - (p->eye[k] + lambda * dir[k]);
}

void vw_poke_move(vw_app *app, float x, float y) {
    vw_poke *p = &app->poke;
    if (p->col < 0 || !p->valid) return;
    float dir[3], f[3], e[3], at[3];
    ray(p, x, y, dir, f);
    sub(p->plane, p->eye, e);
    const float den = dot(dir, f);
    if (!(den > 1e-6f)) return;
    const float lambda = dot(e, f) / den;
    for (int k = 0; k < 3; ++k)
        at[k] = p->eye[k] + lambda * dir[k] + p->grab[k] - p->off[k];
    vw_world_hold(&app->world, p->col, at);
}

void vw_poke_release(vw_app *app) {
    app->poke.col = -1; /* (the collider stays where it was dropped) */
}
