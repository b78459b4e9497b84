/* sinew-bake: a rigged character in, a blob out (DESIGN.md §5).
 *
 *   sinew-bake (FILE.glb|.gltf|.fbx [--tets N] [--train-clips A,B] [--heldout-clips C]
 *              [--fps F] [--height H] | --scene NAME [--tets N] [--frames F] |
 *              --mesh FILE --skeleton FILE.tgf [--weights FILE.dmat] [--clip FILE])
 *              --out FILE.blob [--report DIR]
 *              [--selector greedy|importance|nnhtp] [--tol 0.05] [--max-rank R]
 *              [--compare-cubature] [--no-self-contact] [--return-path|--no-return-path]
 *              [--inertia-modes]
 *              [--solver S] [--hessian M] [--contact-rounds R] [--set-check C]
 *              [--threads T] [--data DIR]
 *              [--force] [--json]
 *
 * Shows progress per stage on stderr and ends with a summary (per-stage time, ranks,
 * cubature sizes, training and held-out errors); with --json the last stdout line is
 * one JSON object; with --report DIR the bake report (bake_report.h: DIR/report.html,
 * DIR/report.json, a contact sheet of held-out frames). The blob is measured (sw_bake_errors, the
 * definition sinew-bench reports too) before it is written; a training error of
 * SW_BAKE_MAX_TRAIN_ERROR or more is an error and writes nothing, unless --force. The blob is
 * written atomically (temporary file + rename). Exit status: 0 written, 1 failed, 2 bad arguments.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SW_TOOL_CHARACTER_ARGS
#define SW_TOOL_REFERENCE_ARGS
#include "tool_common.h"
#include "sw_mesh.h"

#include "bake.h"
#include "bake_adaptive.h"
#include "bake_report.h"
#include "blob_write.h"
#include "character_io.h"
#include "samples.h"
#include "subspace_eval.h"

#define BAKE_BEYOND 32 /* joints listed beyond training, at most (8 in the summary) */

/* v as a JSON number, or null when it is not finite (buf: 32 chars). */
static const char *json_number(double v, char *buf) {
    if (!isfinite(v)) return "null";
    snprintf(buf, 32, "%.5f", v);
    return buf;
}

static void usage(FILE *f) {
    fprintf(f,
            "usage: sinew-bake FILE --out FILE.blob [--report DIR] [--tets N]\n"
            "                  [--train-clips A,B] [--heldout-clips C]\n"
            "       sinew-bake (FILE | --scene NAME | --mesh FILE --skeleton FILE.tgf)\n"
            "                  --out FILE.blob [character options] [bake options]\n"
            "                  [research options] [reference options]\n"
            "what an artist's bake needs (the rest has defaults that suit a character):\n"
            "  FILE             the rigged glTF 2.0 (.gltf, .glb) or FBX character\n"
            "  --out FILE       the blob to write (atomically: FILE.tmp, then renamed); a\n"
            "                   FILE that cannot be written is an error before the bake\n"
            "  --report DIR     write the bake report: DIR/report.html (plots of every clip\n"
            "                   frame's error, ranks, cubature, stage times, a contact sheet of\n"
            "                   held-out frames) and DIR/report.json (the same figures)\n"
            "  --tets N         how finely the simulation fills the character (below)\n"
            "  --train-clips A,B  --heldout-clips C  the clips it learns from and those it\n"
            "                   is measured on (below); a character's only clip is split:\n"
            "                   the figures are measured on its last 40%%, then the blob\n"
            "                   ships trained on all of it (--ship-split: the split's)\n"
            "character:\n" SW_CHARACTER_USAGE);
    fprintf(f,
            "bake:\n"
            "  --cache DIR      keep the full-space solutions in DIR and reuse them when a\n"
            "                   later bake solves the same poses of the same character (a\n"
            "                   re-bake that changes the cubature, rank or report only)\n"
            "  --ship-split     ship the blob trained on the split of a character's only\n"
            "                   clip, the one the held-out figures measure (default: baked\n"
            "                   again on the whole clip once measured)\n"
            "  --threads T      0..256 (default 0: all cores)\n"
            "  --force          write the blob even when its training error is %.2f or more\n"
            "                   (the share of the physics correction it misses on its own\n"
            "                   training poses; without --force that is an error)\n"
            "  --json           one JSON object with the figures as the last stdout line\n",
            SW_BAKE_MAX_TRAIN_ERROR);
    fprintf(f, "research (the model's knobs, for studying the method; [--compare-cubature]\n"
               "[--no-self-contact] too):\n"
               "  --selector S     cubature selector: greedy | importance | nnhtp (default)\n"
               "  --tol T          cubature fit tolerance, 0 < T < 1 (default 0.05)\n"
               "  --max-rank R     basis rank per domain, 1..1024 (default 30)\n"
               "  --fold-share S   a bone whose tets hold less than S of the mesh's volume\n"
               "                   joins its parent's domain, 0..0.5 (default 0: off; 0.03\n"
               "                   folds the elephant's 24 bones into 11 domains)\n"
               "  --spring-k K     interface spring stiffness, K > 0 (default: of 20, 10, 5 and\n"
               "                   2.5 E h the one with the lowest training error)\n"
               "  --return-path    also train on the way home: from the first training clip's\n"
               "                   last frame, its earlier frames backwards, each bent less than\n"
               "                   the one before (a fold keeps its branch on the way out); by\n"
               "                   default on where the held-out frames continue the training\n"
               "                   clip (a --clip or a file's one clip split 60/40), off for\n"
               "                   --train-clips; --no-return-path: never\n"
               "  --pair-sweeps    also train on every joint swept together with its parent\n"
               "                   joint (combinations the single-joint sweeps never show); by\n"
               "                   default on with --joint-range; --no-pair-sweeps: never\n"
               "  --no-sibling-sweeps  do not train on two sibling joints whose flesh meets\n"
               "                   swept together (by default each such pair is: the flesh\n"
               "                   between them shears with the difference of their bends)\n"
               "  --adaptive R     then up to R rounds that each add the K (default 8) of C\n"
               "                   (default 64) random combined poses the blob steps worst (the\n"
               "                   full-space force its state leaves over plain skinning's) to\n"
               "                   the training poses and bake again, until B poses (default 32)\n"
               "                   are added or the held-out error is at most E\n"
               "  --heldout-steps S  without a clip, the 10 random held-out poses are each\n"
               "                   reached from the one before in S held-out poses, 1..64\n"
               "                   (default 4; the reference depends on the path)\n"
               "  --random-poses N  without a clip, N random held-out poses, 1..10000\n"
               "                   (default 10; more define the held-out figure better)\n"
               "  --seed S         the bake's random draws (held-out poses, adaptive candidates,\n"
               "                   cubature candidates), 0..2147483647 (default 1592614637)\n"
               "  --contact-modes  also the static responses to the training poses' self-contact\n"
               "                   forces in the basis (thesis 3.3.1; a higher rank)\n"
               "  --contact-tol T  per pair of domains, each training pose's contact pairs are\n"
               "                   cut to a cubature that keeps their reduced force to T,\n"
               "                   0 <= T < 1 (default 0.05; 0: every pair kept)\n"
               "  --no-pose-force  no pose-space equilibrium force in the blob (by default each\n"
               "                   training pose carries the reduced force that makes its\n"
               "                   projected solution the runtime's equilibrium there,\n"
               "                   interpolated between poses)\n"
               "  --eval-self-contact M  the runtime's self-contact mode the bake's errors are\n"
               "                   measured in: pose-space (default) or pose-pairs\n");
    fprintf(f,
            "  --reference-spread K  at every K-th held-out pose, three more full-space\n"
            "                   solves: from plain skinning, from the reference and from the\n"
            "                   runtime's state; how far they land from the reference says\n"
            "                   how well the reference is defined, and whether the runtime\n"
            "                   sits by another equilibrium\n"
            "  --inertia-modes  for the dynamic step: basis modes for the inertia of the\n"
            "                   bones' accelerations (static responses to them), so that the\n"
            "                   flesh lags and overshoots as the reference does; a higher rank\n");
    fprintf(f, "reference options (every full-space solve of the bake; a change of them\n"
               "solves the poses again instead of reading the cache):\n" SW_REFERENCE_USAGE
               "exit status: 0 blob written, 1 failed, 2 bad arguments\n");
}

int main(int argc, char **argv) {
    static const char *tool = "sinew-bake";
    sw_character_args ca;
    sw_character_args_init(&ca, tool);
    const char *out_path = NULL, *report_dir = NULL;
    int json = 0, force = 0, spread_every = 0;
    sinew_self_contact eval_mode = SINEW_SELF_CONTACT_POSE_SPACE;
    sw_bake_params p = sw_bake_params_default();
    sw_fullsim_params reference = sw_fullsim_params_default(); /* its solver options */
    p.reference = &reference;
    sw_adaptive_params ad = sw_adaptive_params_default();
    sw_adaptive_report arep;
    ad.rounds = 0;
    p.progress = 1;
    sw_tool_progress bar;
    sw_tool_progress_init(&bar, tool);
    p.on_progress = sw_tool_progress_print;
    p.progress_user = &bar;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1;
        if (sw_character_args_take(&ca, argc, argv, &i, &ok) ||
            sw_reference_args_take(&reference, argc, argv, &i, &ok)) {
            /* a character or reference option, consumed */
        } else if (!strcmp(a, "--out") && next)
            out_path = argv[++i];
        else if (!strcmp(a, "--report") && next)
            report_dir = argv[++i];
        else if (!strcmp(a, "--threads") && next)
            ok = sw_tool_int(tool, a, argv[++i], 0, 256, &p.threads);
        else if (!strcmp(a, "--max-rank") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 1024, &p.max_rank);
        else if (!strcmp(a, "--pca-strain") && next)
            ok = sw_tool_real(tool, a, argv[++i], -1e-300, nextafter(1.0, 2.0), "in 0..1",
                              &p.pca_strain);
        else if (!strcmp(a, "--tol") && next)
            ok = sw_tool_real(tool, a, argv[++i], 0, 1, "in the open range 0..1", &p.cubature_tol);
        else if (!strcmp(a, "--selector") && next) {
            const char *s = argv[++i];
            if (!strcmp(s, "greedy"))
                p.selector = SW_CUBATURE_GREEDY;
            else if (!strcmp(s, "importance"))
                p.selector = SW_CUBATURE_IMPORTANCE;
            else if (!strcmp(s, "nnhtp"))
                p.selector = SW_CUBATURE_NNHTP;
            else {
                fprintf(stderr, "%s: --selector wants greedy | importance | nnhtp, got '%s'\n",
                        tool, s);
                ok = 0;
            }
        } else if (!strcmp(a, "--fold-share") && next) {
            ok = sw_tool_real(tool, a, argv[++i], -1, 0.5, "in 0..0.5", &p.fold_share);
            if (ok && p.fold_share < 0) {
                fprintf(stderr, "%s: --fold-share wants a number in 0..0.5, got '%s'\n", tool,
                        argv[i]);
                ok = 0;
            }
        } else if (!strcmp(a, "--spring-k") && next)
            ok = sw_tool_real(tool, a, argv[++i], 0, INFINITY, "above 0", &p.spring_k);
        else if (!strcmp(a, "--cache") && next)
            p.cache_dir = argv[++i];
        else if (!strcmp(a, "--compare-cubature"))
            p.compare_selectors = 1;
        else if (!strcmp(a, "--no-self-contact"))
            p.self_contact = 0;
        else if (!strcmp(a, "--return-path"))
            p.return_path = 1;
        else if (!strcmp(a, "--no-return-path"))
            p.return_path = 0;
        else if (!strcmp(a, "--pair-sweeps"))
            p.pair_sweeps = 1;
        else if (!strcmp(a, "--no-pair-sweeps"))
            p.pair_sweeps = 0;
        else if (!strcmp(a, "--no-sibling-sweeps"))
            p.sibling_sweeps = 0;
        else if (!strcmp(a, "--adaptive") && next)
            ok = sw_tool_int(tool, a, argv[++i], 0, SW_ADAPTIVE_MAX_ROUNDS, &ad.rounds);
        else if (!strcmp(a, "--adaptive-add") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 100000, &ad.add);
        else if (!strcmp(a, "--adaptive-candidates") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 100000, &ad.candidates);
        else if (!strcmp(a, "--adaptive-budget") && next)
            ok = sw_tool_int(tool, a, argv[++i], 0, 1000000, &ad.budget);
        else if (!strcmp(a, "--reference-spread") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 1000000, &spread_every);
        else if (!strcmp(a, "--heldout-steps") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 64, &p.heldout_steps);
        else if (!strcmp(a, "--random-poses") && next)
            ok = sw_tool_int(tool, a, argv[++i], 1, 10000, &p.random_poses);
        else if (!strcmp(a, "--seed") && next) {
            int seed = 0;
            ok = sw_tool_int(tool, a, argv[++i], 0, 2147483647, &seed);
            p.seed = (uint64_t)seed;
        } else if (!strcmp(a, "--adaptive-target") && next)
            ok = sw_tool_real(tool, a, argv[++i], 0, 1, "in 0..1", &ad.target);
        else if (!strcmp(a, "--inertia-modes"))
            p.inertia_modes = 1;
        else if (!strcmp(a, "--contact-modes"))
            p.contact_modes = 1;
        else if (!strcmp(a, "--no-pose-force"))
            p.pose_force = 0;
        else if (!strcmp(a, "--ship-split"))
            p.ship_split = 1;
        else if (!strcmp(a, "--contact-tol") && next)
            ok = sw_tool_real(tool, a, argv[++i], -1e-300, 1, "in 0 <= T < 1",
                              &p.contact_cubature_tol);
        else if (!strcmp(a, "--eval-self-contact") && next) {
            int k = sw_tool_choice(argv[++i], (const char *const[]){"pose-space", "pose-pairs", 0});
            if (!(ok = k >= 0))
                fprintf(stderr, "%s: --eval-self-contact: pose-space or pose-pairs\n", tool);
            eval_mode = k == 1 ? SINEW_SELF_CONTACT_POSE_PAIRS : SINEW_SELF_CONTACT_POSE_SPACE;
        } else if (!strcmp(a, "--force"))
            force = 1;
        else if (!strcmp(a, "--json"))
            json = 1;
        else if (!sw_tool_help(a, usage))
            return sw_tool_bad_arg(tool, a, usage);
        if (!ok) return 2; /* the value's message is out */
    }
    if (!out_path) {
        fprintf(stderr, "%s: give --out FILE.blob\n", tool);
        usage(stderr);
        return 2;
    }
    if (!sw_character_args_valid(&ca)) return 2;
    /* the report's folder before the long run: an unwritable one is an error now */
    const char *dirs[2][2] = {{"--report", report_dir}, {"--cache", p.cache_dir}};
    for (int k = 0; k < 2; ++k)
        if (dirs[k][1] && !sw_tool_make_dirs(dirs[k][1])) {
            fprintf(stderr, "%s: %s '%s': cannot create or write the folder: %s\n", tool,
                    dirs[k][0], dirs[k][1], strerror(errno ? errno : EACCES));
            return 1;
        }
    sw_error err;
    sinew_result r = sw_write_file_check(out_path, &err); /* before the long run, as the folders */
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "%s: --out: ", tool);
    sw_character ch;
    sw_clip_split clips;
    sw_scene_character_info info;
    double t0 = sw_now_seconds();
    r = sw_character_args_make(&ca, &ch, &clips, &info, &err);
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "%s: ", tool);
    const char *source = ca.file ? ca.file : ca.scene ? ca.scene : ca.mesh;
    fprintf(stderr, "%s: %s: %d tets, %d vertices, %d bones, %d clip frames\n", tool,
            ch.name[0] ? ch.name : source, ch.mesh.ntets, ch.mesh.nverts, ch.skel.nbones,
            ch.clip.nframes);
    sw_quality quality = {0};
    if (ca.file) {
        sw_tetmesh_quality(&ch.mesh, 0, &quality);
        sw_tool_print_scene(tool, &ch, &clips, &info, &quality);
    }
    sw_tool_bake_clips(&ca, &clips, &p);
    sw_bake_result res;
    r = ad.rounds > 0 ? sw_bake_adaptive(&ch, &p, &ad, &res, &arep, &err)
                      : sw_bake(&ch, &p, &res, &err);
    if (r != SINEW_OK) {
        sw_character_free(&ch);
        sw_clip_split_free(&clips);
        return sw_tool_failed(r, &err, "%s: ", tool);
    }
    /* measure the blob's bytes before they go to the file */
    void *mem = NULL;
    size_t size = 0;
    sinew_blob *blob = NULL;
    sw_eval_result et, eh;
    memset(&et, 0, sizeof et);
    memset(&eh, 0, sizeof eh);
    double bake_seconds = sw_now_seconds() - t0, t1 = sw_now_seconds();
    sinew_blob_def bd = sinew_blob_def_default();
    int status = 1;
    double *frame_err = NULL; /* every training pose's error, then every held-out one's */
    sw_bake_spread spread;    /* --reference-spread */
    memset(&spread, 0, sizeof spread);
    sw_bake_result whole; /* the blob shipped when baked on the whole clip */
    memset(&whole, 0, sizeof whole);
    if ((r = sw_blob_write_memory(&res.view, &mem, &size, &err)) != SINEW_OK) {
        sw_tool_failed(r, &err, "%s: cannot serialise the blob: ", tool);
        goto done;
    }
    bd.data = mem;
    bd.data_size = size;
    if (sw_tool_blob_load(tool, "just baked", bd, &blob) != SINEW_OK) goto done;
    frame_err = malloc(sizeof(double) * ((size_t)res.ntrain + (size_t)res.nheldout + 1));
    if (!frame_err) {
        fprintf(stderr, "%s: out of memory\n", tool);
        goto done;
    }
    if ((r = sw_bake_errors_frames(blob, &res, eval_mode, &et, &eh, frame_err,
                                   frame_err + res.ntrain, &err)) != SINEW_OK) {
        sw_tool_failed(r, &err, "%s: cannot evaluate the blob: ", tool);
        goto done;
    }
    /* the held-out error in each self-contact mode an instance can take
       (sinew_instance_def.self_contact): which suits this character's motion */
    double mode_err[SW_BAKE_MODES];
    char num[32];
    if ((r = sw_bake_mode_errors(blob, &res, eval_mode, eh.correction_error, mode_err, &err))) {
        sw_tool_failed(r, &err, "%s: cannot evaluate the blob: ", tool);
        goto done;
    }
    if (spread_every > 0 &&
        (r = sw_bake_reference_spread(&ch, &p, blob, &res, eval_mode, spread_every, &spread,
                                      &err)) != SINEW_OK) {
        sw_tool_failed(r, &err, "%s: --reference-spread: ", tool);
        goto done;
    }
    double eval_seconds = sw_now_seconds() - t1;
    /* a blob that cannot step its own training poses is no bake either (its error,
       measured on the steps that did not fail, would say nothing) */
    /* the reduced model's own training error: the equilibrium force makes the training
       poses' errors their projections' whatever the model (bake_equilibrium.c) */
    const double model_err =
        res.model_train_error >= 0 ? res.model_train_error : et.correction_error;
    int absurd = !(model_err < SW_BAKE_MAX_TRAIN_ERROR) || et.failed > 0;
    if (absurd && !force && et.failed > 0) {
        fprintf(stderr,
                "%s: error: %d of the blob's steps through its own %d training poses failed (a "
                "non-finite state: check the material and --spring-k); %s not written, or "
                "--force to write it anyway\n",
                tool, et.failed, res.ntrain, out_path);
        goto done;
    }
    if (absurd && !force) {
        fprintf(stderr,
                "%s: error: the bake's training error is %.4f (at least %.2f: the subspace misses "
                "that share of the physics correction on its own training poses without the "
                "equilibrium force; a sound bake misses a few percent); %s not written. Give a "
                "clip with more frames or joint motion or a higher --max-rank, or --force to "
                "write it anyway\n",
                tool, model_err, SW_BAKE_MAX_TRAIN_ERROR, out_path);
        goto done;
    }
    /* the figures above are the split's; the blob ships trained on the whole clip
       (sw_bake_ships_whole_clip) unless --ship-split or adaptive rounds */
    const int ship_whole = ad.rounds == 0 && sw_bake_ships_whole_clip(&ch, &p);
    if (ship_whole) {
        fprintf(stderr,
                "%s: the figures are of the split (held-out: the clip's last %.0f%%); the blob "
                "ships baked on all %d frames of the clip (--ship-split: the split's)\n",
                tool, 100 * p.heldout_fraction, ch.clip.nframes);
        if ((r = sw_bake_whole_clip(&ch, &p, &whole, &err)) != SINEW_OK) {
            sw_tool_failed(r, &err, "%s: the whole clip's bake: ", tool);
            goto done;
        }
    }
    if ((r = sw_blob_write(out_path, ship_whole ? &whole.view : &res.view, &err)) != SINEW_OK) {
        sw_tool_failed(r, &err, "%s: cannot write %s: ", tool, out_path);
        goto done;
    }
    if (report_dir) {
        int scene_clips = p.ntrain_clips > 0;
        sw_bake_report_input ri = {source,
                                   &ch,
                                   &res,
                                   blob,
                                   scene_clips ? (const char(*)[64])clips.train_names : NULL,
                                   scene_clips ? clips.ntrain : 0,
                                   scene_clips ? (const char(*)[64])clips.heldout_names : NULL,
                                   scene_clips ? clips.nheldout : 0,
                                   frame_err,
                                   frame_err + res.ntrain,
                                   et.correction_error,
                                   eh.correction_error,
                                   et.failed + eh.failed,
                                   bake_seconds,
                                   eval_seconds,
                                   1,
                                   ad.rounds > 0 ? &arep : NULL,
                                   &et,
                                   &eh,
                                   !ca.file                               ? NULL
                                   : info.mesh.mesher == SW_MESHER_TETGEN ? "tetgen"
                                                                          : "lattice",
                                   mode_err,
                                   spread_every > 0 ? &spread : NULL,
                                   sw_linear_solver_name(reference.solver),
                                   sw_hessian_mode_name(reference.hessian)};
        if ((r = sw_bake_report_write(report_dir, &ri, &err)) != SINEW_OK) {
            sw_tool_failed(r, &err, "%s: --report %s: ", tool, report_dir);
            goto done;
        }
        fprintf(stderr, "%s: wrote the report %s/report.html and %s/report.json\n", tool,
                report_dir, report_dir);
    }
    status = 0;
    const sw_blob_view *v = &res.view;
    fprintf(stderr, "%s: wrote %s\n", tool, out_path);
    fprintf(stderr, "  stages (s):");
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k) /* the bake's table (bake.h) */
        fprintf(stderr, "%s %s %.2f", k ? "," : "", sw_bake_stages[k].name, res.stage_seconds[k]);
    fprintf(stderr, "; total %.2f\n", bake_seconds);
    fprintf(stderr, "  domains %d, total rank %d (", v->ndomains, v->rank_total);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].rank);
    fprintf(stderr, "), cubature tets %d (", v->ncub);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].cub_count);
    fprintf(stderr, "), worst cubature fit %.4f\n", res.cubature_error_max);
    /* random held-out poses (no clip) come on a path: say what the count is made of */
    char held_how[128] = "";
    if (res.nheldout > 0 && res.heldout_clip[0] < 0)
        snprintf(held_how, sizeof held_how,
                 " (%d random combined poses, each reached in %d steps, %s)",
                 res.nheldout / p.heldout_steps, p.heldout_steps,
                 ch.range.nframes > 0 ? "the joints within --joint-range"
                                      : "every joint within 90 degrees");
    char pair_how[64] = ""; /* on by default only with a range: say when they ran */
    if (res.pair_sweep_poses > 0)
        snprintf(pair_how, sizeof pair_how, " (%d of joints swept with their parents)",
                 res.pair_sweep_poses);
    fprintf(stderr,
            "  poses: %d training%s, %d held-out%s; basis projection error train %.4f held-out "
            "%.4f; in the linearised model's energy (Galerkin) %.4f / %.4f\n",
            res.ntrain, pair_how, res.nheldout, held_how, res.train_proj_error,
            res.heldout_proj_error, res.train_galerkin_error, res.heldout_galerkin_error);
    fprintf(stderr, "  references solved by: solver %s, %s Hessians, at most %d contact rounds\n",
            sw_linear_solver_name(reference.solver), sw_hessian_mode_name(reference.hessian),
            reference.contact_rounds);
    int32_t kept = 0; /* the pose-space pairs the per-pair cubature keeps */
    for (int32_t c = 0; c < v->ncontacts && v->npair_groups > 0; ++c)
        kept += v->pair_weight[c] > 0;
    fprintf(stderr,
            "  self-contact: %d contact pairs over the training poses in %d pairs of domains; "
            "the per-pair cubature keeps %d (--contact-tol %g)\n",
            v->ncontacts, v->npair_groups, kept, p.contact_cubature_tol);
    if (v->nrender_verts > 0)
        fprintf(stderr,
                "  output: the render mesh, %d vertices (%d welded duplicates), %d triangles, "
                "embedded in %d tets in %.1f ms; %d vertices outside the tets, by %.4g at most; "
                "|barycentric| <= %.3g\n",
                v->nrender_verts, res.render_welded, v->nrender_tris, v->nembed_tets,
                1e3 * res.embed_seconds, res.render_outside, res.render_max_outside,
                res.render_max_bary);
    if (res.train_unsettled + res.heldout_unsettled > 0)
        fprintf(
            stderr,
            "  reference: the contact round cap left the contact set unsettled in %d training and "
            "%d held-out solutions (their fold depends on the cap)\n",
            res.train_unsettled, res.heldout_unsettled);
    fprintf(stderr,
            "  correction error (subspace vs full, share of the correction missed, on the bake's "
            "poses): train %.4f, held-out %.4f (%d failed steps)\n",
            et.correction_error, eh.correction_error, et.failed + eh.failed);
    if (res.model_train_error >= 0)
        fprintf(stderr,
                "  equilibrium force at %d of %d training poses; the training error without it "
                "%.4f\n",
                res.force_poses, res.ntrain, res.model_train_error);
    fprintf(stderr,
            "  seams (the domains' copies of a vertex apart, share of the correction; largest "
            "gap over the rest diagonal): train %.4f, %.2e; held-out %.4f, %.2e\n",
            et.seam, et.seam_max, eh.seam, eh.seam_max);
    for (int set = 0; set < 2; ++set) {
        const sw_eval_result *e = set ? &eh : &et;
        if (e->nregions < 1) continue;
        fprintf(stderr,
                "  %s error by region (strongest bone: share of the error / of the "
                "correction):",
                set ? "held-out" : "training");
        for (int32_t k = 0; k < e->nregions; ++k)
            fprintf(stderr, " bone %d%s%s %.3f / %.3f%s", e->region_bone[k],
                    ch.bone_names ? " " : "", ch.bone_names ? ch.bone_names[e->region_bone[k]] : "",
                    e->region_err[k], e->region_corr[k], k + 1 < e->nregions ? "," : "\n");
    }
    fprintf(stderr, "  held-out error by self-contact mode:");
    for (int k = 0; k < SW_BAKE_MODES; ++k)
        fprintf(stderr, " %s %s%s", sw_self_contact_names[k],
                isfinite(mode_err[k]) ? json_number(mode_err[k], num) : "-",
                k + 1 < SW_BAKE_MODES ? "," : "\n");
    if (spread_every > 0)
        fprintf(stderr,
                "  reference spread at %d held-out poses (every %d-th): runtime %.4f; full-space "
                "solves from plain skinning %.4f, from the reference %.4f, from the runtime's "
                "state %.4f (moved it %.4f); %d unconverged, %d left out\n",
                spread.poses, spread_every, spread.runtime, spread.from_skin, spread.from_reference,
                spread.polished, spread.polish_move, spread.unconverged, spread.failed);
    sw_joint_reach beyond[BAKE_BEYOND];
    int32_t nbeyond_all = sw_bake_beyond_training(&res, &ch.skel, beyond, BAKE_BEYOND);
    int32_t nbeyond = nbeyond_all < BAKE_BEYOND ? nbeyond_all : BAKE_BEYOND;
    if (nbeyond > 0) { /* where the basis extrapolates: what a training clip should reach */
        int32_t shown = nbeyond < 8 ? nbeyond : 8;
        fprintf(stderr,
                "  held-out poses bend %d joint%s beyond training (largest bend held-out "
                "/ in training, degrees):",
                nbeyond_all, nbeyond_all == 1 ? "" : "s");
        for (int32_t k = 0; k < shown; ++k) {
            fprintf(stderr, " bone %d", beyond[k].bone);
            if (ch.bone_names) fprintf(stderr, " %s", ch.bone_names[beyond[k].bone]);
            fprintf(stderr, " %.1f / %.1f%s", beyond[k].heldout_deg, beyond[k].train_deg,
                    k + 1 < shown     ? ","
                    : nbeyond > shown ? ", ...\n"
                                      : "\n");
        }
    }
    if (absurd)
        fprintf(stderr,
                "%s: WARNING: written with --force although its training error is %.4f (refused "
                "at %.2f) with %d failed steps: this blob misses most of the physics correction\n",
                tool, model_err, SW_BAKE_MAX_TRAIN_ERROR, et.failed);
    if (p.compare_selectors) {
        static const char *names[3] = {"greedy", "importance", "nnhtp"};
        for (int s = 0; s < 3; ++s)
            fprintf(stderr, "  selector %-10s %6d tets  %8.2f s  worst fit %.4f\n", names[s],
                    res.selector_points[s], res.selector_seconds[s], res.selector_error[s]);
    }
    if (json) {
        char gt[32], gh[32];
        printf("{\"blob\":\"%s\",\"tets\":%d,\"verts\":%d,\"bones\":%d,\"domains\":%d,\"rank\":%d,"
               "\"cubature_tets\":%d,\"cubature_fit\":%.5f,\"train_poses\":%d,\"return_poses\":%d,"
               "\"pair_sweep_poses\":%d,\"heldout_poses\":%d,"
               "\"proj_err_train\":%.5f,\"proj_err_heldout\":%.5f,\"err_train\":%.5f,\"err_"
               "heldout\":%.5f,"
               "\"ref_unsettled_train\":%d,\"ref_unsettled_heldout\":%d,"
               "\"bake_seconds\":%.2f,\"eval_seconds\":%.2f",
               out_path, ch.mesh.ntets, ch.mesh.nverts, ch.skel.nbones, v->ndomains, v->rank_total,
               v->ncub, res.cubature_error_max, res.ntrain, res.return_poses, res.pair_sweep_poses,
               res.nheldout, res.train_proj_error, res.heldout_proj_error, et.correction_error,
               eh.correction_error, res.train_unsettled, res.heldout_unsettled, bake_seconds,
               eval_seconds);
        printf(",\"stages\":["); /* the bake's table (bake.h), as the report's JSON */
        for (int k = 0; k < SW_BAKE_NSTAGES; ++k)
            printf("%s{\"name\":\"%s\",\"seconds\":%.2f}", k ? "," : "", sw_bake_stages[k].name,
                   res.stage_seconds[k]);
        printf("]");
        printf(",\"pose_force_poses\":%d,\"err_train_model\":%.5f,\"ref_solver\":\"%s\","
               "\"ref_hessian\":\"%s\",\"joint_range_frames\":%d,\"seed\":%llu",
               res.force_poses, model_err, sw_linear_solver_name(reference.solver),
               sw_hessian_mode_name(reference.hessian), ch.range.nframes,
               (unsigned long long)p.seed);
        printf(",\"galerkin_err_train\":%s,\"galerkin_err_heldout\":%s",
               json_number(res.train_galerkin_error, gt),
               json_number(res.heldout_galerkin_error, gh));
        printf(",\"spring_k\":%.6g,\"spring_tried\":[", res.spring_k);
        for (int32_t k = 0; k < res.nspring_tried; ++k)
            printf("%s[%.4g,%.5f]", k ? "," : "", res.spring_tried_mult[k],
                   res.spring_tried_err[k]);
        printf("]");
        printf(",\"seam_train\":%.5f,\"seam_heldout\":%.5f,\"seam_max_train\":%.3e,"
               "\"seam_max_heldout\":%.3e",
               et.seam, eh.seam, et.seam_max, eh.seam_max);
        printf(",\"surface_verts\":%d,\"surface_tris\":%d,\"render_mesh\":%s,"
               "\"render_outside\":%d,\"render_max_outside\":%.6g,\"render_max_bary\":%.4g,"
               "\"embed_seconds\":%.4f",
               sw_blob_output_verts(v), sw_blob_output_ntris(v),
               v->nrender_verts > 0 ? "true" : "false", res.render_outside, res.render_max_outside,
               res.render_max_bary, res.embed_seconds);
        if (ca.file)
            printf(",\"mesher\":\"%s\",\"mesh_min_dihedral_deg\":%.4g,\"mesh_slivers\":%d",
                   info.mesh.mesher == SW_MESHER_TETGEN ? "tetgen" : "lattice",
                   quality.min_dihedral_deg, quality.slivers);
        if (p.compare_selectors)
            printf(",\"selectors\":{\"greedy\":[%d,%.3f,%.4f],\"importance\":[%d,%.3f,%.4f],"
                   "\"nnhtp\":[%d,%.3f,%.4f]}",
                   res.selector_points[0], res.selector_seconds[0], res.selector_error[0],
                   res.selector_points[1], res.selector_seconds[1], res.selector_error[1],
                   res.selector_points[2], res.selector_seconds[2], res.selector_error[2]);
        for (int k = 0; ad.rounds > 0 && k < arep.nrounds; ++k) {
            const sw_adaptive_round *a = &arep.round[k];
            printf("%s{\"train_poses\":%d,\"added\":%d,\"rank\":%d,\"err_train\":%.5f,"
                   "\"err_heldout\":%.5f,\"proj_err_train\":%.5f,\"proj_err_heldout\":%.5f,"
                   "\"score_mean\":%.4f,\"score_max\":%.4f,\"picks_score\":%.4f,"
                   "\"picks_error\":%.5f,\"solved\":%d,\"seconds\":%.2f}%s",
                   k == 0 ? ",\"adaptive\":[" : ",", a->ntrain, a->added, a->rank_total,
                   a->err_train, a->err_heldout, a->proj_train, a->proj_heldout, a->score_mean,
                   a->score_max, a->picks_score, a->picks_error, a->solved, a->seconds,
                   k + 1 == arep.nrounds ? "]" : "");
        }
        printf(",\"contact_pairs\":%d,\"pair_groups\":%d,\"contact_pairs_kept\":%d", v->ncontacts,
               v->npair_groups, kept);
        for (int set = 0; set < 2; ++set) { /* [bone, share of the error, of the correction] */
            const sw_eval_result *e = set ? &eh : &et;
            printf(",\"err_regions_%s\":[", set ? "heldout" : "train");
            for (int32_t k = 0; k < e->nregions; ++k)
                printf("%s[%d,%.4f,%.4f]", k ? "," : "", e->region_bone[k], e->region_err[k],
                       e->region_corr[k]);
            printf("]");
        }
        printf(",\"err_heldout_by_mode\":{");
        for (int k = 0; k < SW_BAKE_MODES; ++k)
            printf("%s\"%s\":%s", k ? "," : "", sw_self_contact_keys[k],
                   json_number(mode_err[k], num));
        printf("}");
        if (spread_every > 0)
            printf(",\"ref_spread\":{\"every\":%d,\"poses\":%d,\"runtime\":%.5f,"
                   "\"from_skin\":%.5f,\"from_reference\":%.5f,\"polished\":%.5f,"
                   "\"polish_move\":%.5f,\"unconverged\":%d,\"failed\":%d}",
                   spread_every, spread.poses, spread.runtime, spread.from_skin,
                   spread.from_reference, spread.polished, spread.polish_move, spread.unconverged,
                   spread.failed);
        for (int32_t k = 0; spread_every > 0 && k < spread.poses; ++k) {
            /* [held-out pose, runtime, from_skin, from_reference, polished, correction] */
            const sw_bake_spread_pose *q = &spread.per_pose[k];
            printf("%s[%d,%.5f,%.5f,%.5f,%.5f,%.4g]%s", k ? "," : ",\"ref_spread_poses\":[",
                   q->heldout, q->runtime, q->from_skin, q->from_reference, q->polished,
                   q->correction, k + 1 == spread.poses ? "]" : "");
        }
        printf(",\"heldout_beyond_training\":["); /* [bone, name, held-out, training deg] */
        for (int32_t k = 0; k < nbeyond; ++k) {
            printf("%s[%d,", k ? "," : "", beyond[k].bone);
            if (ch.bone_names)
                sw_tool_json_string(ch.bone_names[beyond[k].bone]);
            else
                printf("null");
            printf(",%.2f,%.2f]", beyond[k].heldout_deg, beyond[k].train_deg);
        }
        printf("]");
        printf(",\"simulate_cached\":%s,\"simulate_solved\":%d,\"forced\":%s,"
               "\"shipped\":\"%s\"}\n",
               res.simulate_cached ? "true" : "false", res.simulate_solved,
               absurd ? "true" : "false", ship_whole ? "whole_clip" : "as_measured");
    }
done:
    sw_bake_spread_free(&spread);
    sinew_blob_destroy(blob);
    free(mem);
    free(frame_err);
    sw_bake_result_free(&res);
    sw_bake_result_free(&whole);
    sw_character_free(&ch);
    sw_clip_split_free(&clips);
    return status;
}
