/* Assembling a simulation character from real asset files: mesh, skeleton, weights,
 * motion, driven vertices and material, all validated against each other. Also the
 * pose clip of libigl's hand (tutorial 403: slerp identity <-> pose, then FK). */
#include "character_io.h"

#include "tet_lattice.h"

#include "dqs.h"

#include "mesh_io.h"
#include "vec3.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Frames of a pose clip when the caller passes nframes <= 0 (odd: the middle frame is
 * exactly the pose). */
#define SW_DEFAULT_POSE_FRAMES 61
/* Generic material of sw_character_from_files; sw_character_from_dataset overrides it. */
#define SW_DEFAULT_YOUNGS 1e5
#define SW_DEFAULT_POISSON 0.4
#define SW_DEFAULT_DENSITY 1.0
#define SW_DEFAULT_FPS 30.0

/* Unit quaternion in libigl's (x, y, z, w) order to a row-major rotation matrix. */
static void quat_to_mat(const double *q, double *R) {
    const double wxyz[4] = {q[3], q[0], q[1], q[2]};
    sw_quat_to_matrix(wxyz, R);
}

/* slerp(identity, q, a) along the shorter arc (as Eigen's slerp): the rotation about
 * q's axis by a times q's angle. q must be unit. */
static void slerp_from_identity(const double *q, double a, double *out) {
    double sgn = q[3] < 0 ? -1.0 : 1.0; /* q and -q are the same rotation */
    double v[3] = {sgn * q[0], sgn * q[1], sgn * q[2]}, w = sgn * q[3];
    double s = sw_v3_norm(v);
    double half = atan2(s, w); /* half angle in [0, pi/2] */
    double k = s > 0 ? sin(a * half) / s : a;
    for (int i = 0; i < 3; ++i)
        out[i] = k * v[i];
    out[3] = cos(a * half);
}

sinew_result sw_clip_from_pose_quats(const sw_skeleton *s, const double *quats, int32_t nframes,
                                     double fps, sw_clip *out, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "pose clip: out is NULL");
    memset(out, 0, sizeof *out);
    if (!s || !quats)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "pose clip: NULL argument");
    if (nframes < 1 || nframes > 1000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "pose clip: %d frames", nframes);
    if (!(fps > 0) || !isfinite(fps))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "pose clip: fps %g", fps);
    sinew_result rc = sw_skeleton_validate(s, err);
    if (rc) return rc;
    int32_t nb = s->nbones;
    double *q = malloc(sizeof(double) * 4 * (size_t)nb);
    double *local = malloc(sizeof(double) * 9 * (size_t)nb);
    out->T = malloc(sizeof(double) * 12 * (size_t)nb * (size_t)nframes);
    if (!q || !local || !out->T) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "pose clip: out of memory");
        goto done;
    }
    for (int32_t b = 0; b < nb; ++b) {
        double n2 = 0;
        for (int i = 0; i < 4; ++i) {
            if (!isfinite(quats[4 * b + i])) {
                rc = sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                  "pose clip: quaternion of bone %d is not finite", b);
                goto done;
            }
            n2 += quats[4 * b + i] * quats[4 * b + i];
        }
        if (!(fabs(sqrt(n2) - 1.0) < 1e-3)) { /* a typo'd pose, not rounding */
            rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                              "pose clip: quaternion of bone %d has norm %g (expected 1)", b,
                              sqrt(n2));
            goto done;
        }
        for (int i = 0; i < 4; ++i)
            q[4 * b + i] = quats[4 * b + i] / sqrt(n2);
    }
    for (int32_t f = 0; f < nframes; ++f) {
        /* Eased there and back: a = (1 - cos 2 pi t) / 2 starts and ends at rest with zero
         * angular velocity and reaches the pose at t = 1/2. */
        double t = nframes > 1 ? (double)f / (double)(nframes - 1) : 0.0;
        double a = 0.5 * (1.0 - cos(2.0 * 3.14159265358979323846 * t));
        if (2 * f == nframes - 1) a = 1.0; /* exactly the pose in the middle */
        for (int32_t b = 0; b < nb; ++b) {
            double qa[4];
            slerp_from_identity(q + 4 * b, a, qa);
            quat_to_mat(qa, local + 9 * b);
        }
        sw_forward_kinematics(s, local, NULL, out->T + (size_t)f * nb * 12);
    }
    out->nbones = nb;
    out->nframes = nframes;
    out->fps = fps;
done:
    free(q);
    free(local);
    if (rc) sw_clip_free(out);
    return rc;
}

/* A clip that holds the rest pose. */
static sinew_result identity_clip(int32_t nbones, int32_t nframes, sw_clip *out, sw_error *err) {
    out->T = calloc((size_t)nbones * (size_t)nframes * 12, sizeof(double));
    if (!out->T)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "identity clip: out of memory");
    for (int32_t k = 0; k < nbones * nframes; ++k)
        out->T[12 * k] = out->T[12 * k + 4] = out->T[12 * k + 8] = 1.0;
    out->nbones = nbones;
    out->nframes = nframes;
    out->fps = SW_DEFAULT_FPS;
    return SINEW_OK;
}

static int has_suffix(const char *s, const char *suffix) {
    size_t n = strlen(s), k = strlen(suffix);
    if (n < k) return 0;
    for (size_t i = 0; i < k; ++i) {
        char a = s[n - k + i], b = suffix[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (a != b) return 0;
    }
    return 1;
}

/* Pose .dmat: 4*nbones quaternion coefficients (one column or one row). */
static sinew_result pose_dmat_clip(const char *path, const sw_skeleton *s, int32_t nframes,
                                   sw_clip *out, sw_error *err) {
    int32_t rows = 0, cols = 0;
    double *q = NULL;
    sinew_result rc = sw_read_dmat(path, &rows, &cols, &q, err);
    if (rc) return rc;
    if ((int64_t)rows * cols != 4 * (int64_t)s->nbones || (rows != 1 && cols != 1)) {
        free(q);
        return sw_error_set(err, SINEW_ERROR_PARSE,
                            "%s: pose is %d x %d, expected %d x 1 (one x,y,z,w quaternion per "
                            "bone of the skeleton)",
                            path, rows, cols, 4 * s->nbones);
    }
    rc = sw_clip_from_pose_quats(s, q, nframes > 0 ? nframes : SW_DEFAULT_POSE_FRAMES,
                                 SW_DEFAULT_FPS, out, err);
    free(q);
    if (rc) {
        char msg[sizeof err->msg];
        if (err) {
            snprintf(msg, sizeof msg, "%s", err->msg);
            sw_error_set(err, rc, "%s: %s", path, msg);
        }
    }
    return rc;
}

/* The motion of sw_character_from_files: a .txt CD animation (at most nframes frames when
 * nframes > 0), a .dmat pose, or the rest pose held for nframes frames. */
static sinew_result load_motion(const char *path, const sw_skeleton *s, int32_t nframes,
                                sw_clip *out, sw_error *err) {
    if (nframes > 1000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "motion: %d frames", nframes);
    if (!path) return identity_clip(s->nbones, nframes > 0 ? nframes : 1, out, err);
    if (has_suffix(path, ".dmat")) return pose_dmat_clip(path, s, nframes, out, err);
    if (!has_suffix(path, ".txt"))
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                            "%s: unknown motion format (expected a .txt bone animation or a "
                            ".dmat pose)",
                            path);
    sinew_result rc = sw_read_cd_anim(path, s, SW_DEFAULT_FPS, out, err);
    if (!rc && nframes > 0 && nframes < out->nframes) out->nframes = nframes;
    return rc;
}

/* Cross-checks what the readers cannot see alone. */
static sinew_result check_character(const sw_character *c, const char *weights_path,
                                    sw_error *err) {
    if (c->weights.nverts != c->mesh.nverts || c->weights.nbones != c->skel.nbones)
        return sw_error_set(err, SINEW_ERROR_PARSE,
                            "%s: weights are %d x %d, expected %d vertices x %d bones",
                            weights_path ? weights_path : "inverse-distance weights",
                            c->weights.nverts, c->weights.nbones, c->mesh.nverts, c->skel.nbones);
    for (int32_t v = 0; v < c->weights.nverts; ++v) {
        double sum = 0;
        for (int32_t b = 0; b < c->weights.nbones; ++b) {
            double x = c->weights.w[(size_t)v * c->weights.nbones + b];
            if (!(x >= 0))
                return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                    "weights of vertex %d: bone %d has %g", v, b, x);
            sum += x;
        }
        if (!(fabs(sum - 1.0) < 1e-9))
            return sw_error_set(err, SINEW_ERROR_DEGENERATE,
                                "weights of vertex %d sum to %.17g, not 1", v, sum);
    }
    return sw_clip_validate(&c->clip, c->skel.nbones, err);
}

sinew_result sw_character_read_range(const char *path, sw_character *ch, sw_error *err) {
    if (!path || !ch)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "joint range: NULL argument");
    sw_clip c;
    memset(&c, 0, sizeof c);
    /* a pose becomes rest, the pose, rest: its middle frame is the pose exactly */
    sinew_result rc = load_motion(path, &ch->skel, has_suffix(path, ".dmat") ? 3 : 0, &c, err);
    if (!rc && (rc = sw_clip_validate(&c, ch->skel.nbones, err)) && err) {
        char msg[sizeof err->msg]; /* the check names the item, not the file */
        snprintf(msg, sizeof msg, "%s", err->msg);
        sw_error_set(err, rc, "%s: %s", path, msg);
    }
    if (rc) {
        sw_clip_free(&c);
        return rc;
    }
    sw_clip_free(&ch->range);
    ch->range = c;
    return SINEW_OK;
}

void sw_file_stem(const char *path, char *name, size_t cap) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t n = dot && dot > base ? (size_t)(dot - base) : strlen(base);
    if (n >= cap) n = cap - 1;
    memcpy(name, base, n);
    name[n] = '\0';
}

/* The rest of a character once out->mesh holds a valid tet mesh: the skeleton, the
 * weights (the file's, or inverse-distance), the motion, the bone vertices and the
 * default material; mesh_path names the character and the mesh in messages. */
static sinew_result finish_character(const char *mesh_path, const char *tgf_path,
                                     const char *weights_path, const char *motion_path,
                                     int32_t nframes, sw_character *out, sw_error *err) {
    sinew_result rc;
    if ((rc = sw_read_tgf(tgf_path, &out->skel, err))) goto fail;
    if ((rc = sw_skeleton_validate(&out->skel, err))) goto fail_named_tgf;
    if (weights_path)
        rc = sw_read_weights(weights_path, out->mesh.nverts, out->skel.nbones, &out->weights, err);
    else
        rc = sw_weights_inverse_distance(&out->mesh, &out->skel, &out->weights, err);
    if (rc) goto fail;
    if ((rc = load_motion(motion_path, &out->skel, nframes, &out->clip, err))) goto fail;
    if ((rc = check_character(out, weights_path, err))) goto fail;
    out->bone_of_vertex = malloc(sizeof(int32_t) * (size_t)out->mesh.nverts);
    if (!out->bone_of_vertex) {
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "character: out of memory");
        goto fail;
    }
    if ((rc = sw_select_bone_vertices(&out->mesh, &out->skel, &out->weights, out->bone_of_vertex,
                                      err)))
        goto fail_named_mesh;
    sw_file_stem(mesh_path, out->name, sizeof out->name);
    out->youngs = SW_DEFAULT_YOUNGS;
    out->poisson = SW_DEFAULT_POISSON;
    out->density = SW_DEFAULT_DENSITY;
    return SINEW_OK;
fail_named_tgf:
    mesh_path = tgf_path;
fail_named_mesh:
    if (err) { /* validators name the item, not the file */
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        sw_error_set(err, rc, "%s: %s", mesh_path, msg);
    }
fail:
    sw_character_free(out);
    return rc;
}

sinew_result sw_character_from_files(const char *mesh_path, const char *tgf_path,
                                     const char *weights_path, const char *motion_path,
                                     int32_t nframes, sw_character *out, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "character: out is NULL");
    memset(out, 0, sizeof *out);
    if (!mesh_path || !tgf_path)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character: mesh or skeleton path is NULL");
    sinew_result rc = sw_read_tetmesh(mesh_path, &out->mesh, err);
    if (!rc && (rc = sw_tetmesh_validate(&out->mesh, 0.0, err))) {
        char msg[sizeof err->msg]; /* the validator names the item, not the file */
        snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
        sw_error_set(err, rc, "%s: %s", mesh_path, msg);
    }
    if (rc) {
        sw_character_free(out);
        return rc;
    }
    return finish_character(mesh_path, tgf_path, weights_path, motion_path, nframes, out, err);
}

sinew_result sw_character_from_surface(const char *obj_path, int32_t target_tets, sw_mesher mesher,
                                       const char *tgf_path, const char *motion_path,
                                       int32_t nframes, sw_character *out, sw_mesher_report *report,
                                       sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "character: out is NULL");
    memset(out, 0, sizeof *out);
    if (!obj_path || !tgf_path)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character: surface or skeleton path is NULL");
    sw_trimesh surf;
    sinew_result rc = sw_read_obj(obj_path, &surf, err);
    if (rc) return rc;
    rc = sw_tetmesh_fill(&surf, target_tets, mesher, NULL, &out->mesh, report, err);
    if (rc) {
        sw_trimesh_free(&surf);
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
        sw_error_set(err, rc, "%s: %s", obj_path, msg);
        return rc;
    }
    /* the artist's surface is what the runtime outputs, carried by the generated tets;
       finish_character frees it with the character on an error */
    out->render = surf;
    return finish_character(obj_path, tgf_path, NULL, motion_path, nframes, out, err);
}

/* The number after "key": in a flat JSON object (enough for elephant.json's numbers). */
static sinew_result json_number(const char *path, const char *key, double *out, sw_error *err) {
    FILE *f = fopen(path, "rb");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
    char buf[8192];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\"", key);
    const char *p = strstr(buf, quoted);
    if (!p) return sw_error_set(err, SINEW_ERROR_PARSE, "%s: no \"%s\" entry", path, key);
    p += strlen(quoted);
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
        ++p;
    char *end = NULL;
    double v = *p == ':' ? strtod(p + 1, &end) : 0.0;
    if (*p != ':' || end == p + 1)
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: \"%s\" is not followed by a number", path,
                            key);
    if (!isfinite(v))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE, "%s: \"%s\" is %g", path, key, v);
    *out = v;
    return SINEW_OK;
}

static sinew_result load_elephant(const char *dir, int32_t nframes, sw_character *out,
                                  sw_error *err) {
    char mesh[1024], tgf[1024], dmat[1024], anim[1024], json[1024];
    snprintf(mesh, sizeof mesh, "%s/elephant.mesh", dir);
    snprintf(tgf, sizeof tgf, "%s/elephant.tgf", dir);
    snprintf(dmat, sizeof dmat, "%s/elephant.dmat", dir);
    snprintf(anim, sizeof anim, "%s/elephant_anim.txt", dir);
    snprintf(json, sizeof json, "%s/elephant.json", dir);
    double dt, youngs, poisson;
    sinew_result rc;
    if ((rc = json_number(json, "dt", &dt, err)) || (rc = json_number(json, "YM", &youngs, err)) ||
        (rc = json_number(json, "pr", &poisson, err)))
        return rc;
    if (!(dt > 0) || !(youngs > 0) || !(poisson > -1 && poisson < 0.5))
        return sw_error_set(err, SINEW_ERROR_PARSE, "%s: dt %g, YM %g, pr %g out of range", json,
                            dt, youngs, poisson);
    if ((rc = sw_character_from_files(mesh, tgf, dmat, anim, nframes, out, err))) return rc;
    out->clip.fps = 1.0 / dt;
    out->youngs = youngs;
    out->poisson = poisson;
    out->density = 1.0;
    return SINEW_OK;
}

static sinew_result load_hand(const char *dir, int32_t nframes, sw_character *out, sw_error *err) {
    char mesh[1024], tgf[1024], pose[1024];
    snprintf(mesh, sizeof mesh, "%s/hand.mesh", dir);
    snprintf(tgf, sizeof tgf, "%s/hand.tgf", dir);
    snprintf(pose, sizeof pose, "%s/hand-pose.dmat", dir);
    sinew_result rc = sw_character_from_files(mesh, tgf, NULL, pose, nframes, out, err);
    if (rc) return rc;
    out->clip.fps = 30.0;
    out->youngs = 5000.0; /* DESIGN.md §8: the thesis' hand */
    out->poisson = 0.08;
    out->density = 1.0;
    return SINEW_OK;
}

sinew_result sw_character_from_dataset(const char *data_dir, const char *name, int32_t nframes,
                                       sw_character *out, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "dataset: out is NULL");
    memset(out, 0, sizeof *out);
    if (!data_dir || !name)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "dataset: NULL folder or name");
    char dir[900];
    if ((size_t)snprintf(dir, sizeof dir, "%s/%s", data_dir, name) >= sizeof dir)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "dataset: path too long");
    sinew_result rc;
    if (strcmp(name, "elephant-cd") == 0)
        rc = load_elephant(dir, nframes, out, err);
    else if (strcmp(name, "hand-libigl") == 0)
        rc = load_hand(dir, nframes, out, err);
    else
        return sw_error_set(err, SINEW_ERROR_UNSUPPORTED,
                            "dataset '%s' is not known (elephant-cd, hand-libigl)", name);
    if (rc) return rc;
    snprintf(out->name, sizeof out->name, "%s", name);
    return SINEW_OK;
}
