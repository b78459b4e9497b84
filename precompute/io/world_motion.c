/* Keyframed rigid motion of world-file colliders (world_io.h): linear positions,
 * shortest-arc slerp of rotations, held outside the keyed range. */
#include <math.h>

#include "world_io.h"

static void set_transform(const double *p, const double *q, sinew_transform *out) {
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 3; ++k)
        out->position[k] = (float)p[k];
    for (int k = 0; k < 4; ++k)
        out->rotation[k] = (float)(n > 0 ? q[k] / n : (k == 0 ? 1.0 : 0.0));
}

/* Slerp from a to b (unit quaternions) by t in [0, 1] along the shorter arc. */
static void slerp(const double *a, const double *b, double t, double *q) {
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], s = 1.0;
    if (d < 0) { /* q and -q are the same rotation: take the nearer one */
        d = -d;
        s = -1.0;
    }
    double wa, wb;
    if (d > 0.9995) { /* nearly parallel: normalised lerp is exact enough and stable */
        wa = 1.0 - t;
        wb = t;
    } else {
        double th = acos(d), st = sin(th);
        wa = sin((1.0 - t) * th) / st;
        wb = sin(t * th) / st;
    }
    for (int k = 0; k < 4; ++k)
        q[k] = wa * a[k] + s * wb * b[k];
}

void sw_world_collider_at(const sw_world_collider_spec *c, double frame, sinew_transform *out) {
    static const double origin[3] = {0, 0, 0}, identity[4] = {1, 0, 0, 0};
    if (!out) return;
    if (!c || c->nkeys <= 0 || !c->keys) {
        set_transform(origin, identity, out);
        return;
    }
    const sw_world_key *k = c->keys;
    const int32_t n = c->nkeys;
    if (!(frame > k[0].frame)) { /* before the first key, or NaN */
        set_transform(k[0].position, k[0].rotation, out);
        return;
    }
    if (frame >= k[n - 1].frame) {
        set_transform(k[n - 1].position, k[n - 1].rotation, out);
        return;
    }
    int32_t lo = 0, hi = n - 1; /* k[lo].frame < frame < k[hi].frame after the search */
    while (hi - lo > 1) {
        int32_t mid = lo + (hi - lo) / 2;
        if (k[mid].frame <= frame)
            lo = mid;
        else
            hi = mid;
    }
    double t = (frame - k[lo].frame) / (double)(k[hi].frame - k[lo].frame), p[3], q[4];
    for (int i = 0; i < 3; ++i)
        p[i] = k[lo].position[i] + t * (k[hi].position[i] - k[lo].position[i]);
    slerp(k[lo].rotation, k[hi].rotation, t, q);
    set_transform(p, q, out);
}

int32_t sw_world_file_last_key_frame(const sw_world_file *w) {
    int32_t last = 0;
    if (!w) return 0;
    for (int32_t i = 0; i < w->ncolliders; ++i) {
        const sw_world_collider_spec *c = &w->colliders[i];
        if (c->nkeys > 0 && c->keys[c->nkeys - 1].frame > last) last = c->keys[c->nkeys - 1].frame;
    }
    return last;
}
