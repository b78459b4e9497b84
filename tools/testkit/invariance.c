#include "invariance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"

/* Rotation of `angle` radians about `axis` (normalised here), row-major. */
static void axis_angle(const double axis[3], double angle, double R[9]) {
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double x = n > 0 ? axis[0] / n : 0, y = n > 0 ? axis[1] / n : 0, z = n > 0 ? axis[2] / n : 1;
    double c = cos(angle), s = sin(angle), C = 1 - c;
    double M[9] = {c + x * x * C,     x * y * C - z * s, x * z * C + y * s,
                   y * x * C + z * s, c + y * y * C,     y * z * C - x * s,
                   z * x * C - y * s, z * y * C + x * s, c + z * z * C};
    memcpy(R, M, sizeof M);
}

void sw_move_transform(const sw_move *m, int32_t f, double G[12]) {
    double k = m->kind == SW_MOVE_TURNING ? (double)f : 1.0;
    axis_angle(m->axis, k * m->angle, G);
    for (int i = 0; i < 3; ++i)
        G[9 + i] = k * m->shift[i];
    if (m->kind == SW_MOVE_SCALE) { /* the scale alone */
        axis_angle(m->axis, 0, G);
        G[9] = G[10] = G[11] = 0;
    }
}

/* G (R, t) applied to p: R p, plus t when `point`. */
static void carry_float(const double G[12], const float p[3], int point, float out[3]) {
    for (int i = 0; i < 3; ++i)
        out[i] = (float)(G[3 * i] * p[0] + G[3 * i + 1] * p[1] + G[3 * i + 2] * p[2] +
                         (point ? G[9 + i] : 0));
}

void sw_move_collider(const double G[12], sinew_collider_def *c) {
    if (c->shape == SINEW_SHAPE_PLANE) { /* n' = R n, offset' = n' . (G p0), p0 = offset n */
        float n[3] = {c->normal[0], c->normal[1], c->normal[2]}, p0[3];
        float p[3] = {n[0] * c->offset, n[1] * c->offset, n[2] * c->offset};
        carry_float(G, n, 0, c->normal);
        carry_float(G, p, 1, p0);
        c->offset = c->normal[0] * p0[0] + c->normal[1] * p0[1] + c->normal[2] * p0[2];
        return;
    }
    double pos[3], rot[4];
    sw_move_placement(G, c, pos, rot);
    for (int i = 0; i < 3; ++i)
        c->transform.position[i] = (float)pos[i];
    for (int i = 0; i < 4; ++i)
        c->transform.rotation[i] = (float)rot[i];
}

int sw_move_placement(const double G[12], const sinew_collider_def *c, double pos[3],
                      double rot[4]) {
    if (c->shape == SINEW_SHAPE_PLANE) return 0;
    const float *p = c->transform.position;
    for (int i = 0; i < 3; ++i)
        pos[i] = G[3 * i] * p[0] + G[3 * i + 1] * p[1] + G[3 * i + 2] * p[2] + G[9 + i];
    /* the quaternion of G's rotation (Shepperd: from its largest component), times q */
    const double tr = G[0] + G[4] + G[8];
    double g[4];
    if (tr >= G[0] && tr >= G[4] && tr >= G[8]) {
        double r = 2 * sqrt(1 + tr);
        g[0] = r / 4, g[1] = (G[7] - G[5]) / r, g[2] = (G[2] - G[6]) / r, g[3] = (G[3] - G[1]) / r;
    } else {
        int k = G[0] >= G[4] && G[0] >= G[8] ? 0
                : G[4] >= G[8]               ? 1
                                             : 2,
            i = (k + 1) % 3, j = (k + 2) % 3;
        double r = 2 * sqrt(1 + G[4 * k] - G[4 * i] - G[4 * j]);
        g[1 + k] = r / 4;
        g[0] = (G[3 * j + i] - G[3 * i + j]) / r;
        g[1 + i] = (G[3 * i + k] + G[3 * k + i]) / r;
        g[1 + j] = (G[3 * j + k] + G[3 * k + j]) / r;
    }
    const float *q = c->transform.rotation;
    rot[0] = g[0] * q[0] - g[1] * q[1] - g[2] * q[2] - g[3] * q[3];
    rot[1] = g[0] * q[1] + g[1] * q[0] + g[2] * q[3] - g[3] * q[2];
    rot[2] = g[0] * q[2] - g[1] * q[3] + g[2] * q[0] + g[3] * q[1];
    rot[3] = g[0] * q[3] + g[1] * q[2] - g[2] * q[1] + g[3] * q[0];
    return 1;
}

static double move_scale(const sw_move *m) {
    return (m->kind == SW_MOVE_SCALE || m->kind == SW_MOVE_ACTOR) && m->scale > 0 ? m->scale : 1;
}

/* y = s (G x) for the rigid G and scale s: where the first instance's x belongs. */
static void carry_point(const double G[12], double s, const double x[3], double y[3]) {
    for (int i = 0; i < 3; ++i)
        y[i] = s * (G[3 * i] * x[0] + G[3 * i + 1] * x[1] + G[3 * i + 2] * x[2] + G[9 + i]);
}

/* The second instance's bone transform: G T scaled by s (SCALE), or T itself when G goes
 * in as the actor's transform (ACTOR). */
static void carry_bone(const sw_move *m, const double G[12], const double *T, double *out) {
    if (m->kind == SW_MOVE_ACTOR) {
        memcpy(out, T, 12 * sizeof(double));
        return;
    }
    double s = move_scale(m);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            out[3 * i + j] =
                s * (G[3 * i] * T[j] + G[3 * i + 1] * T[3 + j] + G[3 * i + 2] * T[6 + j]);
        out[9 + i] = s * (G[3 * i] * T[9] + G[3 * i + 1] * T[10] + G[3 * i + 2] * T[11] + G[9 + i]);
    }
}

static sinew_result set_pose(sinew_instance *in, const double *T, int32_t nb, int as_float,
                             float *scratch) {
    if (!as_float) return sw_instance_set_pose_d(in, T);
    for (int32_t i = 0; i < 12 * nb; ++i)
        scratch[i] = (float)T[i];
    return sinew_instance_set_pose(in, scratch, (uint32_t)nb);
}

/* The run's def; shared: with no scratch of its own. */
static sinew_instance_def run_def(const sw_invariance_run *run, int shared) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = run->mode;
    if (run->self_contact) d.self_contact = run->self_contact;
    d.max_patch_vertices = run->max_patch_vertices;
    d.novel_contact = run->novel_contact;
    d.shared_workspace = (uint32_t)shared;
    return d;
}

static sinew_result make_instance(const sinew_blob *blob, const sw_invariance_run *run,
                                  const sinew_world *world, int shared, sinew_instance **out) {
    sinew_instance_def d = run_def(run, shared);
    sinew_result r = sinew_instance_create(blob, &d, out);
    if (r == SINEW_OK && world) r = sinew_instance_set_world(*out, world);
    return r;
}

/* The surface of `in` into x (doubles): read as floats when asked. */
static void read_surface(const sinew_instance *in, uint32_t ns, int as_float, float *fs,
                         double *x) {
    if (!as_float) {
        sw_instance_read_surface_d(in, x); /* the host's frame, as the float read */
        return;
    }
    sinew_instance_read_surface(in, fs, NULL, ns);
    for (size_t i = 0; i < (size_t)3 * ns; ++i)
        x[i] = fs[i];
}

/* The rest bounding-box diagonal of the output surface (read at the rest pose). */
static double rest_size(const double *x, uint32_t ns) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < ns; ++v)
        for (int k = 0; k < 3; ++k) {
            lo[k] = fmin(lo[k], x[3 * v + k]);
            hi[k] = fmax(hi[k], x[3 * v + k]);
        }
    double d2 = 0;
    for (int k = 0; k < 3; ++k)
        d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrt(d2);
}

sinew_result sw_invariance_measure(const sinew_blob *blob, const double *clip, int32_t nb,
                                   int32_t frames, const sw_invariance_run *run, const sw_move *m,
                                   sw_invariance_result *out) {
    memset(out, 0, sizeof *out);
    out->worst_frame = -1;
    uint32_t ns = sinew_blob_surface_vertex_count(blob);
    if (nb != (int32_t)sinew_blob_bone_count(blob) || frames < 1 || ns == 0)
        return SINEW_ERROR_INVALID_ARGUMENT;
    sinew_instance *a = NULL, *b = NULL;
    sinew_workspace *ws[2] = {NULL, NULL};
    double *xa = malloc((size_t)3 * ns * sizeof(double)),
           *xb = malloc((size_t)3 * ns * sizeof(double));
    double *Tb = malloc((size_t)12 * nb * sizeof(double));
    float *fs = malloc((size_t)3 * ns * sizeof(float) + (size_t)12 * nb * sizeof(float));
    sinew_result r = xa && xb && Tb && fs ? SINEW_OK : SINEW_ERROR_OUT_OF_MEMORY;
    if (r == SINEW_OK) r = make_instance(blob, run, run->world, 0, &a);
    if (r == SINEW_OK) r = make_instance(blob, run, run->world_moved, run->workspaces != 0, &b);
    for (int k = 0; k < 2 && run->workspaces && r == SINEW_OK; ++k) {
        sinew_instance_def d = run_def(run, 0);
        r = sinew_workspace_create(blob, &d, &ws[k]);
    }
    if (r != SINEW_OK) goto done;
    sw_instance_skinned_surface(a, xa); /* at rest: the instance's first pose */
    out->size = rest_size(xa, ns);
    const double s = move_scale(m);
    const float dt = run->dt > 0 ? run->dt : 1.0f / 30;
    for (int32_t f = 0; f < frames; ++f) {
        const double *T = clip + (size_t)12 * nb * f;
        double G[12];
        sw_move_transform(m, f, G);
        for (int32_t k = 0; k < nb; ++k)
            carry_bone(m, G, T + 12 * k, Tb + 12 * k);
        if (m->kind == SW_MOVE_ACTOR) {
            double A[12];
            memcpy(A, G, sizeof A);
            for (int i = 0; i < 9; ++i)
                A[i] *= s;
            if ((r = sinew_instance_set_actor(b, A)) != SINEW_OK) goto done;
        }
        float *fp = fs + (size_t)3 * ns;
        if ((r = set_pose(a, T, nb, m->float_poses, fp)) != SINEW_OK ||
            (r = set_pose(b, Tb, nb, m->float_poses, fp)) != SINEW_OK)
            goto done;
        out->failed += sinew_instance_step(a, dt) != SINEW_OK;
        out->failed += (run->workspaces ? sinew_instance_step_in(b, ws[f % 2], dt)
                                        : sinew_instance_step(b, dt)) != SINEW_OK;
        sinew_step_stats st = {.struct_size = sizeof st};
        sinew_instance_get_stats(a, &st);
        out->world_contacts += st.world_contacts;
        out->self_contacts += st.self_contacts;
        out->novel_contacts += st.novel_contacts;
        if (st.patch_vertices > out->patch_vertices) out->patch_vertices = st.patch_vertices;
        out->unconverged += !(st.status & SINEW_STEP_CONVERGED);
        sinew_step_stats sb = {.struct_size = sizeof sb};
        sinew_instance_get_stats(b, &sb);
        out->novel_moved += sb.novel_contacts;
        read_surface(a, ns, m->float_output, fs, xa);
        read_surface(b, ns, m->float_output, fs, xb);
        double worst = 0;
        for (uint32_t v = 0; v < ns; ++v) {
            double y[3], d2 = 0;
            if (m->kind == SW_MOVE_ACTOR) /* the actor's frame: the first's own */
                memcpy(y, xa + 3 * v, sizeof y);
            else
                carry_point(G, s, xa + 3 * v, y);
            for (int k = 0; k < 3; ++k)
                d2 += (xb[3 * v + k] - y[k]) * (xb[3 * v + k] - y[k]);
            /* a scaled instance's error in the first's units */
            worst = fmax(worst, sqrt(d2) / (m->kind == SW_MOVE_SCALE ? s : 1));
        }
        if (!(worst / out->size <= out->err)) {
            out->err = worst / out->size;
            out->worst_frame = f;
        }
    }
done:
    sinew_instance_destroy(a);
    sinew_instance_destroy(b);
    sinew_workspace_destroy(ws[0]);
    sinew_workspace_destroy(ws[1]);
    free(xa);
    free(xb);
    free(Tb);
    free(fs);
    return r;
}
