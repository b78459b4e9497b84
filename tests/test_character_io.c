/* Characters from real assets: the complementary-dynamics animation reader, the pose
 * clip, inverse-distance weights, the driven-vertex selection, and whole characters. */
#include "character_io.h"
#include "mesh_io.h"
#include "sw_test.h"

#include <stdint.h>

#define ELEPHANT_DIR SINEW_SHARED_DATA_DIR "/elephant-cd"
#define HAND_DIR SINEW_SHARED_DATA_DIR "/hand-libigl"
#define TMP(name) SINEW_BINARY_DIR "/test_character_io_" name

static const double PI = 3.14159265358979323846;

static int write_text(const char *path, const char *text) {
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

/* ---- small in-memory rigs ---------------------------------------------------------- */

/* Joints 0 (origin), 1 (+x), 2 (+2x), 3 (+y); bones 0:(0,1), 1:(1,2), 2:(0,3). Bones 0
 * and 2 are roots, bone 1 is bone 0's child. */
static void make_fork(sw_skeleton *s) {
    static const double J[12] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0};
    static const int32_t B[6] = {0, 1, 1, 2, 0, 3};
    static const int32_t P[3] = {-1, 0, -1};
    s->njoints = 4;
    s->nbones = 3;
    s->joints = malloc(sizeof J);
    s->bones = malloc(sizeof B);
    s->parent = malloc(sizeof P);
    memcpy(s->joints, J, sizeof J);
    memcpy(s->bones, B, sizeof B);
    memcpy(s->parent, P, sizeof P);
}

/* A box of nx*ny*nz grid vertices (spacing h, centred on the x axis), each cell split
 * into 6 positive tets (Kuhn triangulation). */
static void make_box(int nx, int ny, int nz, double h, sw_tetmesh *m) {
    m->nverts = nx * ny * nz;
    m->ntets = 6 * (nx - 1) * (ny - 1) * (nz - 1);
    m->X = malloc(sizeof(double) * 3 * (size_t)m->nverts);
    m->tets = malloc(sizeof(int32_t) * 4 * (size_t)m->ntets);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                int v = i + nx * (j + ny * k);
                m->X[3 * v] = i * h;
                m->X[3 * v + 1] = (j - 0.5 * (ny - 1)) * h;
                m->X[3 * v + 2] = (k - 0.5 * (nz - 1)) * h;
            }
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k + 1 < nz; ++k)
        for (int j = 0; j + 1 < ny; ++j)
            for (int i = 0; i + 1 < nx; ++i)
                for (int p = 0; p < 6; ++p) {
                    int c[3] = {i, j, k}, *q = m->tets + 4 * t++;
                    q[0] = c[0] + nx * (c[1] + ny * c[2]);
                    for (int s = 0; s < 3; ++s) {
                        c[perms[p][s]]++;
                        q[s + 1] = c[0] + nx * (c[1] + ny * c[2]);
                    }
                    if (sw_tet_signed_volume(m->X + 3 * q[0], m->X + 3 * q[1], m->X + 3 * q[2],
                                             m->X + 3 * q[3]) < 0) {
                        int32_t tmp = q[1];
                        q[1] = q[2];
                        q[2] = tmp;
                    }
                }
}

/* Two bones along the x axis of a box of length L: (0..L/2), (L/2..L). */
static void make_axis_skeleton(double L, sw_skeleton *s) {
    s->njoints = 3;
    s->nbones = 2;
    s->joints = calloc(9, sizeof(double));
    s->bones = malloc(4 * sizeof(int32_t));
    s->parent = malloc(2 * sizeof(int32_t));
    s->joints[3] = 0.5 * L;
    s->joints[6] = L;
    s->bones[0] = 0, s->bones[1] = 1, s->bones[2] = 1, s->bones[3] = 2;
    s->parent[0] = -1, s->parent[1] = 0;
}

/* ---- rigid-transform checks ------------------------------------------------------- */

static double rotation_error(const double *T) {
    double e = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d =
                T[3 * i] * T[3 * j] + T[3 * i + 1] * T[3 * j + 1] + T[3 * i + 2] * T[3 * j + 2];
            e = fmax(e, fabs(d - (i == j)));
        }
    double det = T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                 T[2] * (T[3] * T[7] - T[4] * T[6]);
    return fmax(e, fabs(det - 1));
}

static double dist3(const double *a, const double *b) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* ---- the CD animation reader ------------------------------------------------------ */

/* A 2-frame animation for make_fork. Frame 0 is the rest; frame 1 rotates bone 0 by 90
 * degrees about its rest x axis (= world +y, since its rest frame is Rz(90)), the root by
 * 90 degrees about z, and moves the root by (1, 2, 3). */
static const char *FORK_ANIM = "3 2\n"
                               "5 5 5\n"  /* root rest translation */
                               "0 0 0\n"  /* root rest Euler */
                               "0 0 90\n" /* bone 0 rest frame Rz(90) */
                               "0 0 0\n"  /* bone 1 */
                               "0 0 0\n"  /* bone 2 */
                               "0 0 0\n5 5 5\n0 0 0\n0 0 0\n0 0 0\n"
                               "0 0 90\n6 7 8\n90 0 0\n0 0 0\n0 0 0\n";

TEST(cd_anim_semantics) {
    sw_skeleton s = {0};
    make_fork(&s);
    sw_error err = {0};
    sw_clip c = {0};
    ENSURE(write_text(TMP("fork.txt"), FORK_ANIM));
    sinew_result rc = sw_read_cd_anim(TMP("fork.txt"), &s, 100.0, &c, &err);
    remove(TMP("fork.txt"));
    ENSUREF(rc == SINEW_OK, "%s", err.msg);
    ENSURE(c.nframes == 2 && c.nbones == 3 && c.fps == 100.0);
    for (int k = 0; k < 3 * 12; ++k) /* frame 0 is the rest pose */
        ENSURE_NEAR(c.T[k], (k % 12 == 0 || k % 12 == 4 || k % 12 == 8) ? 1.0 : 0.0, 1e-12);
    /* bone 0, frame 1: Rot_y(90) after Rot_z(90) (root), about the origin, + (1,2,3).
     * (1,0,0) -Rz90-> (0,1,0) -Ry90-> (0,1,0); (0,0,1) -Rz90-> (0,0,1) -Ry90-> (1,0,0). */
    const double *T0 = c.T + 12 * 3;
    double p[3], x[3] = {1, 0, 0}, z[3] = {0, 0, 1};
    sw_transform_point(T0, x, p);
    ENSURE(dist3(p, (double[3]){1, 3, 3}) < 1e-12);
    sw_transform_point(T0, z, p);
    ENSURE(dist3(p, (double[3]){2, 2, 3}) < 1e-12);
    /* bone 1 follows bone 0 rigidly (its own Euler is 0) */
    const double *T1 = c.T + 12 * 4;
    double two[3] = {2, 0, 0}, p0[3];
    sw_transform_point(T1, two, p);
    sw_transform_point(T0, two, p0);
    ENSURE(dist3(p, p0) < 1e-12);
    /* bone 2 (the other root) only gets the root motion: Rz(90) + (1,2,3) */
    sw_transform_point(c.T + 12 * 5, (double[3]){0, 1, 0}, p);
    ENSURE(dist3(p, (double[3]){0, 2, 3}) < 1e-12);
    sw_clip_free(&c);
    sw_skeleton_free(&s);
}

static sinew_result parse_text(const char *text, sw_error *err) {
    sw_skeleton s = {0};
    make_fork(&s);
    sw_clip c = {0};
    write_text(TMP("bad.txt"), text);
    sinew_result rc = sw_read_cd_anim(TMP("bad.txt"), &s, 30.0, &c, err);
    remove(TMP("bad.txt"));
    int zeroed = c.T == NULL && c.nframes == 0;
    sw_clip_free(&c);
    sw_skeleton_free(&s);
    return rc && !zeroed ? SINEW_ERROR_CORRUPT : rc; /* an error must leave out zeroed */
}

TEST(cd_anim_malformed) {
    sw_error err = {0};
    char buf[1024];
    /* truncated: the last bone line of frame 1 is missing */
    snprintf(buf, sizeof buf, "%s", FORK_ANIM);
    buf[strlen(buf) - strlen("0 0 0\n")] = '\0';
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "bad.txt:15:") && strstr(err.msg, "bone 2 in frame 1"), "%s", err.msg);
    /* bone count disagrees with the skeleton */
    snprintf(buf, sizeof buf, "4%s", FORK_ANIM + 1);
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "bad.txt:1:") && strstr(err.msg, "4 bones"), "%s", err.msg);
    /* NaN in frame 1's root translation (line 13) */
    snprintf(buf, sizeof buf, "%s", FORK_ANIM);
    char *q = strstr(buf, "6 7 8");
    memcpy(q, "nan", 3);
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_NOT_FINITE);
    ENSUREF(strstr(err.msg, "bad.txt:13:"), "%s", err.msg);
    /* garbage token */
    snprintf(buf, sizeof buf, "%s", FORK_ANIM);
    q = strstr(buf, "90 0 0");
    memcpy(q, "9x", 2);
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "bad.txt:14:") && strstr(err.msg, "'9x'"), "%s", err.msg);
    /* trailing data, absurd frame count, empty file */
    snprintf(buf, sizeof buf, "%s1 2 3\n", FORK_ANIM);
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "bad.txt:17:"), "%s", err.msg);
    snprintf(buf, sizeof buf, "3 2000000000%s", FORK_ANIM + 3);
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_PARSE);
    ENSURE(parse_text("", &err) == SINEW_ERROR_PARSE);
    ENSURE(parse_text("3 0\n", &err) == SINEW_ERROR_PARSE);
    /* finite translations whose difference overflows: frame 1's transforms (were +inf) */
    snprintf(buf, sizeof buf, "3 2\n-1e308 5 5\n%s", strstr(FORK_ANIM, "0 0 0\n"));
    q = strstr(buf, "6 7 8");
    snprintf(q, sizeof buf - (size_t)(q - buf), "1e308 7 8\n90 0 0\n0 0 0\n0 0 0\n");
    ENSURE(parse_text(buf, &err) == SINEW_ERROR_NOT_FINITE);
    ENSUREF(strstr(err.msg, "bad.txt:16:") && strstr(err.msg, "frame 1 overflow"), "%s", err.msg);
    /* a NUL byte after the frames is trailing garbage, not the end of the text */
    {
        sw_skeleton s = {0};
        make_fork(&s);
        sw_clip c = {0};
        size_t n = strlen(FORK_ANIM);
        memcpy(buf, FORK_ANIM, n);
        memcpy(buf + n, "\0junk\n", 6);
        ENSURE(sw_parse_cd_anim(buf, n, "mem.txt", &s, 30, &c, &err) == SINEW_OK);
        sw_clip_free(&c);
        ENSURE(sw_parse_cd_anim(buf, n + 6, "mem.txt", &s, 30, &c, &err) == SINEW_ERROR_PARSE);
        ENSUREF(strstr(err.msg, "mem.txt:17:") && c.T == NULL, "%s", err.msg);
        sw_skeleton_free(&s);
    }
    /* missing file */
    sw_skeleton s = {0};
    make_fork(&s);
    sw_clip c = {0};
    ENSURE(sw_read_cd_anim(TMP("does_not_exist.txt"), &s, 30, &c, &err) == SINEW_ERROR_IO);
    sw_skeleton_free(&s);
}

/* Joint positions of every frame: head and tail of every bone under its transform. */
TEST(cd_anim_elephant) {
    NEED_DATA("elephant-cd/elephant_anim.txt");
    sw_error err = {0};
    sw_skeleton s = {0};
    sw_clip c = {0};
    sw_tetmesh m = {0};
    sw_weights w = {0};
    ENSUREF(sw_read_tgf(ELEPHANT_DIR "/elephant.tgf", &s, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_read_cd_anim(ELEPHANT_DIR "/elephant_anim.txt", &s, 100, &c, &err) == SINEW_OK, "%s",
            err.msg);
    ENSURE(c.nframes == 457 && c.nbones == 24 && s.nbones == 24);
    double scale = 0; /* skeleton extent */
    for (int j = 0; j < s.njoints; ++j)
        scale = fmax(scale, dist3(s.joints, s.joints + 3 * j));
    double max_step = 0, max_rot = 0, max_acc = 0;
    for (int f = 0; f < c.nframes; ++f)
        for (int b = 0; b < s.nbones; ++b) {
            const double *T = c.T + 12 * ((size_t)f * s.nbones + b);
            const double *h = s.joints + 3 * s.bones[2 * b], *t = s.joints + 3 * s.bones[2 * b + 1];
            double hw[3], tw[3];
            sw_transform_point(T, h, hw);
            sw_transform_point(T, t, tw);
            max_rot = fmax(max_rot, rotation_error(T));
            ENSUREF(fabs(dist3(hw, tw) - dist3(h, t)) <= 1e-9 * dist3(h, t), "frame %d bone %d", f,
                    b);
            if (s.parent[b] >= 0) { /* the joint is shared with the parent's tail */
                double pw[3];
                sw_transform_point(c.T + 12 * ((size_t)f * s.nbones + s.parent[b]), h, pw);
                ENSUREF(dist3(pw, hw) <= 1e-9 * scale, "frame %d bone %d detached", f, b);
            }
            if (f > 0) {
                double prev[3];
                sw_transform_point(T - 12 * s.nbones, t, prev);
                max_step = fmax(max_step, dist3(prev, tw));
                if (f + 1 < c.nframes) { /* second difference: no jumps within smooth motion */
                    double next[3], acc = 0;
                    sw_transform_point(T + 12 * s.nbones, t, next);
                    for (int i = 0; i < 3; ++i)
                        acc += (next[i] - 2 * tw[i] + prev[i]) * (next[i] - 2 * tw[i] + prev[i]);
                    max_acc = fmax(max_acc, sqrt(acc));
                }
            }
        }
    ENSUREF(max_rot < 1e-12, "rotation error %g", max_rot);
    fprintf(stderr,
            "  elephant anim: skeleton extent %.2f, largest joint step per frame %.3f, largest "
            "second difference %.3f\n",
            scale, max_step, max_acc);
    /* The animation is fast (tips move up to ~13% of the body per 10 ms frame) but smooth;
     * a wrapped Euler angle or a wrong axis would swing a limb by its whole length. */
    ENSUREF(max_step < 0.2 * scale, "a joint jumps %g in one frame", max_step);
    ENSUREF(max_acc < 0.1 * scale, "a joint's velocity jumps by %g", max_acc);
    for (int k = 0; k < 24 * 12; ++k) /* frame 0 is the rest pose */
        ENSURE_NEAR(c.T[k], (k % 12 == 0 || k % 12 == 4 || k % 12 == 8) ? 1.0 : 0.0, 1e-12);
    /* the skinned mesh stays an elephant of about the rest size */
    ENSUREF(sw_read_tetmesh(ELEPHANT_DIR "/elephant.mesh", &m, &err) == SINEW_OK, "%s", err.msg);
    ENSUREF(sw_read_weights(ELEPHANT_DIR "/elephant.dmat", m.nverts, 24, &w, &err) == SINEW_OK,
            "%s", err.msg);
    double *x = malloc(sizeof(double) * 3 * m.nverts), rest_ext[3];
    for (int f = 0; f < c.nframes; ++f) {
        sw_lbs(m.nverts, m.X, &w, c.T + (size_t)f * 24 * 12, x);
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int v = 0; v < m.nverts; ++v)
            for (int i = 0; i < 3; ++i)
                lo[i] = fmin(lo[i], x[3 * v + i]), hi[i] = fmax(hi[i], x[3 * v + i]);
        if (f == 0)
            for (int i = 0; i < 3; ++i)
                rest_ext[i] = hi[i] - lo[i];
        double diag = 0, rdiag = 0;
        for (int i = 0; i < 3; ++i)
            diag += (hi[i] - lo[i]) * (hi[i] - lo[i]), rdiag += rest_ext[i] * rest_ext[i];
        if (f % 50 == 0 || f == c.nframes - 1)
            fprintf(stderr, "  frame %3d: x [%7.2f %7.2f] y [%7.2f %7.2f] z [%7.2f %7.2f]\n", f,
                    lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
        ENSUREF(sqrt(diag) > 0.7 * sqrt(rdiag) && sqrt(diag) < 1.5 * sqrt(rdiag),
                "frame %d diag %g vs %g", f, sqrt(diag), sqrt(rdiag));
    }
    free(x);
    sw_weights_free(&w);
    sw_tetmesh_free(&m);
    sw_clip_free(&c);
    sw_skeleton_free(&s);
}

/* ---- pose clip -------------------------------------------------------------------- */

static void quat_matrix(const double *q, double *R) {
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                   2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                   2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    memcpy(R, r, sizeof r);
}

TEST(pose_clip) {
    sw_skeleton s = {0};
    make_fork(&s);
    /* bone 0: 120 degrees about z; bone 1: -(60 degrees about x), stored as the negative
     * quaternion (w < 0) to exercise the shorter arc; bone 2: identity */
    double c60 = cos(PI / 3), s60 = sin(PI / 3), c30 = cos(PI / 6), s30 = sin(PI / 6);
    double q[12] = {0, 0, s60, c60, -s30, 0, 0, -c30, 0, 0, 0, 1};
    sw_clip c = {0};
    sw_error err = {0};
    ENSUREF(sw_clip_from_pose_quats(&s, q, 21, 30, &c, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(c.nframes == 21 && c.nbones == 3 && c.fps == 30);
    double local[27], T[36];
    for (int b = 0; b < 3; ++b)
        quat_matrix(q + 4 * b, local + 9 * b);
    sw_forward_kinematics(&s, local, NULL, T);
    for (int k = 0; k < 36; ++k) {
        double id = (k % 12 == 0 || k % 12 == 4 || k % 12 == 8) ? 1.0 : 0.0;
        ENSURE_NEAR(c.T[k], id, 1e-15);
        ENSURE_NEAR(c.T[20 * 36 + k], id, 1e-12);
        ENSURE_NEAR(c.T[10 * 36 + k], T[k], 1e-12);
    }
    /* frame 5 is a quarter: bone 0 is rotated by a(5) * 120 degrees about z */
    double a = 0.5 * (1 - cos(2 * PI * 5 / 20.0));
    ENSURE_NEAR(atan2(c.T[5 * 36 + 3], c.T[5 * 36 + 0]), a * 2 * PI / 3, 1e-12);
    /* bone 1 turns the short way: its angle grows monotonically to 60 degrees */
    double prev = -1;
    for (int f = 0; f <= 10; ++f) {
        double Rl[9]; /* bone 1 relative to bone 0: R0^T R1 */
        const double *R0 = c.T + f * 36, *R1 = R0 + 12;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                Rl[3 * i + j] = R0[i] * R1[j] + R0[3 + i] * R1[3 + j] + R0[6 + i] * R1[6 + j];
        double ang = acos(fmin(1, (Rl[0] + Rl[4] + Rl[8] - 1) / 2));
        ENSURE(ang >= prev - 1e-12 && ang <= PI / 3 + 1e-12);
        prev = ang;
    }
    ENSURE_NEAR(prev, PI / 3, 1e-12);
    sw_clip_free(&c);
    /* errors */
    q[3] = 2.0;
    ENSURE(sw_clip_from_pose_quats(&s, q, 21, 30, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(err.msg, "bone 0"), "%s", err.msg);
    q[3] = NAN;
    ENSURE(sw_clip_from_pose_quats(&s, q, 21, 30, &c, &err) == SINEW_ERROR_NOT_FINITE);
    ENSURE(c.T == NULL);
    q[3] = c60;
    ENSURE(sw_clip_from_pose_quats(&s, q, 0, 30, &c, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    sw_skeleton_free(&s);
}

/* ---- inverse-distance weights ----------------------------------------------------- */

TEST(inverse_distance_weights) {
    sw_tetmesh m = {0};
    sw_skeleton s = {0};
    make_box(5, 3, 3, 0.25, &m);
    make_fork(&s);
    /* move vertex 0 onto bone 1's segment */
    m.X[0] = 1.5, m.X[1] = 0, m.X[2] = 0;
    sw_weights w = {0};
    sw_error err = {0};
    ENSUREF(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(w.nverts == m.nverts && w.nbones == 3);
    for (int v = 0; v < m.nverts; ++v) {
        double sum = 0;
        for (int b = 0; b < 3; ++b) {
            ENSURE(w.w[3 * v + b] > 0 && w.w[3 * v + b] <= 1);
            sum += w.w[3 * v + b];
        }
        ENSURE_NEAR(sum, 1.0, 1e-14);
    }
    ENSURE(w.w[1] > 1 - 1e-12);
    /* w ~ 1/d^4: a vertex at distances d0, d1, d2 */
    double *p = m.X + 3 * 7, d[3], e[3], sum = 0;
    ENSURE(p[0] == 0.5 && p[1] == 0 && p[2] == -0.25); /* beside bone 0, before bone 1 */
    d[0] = 0.25;
    d[1] = sqrt(0.5 * 0.5 + 0.25 * 0.25);
    d[2] = d[1];
    for (int b = 0; b < 3; ++b)
        sum += (e[b] = pow(d[b], -4));
    for (int b = 0; b < 3; ++b)
        ENSURE_NEAR(w.w[3 * 7 + b], e[b] / sum, 1e-12);
    sw_weights_free(&w);
    /* errors leave out zeroed */
    m.X[4] = NAN;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_ERROR_NOT_FINITE);
    ENSURE(w.w == NULL);
    int32_t nv = m.nverts;
    m.nverts = 0;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_ERROR_DEGENERATE);
    m.nverts = nv;
    m.X[4] = 0;
    s.nbones = 0;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) != SINEW_OK);
    s.nbones = 3;
    sw_skeleton_free(&s);
    sw_tetmesh_free(&m);
}

/* ---- driven vertices -------------------------------------------------------------- */

TEST(bone_vertices_box) {
    const int nx = 13, ny = 7, nz = 7;
    const double h = 0.25, L = (nx - 1) * h;
    sw_tetmesh m = {0};
    sw_skeleton s = {0};
    sw_weights w = {0};
    sw_error err = {0};
    make_box(nx, ny, nz, h, &m);
    make_axis_skeleton(L, &s);
    ENSUREF(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK, "%s", err.msg);
    int32_t *bov = malloc(sizeof(int32_t) * m.nverts), *again = malloc(sizeof(int32_t) * m.nverts);
    ENSUREF(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(sw_select_bone_vertices(&m, &s, &w, again, &err) == SINEW_OK);
    ENSURE(memcmp(bov, again, sizeof(int32_t) * m.nverts) == 0); /* deterministic */
    int count[2] = {0, 0};
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                int v = i + nx * (j + ny * k);
                int on_surface =
                    i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1;
                ENSURE(bov[v] >= -1 && bov[v] < 2);
                if (bov[v] < 0) continue;
                ENSUREF(!on_surface, "surface vertex %d is driven", v);
                count[bov[v]]++;
                /* flesh radius is 0.75; driven vertices lie within 40% of it of the axis */
                double r = sqrt(m.X[3 * v + 1] * m.X[3 * v + 1] + m.X[3 * v + 2] * m.X[3 * v + 2]);
                ENSUREF(r <= 0.4 * 0.75 + 1e-12, "vertex %d at radius %g", v, r);
                ENSURE(bov[v] == (m.X[3 * v] > 0.5 * L ? 1 : 0) ||
                       fabs(m.X[3 * v] - 0.5 * L) < 1e-12);
            }
    fprintf(stderr, "  box: %d and %d driven vertices\n", count[0], count[1]);
    ENSURE(count[0] >= 4 && count[1] >= 4);
    free(bov);
    free(again);
    sw_weights_free(&w);
    sw_skeleton_free(&s);
    sw_tetmesh_free(&m);
}

static int double_cmp(const void *pa, const void *pb) {
    double a = *(const double *)pa, b = *(const double *)pb;
    return a < b ? -1 : a > b;
}

/* A bone whose segment ends at the edge of its flesh (a head whose bone sits at the neck):
 * bone 1 runs from x = -1 to the box's end face at x = 0 and dominates the whole box, so
 * no surface vertex it dominates lies beside its segment, and the nearest of them (the end
 * face's centre) is on it. Its flesh radius is then the median distance to its skin: it
 * drives a core of interior vertices within 40% of that, not just the one tet the
 * nearest skin (radius 0) left it with. */
TEST(bone_vertices_of_a_bone_at_the_edge_of_its_flesh) {
    sw_tetmesh m = {0};
    sw_skeleton s = {0};
    sw_weights w = {0};
    sw_error err = {0};
    make_box(13, 7, 7, 0.25, &m);
    make_axis_skeleton(1.0, &s);
    s.joints[0] = -2.0, s.joints[3] = -1.0, s.joints[6] = 0.0;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK);
    int32_t *bov = malloc(sizeof(int32_t) * m.nverts);
    double *d = malloc(sizeof(double) * m.nverts);
    ENSUREF(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_OK, "%s", err.msg);
    int nd = 0, driven = 0;
    for (int v = 0; v < m.nverts; ++v) { /* bone 1's skin: every box face vertex */
        double x = m.X[3 * v], y = m.X[3 * v + 1], z = m.X[3 * v + 2];
        ENSURE(w.w[2 * v + 1] > w.w[2 * v]);
        if (x == 0 || x == 3.0 || fabs(fabs(y) - 0.75) < 1e-12 || fabs(fabs(z) - 0.75) < 1e-12)
            d[nd++] = sqrt(x * x + y * y + z * z); /* to the segment's end (0, 0, 0) */
    }
    qsort(d, (size_t)nd, sizeof(double), double_cmp);
    const double radius = d[nd / 2];
    for (int v = 0; v < m.nverts; ++v) {
        if (bov[v] != 1) continue;
        driven++;
        const double *X = m.X + 3 * v;
        ENSUREF(sqrt(X[0] * X[0] + X[1] * X[1] + X[2] * X[2]) <= 0.4 * radius + 1e-12,
                "vertex %d is beyond 40%% of the median radius %g", v, radius);
    }
    fprintf(stderr, "  bone at the edge: median skin distance %.3f, %d driven vertices\n", radius,
            driven);
    ENSUREF(driven > 4, "%d driven vertices: the flesh is held by one tet", driven);
    free(d);
    free(bov);
    sw_weights_free(&w);
    sw_skeleton_free(&s);
    sw_tetmesh_free(&m);
}

/* Vertices driven by bone b, and whether they span 3-D (a tet of non-trivial volume). */
static int driven_span(const sw_tetmesh *m, const int32_t *bov, int b, int *count) {
    int ids[4096], n = 0;
    for (int v = 0; v < m->nverts && n < 4096; ++v)
        if (bov[v] == b) ids[n++] = v;
    *count = n;
    for (int i = 0; i < n; ++i) /* brute force: some 4 of them make a real tet */
        for (int j = i + 1; j < n; ++j)
            for (int k = j + 1; k < n; ++k)
                for (int l = k + 1; l < n; ++l)
                    if (fabs(sw_tet_signed_volume(m->X + 3 * ids[i], m->X + 3 * ids[j],
                                                  m->X + 3 * ids[k], m->X + 3 * ids[l])) > 1e-6)
                        return 1;
    return 0;
}

TEST(bone_vertices_top_up_and_errors) {
    /* A thin box, 3 vertices across: the only interior vertices lie on the axis, so each
     * bone's interior set is a line; the top-up has to add the nearest skin vertices. */
    sw_tetmesh m = {0};
    sw_skeleton s = {0};
    sw_weights w = {0};
    sw_error err = {0};
    int count[2];
    make_box(9, 3, 3, 0.25, &m);
    make_axis_skeleton(2.0, &s);
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK);
    int32_t *bov = malloc(sizeof(int32_t) * m.nverts);
    ENSUREF(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_OK, "%s", err.msg);
    for (int b = 0; b < 2; ++b)
        ENSURE(driven_span(&m, bov, b, &count[b]) && count[b] >= 4);
    int skin = 0;
    for (int v = 0; v < m.nverts; ++v) {
        int i = v % 9, j = (v / 9) % 3, k = v / 27;
        if (bov[v] >= 0 && !(j == 1 && k == 1)) skin++;
        if (j == 1 && k == 1 && i > 0 && i < 8) ENSURE(bov[v] >= 0); /* the axis is driven */
    }
    fprintf(stderr, "  thin box: %d and %d driven, %d of them on the skin\n", count[0], count[1],
            skin);
    ENSURE(skin == 4); /* per bone one vertex off the line and one off the plane, no more */
    sw_weights_free(&w);
    sw_tetmesh_free(&m);
    free(bov);
    /* A skeleton near one face: few interior vertices within its flesh radius (0.15),
     * more within its reach; each bone still gets 4 spanning interior vertices. */
    make_box(9, 7, 7, 0.25, &m);
    for (int j = 0; j < 3; ++j)
        s.joints[3 * j + 1] = 0.6;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK);
    bov = malloc(sizeof(int32_t) * m.nverts);
    ENSUREF(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_OK, "%s", err.msg);
    for (int b = 0; b < 2; ++b)
        ENSURE(driven_span(&m, bov, b, &count[b]) && count[b] >= 4);
    fprintf(stderr, "  off-centre: %d and %d driven vertices\n", count[0], count[1]);
    /* mismatched weights */
    w.nbones = 3;
    ENSURE(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    w.nbones = 2;
    free(bov);
    sw_weights_free(&w);
    sw_tetmesh_free(&m);
    /* one tet, two bones: after bone 0 takes the 4 vertices bone 1 has none left */
    make_box(2, 2, 2, 1.0, &m);
    m.ntets = 1;
    ENSURE(sw_weights_inverse_distance(&m, &s, &w, &err) == SINEW_OK);
    bov = malloc(sizeof(int32_t) * m.nverts);
    ENSURE(sw_select_bone_vertices(&m, &s, &w, bov, &err) == SINEW_ERROR_DEGENERATE);
    ENSUREF(strstr(err.msg, "bone 1"), "%s", err.msg);
    for (int v = 0; v < m.nverts; ++v)
        ENSURE(bov[v] == -1);
    free(bov);
    sw_weights_free(&w);
    sw_skeleton_free(&s);
    sw_tetmesh_free(&m);
}

/* ---- whole characters ------------------------------------------------------------- */

static void report_driven(const sw_character *c) {
    int driven = 0, min_per_bone = 1 << 30;
    for (int v = 0; v < c->mesh.nverts; ++v)
        driven += c->bone_of_vertex[v] >= 0;
    for (int b = 0; b < c->skel.nbones; ++b) {
        int n = 0;
        for (int v = 0; v < c->mesh.nverts; ++v)
            n += c->bone_of_vertex[v] == b;
        if (n < min_per_bone) min_per_bone = n;
    }
    fprintf(stderr, "  %s: %d vertices, %d driven (fewest per bone %d), %d frames at %g fps\n",
            c->name, c->mesh.nverts, driven, min_per_bone, c->clip.nframes, c->clip.fps);
}

/* Driven vertices on the surface (-1 if the surface cannot be built). */
static int surface_vertices_driven(const sw_character *c) {
    sw_surface surf = {0};
    sw_error err = {0};
    if (sw_tetmesh_surface(&c->mesh, &surf, &err)) return -1;
    int n = 0;
    for (int k = 0; k < surf.nverts; ++k)
        n += c->bone_of_vertex[surf.verts[k]] >= 0;
    sw_surface_free(&surf);
    return n;
}

static int every_bone_driven(const sw_character *c, int atleast) {
    for (int b = 0; b < c->skel.nbones; ++b) {
        int n;
        if (!driven_span(&c->mesh, c->bone_of_vertex, b, &n) || n < atleast) return 0;
    }
    return 1;
}

TEST(dataset_elephant) {
    NEED_DATA("elephant-cd/elephant.mesh");
    sw_character c = {0};
    sw_error err = {0};
    ENSUREF(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "elephant-cd", 0, &c, &err) ==
                SINEW_OK,
            "%s", err.msg);
    ENSURE(strcmp(c.name, "elephant-cd") == 0);
    ENSURE(c.mesh.nverts == 494 && c.mesh.ntets == 1502 && c.skel.nbones == 24);
    ENSURE(c.clip.nframes == 457 && c.clip.nbones == 24 && c.clip.fps == 100.0);
    ENSURE(c.youngs == 3e5 && c.poisson == 0.4 && c.density == 1.0);
    ENSURE(every_bone_driven(&c, 4));
    report_driven(&c);
    /* 97 interior vertices for 24 bones, none near the thin limbs' bones: those limbs
     * borrow skin vertices (397 on the surface) */
    int skin = surface_vertices_driven(&c);
    fprintf(stderr, "  elephant: %d driven vertices on the surface\n", skin);
    ENSURE(skin >= 0 && skin <= 60);
    sw_character_free(&c);
    ENSURE(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "elephant-cd", 100, &c, &err) ==
           SINEW_OK);
    ENSURE(c.clip.nframes == 100);
    sw_character_free(&c);
}

TEST(dataset_hand) {
    NEED_DATA("hand-libigl/hand.mesh");
    sw_character c = {0};
    sw_error err = {0};
    ENSUREF(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "hand-libigl", 41, &c, &err) ==
                SINEW_OK,
            "%s", err.msg);
    ENSURE(c.mesh.nverts == 7234 && c.skel.nbones == 20 && c.weights.nbones == 20);
    ENSURE(c.clip.nframes == 41 && c.clip.fps == 30.0);
    ENSURE(c.youngs == 5000 && c.poisson == 0.08 && c.density == 1.0);
    ENSURE(every_bone_driven(&c, 4) && surface_vertices_driven(&c) == 0);
    report_driven(&c);
    /* the middle frame is the pose: FK of hand-pose.dmat's quaternions */
    int32_t rows, cols;
    double *q = NULL, local[9 * 20], T[12 * 20];
    ENSURE(sw_read_dmat(HAND_DIR "/hand-pose.dmat", &rows, &cols, &q, &err) == SINEW_OK);
    ENSURE(rows * cols == 80);
    for (int b = 0; b < 20; ++b) {
        double *qb = q + 4 * b,
               n = sqrt(qb[0] * qb[0] + qb[1] * qb[1] + qb[2] * qb[2] + qb[3] * qb[3]);
        for (int i = 0; i < 4; ++i)
            qb[i] /= n;
        quat_matrix(qb, local + 9 * b);
    }
    free(q);
    sw_forward_kinematics(&c.skel, local, NULL, T);
    for (int k = 0; k < 12 * 20; ++k)
        ENSURE_NEAR(c.clip.T[20 * 12 * 20 + k], T[k], 1e-12);
    sw_character_free(&c);
}

/* A joint range read from the hand's pose: rest, the pose (the dataset clip's middle
 * frame, bitwise), rest. A pose of another skeleton or not finite is refused, naming the
 * file, and the range read before is kept. */
TEST(joint_range_from_a_pose) {
    NEED_DATA("hand-libigl/hand.mesh");
    sw_character c = {0};
    sw_error err = {0};
    ENSURE(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "hand-libigl", 41, &c, &err) ==
           SINEW_OK);
    ENSUREF(sw_character_read_range(HAND_DIR "/hand-pose.dmat", &c, &err) == SINEW_OK, "%s",
            err.msg);
    ENSURE(c.range.nbones == 20 && c.range.nframes == 3);
    if (c.range.nframes == 3 && c.clip.nframes == 41)
        ENSURE(!memcmp(c.range.T + 12 * 20, c.clip.T + 20 * 12 * 20, sizeof(double) * 12 * 20) &&
               !memcmp(c.range.T, c.clip.T, sizeof(double) * 12 * 20));
    const char *bad[2] = {"19 quaternions", "nan"};
    for (int k = 0; k < 2; ++k) {
        FILE *f = fopen(TMP("range.dmat"), "wb");
        ENSURE(f);
        if (!f) break;
        fprintf(f, "1 %d\n", k ? 80 : 76);
        for (int i = 0; i < (k ? 80 : 76); ++i)
            fprintf(f, "%s\n", k && i == 5 ? "nan" : i % 4 == 3 ? "1" : "0");
        fclose(f);
        double *kept = c.range.T;
        ENSURE(sw_character_read_range(TMP("range.dmat"), &c, &err) != SINEW_OK);
        ENSUREF(strstr(err.msg, "range.dmat") != NULL, "%s: %s", bad[k], err.msg);
        ENSURE(c.range.T == kept && c.range.nframes == 3);
    }
    remove(TMP("range.dmat"));
    sw_character_free(&c);
}

TEST(corrupt_inputs) {
    sw_character c = {0};
    sw_error err = {0};
    ENSURE(sw_character_from_dataset(SINEW_SHARED_DATA_DIR, "dragon", 0, &c, &err) ==
           SINEW_ERROR_UNSUPPORTED);
    ENSURE(sw_character_from_dataset(TMP("nowhere"), "elephant-cd", 0, &c, &err) == SINEW_ERROR_IO);
    NEED_DATA("elephant-cd/elephant.mesh");
    /* weights with 23 columns instead of 24 */
    FILE *f = fopen(TMP("w23.dmat"), "wb");
    ENSURE(f);
    fprintf(f, "23 494\n");
    for (int k = 0; k < 23 * 494; ++k)
        fprintf(f, "%g\n", 1.0 / 23);
    fclose(f);
    sinew_result rc =
        sw_character_from_files(ELEPHANT_DIR "/elephant.mesh", ELEPHANT_DIR "/elephant.tgf",
                                TMP("w23.dmat"), ELEPHANT_DIR "/elephant_anim.txt", 0, &c, &err);
    remove(TMP("w23.dmat"));
    ENSURE(rc == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "w23.dmat"), "%s", err.msg);
    fprintf(stderr, "  wrong columns: %s\n", err.msg);
    ENSURE(c.mesh.X == NULL && c.weights.w == NULL && c.bone_of_vertex == NULL);
    /* an animation for a skeleton of 23 bones */
    ENSURE(write_text(TMP("anim23.txt"), "23 1\n0 0 0\n0 0 0\n"));
    rc = sw_character_from_files(ELEPHANT_DIR "/elephant.mesh", ELEPHANT_DIR "/elephant.tgf",
                                 ELEPHANT_DIR "/elephant.dmat", TMP("anim23.txt"), 0, &c, &err);
    remove(TMP("anim23.txt"));
    ENSURE(rc == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "anim23.txt:1:") && strstr(err.msg, "23 bones"), "%s", err.msg);
    /* unknown motion format, and a pose of the wrong size */
    rc = sw_character_from_files(ELEPHANT_DIR "/elephant.mesh", ELEPHANT_DIR "/elephant.tgf", NULL,
                                 ELEPHANT_DIR "/elephant.json", 0, &c, &err);
    ENSURE(rc == SINEW_ERROR_UNSUPPORTED);
    NEED_DATA("hand-libigl/hand-pose.dmat");
    rc = sw_character_from_files(ELEPHANT_DIR "/elephant.mesh", ELEPHANT_DIR "/elephant.tgf", NULL,
                                 HAND_DIR "/hand-pose.dmat", 5, &c, &err);
    ENSURE(rc == SINEW_ERROR_PARSE);
    ENSUREF(strstr(err.msg, "hand-pose.dmat") && strstr(err.msg, "96 x 1"), "%s", err.msg);
}

/* A character from a render surface (arm-libigl's .obj) filled by the lattice mesher:
 * the generated mesh is valid, every bone drives some of it, weights are rows of 1, and a
 * surface that is not a file or encloses nothing gives an error naming it. */
TEST(surface_arm) {
    NEED_DATA("arm-libigl/arm.obj");
    sw_character c = {0};
    sw_error err = {0};
    sw_mesher_report rep;
    ENSUREF(sw_character_from_surface(
                SINEW_SHARED_DATA_DIR "/arm-libigl/arm.obj", 3000, SW_MESHER_LATTICE,
                SINEW_SHARED_DATA_DIR "/arm-libigl/arm.tgf", NULL, 4, &c, &rep, &err) == SINEW_OK,
            "%s", err.msg);
    ENSURE(c.mesh.ntets >= 2000 && c.mesh.ntets <= 4500 && c.skel.nbones == 4);
    ENSURE(sw_tetmesh_validate(&c.mesh, 0.0, &err) == SINEW_OK);
    ENSURE(every_bone_driven(&c, 1));
    for (int32_t v = 0; v < c.weights.nverts; ++v) {
        double sum = 0;
        for (int32_t b = 0; b < c.weights.nbones; ++b)
            sum += c.weights.w[(size_t)v * c.weights.nbones + b];
        ENSURE(fabs(sum - 1) < 1e-9);
    }
    ENSURE(strcmp(c.name, "arm") == 0 && c.clip.nframes == 4);
    fprintf(stderr, "    arm: %d tets, %d vertices, spacing %.4g, %d component(s)\n", c.mesh.ntets,
            c.mesh.nverts, rep.lattice.spacing, rep.lattice.components);
    sw_character_free(&c);
    ENSURE(sw_character_from_surface(SINEW_SHARED_DATA_DIR "/arm-libigl/none.obj", 3000,
                                     SW_MESHER_LATTICE, SINEW_SHARED_DATA_DIR "/arm-libigl/arm.tgf",
                                     NULL, 4, &c, NULL, &err) == SINEW_ERROR_IO);
    ENSURE(strstr(err.msg, "none.obj") != NULL && c.mesh.ntets == 0);
    ENSURE(sw_character_from_surface(SINEW_SHARED_DATA_DIR "/arm-libigl/arm.obj", 10,
                                     SW_MESHER_LATTICE, SINEW_SHARED_DATA_DIR "/arm-libigl/arm.tgf",
                                     NULL, 4, &c, NULL, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(strstr(err.msg, "arm.obj") != NULL);
}

SW_TEST_MAIN(CASE(cd_anim_semantics), CASE(cd_anim_malformed), CASE(cd_anim_elephant),
             CASE(pose_clip), CASE(inverse_distance_weights), CASE(bone_vertices_box),
             CASE(bone_vertices_top_up_and_errors),
             CASE(bone_vertices_of_a_bone_at_the_edge_of_its_flesh), CASE(dataset_elephant),
             CASE(dataset_hand), CASE(joint_range_from_a_pose), CASE(corrupt_inputs),
             CASE(surface_arm))
