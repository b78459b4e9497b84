/* sinew-bench: in one run on the same mesh and motion, the full-space reference, the
 * subspace runtime and plain dual-quaternion skinning of the same render surface.
 *
 *   sinew-bench (FILE.glb [--tets N] [--train-clips A,B] [--heldout-clips C] |
 *               --scene NAME [--tets N] [--frames F] | --mesh ... as sinew-bake)
 *               [--blob FILE [--bake-errors]] [--full-frames K] [--contract-steps S]
 *               [--threads T] [--instances N] --json
 *
 * Bakes the character (or loads --blob), then:
 *   full_ms   median full-space quasistatic ms/frame (self-contact on) over the clip (or
 *             its first K frames)
 *   sub_ms    median subspace step + surface read ms/frame over the clip; with
 *             --timing-passes P each frame's time is its least over P plays of the clip
 *             (machine noise only adds time), and dqs_ms's likewise (timing_passes);
 *             failed_steps counts the steps of every play
 *   dqs_ms    median ms/frame of DQS of the output surface (positions and normals): the
 *             render mesh's own vertices when the blob embeds one, so
 *             cost_vs_dqs is the cost against skinning the very mesh a host draws
 *   correction error |x_sub - x_full|_M / |x_full - x_dqs|_M, always through
 *             sw_bake_errors (one definition), on one of three pose sets (err_source):
 *   err_train, err_heldout  without --blob: on the bake's training and held-out poses,
 *             the figures sinew-bake prints (err_source "bake")
 *   err_clip_train, err_clip_heldout  with --blob: on the clip frames the reference
 *             above solved (the first K), split as the bake splits a clip: training = the
 *             first floor(K (1 - heldout_fraction)) frames, held-out = the rest
 *             (err_source "clip"; err_clip_train_frames, err_clip_heldout_frames; null
 *             when a part is empty, e.g. --full-frames 1); a glTF/FBX FILE's clip is its
 *             first held-out clip, all of it held out (err_clip_train null). Costs
 *             nothing beyond the timing run, but these are not the bake's figures: the
 *             bake also trains on joint sweeps and caps the clip frames it trains on
 *   err_train, err_heldout  with --blob --bake-errors: the bake's poses and reference
 *             solutions made anew with the default bake parameters (sw_bake_solutions,
 *             as costly as the bake's simulate stage; err_source "bake_default_poses"), so
 *             a blob baked with other pose options (--return-path, --no-self-contact) is
 *             measured on the default poses
 *   allocs_in_step, locks_in_step: calls counted by the interposer over S steps after
 *             warm-up (-1 when this build cannot observe them)
 *   failed_steps  steps that returned an error (a non-finite state) in all of the above
 *   ref_unsettled reference solutions behind the errors whose self-contact set the
 *             simulator's round cap stopped while it still changed (their fold, and the
 *             error measured against it, depend on the cap)
 *   phase_ms  median ms/frame of each phase of the step (the step's own stats: skin,
 *             contact, dynamics, solve, output), and potential_evals, the mean number of
 *             potential evaluations (cubature passes) a step
 *   beyond_training_frames  timed clip frames the step flagged SINEW_STEP_BEYOND_TRAINING
 *             (a joint bent beyond the bake's training poses); beyond_training_deg_max and
 *             beyond_training_bone: the furthest such bend's excess (degrees) and its bone
 * Ratios: speedup_vs_full = full_ms / sub_ms, cost_vs_dqs = sub_ms / dqs_ms.
 * With --world FILE (a world file, samples/worlds) it then runs the reference and the
 * runtime with that world on the same mesh and motion (world_bench.h) and adds
 *   world_contact_frames  frames in which the reference touches a collider
 *   err_world_sub         correction error over those frames, subspace vs reference
 *   pen_world_full, pen_world_sub  deepest penetration into any collider (world units;
 *                         with a render mesh both of the render mesh, the reference's
 *                         placed by the blob's embedding)
 *   world_query_ms        median ms of a step's world detection; world_queries, the
 *                         mean collider queries a step; world_contacts, the mean copies
 *                         in contact
 *   world_allocs_in_step, world_locks_in_step  the contract counts with world contact
 * With --dynamic [--hold-frames H] it then runs the runtime in dynamic mode
 * (SINEW_STEP_DYNAMIC) and the reference's backward-Euler run of the same clip followed
 * by H frames (default 30) holding its last pose (dyn_bench.h): both at h = 1 / the clip's
 * fps (dyn_dt), both with the blob's Rayleigh damping D = alpha M + beta K(x_n)
 * (dyn_rayleigh_alpha, dyn_rayleigh_beta: the reference's rayleigh_alpha/beta set to
 * them), both with the same lumped masses (density x volume / 4 per tet corner; the
 * runtime's reduced mass is U^T M U of those), both starting settled at the first
 * frame (its quasistatic solution, zero velocity), and adds
 *   err_dynamic       correction error |x_sub - x_full|_M / |x_full - x_dqs|_M over the
 *                     clip's frames (sw_eval_acc, sw_bake_errors' formula), x_full the
 *                     reference's dynamic positions; err_dynamic_hold, over the hold frames
 *   overshoot_sub, overshoot_full  after the clip stops: the largest, over hold frames
 *                     0 .. H-2, mass-weighted RMS distance of the output surface from
 *                     its position at the last hold frame (H-1),
 *                     sqrt(sum_s m_s |x_s(f) - x_s(H-1)|^2 / sum_s m_s), m_s the
 *                     reference's lumped mass of surface vertex s (world units; with a
 *                     render mesh the reference's surface is placed by the blob's own
 *                     embedding and m_s is its barycentric blend of masses); it counts
 *                     the lag the flesh still has when the skeleton stops and every swing
 *                     past the settled shape after it
 *   err_dynamic_ref, err_dynamic_ref_hold  the reference's own spread: a reference solved
 *                     to tolerances 100 times tighter against it, by the same formula;
 *                     err_dynamic_tight, err_dynamic against that tighter reference
 *   overshoot_ratio   overshoot_sub / overshoot_full (target |ratio - 1| <= 0.2)
 *   settle_sub, settle_full  the same distance between hold frames H-2 and H-1: motion
 *                     left at the end (small against the overshoot: H was long enough)
 *   dyn_step_ms, dyn_qs_step_ms, dyn_vs_qs  a dynamic and a quasistatic instance timed
 *                     taking turns over the clip (sw_dyn_bench_cost), and their ratio;
 *                     dyn_step_evals, dyn_qs_step_evals their cubature passes a step
 *   dyn_full_ms, dyn_sub_ms  median ms of a dynamic step beside the reference's; dyn_ref_failed,
 *                     dyn_ref_unconverged, dyn_ref_unsettled, dyn_sub_failed
 *   dyn_sub_limited, dyn_sub_teleport, dyn_sub_guard, dyn_sub_converged  the runtime's
 *                     dynamic steps with each SINEW_STEP_* flag (of frames + hold - 1)
 * With --instances N it then steps a crowd of N quasistatic instances of the blob over the
 * clip, instance i offset by i * (clip frames) / N frames, on 1 thread and on T (--threads;
 * plain pthreads taking the frame's instances one at a time from an atomic counter, then
 * a barrier;
 * crowd_bench.h), each instance's frame the work sub_ms times, and adds
 *   crowd_instances, crowd_threads  N and T (T resolved: 0 is all cores)
 *   crowd_ms          median wall ms of a frame of all N on T threads
 *   crowd_us_per_instance  crowd_ms * 1000 / N
 *   crowd_scaling     median 1-thread frame ms / crowd_ms, same run
 *   crowd_vs_lone     crowd_ms * T / N over crowd_lone_ms, the mean frame ms of one
 *                     instance stepped alone in the same run over the same clip frames
 *   crowd_ms_1thread, crowd_lone_ms, crowd_lone_median_ms, crowd_frames (timed frames,
 *                     after a warm-up)
 *   crowd_instance_bytes, crowd_workspace_bytes  an instance without scratch of its own
 *                     (def.shared_workspace) and a thread's workspace; crowd_bytes: N of
 *                     the one and T of the other
 * Always: instance_bytes (sinew_instance_memory_size with the default def) and
 * blob_bytes (the blob file's size with --blob, else the size of the blob just baked).
 * The optional runs (--instances, --sc-compare, --newton-compare, --error-gap, --world,
 * --dynamic, --novel, --pair, --lod) are the modes of bench/bench_mode.h, run in its table's order
 * after the contract count, each adding its members to the JSON line after the bench's own. The
 * last stdout line is one JSON object. Exit status: 0 done, 1 failed, 2 bad arguments. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define SW_TOOL_CHARACTER_ARGS
#define SW_TOOL_REFERENCE_ARGS
#include "tool_common.h"
#include "sw_mesh.h"

#include "bake.h"
#include "blob_load.h"
#include "blob_write.h"
#include "character_io.h"
#include "dqs.h"
#include "fullsim.h"
#include "instance.h"
#include "mesh_io.h"
#include "rt_interpose.h"
#include "samples.h"
#include "subspace_eval.h"
#include "surface_normals.h"
#include "vec3.h"
#include "weights_heat.h"
#include "world_bench.h"
#include "dyn_bench.h"
#include "crowd_bench.h"
#include "newton_bench.h"
#include "sc_bench.h"
#include "dqs_bench.h"
#include "gap_bench.h"
#include "bench_mode.h"
#include "replay.h"
#include "bench_cli.h"

static const char *const tool = "sinew-bench";

/* The step's phases as sinew_step_stats reports them. */
enum { NPHASES = 5 };

/* The subspace surface of every clip frame as DIR/frame_NNNN.obj (for sinew-render);
 * replays the clip on the instance. */
static sinew_result write_frames(const char *dir, const sinew_blob *blob, sinew_instance *inst,
                                 const sw_character *ch, sw_error *err) {
    uint32_t ns = sinew_blob_surface_vertex_count(blob),
             nt = sinew_blob_surface_triangle_count(blob);
    float *p = malloc(sizeof(float) * 3 * ns);
    double *x = malloc(sizeof(double) * 3 * ns);
    uint32_t *tu = malloc(sizeof(uint32_t) * 3 * nt);
    int32_t *ti = malloc(sizeof(int32_t) * 3 * nt);
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (!p || !x || !tu || !ti) goto done;
    if ((r = sinew_blob_surface_triangles(blob, tu, 3 * nt)) != SINEW_OK) goto done;
    for (uint32_t i = 0; i < 3 * nt; ++i)
        ti[i] = (int32_t)tu[i];
    sinew_instance_reset(inst);
    for (int f = 0; f < ch->clip.nframes; ++f) {
        char path[4096];
        sw_instance_set_pose_d(inst, ch->clip.T + (size_t)f * 12 * ch->skel.nbones);
        sinew_instance_step(inst, 1.0f / 30);
        sinew_instance_read_surface(inst, p, NULL, ns);
        for (uint32_t i = 0; i < 3 * ns; ++i)
            x[i] = p[i];
        snprintf(path, sizeof path, "%s/frame_%04d.obj", dir, f);
        if ((r = sw_write_obj(path, (int32_t)ns, x, (int32_t)nt, ti, err)) != SINEW_OK) goto done;
    }
    r = SINEW_OK;
done:
    if (r == SINEW_ERROR_OUT_OF_MEMORY) sw_error_set(err, r, "out of memory writing frames");
    free(p);
    free(x);
    free(tu);
    free(ti);
    return r;
}

/* A clip part's correction error as printed: its figure, or why it has none. */
static const char *clip_error_text(int has, const char *figure, const sw_eval_result *e) {
    return has ? figure : e->no_correction ? "n/a (at rest: no correction)" : "n/a";
}

/* Everything the bench made and measured. */
typedef struct {
    bench_options o;
    sw_character ch;
    sw_clip_split clips;
    sw_scene_character_info info;
    int nf; /* clip frames */
    sw_bake_params bp;
    sw_tool_progress bar;
    sw_bake_result res;
    sinew_blob *blob;
    const sw_blob_view *v;
    void *mem;
    double bake_s;
    size_t blob_bytes, instance_bytes; /* the file's or the baked blob's size */
    /* the reference over the first kf clip frames */
    sw_fullsim_params fp;
    int kf, full_unsettled, full_newton_max;
    double *full, *full_x, *mass, full_ms, full_mean, full_max;
    sw_linear_solver full_solver;
    /* the subspace runtime */
    sinew_instance *inst;
    uint32_t ns;
    float *pos, *nrm;
    double *sub, *phase, sub_ms, phase_ms[NPHASES], evals, factors, beyond_deg, d_ms;
    int beyond_frames, beyond_bone;
    long failed_steps, allocs, locks;
    /* the correction errors, and the poses they are of when the clip's (clip_errors) */
    sw_eval_result et, eh;
    sw_bake_result clip;
    int clip_errors, ref_unsettled;
    const char *err_source;
    sw_bench_ctx modes;
} bench;

/* The character from the command line; a FILE's import summary on stderr. */
static int load_character(bench *b, sw_error *err) {
    sinew_result r = sw_character_args_make(&b->o.ca, &b->ch, &b->clips, &b->info, err);
    if (r != SINEW_OK) return sw_tool_failed(r, err, "%s: ", tool);
    if (b->o.ca.file) {
        sw_quality quality;
        sw_tetmesh_quality(&b->ch.mesh, 0, &quality);
        sw_tool_print_scene(tool, &b->ch, &b->clips, &b->info, &quality);
    }
    b->nf = b->ch.clip.nframes;
    return 0;
}

/* 1. bake (or load) */
static int bake_or_load(bench *b, sw_error *err) {
    const bench_options *o = &b->o;
    sinew_result r;
    b->bp = sw_bake_params_default();
    b->bp.threads = o->threads;
    b->bp.reference = &b->o.ref_solver; /* its bake's solves as its full frames' */
    b->bp.progress = 1;
    sw_tool_progress_init(&b->bar, tool);
    b->bp.on_progress = sw_tool_progress_print;
    b->bp.progress_user = &b->bar;
    sw_tool_bake_clips(&o->ca, &b->clips, &b->bp);
    sinew_blob_def bd = sinew_blob_def_default();
    if (o->blob_path) {
        bd.path = o->blob_path;
        struct stat sb;
        if (stat(o->blob_path, &sb) == 0) b->blob_bytes = (size_t)sb.st_size;
    } else {
        double t0 = sw_now_seconds();
        size_t size = 0;
        if ((r = sw_bake(&b->ch, &b->bp, &b->res, err)) != SINEW_OK ||
            (r = sw_blob_write_memory(&b->res.view, &b->mem, &size, err)) != SINEW_OK)
            return sw_tool_failed(r, err, "sinew-bench: bake failed: ");
        b->bake_s = sw_now_seconds() - t0;
        bd.data = b->mem;
        bd.data_size = size;
        b->blob_bytes = size;
    }
    if (sw_tool_blob_load(tool, o->blob_path ? o->blob_path : "just baked", bd, &b->blob) !=
        SINEW_OK)
        return 1;
    b->v = sw_blob_get_view(b->blob);
    if ((r = sinew_instance_memory_size(b->blob, NULL, &b->instance_bytes)) != SINEW_OK) {
        fprintf(stderr, "sinew-bench: cannot size an instance: %s\n", sinew_result_string(r));
        return 1;
    }
    if (b->v->nverts != b->ch.mesh.nverts || b->v->nbones != b->ch.skel.nbones) {
        fprintf(stderr,
                "sinew-bench: the blob does not belong to this character (%d/%d vertices, %d/%d "
                "bones)\n",
                b->v->nverts, b->ch.mesh.nverts, b->v->nbones, b->ch.skel.nbones);
        return 1;
    }
    /* An asset without weights: the bake computed heat-diffusion weights (bake.c); the
     * reference simulator gets the same ones (it uses them for its warm start). */
    if (!b->ch.weights.w &&
        (r = sw_weights_heat(&b->ch.mesh, &b->ch.skel, 0, &b->ch.weights, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "sinew-bench: ");
    return 0;
}

/* 2. full-space reference over the first K clip frames (same motion, all cores) */
static int run_reference(bench *b, sw_error *err) {
    const sw_character *ch = &b->ch;
    sinew_result r;
    b->fp = sw_fullsim_params_default();
    b->fp.threads = b->o.threads;
    sw_fullsim_params_take_solver(&b->fp, &b->o.ref_solver);
    b->fp.self_contact = b->o.ref_self_contact;
    sw_fullsim *sim = NULL;
    int nf = b->nf, kf = b->o.full_frames > 0 && b->o.full_frames < nf ? b->o.full_frames : nf;
    b->kf = kf; /* default: the whole clip */
    b->full = malloc((size_t)(kf > 0 ? kf : 1) * sizeof(double));
    b->full_x = malloc((size_t)(kf > 0 ? kf : 1) * 3 * ch->mesh.nverts * sizeof(double));
    b->mass = malloc((size_t)ch->mesh.nverts * sizeof(double)); /* the reference's */
    if (!b->full || !b->full_x || !b->mass) {
        fprintf(stderr, "sinew-bench: out of memory\n");
        return 1;
    }
    if ((r = sw_fullsim_create(ch, &b->fp, &sim, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "%s: ", tool);
    /* the full reference steps every clip frame up to the last timed one, from rest */
    b->full_solver = SW_SOLVER_AUTO;
    for (int f = 0; f < kf; ++f) {
        sw_fullsim_stats st;
        sw_fullsim_step(sim, ch->clip.T + (size_t)f * 12 * ch->skel.nbones, &st);
        b->full_unsettled += st.contacts_unsettled; /* frames whose contact set did not settle */
        b->full[f] = 1e3 * st.seconds;
        b->full_mean += b->full[f] / kf;
        b->full_max = fmax(b->full_max, b->full[f]);
        b->full_newton_max =
            st.newton_iters > b->full_newton_max ? st.newton_iters : b->full_newton_max;
        b->full_solver = st.solver;
        memcpy(b->full_x + (size_t)f * 3 * ch->mesh.nverts, sw_fullsim_positions(sim),
               sizeof(double) * 3 * ch->mesh.nverts);
        fprintf(stderr, "sinew-bench: full-space frame %d/%d: %.1f ms\n", f + 1, kf, b->full[f]);
    }
    b->full_ms = sw_median(b->full, kf);
    memcpy(b->mass, sw_fullsim_masses(sim), sizeof(double) * ch->mesh.nverts);
    sw_fullsim_destroy(sim);
    return 0;
}

/* A timed subspace step: each frame's least time and phases over the plays; the counts
 * are the first play's (a failed step is counted in any play: none is hidden). */
static void sub_step(void *user, int step, int f, double ms, const sinew_step_stats *st) {
    bench *b = user;
    int pass = step / b->nf, nf = b->nf;
    const double ph[NPHASES] = {st->ms_skin, st->ms_contact, st->ms_dynamics, st->ms_solve,
                                st->ms_output};
    for (int k = 0; k < NPHASES; ++k) {
        double *pk = b->phase + (size_t)k * nf + f;
        *pk = pass == 0 ? ph[k] : fmin(*pk, ph[k]);
    }
    b->sub[f] = pass == 0 ? ms : fmin(b->sub[f], ms);
    if (pass > 0) return;
    b->evals += st->potential_evals / (double)nf;
    b->factors += st->factorizations / (double)nf;
    b->beyond_frames += (st->status & SINEW_STEP_BEYOND_TRAINING) != 0;
    if (st->beyond_training_deg > b->beyond_deg)
        b->beyond_deg = st->beyond_training_deg, b->beyond_bone = st->beyond_training_bone;
}

/* 3. subspace: step + read over the clip; 4. plain DQS of the same surface */
static int run_subspace(bench *b, sw_error *err) {
    sinew_result r;
    sinew_instance_def idef = sinew_instance_def_default();
    idef.self_contact = (sinew_self_contact)b->o.self_mode;
    if ((r = sinew_instance_create(b->blob, &idef, &b->inst)) != SINEW_OK) {
        fprintf(stderr, "sinew-bench: cannot create an instance: %s\n", sinew_result_string(r));
        return 1;
    }
    int nf = b->nf;
    b->ns = sinew_blob_surface_vertex_count(b->blob);
    b->pos = malloc((size_t)b->ns * 3 * sizeof(float));
    b->nrm = malloc((size_t)b->ns * 3 * sizeof(float));
    b->sub = malloc((size_t)nf * sizeof(double));
    b->phase = malloc((size_t)nf * NPHASES * sizeof(double));
    b->beyond_bone = -1; /* frames bent beyond the bake's training */
    sw_replay rp = sw_replay_clip(b->inst, b->ch.clip.T, nf, b->ch.skel.nbones,
                                  1.0f / (float)(b->ch.clip.fps > 0 ? b->ch.clip.fps : 30));
    rp.steps = b->o.timing_passes * nf;
    rp.pos = b->pos;
    rp.nrm = b->nrm;
    rp.ns = b->ns;
    rp.on_step = sub_step;
    rp.user = b;
    sw_replay_run(&rp);
    b->failed_steps += rp.failed; /* steps that did not return SINEW_OK (a non-finite state) */
    b->sub_ms = sw_median(b->sub, nf);
    for (int k = 0; k < NPHASES; ++k)
        b->phase_ms[k] = sw_median(b->phase + (size_t)k * nf, nf);
    if (b->o.out_dir && (r = write_frames(b->o.out_dir, b->blob, b->inst, &b->ch, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "%s: --out %s: ", tool, b->o.out_dir);
    /* the render mesh's own vertices when it has one */
    b->d_ms = sw_dqs_bench_ms(b->v, &b->ch.clip, nf, b->o.timing_passes);
    if (!(b->d_ms >= 0)) {
        fprintf(stderr, "sinew-bench: out of memory\n");
        return 1;
    }
    return 0;
}

/* 5. errors against full-space solutions, always by the bake's definition
   (sw_bake_errors): on the bake's poses when it baked here; a given blob on the clip
   frames the reference solved above (split as the bake splits a clip), or, with
   --bake-errors, on the bake's poses solved anew with the default parameters and the
   reference options */
static int measure_errors(bench *b, sw_error *err) {
    const bench_options *o = &b->o;
    sinew_self_contact mode = (sinew_self_contact)o->self_mode;
    sinew_result r;
    b->clip_errors = o->blob_path && !o->bake_errors;
    b->err_source = !o->blob_path ? "bake" : b->clip_errors ? "clip" : "bake_default_poses";
    if (b->clip_errors) {
        /* borrows the clip's poses and the solutions above: never sw_bake_result_free'd */
        sw_bake_result clip;
        memset(&clip, 0, sizeof clip);
        b->clip.nheldout = 0;
        int kf = b->kf;
        /* a file's held-out clip (the character's clip then) is held out whole */
        int ntr = b->bp.nheldout_clips > 0 ? 0 : (int)floor(kf * (1.0 - b->bp.heldout_fraction));
        size_t pt = (size_t)12 * b->ch.skel.nbones, px = (size_t)3 * b->ch.mesh.nverts;
        clip.mass = b->mass;
        clip.ntrain = ntr;
        clip.train_T = b->ch.clip.T;
        clip.train_x = b->full_x;
        clip.nheldout = kf - ntr;
        clip.heldout_T = b->ch.clip.T + ntr * pt;
        clip.heldout_x = b->full_x + ntr * px;
        clip.heldout_after = ntr; /* the reference solved the clip on one path */
        if ((r = sw_bake_errors(b->blob, &clip, mode, &b->et, &b->eh, err)) != SINEW_OK)
            return sw_tool_failed(r, err, "%s: cannot evaluate the blob: ", tool);
        b->ref_unsettled = b->full_unsettled;
        b->clip = clip;
    } else {
        if (o->blob_path && (r = sw_bake_solutions(&b->ch, &b->bp, &b->res, err)) != SINEW_OK)
            return sw_tool_failed(r, err, "%s: the bake's reference solutions: ", tool);
        if ((r = sw_bake_errors(b->blob, &b->res, mode, &b->et, &b->eh, err)) != SINEW_OK)
            return sw_tool_failed(r, err, "%s: cannot evaluate the blob: ", tool);
        b->ref_unsettled = b->res.train_unsettled + b->res.heldout_unsettled;
    }
    return 0;
}

/* 6. the real-time contract: allocation and lock calls inside the step, after a warm-up;
 * a rejected pose must not allocate either */
static void run_contract(bench *b) {
    b->allocs = b->locks = -1;
    (void)sw_rt_interpose_active(); /* its self-check counts: outside the counted steps */
    if (b->o.contract_steps > 0) {
        sw_replay rp = sw_replay_clip(b->inst, b->ch.clip.T, b->nf, b->ch.skel.nbones, 1.0f / 30);
        rp.warmup = 10;
        rp.steps = b->o.contract_steps;
        rp.count_rt = 1;
        rp.post_null = 1;
        rp.pos = b->pos;
        rp.nrm = b->nrm;
        rp.ns = b->ns;
        sw_replay_run(&rp);
        b->failed_steps += rp.failed;
        sw_rt_counts_report(&rp.counts, &b->allocs, &b->locks);
    }
    b->failed_steps += b->et.failed + b->eh.failed;
}

/* 7.. the modes asked for (bench_mode.h) */
static int run_modes(bench *b, sw_error *err) {
    const bench_options *o = &b->o;
    sw_bench_ctx *c = &b->modes;
    *c = (sw_bench_ctx){.ch = &b->ch,
                        .blob = b->blob,
                        .res = &b->res,
                        .fp = &b->fp,
                        .full_x = b->full_x,
                        .nf = b->nf,
                        .kf = b->kf,
                        .clip_frames = o->ca.frames,
                        .threads = o->threads,
                        .timing_passes = o->timing_passes,
                        .contract_steps = o->contract_steps,
                        .self_mode = (sinew_self_contact)o->self_mode,
                        .world_path = o->world_path,
                        .cond = &o->cond,
                        .dynamic = o->dynamic,
                        .hold_frames = o->hold_frames,
                        .instances = o->instances,
                        .sc_compare = o->sc_compare,
                        .novel = o->novel,
                        .pair = o->pair,
                        .newton_compare = o->newton_compare,
                        .lod = o->lod,
                        .err_res = b->clip_errors ? &b->clip : &b->res,
                        .error_gap = o->error_gap};
    for (int k = 0; k < sw_bench_nmodes; ++k) {
        const sw_bench_mode *m = &sw_bench_modes[k];
        if (!m->wanted(c)) continue;
        sinew_result r = m->run(c, err);
        if (r != SINEW_OK) return sw_tool_failed(r, err, "%s: %s", tool, m->fail);
    }
    b->failed_steps += c->failed;
    return 0;
}

/* The summary on stderr; the clip errors' texts ("null" when a part has none) in e_tr,
 * e_ho. */
static void print_summary(const bench *b, char *e_tr, char *e_ho, size_t n) {
    /* an empty part of the clip's split (very few frames, --full-frames 1) has no error, nor
       has one whose frames are at rest (a share of rounding: sw_eval_result.no_correction) */
    const sw_eval_result *et = &b->et, *eh = &b->eh;
    int has_tr = !b->clip_errors || (et->frames > 0 && !et->no_correction),
        has_ho = !b->clip_errors || (eh->frames > 0 && !eh->no_correction);
    snprintf(e_tr, n, "null");
    snprintf(e_ho, n, "null");
    if (has_tr) snprintf(e_tr, n, "%.5f", et->correction_error);
    if (has_ho) snprintf(e_ho, n, "%.5f", eh->correction_error);
    fprintf(stderr,
            "sinew-bench: full %.2f ms, subspace %.3f ms, DQS %.3f ms per frame; speedup %.1fx, "
            "cost %.1fx DQS;\n",
            b->full_ms, b->sub_ms, b->d_ms, b->full_ms / b->sub_ms, b->sub_ms / b->d_ms);
    if (b->clip_errors)
        fprintf(stderr,
                "             correction error on clip frames (not the bake's figures): train "
                "%s (%d frames) held-out %s (%d frames);\n",
                clip_error_text(has_tr, e_tr, et), et->frames, clip_error_text(has_ho, e_ho, eh),
                eh->frames);
    else
        fprintf(stderr, "             correction error (%s) train %.4f held-out %.4f;\n",
                b->err_source, et->correction_error, eh->correction_error);
    fprintf(stderr, "             allocs %ld, locks %ld in %d steps\n", b->allocs, b->locks,
            b->o.contract_steps);
    fprintf(stderr, "             memory: %zu bytes an instance, blob %zu bytes\n",
            b->instance_bytes, b->blob_bytes);
    fprintf(stderr,
            "             step phases (median ms): skin %.4f, contact %.4f, dynamics %.4f, solve "
            "%.4f, output %.4f; %.1f potential evaluations and %.1f factorisations a step\n",
            b->phase_ms[0], b->phase_ms[1], b->phase_ms[2], b->phase_ms[3], b->phase_ms[4],
            b->evals, b->factors);
}

/* The JSON line: the bench's members, then each mode's. */
static void print_json(const bench *b, const char *e_tr, const char *e_ho) {
    const sw_character_args *ca = &b->o.ca;
    const double *ph = b->phase_ms;
    printf("{\"scene\":\"%s\",\"tets\":%d,\"verts\":%d,\"surface_verts\":%u,\"frames\":%d,"
           "\"speedup_vs_full\":%.2f,\"cost_vs_dqs\":%.2f,\"%s\":%s,\"%s\":%s,"
           "\"rank\":%d,\"cubature_tets\":%d,\"allocs_in_step\":%ld,\"locks_in_step\":%ld,"
           "\"contract_steps\":%d,\"full_ms\":%.3f,\"sub_ms\":%.4f,\"dqs_ms\":%.4f,\"bake_"
           "seconds\":%.2f,"
           "\"err_source\":\"%s\",\"failed_steps\":%ld,\"ref_unsettled\":%d,"
           "\"phase_ms\":{\"skin\":%.4f,\"contact\":%.4f,\"dynamics\":%.4f,\"solve\":%.4f,"
           "\"output\":%.4f},\"potential_evals\":%.2f,\"solver\":\"%s\",\"unsettled_frames\":%d,"
           "\"newton_iters_max\":%d,\"full_ms_mean\":%.3f,\"full_ms_max\":%.3f",
           ca->file    ? ca->file
           : ca->scene ? ca->scene
                       : ca->mesh,
           b->ch.mesh.ntets, b->ch.mesh.nverts, b->ns, b->nf, b->full_ms / b->sub_ms,
           b->sub_ms / b->d_ms, b->clip_errors ? "err_clip_train" : "err_train", e_tr,
           b->clip_errors ? "err_clip_heldout" : "err_heldout", e_ho, b->v->rank_total, b->v->ncub,
           b->allocs, b->locks, b->o.contract_steps, b->full_ms, b->sub_ms, b->d_ms, b->bake_s,
           b->err_source, b->failed_steps, b->ref_unsettled, ph[0], ph[1], ph[2], ph[3], ph[4],
           b->evals, sw_linear_solver_name(b->full_solver), b->full_unsettled, b->full_newton_max,
           b->full_mean, b->full_max);
    printf(",\"factorizations\":%.2f,\"instance_bytes\":%zu,\"blob_bytes\":%zu,"
           "\"beyond_training_frames\":%d,\"beyond_training_deg_max\":%.2f,"
           "\"beyond_training_bone\":%d,\"timing_passes\":%d",
           b->factors, b->instance_bytes, b->blob_bytes, b->beyond_frames, b->beyond_deg,
           b->beyond_bone, b->o.timing_passes);
    printf(",\"self_contact\":\"%s\",\"ref_self_contact\":%d", sw_self_contact_keys[b->o.self_mode],
           b->o.ref_self_contact);
    if (b->clip_errors)
        printf(",\"err_clip_train_frames\":%d,\"err_clip_heldout_frames\":%d",
               b->et.frames + b->et.failed, b->eh.frames + b->eh.failed);
    for (int k = 0; k < sw_bench_nmodes; ++k)
        if (sw_bench_modes[k].wanted(&b->modes)) sw_bench_modes[k].json(&b->modes);
    printf("}\n");
}

static void bench_free(bench *b) {
    free(b->full);
    free(b->full_x);
    free(b->mass);
    free(b->sub);
    free(b->phase);
    free(b->pos);
    free(b->nrm);
    sinew_instance_destroy(b->inst);
    sinew_blob_destroy(b->blob);
    free(b->mem);
    sw_bake_result_free(&b->res);
    sw_character_free(&b->ch);
    sw_clip_split_free(&b->clips);
}

int main(int argc, char **argv) {
    static bench b;
    sw_error err;
    int status = bench_parse_args(argc, argv, &b.o);
    if (!status) status = load_character(&b, &err);
    if (!status) status = bake_or_load(&b, &err);
    if (!status) status = run_reference(&b, &err);
    if (!status) status = run_subspace(&b, &err);
    if (!status) status = measure_errors(&b, &err);
    if (!status) run_contract(&b);
    if (!status) status = run_modes(&b, &err);
    if (status) return status;
    char e_tr[32], e_ho[32];
    print_summary(&b, e_tr, e_ho, sizeof e_tr);
    if (b.o.json) print_json(&b, e_tr, e_ho);
    bench_free(&b);
    return 0;
}
