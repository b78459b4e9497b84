/* The PNG writer (parsed back with an independent reader: chunk CRCs, stored-block
 * inflate, Adler-32, scanlines) and the Embree renderer (an icosphere's projected disc,
 * lighting direction, shadows, viewer-facing normals, thread independence, framing,
 * input validation). */
#include <stdint.h>
#include <sys/stat.h>
#include <time.h>

#include "png_write.h"
#include "render.h"
#include "sw_test.h"

#ifndef SINEW_BINARY_DIR
#define SINEW_BINARY_DIR "."
#endif

/* ---- an independent PNG reader (only what sw_write_png may produce) --------------- */

/* Bit-at-a-time CRC-32, deliberately unlike the writer's table version. */
static uint32_t crc_bitwise(const uint8_t *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

static uint32_t adler_slow(const uint8_t *p, size_t n) {
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < n; ++i) {
        a = (a + p[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    return (b << 16) | a;
}

static uint32_t be32(const uint8_t *p) {
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

static uint8_t *slurp(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *buf = malloc(len > 0 ? (size_t)len : 1);
    if (buf && fread(buf, 1, (size_t)len, f) != (size_t)len) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *n = (size_t)len;
    return buf;
}

typedef struct {
    uint32_t w, h;
    int idat_chunks;
    int stored_blocks;
    uint8_t *raw; /* filtered scanlines */
    size_t raw_len;
} png_info;

/* Returns NULL on success or a description of the first defect. */
static const char *parse_png(const uint8_t *f, size_t n, png_info *info) {
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    memset(info, 0, sizeof *info);
    if (n < 8 || memcmp(f, sig, 8)) return "bad signature";
    size_t pos = 8, zlen = 0;
    uint8_t *z = malloc(n);
    int seen_ihdr = 0, seen_iend = 0;
    while (pos < n) {
        if (n - pos < 12) return free(z), "truncated chunk header";
        uint32_t len = be32(f + pos);
        if (len > n - pos - 12) return free(z), "chunk length past end of file";
        const uint8_t *type = f + pos + 4, *data = f + pos + 8;
        if (crc_bitwise(type, 4 + (size_t)len) != be32(data + len)) return free(z), "bad CRC";
        if (!memcmp(type, "IHDR", 4)) {
            if (seen_ihdr || pos != 8 || len != 13) return free(z), "IHDR misplaced";
            info->w = be32(data);
            info->h = be32(data + 4);
            if (data[8] != 8 || data[9] != 2 || data[10] || data[11] || data[12])
                return free(z), "IHDR not 8-bit RGB deflate/filter0/no interlace";
            seen_ihdr = 1;
        } else if (!memcmp(type, "IDAT", 4)) {
            memcpy(z + zlen, data, len);
            zlen += len;
            info->idat_chunks++;
        } else if (!memcmp(type, "IEND", 4)) {
            if (len) return free(z), "IEND with data";
            seen_iend = 1;
            pos += 12;
            break;
        } else {
            return free(z), "unexpected chunk";
        }
        pos += 12 + (size_t)len;
    }
    if (!seen_ihdr || !seen_iend || pos != n) return free(z), "missing IHDR/IEND or trailing bytes";
    /* zlib header (RFC 1950): CM 8, no preset dictionary, check bits. */
    if (zlen < 6 || (z[0] & 15) != 8 || (z[1] & 0x20) || ((z[0] << 8) | z[1]) % 31)
        return free(z), "bad zlib header";
    size_t zp = 2, cap = zlen, out = 0;
    uint8_t *raw = malloc(cap);
    for (;;) {
        if (zp + 5 > zlen) return free(z), free(raw), "truncated stored block";
        uint8_t hdr = z[zp];
        if ((hdr >> 1) & 3) return free(z), free(raw), "not a stored block";
        unsigned len = z[zp + 1] | (z[zp + 2] << 8), nlen = z[zp + 3] | (z[zp + 4] << 8);
        if ((len ^ 0xFFFFu) != nlen) return free(z), free(raw), "LEN/NLEN mismatch";
        zp += 5;
        if (zp + len > zlen) return free(z), free(raw), "stored block past end";
        memcpy(raw + out, z + zp, len);
        out += len;
        zp += len;
        info->stored_blocks++;
        if (hdr & 1) break;
    }
    if (zp + 4 != zlen) return free(z), free(raw), "bytes after the Adler-32";
    if (be32(z + zp) != adler_slow(raw, out)) return free(z), free(raw), "bad Adler-32";
    free(z);
    info->raw = raw;
    info->raw_len = out;
    return NULL;
}

static void check_png_round_trip(int w, int h, uint32_t seed, int *min_idat, int *min_blocks) {
    uint8_t *rgb = malloc((size_t)w * h * 3);
    for (size_t i = 0; i < (size_t)w * h * 3; ++i) {
        seed = seed * 1664525u + 1013904223u;
        rgb[i] = (uint8_t)(seed >> 24);
    }
    char path[512];
    snprintf(path, sizeof path, "%s/test_render_rt_%dx%d.png", SINEW_BINARY_DIR, w, h);
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_write_png(path, w, h, rgb, &err);
    size_t n = 0;
    uint8_t *file = rc ? NULL : slurp(path, &n);
    png_info info;
    const char *why = file ? parse_png(file, n, &info) : "not written";
    int ok = !why && info.w == (uint32_t)w && info.h == (uint32_t)h &&
             info.raw_len == (size_t)h * (1 + 3 * (size_t)w);
    for (int y = 0; ok && y < h; ++y) {
        const uint8_t *line = info.raw + (size_t)y * (1 + 3 * (size_t)w);
        ok = line[0] == 0 && !memcmp(line + 1, rgb + (size_t)y * 3 * w, 3 * (size_t)w);
    }
    *min_idat = why ? 0 : info.idat_chunks;
    *min_blocks = why ? 0 : info.stored_blocks;
    free(file);
    if (!why) free(info.raw);
    free(rgb);
    remove(path);
    if (rc) fprintf(stderr, "  write: %s\n", err.msg);
    if (why) fprintf(stderr, "  parse: %s\n", why);
    if (!ok) *min_idat = -1;
}

TEST(checksums_known_vectors) {
    const uint8_t *s = (const uint8_t *)"123456789";
    ENSURE(sw_crc32(0, s, 9) == 0xCBF43926u);
    ENSURE(crc_bitwise(s, 9) == 0xCBF43926u);
    /* Continuation: two halves equal the whole. */
    ENSURE(sw_crc32(sw_crc32(0, s, 4), s + 4, 5) == 0xCBF43926u);
    ENSURE(sw_adler32(1, (const uint8_t *)"Wikipedia", 9) == 0x11E60398u);
    /* Long run of 0xFF: exercises the deferred modulo. */
    static uint8_t big[100000];
    memset(big, 0xFF, sizeof big);
    ENSURE(sw_adler32(1, big, sizeof big) == adler_slow(big, sizeof big));
    ENSURE(sw_adler32(sw_adler32(1, big, 777), big + 777, sizeof big - 777) ==
           adler_slow(big, sizeof big));
}

TEST(png_round_trip_small) {
    int idat, blocks;
    check_png_round_trip(7, 5, 1u, &idat, &blocks);
    ENSUREF(idat == 1 && blocks == 1, "idat %d blocks %d", idat, blocks);
    check_png_round_trip(1, 1, 2u, &idat, &blocks);
    ENSUREF(idat == 1 && blocks == 1, "idat %d blocks %d", idat, blocks);
}

TEST(png_round_trip_many_blocks_and_chunks) {
    int idat, blocks;
    /* 700 x 520: 1.09 MB of scanlines -> 17 stored blocks over 2 IDAT chunks, with
     * scanlines straddling block boundaries. */
    check_png_round_trip(700, 520, 3u, &idat, &blocks);
    ENSUREF(idat == 2 && blocks == 17, "idat %d blocks %d", idat, blocks);
    /* Exactly one full block: 65535 = 771 rows of 1 + 3*28 = 85 bytes; one row more
     * spills into a second block. */
    check_png_round_trip(28, 771, 4u, &idat, &blocks);
    ENSUREF(idat == 1 && blocks == 1, "idat %d blocks %d", idat, blocks);
    check_png_round_trip(28, 772, 5u, &idat, &blocks);
    ENSUREF(idat == 1 && blocks == 2, "idat %d blocks %d", idat, blocks);
}

TEST(png_errors) {
    uint8_t px[12] = {0};
    sw_error err;
    sw_error_clear(&err);
    ENSURE(sw_write_png(SINEW_BINARY_DIR "/x.png", 0, 4, px, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "0 x 4"));
    ENSURE(sw_write_png(SINEW_BINARY_DIR "/x.png", 2, 2, NULL, &err) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_write_png(NULL, 2, 2, px, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sw_write_png(SINEW_BINARY_DIR "/x.png", SW_PNG_MAX_DIM + 1, 1, px, &err) ==
           SINEW_ERROR_INVALID_ARGUMENT);
    const char *bad = SINEW_BINARY_DIR "/no_such_dir_for_render/x.png";
    ENSURE(sw_write_png(bad, 2, 2, px, &err) == SINEW_ERROR_IO);
    ENSURE(strstr(err.msg, "no_such_dir_for_render"));
    /* Atomic: a failed rename (target is a directory) leaves neither file nor temp. */
    const char *dir = SINEW_BINARY_DIR "/test_render_dir";
    mkdir(dir, 0755);
    ENSURE(sw_write_png(dir, 2, 2, px, &err) == SINEW_ERROR_IO);
    FILE *f = fopen(SINEW_BINARY_DIR "/test_render_dir.tmp", "rb");
    if (f) fclose(f);
    ENSURE(f == NULL);
}

/* ---- an icosphere ----------------------------------------------------------------- */

typedef struct {
    int32_t nv, nt;
    double *X;
    int32_t *T;
} mesh;

static int32_t midpoint(mesh *m, int64_t *keys, int32_t *vals, size_t cap, int32_t a, int32_t b) {
    int64_t key = a < b ? (int64_t)a * 1000003 + b : (int64_t)b * 1000003 + a;
    size_t h = (size_t)(key * 2654435761u) % cap;
    while (keys[h] >= 0 && keys[h] != key)
        h = (h + 1) % cap;
    if (keys[h] == key) return vals[h];
    double *p = m->X + 3 * m->nv;
    for (int k = 0; k < 3; ++k)
        p[k] = 0.5 * (m->X[3 * a + k] + m->X[3 * b + k]);
    double n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; ++k)
        p[k] /= n;
    keys[h] = key;
    vals[h] = m->nv;
    return m->nv++;
}

/* Unit icosphere, CCW outward, 20 * 4^level triangles. */
static mesh icosphere(int level) {
    static const int32_t F[60] = {0, 11, 5, 0, 5,  1,  0,  1,  7,  0,  7, 10, 0, 10, 11,
                                  1, 5,  9, 5, 11, 4,  11, 10, 2,  10, 7, 6,  7, 1,  8,
                                  3, 9,  4, 3, 4,  2,  3,  2,  6,  3,  6, 8,  3, 8,  9,
                                  4, 9,  5, 2, 4,  11, 6,  2,  10, 8,  6, 7,  9, 8,  1};
    double t = (1 + sqrt(5.0)) / 2;
    double V[36] = {-1, t,  0,  1, t, 0,  -1, -t, 0,  1, -t, 0, 0,  -1, t,  0,  1, t,
                    0,  -1, -t, 0, 1, -t, t,  0,  -1, t, 0,  1, -t, 0,  -1, -t, 0, 1};
    int32_t nt = 20;
    for (int l = 0; l < level; ++l)
        nt *= 4;
    mesh m = {12, 20, malloc(sizeof(double) * 3 * (size_t)(nt / 2 + 2)),
              malloc(sizeof(int32_t) * 3 * (size_t)nt)};
    for (int i = 0; i < 12; ++i) {
        double n =
            sqrt(V[3 * i] * V[3 * i] + V[3 * i + 1] * V[3 * i + 1] + V[3 * i + 2] * V[3 * i + 2]);
        for (int k = 0; k < 3; ++k)
            m.X[3 * i + k] = V[3 * i + k] / n;
    }
    memcpy(m.T, F, sizeof F);
    for (int l = 0; l < level; ++l) {
        size_t cap = (size_t)m.nt * 4 + 7;
        int64_t *keys = malloc(cap * sizeof *keys);
        int32_t *vals = malloc(cap * sizeof *vals);
        int32_t *T2 = malloc(sizeof(int32_t) * 12 * (size_t)m.nt);
        for (size_t i = 0; i < cap; ++i)
            keys[i] = -1;
        for (int32_t f = 0; f < m.nt; ++f) {
            int32_t a = m.T[3 * f], b = m.T[3 * f + 1], c = m.T[3 * f + 2];
            int32_t ab = midpoint(&m, keys, vals, cap, a, b);
            int32_t bc = midpoint(&m, keys, vals, cap, b, c);
            int32_t ca = midpoint(&m, keys, vals, cap, c, a);
            int32_t q[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
            memcpy(T2 + 12 * f, q, sizeof q);
        }
        free(keys);
        free(vals);
        free(m.T);
        m.T = T2;
        m.nt *= 4;
    }
    return m;
}

static void mesh_free(mesh *m) {
    free(m->X);
    free(m->T);
}

static double signed_volume(const mesh *m) {
    double v = 0;
    for (int32_t f = 0; f < m->nt; ++f) {
        const double *a = m->X + 3 * m->T[3 * f], *b = m->X + 3 * m->T[3 * f + 1],
                     *c = m->X + 3 * m->T[3 * f + 2];
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) /
             6.0;
    }
    return v;
}

/* ---- image helpers ----------------------------------------------------------------- */

static int is_background(const sw_render_params *p, const uint8_t *px) {
    for (int k = 0; k < 3; ++k)
        if (px[k] != (uint8_t)lrint(255.0 * p->background[k])) return 0;
    return 1;
}

/* Where world point q lands under the renderer's pinhole model (pixels from the top
 * left, not rounded). */
static void pixel_of(const sw_render_params *p, const double q[3], double px[2]) {
    double f[3], r[3], u[3], d[3];
    for (int k = 0; k < 3; ++k)
        f[k] = p->target[k] - p->eye[k], d[k] = q[k] - p->eye[k];
    double n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; ++k)
        f[k] /= n;
    r[0] = f[1] * p->up[2] - f[2] * p->up[1];
    r[1] = f[2] * p->up[0] - f[0] * p->up[2];
    r[2] = f[0] * p->up[1] - f[1] * p->up[0];
    n = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; ++k)
        r[k] /= n;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    double z = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    double x = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / z;
    double y = (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]) / z;
    double th = tan(0.5 * p->fov_y_deg * 3.14159265358979323846 / 180.0);
    double aspect = (double)p->width / p->height;
    px[0] = (x / (th * aspect) + 1) * 0.5 * p->width;
    px[1] = (1 - y / th) * 0.5 * p->height;
}

/* The pixel of world point q (for the shadow test). */
static void project(const sw_render_params *p, const double q[3], int *px, int *py) {
    double xy[2];
    pixel_of(p, q, xy);
    *px = (int)floor(xy[0]);
    *py = (int)floor(xy[1]);
}

static double luma(const uint8_t *px) {
    return 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
}

/* ---- renderer tests ---------------------------------------------------------------- */

TEST(icosphere_is_closed_and_outward) {
    mesh m = icosphere(3);
    double v = signed_volume(&m);
    int32_t nv = m.nv, nt = m.nt;
    mesh_free(&m);
    ENSURE(nt == 1280 && nv == 642); /* Euler: V = T/2 + 2 */
    ENSURE_NEAR(v, 4.0 / 3.0 * 3.14159265358979323846, 0.05);
}

TEST(sphere_disc_centre_corners_area) {
    mesh m = icosphere(4);
    sw_render_params p = sw_render_params_default(320, 240);
    p.supersample = 1; /* pixel centres only: lit iff the centre ray hits the sphere */
    uint8_t *img = malloc(320 * 240 * 3);
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    mesh_free(&m);
    if (rc) free(img);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    int centre_lit = !is_background(&p, img + 3 * (120 * 320 + 160));
    int corners_bg = is_background(&p, img) && is_background(&p, img + 3 * 319) &&
                     is_background(&p, img + 3 * (239 * 320)) &&
                     is_background(&p, img + 3 * (239 * 320 + 319));
    long lit = 0;
    for (int i = 0; i < 320 * 240; ++i)
        lit += !is_background(&p, img + 3 * i);
    char path[512];
    snprintf(path, sizeof path, "%s/test_render_sphere.png", SINEW_BINARY_DIR);
    rc = sw_write_png(path, 320, 240, img, &err);
    free(img);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(centre_lit);
    ENSURE(corners_bg);
    /* Silhouette of a unit sphere at distance 5: a cone of half-angle asin(1/5); on the
     * image its radius is tan(asin(0.2)) / tan(fov/2) * h/2 pixels. */
    double rpx = tan(asin(0.2)) / tan(17.5 * 3.14159265358979323846 / 180.0) * 120.0;
    double disc = 3.14159265358979323846 * rpx * rpx;
    ENSUREF(fabs(lit - disc) < 0.04 * disc, "lit %ld pixels, disc %.0f", lit, disc);
}

/* Mean luma of the lit pixels left and right of the centre column, key light toward
 * world x = side (the camera looks down -Z, so -X is the image's left). */
static sinew_result side_means(double side, double means[2], sw_error *err) {
    mesh m = icosphere(4);
    sw_render_params p = sw_render_params_default(160, 120);
    p.key_dir[0] = side;
    uint8_t *img = malloc(160 * 120 * 3);
    sinew_result rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, err);
    mesh_free(&m);
    double sum[2] = {0, 0};
    long cnt[2] = {0, 0};
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 160; ++x) {
            const uint8_t *px = img + 3 * (y * 160 + x);
            if (x == 80 || is_background(&p, px)) continue;
            sum[x > 80] += luma(px);
            cnt[x > 80]++;
        }
    free(img);
    if (!rc && (cnt[0] < 500 || cnt[1] < 500))
        rc =
            sw_error_set(err, SINEW_ERROR_DEGENERATE, "too few lit pixels %ld %ld", cnt[0], cnt[1]);
    means[0] = cnt[0] ? sum[0] / cnt[0] : 0;
    means[1] = cnt[1] ? sum[1] / cnt[1] : 0;
    return rc;
}

TEST(key_light_side_is_brighter) {
    double l[2], r[2];
    sw_error err;
    sinew_result rc = side_means(-1.0, l, &err);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    rc = side_means(+1.0, r, &err);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    /* The default fill comes from the right, so the two cases are not mirror images;
     * the key still dominates either way. */
    ENSUREF(l[0] > 1.15 * l[1], "key left: left mean %.1f, right mean %.1f", l[0], l[1]);
    ENSUREF(r[1] > 1.15 * r[0], "key right: left mean %.1f, right mean %.1f", r[0], r[1]);
}

TEST(ground_shadow_under_sphere) {
    mesh m = icosphere(3);
    sw_render_params p = sw_render_params_default(200, 150);
    double eye[3] = {0, 1.5, 6}, target[3] = {0, -0.5, 0}, key[3] = {0, 1, 0};
    memcpy(p.eye, eye, sizeof eye);
    memcpy(p.target, target, sizeof target);
    memcpy(p.key_dir, key, sizeof key);
    p.ground = 1;
    p.ground_level = -1.0;
    p.ground_tile = 0.5;
    p.ground_radius = 10.0;
    uint8_t *with = malloc(200 * 150 * 3), *without = malloc(200 * 150 * 3);
    sw_error err;
    sinew_result rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, with, &err);
    p.shadows = 0;
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, without, &err);
    mesh_free(&m);
    const double under[3] = {0, -1, 0.8}, away[3] = {1.8, -1, 0.8};
    int ux, uy, ax, ay;
    project(&p, under, &ux, &uy);
    project(&p, away, &ax, &ay);
    int inside =
        ux > 0 && ux < 199 && uy > 0 && uy < 149 && ax > 0 && ax < 199 && ay > 0 && ay < 149;
    double lu_with = inside ? luma(with + 3 * (uy * 200 + ux)) : 0;
    double lu_without = inside ? luma(without + 3 * (uy * 200 + ux)) : 0;
    int away_same = inside && !memcmp(with + 3 * (ay * 200 + ax), without + 3 * (ay * 200 + ax), 3);
    int away_ground = inside && !is_background(&p, with + 3 * (ay * 200 + ax));
    free(with);
    free(without);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSUREF(inside, "probe pixels (%d,%d) (%d,%d)", ux, uy, ax, ay);
    ENSUREF(lu_with < 0.7 * lu_without, "shadowed %.1f, unshadowed %.1f", lu_with, lu_without);
    ENSURE(away_same);
    ENSURE(away_ground);
}

TEST(flipped_winding_renders_the_same) {
    /* Normals are turned toward the viewer, so an inside-out surface (what an inverted
     * region looks like) shades exactly like the outward one. */
    mesh m = icosphere(3);
    sw_render_params p = sw_render_params_default(120, 90);
    uint8_t *a = malloc(120 * 90 * 3), *b = malloc(120 * 90 * 3);
    sw_error err;
    sinew_result rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, a, &err);
    for (int32_t f = 0; f < m.nt; ++f) {
        int32_t t = m.T[3 * f + 1];
        m.T[3 * f + 1] = m.T[3 * f + 2];
        m.T[3 * f + 2] = t;
    }
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, b, &err);
    mesh_free(&m);
    long differ = 0, lit = 0;
    for (int i = 0; i < 120 * 90 * 3; ++i)
        differ += abs((int)a[i] - (int)b[i]) > 1;
    for (int i = 0; i < 120 * 90; ++i)
        lit += !is_background(&p, a + 3 * i);
    free(a);
    free(b);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(lit > 1000);
    ENSUREF(differ == 0, "%ld channels differ", differ);
}

TEST(threads_and_colours) {
    mesh m = icosphere(3);
    sw_render_params p = sw_render_params_default(100, 80);
    p.ground = 1;
    p.ground_level = -1;
    uint8_t *a = malloc(100 * 80 * 3), *b = malloc(100 * 80 * 3);
    float *col = malloc(sizeof(float) * 3 * (size_t)m.nt);
    for (int32_t f = 0; f < m.nt; ++f)
        col[3 * f] = 0.1f, col[3 * f + 1] = 0.2f, col[3 * f + 2] = 0.9f;
    sw_error err;
    p.threads = 1;
    sinew_result rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, col, a, &err);
    p.threads = 3;
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, col, b, &err);
    mesh_free(&m);
    free(col);
    int same = !memcmp(a, b, 100 * 80 * 3);
    const uint8_t *c = a + 3 * (40 * 100 + 50);
    int blue = c[2] > c[0] + 40 && c[2] > c[1] + 20;
    free(a);
    free(b);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(same);
    ENSURE(blue);
}

/* The lit pixels' bounding rectangle (x0, y0, x1, y1) of an image rendered with p, and
 * whether the border is background everywhere. */
static long lit_rect(const sw_render_params *p, const uint8_t *img, int w, int h, int rect[4],
                     int *border_bg) {
    long lit = 0;
    rect[0] = w, rect[1] = h, rect[2] = -1, rect[3] = -1;
    *border_bg = 1;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (is_background(p, img + 3 * (y * w + x))) continue;
            lit++;
            if (x == 0 || y == 0 || x == w - 1 || y == h - 1) *border_bg = 0;
            rect[0] = x < rect[0] ? x : rect[0], rect[1] = y < rect[1] ? y : rect[1];
            rect[2] = x > rect[2] ? x : rect[2], rect[3] = y > rect[3] ? y : rect[3];
        }
    return lit;
}

/* The box's corners fit the image with the 5% margin and reach it, their image centred;
 * a sphere in it is drawn whole within their image. */
TEST(frame_camera_fits_an_offset_box) {
    mesh m = icosphere(3);
    for (int32_t v = 0; v < m.nv; ++v) {
        m.X[3 * v] = 2 * m.X[3 * v] + 10;
        m.X[3 * v + 1] = 2 * m.X[3 * v + 1] + 5;
        m.X[3 * v + 2] = 2 * m.X[3 * v + 2] - 3;
    }
    sw_render_params p = sw_render_params_default(160, 90);
    double bmin[3], bmax[3];
    sw_error err;
    sinew_result rc = sw_render_bbox(m.nv, m.X, bmin, bmax, &err);
    if (!rc) rc = sw_render_frame_camera(&p, bmin, bmax, &err);
    uint8_t *img = malloc(160 * 90 * 3);
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    mesh_free(&m);
    int rect[4], border_bg;
    long lit = lit_rect(&p, img, 160, 90, rect, &border_bg);
    free(img);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(border_bg);
    /* the corners' image: within 2.5% of the border on each side at most, and touching
       it on one axis */
    double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30};
    for (int i = 0; i < 8; ++i) {
        double c[3], px[2];
        for (int k = 0; k < 3; ++k)
            c[k] = (i >> k) & 1 ? bmax[k] : bmin[k];
        pixel_of(&p, c, px);
        for (int a = 0; a < 2; ++a)
            lo[a] = fmin(lo[a], px[a]), hi[a] = fmax(hi[a], px[a]);
    }
    ENSUREF(lo[0] >= 0.025 * 160 - 1e-6 && hi[0] <= 0.975 * 160 + 1e-6 &&
                lo[1] >= 0.025 * 90 - 1e-6 && hi[1] <= 0.975 * 90 + 1e-6,
            "corners over [%g, %g] x [%g, %g]", lo[0], hi[0], lo[1], hi[1]);
    ENSUREF(fmin(fmin(lo[0], 160 - hi[0]) - 4, fmin(lo[1], 90 - hi[1]) - 2.25) < 0.25,
            "corners over [%g, %g] x [%g, %g]: not fitted", lo[0], hi[0], lo[1], hi[1]);
    ENSURE_NEAR(0.5 * (lo[0] + hi[0]), 80, 1.0); /* centred, within the depth's tilt */
    ENSURE_NEAR(0.5 * (lo[1] + hi[1]), 45, 1.0);
    /* the sphere (radius 2 in a box of side 4) drawn whole, within the corners' image */
    ENSUREF(lit > 1500 && rect[3] - rect[1] > 40, "lit %ld, %d rows", lit, rect[3] - rect[1]);
    ENSUREF(rect[0] >= lo[0] - 1 && rect[2] <= hi[0] + 1 && rect[1] >= lo[1] - 1 &&
                rect[3] <= hi[1] + 1,
            "sphere over [%d, %d] x [%d, %d]", rect[0], rect[2], rect[1], rect[3]);
    ENSURE_NEAR(p.ground_level, 3.0, 1e-12); /* lowest y of the box */
    sw_render_params q = sw_render_params_default(10, 10);
    double nan_box[3] = {NAN, 0, 0};
    ENSURE(sw_render_frame_camera(&q, nan_box, bmax, &err) == SINEW_ERROR_NOT_FINITE);
    ENSURE(sw_render_frame_camera(&q, bmax, bmin, &err) == SINEW_ERROR_INVALID_ARGUMENT);
}

/* Framed by its own points, a long thin body (a sphere stretched 8 times along x, turned
 * by the 3/4 view) fills the image along one axis and sits in its middle; framed by its
 * box's corners it is drawn smaller. A point that is not finite is refused. */
TEST(frame_points_fills_the_image_with_a_long_body) {
    mesh m = icosphere(3);
    for (int32_t v = 0; v < m.nv; ++v) {
        m.X[3 * v] = 8 * m.X[3 * v] + 3;
        m.X[3 * v + 2] -= 2;
    }
    sw_render_params p = sw_render_params_default(160, 90), q = p;
    double bmin[3], bmax[3];
    sw_error err;
    sinew_result rc = sw_render_frame_points(&p, m.nv, m.X, &err);
    if (!rc) rc = sw_render_bbox(m.nv, m.X, bmin, bmax, &err);
    if (!rc) rc = sw_render_frame_camera(&q, bmin, bmax, &err);
    uint8_t *img = malloc(160 * 90 * 3), *imq = malloc(160 * 90 * 3);
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    if (!rc) rc = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, imq, &err);
    int rect[4], rq[4], border_bg, border_q;
    long lit = lit_rect(&p, img, 160, 90, rect, &border_bg);
    long lit_box = lit_rect(&q, imq, 160, 90, rq, &border_q);
    free(img);
    free(imq);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(border_bg && border_q);
    int wide = rect[2] - rect[0] + 1, tall = rect[3] - rect[1] + 1;
    ENSUREF(wide >= 0.9 * 160 || tall >= 0.9 * 90, "%d x %d pixels lit of 160 x 90", wide, tall);
    ENSUREF(abs(rect[0] + rect[2] - 159) <= 3 && abs(rect[1] + rect[3] - 89) <= 3,
            "lit over [%d, %d] x [%d, %d]", rect[0], rect[2], rect[1], rect[3]);
    ENSUREF(lit > 1.1 * lit_box, "lit %ld framed by the points, %ld by the box", lit, lit_box);
    m.X[3 * 11 + 2] = INFINITY;
    ENSURE(sw_render_frame_points(&p, m.nv, m.X, &err) == SINEW_ERROR_NOT_FINITE);
    mesh_free(&m);
}

TEST(render_input_errors) {
    mesh m = icosphere(1);
    sw_render_params p = sw_render_params_default(32, 24);
    uint8_t img[32 * 24 * 3];
    sw_error err;
    sw_error_clear(&err);
    sinew_result rc_ok = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);

    m.X[3 * 7 + 1] = NAN;
    sinew_result rc_nan = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    int nan_msg = strstr(err.msg, "vertex 7") != NULL;
    m.X[3 * 7 + 1] = 1e38; /* finite but beyond float precision */
    sinew_result rc_big = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    m.X[3 * 7 + 1] = 0.5;

    int32_t saved = m.T[3 * 5 + 2];
    m.T[3 * 5 + 2] = m.nv;
    sinew_result rc_idx = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    int idx_msg = strstr(err.msg, "triangle 5") != NULL;
    m.T[3 * 5 + 2] = -1;
    sinew_result rc_neg = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    m.T[3 * 5 + 2] = saved;

    float col[3 * 80];
    for (int i = 0; i < 3 * 80; ++i)
        col[i] = 0.5f;
    col[3 * 9] = NAN;
    sinew_result rc_col = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, col, img, &err);

    sw_render_params q = p;
    q.width = 0;
    sinew_result rc_w0 = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    q.height = SW_RENDER_MAX_DIM + 1;
    sinew_result rc_hbig = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    memcpy(q.target, q.eye, sizeof q.eye);
    sinew_result rc_cam = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    q.up[0] = 0, q.up[1] = 0, q.up[2] = 1; /* parallel to the view direction */
    sinew_result rc_up = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    q.supersample = 0;
    sinew_result rc_ss = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    q.fov_y_deg = 180;
    sinew_result rc_fov = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    q = p;
    q.ground = 1;
    q.ground_tile = 0;
    sinew_result rc_tile = sw_render_surface(&q, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    sinew_result rc_null = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, NULL, &err);
    sinew_result rc_negn = sw_render_surface(&p, -1, m.X, m.nt, m.T, NULL, img, &err);
    /* An empty surface is legal: background only. */
    sinew_result rc_empty = sw_render_surface(&p, 0, NULL, 0, NULL, NULL, img, &err);
    int all_bg = 1;
    for (int i = 0; i < 32 * 24; ++i)
        all_bg &= is_background(&p, img + 3 * i);
    mesh_free(&m);

    ENSURE(rc_ok == SINEW_OK);
    ENSURE(rc_nan == SINEW_ERROR_NOT_FINITE && nan_msg);
    ENSURE(rc_big == SINEW_ERROR_NOT_FINITE);
    ENSURE(rc_idx == SINEW_ERROR_INVALID_ARGUMENT && idx_msg);
    ENSURE(rc_neg == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_col == SINEW_ERROR_NOT_FINITE);
    ENSURE(rc_w0 == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_hbig == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_cam == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_up == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_ss == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_fov == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_tile == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_null == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_negn == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(rc_empty == SINEW_OK && all_bg);
}

TEST(timing_20k_triangles_640x480) {
    mesh m = icosphere(5); /* 20480 triangles */
    sw_render_params p = sw_render_params_default(640, 480);
    double bmin[3], bmax[3];
    sw_error err;
    sinew_result rc = sw_render_bbox(m.nv, m.X, bmin, bmax, &err);
    if (!rc) rc = sw_render_frame_camera(&p, bmin, bmax, &err);
    p.ground = 1;
    uint8_t *img = malloc(640 * 480 * 3);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (!rc) rc = sw_render_surface(&p, m.nv, m.X, m.nt, m.T, NULL, img, &err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double ms = 1e3 * (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_nsec - t0.tv_nsec);
    fprintf(stderr, "  %d triangles, 640x480, 2x2 supersampling, 1 thread: %.1f ms\n", m.nt, ms);
    mesh_free(&m);
    char path[512];
    snprintf(path, sizeof path, "%s/test_render_20k.png", SINEW_BINARY_DIR);
    if (!rc) rc = sw_write_png(path, 640, 480, img, &err);
    long lit = 0;
    for (int i = 0; i < 640 * 480; ++i)
        lit += !is_background(&p, img + 3 * i);
    free(img);
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(lit > 640 * 480 / 4);
}

SW_TEST_MAIN(CASE(checksums_known_vectors), CASE(png_round_trip_small),
             CASE(png_round_trip_many_blocks_and_chunks), CASE(png_errors),
             CASE(icosphere_is_closed_and_outward), CASE(sphere_disc_centre_corners_area),
             CASE(key_light_side_is_brighter), CASE(ground_shadow_under_sphere),
             CASE(flipped_winding_renders_the_same), CASE(threads_and_colours),
             CASE(frame_camera_fits_an_offset_box),
             CASE(frame_points_fills_the_image_with_a_long_body), CASE(render_input_errors),
             CASE(timing_20k_triangles_640x480))
