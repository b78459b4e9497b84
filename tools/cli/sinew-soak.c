/* sinew-soak: randomised abuse of several dynamic and quasistatic instances of one blob
 * (issue 15): each frame one instance gets a mocap pose (CMU BVH 01_01: RightArm,
 * RightForeArm and RightHand rotations on the first three bones), a NaN or infinite
 * pose, a scaled, sheared or mirrored pose, a teleport, a rotation snap of a bone, a snap
 * at 1/60 s the host declares a cut (sinew_instance_mark_teleport), a dt spike anywhere in
 * [1e-9, 1], or a reset, then a step. Counted: step errors, non-finite
 * outputs, allocations and locks inside the step (tools/rt_interpose), steps flagged per
 * cause, and the largest distance of an output vertex from its skinned position relative
 * to the instance's bound (sinew_types.h). Deterministic for a seed.
 *
 *   sinew-soak [--frames N (1000000)] [--tets T (2000)] [--blob FILE] [--instances K (4)]
 *              [--seed S (1)] [--bvh FILE] [--check]
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

int main(int argc, char **argv) {
    long frames = 1000000;
    int tets = 2000, ninst = 4, check = 0;
    const char *blob_path = NULL, *bvh = SINEW_SHARED_DATA_DIR "/bvh-cmu-01_01/01_01.bvh";
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--frames") && next)
            frames = atol(argv[++i]);
        else if (!strcmp(a, "--tets") && next)
            tets = atoi(argv[++i]);
        else if (!strcmp(a, "--instances") && next)
            ninst = atoi(argv[++i]);
        else if (!strcmp(a, "--seed") && next)
            rng_state = (uint64_t)strtoull(argv[++i], NULL, 10) * 2654435761ull + 1;
        else if (!strcmp(a, "--blob") && next)
            blob_path = argv[++i];
        else if (!strcmp(a, "--bvh") && next)
            bvh = argv[++i];
        else if (!strcmp(a, "--check"))
            check = 1;
        else {
            fprintf(stderr,
                    "usage: sinew-soak [--frames N] [--tets T] [--blob FILE] [--instances K] "
                    "[--seed S] [--bvh FILE] [--check]\n");
            return 2;
        }
    }
    if (frames < 1 || ninst < 1 || ninst > 64) return 2;
    (void)sw_rt_interpose_active(); /* its self-check, outside the counted sections */

    /* the blob: loaded, or a finger baked here */
    sw_character ch;
    sw_bake_result res;
    void *data = NULL;
    size_t size = 0;
    sinew_blob *blob = NULL;
    sw_error err;
    memset(&ch, 0, sizeof ch);
    memset(&res, 0, sizeof res);
    sinew_blob_def bd = sinew_blob_def_default();
    if (blob_path) {
        bd.path = blob_path;
    } else {
        sw_bake_params p = sw_bake_params_default();
        p.threads = 2;
        if (sw_sample_make("finger", tets, 12, &ch, &err) != SINEW_OK ||
            sw_bake(&ch, &p, &res, &err) != SINEW_OK ||
            sw_blob_write_memory(&res.view, &data, &size, &err) != SINEW_OK) {
            fprintf(stderr, "sinew-soak: bake failed: %s\n", err.msg);
            return 1;
        }
        bd.data = data;
        bd.data_size = size;
    }
    if (sinew_blob_load(&bd, &blob) != SINEW_OK) {
        fprintf(stderr, "sinew-soak: cannot load the blob\n");
        return 1;
    }
    const sw_blob_view *v = sw_blob_get_view(blob);
    int32_t nb = v->nbones, ns = sw_blob_output_verts(v);
    mocap mc;
    int have_mocap = mocap_read(bvh, &mc);
    if (!have_mocap)
        fprintf(stderr, "sinew-soak: no BVH at %s; mocap frames use the rest pose\n", bvh);

    sinew_instance *inst[64];
    for (int k = 0; k < ninst; ++k) {
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = k % 2 ? SINEW_STEP_QUASISTATIC : SINEW_STEP_DYNAMIC;
        if (sinew_instance_create(blob, &d, &inst[k]) != SINEW_OK) return 1;
    }
    double *L = calloc(9 * (size_t)nb, sizeof(double)), *T = malloc(sizeof(double) * 12 * nb),
           *T2 = malloc(sizeof(double) * 12 * nb), *skin = malloc(sizeof(double) * 3 * ns),
           *last = calloc(12 * (size_t)nb * ninst, sizeof(double));
    float *Tf = malloc(sizeof(float) * 12 * nb);
    for (int32_t b = 0; b < nb; ++b)
        L[9 * b] = L[9 * b + 4] = L[9 * b + 8] = 1;
    for (int k = 0; k < ninst; ++k)
        snap_pose_from_local(v, L, last + 12 * (size_t)nb * k);
    long mframe[64] = {0};
    for (int k = 0; k < ninst; ++k)
        mframe[k] = have_mocap ? (long)(urand() * mc.nframes) : 0;

    uint64_t actions[A_COUNT] = {0}, rejected = 0, errors = 0, nonfinite = 0, over_bound = 0,
             cuts_unflagged = 0;
    uint64_t flag_count[8] = {0}, allocs = 0, locks = 0, frees = 0;
    double worst = 0, bound_min = INFINITY;
    for (int k = 0; k < ninst; ++k)
        bound_min = fmin(bound_min, sw_instance_displacement_bound(inst[k]));
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long fr = 0; fr < frames; ++fr) {
        int k = (int)(fr % ninst);
        sinew_instance *in = inst[k];
        double *Tk = last + 12 * (size_t)nb * k;
        double u = urand();
        int act = u < 0.70   ? A_MOCAP
                  : u < 0.75 ? A_NAN
                  : u < 0.80 ? A_NONRIGID
                  : u < 0.85 ? A_TELEPORT
                  : u < 0.90 ? A_SNAP
                  : u < 0.92 ? A_CUT
                  : u < 0.99 ? A_DT_SPIKE
                             : A_RESET;
        actions[act]++;
        float dt = have_mocap ? (float)(1 / mc.fps) : 1.0f / 60;
        memcpy(T, Tk, sizeof(double) * 12 * nb);
        if (act == A_MOCAP || act == A_DT_SPIKE) {
            if (have_mocap) {
                const double *M = mc.rot + 27 * (size_t)(mframe[k]++ % mc.nframes);
                for (int32_t b = 0; b < nb && b < 3; ++b)
                    memcpy(L + 9 * b, M + 9 * b, 9 * sizeof(double));
                snap_pose_from_local(v, L, T);
            }
            if (act == A_DT_SPIKE) dt = (float)pow(10.0, -9 * urand()); /* 1e-9 .. 1 */
        } else if (act == A_TELEPORT) {
            for (int32_t b = 0; b < nb; ++b)
                for (int i = 0; i < 3; ++i)
                    T[12 * b + 9 + i] += (urand() - 0.5) * 20;
        } else if (act == A_SNAP) {
            snap_rotate(v, Tk, (int32_t)(urand() * nb) % nb, (urand() - 0.5) * 2 * 3.14159, T);
            static const float dts[4] = {1e-9f, 1e-6f, 1e-3f, 1.0f / 60};
            dt = dts[(int)(urand() * 4) & 3];
        } else if (act == A_CUT) { /* a snap at the frame rate the host declares a cut */
            snap_rotate(v, Tk, (int32_t)(urand() * nb) % nb, (urand() - 0.5) * 3.14159, T);
            dt = 1.0f / 60;
            if (sinew_instance_mark_teleport(in) != SINEW_OK) errors++;
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
        sinew_result r = sinew_instance_set_pose(in, Tf, (uint32_t)nb);
        if (r != SINEW_OK) {
            rejected++;
            if (act != A_NAN && act != A_NONRIGID) errors++; /* a good pose refused */
        } else {
            for (int i = 0; i < 12 * nb; ++i) /* the pose as the instance holds it */
                Tk[i] = (double)Tf[i];
        }
        sw_rt_count_begin();
        r = sinew_instance_step(in, dt);
        sw_rt_counts c = sw_rt_count_end();
        allocs += c.allocs;
        frees += c.frees;
        locks += c.locks;
        if (r != SINEW_OK) {
            errors++;
            continue;
        }
        sinew_step_stats st = {.struct_size = sizeof st};
        sinew_instance_get_stats(in, &st);
        for (int bit = 0; bit < 8; ++bit)
            flag_count[bit] += (st.status >> bit) & 1u;
        cuts_unflagged += act == A_CUT && !(st.status & SINEW_STEP_TELEPORT);
        double d = snap_deviation(in, v, skin);
        if (d < 0) {
            nonfinite++;
            continue;
        }
        double ratio = d / sw_instance_displacement_bound(in);
        worst = fmax(worst, ratio);
        over_bound += ratio > 1 + 1e-9;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    int active = sw_rt_interpose_active();

    printf("{\"frames\": %ld, \"instances\": %d, \"tets\": %d, \"surface_vertices\": %d, "
           "\"seconds\": %.2f, \"us_per_frame\": %.2f, \"mocap\": %s, \"actions\": {",
           frames, ninst, blob_path ? -1 : tets, ns, secs, 1e6 * secs / (double)frames,
           have_mocap ? "true" : "false");
    for (int a = 0; a < A_COUNT; ++a)
        printf("%s\"%s\": %llu", a ? ", " : "", action_name[a], (unsigned long long)actions[a]);
    static const char *flag_name[8] = {"converged",  "guard",  "teleport", "failed",
                                       "pose_space", "budget", "limited",  "bit7"};
    printf("}, \"flagged\": {");
    for (int bit = 0; bit < 7; ++bit)
        printf("%s\"%s\": %llu", bit ? ", " : "", flag_name[bit],
               (unsigned long long)flag_count[bit]);
    printf("}, \"rejected_poses\": %llu, \"step_errors\": %llu, \"nonfinite_outputs\": %llu, "
           "\"allocs_in_step\": %lld, \"frees_in_step\": %lld, \"locks_in_step\": %lld, "
           "\"max_deviation_over_bound\": %.4f, \"over_bound_steps\": %llu, "
           "\"bound\": %.4g, \"cuts_unflagged\": %llu, \"crashes\": 0}\n",
           (unsigned long long)rejected, (unsigned long long)errors, (unsigned long long)nonfinite,
           (active & SW_RT_CAT_ALLOCS) ? (long long)allocs : -1LL,
           (active & SW_RT_CAT_FREES) ? (long long)frees : -1LL,
           (active & SW_RT_CAT_LOCKS) ? (long long)locks : -1LL, worst,
           (unsigned long long)over_bound, bound_min, (unsigned long long)cuts_unflagged);
    int bad = errors || nonfinite || over_bound || allocs || frees || locks || cuts_unflagged;

    for (int k = 0; k < ninst; ++k)
        sinew_instance_destroy(inst[k]);
    free(L);
    free(T);
    free(T2);
    free(skin);
    free(last);
    free(Tf);
    free(have_mocap ? mc.rot : NULL);
    sinew_blob_destroy(blob);
    free(data);
    if (!blob_path) {
        sw_bake_result_free(&res);
        sw_character_free(&ch);
    }
    return check && bad ? 1 : 0;
}
