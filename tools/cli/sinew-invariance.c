/* sinew-invariance: does where the character stands, faces or how it is scaled change its
 * flesh? (DESIGN.md §3, invariance.h)
 *
 *   sinew-invariance (FILE.glb [--tets N] ... | --scene NAME [--tets N] [--frames F] |
 *                     --mesh ... as sinew-bake) --blob FILE [--frames-max K] [--seed S]
 *                    [--reach D] [--angle A] [--world FILE] [--fold S] [--novel-contact]
 *                    [--json]
 *
 * Plays the character's clip (and a glTF/FBX FILE's held-out clips after it, at most K
 * frames in all, default 120; with --fold S then 16 frames bending the joints of its most
 * bent frame on to S times as far) in two instances of the blob, the second carried by a
 * motion of the whole pose, and prints for each case the largest distance of an output
 * vertex from where it should be, as a share of the character's size:
 *   rigid_<mode>     quasistatic, one random rigid motion (any axis, up to 180 degrees,
 *                    a translation up to --reach D units, 10^5 by default) on every
 *                    bone (double poses), in each self-contact mode: pose_space,
 *                    pose_pairs, exhaustive
 *   turning          quasistatic, turning 4 degrees a frame about a random axis while
 *                    walking away
 *   dynamic          dynamic mode, one random rigid motion
 *   far_actor        the actor D units from the origin, turned (sinew_instance_set_actor),
 *                    float poses in its frame, the float surface read in its frame
 *   scale_0.01, scale_100
 *                    the pose scaled uniformly (float poses and surface)
 * With --world FILE (a world file, samples/worlds) also, its colliders held at their
 * frame-0 placements and, for the second instance, carried by the motion too (a rigid
 * motion of the same turn moved by at most 10 units: float collider placements):
 *   world_quasistatic, world_dynamic, world_patch
 *                    quasistatic, dynamic, and quasistatic with condensation patches (a
 *                    budget of a quarter of the vertices)
 * With --novel-contact every case runs with sinew_instance_def.novel_contact on (the
 * pose-pairs and exhaustive cases, which refuse it, are left out), and each line counts
 * the novel contacts both instances found: a case where neither found any says nothing
 * about the novel path. A self-contact mode the blob refuses (pose pairs where the bake
 * kept none; exhaustive without the tet mesh) is skipped, the runtime's reason printed.
 * The last stdout line is one JSON object. Exit status: 0 done, 1 failed, 2 bad arguments. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SW_TOOL_CHARACTER_ARGS
#include "tool_common.h"

#include "invariance.h"
#include "world_io.h"

static const char *const TOOL = "sinew-invariance";

typedef struct {
    const char *blob_path, *world_path;
    int kmax, seed, json, novel;
    double far, angle, fold;
} options;

static const char *const SYNOPSIS =
    "sinew-invariance (FILE [--tets N] [--train-clips A,B] [--heldout-clips C] |\n"
    "                         --scene NAME [--tets N] [--frames F] [--data DIR] |\n"
    "                         --mesh FILE --skeleton FILE.tgf [--weights FILE.dmat]\n"
    "                         [--clip FILE [--frames F]])\n"
    "                        --blob FILE [--frames-max K] [--seed S] [--novel-contact]\n"
    "                        [--json]\n";

static int parse_args(int argc, char **argv, sw_character_args *ca, options *o) {
    *o = (options){.kmax = 120, .seed = 1, .far = 1e5, .angle = -1};
    const sw_flag flags[] = {
        {SW_STR("--blob", &o->blob_path, "FILE", "the blob sinew-bake wrote for this character")},
        {SW_INT("--frames-max", &o->kmax, 1, 100000, "K",
                "clip frames played, 1..100000 (default 120)")},
        {SW_INT("--seed", &o->seed, 1, 2147483647, "S",
                "the random motions' seed, 1..2^31 (default 1)")},
        {SW_REAL("--reach", &o->far, -1e-300, 1e7, "in 0 <= D <= 1e7", "D",
                 "the rigid motions' and the actor's translation, up to D\n"
                 "units on each axis, 0..1e7 (default 1e5)")},
        {SW_REAL("--angle", &o->angle, 0, 180.0000001, "in 0 < A <= 180", "A",
                 "the rigid motions' turn, degrees (default: random in 90..180;\n"
                 "a tiny one tells rounding's effect from the heading's)")},
        {SW_STR("--world", &o->world_path, "FILE",
                "also with this world file's colliders (at frame 0), carried\n"
                "by the motion: world_quasistatic, world_dynamic, world_patch")},
        {SW_REAL("--fold", &o->fold, 1, 4.0000001, "in 1 < S <= 4", "S",
                 "after the clip, 16 frames bending the joints of its most\n"
                 "bent frame on to S times as far (at most 170 degrees a\n"
                 "joint): self-contact past the training (default: none)")},
        {SW_SET("--novel-contact", &o->novel, 1,
                "every case with novel self-contact detection on\n"
                "(sinew_instance_def.novel_contact; the pose-pairs and\n"
                "exhaustive cases are left out)")},
        {SW_SET("--json", &o->json, 1, "the figures as one JSON object on the last line")},
    };
    sw_flag character[SW_CHARACTER_NFLAGS];
    const sw_flag_group groups[] = {
        {"character:\n" SW_CHARACTER_FILE_USAGE, character, sw_character_flags(ca, character)},
        {"invariance:", flags, SW_FLAGS_N(flags)}};
    const sw_tool_cli cli = {TOOL, SYNOPSIS, groups, SW_FLAGS_N(groups), NULL, &ca->file, 1};
    if (sw_flags_parse(&cli, argc, argv)) return 2;
    if (!sw_character_args_valid(ca)) return 2;
    if (!o->blob_path) {
        fprintf(stderr, "%s: --blob FILE is needed (bake it with sinew-bake)\n", TOOL);
        return 2;
    }
    return 0;
}

static unsigned long long rng = 1;
static double urand(void) { /* xorshift64* */
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (double)((rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* A random rigid motion: a uniform axis, a turn in (90, 180] degrees, a translation up to
 * `reach` on each axis. */
static sw_move random_rigid(double reach) {
    sw_move m = {0};
    m.kind = SW_MOVE_RIGID;
    double z = 2 * urand() - 1, a = 6.283185307179586 * urand(), r = sqrt(1 - z * z);
    m.axis[0] = r * cos(a), m.axis[1] = r * sin(a), m.axis[2] = z;
    m.angle = 3.141592653589793 * (0.5 + 0.5 * urand());
    for (int k = 0; k < 3; ++k)
        m.shift[k] = reach * (2 * urand() - 1);
    return m;
}

typedef struct {
    const char *name;
    sw_invariance_result res;
} row;

/* The world file's colliders at frame 0 into *w, and carried by m's motion into *wm. */
static int load_worlds(const char *path, const sw_move *m, sinew_world **w, sinew_world **wm) {
    sw_world_file f;
    sw_error err;
    sw_error_clear(&err);
    if (sw_world_file_read(path, &f, &err) != SINEW_OK) {
        fprintf(stderr, "%s: %s\n", TOOL, err.msg);
        return 0;
    }
    double G[12];
    sw_move_transform(m, 0, G);
    sinew_world_def wd = sinew_world_def_default();
    int ok = sinew_world_create(&wd, w) == SINEW_OK && sinew_world_create(&wd, wm) == SINEW_OK;
    for (int32_t c = 0; ok && c < f.ncolliders; ++c) {
        sinew_collider_def d = f.colliders[c].def;
        sinew_collider_id id;
        double pos[3], rot[4]; /* carried in doubles, as a host with a double world */
        int placed = sw_move_placement(G, &d, pos, rot);
        ok = sinew_world_add_collider(*w, &d, &id) == SINEW_OK;
        sw_move_collider(G, &d);
        ok = ok && sinew_world_add_collider(*wm, &d, &id) == SINEW_OK;
        if (ok && placed) ok = sinew_world_set_collider_transform_d(*wm, id, pos, rot) == SINEW_OK;
    }
    sw_world_file_free(&f);
    if (!ok) fprintf(stderr, "%s: %s: the world's colliders could not be built\n", TOOL, path);
    return ok;
}

enum { FOLD_FRAMES = 16 };

/* The rotation angle of R (row-major) and its unit axis (any when the angle is 0). */
static double rotation_angle(const double R[9], double k[3]) {
    k[0] = R[7] - R[5], k[1] = R[2] - R[6], k[2] = R[3] - R[1];
    double s = sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
    double a = atan2(0.5 * s, 0.5 * (R[0] + R[4] + R[8] - 1));
    for (int i = 0; i < 3; ++i)
        k[i] = s > 0 ? k[i] / s : (i == 2);
    return a;
}

/* Bone b of frame T bent `by` times as far at its head joint, its parent already in out
 * (done[] marks the bones written): out_b = out_p (h + L^by (x - h)), L the joint's
 * rotation (R_p^T R_b), h the head joint's rest position; a root stays as it is. */
static void fold_bone(const sw_skeleton *sk, const double *T, double by, int32_t b, char *done,
                      double *out) {
    if (done[b]) return;
    const double *Tb = T + 12 * b;
    double *o = out + 12 * b;
    int32_t p = sk->parent[b];
    done[b] = 1;
    if (p < 0) {
        memcpy(o, Tb, 12 * sizeof(double));
        return;
    }
    fold_bone(sk, T, by, p, done, out);
    const double *Tp = T + 12 * p, *h = sk->joints + 3 * sk->bones[2 * b];
    double L[9], k[3], R[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            L[3 * i + j] = Tp[i] * Tb[j] + Tp[3 + i] * Tb[3 + j] + Tp[6 + i] * Tb[6 + j];
    double a = fmin(by * rotation_angle(L, k), 170 * 3.141592653589793 / 180);
    double c = cos(a), s = sin(a), C = 1 - c, u[3];
    double M[9] = {
        c + k[0] * k[0] * C,        k[0] * k[1] * C - k[2] * s, k[0] * k[2] * C + k[1] * s,
        k[1] * k[0] * C + k[2] * s, c + k[1] * k[1] * C,        k[1] * k[2] * C - k[0] * s,
        k[2] * k[0] * C - k[1] * s, k[2] * k[1] * C + k[0] * s, c + k[2] * k[2] * C};
    for (int i = 0; i < 3; ++i) /* the bent joint's map: M x + u, u = h - M h */
        u[i] = h[i] - (M[3 * i] * h[0] + M[3 * i + 1] * h[1] + M[3 * i + 2] * h[2]);
    const double *Op = out + 12 * p;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            R[3 * i + j] = Op[3 * i] * M[j] + Op[3 * i + 1] * M[3 + j] + Op[3 * i + 2] * M[6 + j];
        o[9 + i] = Op[9 + i] + Op[3 * i] * u[0] + Op[3 * i + 1] * u[1] + Op[3 * i + 2] * u[2];
    }
    memcpy(o, R, sizeof R);
}

/* FOLD_FRAMES frames after frame n - 1 of T taking the most bent of the n frames (the
 * largest sum of joint angles) from once to `by` times its bends (at most 170 degrees a
 * joint): past any training, into self-contact the bake never saw. */
static void fold_frames(const sw_skeleton *sk, double *T, int32_t n, double by) {
    int32_t nb = sk->nbones, most = 0;
    size_t per = (size_t)12 * nb;
    double best = -1;
    for (int32_t f = 0; f < n; ++f) {
        double sum = 0, k[3], L[9];
        for (int32_t b = 0; b < nb; ++b) {
            const double *Tb = T + per * f + 12 * b, *Tp = T + per * f + 12 * sk->parent[b];
            if (sk->parent[b] < 0) continue;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    L[3 * i + j] = Tp[i] * Tb[j] + Tp[3 + i] * Tb[3 + j] + Tp[6 + i] * Tb[6 + j];
            sum += rotation_angle(L, k);
        }
        if (sum > best) best = sum, most = f;
    }
    char *done = calloc((size_t)nb, 1);
    for (int32_t s = 1; done && s <= FOLD_FRAMES; ++s) {
        memset(done, 0, (size_t)nb);
        for (int32_t b = 0; b < nb; ++b)
            fold_bone(sk, T + per * most, 1 + (by - 1) * s / FOLD_FRAMES, b, done,
                      T + per * (n + s - 1));
    }
    free(done);
}

/* The clip the runs play: the character's, then a FILE's held-out clips, at most kmax
 * frames, then the fold (fold > 1: FOLD_FRAMES more) (malloc'd, *frames set). */
static double *play_clip(const sw_character *ch, const sw_clip_split *clips, int kmax, double fold,
                         int32_t *frames) {
    int32_t nb = ch->skel.nbones, n = 0;
    size_t per = (size_t)12 * nb;
    double *T = malloc(((size_t)kmax + FOLD_FRAMES) * per * sizeof(double));
    if (!T) return NULL;
    for (int32_t f = 0; f < ch->clip.nframes && n < kmax; ++f)
        memcpy(T + per * n++, ch->clip.T + per * f, per * sizeof(double));
    for (int32_t c = 0; clips && c < clips->nheldout; ++c)
        for (int32_t f = 0; f < clips->heldout[c].nframes && n < kmax; ++f)
            memcpy(T + per * n++, clips->heldout[c].T + per * f, per * sizeof(double));
    if (fold > 1 && n > 0) {
        fold_frames(&ch->skel, T, n, fold);
        n += FOLD_FRAMES;
    }
    *frames = n;
    return T;
}

/* The motions of the whole pose the cases carry the second instance by. */
typedef struct {
    sw_move rigid, turning, actor, s_small, s_big, near;
} moves;

static moves make_moves(const options *o) {
    moves m = {.s_small = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, 0.01, 1, 1},
               .s_big = {SW_MOVE_SCALE, {0, 0, 1}, 0, {0, 0, 0}, 100, 1, 1}};
    m.rigid = random_rigid(o->far); /* in this order: one stream of random numbers */
    m.turning = random_rigid(0);
    m.actor = random_rigid(o->far);
    if (o->angle > 0) m.rigid.angle = m.actor.angle = o->angle * 3.141592653589793 / 180;
    m.turning.kind = SW_MOVE_TURNING;
    m.turning.angle = 4 * 3.141592653589793 / 180;
    for (int k = 0; k < 3; ++k) /* walking away: a tenth of a unit a frame */
        m.turning.shift[k] = 0.1 * (2 * urand() - 1);
    m.actor.kind = SW_MOVE_ACTOR;
    m.actor.float_poses = m.actor.float_output = 1;
    m.near = m.rigid;
    for (int k = 0; k < 3; ++k) /* float collider placements: within 10 units */
        m.near.shift[k] = fmax(-10, fmin(10, m.near.shift[k]));
    return m;
}

/* One case's line on stderr; *novel_least the fewest novel contacts either instance of a
 * case found so far. */
static void print_case(const row *w, int frames, int novel, int64_t *novel_least) {
    fprintf(stderr,
            "%s: %-18s %.3e of the size (frame %d of %d), %d failed steps, %d short of "
            "tolerance, %lld world contacts, largest patch %u",
            TOOL, w->name, w->res.err, w->res.worst_frame, frames, w->res.failed,
            w->res.unconverged, (long long)w->res.world_contacts, w->res.patch_vertices);
    if (novel) {
        fprintf(stderr, ", novel contacts %lld / %lld", (long long)w->res.novel_contacts,
                (long long)w->res.novel_moved);
        int64_t least =
            w->res.novel_contacts < w->res.novel_moved ? w->res.novel_contacts : w->res.novel_moved;
        if (*novel_least < 0 || least < *novel_least) *novel_least = least;
    }
    fprintf(stderr, "\n");
}

int main(int argc, char **argv) {
    sw_character_args ca;
    sw_character_args_init(&ca, TOOL);
    options o;
    if (parse_args(argc, argv, &ca, &o)) return 2;
    rng = (unsigned long long)o.seed * 0x9E3779B97F4A7C15ull | 1;
    sw_character ch;
    sw_clip_split clips;
    sw_error err;
    sinew_result r = sw_character_args_make(&ca, &ch, &clips, NULL, &err);
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "%s: ", TOOL);
    sinew_blob_def bd = sinew_blob_def_default();
    bd.path = o.blob_path;
    sinew_blob *blob = NULL;
    if (sw_tool_blob_load(TOOL, o.blob_path, bd, &blob) != SINEW_OK) return 1;
    int32_t frames = 0, nb = ch.skel.nbones;
    double *clip = play_clip(&ch, &clips, o.kmax, o.fold, &frames);
    if (!clip || frames < 1) {
        fprintf(stderr, "%s: the character has no clip to play\n", TOOL);
        return 1;
    }
    float dt = (float)(1.0 / (ch.clip.fps > 0 ? ch.clip.fps : 30));
    const moves m = make_moves(&o);
    sinew_world *world = NULL, *moved = NULL;
    if (o.world_path && !load_worlds(o.world_path, &m.near, &world, &moved)) return 1;
    uint32_t quarter = sinew_blob_surface_vertex_count(blob) / 4 + 1;
    struct {
        const char *name;
        sinew_step_mode mode;
        sinew_self_contact sc;
        const sw_move *m;
        const sinew_world *w, *wm;
        uint32_t patch;
    } cases[] = {
        {"rigid_pose_space", SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_POSE_SPACE, &m.rigid, NULL,
         NULL, 0},
        {"rigid_pose_pairs", SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_POSE_PAIRS, &m.rigid, NULL,
         NULL, 0},
        {"rigid_exhaustive", SINEW_STEP_QUASISTATIC, SINEW_SELF_CONTACT_EXHAUSTIVE, &m.rigid, NULL,
         NULL, 0},
        {"turning", SINEW_STEP_QUASISTATIC, 0, &m.turning, NULL, NULL, 0},
        {"dynamic", SINEW_STEP_DYNAMIC, 0, &m.rigid, NULL, NULL, 0},
        {"far_actor", SINEW_STEP_QUASISTATIC, 0, &m.actor, NULL, NULL, 0},
        {"scale_0.01", SINEW_STEP_QUASISTATIC, 0, &m.s_small, NULL, NULL, 0},
        {"scale_100", SINEW_STEP_QUASISTATIC, 0, &m.s_big, NULL, NULL, 0},
        {"world_quasistatic", SINEW_STEP_QUASISTATIC, 0, &m.near, world, moved, 0},
        {"world_dynamic", SINEW_STEP_DYNAMIC, 0, &m.near, world, moved, 0},
        {"world_patch", SINEW_STEP_QUASISTATIC, 0, &m.near, world, moved, quarter},
    };
    enum { NCASES = sizeof cases / sizeof cases[0] };
    row rows[NCASES];
    double worst = 0;
    long failed = 0;
    int ncases = world ? NCASES : NCASES - 3, nrows = 0;
    int64_t novel_least = -1;
    for (int c = 0; c < ncases; ++c) {
        if (o.novel && cases[c].sc != 0 && cases[c].sc != SINEW_SELF_CONTACT_POSE_SPACE)
            continue; /* novel contact adds to pose-space self-contact alone */
        sw_invariance_run run = {cases[c].mode,  cases[c].sc,       cases[c].w, cases[c].wm, dt,
                                 cases[c].patch, (uint32_t)o.novel, 0};
        row *w = &rows[nrows++];
        w->name = cases[c].name;
        r = sw_invariance_measure(blob, clip, nb, frames, &run, cases[c].m, &w->res);
        if (r == SINEW_ERROR_INVALID_ARGUMENT && cases[c].sc != 0 &&
            cases[c].sc != SINEW_SELF_CONTACT_POSE_SPACE) { /* the runtime said why, above */
            fprintf(stderr, "%s: %-18s skipped: the blob refuses this self-contact mode\n", TOOL,
                    cases[c].name);
            nrows--;
            continue;
        }
        if (r != SINEW_OK) {
            fprintf(stderr, "%s: case %s failed: %s\n", TOOL, cases[c].name,
                    sinew_result_string(r));
            return 1;
        }
        worst = fmax(worst, w->res.err);
        failed += w->res.failed;
        print_case(w, frames, o.novel, &novel_least);
    }
    if (o.json) {
        printf("{\"frames\":%d,\"size\":%.9g,\"worst\":%.4e,\"failed_steps\":%ld", frames,
               rows[0].res.size, worst, failed);
        if (o.novel) printf(",\"novel_contacts_least\":%lld", (long long)novel_least);
        for (int c = 0; c < nrows; ++c)
            printf(",\"%s\":%.4e", rows[c].name, rows[c].res.err);
        printf("}\n");
    }
    free(clip);
    sinew_world_destroy(world);
    sinew_world_destroy(moved);
    sinew_blob_destroy(blob);
    sw_clip_split_free(&clips);
    sw_character_free(&ch);
    return 0;
}
