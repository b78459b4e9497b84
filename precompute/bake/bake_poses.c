/* Stage "poses" (bake.c, sw_bake_stages): reads s->rig, s->domains and the clips; writes s->poses
 * (the pose sequences the simulate stage solves, bake_simulate.c). */
/* Training and held-out poses (DESIGN.md §5).
 * Training: the first (1 - heldout) frames of the clip (evenly subsampled), or with
 * training clips of their own (sw_bake_params.train_clips: a glTF file's clips) each of
 * them as its own path from rest, with
 * return_path (by default where the held-out frames continue the training clip) the way
 * home from the first one's last frame (its earlier frames
 * backwards, each bent less than the one before: a fold that buckled on the way in can
 * stay buckled on the way out, and the runtime picks the branch by the direction the
 * pose arrives from), per joint, a sweep from rest to
 * the largest rotation the training frames give it, and the caller's extra poses
 * (sw_bake_params.extra_poses: the adaptive loop's) in paths from rest.
 * Held-out: the clip's remaining frames, or the held-out clips one after the other on
 * one path from rest, never used to build the basis or cubature; without a clip, random combined
 * poses with a fixed seed, each reached from the one before in heldout_steps poses. Each sequence
 * is solved in order, every solve warm-starting the next (bake_simulate.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "mat3.h"
#include "pose_space.h"
#include "vec3.h"

/* Rotation part of a clip's bone transform relative to its parent: L = R_p^T R_b. */
static void local_rotation(const sw_skeleton *sk, const double *T, int32_t b, double L[9]) {
    const double *Rb = T + 12 * b;
    int32_t p = sk->parent[b];
    if (p < 0) {
        memcpy(L, Rb, 9 * sizeof(double));
        return;
    }
    const double *Rp = T + 12 * p;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            L[3 * i + j] = Rp[i] * Rb[j] + Rp[3 + i] * Rb[3 + j] + Rp[6 + i] * Rb[6 + j];
}

/* Axis-angle of a rotation matrix (angle in [0, pi]). The angle is atan2(sin, cos) of
 * the skew part's length (2 sin) and the trace (1 + 2 cos): acos of the trace alone
 * loses half the digits near 0 and pi (a 1e-8 rad turn reads as 0 or 1.5e-8). */
static double rotation_axis_angle(const double R[9], double axis[3]) {
    double a[3] = {R[7] - R[5], R[2] - R[6], R[3] - R[1]};
    double n = sw_v3_norm(a);
    double angle = atan2(0.5 * n, 0.5 * (R[0] + R[4] + R[8] - 1.0));
    if (n < 1e-12) { /* angle 0 or pi: take the column of the largest diagonal of R + I */
        int k = R[0] >= R[4] && R[0] >= R[8] ? 0 : R[4] >= R[8] ? 1 : 2;
        for (int i = 0; i < 3; ++i)
            a[i] = R[3 * i + k] + (i == k ? 1.0 : 0.0);
        n = sw_v3_norm(a);
        if (n < 1e-12) {
            a[0] = 1;
            a[1] = a[2] = 0;
            n = 1;
        }
    }
    for (int i = 0; i < 3; ++i)
        axis[i] = a[i] / n;
    return angle;
}

static int seq_alloc(sw_pose_seq *q, int32_t npose, int32_t nb, int32_t nv) {
    q->npose = npose;
    q->T = malloc((size_t)npose * 12 * nb * sizeof(double));
    q->x = malloc((size_t)npose * 3 * nv * sizeof(double));
    q->contact_ptr = calloc((size_t)npose + 1, sizeof(int32_t));
    q->clip = malloc(((size_t)npose + 1) * sizeof(int32_t));
    q->frame = malloc(((size_t)npose + 1) * sizeof(int32_t));
    if (!q->T || !q->x || !q->contact_ptr || !q->clip || !q->frame) return 0;
    for (int32_t i = 0; i < npose; ++i)
        q->clip[i] = q->frame[i] = -1; /* not a clip frame until filled from one */
    return 1;
}

static uint64_t splitmix(uint64_t *s) {
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

int32_t sw_bake_min_frames(double heldout_fraction) {
    for (int32_t f = 2; f < 1000000; ++f)
        if ((int32_t)floor(f * (1.0 - heldout_fraction)) >= 2) return f;
    return 1000000;
}

/* A run of clip frames that becomes a pose sequence: frames [first, first + count) of
 * `clip`, labelled `label` (the clip's index) in the result. */
typedef struct clip_range {
    const sw_clip *clip;
    int32_t first, count, label;
} clip_range;

/* n frames of r spread evenly (its first and last included) into q's poses [at, at + n). */
static void fill_from_range(sw_pose_seq *q, int32_t at, const clip_range *r, int32_t n,
                            int32_t nb) {
    for (int32_t i = 0; i < n; ++i) {
        int32_t f = r->first + (n == 1 ? 0 : (int32_t)((int64_t)i * (r->count - 1) / (n - 1)));
        memcpy(q->T + (size_t)(at + i) * 12 * nb, r->clip->T + (size_t)f * 12 * nb,
               12 * nb * sizeof(double));
        q->clip[at + i] = r->label;
        q->frame[at + i] = f;
    }
}

/* The training and held-out clip ranges: the given clips (params train_clips,
 * heldout_clips), or the first (1 - heldout_fraction) of the character's clip and the
 * rest. Returns the number of training ranges; *nheld the held-out ones. */
static int32_t clip_ranges(const sw_bake_state *s, clip_range *train, clip_range *held,
                           int32_t *nheld) {
    const sw_bake_params *p = s->p;
    int32_t nb = s->rig.nb, ntr = 0;
    *nheld = 0;
    if (p->ntrain_clips > 0) {
        for (int32_t i = 0; i < p->ntrain_clips; ++i)
            if (p->train_clips[i].nbones == nb && p->train_clips[i].nframes > 0)
                train[ntr++] = (clip_range){&p->train_clips[i], 0, p->train_clips[i].nframes, i};
        for (int32_t i = 0; i < p->nheldout_clips; ++i)
            if (p->heldout_clips[i].nbones == nb && p->heldout_clips[i].nframes > 0)
                held[(*nheld)++] =
                    (clip_range){&p->heldout_clips[i], 0, p->heldout_clips[i].nframes, i};
        return ntr;
    }
    const sw_clip *clip = &s->rig.ch.clip;
    int32_t nf = clip->T && clip->nbones == nb ? clip->nframes : 0;
    int32_t ntf = nf >= 2 ? (int32_t)floor(nf * (1.0 - p->heldout_fraction)) : 0;
    if (nf >= 2 && ntf < 1) ntf = 1;
    if (ntf > 0) train[ntr++] = (clip_range){clip, 0, ntf, 0};
    if (nf - ntf > 0 && nf >= 2) held[(*nheld)++] = (clip_range){clip, ntf, nf - ntf, 0};
    return ntr;
}

void sw_bake_joint_reach(const sw_skeleton *sk, const double *T, int32_t n, double *angle,
                         double *axis) {
    int32_t nb = sk->nbones;
    for (int32_t f = 0; f < n; ++f)
        for (int32_t b = 0; b < nb; ++b) {
            if (sk->parent[b] < 0) continue;
            double L[9], ax[3];
            local_rotation(sk, T + (size_t)f * 12 * nb, b, L);
            double a = rotation_axis_angle(L, ax);
            if (a > angle[b]) {
                angle[b] = a;
                if (axis) memcpy(axis + 3 * b, ax, sizeof ax);
            }
        }
}

int32_t sw_bake_beyond_training(const sw_bake_result *r, const sw_skeleton *sk, sw_joint_reach *out,
                                int32_t max) {
    int32_t nb = sk->nbones, n = 0, total = 0;
    double *reach = calloc((size_t)nb + 1, sizeof(double));
    if (!reach) return -1;
    if (r->heldout_T && r->sweep_angle)
        sw_bake_joint_reach(sk, r->heldout_T, r->nheldout, reach, NULL);
    const double deg = 57.29577951308232;
    for (int32_t b = 0; b < nb; ++b) {
        double h = reach[b] * deg, t = r->sweep_angle ? r->sweep_angle[b] * deg : 0;
        if (!sw_joint_beyond_training(reach[b], r->sweep_angle ? r->sweep_angle[b] : 0)) continue;
        sw_joint_reach j = {b, h, t};
        total++;
        int32_t k = n < max ? n++ : max; /* insertion by multiple of the trained bend */
        while (k > 0 && h * out[k - 1].train_deg > out[k - 1].heldout_deg * t) {
            if (k < max) out[k] = out[k - 1];
            --k;
        }
        if (k < max) out[k] = j;
    }
    free(reach);
    return total;
}

int32_t sw_bake_pose_beyond(const sw_skeleton *sk, const double *T, const double *trained) {
    double *bend = calloc((size_t)sk->nbones + 1, sizeof(double));
    if (!bend) return -1;
    sw_bake_joint_reach(sk, T, 1, bend, NULL);
    int32_t n = 0;
    for (int32_t b = 0; b < sk->nbones; ++b)
        n += sk->parent[b] >= 0 && sw_joint_beyond_training(bend[b], trained ? trained[b] : 0);
    free(bend);
    return n;
}

/* The largest rotation each joint reaches in the training ranges: its sweep. Without a
 * clip, the largest in the character's joint range (sw_character.range) or else 90
 * degrees about an axis across the bone. A bare skeleton says nothing of its joints'
 * limits: the 90 degrees bend a hand's metacarpals into the palm independently, which
 * no hand does, and most of the bare hand's held-out error was there; its own pose as
 * its range removes most of it (docs/notes/generalisation.md, "Joint ranges"). */
static void sweep_extents(const sw_bake_state *s, const clip_range *train, int32_t ntr,
                          double *sweep_axis, double *sweep_angle) {
    const sw_skeleton *sk = &s->rig.ch.skel;
    int32_t nb = s->rig.nb;
    for (int32_t r = 0; r < ntr; ++r)
        sw_bake_joint_reach(sk, train[r].clip->T + (size_t)train[r].first * 12 * nb, train[r].count,
                            sweep_angle, sweep_axis);
    if (ntr > 0) return;
    if (s->rig.ch.range.nframes > 0) {
        sw_bake_joint_reach(sk, s->rig.ch.range.T, s->rig.ch.range.nframes, sweep_angle,
                            sweep_axis);
        return;
    }
    for (int32_t b = 0; b < nb; ++b) {
        if (sk->parent[b] < 0) continue;
        const double *h = sk->joints + 3 * sk->bones[2 * b],
                     *t = sk->joints + 3 * sk->bones[2 * b + 1];
        double d[3], z[3] = {0, 0, 1}, a[3];
        sw_v3_sub(t, h, d);
        if (fabs(d[2]) > 0.9 * sw_v3_norm(d)) z[1] = 1, z[2] = 0;
        sw_v3_cross(d, z, a);
        double n = sw_v3_norm(a);
        if (n == 0) continue;
        for (int i = 0; i < 3; ++i)
            sweep_axis[3 * b + i] = a[i] / n;
        sweep_angle[b] = 1.5707963267948966; /* 90 degrees */
    }
}

/* Held-out poses: the held-out ranges in one path (each at most max_train_frames frames);
 * the character's own clip's continue its training frames' path. Without any, random
 * combined poses with a fixed seed. Returns 0 when out of memory. */
static int heldout_poses(sw_bake_state *s, const clip_range *held, int32_t nheld,
                         const double *sweep_axis, const double *sweep_angle, double *local) {
    int32_t nb = s->rig.nb, cap = s->p->max_train_frames, n = 0;
    for (int32_t r = 0; r < nheld; ++r)
        n += held[r].count < cap ? held[r].count : cap;
    if (n > 0) {
        if (!seq_alloc(&s->poses.heldout, n, nb, s->rig.nv)) return 0;
        for (int32_t r = 0, at = 0; r < nheld; ++r) {
            int32_t k = held[r].count < cap ? held[r].count : cap;
            fill_from_range(&s->poses.heldout, at, &held[r], k, nb);
            at += k;
        }
        /* the reference is path dependent (contact states, buckled folds): the held-out
           part of the character's clip is solved along the clip's path, after its
           training frames, as a host playing the clip sees it; held-out clips of their
           own start from rest */
        if (s->p->ntrain_clips == 0 && s->poses.ntrain_seq > 0 && s->poses.train[0].clip[0] == 0) {
            s->poses.train[0].then[0] = &s->poses.heldout;
            s->poses.heldout.continues = 1;
        }
        return 1;
    }
    if (s->p->random_poses <= 0) return 1;
    /* a path through the random poses, as a host's motion moves: solved pose to pose, a
       jump of up to 90 degrees a joint left the reference's contact on another branch
       (0.24 of the bare hand's correction from the same pose reached gradually) */
    n = s->p->random_poses * s->p->heldout_steps;
    if (!seq_alloc(&s->poses.heldout, n, nb, s->rig.nv)) return 0;
    sw_bake_random_poses(&s->rig.ch.skel, sweep_axis, sweep_angle, s->p->seed, s->p->random_poses,
                         s->p->heldout_steps, local, s->poses.heldout.T);
    return 1;
}

void sw_bake_random_poses(const sw_skeleton *sk, const double *sweep_axis,
                          const double *sweep_angle, uint64_t seed, int32_t n, int32_t steps,
                          double *local, double *T) {
    double *from = local + 9 * (size_t)sk->nbones; /* each joint's angle at the pose before */
    for (int32_t k = 0; k < sk->nbones; ++k)
        from[k] = 0;
    for (int32_t i = 0; i < n; ++i) {
        double *to = from + sk->nbones;
        for (int32_t k = 0; k < sk->nbones; ++k) {
            double u = (double)(splitmix(&seed) >> 11) * 0x1.0p-53;
            to[k] = sweep_angle[k] > 0 ? sweep_angle[k] * u : 0;
        }
        for (int32_t st = 1; st <= steps; ++st) {
            for (int32_t k = 0; k < sk->nbones; ++k) {
                double a = st == steps ? to[k] : from[k] + (to[k] - from[k]) * st / steps;
                sw_m3_axis_angle(sweep_axis + 3 * k, a, local + 9 * k);
                if (!(sweep_angle[k] > 0)) {
                    memset(local + 9 * k, 0, 9 * sizeof(double));
                    local[9 * k] = local[9 * k + 4] = local[9 * k + 8] = 1;
                }
            }
            sw_forward_kinematics(sk, local, NULL,
                                  T + ((size_t)i * steps + st - 1) * 12 * sk->nbones);
        }
        memcpy(from, to, (size_t)sk->nbones * sizeof(double));
    }
}

/* Training sequences: every training range (at most max_train_frames of it), the first
 * one's return path when asked, then a sweep per joint. Returns 0 when out of memory. */
/* Sample i of n of the sweeps: every bone of `bones` (nsw of them) turned by i/n of its
 * sweep angle, every other joint at rest. */
static void sweep_pose(const sw_bake_state *s, const int32_t *bones, int nsw, int32_t i, int32_t n,
                       const double *sweep_axis, const double *sweep_angle, double *local,
                       double *T) {
    for (int32_t k = 0; k < s->rig.nb; ++k) {
        double *L = local + 9 * k;
        memset(L, 0, 9 * sizeof(double));
        L[0] = L[4] = L[8] = 1;
    }
    for (int j = 0; j < nsw; ++j)
        sw_m3_axis_angle(sweep_axis + 3 * bones[j], sweep_angle[bones[j]] * i / n,
                         local + 9 * bones[j]);
    sw_forward_kinematics(&s->rig.ch.skel, local, NULL, T);
}

/* Whether the sweeps bend bone b's joint (b >= 0). A pair sweep turns a joint and its
 * parent's together when both are (the flesh between two domain boundaries
 * depends on both joints, and the single sweeps never show them combined). */
static int swept(const double *sweep_angle, int32_t b) {
    return b >= 0 && sweep_angle[b] > 1e-3;
}

/* How far pose T is bent from rest: the sum over the joints (bones with a parent; the
 * root's motion is rigid) of the squared angle of the bone's rotation in its parent's. */
static double joint_bend(const sw_skeleton *sk, const double *T) {
    double sum = 0, L[9], axis[3];
    for (int32_t b = 0; b < sk->nbones; ++b) {
        if (sk->parent[b] < 0) continue;
        local_rotation(sk, T, b, L);
        double a = rotation_axis_angle(L, axis);
        sum += a * a;
    }
    return sum;
}

/* The return path's poses: the first training clip's frames (in q, n of them) played
 * back from the last one, keeping a frame only when it is bent less than every one kept
 * before it (the last included), so that the path goes home from where the clip left
 * the fold. A clip whose training part ends after its peak (the finger's: bend, then
 * part of the way back) would otherwise be re-bent to the peak first, and the reference
 * then unbends on a branch of its own: held-out frames that go on unbending from the
 * last training frame lie far from any blend of two neighbouring samples of that re-bent
 * path, and as far from the way in.
 * idx: at most n - 1 entries; returns how many. */
static int32_t return_frames(const sw_skeleton *sk, const sw_pose_seq *q, int32_t n, int32_t nb,
                             int32_t *idx) {
    int32_t m = 0;
    double bend = n > 0 ? joint_bend(sk, q->T + (size_t)(n - 1) * 12 * nb) : 0;
    for (int32_t i = n - 2; i >= 0; --i) {
        double b = joint_bend(sk, q->T + (size_t)i * 12 * nb);
        if (b < bend) {
            idx[m++] = i;
            bend = b;
        }
    }
    return m;
}

/* Whether the bake trains on the way home (sw_bake_params.return_path): by default where
 * the held-out frames continue the training part of the character's own clip. */
static int wants_return_path(const sw_bake_params *p, int32_t nheld) {
    return p->return_path > 0 || (p->return_path < 0 && p->ntrain_clips == 0 && nheld > 0);
}

/* The domain that holds bone b's flesh: b's own, or (a bone folded into its parent's
 * domain, or one that owns no tet) its nearest ancestor's; -1 if none has one. */
static int32_t bone_domain(const sw_bake_state *s, int32_t b) {
    for (; b >= 0; b = s->rig.ch.skel.parent[b])
        for (int32_t d = 0; d < s->domains.nd; ++d)
            if (s->domains.domain_bone[d] == b) return d;
    return -1;
}

/* Whether the flesh of bones a and b meets: one domain holds both, or their domains share
 * a vertex (the copies are ascending per domain: a merge). */
static int flesh_meets(const sw_bake_state *s, int32_t a, int32_t b) {
    int32_t da = bone_domain(s, a), db = bone_domain(s, b);
    if (da < 0 || db < 0) return 0;
    if (da == db) return 1;
    int32_t i = s->domains.dom_vert_ptr[da], j = s->domains.dom_vert_ptr[db];
    while (i < s->domains.dom_vert_ptr[da + 1] && j < s->domains.dom_vert_ptr[db + 1]) {
        int32_t u = s->domains.dom_verts[i], w = s->domains.dom_verts[j];
        if (u == w) return 1;
        i += u < w;
        j += w < u;
    }
    return 0;
}

/* Whether every joint is also swept with its parent joint (sw_bake_params.pair_sweeps):
 * by default where the character's joint range bounds the sweeps. Within the rig's range
 * the combinations are what the single sweeps miss (docs/notes/generalisation.md, Joint
 * ranges); at the 90-degree default they bend two joints into flesh no rig reaches, and
 * the held-out error grows (docs/notes/accuracy.md). */
static int wants_pair_sweeps(const sw_bake_state *s) {
    return s->p->pair_sweeps > 0 || (s->p->pair_sweeps < 0 && s->rig.ch.range.nframes > 0);
}

/* The joints swept in pairs (pairs[2 k], pairs[2 k + 1]; NULL: only counted), returns
 * how many: two sibling joints whose flesh meets (sibling_sweeps: the flesh between two
 * fingers' metacarpals is sheared by the difference of their bends, which neither sweep
 * alone shows), and with the pair sweeps every joint with its parent joint (*nparent of
 * them, the last). */
static int32_t sweep_pairs(const sw_bake_state *s, const double *sweep_angle, int32_t *pairs,
                           int32_t *nparent) {
    const sw_skeleton *sk = &s->rig.ch.skel;
    const int parent_pairs = wants_pair_sweeps(s);
    int32_t n = 0;
    for (int32_t a = 0; s->p->sibling_sweeps && a < s->rig.nb; ++a)
        for (int32_t b = a + 1; b < s->rig.nb; ++b)
            if (sk->parent[a] == sk->parent[b] && sk->parent[a] >= 0 && swept(sweep_angle, a) &&
                swept(sweep_angle, b) && flesh_meets(s, a, b)) {
                if (pairs) pairs[2 * n] = a, pairs[2 * n + 1] = b;
                n++;
            }
    *nparent = 0;
    for (int32_t b = 0; parent_pairs && b < s->rig.nb; ++b)
        if (swept(sweep_angle, b) && swept(sweep_angle, sk->parent[b])) {
            if (pairs) pairs[2 * n] = b, pairs[2 * n + 1] = sk->parent[b];
            n++;
            ++*nparent;
        }
    return n;
}

/* Training sequence *qi (then advanced): sweep_samples poses turning the nsw `bones`
 * together from rest to their sweeps' ends. Returns 0 when out of memory. */
static int add_sweep(sw_bake_state *s, const int32_t *bones, int nsw, const double *sweep_axis,
                     const double *sweep_angle, double *local, int32_t *qi) {
    int32_t n = s->p->sweep_samples;
    sw_pose_seq *q = &s->poses.train[*qi];
    if (!seq_alloc(q, n, s->rig.nb, s->rig.nv)) return 0;
    for (int32_t i = 0; i < n; ++i)
        sweep_pose(s, bones, nsw, i + 1, n, sweep_axis, sweep_angle, local,
                   q->T + (size_t)i * 12 * s->rig.nb);
    ++*qi;
    return 1;
}

static int training_poses(sw_bake_state *s, const clip_range *train, int32_t ntr, int32_t nheld,
                          int32_t njoint, const double *sweep_axis, const double *sweep_angle,
                          double *local) {
    const sw_skeleton *sk = &s->rig.ch.skel;
    int32_t nb = s->rig.nb, cap = s->p->max_train_frames;
    int32_t n0 = ntr > 0 ? (train[0].count < cap ? train[0].count : cap) : 0;
    int32_t nreturn = wants_return_path(s->p, nheld) && n0 >= 2 ? n0 - 1 : 0;
    int32_t nparent;
    int32_t npair = sweep_pairs(s, sweep_angle, NULL, &nparent);
    s->poses.pair_sweep_poses = nparent * s->p->sweep_samples;
    int32_t chain = s->p->extra_chain > 0 ? s->p->extra_chain : s->p->nextra_poses;
    int32_t nextra = s->p->nextra_poses > 0 ? (s->p->nextra_poses + chain - 1) / chain : 0;
    s->poses.ntrain_seq = ntr + (nreturn > 0) + njoint + npair + nextra;
    s->poses.train = calloc((size_t)s->poses.ntrain_seq + 1, sizeof(sw_pose_seq));
    if (!s->poses.train) return 0;
    int32_t qi = 0;
    for (int32_t r = 0; r < ntr; ++r, ++qi) {
        int32_t n = train[r].count < cap ? train[r].count : cap;
        if (!seq_alloc(&s->poses.train[qi], n, nb, s->rig.nv)) return 0;
        fill_from_range(&s->poses.train[qi], 0, &train[r], n, nb);
    }
    if (nreturn > 0) { /* train[0]'s frames on the way home, continuing from its last solution */
        int32_t *idx = malloc((size_t)nreturn * sizeof(int32_t));
        if (!idx) return 0;
        nreturn = return_frames(sk, &s->poses.train[0], n0, nb, idx);
        if (nreturn > 0 && !seq_alloc(&s->poses.train[qi], nreturn, nb, s->rig.nv)) {
            free(idx);
            return 0;
        }
        for (int32_t i = 0; i < nreturn; ++i)
            memcpy(s->poses.train[qi].T + (size_t)i * 12 * nb,
                   s->poses.train[0].T + (size_t)idx[i] * 12 * nb, 12 * nb * sizeof(double));
        free(idx);
        s->poses.return_poses = nreturn;
        if (nreturn > 0) {
            s->poses.train[0].then[1] = &s->poses.train[qi];
            s->poses.train[qi].continues = 1;
            qi++;
        } else { /* the clip ended at rest: nothing to go home through */
            s->poses.ntrain_seq--;
        }
    }
    /* a sweep per joint, then the pairs' sweeps, both joints of a pair turned together */
    int32_t *pairs = malloc(sizeof(int32_t) * (2 * (size_t)npair + 1));
    int ok = pairs != NULL;
    if (ok) sweep_pairs(s, sweep_angle, pairs, &nparent);
    for (int32_t b = 0; ok && b < nb; ++b)
        if (swept(sweep_angle, b)) ok = add_sweep(s, &b, 1, sweep_axis, sweep_angle, local, &qi);
    for (int32_t k = 0; ok && k < npair; ++k)
        ok = add_sweep(s, pairs + 2 * k, 2, sweep_axis, sweep_angle, local, &qi);
    free(pairs);
    if (!ok) return 0;
    /* the caller's poses (the adaptive loop's), `chain` at a time on a path from rest */
    for (int32_t at = 0; at < s->p->nextra_poses; at += chain, ++qi) {
        int32_t n = s->p->nextra_poses - at < chain ? s->p->nextra_poses - at : chain;
        if (!seq_alloc(&s->poses.train[qi], n, nb, s->rig.nv)) return 0;
        memcpy(s->poses.train[qi].T, s->p->extra_poses + (size_t)at * 12 * nb,
               (size_t)n * 12 * nb * sizeof(double));
    }
    return 1;
}

sinew_result sw_bake_poses(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    (void)out;
    int32_t nb = s->rig.nb, nheld = 0;
    int32_t nr = s->p->ntrain_clips + s->p->nheldout_clips + 1;
    clip_range *train = calloc((size_t)nr, sizeof *train), *held = calloc((size_t)nr, sizeof *held);
    double *sweep_axis = calloc((size_t)nb * 3, sizeof(double));
    double *sweep_angle = calloc((size_t)nb, sizeof(double));
    double *local = malloc((size_t)nb * SW_RANDOM_POSE_SCRATCH * sizeof(double));
    sinew_result rc = SINEW_OK;
    if (!train || !held || !sweep_axis || !sweep_angle || !local) goto oom;
    int32_t ntr = clip_ranges(s, train, held, &nheld);
    sweep_extents(s, train, ntr, sweep_axis, sweep_angle);
    int32_t njoint = 0;
    for (int32_t b = 0; b < nb; ++b)
        njoint += sweep_angle[b] > 1e-3;
    if (njoint == 0) { /* nothing to learn: every training snapshot is the rest shape */
        const sw_clip *clip = &s->rig.ch.clip;
        int32_t nf = clip->T && clip->nbones == nb ? clip->nframes : 0;
        if (s->p->ntrain_clips > 0)
            rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                              "too few poses to train: the %d training clips bend no joint, and "
                              "the basis and the cubature are learnt from the training poses' "
                              "deformation",
                              s->p->ntrain_clips);
        else if (ntr == 0 && s->rig.ch.range.nframes > 0)
            rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                              "no training poses: the joint range turns no joint (every bone "
                              "at rest in its %d frames), so nothing is swept",
                              s->rig.ch.range.nframes);
        else
            rc = sw_error_set(
                err, SINEW_ERROR_INVALID_ARGUMENT,
                nf < 2 ? "no training poses: the skeleton has no joint to bend"
                       : "too few poses to train: the clip's %d training frames (the first "
                         "%.0f%% of its %d; the rest is held out) bend no joint, and the basis and "
                         "the cubature are learnt from the training poses' deformation; a clip "
                         "that starts at rest needs at least 2 training frames, i.e. at least %d "
                         "frames",
                ntr > 0 ? train[0].count : 0, 100 * (1 - s->p->heldout_fraction), nf,
                sw_bake_min_frames(s->p->heldout_fraction));
        goto done;
    }
    if (!training_poses(s, train, ntr, nheld, njoint, sweep_axis, sweep_angle, local) ||
        !heldout_poses(s, held, nheld, sweep_axis, sweep_angle, local))
        goto oom;
    goto done;
oom:
    rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for poses");
done:
    free(train);
    free(held);
    s->poses.sweep_axis = sweep_axis; /* the adaptive loop's candidates (sw_bake_result) */
    s->poses.sweep_angle = sweep_angle;
    free(local);
    return rc;
}
