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
 *             render mesh's own vertices when the blob embeds one (issue 14), so
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
 *   overshoot_ratio   overshoot_sub / overshoot_full (target |ratio - 1| <= 0.2)
 *   settle_sub, settle_full  the same distance between hold frames H-2 and H-1: motion
 *                     left at the end (small against the overshoot: H was long enough)
 *   dyn_full_ms, dyn_sub_ms  median ms of a dynamic step; dyn_ref_failed,
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
 * Always: instance_bytes (sinew_instance_memory_size with the default def) and
 * blob_bytes (the blob file's size with --blob, else the size of the blob just baked).
 * The last stdout line is one JSON object. Exit status: 0 done, 1 failed, 2 bad arguments. */
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

/* The step's phases as sinew_step_stats reports them. */
enum { NPHASES = 5 };

static void usage(FILE *f) {
    fprintf(f, "usage: sinew-bench (FILE [--tets N] [--train-clips A,B] [--heldout-clips C] |\n"
               "                    --scene NAME [--tets N] [--frames F] [--data DIR] |\n"
               "                    --mesh FILE --skeleton FILE.tgf [--weights FILE.dmat]\n"
               "                    [--clip FILE [--frames F] | --joint-range FILE])\n"
               "                   [--blob FILE [--bake-errors]]\n"
               "                   [--full-frames K] [--contract-steps S] [--threads T]\n"
               "                   [--timing-passes P]\n"
               "                   [reference options] [--out DIR]\n"
               "                   [--world FILE.json [--rho R] [--patch-budget N]]\n"
               "                   [--dynamic [--hold-frames H]] [--instances N]\n"
               "                   [--self-contact pose-space|exhaustive] [--sc-compare]\n"
               "                   [--newton-compare]\n"
               "                   [--error-gap] [--json]\n"
               "character:\n" SW_CHARACTER_USAGE);
    fprintf(f,
            "bench:\n"
            "  --blob FILE         a blob sinew-bake wrote for this character (default: bake,\n"
            "                      and report the bake's err_train/err_heldout). The errors are\n"
            "                      then measured on the clip frames the reference solved, split\n"
            "                      as the bake splits a clip: err_clip_train, err_clip_heldout\n"
            "                      (err_source \"clip\"), not the bake's figures\n"
            "  --bake-errors       with --blob: re-solve the bake's training and held-out poses\n"
            "                      (default bake parameters, the reference options below; as\n"
            "                      slow as the bake's simulate stage) and report the bake's "
            "err_train/err_heldout\n"
            "                      (err_source \"bake_default_poses\")\n"
            "  --full-frames K     time the reference over the first K clip frames, 1..100000\n"
            "                      (default: the whole clip)\n"
            "  --contract-steps S  steps counted for allocations and locks, 0..100000000\n"
            "                      (default 10000)\n"
            "  --threads T         0..256 (default 0: all cores); also the crowd's threads\n"
            "  --timing-passes P   play the clip P times for sub_ms and dqs_ms, each frame's\n"
            "                      least time of the P, 1..1000 (default 1; the errors and\n"
            "                      counts: the first play's; failed_steps: every play's)\n"
            "  --out DIR           write the subspace surface of every clip frame as\n"
            "                      DIR/frame_NNNN.obj; with --world, the condensed run's\n"
            "                      (the first radius) as DIR/condensed/frame_NNNN.obj, the\n"
            "                      patch in red (sinew-render --frames DIR/condensed)\n"
            "  --world F           also run reference and runtime against world file F (.json,\n"
            "                      schema 1, samples/worlds/README.md) and report its figures;\n"
            "                      with a blob holding the tet mesh, also a condensed runtime\n"
            "                      (full-space patches at novel contact) and its figures\n"
            "  --rho R[,R...]      with --world: the patch radius in units of the rest\n"
            "                      bounding-box diagonal, 0 < R <= 1 (default 0.05); several\n"
            "                      (at most 8) run one condensed instance each against the\n"
            "                      same reference run (the first in the top-level figures,\n"
            "                      the others in cond_sweep)\n"
            "  --patch-budget N    with --world: max_patch_vertices (default a quarter of\n"
            "                      the vertices)\n"
            "  --self-contact M    pose-space (default) or exhaustive: the runtime's mode\n"
            "                      (sinew_instance_def.self_contact) for the timing and errors\n"
            "  --sc-compare        also time self-contact in both modes over the clip: sc_*\n"
            "  --newton-compare    also time the quasistatic step with Newton on the current\n"
            "                      and starting on the rest Hessian over the clip: newton_*\n"
            "  --error-gap         also the runtime against its basis's projection on the\n"
            "                      bake's held-out poses (not with --blob alone): gap_*\n"
            "  --dynamic           also run the runtime in dynamic mode against the reference's\n"
            "                      backward-Euler run of the clip (same dt, damping, masses)\n"
            "                      and report err_dynamic and the overshoot after the clip\n"
            "  --hold-frames H     with --dynamic: frames holding the last pose, 2..100000\n"
            "                      (default 30)\n"
            "  --instances N       also step a crowd of N instances of the blob over the clip,\n"
            "                      1..4096, each offset in time, on 1 thread and on T\n"
            "                      (--threads) host pthreads, and report crowd_ms,\n"
            "                      crowd_us_per_instance, crowd_scaling, crowd_vs_lone\n"
            "  --json              one JSON object with the figures as the last stdout line\n");
    fprintf(f, "reference options (the full-space run the bench times, and the full-space solves\n"
               "of a bake it runs or of --bake-errors):\n" SW_REFERENCE_USAGE
               "exit status: 0 done, 1 failed, 2 bad arguments\n");
}

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

/* --rho R[,R...]: patch radii in (0, 1], at most SW_COND_MAX_RHO. */
static int parse_rhos(const char *tool, const char *s, sw_cond_bench_params *cp) {
    char buf[256];
    if (strlen(s) >= sizeof buf) return sw_tool_real(tool, "--rho", "", 0, 1, "in (0, 1]", NULL);
    strcpy(buf, s);
    cp->nrho = 0;
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (cp->nrho == SW_COND_MAX_RHO) {
            fprintf(stderr, "%s: --rho takes at most %d radii\n", tool, SW_COND_MAX_RHO);
            return 0;
        }
        if (!sw_tool_real(tool, "--rho", tok, 0, 1.0000001, "in (0, 1]", &cp->rho[cp->nrho]))
            return 0;
        cp->nrho++;
    }
    return cp->nrho > 0 || sw_tool_real(tool, "--rho", s, 0, 1, "in (0, 1]", NULL);
}

/* A clip part's correction error as printed: its figure, or why it has none. */
static const char *clip_error_text(int has, const char *figure, const sw_eval_result *e) {
    return has ? figure : e->no_correction ? "n/a (at rest: no correction)" : "n/a";
}

int main(int argc, char **argv) {
    static const char *tool = "sinew-bench";
    sw_character_args ca;
    sw_character_args_init(&ca, tool);
    const char *blob_path = NULL, *out_dir = NULL, *world_path = NULL;
    int json = 0, full_frames = 0, contract_steps = 10000, threads = 0, bake_errors = 0;
    int timing_passes = 1;
    int dynamic = 0, hold_frames = 0, instances = 0, patch_budget = 0;
    sinew_self_contact self_mode = SINEW_SELF_CONTACT_POSE_SPACE;
    int sc_compare = 0, error_gap = 0, newton_compare = 0;
    sw_cond_bench_params cond = {{0}, 0, 0, NULL};
    sw_fullsim_params ref_solver = sw_fullsim_params_default(); /* the reference's options */
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1;
        if (sw_reference_args_take(&ref_solver, argc, argv, &i, &ok)) {
            if (!ok) return 2;
        } else if (sw_character_args_take(&ca, argc, argv, &i, &ok)) {
            /* a character option, consumed */
        } else if (!strcmp(a, "--blob") && next)
            blob_path = argv[++i];
        else if (!strcmp(a, "--out") && next)
            out_dir = argv[++i];
        else if (!strcmp(a, "--world") && next)
            world_path = argv[++i];
        else if (!strcmp(a, "--rho") && next)
            ok = parse_rhos(tool, argv[++i], &cond);
        else if (!strcmp(a, "--patch-budget") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 100000000, &patch_budget);
        else if (!strcmp(a, "--full-frames") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 100000, &full_frames);
        else if (!strcmp(a, "--contract-steps") && next)
            ok = sw_tool_int(tool, a, argv[++i], 0, 100000000, &contract_steps);
        else if (!strcmp(a, "--threads") && next)
            ok = sw_tool_int(tool, a, argv[++i], 0, 256, &threads);
        else if (!strcmp(a, "--timing-passes") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 1000, &timing_passes);
        else if (!strcmp(a, "--instances") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 4096, &instances);
        else if (!strcmp(a, "--hold-frames") && next)
            ok = sw_tool_int(tool, a, argv[++i], 2, 100000, &hold_frames);
        else if (!strcmp(a, "--self-contact") && next) {
            int k = sw_tool_choice(argv[++i], sw_self_contact_names);
            if (!(ok = k >= 0))
                fprintf(stderr, "%s: --self-contact: pose-space, exhaustive or pose-pairs\n", tool);
            self_mode = ok ? (sinew_self_contact)k : SINEW_SELF_CONTACT_POSE_SPACE;
        } else if (!strcmp(a, "--sc-compare"))
            sc_compare = 1;
        else if (!strcmp(a, "--newton-compare"))
            newton_compare = 1;
        else if (!strcmp(a, "--error-gap"))
            error_gap = 1;
        else if (!strcmp(a, "--dynamic"))
            dynamic = 1;
        else if (!strcmp(a, "--bake-errors"))
            bake_errors = 1;
        else if (!strcmp(a, "--json"))
            json = 1;
        else if (!sw_tool_help(a, usage))
            return sw_tool_bad_arg(tool, a, usage);
        if (!ok) return 2; /* the value's message is out */
    }
    if (!sw_character_args_valid(&ca)) return 2;
    if (error_gap && blob_path && !bake_errors) {
        fprintf(stderr,
                "%s: --error-gap needs the bake's poses: without --blob, or with "
                "--bake-errors\n",
                tool);
        return 2;
    }
    if (bake_errors && !blob_path) {
        fprintf(stderr,
                "%s: --bake-errors applies only with --blob (without --blob the bench bakes and "
                "reports the bake's own err_train/err_heldout already)\n",
                tool);
        return 2;
    }
    if (hold_frames && !dynamic) {
        fprintf(stderr, "%s: --hold-frames applies only with --dynamic\n", tool);
        return 2;
    }
    if ((cond.nrho > 0 || patch_budget > 0) && !world_path) {
        fprintf(stderr, "%s: --rho and --patch-budget apply only with --world\n", tool);
        return 2;
    }
    cond.budget = (uint32_t)patch_budget;
    cond.out_dir = out_dir;
    if (world_path && !sw_tool_format(tool, "--world", world_path, "json", ".json (world file)"))
        return 2;
    /* the output folder before the long run: an unwritable one is an error now */
    if (out_dir && !sw_tool_make_dirs(out_dir)) {
        fprintf(stderr, "%s: --out '%s': cannot create or write the folder: %s\n", tool, out_dir,
                strerror(errno ? errno : EACCES));
        return 1;
    }
    sw_error err;
    sw_character ch;
    sw_clip_split clips;
    sw_scene_character_info info;
    sinew_result r = sw_character_args_make(&ca, &ch, &clips, &info, &err);
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "%s: ", tool);
    if (ca.file) {
        sw_quality quality;
        sw_tetmesh_quality(&ch.mesh, 0, &quality);
        sw_tool_print_scene(tool, &ch, &clips, &info, &quality);
    }
    int nf = ch.clip.nframes;

    /* 1. bake (or load) */
    sw_bake_params bp = sw_bake_params_default();
    bp.threads = threads;
    bp.reference = &ref_solver; /* its bake's solves as its full frames' */
    bp.progress = 1;
    sw_tool_progress bar;
    sw_tool_progress_init(&bar, tool);
    bp.on_progress = sw_tool_progress_print;
    bp.progress_user = &bar;
    sw_tool_bake_clips(&ca, &clips, &bp);
    sw_bake_result res;
    memset(&res, 0, sizeof res);
    sinew_blob *blob = NULL;
    void *mem = NULL;
    double bake_s = 0;
    size_t blob_bytes = 0; /* the file's or the baked blob's size */
    sinew_blob_def bd = sinew_blob_def_default();
    if (blob_path) {
        bd.path = blob_path;
        struct stat sb;
        if (stat(blob_path, &sb) == 0) blob_bytes = (size_t)sb.st_size;
    } else {
        double t0 = sw_now_seconds();
        size_t size = 0;
        if ((r = sw_bake(&ch, &bp, &res, &err)) != SINEW_OK ||
            (r = sw_blob_write_memory(&res.view, &mem, &size, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "sinew-bench: bake failed: ");
        bake_s = sw_now_seconds() - t0;
        bd.data = mem;
        bd.data_size = size;
        blob_bytes = size;
    }
    if (sw_tool_blob_load(tool, blob_path ? blob_path : "just baked", bd, &blob) != SINEW_OK)
        return 1;
    const sw_blob_view *v = sw_blob_get_view(blob);
    size_t instance_bytes = 0;
    if ((r = sinew_instance_memory_size(blob, NULL, &instance_bytes)) != SINEW_OK) {
        fprintf(stderr, "sinew-bench: cannot size an instance: %s\n", sinew_result_string(r));
        return 1;
    }
    if (v->nverts != ch.mesh.nverts || v->nbones != ch.skel.nbones) {
        fprintf(stderr,
                "sinew-bench: the blob does not belong to this character (%d/%d vertices, %d/%d "
                "bones)\n",
                v->nverts, ch.mesh.nverts, v->nbones, ch.skel.nbones);
        return 1;
    }

    /* An asset without weights: the bake computed heat-diffusion weights (bake.c); the
     * reference simulator gets the same ones (it uses them for its warm start). */
    if (!ch.weights.w &&
        (r = sw_weights_heat(&ch.mesh, &ch.skel, 0, &ch.weights, &err)) != SINEW_OK)
        return sw_tool_failed(r, &err, "sinew-bench: ");

    /* 2. full-space reference over the first K clip frames (same motion, all cores) */
    sw_fullsim_params fp = sw_fullsim_params_default();
    fp.threads = threads;
    sw_fullsim_params_take_solver(&fp, &ref_solver);
    sw_fullsim *sim = NULL;
    int kf = full_frames > 0 && full_frames < nf ? full_frames : nf; /* default: the whole clip */
    double *full = malloc((size_t)(kf > 0 ? kf : 1) * sizeof(double));
    double *full_x = malloc((size_t)(kf > 0 ? kf : 1) * 3 * ch.mesh.nverts * sizeof(double));
    double *mass = malloc((size_t)ch.mesh.nverts * sizeof(double)); /* the reference's */
    if (!full || !full_x || !mass) {
        fprintf(stderr, "sinew-bench: out of memory\n");
        return 1;
    }
    if ((r = sw_fullsim_create(&ch, &fp, &sim, &err)) != SINEW_OK)
        return sw_tool_failed(r, &err, "%s: ", tool);
    /* the full reference steps every clip frame up to the last timed one, from rest */
    int full_unsettled = 0; /* frames whose contact set did not settle */
    int full_newton_max = 0;
    double full_mean = 0, full_max = 0;
    sw_linear_solver full_solver = SW_SOLVER_AUTO;
    for (int f = 0; f < kf; ++f) {
        sw_fullsim_stats st;
        sw_fullsim_step(sim, ch.clip.T + (size_t)f * 12 * ch.skel.nbones, &st);
        full_unsettled += st.contacts_unsettled;
        full[f] = 1e3 * st.seconds;
        full_mean += full[f] / kf;
        full_max = fmax(full_max, full[f]);
        full_newton_max = st.newton_iters > full_newton_max ? st.newton_iters : full_newton_max;
        full_solver = st.solver;
        memcpy(full_x + (size_t)f * 3 * ch.mesh.nverts, sw_fullsim_positions(sim),
               sizeof(double) * 3 * ch.mesh.nverts);
        fprintf(stderr, "sinew-bench: full-space frame %d/%d: %.1f ms\n", f + 1, kf, full[f]);
    }
    double full_ms = sw_median(full, kf);
    memcpy(mass, sw_fullsim_masses(sim), sizeof(double) * ch.mesh.nverts);
    sw_fullsim_destroy(sim);

    /* 3. subspace: step + read over the clip */
    sinew_instance *inst;
    sinew_instance_def idef = sinew_instance_def_default();
    idef.self_contact = self_mode;
    if ((r = sinew_instance_create(blob, &idef, &inst)) != SINEW_OK) {
        fprintf(stderr, "sinew-bench: cannot create an instance: %s\n", sinew_result_string(r));
        return 1;
    }
    uint32_t ns = sinew_blob_surface_vertex_count(blob);
    float *pos = malloc((size_t)ns * 3 * sizeof(float)),
          *nrm = malloc((size_t)ns * 3 * sizeof(float));
    double *sub = malloc((size_t)nf * sizeof(double));
    double *phase = malloc((size_t)nf * NPHASES * sizeof(double)), evals = 0, factors = 0;
    long failed_steps = 0; /* steps that did not return SINEW_OK (a non-finite state) */
    int beyond_frames = 0, beyond_bone = -1; /* frames bent beyond the bake's training */
    double beyond_deg = 0;
    for (int pass = 0; pass < timing_passes; ++pass)
        for (int f = 0; f < nf; ++f) {
            double t0 = sw_now_seconds();
            sw_instance_set_pose_d(inst, ch.clip.T + (size_t)f * 12 * ch.skel.nbones);
            failed_steps +=
                sinew_instance_step(inst, 1.0f / (float)(ch.clip.fps > 0 ? ch.clip.fps : 30)) !=
                SINEW_OK;
            sinew_instance_read_surface(inst, pos, nrm, ns);
            double ms = 1e3 * (sw_now_seconds() - t0);
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(inst, &st);
            const double ph[NPHASES] = {st.ms_skin, st.ms_contact, st.ms_dynamics, st.ms_solve,
                                        st.ms_output};
            for (int k = 0; k < NPHASES; ++k) {
                double *pk = phase + (size_t)k * nf + f;
                *pk = pass == 0 ? ph[k] : fmin(*pk, ph[k]);
            }
            sub[f] = pass == 0 ? ms : fmin(sub[f], ms);
            if (pass > 0)
                continue; /* the counts are the first play's (a failed step is
                             counted in any play: none is hidden) */
            evals += st.potential_evals / (double)nf;
            factors += st.factorizations / (double)nf;
            beyond_frames += (st.status & SINEW_STEP_BEYOND_TRAINING) != 0;
            if (st.beyond_training_deg > beyond_deg)
                beyond_deg = st.beyond_training_deg, beyond_bone = st.beyond_training_bone;
        }
    double sub_ms = sw_median(sub, nf), phase_ms[NPHASES];
    for (int k = 0; k < NPHASES; ++k)
        phase_ms[k] = sw_median(phase + (size_t)k * nf, nf);
    free(phase);
    if (out_dir && (r = write_frames(out_dir, blob, inst, &ch, &err)) != SINEW_OK)
        return sw_tool_failed(r, &err, "%s: --out %s: ", tool, out_dir);

    /* 4. plain DQS of the same surface (the render mesh's own vertices when it has one) */
    double d_ms = sw_dqs_bench_ms(v, &ch.clip, nf, timing_passes);
    if (!(d_ms >= 0)) {
        fprintf(stderr, "sinew-bench: out of memory\n");
        return 1;
    }

    /* 5. errors against full-space solutions, always by the bake's definition
       (sw_bake_errors): on the bake's poses when it baked here; a given blob on the clip
       frames the reference solved above (split as the bake splits a clip), or, with
       --bake-errors, on the bake's poses solved anew with the default parameters and the
       reference options */
    sw_eval_result et, eh;
    int clip_errors = blob_path && !bake_errors;
    const char *err_source = !blob_path ? "bake" : clip_errors ? "clip" : "bake_default_poses";
    int ref_unsettled;
    if (clip_errors) {
        /* borrows the clip's poses and the solutions above: never sw_bake_result_free'd */
        sw_bake_result clip;
        memset(&clip, 0, sizeof clip);
        /* a file's held-out clip (the character's clip then) is held out whole */
        int ntr = bp.nheldout_clips > 0 ? 0 : (int)floor(kf * (1.0 - bp.heldout_fraction));
        size_t pt = (size_t)12 * ch.skel.nbones, px = (size_t)3 * ch.mesh.nverts;
        clip.mass = mass;
        clip.ntrain = ntr;
        clip.train_T = ch.clip.T;
        clip.train_x = full_x;
        clip.nheldout = kf - ntr;
        clip.heldout_T = ch.clip.T + ntr * pt;
        clip.heldout_x = full_x + ntr * px;
        clip.heldout_after = ntr; /* the reference solved the clip on one path */
        if ((r = sw_bake_errors(blob, &clip, self_mode, &et, &eh, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "%s: cannot evaluate the blob: ", tool);
        ref_unsettled = full_unsettled;
    } else {
        if (blob_path && (r = sw_bake_solutions(&ch, &bp, &res, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "%s: the bake's reference solutions: ", tool);
        if ((r = sw_bake_errors(blob, &res, self_mode, &et, &eh, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "%s: cannot evaluate the blob: ", tool);
        ref_unsettled = res.train_unsettled + res.heldout_unsettled;
    }

    sw_gap_bench gap;
    if (error_gap && (r = sw_gap_bench_run(blob, &res, self_mode, &gap, &err)) != SINEW_OK)
        return sw_tool_failed(r, &err, "%s: ", tool);
    if (error_gap) sw_gap_bench_print(&gap, stderr, 0);

    /* 6. the real-time contract: allocation and lock calls inside the step */
    long allocs = -1, locks = -1;
    (void)sw_rt_interpose_active(); /* its self-check counts: outside the counted steps */
    if (contract_steps > 0) {
        for (int f = 0; f < 10; ++f) { /* warm-up */
            sw_instance_set_pose_d(inst, ch.clip.T + (size_t)(f % nf) * 12 * ch.skel.nbones);
            sinew_instance_step(inst, 1.0f / 30);
        }
        sw_rt_count_begin();
        for (int s = 0; s < contract_steps; ++s) {
            sinew_instance_set_pose(inst, NULL, 0); /* rejected: also must not allocate */
            sw_instance_set_pose_d(inst, ch.clip.T + (size_t)(s % nf) * 12 * ch.skel.nbones);
            failed_steps += sinew_instance_step(inst, 1.0f / 30) != SINEW_OK;
            sinew_instance_read_surface(inst, pos, nrm, ns);
        }
        sw_rt_counts c = sw_rt_count_end();
        sw_rt_counts_report(&c, &allocs, &locks);
    }
    failed_steps += et.failed + eh.failed;

    /* 7. the collision world, when given */
    sw_world_bench wb;
    memset(&wb, 0, sizeof wb);
    if (world_path) {
        sw_world_scene ws;
        if ((r = sw_world_scene_load(world_path, &ws, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "sinew-bench: ");
        r = sw_world_bench_run(&ch, blob, &ws, &fp, ca.frames, contract_steps, &cond, &wb, &err);
        sw_world_scene_free(&ws);
        if (r != SINEW_OK) return sw_tool_failed(r, &err, "sinew-bench: world run failed: ");
        failed_steps += wb.sub_failed + wb.ref_failed;
        fprintf(stderr,
                "sinew-bench: world %s: %d frames, %d with contact; err_world_sub %.4f; "
                "penetration full %.5f sub %.5f; world query %.4f ms, %.0f queries, %.1f "
                "contacts a step; allocs %ld, locks %ld\n",
                world_path, wb.frames, wb.world_contact_frames, wb.err_world_sub, wb.pen_world_full,
                wb.pen_world_sub, wb.world_query_ms, wb.world_queries, wb.world_contacts, wb.allocs,
                wb.locks);
        for (int k = 0; k < wb.ncond; ++k) {
            const sw_cond_bench *cb = &wb.cond[k];
            failed_steps += cb->failed;
            fprintf(stderr,
                    "sinew-bench: condensed (rho %.4g of the diagonal, budget %u): err_world_cond "
                    "%.4f (subspace %.4f); speedup mean %.1f worst %.1f; patch %.2f%% mean, "
                    "%.2f%% max; frame p100/p50 %.2f; %d frames truncated; pop %.2f; frames with a "
                    "patch %.1f ms at %.0f vertices, %.0f tets (means)\n",
                    cb->rho, cb->budget, cb->err_world_cond, wb.err_world_sub, cb->speedup_mean,
                    cb->speedup_worst, 100 * cb->patch_frac_mean, 100 * cb->patch_frac_max,
                    cb->p100_over_p50, cb->truncated_frames, cb->pop_max, cb->patch_ms_mean,
                    cb->patch_verts_mean, cb->patch_tets_mean);
        }
    }
    /* 8. dynamics against the reference's backward Euler, when asked */
    sw_dyn_bench db;
    memset(&db, 0, sizeof db);
    if (dynamic) {
        r = sw_dyn_bench_run(&ch, blob, &fp, hold_frames ? hold_frames : 30,
                             kf == nf ? full_x : NULL, &db, &err);
        if (r != SINEW_OK) return sw_tool_failed(r, &err, "sinew-bench: dynamic run failed: ");
        failed_steps += db.sub_failed + db.ref_failed;
        fprintf(stderr,
                "sinew-bench: dynamic (dt %g, Rayleigh %g %g, %d + %d hold frames): err_dynamic "
                "%.4f (hold %.4f); overshoot sub %.5g full %.5g ratio %.3f; settle sub %.3g "
                "full %.3g; dynamic increment error %.4f (rms %.3g); %.2f / %.3f ms a step\n",
                db.dt, db.rayleigh_alpha, db.rayleigh_beta, db.frames, db.hold_frames,
                db.err_dynamic, db.err_dynamic_hold, db.overshoot_sub, db.overshoot_full,
                db.overshoot_ratio, db.settle_sub, db.settle_full, db.err_increment,
                db.increment_rms, db.full_ms, db.sub_ms);
    }
    /* 9. a crowd of instances on host threads, when asked */
    sw_crowd_bench cb;
    memset(&cb, 0, sizeof cb);
    if (instances) {
        if ((r = sw_crowd_bench_run(&ch, blob, instances, threads, &cb, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "sinew-bench: crowd run failed: ");
        failed_steps += cb.failed;
        fprintf(stderr,
                "sinew-bench: crowd of %d instances on %d threads (%d frames after %d warm-up): "
                "%.3f ms a frame (%.1f us an instance), 1 thread %.3f ms, scaling %.2fx; lone "
                "instance %.4f ms, crowd/lone %.2f\n",
                cb.instances, cb.threads, cb.frames, cb.warmup_frames, cb.ms, cb.us_per_instance,
                cb.ms_1thread, cb.scaling, cb.lone_ms, cb.vs_lone);
    }
    /* 10. self-contact, pose-space against exhaustive, when asked */
    sw_sc_bench scb;
    memset(&scb, 0, sizeof scb);
    if (sc_compare) {
        float dt = 1.0f / (float)(ch.clip.fps > 0 ? ch.clip.fps : 30);
        if ((r = sw_sc_bench_run(blob, ch.clip.T, nf, dt, 3, &scb, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "sinew-bench: self-contact comparison failed: ");
        failed_steps += scb.failed;
        sw_sc_bench_print(&scb, stderr, 0);
    }
    /* 11. Newton on the current and on the rest Hessian, when asked */
    sw_newton_bench nwb;
    memset(&nwb, 0, sizeof nwb);
    if (newton_compare) {
        float dt = 1.0f / (float)(ch.clip.fps > 0 ? ch.clip.fps : 30);
        if ((r = sw_newton_bench_run(blob, ch.clip.T, nf, dt, 3, &nwb, &err)) != SINEW_OK)
            return sw_tool_failed(r, &err, "sinew-bench: Newton comparison failed: ");
        failed_steps += nwb.failed;
        sw_newton_bench_print(&nwb, stderr, 0);
    }
    /* an empty part of the clip's split (very few frames, --full-frames 1) has no error, nor
       has one whose frames are at rest (a share of rounding: sw_eval_result.no_correction) */
    char e_tr[32] = "null", e_ho[32] = "null";
    int has_tr = !clip_errors || (et.frames > 0 && !et.no_correction),
        has_ho = !clip_errors || (eh.frames > 0 && !eh.no_correction);
    if (has_tr) snprintf(e_tr, sizeof e_tr, "%.5f", et.correction_error);
    if (has_ho) snprintf(e_ho, sizeof e_ho, "%.5f", eh.correction_error);
    fprintf(stderr,
            "sinew-bench: full %.2f ms, subspace %.3f ms, DQS %.3f ms per frame; speedup %.1fx, "
            "cost %.1fx DQS;\n",
            full_ms, sub_ms, d_ms, full_ms / sub_ms, sub_ms / d_ms);
    if (clip_errors)
        fprintf(stderr,
                "             correction error on clip frames (not the bake's figures): train "
                "%s (%d frames) held-out %s (%d frames);\n",
                clip_error_text(has_tr, e_tr, &et), et.frames, clip_error_text(has_ho, e_ho, &eh),
                eh.frames);
    else
        fprintf(stderr, "             correction error (%s) train %.4f held-out %.4f;\n",
                err_source, et.correction_error, eh.correction_error);
    fprintf(stderr, "             allocs %ld, locks %ld in %d steps\n", allocs, locks,
            contract_steps);
    fprintf(stderr, "             memory: %zu bytes an instance, blob %zu bytes\n", instance_bytes,
            blob_bytes);
    fprintf(stderr,
            "             step phases (median ms): skin %.4f, contact %.4f, dynamics %.4f, solve "
            "%.4f, output %.4f; %.1f potential evaluations and %.1f factorisations a step\n",
            phase_ms[0], phase_ms[1], phase_ms[2], phase_ms[3], phase_ms[4], evals, factors);
    if (json)
        printf(
            "{\"scene\":\"%s\",\"tets\":%d,\"verts\":%d,\"surface_verts\":%u,\"frames\":%d,"
            "\"speedup_vs_full\":%.2f,\"cost_vs_dqs\":%.2f,\"%s\":%s,\"%s\":%s,"
            "\"rank\":%d,\"cubature_tets\":%d,\"allocs_in_step\":%ld,\"locks_in_step\":%ld,"
            "\"contract_steps\":%d,\"full_ms\":%.3f,\"sub_ms\":%.4f,\"dqs_ms\":%.4f,\"bake_"
            "seconds\":%.2f,"
            "\"err_source\":\"%s\",\"failed_steps\":%ld,\"ref_unsettled\":%d,"
            "\"phase_ms\":{\"skin\":%.4f,\"contact\":%.4f,\"dynamics\":%.4f,\"solve\":%.4f,"
            "\"output\":%.4f},\"potential_evals\":%.2f,\"solver\":\"%s\",\"unsettled_frames\":%d,"
            "\"newton_iters_max\":%d,\"full_ms_mean\":%.3f,\"full_ms_max\":%.3f",
            ca.file    ? ca.file
            : ca.scene ? ca.scene
                       : ca.mesh,
            ch.mesh.ntets, ch.mesh.nverts, ns, nf, full_ms / sub_ms, sub_ms / d_ms,
            clip_errors ? "err_clip_train" : "err_train", e_tr,
            clip_errors ? "err_clip_heldout" : "err_heldout", e_ho, v->rank_total, v->ncub, allocs,
            locks, contract_steps, full_ms, sub_ms, d_ms, bake_s, err_source, failed_steps,
            ref_unsettled, phase_ms[0], phase_ms[1], phase_ms[2], phase_ms[3], phase_ms[4], evals,
            sw_linear_solver_name(full_solver), full_unsettled, full_newton_max, full_mean,
            full_max);
    if (json)
        printf(",\"factorizations\":%.2f,\"instance_bytes\":%zu,\"blob_bytes\":%zu,"
               "\"beyond_training_frames\":%d,\"beyond_training_deg_max\":%.2f,"
               "\"beyond_training_bone\":%d,\"timing_passes\":%d",
               factors, instance_bytes, blob_bytes, beyond_frames, beyond_deg, beyond_bone,
               timing_passes);
    if (json && instances)
        printf(",\"crowd_instances\":%d,\"crowd_threads\":%d,\"crowd_frames\":%d,"
               "\"crowd_ms\":%.4f,\"crowd_us_per_instance\":%.3f,\"crowd_scaling\":%.3f,"
               "\"crowd_vs_lone\":%.3f,\"crowd_ms_1thread\":%.4f,\"crowd_lone_ms\":%.4f,"
               "\"crowd_lone_median_ms\":%.4f",
               cb.instances, cb.threads, cb.frames, cb.ms, cb.us_per_instance, cb.scaling,
               cb.vs_lone, cb.ms_1thread, cb.lone_ms, cb.lone_median_ms);
    if (json) printf(",\"self_contact\":\"%s\"", sw_self_contact_keys[self_mode]);
    if (json && sc_compare) sw_sc_bench_print(&scb, stdout, 1);
    if (json && newton_compare) sw_newton_bench_print(&nwb, stdout, 1);
    if (json && error_gap) sw_gap_bench_print(&gap, stdout, 1);
    if (json && clip_errors)
        printf(",\"err_clip_train_frames\":%d,\"err_clip_heldout_frames\":%d",
               et.frames + et.failed, eh.frames + eh.failed);
    if (json && world_path)
        printf(",\"world\":\"%s\",\"world_frames\":%d,\"world_contact_frames\":%d,"
               "\"err_world_sub\":%.5f,\"pen_world_full\":%.6g,\"pen_world_sub\":%.6g,"
               "\"world_query_ms\":%.5f,\"world_queries\":%.1f,\"world_contacts\":%.1f,"
               "\"world_full_ms\":%.3f,\"world_sub_ms\":%.4f,\"world_ref_unsettled\":%d,"
               "\"world_allocs_in_step\":%ld,\"world_locks_in_step\":%ld",
               world_path, wb.frames, wb.world_contact_frames, wb.err_world_sub, wb.pen_world_full,
               wb.pen_world_sub, wb.world_query_ms, wb.world_queries, wb.world_contacts, wb.full_ms,
               wb.sub_ms, wb.ref_unsettled, wb.allocs, wb.locks);
    for (int k = 0; json && k < wb.ncond; ++k) {
        const sw_cond_bench *cb = &wb.cond[k];
        if (k == 1) printf(",\"cond_sweep\":[");
        if (k >= 1)
            printf("%s{\"rho\":%.5g,\"err_world_cond\":%.5f,\"speedup_cond_mean\":%.2f,"
                   "\"speedup_cond_worst\":%.2f,\"patch_frac_mean\":%.5f,\"patch_frac_max\":%.5f,"
                   "\"cond_ms_max\":%.4f,\"patch_ms_mean\":%.4f,\"patch_verts_mean\":%.1f,"
                   "\"patch_tets_mean\":%.1f}%s",
                   k > 1 ? "," : "", cb->rho, cb->err_world_cond, cb->speedup_mean,
                   cb->speedup_worst, cb->patch_frac_mean, cb->patch_frac_max, cb->ms_max,
                   cb->patch_ms_mean, cb->patch_verts_mean, cb->patch_tets_mean,
                   k == wb.ncond - 1 ? "]" : "");
    }
    if (json && wb.ncond > 0)
        printf(",\"rho\":%.5g,\"patch_budget\":%u,\"err_world_cond\":%.5f,"
               "\"speedup_cond_mean\":%.2f,\"speedup_cond_worst\":%.2f,\"patch_frac_mean\":%.5f,"
               "\"patch_frac_max\":%.5f,\"frame_p100_over_p50\":%.3f,"
               "\"patch_truncated_frames\":%d,\"pop_max\":%.3f,\"cond_ms_median\":%.4f,"
               "\"cond_ms_max\":%.4f,\"pcg_iters_max\":%u,\"patch_ms_mean\":%.4f,"
               "\"patch_verts_mean\":%.1f,\"patch_tets_mean\":%.1f",
               wb.cond[0].rho, wb.cond[0].budget, wb.cond[0].err_world_cond,
               wb.cond[0].speedup_mean, wb.cond[0].speedup_worst, wb.cond[0].patch_frac_mean,
               wb.cond[0].patch_frac_max, wb.cond[0].p100_over_p50, wb.cond[0].truncated_frames,
               wb.cond[0].pop_max, wb.cond[0].ms_median, wb.cond[0].ms_max,
               wb.cond[0].pcg_iters_max, wb.cond[0].patch_ms_mean, wb.cond[0].patch_verts_mean,
               wb.cond[0].patch_tets_mean);
    char ratio[32] = "null"; /* no reference overshoot: no ratio */
    if (isfinite(db.overshoot_ratio)) snprintf(ratio, sizeof ratio, "%.4f", db.overshoot_ratio);
    char inc[32] = "null"; /* no reference quasistatic clip (--full-frames): no increment */
    if (isfinite(db.err_increment)) snprintf(inc, sizeof inc, "%.5f", db.err_increment);
    if (json && dynamic)
        printf(",\"dyn_dt\":%.9g,\"dyn_rayleigh_alpha\":%g,\"dyn_rayleigh_beta\":%g,"
               "\"hold_frames\":%d,\"err_dynamic\":%.5f,\"err_dynamic_hold\":%.5f,"
               "\"overshoot_sub\":%.6g,\"overshoot_full\":%.6g,\"overshoot_ratio\":%s,"
               "\"settle_sub\":%.6g,\"settle_full\":%.6g,\"dyn_full_ms\":%.3f,"
               "\"dyn_sub_ms\":%.4f,\"dyn_ref_failed\":%d,\"dyn_ref_unconverged\":%d,"
               "\"dyn_ref_unsettled\":%d,\"dyn_sub_failed\":%d,\"err_dyn_increment\":%s,"
               "\"dyn_increment_rms\":%.6g,\"dyn_sub_limited\":%d,\"dyn_sub_teleport\":%d,"
               "\"dyn_sub_guard\":%d,\"dyn_sub_converged\":%d",
               db.dt, db.rayleigh_alpha, db.rayleigh_beta, db.hold_frames, db.err_dynamic,
               db.err_dynamic_hold, db.overshoot_sub, db.overshoot_full, ratio, db.settle_sub,
               db.settle_full, db.full_ms, db.sub_ms, db.ref_failed, db.ref_unconverged,
               db.ref_unsettled, db.sub_failed, inc, db.increment_rms, db.sub_limited,
               db.sub_teleport, db.sub_guard, db.sub_converged);
    if (json) printf("}\n");
    free(full);
    free(full_x);
    free(mass);
    free(sub);
    free(pos);
    free(nrm);
    sinew_instance_destroy(inst);
    sinew_blob_destroy(blob);
    free(mem);
    sw_bake_result_free(&res);
    sw_character_free(&ch);
    sw_clip_split_free(&clips);
    return 0;
}
