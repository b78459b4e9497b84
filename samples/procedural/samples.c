/* Procedural sample characters: a tube (tube_mesh.c) with a chain of bones on its axis,
 * smooth skin weights, bone-driven interior vertices and a bending clip.
 *
 * Units follow the thesis's hand (bones 1-4.5 units long) and its material, E = 5000,
 * nu = 0.08 (DESIGN.md §8). Density is 1 mass unit per cubic unit: with it the shapes
 * sag by under 1% under gravity (rho g L / E ~ 0.008), and the thesis normalises the
 * total mass anyway. */
#include "samples.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tube_mesh.h"

#define SW_SAMPLE_MAX_BONES 3
#define PI 3.14159265358979323846

typedef struct sample_def {
    const char *name;
    sw_tube_profile shape;
    int32_t nbones;
    double joint_x[SW_SAMPLE_MAX_BONES + 1]; /* root head .. last tail, on the axis */
    double peak_deg[SW_SAMPLE_MAX_BONES];    /* per bone: bend of its head joint */
} sample_def;

static const sample_def sample_defs[] = {
    /* Fig. 3.3: a straight cylinder with one joint in the middle folded to 140 degrees. */
    {"cylinder", {4.0, 0.5, 0.5, 0, 0}, 2, {0.0, 2.0, 4.0}, {0.0, 140.0}},
    /* Fig. 3.4: three phalanges, tapered, rounded tip; the distal one reaches back
     * toward the proximal one (contact between non-adjacent domains). */
    {"finger", {3.6, 0.45, 0.35, 0, 1}, 3, {0.0, 1.6, 2.7, 3.6}, {0.0, 110.0, 100.0}},
    /* Fig. 4.4: a capsule with one joint in the middle bent to 90 degrees. */
    {"capsule", {4.0, 0.5, 0.5, 1, 1}, 2, {0.0, 2.0, 4.0}, {0.0, 90.0}},
};

#define NSAMPLES ((int)(sizeof sample_defs / sizeof sample_defs[0]))

const char *const *sw_sample_names(void) {
    static const char *const names[] = {"cylinder", "finger", "capsule", NULL};
    return names;
}

static double smoothstep(double t) {
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return t * t * (3.0 - 2.0 * t);
}

/* Half-width of the blend around interior joint j (1..nbones-1): the local radius,
 * but under half of each neighbouring bone so that blends never overlap. */
static double blend_halfwidth(const sample_def *d, int32_t j) {
    double h = sw_tube_body_radius(&d->shape, d->joint_x[j]);
    double gap = fmin(d->joint_x[j] - d->joint_x[j - 1], d->joint_x[j + 1] - d->joint_x[j]);
    return fmin(h, 0.45 * gap);
}

/* Weights: gamma_j rises 0 -> 1 across joint j; bone b gets gamma_b - gamma_{b+1}
 * (gamma_0 = 1, gamma_nbones = 0), which telescopes to a row sum of 1 and is
 * non-negative because the blends do not overlap. */
static void fill_weights(const sample_def *d, const sw_tetmesh *m, double *w) {
    const int32_t nb = d->nbones;
    for (int32_t v = 0; v < m->nverts; ++v) {
        double x = m->X[3 * v], gamma[SW_SAMPLE_MAX_BONES + 1];
        gamma[0] = 1.0;
        gamma[nb] = 0.0;
        for (int32_t j = 1; j < nb; ++j) {
            double h = blend_halfwidth(d, j);
            gamma[j] = smoothstep((x - d->joint_x[j] + h) / (2.0 * h));
        }
        for (int32_t b = 0; b < nb; ++b)
            w[(size_t)v * nb + b] = gamma[b] - gamma[b + 1];
    }
}

/* The bone containing x along the axis. */
static int32_t bone_at(const sample_def *d, double x) {
    int32_t b = 0;
    while (b + 1 < d->nbones && x >= d->joint_x[b + 1])
        ++b;
    return b;
}

/* Bone-driven vertices: interior, near the axis (the "bone"), away from the joints.
 * On coarse meshes the strict criterion may leave a bone with fewer than 4 vertices;
 * the limits then widen step by step (radius up, joint clearance down). */
static sinew_result fill_bone_of_vertex(const sample_def *d, const sw_tetmesh *m,
                                        const unsigned char *surf, int32_t *bov, sw_error *err) {
    double radial = 0.3, clearance = 0.6;
    for (int attempt = 0; attempt < 12; ++attempt) {
        int32_t count[SW_SAMPLE_MAX_BONES] = {0};
        for (int32_t v = 0; v < m->nverts; ++v) {
            const double *X = m->X + 3 * v;
            double R = sw_tube_body_radius(&d->shape, X[0]);
            int32_t b = bone_at(d, X[0]);
            int ok = !surf[v] && hypot(X[1], X[2]) <= radial * R;
            for (int32_t j = 1; j < d->nbones && ok; ++j)
                ok = fabs(X[0] - d->joint_x[j]) >=
                     clearance * sw_tube_body_radius(&d->shape, d->joint_x[j]);
            bov[v] = ok ? b : -1;
            if (ok) count[b]++;
        }
        int enough = 1;
        for (int32_t b = 0; b < d->nbones; ++b)
            enough &= count[b] >= 4;
        if (enough) return SINEW_OK;
        radial = fmin(radial * 1.3, 0.9);
        clearance *= 0.8;
    }
    return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                        "sample '%s': mesh too coarse to give every bone 4 interior vertices",
                        d->name);
}

static sinew_result fill_skeleton(const sample_def *d, sw_skeleton *s, sw_error *err) {
    const int32_t nb = d->nbones;
    s->njoints = nb + 1;
    s->nbones = nb;
    s->joints = calloc(3 * (size_t)(nb + 1), sizeof(double));
    s->bones = malloc(2 * sizeof(int32_t) * (size_t)nb);
    s->parent = malloc(sizeof(int32_t) * (size_t)nb);
    if (!s->joints || !s->bones || !s->parent)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for a skeleton");
    for (int32_t j = 0; j <= nb; ++j)
        s->joints[3 * j] = d->joint_x[j];
    for (int32_t b = 0; b < nb; ++b) {
        s->bones[2 * b] = b;
        s->bones[2 * b + 1] = b + 1;
        s->parent[b] = b - 1;
    }
    return sw_skeleton_validate(s, err);
}

/* Bend of frame f in [0, 1]: a cosine ease from 0 up to the peak at frame nframes/2
 * and back down to 0 at the last frame. */
static double bend_fraction(int32_t f, int32_t nframes) {
    int32_t mid = nframes / 2, last = nframes - 1;
    if (f <= mid) return 0.5 * (1.0 - cos(PI * f / mid));
    return 0.5 * (1.0 - cos(PI * (double)(last - f) / (last - mid)));
}

/* Clip: every joint rotates about +z (bending in the x-y plane), the root stays put;
 * forward kinematics composes the chain. */
static sinew_result fill_clip(const sample_def *d, const sw_skeleton *s, int32_t nframes,
                              sw_clip *c, sw_error *err) {
    const int32_t nb = d->nbones;
    c->nbones = nb;
    c->nframes = nframes;
    c->fps = 30.0;
    c->T = malloc(sizeof(double) * 12 * (size_t)nb * (size_t)nframes);
    if (!c->T)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for %d clip frames",
                            nframes);
    for (int32_t f = 0; f < nframes; ++f) {
        double local[9 * SW_SAMPLE_MAX_BONES], e = bend_fraction(f, nframes);
        for (int32_t b = 0; b < nb && b < SW_SAMPLE_MAX_BONES; ++b) {
            double a = e * d->peak_deg[b] * PI / 180.0, ca = cos(a), sa = sin(a);
            const double R[9] = {ca, -sa, 0, sa, ca, 0, 0, 0, 1};
            memcpy(local + 9 * b, R, sizeof R);
        }
        sw_forward_kinematics(s, local, NULL, c->T + (size_t)12 * nb * f);
    }
    return SINEW_OK;
}

static sinew_result build(const sample_def *d, int32_t target_tets, int32_t nframes,
                          sw_character *out, sw_error *err) {
    unsigned char *surf = NULL;
    sinew_result r = sw_tube_mesh(&d->shape, target_tets, &out->mesh, &surf, err);
    if (r != SINEW_OK) return r;
    const int32_t nv = out->mesh.nverts;
    out->weights.nverts = nv;
    out->weights.nbones = d->nbones;
    out->weights.w = malloc(sizeof(double) * (size_t)nv * (size_t)d->nbones);
    out->bone_of_vertex = malloc(sizeof(int32_t) * (size_t)nv);
    if (!out->weights.w || !out->bone_of_vertex) {
        free(surf);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "out of memory for weights of %d vertices", nv);
    }
    fill_weights(d, &out->mesh, out->weights.w);
    r = fill_bone_of_vertex(d, &out->mesh, surf, out->bone_of_vertex, err);
    free(surf);
    if (r == SINEW_OK) r = fill_skeleton(d, &out->skel, err);
    if (r == SINEW_OK) r = fill_clip(d, &out->skel, nframes, &out->clip, err);
    return r;
}

sinew_result sw_sample_make(const char *name, int32_t target_tets, int32_t nframes,
                            sw_character *out, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sample output is NULL");
    memset(out, 0, sizeof *out);
    if (!name) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sample name is NULL");
    const sample_def *d = NULL;
    for (int i = 0; i < NSAMPLES; ++i)
        if (strcmp(name, sample_defs[i].name) == 0) d = &sample_defs[i];
    if (!d)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "unknown sample '%.64s' (known: cylinder, finger, capsule)", name);
    if (target_tets < 1000 || target_tets > 2000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sample '%s': target of %d tets is outside [1000, 2000000]", name,
                            target_tets);
    if (nframes < 2 || nframes > 1000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "sample '%s': %d frames is outside [2, 1000000]", name, nframes);
    sinew_result r = build(d, target_tets, nframes, out, err);
    if (r != SINEW_OK) {
        sw_character_free(out);
        return r;
    }
    snprintf(out->name, sizeof out->name, "%s", d->name);
    out->youngs = 5000.0;
    out->poisson = 0.08;
    out->density = 1.0;
    return SINEW_OK;
}
