/* The finger fixture of the world tests (test_world_contact.c, test_world_threads.c): a
 * small baked finger, a table under it, and a sphere that moves along it. */
#ifndef SW_WORLD_FIXTURE_H
#define SW_WORLD_FIXTURE_H

#include "bake_fixture.h"
#include "sinew/sinew_world.h"

static bake_fixture fx;
static int fx_ok = -1;

static inline const bake_fixture *fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "finger", 2000, 12, 0);
    return fx_ok ? &fx : NULL;
}

/* The finger (along +x from 0 to 3.6, radius 0.45 at the root) pressed `depth` into a
 * table under it: a box whose top face is at y = -0.44 + depth. */
static inline sinew_world *table_world(double depth, float friction, sinew_collider_id *id) {
    sinew_world *w;
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, &w) != SINEW_OK) return NULL;
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_BOX;
    c.half_extents[0] = 2.5f;
    c.half_extents[1] = 0.2f;
    c.half_extents[2] = 1.0f;
    c.friction = friction;
    c.transform.position[0] = 1.8f;
    c.transform.position[1] = (float)(-0.44 + depth - 0.2);
    if (sinew_world_add_collider(w, &c, id) != SINEW_OK) {
        sinew_world_destroy(w);
        return NULL;
    }
    return w;
}

/* A sphere that moves along the finger every step (no rebuild) while the finger folds. */
typedef struct {
    const bake_fixture *f;
    sinew_world *w;
    sinew_collider_id ball;
} moving_scene;

static inline void ball_at(int s, sinew_transform *t) {
    *t = sinew_transform_identity();
    t->position[0] = (float)(0.5 + 0.1 * (s % 25));
    t->position[1] = -0.5f;
}

static inline int moving_scene_make(moving_scene *m) {
    m->f = fixture();
    if (!m->f) return 0;
    sinew_collider_id table;
    m->w = table_world(0.05, 0.3f, &table);
    if (!m->w) return 0;
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_SPHERE;
    c.radius = 0.2f;
    ball_at(0, &c.transform);
    return sinew_world_add_collider(m->w, &c, &m->ball) == SINEW_OK;
}

#endif
