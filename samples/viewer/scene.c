/* A procedural sample scene as a host would drive it: the bake generates these tubes
 * (samples/procedural/samples.c) and bakes them with no asset file, so the viewer holds
 * their description (the bone chain on the x axis, the bends of the clip) and skins the
 * blob's own rest surface with the generator's weight rule. The descriptions mirror the
 * generator's table; the blob must be baked from the same scene. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "viewer.h"

#define PI 3.14159265358979323846

typedef struct scene_def {
    const char *name;
    int32_t nbones;
    double joint_x[4];  /* root head .. last tail, on the axis */
    double peak_deg[3]; /* per bone: bend of its head joint at the clip's peak */
} scene_def;

static const scene_def scene_defs[] = {
    {"cylinder", 2, {0.0, 2.0, 4.0}, {0.0, 140.0}},
    {"finger", 3, {0.0, 1.6, 2.7, 3.6}, {0.0, 110.0, 100.0}},
    {"capsule", 2, {0.0, 2.0, 4.0}, {0.0, 90.0}},
};

/* The bake's clip bends from straight to the peak and back; played here over this
 * period, looped. */
#define SCENE_PERIOD_S 2.0

static double smoothstep(double t) {
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return t * t * (3.0 - 2.0 * t);
}

static int scene_pose(const vw_asset *a, int clip, double t, float *out) {
    const scene_def *d = a->impl;
    (void)clip;
    double e = 0.5 * (1 - cos(2 * PI * t / SCENE_PERIOD_S)), M[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int32_t b = 0; b < d->nbones; ++b) {
        double ang = e * d->peak_deg[b] * PI / 180, c = cos(ang), s = sin(ang), h = d->joint_x[b];
        /* local: x -> h + Rz (x - h); global = parent global o local */
        const double L[12] = {c, -s, 0, s, c, 0, 0, 0, 1, h - c * h, -s * h, 0};
        double G[12];
        for (int r = 0; r < 3; ++r) {
            for (int k = 0; k < 3; ++k)
                G[3 * r + k] = M[3 * r] * L[k] + M[3 * r + 1] * L[3 + k] + M[3 * r + 2] * L[6 + k];
            G[9 + r] = M[3 * r] * L[9] + M[3 * r + 1] * L[10] + M[3 * r + 2] * L[11] + M[9 + r];
        }
        memcpy(M, G, sizeof G);
        for (int k = 0; k < 12; ++k)
            out[12 * b + k] = (float)M[k];
    }
    return 1;
}

int vw_scene_asset(const char *name, const float *rest, int32_t nverts, const uint32_t *tris,
                   int32_t ntris, uint32_t nbones, vw_asset *a, char *err, size_t errlen) {
    memset(a, 0, sizeof *a);
    const scene_def *d = NULL;
    for (size_t i = 0; i < sizeof scene_defs / sizeof scene_defs[0]; ++i)
        if (!strcmp(scene_defs[i].name, name)) d = &scene_defs[i];
    if (!d) {
        snprintf(err, errlen, "unknown scene '%s' (known: cylinder, finger, capsule)", name);
        return 0;
    }
    if ((uint32_t)d->nbones != nbones) {
        snprintf(err, errlen, "scene '%s' has %d bones, the blob %u: baked from another scene",
                 name, d->nbones, nbones);
        return 0;
    }
    a->nbones = d->nbones, a->nverts = nverts, a->ntris = ntris, a->nclips = 1;
    snprintf(a->clip_names[0], sizeof a->clip_names[0], "bend");
    a->clip_duration[0] = SCENE_PERIOD_S;
    a->impl = (void *)d, a->pose = scene_pose;
    a->rest = malloc(sizeof(float) * 3 * (size_t)nverts);
    a->tris = malloc(sizeof(uint32_t) * 3 * (size_t)(ntris ? ntris : 1));
    a->wbone = calloc(4 * (size_t)nverts, sizeof(int32_t));
    a->wgt = calloc(4 * (size_t)nverts, sizeof(float));
    if (!a->rest || !a->tris || !a->wbone || !a->wgt) {
        snprintf(err, errlen, "out of memory");
        vw_asset_free(a);
        return 0;
    }
    memcpy(a->rest, rest, sizeof(float) * 3 * (size_t)nverts);
    memcpy(a->tris, tris, sizeof(uint32_t) * 3 * (size_t)ntris);
    /* The blend half-width around joint j: the tube's radius there (measured on the
     * surface), under half of each neighbouring bone. */
    double hw[4] = {0};
    for (int32_t j = 1; j < d->nbones; ++j) {
        double r = 0;
        for (int32_t v = 0; v < nverts; ++v)
            if (fabs(rest[3 * v] - d->joint_x[j]) < 0.1)
                r = fmax(r, hypot(rest[3 * v + 1], rest[3 * v + 2]));
        double gap = fmin(d->joint_x[j] - d->joint_x[j - 1], d->joint_x[j + 1] - d->joint_x[j]);
        hw[j] = fmin(r > 0 ? r : 0.4, 0.45 * gap);
    }
    for (int32_t v = 0; v < nverts; ++v) {
        double g[5] = {1, 0, 0, 0, 0};
        for (int32_t j = 1; j < d->nbones; ++j)
            g[j] = smoothstep((rest[3 * v] - d->joint_x[j] + hw[j]) / (2 * hw[j]));
        g[d->nbones] = 0;
        for (int32_t b = 0; b < d->nbones && b < 4; ++b)
            a->wbone[4 * v + b] = b, a->wgt[4 * v + b] = (float)(g[b] - g[b + 1]);
    }
    return 1;
}
