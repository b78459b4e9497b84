/* Ray-cast renderer over Embree 3 (see render.h). Geometry goes to Embree as float
 * triangles; shading is done here in double, per pixel, independent of thread count. */
#include "render.h"
#include "vec3.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
/* Coordinates beyond this would lose everything when converted to float for Embree. */
#define COORD_MAX 1e30

static double clamp01(double x) {
    return x < 0 ? 0 : (x > 1 ? 1 : x);
}

/* ---- parameters ------------------------------------------------------------------ */

sw_render_params sw_render_params_default(int32_t width, int32_t height) {
    sw_render_params p;
    memset(&p, 0, sizeof p);
    p.width = width;
    p.height = height;
    p.eye[2] = 5.0;
    p.up[1] = 1.0;
    p.fov_y_deg = 35.0;
    p.supersample = 2;
    p.key = 0.85;
    p.fill = 0.25;
    p.ambient = 0.12;
    p.shadows = 1;
    p.smooth = 1;
    p.ground_tile = 1.0;
    p.ground_radius = 20.0;
    p.background[0] = 0.80f;
    p.background[1] = 0.84f;
    p.background[2] = 0.89f;
    p.threads = 1;
    p.view_azimuth_deg = 35.0;
    p.view_elevation_deg = 20.0;
    return p;
}

sinew_result sw_render_bbox(int32_t nverts, const double *X, double bmin[3], double bmax[3],
                            sw_error *err) {
    if (nverts < 1 || !X)
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "render: no vertices to bound");
    for (int k = 0; k < 3; ++k)
        bmin[k] = bmax[k] = X[k];
    for (int32_t v = 0; v < nverts; ++v)
        for (int k = 0; k < 3; ++k) {
            double x = X[3 * (int64_t)v + k];
            if (!isfinite(x))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "render: vertex %d coordinate %d is %g", v, k, x);
            if (x < bmin[k]) bmin[k] = x;
            if (x > bmax[k]) bmax[k] = x;
        }
    return SINEW_OK;
}

/* An orthonormal camera basis; returns 0 when eye == target or up is parallel to the
 * view direction. */
static int camera_basis(const sw_render_params *p, double fwd[3], double right[3], double cup[3]) {
    for (int k = 0; k < 3; ++k)
        fwd[k] = p->target[k] - p->eye[k];
    if (!(sw_v3_normalize(fwd) > 0)) return 0;
    sw_v3_cross(fwd, p->up, right);
    double n = sw_v3_norm(right), nu = sw_v3_norm(p->up);
    if (!(n > 1e-9 * nu)) return 0;
    sw_v3_normalize(right);
    sw_v3_cross(right, fwd, cup);
    return 1;
}

/* The eye's distance from the target c along dir at which every point o + c lies in the
 * view: |o . right| <= tx (dist - o . dir) and |o . vup| <= ty (...), with a 5% margin;
 * at least `least`. */
static double fit_distance(const double *pts, int64_t n, const double c[3], const double dir[3],
                           const double right[3], const double vup[3], double tx, double ty,
                           double least) {
    double dist = least;
    for (int64_t i = 0; i < n; ++i) {
        const double o[3] = {pts[3 * i] - c[0], pts[3 * i + 1] - c[1], pts[3 * i + 2] - c[2]};
        double depth = sw_v3_dot(o, dir);
        dist = fmax(dist, depth + fabs(sw_v3_dot(o, right)) / (0.95 * tx));
        dist = fmax(dist, depth + fabs(sw_v3_dot(o, vup)) / (0.95 * ty));
    }
    return dist;
}

/* The middle of the points' image at distance dist, as the offset along right and vup at
 * the target's depth that centres it. */
static void image_middle(const double *pts, int64_t n, const double c[3], const double dir[3],
                         const double right[3], const double vup[3], double dist, double shift[2]) {
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int64_t i = 0; i < n; ++i) {
        const double o[3] = {pts[3 * i] - c[0], pts[3 * i + 1] - c[1], pts[3 * i + 2] - c[2]};
        double depth = dist - sw_v3_dot(o, dir);
        double a = sw_v3_dot(o, right) / depth, b = sw_v3_dot(o, vup) / depth;
        lo[0] = fmin(lo[0], a), hi[0] = fmax(hi[0], a);
        lo[1] = fmin(lo[1], b), hi[1] = fmax(hi[1], b);
    }
    shift[0] = 0.5 * (lo[0] + hi[0]) * dist;
    shift[1] = 0.5 * (lo[1] + hi[1]) * dist;
}

/* sw_render_frame_camera, the eye fitted to `pts` (n points; NULL: the box's corners). */
static sinew_result frame(sw_render_params *p, const double bmin[3], const double bmax[3],
                          const double *pts, int64_t n, sw_error *err) {
    if (!p || !bmin || !bmax)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "render: NULL argument");
    if (!sw_v3_isfinite(bmin) || !sw_v3_isfinite(bmax))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "render: bounding box is not finite");
    for (int k = 0; k < 3; ++k)
        if (bmin[k] > bmax[k])
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "render: bounding box min %g > max %g on axis %d", bmin[k], bmax[k],
                                k);
    if (p->width < 1 || p->height < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "render: image size %d x %d",
                            p->width, p->height);
    if (!(p->fov_y_deg > 0 && p->fov_y_deg < 170))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: vertical fov %g outside (0, 170) degrees", p->fov_y_deg);
    if (!isfinite(p->view_azimuth_deg) || !(fabs(p->view_elevation_deg) < 90))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: view azimuth %g / elevation %g (elevation within (-90, 90))",
                            p->view_azimuth_deg, p->view_elevation_deg);
    double u[3] = {p->up[0], p->up[1], p->up[2]};
    if (!sw_v3_isfinite(u) || !(sw_v3_normalize(u) > 0))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "render: up vector is zero");
    /* "Front" is +Z unless up is close to Z (then +X), made perpendicular to up. */
    double f[3] = {0, 0, 1};
    if (fabs(u[2]) > 0.9) f[0] = 1, f[2] = 0;
    double fu = sw_v3_dot(f, u);
    for (int k = 0; k < 3; ++k)
        f[k] -= fu * u[k];
    sw_v3_normalize(f);
    double s[3];
    sw_v3_cross(u, f, s);
    double c[3], d[3];
    for (int k = 0; k < 3; ++k) {
        c[k] = 0.5 * (bmin[k] + bmax[k]);
        d[k] = bmax[k] - bmin[k];
    }
    double r = 0.5 * sw_v3_norm(d);
    if (!(r > 0)) r = 1e-3 * (1.0 + sw_v3_norm(c)); /* a single point: any small frame */
    double ty = tan(0.5 * p->fov_y_deg * PI / 180.0);
    double tx = ty * (double)p->width / (double)p->height;
    double az = p->view_azimuth_deg * PI / 180.0, el = p->view_elevation_deg * PI / 180.0;
    double dir[3], right[3], vup[3]; /* from the target to the eye; the image's axes */
    for (int k = 0; k < 3; ++k)
        dir[k] = cos(el) * (cos(az) * f[k] + sin(az) * s[k]) + sin(el) * u[k];
    sw_v3_cross(dir, u, right);
    sw_v3_normalize(right); /* |el| < 90: dir is never along up */
    sw_v3_cross(right, dir, vup);
    double corners[24];
    if (!pts) {
        for (int i = 0; i < 8; ++i)
            for (int k = 0; k < 3; ++k)
                corners[3 * i + k] = (i >> k) & 1 ? bmax[k] : bmin[k];
        pts = corners, n = 8;
    }
    /* The eye as near as the points allow, never inside the box's bounding sphere, then
     * the target moved so that their image is centred and the eye fitted again: a long
     * character (the Fox, a tail and four legs) fills the tile, where the bounding
     * sphere left it a third of the width. */
    double t[3] = {c[0], c[1], c[2]}, shift[2];
    double dist = fit_distance(pts, n, t, dir, right, vup, tx, ty, 1.05 * r);
    for (int it = 0; it < 4; ++it) { /* the perspective moves the middle as the eye moves */
        image_middle(pts, n, t, dir, right, vup, dist, shift);
        for (int k = 0; k < 3; ++k)
            t[k] += shift[0] * right[k] + shift[1] * vup[k];
        dist = fit_distance(pts, n, t, dir, right, vup, tx, ty, 1.05 * r);
    }
    for (int k = 0; k < 3; ++k) {
        p->eye[k] = t[k] + dist * dir[k];
        p->target[k] = t[k];
    }
    double lo = INFINITY;
    for (int i = 0; i < 8; ++i) {
        double corner[3] = {(i & 1) ? bmax[0] : bmin[0], (i & 2) ? bmax[1] : bmin[1],
                            (i & 4) ? bmax[2] : bmin[2]};
        double h = sw_v3_dot(corner, u);
        if (h < lo) lo = h;
    }
    p->ground_level = lo;
    p->ground_tile = 0.25 * r;
    p->ground_radius = 4.0 * r;
    return SINEW_OK;
}

sinew_result sw_render_frame_camera(sw_render_params *p, const double bmin[3], const double bmax[3],
                                    sw_error *err) {
    return frame(p, bmin, bmax, NULL, 0, err);
}

sinew_result sw_render_frame_points(sw_render_params *p, int32_t npts, const double *X,
                                    sw_error *err) {
    double lo[3], hi[3];
    sinew_result r = sw_render_bbox(npts, X, lo, hi, err);
    return r != SINEW_OK ? r : frame(p, lo, hi, X, npts, err);
}

static sinew_result validate_params(const sw_render_params *p, sw_error *err) {
    if (p->width < 1 || p->height < 1 || p->width > SW_RENDER_MAX_DIM ||
        p->height > SW_RENDER_MAX_DIM)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: image size %d x %d outside 1..%d", p->width, p->height,
                            SW_RENDER_MAX_DIM);
    if (!(p->fov_y_deg > 0 && p->fov_y_deg < 170))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: vertical fov %g outside (0, 170) degrees", p->fov_y_deg);
    if (p->supersample < 1 || p->supersample > 4)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: supersample %d outside 1..4", p->supersample);
    if (p->threads < 0 || p->threads > 64)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: thread count %d outside 0..64", p->threads);
    if (!sw_v3_isfinite(p->eye) || !sw_v3_isfinite(p->target) || !sw_v3_isfinite(p->up) ||
        !sw_v3_isfinite(p->key_dir))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                            "render: camera or light vector is not finite");
    double a[3], b[3], c[3];
    if (!camera_basis(p, a, b, c))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: degenerate camera (eye == target or up parallel to the "
                            "view direction)");
    const double li[3] = {p->key, p->fill, p->ambient};
    for (int k = 0; k < 3; ++k)
        if (!(li[k] >= 0 && li[k] < 1e6))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "render: light intensity %g is negative or not finite", li[k]);
    for (int k = 0; k < 3; ++k)
        if (!(p->background[k] >= 0 && p->background[k] <= 1))
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "render: background component %d = %g outside [0, 1]", k,
                                (double)p->background[k]);
    if (p->ground &&
        !(isfinite(p->ground_level) && p->ground_tile > 0 && isfinite(p->ground_tile) &&
          p->ground_radius > 0 && isfinite(p->ground_radius)))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: ground plane needs a finite level and positive tile "
                            "(%g) and radius (%g)",
                            p->ground_tile, p->ground_radius);
    return SINEW_OK;
}

static sinew_result validate_mesh(int32_t nverts, const double *X, int32_t ntris,
                                  const int32_t *tris, const float *colors, sw_error *err) {
    if (nverts < 0 || ntris < 0 || (nverts > 0 && !X) || (ntris > 0 && !tris))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "render: bad mesh arguments (%d vertices, %d triangles)", nverts,
                            ntris);
    for (int64_t i = 0; i < 3 * (int64_t)nverts; ++i)
        if (!isfinite(X[i]) || fabs(X[i]) > COORD_MAX)
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "render: vertex %lld coordinate %d is %g%s", (long long)(i / 3),
                                (int)(i % 3), X[i], isfinite(X[i]) ? " (too large)" : "");
    for (int64_t i = 0; i < 3 * (int64_t)ntris; ++i)
        if (tris[i] < 0 || tris[i] >= nverts)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "render: triangle %lld references vertex %d of %d",
                                (long long)(i / 3), tris[i], nverts);
    if (colors)
        for (int64_t i = 0; i < 3 * (int64_t)ntris; ++i)
            if (!isfinite(colors[i]))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "render: colour of triangle %lld is not finite",
                                    (long long)(i / 3));
    return SINEW_OK;
}

/* ---- the scene ------------------------------------------------------------------- */

typedef struct {
    const sw_render_params *p;
    const double *X;
    const int32_t *tris;
    const float *colors;
    const float *vnormals; /* 3*nverts or NULL */
    RTCScene scene;        /* NULL when there are no triangles */
    double fwd[3], right[3], cup[3];
    double key_dir[3], fill_dir[3], up[3];
    double tan_half, aspect, eps;
    uint8_t *rgb;
} render_ctx;

typedef struct {
    enum RTCError code;
    char msg[200];
} embree_errors;

static void on_embree_error(void *user, enum RTCError code, const char *str) {
    embree_errors *e = user;
    if (e->code == RTC_ERROR_NONE) {
        e->code = code;
        snprintf(e->msg, sizeof e->msg, "%s", str ? str : "(no message)");
    }
}

/* `code` is what rtcGetDeviceError returned (reading it clears it); the callback's
 * first error is the fallback and supplies the message. */
static sinew_result embree_fail(enum RTCError code, const embree_errors *e, const char *what,
                                sw_error *err) {
    if (code == RTC_ERROR_NONE) code = e->code;
    if (code == RTC_ERROR_NONE) code = RTC_ERROR_UNKNOWN;
    sinew_result rc = code == RTC_ERROR_OUT_OF_MEMORY     ? SINEW_ERROR_OUT_OF_MEMORY
                      : code == RTC_ERROR_UNSUPPORTED_CPU ? SINEW_ERROR_UNSUPPORTED
                                                          : SINEW_ERROR_INVALID_ARGUMENT;
    return sw_error_set(err, rc, "render: Embree %s failed (error %d: %s)", what, (int)code,
                        e->msg[0] ? e->msg : "no message");
}

/* Area-weighted vertex normals (the cross product's length is twice the area). */
static float *vertex_normals(int32_t nverts, const double *X, int32_t ntris, const int32_t *tris) {
    double *acc = calloc((size_t)nverts * 3 + 1, sizeof *acc);
    float *n = malloc(((size_t)nverts * 3 + 1) * sizeof *n);
    if (!acc || !n) {
        free(acc);
        free(n);
        return NULL;
    }
    for (int32_t t = 0; t < ntris; ++t) {
        const int32_t *v = tris + 3 * (int64_t)t;
        const double *a = X + 3 * (int64_t)v[0], *b = X + 3 * (int64_t)v[1],
                     *c = X + 3 * (int64_t)v[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double fn[3];
        sw_v3_cross(e1, e2, fn);
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k)
                acc[3 * (int64_t)v[i] + k] += fn[k];
    }
    for (int32_t v = 0; v < nverts; ++v) {
        sw_v3_normalize(acc + 3 * (int64_t)v);
        for (int k = 0; k < 3; ++k)
            n[3 * (int64_t)v + k] = (float)acc[3 * (int64_t)v + k];
    }
    free(acc);
    return n;
}

static sinew_result build_scene(RTCDevice dev, const embree_errors *e, int32_t nverts,
                                const double *X, int32_t ntris, const int32_t *tris, RTCScene *out,
                                sw_error *err) {
    *out = NULL;
    RTCScene scene = rtcNewScene(dev);
    if (!scene) return embree_fail(rtcGetDeviceError(dev), e, "rtcNewScene", err);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) {
        rtcReleaseScene(scene);
        return embree_fail(rtcGetDeviceError(dev), e, "rtcNewGeometry", err);
    }
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), (size_t)nverts);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), (size_t)ntris);
    if (!vb || !ib) {
        enum RTCError code = rtcGetDeviceError(dev);
        rtcReleaseGeometry(g);
        rtcReleaseScene(scene);
        return embree_fail(code, e, "geometry buffer allocation", err);
    }
    for (int64_t i = 0; i < 3 * (int64_t)nverts; ++i)
        vb[i] = (float)X[i];
    for (int64_t i = 0; i < 3 * (int64_t)ntris; ++i)
        ib[i] = (unsigned)tris[i];
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g); /* the scene holds its own reference */
    rtcCommitScene(scene);
    enum RTCError code = rtcGetDeviceError(dev);
    if (code != RTC_ERROR_NONE || e->code != RTC_ERROR_NONE) {
        sinew_result rc = embree_fail(code, e, "scene build", err);
        rtcReleaseScene(scene);
        return rc;
    }
    *out = scene;
    return SINEW_OK;
}

/* ---- shading --------------------------------------------------------------------- */

static int occluded(const render_ctx *c, const double o[3], const double d[3]) {
    if (!c->scene || !c->p->shadows) return 0;
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    struct RTCRay r;
    memset(&r, 0, sizeof r);
    r.org_x = (float)o[0];
    r.org_y = (float)o[1];
    r.org_z = (float)o[2];
    r.dir_x = (float)d[0];
    r.dir_y = (float)d[1];
    r.dir_z = (float)d[2];
    r.tnear = (float)c->eps;
    r.tfar = INFINITY;
    r.mask = 0xFFFFFFFFu;
    rtcOccluded1(c->scene, &ictx, &r);
    return r.tfar < 0; /* Embree sets tfar to -inf on a hit */
}

/* Lambert with ambient, a shadowed key light and an unshadowed fill; `n` faces the
 * viewer. Returns linear radiance for `albedo`. */
static void lambert(const render_ctx *c, const double pos[3], const double n[3],
                    const double albedo[3], double out[3]) {
    double kd = sw_v3_dot(n, c->key_dir), fd = sw_v3_dot(n, c->fill_dir);
    double light = c->p->ambient + c->p->fill * (fd > 0 ? fd : 0);
    if (kd > 0) {
        double o[3];
        for (int k = 0; k < 3; ++k)
            o[k] = pos[k] + c->eps * n[k];
        if (!occluded(c, o, c->key_dir)) light += c->p->key * kd;
    }
    for (int k = 0; k < 3; ++k)
        out[k] = albedo[k] * light;
}

/* Display encoding (gamma 1/2.2): shading is done in linear light. */
static double encode(double x) {
    return pow(clamp01(x), 1.0 / 2.2);
}

static void shade_surface(const render_ctx *c, const struct RTCRayHit *rh, const double dir[3],
                          double out[3]) {
    const int32_t *v = c->tris + 3 * (int64_t)rh->hit.primID;
    const double *a = c->X + 3 * (int64_t)v[0], *b = c->X + 3 * (int64_t)v[1],
                 *q = c->X + 3 * (int64_t)v[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]};
    double ng[3];
    sw_v3_cross(e1, e2, ng); /* CCW geometric normal, same convention as vertex_normals */
    sw_v3_normalize(ng);
    /* Face the viewer: an inverted or self-intersecting patch seen from its back still
     * gets light instead of a black hole. The smooth normal flips with it. */
    double sgn = sw_v3_dot(ng, dir) > 0 ? -1.0 : 1.0;
    double n[3] = {sgn * ng[0], sgn * ng[1], sgn * ng[2]};
    if (c->vnormals) {
        double u = rh->hit.u, w = rh->hit.v, s[3];
        for (int k = 0; k < 3; ++k)
            s[k] = sgn * ((1 - u - w) * c->vnormals[3 * (int64_t)v[0] + k] +
                          u * c->vnormals[3 * (int64_t)v[1] + k] +
                          w * c->vnormals[3 * (int64_t)v[2] + k]);
        /* Keep the smooth normal only where it agrees with the face. */
        if (sw_v3_normalize(s) > 1e-6 && sw_v3_dot(s, n) > 0) memcpy(n, s, sizeof n);
    }
    double albedo[3] = {0.80, 0.45, 0.36}; /* linear skin tone */
    if (c->colors)
        for (int k = 0; k < 3; ++k)
            albedo[k] = clamp01(c->colors[3 * (int64_t)rh->hit.primID + k]);
    double pos[3];
    double t = rh->ray.tfar;
    for (int k = 0; k < 3; ++k)
        pos[k] = c->p->eye[k] + t * dir[k];
    lambert(c, pos, n, albedo, out);
    for (int k = 0; k < 3; ++k)
        out[k] = encode(out[k]);
}

/* The ground hit at distance t, faded into the background toward ground_radius. */
static void shade_ground(const render_ctx *c, double t, const double dir[3], double out[3]) {
    const sw_render_params *p = c->p;
    double pos[3], n[3], rel[3];
    for (int k = 0; k < 3; ++k)
        pos[k] = p->eye[k] + t * dir[k];
    double sgn = sw_v3_dot(c->up, dir) > 0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k)
        n[k] = sgn * c->up[k];
    /* Checker coordinates along the camera's right and its projection on the plane. */
    double a[3], b[3];
    sw_v3_cross(c->up, c->right, b);
    if (!(sw_v3_normalize(b) > 0)) b[0] = 1, b[1] = b[2] = 0;
    sw_v3_cross(b, c->up, a);
    for (int k = 0; k < 3; ++k)
        rel[k] = pos[k] - p->target[k];
    double x = sw_v3_dot(rel, a) / p->ground_tile, y = sw_v3_dot(rel, b) / p->ground_tile;
    double r = (sw_v3_dot(rel, rel) - sw_v3_dot(rel, c->up) * sw_v3_dot(rel, c->up));
    r = sqrt(r > 0 ? r : 0) / p->ground_radius;
    if (r >= 1) {
        for (int k = 0; k < 3; ++k)
            out[k] = p->background[k];
        return;
    }
    int odd = (int)(((long long)floor(x) + (long long)floor(y)) & 1);
    double g = odd ? 0.30 : 0.50, albedo[3] = {g, g, g};
    lambert(c, pos, n, albedo, out);
    double f = r * r * (3 - 2 * r); /* smoothstep fade */
    for (int k = 0; k < 3; ++k)
        out[k] = (1 - f) * encode(out[k]) + f * p->background[k];
}

/* Encoded colour seen along `dir` from the eye. */
static void trace(const render_ctx *c, const double dir[3], double out[3]) {
    const sw_render_params *p = c->p;
    double t_hit = INFINITY;
    struct RTCRayHit rh;
    if (c->scene) {
        struct RTCIntersectContext ictx;
        rtcInitIntersectContext(&ictx);
        memset(&rh, 0, sizeof rh);
        rh.ray.org_x = (float)p->eye[0];
        rh.ray.org_y = (float)p->eye[1];
        rh.ray.org_z = (float)p->eye[2];
        rh.ray.dir_x = (float)dir[0];
        rh.ray.dir_y = (float)dir[1];
        rh.ray.dir_z = (float)dir[2];
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(c->scene, &ictx, &rh);
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) t_hit = rh.ray.tfar;
    }
    double t_ground = INFINITY;
    if (p->ground) {
        double dn = sw_v3_dot(dir, c->up);
        if (dn != 0) {
            double t = (p->ground_level - sw_v3_dot(p->eye, c->up)) / dn;
            if (t > 0) t_ground = t;
        }
    }
    if (t_hit < INFINITY && t_hit <= t_ground) {
        shade_surface(c, &rh, dir, out);
    } else if (t_ground < INFINITY) {
        shade_ground(c, t_ground, dir, out);
    } else {
        for (int k = 0; k < 3; ++k)
            out[k] = p->background[k];
    }
}

static void render_row(const render_ctx *c, int32_t y) {
    const sw_render_params *p = c->p;
    int ss = p->supersample;
    double inv = 1.0 / (double)(ss * ss);
    for (int32_t x = 0; x < p->width; ++x) {
        double acc[3] = {0, 0, 0};
        for (int sy = 0; sy < ss; ++sy)
            for (int sx = 0; sx < ss; ++sx) {
                double px = x + (sx + 0.5) / ss, py = y + (sy + 0.5) / ss;
                double u = (2.0 * px / p->width - 1.0) * c->tan_half * c->aspect;
                double v = (1.0 - 2.0 * py / p->height) * c->tan_half;
                double dir[3], col[3];
                for (int k = 0; k < 3; ++k)
                    dir[k] = c->fwd[k] + u * c->right[k] + v * c->cup[k];
                sw_v3_normalize(dir);
                trace(c, dir, col);
                for (int k = 0; k < 3; ++k)
                    acc[k] += col[k];
            }
        uint8_t *o = c->rgb + 3 * ((int64_t)y * p->width + x);
        for (int k = 0; k < 3; ++k)
            o[k] = (uint8_t)lrint(255.0 * clamp01(acc[k] * inv));
    }
}

typedef struct {
    const render_ctx *c;
    int32_t first, stride;
} row_job;

static void *row_worker(void *arg) {
    const row_job *j = arg;
    for (int32_t y = j->first; y < j->c->p->height; y += j->stride)
        render_row(j->c, y);
    return NULL;
}

/* Rows are interleaved over threads; each pixel depends on nothing else, so the image
 * is identical for any thread count. A thread that cannot start is done by the caller. */
static void render_rows(const render_ctx *c) {
    int32_t nt = c->p->threads > 1 ? c->p->threads : 1;
    if (nt > c->p->height) nt = c->p->height;
    row_job jobs[64];
    pthread_t tid[64];
    int started[64] = {0};
    if (nt > 64) nt = 64;
    for (int32_t i = 0; i < nt; ++i)
        jobs[i] = (row_job){c, i, nt};
    for (int32_t i = 1; i < nt; ++i)
        started[i] = pthread_create(&tid[i], NULL, row_worker, &jobs[i]) == 0;
    row_worker(&jobs[0]);
    for (int32_t i = 1; i < nt; ++i) {
        if (started[i])
            pthread_join(tid[i], NULL);
        else
            row_worker(&jobs[i]);
    }
}

static void setup_lights(render_ctx *c) {
    const sw_render_params *p = c->p;
    memcpy(c->up, p->up, sizeof c->up);
    sw_v3_normalize(c->up);
    memcpy(c->key_dir, p->key_dir, sizeof c->key_dir);
    if (!(sw_v3_normalize(c->key_dir) > 0))
        for (int k = 0; k < 3; ++k) /* upper left, a little in front of the subject */
            c->key_dir[k] = -0.6 * c->right[k] + 0.7 * c->cup[k] - 0.45 * c->fwd[k];
    sw_v3_normalize(c->key_dir);
    for (int k = 0; k < 3; ++k)
        c->fill_dir[k] = 0.7 * c->right[k] - 0.2 * c->cup[k] - 0.6 * c->fwd[k];
    sw_v3_normalize(c->fill_dir);
}

sinew_result sw_render_surface(const sw_render_params *p, int32_t nverts, const double *X,
                               int32_t ntris, const int32_t *tris, const float *tri_colors,
                               uint8_t *rgb_out, sw_error *err) {
    if (!p || !rgb_out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "render: NULL %s",
                            p ? "output image" : "parameters");
    sinew_result rc = validate_params(p, err);
    if (!rc) rc = validate_mesh(nverts, X, ntris, tris, tri_colors, err);
    if (rc) return rc;

    render_ctx c;
    memset(&c, 0, sizeof c);
    c.p = p;
    c.X = X;
    c.tris = tris;
    c.colors = tri_colors;
    c.rgb = rgb_out;
    camera_basis(p, c.fwd, c.right, c.cup);
    setup_lights(&c);
    c.tan_half = tan(0.5 * p->fov_y_deg * PI / 180.0);
    c.aspect = (double)p->width / (double)p->height;
    /* Shadow-ray offset: relative to the scene size so float round-off of the hit
     * point cannot make a surface shadow itself. */
    double scale = sw_v3_norm(p->eye) + sw_v3_norm(p->target);
    if (nverts > 0) {
        double bmin[3], bmax[3], d[3];
        sw_render_bbox(nverts, X, bmin, bmax, NULL);
        for (int k = 0; k < 3; ++k)
            d[k] = bmax[k] - bmin[k];
        scale += sw_v3_norm(d) + sw_v3_norm(bmin) + sw_v3_norm(bmax);
    }
    c.eps = 2e-5 * (scale > 0 ? scale : 1.0);

    float *vn = NULL;
    if (ntris > 0 && p->smooth) {
        vn = vertex_normals(nverts, X, ntris, tris);
        if (!vn)
            return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                                "render: out of memory for %d vertex normals", nverts);
        c.vnormals = vn;
    }

    RTCDevice dev = NULL;
    embree_errors ee;
    memset(&ee, 0, sizeof ee);
    if (ntris > 0) {
        /* One build thread: no spinning TBB workers left behind (STYLE.md §6). */
        dev = rtcNewDevice("threads=1");
        if (!dev) {
            free(vn);
            return embree_fail(rtcGetDeviceError(NULL), &ee, "rtcNewDevice", err);
        }
        rtcSetDeviceErrorFunction(dev, on_embree_error, &ee);
        rc = build_scene(dev, &ee, nverts, X, ntris, tris, &c.scene, err);
    }
    if (!rc) {
        render_rows(&c);
        enum RTCError code = dev ? rtcGetDeviceError(dev) : RTC_ERROR_NONE;
        if (code != RTC_ERROR_NONE || ee.code != RTC_ERROR_NONE)
            rc = embree_fail(code, &ee, "ray query", err);
    }
    if (c.scene) rtcReleaseScene(c.scene);
    if (dev) rtcReleaseDevice(dev);
    free(vn);
    return rc;
}
