/* sinew-soak: randomised abuse of several dynamic and quasistatic instances of one blob:
 * each frame one instance gets a mocap pose (CMU BVH 01_01: RightArm, RightForeArm and RightHand
 * rotations on the first three bones), a NaN or infinite pose, a scaled, sheared or mirrored pose,
 * a teleport, a rotation snap of a bone, a snap at 1/60 s the host declares a cut
 * (sinew_instance_mark_teleport), a dt spike anywhere in [1e-9, 1], or a reset, then a step.
 * Counted: step errors, non-finite outputs, allocations and locks inside the step
 * (tools/testkit/rt_interpose.h), steps flagged per cause, and the largest distance of an output
 * vertex from its skinned position relative to the instance's bound (sinew_types.h). Deterministic
 * for a seed.
 *
 *   sinew-soak [--frames N (1000000)] [--tets T (2000)] [--blob FILE] [--instances K (4)]
 *              [--seed S (1)] [--bvh FILE] [--check]   (--help: every flag)
 *
 * The last stdout line is one JSON object. --check exits 1 unless there were 0 non-finite
 * outputs, 0 step errors other than the rejected poses, 0 allocations, 0 locks, every
 * declared cut flagged TELEPORT and every deviation within the bound. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bake.h"
#include "blob_load.h"
#include "blob_write.h"
#include "instance.h"
#include "rt_interpose.h"
#include "samples.h"
#include "snap_probe.h"
#include "tool_common.h"

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "."
#endif

/* xorshift64*: the run's only randomness. */
static uint64_t rng_state = 1;
static double urand(void) {
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- a minimal BVH reader: the rotation channels of three named joints ------------- */

typedef struct {
    int nframes;
    double fps;
    double *rot; /* 9 nframes per joint: 3 joints, row-major local rotations */
} mocap;

static void euler_zyx(double z, double y, double x, double R[9]) { /* R = Rz Ry Rx, degrees */
    double a = z * 3.14159265358979323846 / 180, b = y * 3.14159265358979323846 / 180,
           c = x * 3.14159265358979323846 / 180;
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
    R[0] = ca * cb, R[1] = ca * sb * sc - sa * cc, R[2] = ca * sb * cc + sa * sc;
    R[3] = sa * cb, R[4] = sa * sb * sc + ca * cc, R[5] = sa * sb * cc - ca * sc;
    R[6] = -sb, R[7] = cb * sc, R[8] = cb * cc;
}

/* Reads the BVH at path; 1 on success. Assumes each joint's rotation channels come in
 * the order Z Y X (as in the CMU conversions) after any position channels. */
static int mocap_read(const char *path, mocap *m) {
    static const char *want[3] = {"RightArm", "RightForeArm", "RightHand"};
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    char tok[256];
    int chan = 0, first[3] = {-1, -1, -1}, ok = 0, pending = -1;
    memset(m, 0, sizeof *m);
    while (fscanf(f, "%255s", tok) == 1) {
        if (!strcmp(tok, "ROOT") || !strcmp(tok, "JOINT")) {
            if (fscanf(f, "%255s", tok) != 1) break;
            pending = -1;
            for (int j = 0; j < 3; ++j)
                if (!strcmp(tok, want[j])) pending = j;
        } else if (!strcmp(tok, "CHANNELS")) {
            int n;
            if (fscanf(f, "%d", &n) != 1) break;
            if (pending >= 0) first[pending] = chan + n - 3;
            pending = -1;
            chan += n;
        } else if (!strcmp(tok, "Frames:")) {
            if (fscanf(f, "%d", &m->nframes) != 1) break;
        } else if (!strcmp(tok, "Time:")) {
            double ft;
            if (fscanf(f, "%lf", &ft) != 1 || !(ft > 0)) break;
            m->fps = 1 / ft;
            ok = m->nframes > 0 && first[0] >= 0 && first[1] >= 0 && first[2] >= 0;
            break;
        }
    }
    double *row = ok ? malloc(sizeof(double) * (size_t)chan) : NULL;
    m->rot = ok ? malloc(sizeof(double) * 27 * (size_t)m->nframes) : NULL;
    ok = ok && row && m->rot;
    for (int fr = 0; ok && fr < m->nframes; ++fr) {
        for (int c = 0; c < chan && ok; ++c)
            ok = fscanf(f, "%lf", &row[c]) == 1;
        for (int j = 0; ok && j < 3; ++j)
            euler_zyx(row[first[j]], row[first[j] + 1], row[first[j] + 2],
                      m->rot + 27 * (size_t)fr + 9 * j);
    }
    free(row);
    fclose(f);
    if (!ok) {
        free(m->rot);
        m->rot = NULL;
    }
    return ok;
}

/* ---- the soak ---------------------------------------------------------------------- */

enum { A_MOCAP, A_NAN, A_NONRIGID, A_TELEPORT, A_SNAP, A_CUT, A_DT_SPIKE, A_RESET, A_COUNT };
static const char *action_name[A_COUNT] = {"mocap", "nan", "nonrigid", "teleport",
                                           "snap",  "cut", "dt_spike", "reset"};

typedef struct {
    int frames, tets, ninst, check;
    const char *blob_path, *bvh;
} options;

/* --seed S: the run's random stream */
static int take_seed(const char *tool, const char *flag, const char *v, void *target) {
    (void)target;
    char *end;
    unsigned long long seed = strtoull(v, &end, 10);
    if (*end || end == v) {
        fprintf(stderr, "%s: %s wants a non-negative integer, got '%s'\n", tool, flag, v);
        return 0;
    }
    rng_state = (uint64_t)seed * 2654435761ull + 1;
    return 1;
}

static int parse_args(int argc, char **argv, options *o) {
    *o = (options){.frames = 1000000, .tets = 2000, .ninst = 4};
    o->bvh = SINEW_SHARED_DATA_DIR "/bvh-cmu-01_01/01_01.bvh";
    const sw_flag flags[] = {
        {SW_INT("--frames", &o->frames, 1, 2147483647, "N",
                "frames, one instance each (default 1000000)")},
        {SW_INT("--tets", &o->tets, 1000, 2000000, "T",
                "the baked finger's tets, 1000..2000000 (default 2000; not with --blob)")},
        {SW_STR("--blob", &o->blob_path, "FILE", "soak this blob (default: a finger baked here)")},
        {SW_INT("--instances", &o->ninst, 1, 64, "K",
                "instances, alternately dynamic and quasistatic, 1..64 (default 4)")},
        {SW_CALL("--seed", take_seed, NULL, "S", "the random stream (default 1)")},
        {SW_STR("--bvh", &o->bvh, "FILE",
                "the mocap clip (default the shared data's CMU 01_01; without it the\n"
                "mocap frames use the rest pose)")},
        {SW_SET("--check", &o->check, 1,
                "exit 1 unless every step was clean (no non-finite output, error,\n"
                "allocation or lock, every cut flagged, every deviation within the bound)")},
    };
    const sw_flag_group groups[] = {{NULL, flags, SW_FLAGS_N(flags)}};
    const sw_tool_cli cli = {"sinew-soak",
                             "sinew-soak [--frames N] [--tets T] [--blob FILE] [--instances K]\n"
                             "                  [--seed S] [--bvh FILE] [--check]\n",
                             groups,
                             1,
                             "The last stdout line is one JSON object.\n"
                             "exit status: 0 done, 1 failed (or --check found a fault), 2 bad "
                             "arguments\n",
                             NULL,
                             0};
    return sw_flags_parse(&cli, argc, argv);
}

/* The soaked blob: loaded from a file, or a finger baked here. */
typedef struct {
    sw_character ch;
    sw_bake_result res;
    void *data;
    sinew_blob *blob;
} soak_blob;

static int load_blob(const options *o, soak_blob *b) {
    size_t size = 0;
    sw_error err;
    memset(b, 0, sizeof *b);
    sinew_blob_def bd = sinew_blob_def_default();
    if (o->blob_path) {
        bd.path = o->blob_path;
    } else {
        sw_bake_params p = sw_bake_params_default();
        p.threads = 2;
        if (sw_sample_make("finger", o->tets, 12, &b->ch, &err) != SINEW_OK ||
            sw_bake(&b->ch, &p, &b->res, &err) != SINEW_OK ||
            sw_blob_write_memory(&b->res.view, &b->data, &size, &err) != SINEW_OK) {
            fprintf(stderr, "sinew-soak: bake failed: %s\n", err.msg);
            return 0;
        }
        bd.data = b->data;
        bd.data_size = size;
    }
    if (sinew_blob_load(&bd, &b->blob) != SINEW_OK) {
        fprintf(stderr, "sinew-soak: cannot load the blob\n");
        return 0;
    }
    return 1;
}

static void free_blob(const options *o, soak_blob *b) {
    sinew_blob_destroy(b->blob);
    free(b->data);
    if (!o->blob_path) {
        sw_bake_result_free(&b->res);
        sw_character_free(&b->ch);
    }
}

/* The run's state: the instances, their last poses, the scratch poses. */
typedef struct {
    const sw_blob_view *v;
    int32_t nb, ns;
    int ninst, have_mocap;
    mocap mc;
    sinew_instance *inst[64];
    double *L, *T, *T2, *skin, *last;
    float *Tf;
    long mframe[64];
} soak_run;

/* What the run counted. */
typedef struct {
    uint64_t actions[A_COUNT], rejected, errors, nonfinite, over_bound, cuts_unflagged;
    uint64_t flag_count[8], allocs, locks, frees;
    double worst, bound_min;
} soak_tally;

static int run_init(const options *o, const sinew_blob *blob, soak_run *s) {
    memset(s, 0, sizeof *s);
    s->v = sw_blob_get_view(blob);
    s->nb = s->v->nbones;
    s->ns = sw_blob_output_verts(s->v);
    s->ninst = o->ninst;
    int32_t nb = s->nb;
    s->have_mocap = mocap_read(o->bvh, &s->mc);
    if (!s->have_mocap)
        fprintf(stderr, "sinew-soak: no BVH at %s; mocap frames use the rest pose\n", o->bvh);
    for (int k = 0; k < s->ninst; ++k) {
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = k % 2 ? SINEW_STEP_QUASISTATIC : SINEW_STEP_DYNAMIC;
        if (sinew_instance_create(blob, &d, &s->inst[k]) != SINEW_OK) return 0;
    }
    s->L = calloc(9 * (size_t)nb, sizeof(double));
    s->T = malloc(sizeof(double) * 12 * nb);
    s->T2 = malloc(sizeof(double) * 12 * nb);
    s->skin = malloc(sizeof(double) * 3 * s->ns);
    s->last = calloc(12 * (size_t)nb * s->ninst, sizeof(double));
    s->Tf = malloc(sizeof(float) * 12 * nb);
    for (int32_t b = 0; b < nb; ++b)
        s->L[9 * b] = s->L[9 * b + 4] = s->L[9 * b + 8] = 1;
    for (int k = 0; k < s->ninst; ++k)
        snap_pose_from_local(s->v, s->L, s->last + 12 * (size_t)nb * k);
    for (int k = 0; k < s->ninst; ++k)
        s->mframe[k] = s->have_mocap ? (long)(urand() * s->mc.nframes) : 0;
    return 1;
}

static void run_free(soak_run *s) {
    for (int k = 0; k < s->ninst; ++k)
        sinew_instance_destroy(s->inst[k]);
    free(s->L);
    free(s->T);
    free(s->T2);
    free(s->skin);
    free(s->last);
    free(s->Tf);
    free(s->have_mocap ? s->mc.rot : NULL);
}

/* Frame fr's abuse of instance k: chooses the action, writes the pose into s->Tf (as
 * floats) and returns the action, with the step's dt in *dt. */
static int abuse(soak_run *s, int k, soak_tally *t, float *dt) {
    sinew_instance *in = s->inst[k];
    int32_t nb = s->nb;
    double *Tk = s->last + 12 * (size_t)nb * k, *T = s->T;
    float *Tf = s->Tf;
    double u = urand();
    int act = u < 0.70   ? A_MOCAP
              : u < 0.75 ? A_NAN
              : u < 0.80 ? A_NONRIGID
              : u < 0.85 ? A_TELEPORT
              : u < 0.90 ? A_SNAP
              : u < 0.92 ? A_CUT
              : u < 0.99 ? A_DT_SPIKE
                         : A_RESET;
    t->actions[act]++;
    *dt = s->have_mocap ? (float)(1 / s->mc.fps) : 1.0f / 60;
    memcpy(T, Tk, sizeof(double) * 12 * nb);
    if (act == A_MOCAP || act == A_DT_SPIKE) {
        if (s->have_mocap) {
            const double *M = s->mc.rot + 27 * (size_t)(s->mframe[k]++ % s->mc.nframes);
            for (int32_t b = 0; b < nb && b < 3; ++b)
                memcpy(s->L + 9 * b, M + 9 * b, 9 * sizeof(double));
            snap_pose_from_local(s->v, s->L, T);
        }
        if (act == A_DT_SPIKE) *dt = (float)pow(10.0, -9 * urand()); /* 1e-9 .. 1 */
    } else if (act == A_TELEPORT) {
        for (int32_t b = 0; b < nb; ++b)
            for (int i = 0; i < 3; ++i)
                T[12 * b + 9 + i] += (urand() - 0.5) * 20;
    } else if (act == A_SNAP) {
        snap_rotate(s->v, Tk, (int32_t)(urand() * nb) % nb, (urand() - 0.5) * 2 * 3.14159, T);
        static const float dts[4] = {1e-9f, 1e-6f, 1e-3f, 1.0f / 60};
        *dt = dts[(int)(urand() * 4) & 3];
    } else if (act == A_CUT) { /* a snap at the frame rate the host declares a cut */
        snap_rotate(s->v, Tk, (int32_t)(urand() * nb) % nb, (urand() - 0.5) * 3.14159, T);
        *dt = 1.0f / 60;
        if (sinew_instance_mark_teleport(in) != SINEW_OK) t->errors++;
    } else if (act == A_RESET) {
        sinew_instance_reset(in);
        for (int32_t b = 0; b < nb; ++b) {
            memset(T + 12 * b, 0, 12 * sizeof(double));
            T[12 * b] = T[12 * b + 4] = T[12 * b + 8] = 1;
        }
    }
    for (int i = 0; i < 12 * nb; ++i)
        Tf[i] = (float)T[i];
    int32_t bb = (int32_t)(urand() * nb) % nb;
    if (act == A_NAN) {
        Tf[12 * bb + (int)(urand() * 12) % 12] = urand() < 0.5 ? NAN : INFINITY;
    } else if (act == A_NONRIGID) {
        double w = urand();
        if (w < 0.4)
            for (int i = 0; i < 9; ++i)
                Tf[12 * bb + i] *= (float)(1.01 + urand()); /* scaled */
        else if (w < 0.8)
            Tf[12 * bb + 1] += (float)(0.01 + urand()); /* sheared */
        else
            for (int i = 0; i < 3; ++i)
                Tf[12 * bb + 3 * i] = -Tf[12 * bb + 3 * i]; /* mirrored */
    }
    return act;
}

/* Frame fr: one instance abused, posed and stepped (counted), its output measured. */
static void soak_frame(soak_run *s, long fr, soak_tally *t) {
    int k = (int)(fr % s->ninst);
    sinew_instance *in = s->inst[k];
    double *Tk = s->last + 12 * (size_t)s->nb * k;
    float dt;
    int act = abuse(s, k, t, &dt);
    sinew_result r = sinew_instance_set_pose(in, s->Tf, (uint32_t)s->nb);
    if (r != SINEW_OK) {
        t->rejected++;
        if (act != A_NAN && act != A_NONRIGID) t->errors++; /* a good pose refused */
    } else {
        for (int i = 0; i < 12 * s->nb; ++i) /* the pose as the instance holds it */
            Tk[i] = (double)s->Tf[i];
    }
    sw_rt_count_begin();
    r = sinew_instance_step(in, dt);
    sw_rt_counts c = sw_rt_count_end();
    t->allocs += c.allocs;
    t->frees += c.frees;
    t->locks += c.locks;
    if (r != SINEW_OK) {
        t->errors++;
        return;
    }
    sinew_step_stats st = {.struct_size = sizeof st};
    sinew_instance_get_stats(in, &st);
    for (int bit = 0; bit < 8; ++bit)
        t->flag_count[bit] += (st.status >> bit) & 1u;
    t->cuts_unflagged += act == A_CUT && !(st.status & SINEW_STEP_TELEPORT);
    double d = snap_deviation(in, s->v, s->skin);
    if (d < 0) {
        t->nonfinite++;
        return;
    }
    double ratio = d / sw_instance_displacement_bound(in);
    t->worst = fmax(t->worst, ratio);
    t->over_bound += ratio > 1 + 1e-9;
}

static void print_json(const options *o, const soak_run *s, const soak_tally *t, double secs) {
    int active = sw_rt_interpose_active();
    printf("{\"frames\": %ld, \"instances\": %d, \"tets\": %d, \"surface_vertices\": %d, "
           "\"seconds\": %.2f, \"us_per_frame\": %.2f, \"mocap\": %s, \"actions\": {",
           (long)o->frames, o->ninst, o->blob_path ? -1 : o->tets, s->ns, secs,
           1e6 * secs / (double)o->frames, s->have_mocap ? "true" : "false");
    for (int a = 0; a < A_COUNT; ++a)
        printf("%s\"%s\": %llu", a ? ", " : "", action_name[a], (unsigned long long)t->actions[a]);
    static const char *flag_name[8] = {"converged",  "guard",  "teleport", "failed",
                                       "pose_space", "budget", "limited",  "bit7"};
    printf("}, \"flagged\": {");
    for (int bit = 0; bit < 7; ++bit)
        printf("%s\"%s\": %llu", bit ? ", " : "", flag_name[bit],
               (unsigned long long)t->flag_count[bit]);
    printf("}, \"rejected_poses\": %llu, \"step_errors\": %llu, \"nonfinite_outputs\": %llu, "
           "\"allocs_in_step\": %lld, \"frees_in_step\": %lld, \"locks_in_step\": %lld, "
           "\"max_deviation_over_bound\": %.4f, \"over_bound_steps\": %llu, "
           "\"bound\": %.4g, \"cuts_unflagged\": %llu, \"crashes\": 0}\n",
           (unsigned long long)t->rejected, (unsigned long long)t->errors,
           (unsigned long long)t->nonfinite,
           (active & SW_RT_CAT_ALLOCS) ? (long long)t->allocs : -1LL,
           (active & SW_RT_CAT_FREES) ? (long long)t->frees : -1LL,
           (active & SW_RT_CAT_LOCKS) ? (long long)t->locks : -1LL, t->worst,
           (unsigned long long)t->over_bound, t->bound_min, (unsigned long long)t->cuts_unflagged);
}

int main(int argc, char **argv) {
    options o;
    if (parse_args(argc, argv, &o)) return 2;
    (void)sw_rt_interpose_active(); /* its self-check, outside the counted sections */
    soak_blob b;
    if (!load_blob(&o, &b)) return 1;
    static soak_run s;
    if (!run_init(&o, b.blob, &s)) return 1;
    soak_tally t = {.bound_min = INFINITY};
    for (int k = 0; k < o.ninst; ++k)
        t.bound_min = fmin(t.bound_min, sw_instance_displacement_bound(s.inst[k]));
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long fr = 0; fr < o.frames; ++fr)
        soak_frame(&s, fr, &t);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    print_json(&o, &s, &t, secs);
    int bad = t.errors || t.nonfinite || t.over_bound || t.allocs || t.frees || t.locks ||
              t.cuts_unflagged;
    run_free(&s);
    free_blob(&o, &b);
    return o.check && bad ? 1 : 0;
}
