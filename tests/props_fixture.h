/* Props that press the finger of the test fixtures (along +x from 0 to 3.6, radius 0.45
 * at the root): a tent of four triangles, apex down (a mesh collider: Embree's path), and
 * a wedge (a convex hull: libccd's). The same shapes as samples/worlds/finger_props.json. */
#ifndef SW_PROPS_FIXTURE_H
#define SW_PROPS_FIXTURE_H

#include "sinew/sinew_world.h"

static const float props_tent_v[] = {-0.6f, 0,     -0.6f, 0.6f, 0, -0.6f,  0.6f, 0,
                                     0.6f,  -0.6f, 0,     0.6f, 0, -0.25f, 0};
static const uint32_t props_tent_i[] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
static const float props_wedge_p[] = {-0.3f, 0, -0.3f, 0.3f, 0,     -0.3f, 0.3f, 0,     0.3f,
                                      -0.3f, 0, 0.3f,  0,    0.35f, 0,     0,    -0.2f, 0};

/* The tent's (or, hull set, the wedge's) collider def at t. */
static inline sinew_collider_def props_def(int hull, sinew_transform t) {
    sinew_collider_def c = sinew_collider_def_default();
    if (hull) {
        c.shape = SINEW_SHAPE_HULL;
        c.points = props_wedge_p, c.point_count = 6;
    } else {
        c.shape = SINEW_SHAPE_MESH;
        c.vertices = props_tent_v, c.vertex_count = 5;
        c.indices = props_tent_i, c.triangle_count = 4;
    }
    c.transform = t;
    return c;
}

/* A transform at (x, y, 0), unturned. */
static inline sinew_transform props_at(float x, float y) {
    sinew_transform t = sinew_transform_identity();
    t.position[0] = x, t.position[1] = y;
    return t;
}

/* Adds the tent over the finger at x = tent_x and the wedge under it at x = wedge_x to w;
 * 1 on success. */
static inline int props_add(sinew_world *w, float tent_x, float wedge_x, sinew_collider_id *tent,
                            sinew_collider_id *wedge) {
    sinew_collider_def m = props_def(0, props_at(tent_x, 0.6f)),
                       h = props_def(1, props_at(wedge_x, -0.55f));
    return sinew_world_add_collider(w, &m, tent) == SINEW_OK &&
           sinew_world_add_collider(w, &h, wedge) == SINEW_OK;
}

#endif
