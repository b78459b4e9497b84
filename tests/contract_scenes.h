/* The poses and worlds test_step_contract's paths step through: the clip's fold taken
 * further, the clip carried by a rigid motion, the boxes, the moving ball, and the
 * moving mesh and hull of props_fixture.h. */
#ifndef SW_CONTRACT_SCENES_H
#define SW_CONTRACT_SCENES_H

#include <math.h>
#include <string.h>

#include "contract_fixture.h"
#include "props_fixture.h"
#include "sinew/sinew_world.h"

/* Frame k of the clip (looped). */
static const float *clip_pose(const contract_fixture *f, int k) {
    return f->poses + (size_t)12 * f->nb * (size_t)(k % f->frames);
}

/* The clip's most folded pose with every joint's bend (the bone's rotation in its parent's
 * frame; the finger's bones are a chain, bone b's parent b - 1) raised to the power m:
 * the fold taken m times as far as the clip takes it, past the bake's training. */
static double bend(const float *P, const float *B) { /* the angle of R_p^T R_b */
    double tr = 0;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            tr += (double)P[3 * k + i] * B[3 * k + i];
    return acos(fmax(-1.0, fmin(1.0, 0.5 * (tr - 1))));
}

static void folded_pose(const contract_fixture *f, double m, float *out) {
    int deepest = 0; /* the clip's frame folded furthest */
    double most = -1;
    for (int k = 0; k < f->frames; ++k) {
        const float *T = clip_pose(f, k);
        double sum = 0;
        for (uint32_t b = 1; b < f->nb; ++b)
            sum += bend(T + 12 * (b - 1), T + 12 * b);
        if (sum > most) most = sum, deepest = k;
    }
    const float *T = clip_pose(f, deepest);
    memcpy(out, T, 12 * sizeof(float)); /* the root as the clip has it */
    for (uint32_t b = 1; b < f->nb; ++b) {
        const float *P = T + 12 * (b - 1), *B = T + 12 * b;
        double L[9], t[3], c, ang, ax[3];
        for (int i = 0; i < 3; ++i) /* L = R_p^T R_b, t = R_p^T (t_b - t_p) */
            for (int j = 0; j < 3; ++j) {
                L[3 * i + j] = 0;
                for (int k = 0; k < 3; ++k)
                    L[3 * i + j] += (double)P[3 * k + i] * B[3 * k + j];
            }
        for (int i = 0; i < 3; ++i) {
            t[i] = 0;
            for (int k = 0; k < 3; ++k)
                t[i] += (double)P[3 * k + i] * (B[9 + k] - P[9 + k]);
        }
        c = fmax(-1.0, fmin(1.0, 0.5 * (L[0] + L[4] + L[8] - 1)));
        ang = acos(c);
        ax[0] = L[7] - L[5], ax[1] = L[2] - L[6], ax[2] = L[3] - L[1];
        double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
        double a = fmin(m * ang, 3.0), sa = sin(a), ca = cos(a), R[9];
        for (int i = 0; i < 3; ++i)
            ax[i] = n > 0 ? ax[i] / n : (i == 2);
        for (int i = 0; i < 3; ++i) /* Rodrigues */
            for (int j = 0; j < 3; ++j) {
                static const int e[3][3] = {{0, -3, 2}, {3, 0, -1}, {-2, 1, 0}};
                int k = e[i][j] > 0 ? e[i][j] - 1 : -e[i][j] - 1;
                double K = e[i][j] == 0 ? 0 : (e[i][j] > 0 ? ax[k] : -ax[k]);
                R[3 * i + j] = (i == j ? ca : 0) + (1 - ca) * ax[i] * ax[j] + sa * K;
            }
        float *Pn = out + 12 * (b - 1), *Bn = out + 12 * b;
        for (int i = 0; i < 3; ++i) { /* the child: parent's new frame times (R, t) */
            for (int j = 0; j < 3; ++j)
                Bn[3 * i + j] =
                    (float)(Pn[3 * i] * R[j] + Pn[3 * i + 1] * R[3 + j] + Pn[3 * i + 2] * R[6 + j]);
            Bn[9 + i] =
                (float)(Pn[3 * i] * t[0] + Pn[3 * i + 1] * t[1] + Pn[3 * i + 2] * t[2] + Pn[9 + i]);
        }
    }
}

/* The pose k of the clip with every bone carried by x -> R x + t. */
static void moved_pose(const contract_fixture *f, int k, const float R[9], const float t[3],
                       float *out) {
    const float *T = clip_pose(f, k);
    for (uint32_t b = 0; b < f->nb; ++b) {
        const float *A = T + 12 * b;
        float *B = out + 12 * b;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                B[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] + R[3 * i + 2] * A[6 + j];
            B[9 + i] = R[3 * i] * A[9] + R[3 * i + 1] * A[10] + R[3 * i + 2] * A[11] + t[i];
        }
    }
}

/* A world of one box (centre, half extents, stiffness; 0: the blob's) and, when ball is
 * not NULL, a sphere of radius 0.2 that the run moves along under the finger. */
static sinew_world *make_world(const float centre[3], const float half[3], float stiffness,
                               sinew_collider_id *ball) {
    sinew_world *w = NULL;
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, &w) != SINEW_OK) return NULL;
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_BOX;
    memcpy(c.half_extents, half, sizeof c.half_extents);
    memcpy(c.transform.position, centre, sizeof c.transform.position);
    c.friction = ball ? 0.3f : 0.0f; /* the table: some friction */
    c.stiffness = stiffness;
    sinew_collider_id box;
    int ok = sinew_world_add_collider(w, &c, &box) == SINEW_OK;
    if (ok && ball) {
        c = sinew_collider_def_default();
        c.shape = SINEW_SHAPE_SPHERE;
        c.radius = 0.2f;
        c.transform.position[0] = 0.5f;
        c.transform.position[1] = -0.5f;
        ok = sinew_world_add_collider(w, &c, ball) == SINEW_OK;
    }
    if (!ok) {
        sinew_world_destroy(w);
        return NULL;
    }
    return w;
}

/* The tent (a mesh collider, Embree) over the finger and the wedge (a convex hull,
 * libccd) under it of props_fixture.h, each moved every step (tent_at, hull_at). */
enum { MESH_HULL_STEPS = 10000 };

static sinew_transform tent_at(int s) {
    return props_at((float)(0.6 + 0.1 * (s % 27)), 0.6f);
}

static sinew_transform hull_at(int s) {
    return props_at((float)(0.4 + 0.12 * (s % 23)), -0.55f);
}

static sinew_world *mesh_hull_world(sinew_collider_id *mesh, sinew_collider_id *hull) {
    sinew_world *w = NULL;
    sinew_world_def wd = sinew_world_def_default();
    if (sinew_world_create(&wd, &w) != SINEW_OK) return NULL;
    sinew_collider_def m = props_def(0, tent_at(0)), h = props_def(1, hull_at(0));
    if (sinew_world_add_collider(w, &m, mesh) != SINEW_OK ||
        sinew_world_add_collider(w, &h, hull) != SINEW_OK) {
        sinew_world_destroy(w);
        return NULL;
    }
    return w;
}

static sinew_transform ball_at(int s) {
    sinew_transform t = sinew_transform_identity();
    t.position[0] = (float)(0.5 + 0.1 * (s % 25));
    t.position[1] = -0.5f;
    return t;
}

#endif
