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
#include "blob_parts.h"
#include "blob_write.h"
#include "character_io.h"
#include "samples.h"
#include "subspace_eval.h"
#include "bake_cli.h"
#include "character_paint.h"

static const char *const tool = "sinew-bake";

#define BAKE_BEYOND 32 /* joints listed beyond training, at most (8 in the summary) */

/* v as a JSON number, or null when it is not finite (buf: 32 chars). */
static const char *json_number(double v, char *buf) {
    if (!isfinite(v)) return "null";
    snprintf(buf, 32, "%.5f", v);
    return buf;
}

/* Everything the bake made and measured. The steps that read it (write_outputs,
 * print_summary, print_json) read it through b. */
typedef struct {
    bake_options o;
    sw_tool_progress bar;
    sw_character ch;
    sw_clip_split clips;
    sw_scene_character_info info;
    sw_quality quality;
    const char *source;
    double t0, bake_seconds, eval_seconds;
    sw_bake_result res;
    sw_adaptive_report arep;
    void *mem;
    sinew_blob *blob;
    sw_eval_result et, eh;
    double *frame_err;     /* every training pose's error, then every held-out one's */
    sw_bake_spread spread; /* --reference-spread */
    double mode_err[SW_BAKE_MODES];
    double model_err; /* the reduced model's own training error */
    int absurd;
    int32_t kept; /* the pose-space pairs the per-pair cubature keeps */
    sw_joint_reach beyond[BAKE_BEYOND];
    int32_t nbeyond_all, nbeyond;
    int ship_whole;        /* the blob shipped is baked again on the whole clip */
    sw_blob_memory memory; /* the shipped blob's and its instances' */
    sw_bake_result whole;  /* that bake */
} bake;

/* The character from the command line, its summary on stderr. */
static int load_character(bake *b, sw_error *err) {
    const sw_character_args *ca = &b->o.ca;
    sw_character *ch = &b->ch;
    b->t0 = sw_now_seconds();
    sinew_result r = sw_character_args_make(ca, ch, &b->clips, &b->info, err);
    if (r != SINEW_OK) return sw_tool_failed(r, err, "%s: ", tool);
    b->source = ca->file ? ca->file : ca->scene ? ca->scene : ca->mesh;
    fprintf(stderr, "%s: %s: %d tets, %d vertices, %d bones, %d clip frames\n", tool,
            ch->name[0] ? ch->name : b->source, ch->mesh.ntets, ch->mesh.nverts, ch->skel.nbones,
            ch->clip.nframes);
    char paint[160];
    sw_character_paint_summary(ch, paint, sizeof paint);
    if (paint[0]) fprintf(stderr, "%s: painted material: %s\n", tool, paint);
    if (ca->file) {
        sw_tetmesh_quality(&ch->mesh, 0, &b->quality);
        sw_tool_print_scene(tool, ch, &b->clips, &b->info, &b->quality);
    }
    return 0;
}

/* The bake (with --adaptive, its rounds). */
static int run_bake(bake *b, sw_error *err) {
    bake_options *o = &b->o;
    sw_tool_progress_init(&b->bar, tool);
    o->p.on_progress = sw_tool_progress_print;
    o->p.progress_user = &b->bar;
    sw_tool_bake_clips(&o->ca, &b->clips, &o->p);
    sinew_result r = o->ad.rounds > 0
                         ? sw_bake_adaptive(&b->ch, &o->p, &o->ad, &b->res, &b->arep, err)
                         : sw_bake(&b->ch, &o->p, &b->res, err);
    if (r != SINEW_OK) return sw_tool_failed(r, err, "%s: ", tool);
    b->bake_seconds = sw_now_seconds() - b->t0;
    return 0;
}

/* The blob measured before it goes to the file: its errors on the bake's poses, in each
 * self-contact mode, and with --reference-spread the reference's spread. */
static int measure(bake *b, sw_error *err) {
    const bake_options *o = &b->o;
    sw_bake_result *res = &b->res;
    sinew_self_contact eval_mode =
        o->eval_pairs ? SINEW_SELF_CONTACT_POSE_PAIRS : SINEW_SELF_CONTACT_POSE_SPACE;
    double t1 = sw_now_seconds();
    size_t size = 0;
    sinew_result r;
    if ((r = sw_blob_write_memory(&res->view, &b->mem, &size, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "%s: cannot serialise the blob: ", tool);
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = b->mem;
    bd.data_size = size;
    if (sw_tool_blob_load(tool, "just baked", bd, &b->blob) != SINEW_OK) return 1;
    b->frame_err = malloc(sizeof(double) * ((size_t)res->ntrain + (size_t)res->nheldout + 1));
    if (!b->frame_err) {
        fprintf(stderr, "%s: out of memory\n", tool);
        return 1;
    }
    if ((r = sw_bake_errors_frames(b->blob, res, eval_mode, &b->et, &b->eh, b->frame_err,
                                   b->frame_err + res->ntrain, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "%s: cannot evaluate the blob: ", tool);
    /* the held-out error in each self-contact mode an instance can take
       (sinew_instance_def.self_contact): which suits this character's motion */
    if ((r = sw_bake_mode_errors(b->blob, res, eval_mode, b->eh.correction_error, b->mode_err,
                                 err)))
        return sw_tool_failed(r, err, "%s: cannot evaluate the blob: ", tool);
    if (o->spread_every > 0 &&
        (r = sw_bake_reference_spread(&b->ch, &o->p, b->blob, res, eval_mode, o->spread_every,
                                      &b->spread, err)) != SINEW_OK)
        return sw_tool_failed(r, err, "%s: --reference-spread: ", tool);
    b->eval_seconds = sw_now_seconds() - t1;
    /* a blob that cannot step its own training poses is no bake either (its error,
       measured on the steps that did not fail, would say nothing) */
    /* the reduced model's own training error: the equilibrium force makes the training
       poses' errors their projections' whatever the model (bake_equilibrium.c) */
    b->model_err = res->model_train_error >= 0 ? res->model_train_error : b->et.correction_error;
    b->absurd = !(b->model_err < SW_BAKE_MAX_TRAIN_ERROR) || b->et.failed > 0;
    /* what the summary and the JSON line both list */
    const sw_blob_view *v = &res->view;
    for (int32_t c = 0; c < v->ncontacts && v->npair_groups > 0; ++c)
        b->kept += v->pair_weight[c] > 0;
    b->nbeyond_all = sw_bake_beyond_training(res, &b->ch.skel, b->beyond, BAKE_BEYOND);
    b->nbeyond = b->nbeyond_all < BAKE_BEYOND ? b->nbeyond_all : BAKE_BEYOND;
    return 0;
}

/* The shipped view written to the out path atomically, and its memory measured. */
static int write_blob(bake *b, const sw_blob_view *view) {
    void *data = NULL;
    size_t size = 0;
    sinew_blob *blob = NULL;
    sw_error err;
    sinew_result r = sw_blob_write_memory(view, &data, &size, &err);
    if (r == SINEW_OK) r = sw_write_file_atomic(b->o.out_path, data, size, &err);
    if (r != SINEW_OK) {
        free(data);
        return sw_tool_failed(r, &err, "%s: cannot write %s: ", tool, b->o.out_path);
    }
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = data;
    bd.data_size = size;
    int ok = sw_tool_blob_load(tool, "written", bd, &blob) == SINEW_OK &&
             sw_blob_memory_measure(data, size, blob, &b->memory);
    sinew_blob_destroy(blob);
    free(data);
    if (!ok) fprintf(stderr, "%s: cannot measure the written blob's memory\n", tool);
    return !ok;
}

/* The blob written (unless absurd without --force) and with --report the report. */
static int write_outputs(bake *b) {
    const sw_bake_result *shipped = b->ship_whole ? &b->whole : &b->res;
    sw_error err;
    sinew_result r;
    if (b->absurd && !b->o.force && b->et.failed > 0) {
        fprintf(stderr,
                "%s: error: %d of the blob's steps through its own %d training poses failed (a "
                "non-finite state: check the material and --spring-k); %s not written, or "
                "--force to write it anyway\n",
                tool, b->et.failed, b->res.ntrain, b->o.out_path);
        return 1;
    }
    if (b->absurd && !b->o.force) {
        fprintf(stderr,
                "%s: error: the bake's training error is %.4f (at least %.2f: the subspace misses "
                "that share of the physics correction on its own training poses without the "
                "equilibrium force; a sound bake misses a few percent); %s not written. Give a "
                "clip with more frames or joint motion or a higher --max-rank, or --force to "
                "write it anyway\n",
                tool, b->model_err, SW_BAKE_MAX_TRAIN_ERROR, b->o.out_path);
        return 1;
    }
    if (write_blob(b, &shipped->view)) return 1;
    if (b->o.report_dir) {
        int scene_clips = b->o.p.ntrain_clips > 0;
        sw_bake_report_input ri = {b->source,
                                   &b->ch,
                                   &b->res,
                                   b->blob,
                                   scene_clips ? (const char(*)[64])b->clips.train_names : NULL,
                                   scene_clips ? b->clips.ntrain : 0,
                                   scene_clips ? (const char(*)[64])b->clips.heldout_names : NULL,
                                   scene_clips ? b->clips.nheldout : 0,
                                   b->frame_err,
                                   b->frame_err + b->res.ntrain,
                                   b->et.correction_error,
                                   b->eh.correction_error,
                                   b->et.failed + b->eh.failed,
                                   b->bake_seconds,
                                   b->eval_seconds,
                                   1,
                                   b->o.ad.rounds > 0 ? &b->arep : NULL,
                                   &b->et,
                                   &b->eh,
                                   !b->o.ca.file                             ? NULL
                                   : b->info.mesh.mesher == SW_MESHER_TETGEN ? "tetgen"
                                                                             : "lattice",
                                   b->mode_err,
                                   b->o.spread_every > 0 ? &b->spread : NULL,
                                   sw_linear_solver_name(b->o.reference.solver),
                                   sw_hessian_mode_name(b->o.reference.hessian),
                                   b->o.ad.rounds > 0 ? b->o.ad.target : 0,
                                   &b->memory};
        if ((r = sw_bake_report_write(b->o.report_dir, &ri, &err)) != SINEW_OK) {
            sw_tool_failed(r, &err, "%s: --report %s: ", tool, b->o.report_dir);
            return 1;
        }
        fprintf(stderr, "%s: wrote the report %s/report.html and %s/report.json\n", tool,
                b->o.report_dir, b->o.report_dir);
    }
    return 0;
}

/* The bake's summary on stderr. */
/* The blob's model: stages, domains and ranks, poses and bases, the references, contact
 * and the output surface. */
static void print_model(const bake *b) {
    const sw_blob_view *v = &b->res.view;
    fprintf(stderr, "%s: wrote %s\n", tool, b->o.out_path);
    fprintf(stderr, "  stages (s):");
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k) /* the bake's table (bake.h) */
        fprintf(stderr, "%s %s %.2f", k ? "," : "", sw_bake_stages[k].name,
                b->res.stage_seconds[k]);
    fprintf(stderr, "; total %.2f\n", b->bake_seconds);
    fprintf(stderr, "  domains %d, total rank %d (", v->ndomains, v->rank_total);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].rank);
    fprintf(stderr, "), cubature tets %d (", v->ncub);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].cub_count);
    fprintf(stderr, "), worst cubature fit %.4f\n", b->res.cubature_error_max);
    /* random held-out poses (no clip) come on a path: say what the count is made of */
    char held_how[128] = "";
    if (b->res.nheldout > 0 && b->res.heldout_clip[0] < 0)
        snprintf(held_how, sizeof held_how,
                 " (%d random combined poses, each reached in %d steps, %s)",
                 b->res.nheldout / b->o.p.heldout_steps, b->o.p.heldout_steps,
                 b->ch.range.nframes > 0 ? "the joints within --joint-range"
                                         : "every joint within 90 degrees");
    char pair_how[64] = ""; /* on by default only with a range: say when they ran */
    if (b->res.pair_sweep_poses > 0)
        snprintf(pair_how, sizeof pair_how, " (%d of joints swept with their parents)",
                 b->res.pair_sweep_poses);
    fprintf(stderr,
            "  poses: %d training%s, %d held-out%s; basis projection error train %.4f held-out "
            "%.4f; in the linearised model's energy (Galerkin) %.4f / %.4f\n",
            b->res.ntrain, pair_how, b->res.nheldout, held_how, b->res.train_proj_error,
            b->res.heldout_proj_error, b->res.train_galerkin_error, b->res.heldout_galerkin_error);
    if (b->res.rank_trained < b->res.view.rank_total)
        fprintf(stderr,
                "  the modes from physics: held-out projection error %.4f with them (rank %d), "
                "%.4f with the trained modes alone (rank %d)\n",
                b->res.heldout_proj_error, b->res.view.rank_total,
                b->res.heldout_proj_error_trained, b->res.rank_trained);
    fprintf(stderr, "  references solved by: solver %s, %s Hessians, at most %d contact rounds\n",
            sw_linear_solver_name(b->o.reference.solver),
            sw_hessian_mode_name(b->o.reference.hessian), b->o.reference.contact_rounds);
    fprintf(stderr,
            "  self-contact: %d contact pairs over the training poses in %d pairs of domains; "
            "the per-pair cubature keeps %d (--contact-tol %g)\n",
            v->ncontacts, v->npair_groups, b->kept, b->o.p.contact_cubature_tol);
    sw_blob_memory_print(&b->memory);
    if (v->nrender_verts > 0)
        fprintf(stderr,
                "  output: the render mesh, %d vertices (%d welded duplicates), %d triangles, "
                "embedded in %d tets in %.1f ms; %d vertices outside the tets, by %.4g at most; "
                "|barycentric| <= %.3g\n",
                v->nrender_verts, b->res.render_welded, v->nrender_tris, v->nembed_tets,
                1e3 * b->res.embed_seconds, b->res.render_outside, b->res.render_max_outside,
                b->res.render_max_bary);
}

/* How well the blob reproduces its references: on the bake's poses, by region and by
 * self-contact mode. */
static void print_accuracy(const bake *b) {
    char num[32];
    if (b->res.train_unsettled + b->res.heldout_unsettled > 0)
        fprintf(stderr,
                "  reference: the contact round cap left the contact set unsettled in %d "
                "training and "
                "%d held-out solutions (their fold depends on the cap)\n",
                b->res.train_unsettled, b->res.heldout_unsettled);
    fprintf(stderr,
            "  correction error (subspace vs full, share of the correction missed, on the bake's "
            "poses): train %.4f, held-out %.4f (%d failed steps)\n",
            b->et.correction_error, b->eh.correction_error, b->et.failed + b->eh.failed);
    if (b->res.model_train_error >= 0)
        fprintf(stderr,
                "  equilibrium force at %d of %d training poses; the training error without it "
                "%.4f\n",
                b->res.force_poses, b->res.ntrain, b->res.model_train_error);
    fprintf(stderr,
            "  seams (the domains' copies of a vertex apart, share of the correction; largest "
            "gap over the rest diagonal): train %.4f, %.2e; held-out %.4f, %.2e\n",
            b->et.seam, b->et.seam_max, b->eh.seam, b->eh.seam_max);
    for (int set = 0; set < 2; ++set) {
        const sw_eval_result *e = set ? &b->eh : &b->et;
        if (e->nregions < 1) continue;
        fprintf(stderr,
                "  %s error by region (strongest bone: share of the error / of the "
                "correction):",
                set ? "held-out" : "training");
        for (int32_t k = 0; k < e->nregions; ++k)
            fprintf(stderr, " bone %d%s%s %.3f / %.3f%s", e->region_bone[k],
                    b->ch.bone_names ? " " : "",
                    b->ch.bone_names ? b->ch.bone_names[e->region_bone[k]] : "", e->region_err[k],
                    e->region_corr[k], k + 1 < e->nregions ? "," : "\n");
    }
    fprintf(stderr, "  held-out error by self-contact mode:");
    for (int k = 0; k < SW_BAKE_MODES; ++k)
        fprintf(stderr, " %s %s%s", sw_self_contact_names[k],
                isfinite(b->mode_err[k]) ? json_number(b->mode_err[k], num) : "-",
                k + 1 < SW_BAKE_MODES ? "," : "\n");
}

/* What to look at: the reference's own spread, joints bent beyond training, a forced
 * blob, the cubature selectors compared. */
static void print_advice(const bake *b) {
    if (b->o.spread_every > 0)
        fprintf(stderr,
                "  reference spread at %d held-out poses (every %d-th): runtime %.4f; "
                "full-space "
                "solves from plain skinning %.4f, from the reference %.4f, from the runtime's "
                "state %.4f (moved it %.4f); %d unconverged, %d left out\n",
                b->spread.poses, b->o.spread_every, b->spread.runtime, b->spread.from_skin,
                b->spread.from_reference, b->spread.polished, b->spread.polish_move,
                b->spread.unconverged, b->spread.failed);
    if (b->nbeyond > 0) { /* where the basis extrapolates: what a training clip should reach */
        int32_t shown = b->nbeyond < 8 ? b->nbeyond : 8;
        fprintf(stderr,
                "  held-out poses bend %d joint%s beyond training (largest bend held-out "
                "/ in training, degrees):",
                b->nbeyond_all, b->nbeyond_all == 1 ? "" : "s");
        for (int32_t k = 0; k < shown; ++k) {
            fprintf(stderr, " bone %d", b->beyond[k].bone);
            if (b->ch.bone_names) fprintf(stderr, " %s", b->ch.bone_names[b->beyond[k].bone]);
            fprintf(stderr, " %.1f / %.1f%s", b->beyond[k].heldout_deg, b->beyond[k].train_deg,
                    k + 1 < shown        ? ","
                    : b->nbeyond > shown ? ", ...\n"
                                         : "\n");
        }
    }
    if (b->absurd)
        fprintf(stderr,
                "%s: WARNING: written with --force although its training error is %.4f (refused "
                "at %.2f) with %d failed steps: this blob misses most of the physics correction\n",
                tool, b->model_err, SW_BAKE_MAX_TRAIN_ERROR, b->et.failed);
    if (b->o.p.compare_selectors) {
        static const char *names[3] = {"greedy", "importance", "nnhtp"};
        for (int s = 0; s < 3; ++s)
            fprintf(stderr, "  selector %-10s %6d tets  %8.2f s  worst fit %.4f\n", names[s],
                    b->res.selector_points[s], b->res.selector_seconds[s],
                    b->res.selector_error[s]);
    }
}

static void print_summary(const bake *b) {
    print_model(b);
    print_accuracy(b);
    print_advice(b);
}

/* The JSON line, with --json. */
/* sinew-bake --json, one object in parts: the model, */
static void json_model(const bake *b) {
    char gt[32], gh[32];
    printf("{\"blob\":\"%s\",\"tets\":%d,\"verts\":%d,\"bones\":%d,\"domains\":%d,\"rank\":%d,"
           "\"cubature_tets\":%d,\"cubature_fit\":%.5f,\"train_poses\":%d,\"return_poses\":%d,"
           "\"pair_sweep_poses\":%d,\"heldout_poses\":%d,"
           "\"proj_err_train\":%.5f,\"proj_err_heldout\":%.5f,\"rank_trained\":%d,"
           "\"proj_err_heldout_trained\":%.5f,\"err_train\":%.5f,\"err_"
           "heldout\":%.5f,"
           "\"ref_unsettled_train\":%d,\"ref_unsettled_heldout\":%d,"
           "\"bake_seconds\":%.2f,\"eval_seconds\":%.2f",
           b->o.out_path, b->ch.mesh.ntets, b->ch.mesh.nverts, b->ch.skel.nbones,
           b->res.view.ndomains, b->res.view.rank_total, b->res.view.ncub,
           b->res.cubature_error_max, b->res.ntrain, b->res.return_poses, b->res.pair_sweep_poses,
           b->res.nheldout, b->res.train_proj_error, b->res.heldout_proj_error, b->res.rank_trained,
           b->res.heldout_proj_error_trained, b->et.correction_error, b->eh.correction_error,
           b->res.train_unsettled, b->res.heldout_unsettled, b->bake_seconds, b->eval_seconds);
    printf(",\"stages\":["); /* the bake's table (bake.h), as the report's JSON */
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k)
        printf("%s{\"name\":\"%s\",\"seconds\":%.2f}", k ? "," : "", sw_bake_stages[k].name,
               b->res.stage_seconds[k]);
    printf("]");
    printf(",\"pose_force_poses\":%d,\"err_train_model\":%.5f,\"ref_solver\":\"%s\","
           "\"ref_hessian\":\"%s\",\"joint_range_frames\":%d,\"seed\":%llu",
           b->res.force_poses, b->model_err, sw_linear_solver_name(b->o.reference.solver),
           sw_hessian_mode_name(b->o.reference.hessian), b->ch.range.nframes,
           (unsigned long long)b->o.p.seed);
    printf(",\"galerkin_err_train\":%s,\"galerkin_err_heldout\":%s",
           json_number(b->res.train_galerkin_error, gt),
           json_number(b->res.heldout_galerkin_error, gh));
    printf(",\"spring_k\":%.6g,\"spring_tried\":[", b->res.spring_k);
    for (int32_t k = 0; k < b->res.nspring_tried; ++k)
        printf("%s[%.4g,%.5f]", k ? "," : "", b->res.spring_tried_mult[k],
               b->res.spring_tried_err[k]);
    printf("]");
    printf(",\"seam_train\":%.5f,\"seam_heldout\":%.5f,\"seam_max_train\":%.3e,"
           "\"seam_max_heldout\":%.3e",
           b->et.seam, b->eh.seam, b->et.seam_max, b->eh.seam_max);
    printf(",\"surface_verts\":%d,\"surface_tris\":%d,\"render_mesh\":%s,"
           "\"render_outside\":%d,\"render_max_outside\":%.6g,\"render_max_bary\":%.4g,"
           "\"embed_seconds\":%.4f",
           sw_blob_output_verts(&b->res.view), sw_blob_output_ntris(&b->res.view),
           b->res.view.nrender_verts > 0 ? "true" : "false", b->res.render_outside,
           b->res.render_max_outside, b->res.render_max_bary, b->res.embed_seconds);
    if (b->o.ca.file)
        printf(",\"mesher\":\"%s\",\"mesh_min_dihedral_deg\":%.4g,\"mesh_slivers\":%d",
               b->info.mesh.mesher == SW_MESHER_TETGEN ? "tetgen" : "lattice",
               b->quality.min_dihedral_deg, b->quality.slivers);
}

/* how it was trained (the selectors compared, the adaptive rounds, the contact kept), */
static void json_training(const bake *b) {
    if (b->o.p.compare_selectors)
        printf(",\"selectors\":{\"greedy\":[%d,%.3f,%.4f],\"importance\":[%d,%.3f,%.4f],"
               "\"nnhtp\":[%d,%.3f,%.4f]}",
               b->res.selector_points[0], b->res.selector_seconds[0], b->res.selector_error[0],
               b->res.selector_points[1], b->res.selector_seconds[1], b->res.selector_error[1],
               b->res.selector_points[2], b->res.selector_seconds[2], b->res.selector_error[2]);
    for (int k = 0; b->o.ad.rounds > 0 && k < b->arep.nrounds; ++k) {
        const sw_adaptive_round *a = &b->arep.round[k];
        printf("%s{\"train_poses\":%d,\"added\":%d,\"rank\":%d,\"err_train\":%.5f,"
               "\"err_heldout\":%.5f,\"proj_err_train\":%.5f,\"proj_err_heldout\":%.5f,"
               "\"score_mean\":%.4f,\"score_max\":%.4f,\"picks_score\":%.4f,"
               "\"picks_error\":%.5f,\"solved\":%d,\"seconds\":%.2f}%s",
               k == 0 ? ",\"adaptive\":[" : ",", a->ntrain, a->added, a->rank_total, a->err_train,
               a->err_heldout, a->proj_train, a->proj_heldout, a->score_mean, a->score_max,
               a->picks_score, a->picks_error, a->solved, a->seconds,
               k + 1 == b->arep.nrounds ? "]" : "");
    }
    printf(",\"contact_pairs\":%d,\"pair_groups\":%d,\"contact_pairs_kept\":%d",
           b->res.view.ncontacts, b->res.view.npair_groups, b->kept);
}

/* where its error is (regions, self-contact modes, the reference's own spread), */
static void json_errors(const bake *b) {
    char num[32];
    for (int set = 0; set < 2; ++set) { /* [bone, share of the error, of the correction] */
        const sw_eval_result *e = set ? &b->eh : &b->et;
        printf(",\"err_regions_%s\":[", set ? "heldout" : "train");
        for (int32_t k = 0; k < e->nregions; ++k)
            printf("%s[%d,%.4f,%.4f]", k ? "," : "", e->region_bone[k], e->region_err[k],
                   e->region_corr[k]);
        printf("]");
    }
    printf(",\"err_heldout_by_mode\":{");
    for (int k = 0; k < SW_BAKE_MODES; ++k)
        printf("%s\"%s\":%s", k ? "," : "", sw_self_contact_keys[k],
               json_number(b->mode_err[k], num));
    printf("}");
    if (b->o.spread_every > 0)
        printf(",\"ref_spread\":{\"every\":%d,\"poses\":%d,\"runtime\":%.5f,"
               "\"from_skin\":%.5f,\"from_reference\":%.5f,\"polished\":%.5f,"
               "\"polish_move\":%.5f,\"unconverged\":%d,\"failed\":%d}",
               b->o.spread_every, b->spread.poses, b->spread.runtime, b->spread.from_skin,
               b->spread.from_reference, b->spread.polished, b->spread.polish_move,
               b->spread.unconverged, b->spread.failed);
    for (int32_t k = 0; b->o.spread_every > 0 && k < b->spread.poses; ++k) {
        /* [held-out pose, runtime, from_skin, from_reference, polished, correction] */
        const sw_bake_spread_pose *q = &b->spread.per_pose[k];
        printf("%s[%d,%.5f,%.5f,%.5f,%.5f,%.4g]%s", k ? "," : ",\"ref_spread_poses\":[", q->heldout,
               q->runtime, q->from_skin, q->from_reference, q->polished, q->correction,
               k + 1 == b->spread.poses ? "]" : "");
    }
}

/* and the joints the held-out clips bend beyond training. */
static void json_beyond(const bake *b) {
    printf(",\"heldout_beyond_training\":["); /* [bone, name, held-out, training deg] */
    for (int32_t k = 0; k < b->nbeyond; ++k) {
        printf("%s[%d,", k ? "," : "", b->beyond[k].bone);
        if (b->ch.bone_names)
            sw_tool_json_string(b->ch.bone_names[b->beyond[k].bone]);
        else
            printf("null");
        printf(",%.2f,%.2f]", b->beyond[k].heldout_deg, b->beyond[k].train_deg);
    }
    printf("]");
}

static void print_json(const bake *b) {
    if (!b->o.json) return;
    json_model(b);
    json_training(b);
    json_errors(b);
    json_beyond(b);
    sw_blob_memory_json(&b->memory);
    printf(",\"simulate_cached\":%s,\"simulate_solved\":%d,\"forced\":%s,"
           "\"shipped\":\"%s\"}\n",
           b->res.simulate_cached ? "true" : "false", b->res.simulate_solved,
           b->absurd ? "true" : "false", b->ship_whole ? "whole_clip" : "as_measured");
}

/* The figures are the split's; a character's only clip then ships trained on the whole
 * clip (sw_bake_ships_whole_clip) unless --ship-split or adaptive rounds. Not when the
 * blob is not going to be written (absurd without --force). */
static int ship_whole_clip(bake *b, sw_error *err) {
    const bake_options *o = &b->o;
    if (o->ad.rounds > 0 || !sw_bake_ships_whole_clip(&b->ch, &o->p)) return 0;
    if (b->absurd && !o->force) return 0;
    fprintf(stderr,
            "%s: the figures are of the split (held-out: the clip's last %.0f%%); the blob "
            "ships baked on all %d frames of the clip (--ship-split: the split's)\n",
            tool, 100 * o->p.heldout_fraction, b->ch.clip.nframes);
    sinew_result r = sw_bake_whole_clip(&b->ch, &o->p, &b->whole, err);
    if (r != SINEW_OK) return sw_tool_failed(r, err, "%s: the whole clip's bake: ", tool);
    b->ship_whole = 1;
    return 0;
}

static void bake_free(bake *b) {
    sw_bake_result_free(&b->whole);
    sw_bake_spread_free(&b->spread);
    sinew_blob_destroy(b->blob);
    free(b->mem);
    free(b->frame_err);
    sw_bake_result_free(&b->res);
    sw_character_free(&b->ch);
    sw_clip_split_free(&b->clips);
}

int main(int argc, char **argv) {
    static bake b;
    sw_error err;
    int status = bake_parse_args(argc, argv, &b.o);
    if (status || (status = load_character(&b, &err))) return status;
    if (b.o.plan_path || b.o.p.shard_count > 0) { /* a farm's plan or shard: no blob */
        sw_tool_bake_clips(&b.o.ca, &b.clips, &b.o.p);
        status = bake_farm(&b.o, &b.ch);
        sw_character_free(&b.ch);
        sw_clip_split_free(&b.clips);
        return status;
    }
    if ((status = run_bake(&b, &err))) {
        sw_character_free(&b.ch);
        sw_clip_split_free(&b.clips);
        return status;
    }
    if (!(status = measure(&b, &err)) && !(status = ship_whole_clip(&b, &err)) &&
        !(status = write_outputs(&b))) {
        print_summary(&b);
        print_json(&b);
    }
    bake_free(&b);
    return status;
}
