/* Reader of the complementary-dynamics bone animation (elephant-cd/elephant_anim.txt).
 *
 * Format (whitespace-separated numbers, angles in degrees):
 *   num_bones num_frames
 *   root rest translation (3)
 *   root rest Euler (3)
 *   per bone: rest Euler (3)                      -> rest frame A_b = Rz Ry Rx
 *   per frame: root Euler (3), root translation (3),
 *              per bone: Euler (3) about the bone's rest axes (columns of A_b)
 *
 * Semantics as the origin's reader (read_bone_anim): a rotation by (x, y, z) about the
 * columns a0, a1, a2 of A is Rot(a2, z) Rot(a1, y) Rot(a0, x) = A (Rz Ry Rx) A^T, a
 * relative rotation in rest space about the bone's head; when the skeleton has several
 * roots, every root also gets the root rotation (about the root rest axes) applied
 * first, and every root gets the translation (root translation - root rest
 * translation). The transforms then follow by forward kinematics (igl convention, the
 * same as sw_forward_kinematics).
 *
 * Coordinates: the origin normalises mesh, joints and translations by (x - c) / s
 * before FK. FK commutes with that similarity (rotations are unchanged, translations
 * scale with s and the centre cancels in the translation difference), so applying the
 * raw translation difference to the raw TGF joints gives exactly the conjugated
 * transforms for the raw .mesh coordinates. We therefore do not normalise. */
#include "clip_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct anim_reader {
    const char *path;
    char *buf;
    size_t len, pos;
    int line;      /* line of the cursor */
    int last_line; /* line of the last token read: where a truncated file ends */
} anim_reader;

static sinew_result load_file(const char *path, anim_reader *r, sw_error *err) {
    memset(r, 0, sizeof *r);
    r->path = path;
    r->line = 1;
    FILE *f = fopen(path, "rb");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        cap *= 2;
        char *nb = realloc(buf, cap + 1);
        if (!nb) free(buf);
        buf = nb;
    }
    int bad = ferror(f);
    fclose(f);
    if (!buf) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (bad) {
        free(buf);
        return sw_error_set(err, SINEW_ERROR_IO, "%s: read error", path);
    }
    buf[n] = '\0';
    r->buf = buf;
    r->len = n;
    return SINEW_OK;
}

static sinew_result load_mem(const char *name, const char *text, size_t len, anim_reader *r,
                             sw_error *err) {
    memset(r, 0, sizeof *r);
    r->path = name;
    r->line = 1;
    if (!text && len) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: no text", name);
    char *buf = malloc(len + 1);
    if (!buf) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    if (len) memcpy(buf, text, len);
    buf[len] = '\0';
    r->buf = buf;
    r->len = len;
    return SINEW_OK;
}

static int is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Next whitespace-separated token: returns its length (0 at end of file) and leaves
 * r->line at the token's line. */
static size_t next_token(anim_reader *r, const char **tok) {
    while (r->pos < r->len && is_space(r->buf[r->pos])) {
        if (r->buf[r->pos] == '\n') r->line++;
        r->pos++;
    }
    *tok = r->buf + r->pos;
    size_t start = r->pos;
    while (r->pos < r->len && !is_space(r->buf[r->pos])) /* a NUL byte is garbage, not the end */
        r->pos++;
    if (r->pos > start) r->last_line = r->line;
    return r->pos - start;
}

/* Reads one finite number; `what` names it in the error message. */
static sinew_result read_number(anim_reader *r, double *out, const char *what, sw_error *err) {
    const char *tok;
    size_t n = next_token(r, &tok);
    if (n == 0)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: file ends while reading %s", r->path,
                            r->last_line, what);
    char tmp[64];
    if (n >= sizeof tmp)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: token too long while reading %s",
                            r->path, r->line, what);
    memcpy(tmp, tok, n);
    tmp[n] = '\0';
    char *end;
    double v = strtod(tmp, &end);
    if (end != tmp + n)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: expected a number for %s, got '%s'",
                            r->path, r->line, what, tmp);
    if (!isfinite(v))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "%s:%d: non-finite value '%s' in %s",
                            r->path, r->line, tmp, what);
    *out = v;
    return SINEW_OK;
}

static sinew_result read_int(anim_reader *r, long *out, const char *what, sw_error *err) {
    const char *tok;
    size_t n = next_token(r, &tok);
    if (n == 0)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: file ends while reading %s", r->path,
                            r->last_line > 0 ? r->last_line : 1, what);
    char tmp[32];
    if (n >= sizeof tmp)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: %s is not an integer", r->path, r->line,
                            what);
    memcpy(tmp, tok, n);
    tmp[n] = '\0';
    char *end;
    errno = 0;
    long v = strtol(tmp, &end, 10);
    if (end != tmp + n || errno)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: %s is not an integer: '%s'", r->path,
                            r->line, what, tmp);
    *out = v;
    return SINEW_OK;
}

static sinew_result read_vec3(anim_reader *r, double *v, const char *what, sw_error *err) {
    for (int i = 0; i < 3; ++i) {
        sinew_result rc = read_number(r, v + i, what, err);
        if (rc) return rc;
    }
    return SINEW_OK;
}

/* C = A B (3x3 row-major); C may alias neither input. */
static void mat3_mul(const double *A, const double *B, double *C) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* Rz(z) Ry(y) Rx(x) from degrees: the origin's euler_to_quat about fixed axes. */
static void euler_deg_to_mat(const double *e, double *R) {
    const double k = 3.14159265358979323846 / 180.0;
    double cx = cos(e[0] * k), sx = sin(e[0] * k);
    double cy = cos(e[1] * k), sy = sin(e[1] * k);
    double cz = cos(e[2] * k), sz = sin(e[2] * k);
    double Rx[9] = {1, 0, 0, 0, cx, -sx, 0, sx, cx};
    double Ry[9] = {cy, 0, sy, 0, 1, 0, -sy, 0, cy};
    double Rz[9] = {cz, -sz, 0, sz, cz, 0, 0, 0, 1};
    double Ryx[9];
    mat3_mul(Ry, Rx, Ryx);
    mat3_mul(Rz, Ryx, R);
}

/* Euler angles about the axes of rest frame A: A (Rz Ry Rx) A^T. */
static void euler_about_frame(const double *e, const double *A, double *R) {
    double E[9], AE[9], At[9];
    euler_deg_to_mat(e, E);
    mat3_mul(A, E, AE);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            At[3 * i + j] = A[3 * j + i];
    mat3_mul(AE, At, R);
}

/* Parses the frames after the header into out->T (allocated by the caller). */
static sinew_result read_frames(anim_reader *r, const sw_skeleton *s, int32_t nframes, sw_clip *out,
                                sw_error *err) {
    int32_t nb = s->nbones, nroots = 0;
    for (int32_t b = 0; b < nb; ++b)
        nroots += s->parent[b] < 0;
    double *rest = malloc(sizeof(double) * 9 * (size_t)nb);
    double *local = malloc(sizeof(double) * 9 * (size_t)nb);
    sinew_result rc = SINEW_OK;
    double root_rest_t[3], e[3], root_A[9];
    char what[96];
    if (!rest || !local) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", r->path);
        goto done;
    }
    if ((rc = read_vec3(r, root_rest_t, "the root rest translation", err))) goto done;
    if ((rc = read_vec3(r, e, "the root rest Euler angles", err))) goto done;
    euler_deg_to_mat(e, root_A);
    for (int32_t b = 0; b < nb; ++b) {
        snprintf(what, sizeof what, "the rest Euler angles of bone %d", b);
        if ((rc = read_vec3(r, e, what, err))) goto done;
        euler_deg_to_mat(e, rest + 9 * b);
    }
    for (int32_t f = 0; f < nframes; ++f) {
        double root_R[9], root_t[3], dT[3];
        snprintf(what, sizeof what, "the root rotation of frame %d", f);
        if ((rc = read_vec3(r, e, what, err))) goto done;
        euler_about_frame(e, root_A, root_R);
        snprintf(what, sizeof what, "the root translation of frame %d", f);
        if ((rc = read_vec3(r, root_t, what, err))) goto done;
        for (int i = 0; i < 3; ++i)
            dT[i] = root_t[i] - root_rest_t[i];
        for (int32_t b = 0; b < nb; ++b) {
            double q[9];
            snprintf(what, sizeof what, "the rotation of bone %d in frame %d", b, f);
            if ((rc = read_vec3(r, e, what, err))) goto done;
            euler_about_frame(e, rest + 9 * b, q);
            /* The origin applies the root rotation only to multi-root skeletons (a
             * single root's own Euler angles already carry it). */
            if (s->parent[b] < 0 && nroots > 1)
                mat3_mul(q, root_R, local + 9 * b);
            else
                memcpy(local + 9 * b, q, sizeof q);
        }
        double *T = out->T + (size_t)f * nb * 12;
        sw_forward_kinematics(s, local, dT, T);
        for (int32_t k = 0; k < 12 * nb; ++k)
            if (!isfinite(T[k])) { /* finite numbers whose differences or sums overflow */
                rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                  "%s:%d: the transforms of frame %d overflow (translations too "
                                  "large)",
                                  r->path, r->last_line, f);
                goto done;
            }
    }
    const char *tok;
    if (next_token(r, &tok) != 0)
        rc = sw_error_set(err, SINEW_ERROR_PARSE,
                          "%s:%d: unexpected data after the %d frames the header announced",
                          r->path, r->line, nframes);
done:
    free(rest);
    free(local);
    return rc;
}

/* Checks the arguments every entry shares. */
static sinew_result check_args(const char *name, const sw_skeleton *s, double fps, sw_clip *out,
                               sw_error *err) {
    if (!out)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_cd_anim: out is NULL");
    memset(out, 0, sizeof *out);
    if (!name || !s)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_cd_anim: NULL argument");
    if (!(fps > 0) || !isfinite(fps))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: fps must be positive, got %g",
                            name, fps);
    return sw_skeleton_validate(s, err);
}

/* Parses the loaded reader `r` into *out (zeroed by check_args) and frees its text. */
static sinew_result read_anim(anim_reader *r, const sw_skeleton *s, double fps, sw_clip *out,
                              sw_error *err) {
    const char *path = r->path;
    long nb, nf;
    sinew_result rc;
    if ((rc = read_int(r, &nb, "the bone count", err))) goto fail;
    if ((rc = read_int(r, &nf, "the frame count", err))) goto fail;
    if (nb != s->nbones) {
        rc = sw_error_set(err, SINEW_ERROR_PARSE, "%s:%d: animation has %ld bones, skeleton has %d",
                          path, r->line, nb, s->nbones);
        goto fail;
    }
    /* Each number takes at least two bytes (digit and separator), so a frame count the
     * file cannot hold is rejected before allocating for it. */
    double need = 6.0 + 3.0 * (double)nb + (double)nf * (6.0 + 3.0 * (double)nb);
    if (nf < 1 || 2.0 * need - 1.0 > (double)r->len) {
        rc = sw_error_set(err, SINEW_ERROR_PARSE,
                          "%s:%d: frame count %ld is impossible for a file of %zu bytes", path,
                          r->line, nf, r->len);
        goto fail;
    }
    out->T = malloc(sizeof(double) * 12 * (size_t)nb * (size_t)nf);
    if (!out->T) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory for %ld frames", path,
                          nf);
        goto fail;
    }
    out->nbones = (int32_t)nb;
    out->nframes = (int32_t)nf;
    out->fps = fps;
    if ((rc = read_frames(r, s, (int32_t)nf, out, err))) goto fail;
    free(r->buf);
    return SINEW_OK;
fail:
    free(r->buf);
    sw_clip_free(out);
    return rc;
}

sinew_result sw_read_cd_anim(const char *path, const sw_skeleton *s, double fps, sw_clip *out,
                             sw_error *err) {
    sinew_result rc = check_args(path, s, fps, out, err);
    if (rc) return rc;
    anim_reader r;
    if ((rc = load_file(path, &r, err))) return rc;
    return read_anim(&r, s, fps, out, err);
}

sinew_result sw_parse_cd_anim(const char *text, size_t len, const char *name_for_errors,
                              const sw_skeleton *s, double fps, sw_clip *out, sw_error *err) {
    const char *name = name_for_errors ? name_for_errors : "<text>";
    sinew_result rc = check_args(name, s, fps, out, err);
    if (rc) return rc;
    anim_reader r;
    if ((rc = load_mem(name, text, len, &r, err))) return rc;
    return read_anim(&r, s, fps, out, err);
}
