/* Sampling an assimp animation into a clip of rest -> world bone transforms, and the 4x4
 * helpers the import shares (scene_internal.h).
 *
 * Keys: positions and scales are interpolated linearly, rotations by shortest-path slerp.
 * assimp 5.2.5's C key structs carry no interpolation mode, so glTF STEP keys are
 * interpolated too and glTF CUBICSPLINE keys are approximated by their values (assimp
 * keeps the value, not the tangents). Before the first key the first value holds, after
 * the last the last (mPreState/mPostState "default" and "constant" alike). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene_internal.h"

void sw_m4_mul(const double *a, const double *b, double *out) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0;
            for (int k = 0; k < 4; ++k)
                s += a[4 * i + k] * b[4 * k + j];
            out[4 * i + j] = s;
        }
}

int sw_m4_affine_inverse(const double *m, double *out) {
    const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
                 i = m[10];
    const double A = e * i - f * h, B = f * g - d * i, C = d * h - e * g;
    const double det = a * A + b * B + c * C;
    if (!isfinite(det) || fabs(det) < 1e-300) return 0;
    const double r = 1.0 / det;
    double inv[9] = {A * r, (c * h - b * i) * r, (b * f - c * e) * r,
                     B * r, (a * i - c * g) * r, (c * d - a * f) * r,
                     C * r, (b * g - a * h) * r, (a * e - b * d) * r};
    for (int row = 0; row < 3; ++row) {
        for (int k = 0; k < 3; ++k)
            out[4 * row + k] = inv[3 * row + k];
        out[4 * row + 3] =
            -(inv[3 * row] * m[3] + inv[3 * row + 1] * m[7] + inv[3 * row + 2] * m[11]);
    }
    out[12] = out[13] = out[14] = 0;
    out[15] = 1;
    return 1;
}

int sw_m4_from_ai(const struct aiMatrix4x4 *m, double *out) {
    const ai_real v[16] = {m->a1, m->a2, m->a3, m->a4, m->b1, m->b2, m->b3, m->b4,
                           m->c1, m->c2, m->c3, m->c4, m->d1, m->d2, m->d3, m->d4};
    for (int k = 0; k < 16; ++k) {
        out[k] = (double)v[k];
        if (!isfinite(out[k])) return 0;
    }
    return 1;
}

/* Index of the last key with time <= t in times[0..n) (stride `stride` bytes), or 0. */
static unsigned key_before(const void *keys, size_t stride, unsigned n, double t) {
    unsigned lo = 0, hi = n; /* first key with time > t lies in [lo, hi] */
    while (lo < hi) {
        unsigned mid = lo + (hi - lo) / 2;
        double tm = *(const double *)((const char *)keys + (size_t)mid * stride);
        if (tm <= t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo ? lo - 1 : 0;
}

/* Where tick t lies between key times ta and tb, in [0, 1] (0 when tb is not after ta:
 * the last key, or two keys at one time). */
static double key_fraction(double ta, double tb, double t) {
    return t > ta && tb > ta ? fmin(1.0, (t - ta) / (tb - ta)) : 0.0;
}

/* Linear interpolation of vector keys at tick t. */
static void sample_vec(const struct aiVectorKey *k, unsigned n, double t, double *out) {
    unsigned i = key_before(k, sizeof *k, n, t), j = i + 1 < n ? i + 1 : i;
    double u = key_fraction(k[i].mTime, k[j].mTime, t);
    const struct aiVector3D *a = &k[i].mValue, *b = &k[j].mValue;
    out[0] = (1 - u) * a->x + u * b->x;
    out[1] = (1 - u) * a->y + u * b->y;
    out[2] = (1 - u) * a->z + u * b->z;
}

/* Shortest-path slerp of quaternion keys at tick t, normalised; out = (w, x, y, z). */
static void sample_quat(const struct aiQuatKey *k, unsigned n, double t, double *out) {
    unsigned i = key_before(k, sizeof *k, n, t), j = i + 1 < n ? i + 1 : i;
    double u = key_fraction(k[i].mTime, k[j].mTime, t);
    const struct aiQuaternion *qa = &k[i].mValue, *qb = &k[j].mValue;
    double a[4] = {qa->w, qa->x, qa->y, qa->z}, b[4] = {qb->w, qb->x, qb->y, qb->z};
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0) {
        d = -d;
        for (int c = 0; c < 4; ++c)
            b[c] = -b[c];
    }
    double wa = 1 - u, wb = u;
    if (d < 0.9995) { /* (nearly parallel: the normalised lerp below is exact enough) */
        double th = acos(fmin(1.0, d)), s = sin(th);
        wa = sin((1 - u) * th) / s;
        wb = sin(u * th) / s;
    }
    double nrm = 0;
    for (int c = 0; c < 4; ++c) {
        out[c] = wa * a[c] + wb * b[c];
        nrm += out[c] * out[c];
    }
    nrm = sqrt(nrm);
    if (!(nrm > 1e-12)) {
        out[0] = 1, out[1] = out[2] = out[3] = 0;
        return;
    }
    for (int c = 0; c < 4; ++c)
        out[c] /= nrm;
}

/* The node's local transform from translation, rotation (w,x,y,z) and scale: T R S. */
static void trs_matrix(const double *t, const double *q, const double *s, double *m) {
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            m[4 * r + c] = R[3 * r + c] * s[c];
        m[4 * r + 3] = t[r];
    }
    m[12] = m[13] = m[14] = 0;
    m[15] = 1;
}

/* Decomposes a node's bind local transform into T, R (w,x,y,z) and S, so that a channel
 * with only rotation keys keeps the node's own translation and scale. */
static void decompose(const double *m, double *t, double *q, double *s) {
    double R[9];
    for (int c = 0; c < 3; ++c) {
        s[c] = sqrt(m[c] * m[c] + m[4 + c] * m[4 + c] + m[8 + c] * m[8 + c]);
        for (int r = 0; r < 3; ++r)
            R[3 * r + c] = s[c] > 1e-300 ? m[4 * r + c] / s[c] : (r == c);
    }
    for (int r = 0; r < 3; ++r)
        t[r] = m[4 * r + 3];
    double tr = R[0] + R[4] + R[8];
    if (tr > 0) {
        double k = 2 * sqrt(tr + 1);
        q[0] = 0.25 * k, q[1] = (R[7] - R[5]) / k, q[2] = (R[2] - R[6]) / k,
        q[3] = (R[3] - R[1]) / k;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        double k = 2 * sqrt(fmax(0.0, 1 + R[0] - R[4] - R[8]));
        q[0] = (R[7] - R[5]) / k, q[1] = 0.25 * k, q[2] = (R[1] + R[3]) / k,
        q[3] = (R[2] + R[6]) / k;
    } else if (R[4] > R[8]) {
        double k = 2 * sqrt(fmax(0.0, 1 + R[4] - R[0] - R[8]));
        q[0] = (R[2] - R[6]) / k, q[1] = (R[1] + R[3]) / k, q[2] = 0.25 * k,
        q[3] = (R[5] + R[7]) / k;
    } else {
        double k = 2 * sqrt(fmax(0.0, 1 + R[8] - R[0] - R[4]));
        q[0] = (R[3] - R[1]) / k, q[1] = (R[2] + R[6]) / k, q[2] = (R[5] + R[7]) / k,
        q[3] = 0.25 * k;
    }
}

static int channel_finite(const struct aiNodeAnim *c) {
    for (unsigned k = 0; k < c->mNumPositionKeys; ++k) {
        const struct aiVectorKey *v = &c->mPositionKeys[k];
        if (!isfinite(v->mTime) || !isfinite(v->mValue.x) || !isfinite(v->mValue.y) ||
            !isfinite(v->mValue.z))
            return 0;
    }
    for (unsigned k = 0; k < c->mNumScalingKeys; ++k) {
        const struct aiVectorKey *v = &c->mScalingKeys[k];
        if (!isfinite(v->mTime) || !isfinite(v->mValue.x) || !isfinite(v->mValue.y) ||
            !isfinite(v->mValue.z))
            return 0;
    }
    for (unsigned k = 0; k < c->mNumRotationKeys; ++k) {
        const struct aiQuatKey *v = &c->mRotationKeys[k];
        if (!isfinite(v->mTime) || !isfinite(v->mValue.w) || !isfinite(v->mValue.x) ||
            !isfinite(v->mValue.y) || !isfinite(v->mValue.z))
            return 0;
    }
    return 1;
}

/* The local transform of node i at tick t: its channel's keys over its bind TRS. */
static void node_local(const sw_scene_nodes *nodes, int32_t i, const struct aiNodeAnim *c, double t,
                       double *m) {
    double bind[16];
    sw_m4_from_ai(&nodes->node[i]->mTransformation, bind);
    if (!c) {
        memcpy(m, bind, sizeof bind);
        return;
    }
    double tr[3], q[4], s[3];
    decompose(bind, tr, q, s);
    if (c->mNumPositionKeys) sample_vec(c->mPositionKeys, c->mNumPositionKeys, t, tr);
    if (c->mNumRotationKeys) sample_quat(c->mRotationKeys, c->mNumRotationKeys, t, q);
    if (c->mNumScalingKeys) sample_vec(c->mScalingKeys, c->mNumScalingKeys, t, s);
    trs_matrix(tr, q, s, m);
}

/* Longest clip accepted: frames x bones x 12 doubles within 1 GiB. */
#define SW_CLIP_MAX_DOUBLES ((size_t)1 << 27)

sinew_result sw_scene_sample_clip(const struct aiAnimation *a, const sw_scene_nodes *nodes,
                                  int32_t nbones, const int32_t *bone_node, const double *Binv,
                                  double scale, double fps, const char *name, sw_imported_clip *out,
                                  sw_error *err) {
    memset(out, 0, sizeof *out);
    /* assimp's glTF importer counts in milliseconds (mTicksPerSecond 1000); 0 means the
     * format gave no rate, for which assimp's own default is 25 ticks a second. */
    double tps = a->mTicksPerSecond > 0 ? a->mTicksPerSecond : 25.0;
    double dur = a->mDuration / tps;
    if (!isfinite(dur) || dur < 0)
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "%s: animation '%s' has duration %g", name,
                            a->mName.data, dur);
    double nf = floor(dur * fps + 1e-6) + 1;
    if (nf * nbones * 12 > (double)SW_CLIP_MAX_DOUBLES)
        return sw_error_set(err, SINEW_ERROR_CAPACITY,
                            "%s: animation '%s' of %g s at %g fps is too long (%g frames)", name,
                            a->mName.data, dur, fps, nf);
    const struct aiNodeAnim **chan = calloc((size_t)nodes->n, sizeof *chan);
    double *G = malloc(sizeof(double) * 16 * (size_t)nodes->n);
    double *T = malloc(sizeof(double) * 12 * (size_t)nbones * (size_t)nf);
    sinew_result rc = SINEW_OK;
    if (!chan || !G || !T) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
        goto done;
    }
    for (unsigned c = 0; c < a->mNumChannels; ++c) {
        const struct aiNodeAnim *ch = a->mChannels[c];
        if (!channel_finite(ch)) {
            rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                              "%s: animation '%s', channel '%s' has a key that is not finite", name,
                              a->mName.data, ch->mNodeName.data);
            goto done;
        }
        /* The channel drives the first node of its name, or a joint of that name if there
         * is one (names repeat: scene_import.c, find_bone_node). A channel of an unknown
         * node is unused. */
        int32_t hit = -1;
        for (int32_t i = 0; i < nodes->n; ++i)
            if (!strcmp(nodes->node[i]->mName.data, ch->mNodeName.data)) {
                if (hit < 0 || (nodes->node_bone[i] >= 0 && nodes->node_bone[hit] < 0)) hit = i;
            }
        if (hit >= 0 && !chan[hit]) chan[hit] = ch;
    }
    for (int32_t f = 0; f < (int32_t)nf; ++f) {
        double t = (f / fps) * tps, L[16];
        for (int32_t i = 0; i < nodes->n; ++i) {
            node_local(nodes, i, chan[i], t, L);
            if (nodes->parent[i] < 0)
                memcpy(G + 16 * i, L, sizeof L);
            else
                sw_m4_mul(G + 16 * nodes->parent[i], L, G + 16 * i);
        }
        for (int32_t b = 0; b < nbones; ++b) {
            /* rest (bind, world) -> world. A joint whose global transform scales keeps the
             * scale in R (R is then not a rotation). */
            double M[16], *o = T + 12 * ((size_t)f * nbones + b);
            sw_m4_mul(G + 16 * bone_node[b], Binv + 16 * b, M);
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c)
                    o[3 * r + c] = M[4 * r + c];
                o[9 + r] = M[4 * r + 3] * scale;
            }
        }
    }
    for (size_t k = 0; k < 12 * (size_t)nbones * (size_t)nf; ++k)
        if (!isfinite(T[k])) {
            rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                              "%s: animation '%s' gives a bone transform that is not finite", name,
                              a->mName.data);
            goto done;
        }
    out->clip.nbones = nbones;
    out->clip.nframes = (int32_t)nf;
    out->clip.fps = fps;
    out->clip.T = T;
    T = NULL;
    out->duration_s = dur;
done:
    free(chan);
    free(G);
    free(T);
    return rc;
}
