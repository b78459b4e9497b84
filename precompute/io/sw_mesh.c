/* Lifetime, validation and rigid-motion helpers of the bake-side geometry types. */
#include "sw_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void sw_tetmesh_free(sw_tetmesh *m) {
    if (!m) return;
    free(m->X);
    free(m->tets);
    memset(m, 0, sizeof *m);
}

void sw_trimesh_free(sw_trimesh *m) {
    if (!m) return;
    free(m->X);
    free(m->tris);
    memset(m, 0, sizeof *m);
}

void sw_surface_free(sw_surface *s) {
    if (!s) return;
    free(s->tris);
    free(s->verts);
    memset(s, 0, sizeof *s);
}

void sw_skeleton_free(sw_skeleton *s) {
    if (!s) return;
    free(s->joints);
    free(s->bones);
    free(s->parent);
    memset(s, 0, sizeof *s);
}

void sw_weights_free(sw_weights *w) {
    if (!w) return;
    free(w->w);
    memset(w, 0, sizeof *w);
}

void sw_clip_free(sw_clip *c) {
    if (!c) return;
    free(c->T);
    memset(c, 0, sizeof *c);
}

sinew_result sw_clip_validate(const sw_clip *c, int32_t nbones, sw_error *err) {
    if (!c || c->nbones != nbones || c->nframes < 1 || !c->T)
        return sw_error_set(err, SINEW_ERROR_PARSE,
                            "motion has %d bones x %d frames, skeleton %d bones", c ? c->nbones : 0,
                            c ? c->nframes : 0, nbones);
    for (size_t k = 0; k < (size_t)c->nframes * c->nbones * 12; ++k)
        if (!isfinite(c->T[k]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "motion frame %zu is not finite",
                                k / (12 * (size_t)c->nbones));
    return SINEW_OK;
}

void sw_character_free(sw_character *c) {
    if (!c) return;
    sw_tetmesh_free(&c->mesh);
    sw_skeleton_free(&c->skel);
    sw_weights_free(&c->weights);
    sw_clip_free(&c->clip);
    sw_clip_free(&c->range);
    sw_trimesh_free(&c->render);
    free(c->bone_of_vertex);
    free(c->bone_names);
    free(c->bone_bind);
    free(c->render_source);
    free(c->source_mesh_verts);
    free(c->render_stiffness);
    free(c->tet_stiffness);
    memset(c, 0, sizeof *c);
}

double sw_tet_signed_volume(const double *a, const double *b, const double *c, const double *d) {
    double e1[3], e2[3], e3[3];
    for (int i = 0; i < 3; ++i) {
        e1[i] = b[i] - a[i];
        e2[i] = c[i] - a[i];
        e3[i] = d[i] - a[i];
    }
    return (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
            e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) /
           6.0;
}

double sw_tetmesh_volume(const sw_tetmesh *m) {
    double v = 0;
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *k = m->tets + 4 * (int64_t)t;
        v += sw_tet_signed_volume(m->X + 3 * (int64_t)k[0], m->X + 3 * (int64_t)k[1],
                                  m->X + 3 * (int64_t)k[2], m->X + 3 * (int64_t)k[3]);
    }
    return v;
}

double sw_trimesh_signed_volume(const sw_trimesh *m) {
    static const double o[3] = {0, 0, 0};
    double v = 0;
    for (int32_t t = 0; t < m->ntris; ++t) {
        const int32_t *c = m->tris + 3 * (int64_t)t;
        v += sw_tet_signed_volume(o, m->X + 3 * (int64_t)c[0], m->X + 3 * (int64_t)c[1],
                                  m->X + 3 * (int64_t)c[2]);
    }
    return v;
}

sinew_result sw_trimesh_validate(const sw_trimesh *m, const char *who, sw_error *err) {
    if (!m || m->nverts < 3 || m->ntris < 1 || !m->X || !m->tris)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: an empty surface (%d vertices, %d triangles)", who,
                            m ? m->nverts : 0, m ? m->ntris : 0);
    for (int64_t i = 0; i < 3 * (int64_t)m->nverts; ++i)
        if (!isfinite(m->X[i]))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: vertex %lld is not finite",
                                who, (long long)(i / 3));
    for (int64_t i = 0; i < 3 * (int64_t)m->ntris; ++i)
        if (m->tris[i] < 0 || m->tris[i] >= m->nverts)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "%s: triangle %lld names vertex %d of %d", who, (long long)(i / 3),
                                m->tris[i], m->nverts);
    return SINEW_OK;
}

sinew_result sw_tetmesh_validate(const sw_tetmesh *m, double min_volume, sw_error *err) {
    if (!m || m->nverts < 4 || m->ntets < 1 || !m->X || !m->tets)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tet mesh is empty (%d vertices, %d tets)",
                            m ? m->nverts : 0, m ? m->ntets : 0);
    for (int32_t v = 0; v < 3 * m->nverts; ++v)
        if (!isfinite(m->X[v]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "vertex %d has a non-finite coordinate", v / 3);
    for (int32_t t = 0; t < m->ntets; ++t) {
        const int32_t *q = m->tets + 4 * t;
        for (int k = 0; k < 4; ++k) {
            if (q[k] < 0 || q[k] >= m->nverts)
                return sw_error_set(err, SINEW_ERROR_PARSE,
                                    "tet %d references vertex %d (mesh has %d vertices)", t, q[k],
                                    m->nverts);
            for (int j = 0; j < k; ++j)
                if (q[j] == q[k])
                    return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tet %d repeats vertex %d", t,
                                        q[k]);
        }
        double vol = sw_tet_signed_volume(m->X + 3 * q[0], m->X + 3 * q[1], m->X + 3 * q[2],
                                          m->X + 3 * q[3]);
        if (!isfinite(vol))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "tet %d has volume %g", t, vol);
        if (!(vol > min_volume))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "tet %d has volume %g (must be > %g; inverted or flat)", t, vol,
                                min_volume);
    }
    return SINEW_OK;
}

void sw_transform_point(const double *T, const double *p, double *out) {
    double r0 = T[0] * p[0] + T[1] * p[1] + T[2] * p[2] + T[9];
    double r1 = T[3] * p[0] + T[4] * p[1] + T[5] * p[2] + T[10];
    double r2 = T[6] * p[0] + T[7] * p[1] + T[8] * p[2] + T[11];
    out[0] = r0;
    out[1] = r1;
    out[2] = r2;
}

int32_t sw_bone_depth(const sw_skeleton *s, int32_t b) {
    int32_t d = 0;
    while (s->parent[b] >= 0)
        b = s->parent[b], d++;
    return d;
}

sinew_result sw_skeleton_validate(const sw_skeleton *s, sw_error *err) {
    if (!s || s->nbones < 1 || s->njoints < 2 || !s->joints || !s->bones || !s->parent)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "skeleton has no bones");
    if (s->nbones > SW_MAX_BONES)
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED, "skeleton has %d bones (at most %d)",
                            s->nbones, SW_MAX_BONES);
    for (int32_t j = 0; j < 3 * s->njoints; ++j)
        if (!isfinite(s->joints[j]))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "joint %d is not finite", j / 3);
    for (int32_t b = 0; b < s->nbones; ++b) {
        for (int k = 0; k < 2; ++k)
            if (s->bones[2 * b + k] < 0 || s->bones[2 * b + k] >= s->njoints)
                return sw_error_set(err, SINEW_ERROR_PARSE, "bone %d references joint %d of %d", b,
                                    s->bones[2 * b + k], s->njoints);
        if (s->parent[b] < -1 || s->parent[b] >= s->nbones || s->parent[b] == b)
            return sw_error_set(err, SINEW_ERROR_PARSE, "bone %d has parent %d", b, s->parent[b]);
    }
    for (int32_t b = 0; b < s->nbones; ++b) { /* a chain longer than nbones is a cycle */
        int32_t depth = 0;
        for (int32_t p = s->parent[b]; p >= 0; p = s->parent[p])
            if (++depth > s->nbones)
                return sw_error_set(err, SINEW_ERROR_PARSE, "bone %d is in a parent cycle", b);
    }
    return SINEW_OK;
}

/* T = A ∘ B for rigid transforms (apply B, then A). */
static void compose(const double *A, const double *B, double *T) {
    double R[9], t[3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            R[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
        t[i] = A[3 * i] * B[9] + A[3 * i + 1] * B[10] + A[3 * i + 2] * B[11] + A[9 + i];
    }
    memcpy(T, R, sizeof R);
    memcpy(T + 9, t, sizeof t);
}

/* Transform of bone b, computing unfinished ancestors first (iteratively). */
static void fk_bone(const sw_skeleton *s, const double *local, const double *root_t, double *T,
                    unsigned char *done, int32_t b) {
    while (!done[b]) {
        int32_t c = b; /* walk up to the highest unfinished ancestor */
        while (s->parent[c] >= 0 && !done[s->parent[c]])
            c = s->parent[c];
        const double *h = s->joints + 3 * s->bones[2 * c];
        const double *L = local + 9 * c;
        double Lc[12]; /* x -> h + L (x - h) */
        memcpy(Lc, L, 9 * sizeof(double));
        for (int i = 0; i < 3; ++i)
            Lc[9 + i] = h[i] - (L[3 * i] * h[0] + L[3 * i + 1] * h[1] + L[3 * i + 2] * h[2]);
        if (s->parent[c] >= 0) {
            compose(T + 12 * s->parent[c], Lc, T + 12 * c);
        } else {
            memcpy(T + 12 * c, Lc, sizeof Lc);
            if (root_t)
                for (int i = 0; i < 3; ++i)
                    T[12 * c + 9 + i] += root_t[i];
        }
        done[c] = 1;
    }
}

void sw_forward_kinematics(const sw_skeleton *s, const double *local,
                           const double *root_translation, double *T) {
    unsigned char done[SW_MAX_BONES] = {0};
    for (int32_t b = 0; b < s->nbones && b < SW_MAX_BONES; ++b)
        fk_bone(s, local, root_translation, T, done, b);
}

void sw_lbs(int32_t n, const double *X, const sw_weights *W, const double *T, double *x) {
    for (int32_t v = 0; v < n; ++v) {
        double acc[3] = {0, 0, 0}, p[3];
        const double *w = W->w + (size_t)v * W->nbones;
        for (int32_t b = 0; b < W->nbones; ++b) {
            if (w[b] == 0.0) continue;
            sw_transform_point(T + 12 * b, X + 3 * v, p);
            for (int i = 0; i < 3; ++i)
                acc[i] += w[b] * p[i];
        }
        for (int i = 0; i < 3; ++i)
            x[3 * v + i] = acc[i];
    }
}

double sw_point_segment_distance(const double *p, const double *a, const double *b) {
    double ab[3], ap[3], ab2 = 0, t = 0, d2 = 0;
    for (int i = 0; i < 3; ++i) {
        ab[i] = b[i] - a[i];
        ap[i] = p[i] - a[i];
        ab2 += ab[i] * ab[i];
        t += ab[i] * ap[i];
    }
    t = ab2 > 0 ? t / ab2 : 0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    for (int i = 0; i < 3; ++i) {
        double d = ap[i] - t * ab[i];
        d2 += d * d;
    }
    return sqrt(d2);
}
