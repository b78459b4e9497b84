/* The bake report: figures gathered once, written as JSON (libcjson) and as one HTML
 * page with inline SVG (bake_report.h; the page in bake_report_html.c, the verdict in
 * bake_report_verdict.c).
 *
 * report.json (schema 1):
 *   sinew_bake_report  1
 *   verdict {status "pass" | "miss" | "not_measured", pass (null: not measured),
 *              err_heldout, target, target_source "default" | "given", headline, advice
 *              (plain words), add_motion_for "joints_beyond_training" | "joints_with_error" |
 *              "none", add_motion [{bone, name, heldout_deg, train_deg} | {bone, name,
 *              err_share}]}: the held-out error against the target (SW_BAKE_REPORT_TARGET
 *              unless given) and, on a miss, the joints to add training motion for
 *   source, character {name, tets, verts, bones, render_verts, render_tris, youngs,
 *                      poisson, density, mesher (null: the character's own tet mesh),
 *                      quality {min_dihedral_deg, max_dihedral_deg, slivers, inverted,
 *                      degenerate} (sw_tetmesh_quality)}
 *   err_train, err_heldout, proj_err_train, proj_err_heldout, galerkin_err_train,
 *   galerkin_err_heldout (null: not definite), cubature_fit, failed_steps
 *   levels_of_detail {pose_space_modes, pose_space_dropped, pose_space_ridge,
 *              err_heldout_surface [full, reduced, pose-space]}: each level's held-out
 *              error on the output surface (bake_lod.c)
 *   springs {k, eh, tried [[E h multiple, training error]]}: the interface springs'
 *              stiffness and the choices the bake measured (bake_springs.c)
 *   seams {train, heldout, max_train, max_heldout}: the domains' copies of a vertex apart
 *              (sw_eval_result's seam, seam_max), or null
 *   bake_seconds, eval_seconds, stages [{name, seconds}]
 *   render {verts, outside, max_outside}: the render mesh's vertices, those embedded
 *              outside the tets (they follow the nearest tet, extrapolated), or null
 *   clips [{name, split "train" | "heldout", frames [clip frame], error [per frame]}]
 *   sweeps {poses, mean_error}: the training poses of no clip (joint sweeps, return path)
 *   domains [{bone, rank, energy, cubature}]
 *   adaptive [{train_poses, added, rank, err_train, err_heldout, proj_err_train,
 *              proj_err_heldout, picks_error (null: not verified), seconds}]: one per
 *              bake of the adaptive loop (bake_adaptive.h), or null without it
 *   err_regions {train, heldout: [{bone, name, err_share, correction_share}]}: the bones whose
 *              vertices (by their strongest bone) hold the largest shares of the squared
 *              error (sw_eval_result's regions), or null
 *   err_heldout_by_mode {pose_space, exhaustive, pose_pairs}: the held-out error in each
 *              self-contact mode (null: not measured, or the blob has no per-pair sections),
 *              or null
 *   heldout_beyond_training [{bone, name (null: the file names none), heldout_deg,
 *              train_deg}]: the joints the held-out poses bend further than the training
 *              poses (sw_bake_beyond_training), the largest multiple of the trained bend
 *              first, at most 32
 *   contact_sheet: the PNG's file name, or null
 *   contact_sheet_tiles {color_scale, character_size (length units), columns [key],
 *              rows [{heldout_pose, clip, frame, files [per column], max_dist, mean_dist
 *              [per column: vertex distances from the reference]}]}, or null
 *   reference {solver, hessian}: what solved the full-space references (null: not given)
 *   joint_range_frames: the frames of the character's joint range that bound its sweeps
 *              and random poses (sw_character.range; 0: none, 90 degrees a joint) */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bake_report_internal.h"
#include "blob_load.h"
#include "mesh_io.h"
#include "pose_space.h"
#include "tool_common.h"

/* The one place the report reads the bake's stage list: the bake's own table
 * (sw_bake_stages, bake.h) and the seconds sw_bake_result.stage_seconds keeps for each. */
int32_t report_stage_times(const sw_bake_result *res, const char **names, double *seconds) {
    _Static_assert(SW_BAKE_NSTAGES <= REPORT_MAX_STAGES, "room for the stages");
    for (int32_t k = 0; k < SW_BAKE_NSTAGES; ++k) {
        names[k] = sw_bake_stages[k].name;
        seconds[k] = res->stage_seconds[k];
    }
    return SW_BAKE_NSTAGES;
}

void report_bone_name(const sw_character *ch, int32_t bone, char *buf, size_t n) {
    if (ch->bone_names && ch->bone_names[bone][0])
        snprintf(buf, n, "%s", ch->bone_names[bone]);
    else
        snprintf(buf, n, "bone %d", bone);
}

static void report_free(report *r) {
    for (int32_t i = 0; i < r->nclips; ++i) {
        free(r->clips[i].frame);
        free(r->clips[i].error);
        free(r->clips[i].beyond);
    }
    free(r->clips);
    memset(r, 0, sizeof *r);
}

/* The poses of one split labelled `label` as a clip of the report (label -1: the poses
 * of no clip, numbered in order: a bare skeleton's random combined held-out poses), each
 * with its error and the joints it bends beyond the bake's training (T: the split's
 * poses, 12 nbones each). */
static int gather_clip(report_clip *c, int32_t npose, const int32_t *labels, const int32_t *frames,
                       const double *errors, int32_t label, const double *T,
                       const sw_bake_report_input *in) {
    const sw_skeleton *sk = &in->ch->skel;
    c->frame = malloc(sizeof(int32_t) * ((size_t)npose + 1));
    c->error = malloc(sizeof(double) * ((size_t)npose + 1));
    c->beyond = malloc(sizeof(int32_t) * ((size_t)npose + 1));
    if (!c->frame || !c->error || !c->beyond) return 0;
    for (int32_t k = 0; k < npose; ++k)
        if (labels[k] == label) {
            int32_t b =
                sw_bake_pose_beyond(sk, T + (size_t)k * 12 * sk->nbones, in->res->sweep_angle);
            if (b < 0) return 0;
            c->nbeyond += b > 0;
            c->beyond[c->n] = b;
            c->frame[c->n] = label < 0 ? c->n : frames[k];
            c->error[c->n++] = errors[k];
        }
    return 1;
}

int report_heldout_random(const sw_bake_result *res) {
    return res->nheldout > 0 && res->heldout_clip[0] < 0;
}

static int gather(const sw_bake_report_input *in, report *r) {
    const sw_bake_result *res = in->res;
    int32_t nt = in->train_names ? in->ntrain_names : 1,
            nh = in->heldout_names ? in->nheldout_names : 1;
    r->clips = calloc((size_t)(nt + nh), sizeof *r->clips);
    if (!r->clips) return 0;
    for (int s = 0; s < 2; ++s) {
        int32_t n = s ? nh : nt, npose = s ? res->nheldout : res->ntrain;
        const char(*names)[64] = s ? in->heldout_names : in->train_names;
        for (int32_t i = 0; i < n; ++i) {
            report_clip *c = &r->clips[r->nclips++];
            c->heldout = s;
            int32_t label = s && report_heldout_random(res) ? -1 : i;
            if (names)
                snprintf(c->name, sizeof c->name, "%s", names[i]);
            else if (label < 0)
                snprintf(c->name, sizeof c->name, "random combined poses");
            else
                snprintf(c->name, sizeof c->name, "%s (%s part)",
                         in->ch->name[0] ? in->ch->name : "clip", s ? "held-out" : "training");
            if (!gather_clip(c, npose, s ? res->heldout_clip : res->train_clip,
                             s ? res->heldout_frame : res->train_frame,
                             s ? in->heldout_frames : in->train_frames, label,
                             s ? res->heldout_T : res->train_T, in))
                return 0;
            if (!names && c->n == 0) { /* no clip to show (a bare skeleton trains on sweeps) */
                free(c->frame);
                free(c->error);
                free(c->beyond);
                memset(c, 0, sizeof *c);
                r->nclips--;
            }
        }
    }
    double sum = 0;
    for (int32_t k = 0; k < res->ntrain; ++k)
        if (res->train_clip[k] < 0 && isfinite(in->train_frames[k]))
            sum += in->train_frames[k], r->sweep_poses++;
    r->sweep_mean = r->sweep_poses ? sum / r->sweep_poses : 0;
    r->nbeyond_all = sw_bake_beyond_training(res, &in->ch->skel, r->beyond, REPORT_BEYOND);
    r->nbeyond = r->nbeyond_all < REPORT_BEYOND ? r->nbeyond_all : REPORT_BEYOND;
    return r->nbeyond_all >= 0;
}

/* A number for JSON: non-finite (a failed step) becomes null. */
static cJSON *json_number(double v) {
    return isfinite(v) ? cJSON_CreateNumber(v) : cJSON_CreateNull();
}

/* The four shares of sw_bake_spread (the whole figure's, or one pose's) into o. */
static void json_spread_shares(cJSON *o, double runtime, double from_skin, double from_reference,
                               double polished) {
    cJSON_AddItemToObject(o, "runtime", json_number(runtime));
    cJSON_AddItemToObject(o, "from_skin", json_number(from_skin));
    cJSON_AddItemToObject(o, "from_reference", json_number(from_reference));
    cJSON_AddItemToObject(o, "polished", json_number(polished));
}

/* --reference-spread's figures, whole and per pose (null: not measured). */
static cJSON *json_spread(const sw_bake_spread *s) {
    if (!s) return cJSON_CreateNull();
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "poses", s->poses);
    json_spread_shares(o, s->runtime, s->from_skin, s->from_reference, s->polished);
    cJSON_AddItemToObject(o, "polish_move", json_number(s->polish_move));
    cJSON_AddNumberToObject(o, "unconverged", s->unconverged);
    cJSON_AddNumberToObject(o, "failed", s->failed);
    cJSON *pp = cJSON_AddArrayToObject(o, "per_pose");
    for (int32_t k = 0; k < s->poses; ++k) {
        const sw_bake_spread_pose *q = &s->per_pose[k];
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "heldout", q->heldout);
        json_spread_shares(e, q->runtime, q->from_skin, q->from_reference, q->polished);
        cJSON_AddItemToObject(e, "correction", json_number(q->correction));
        cJSON_AddItemToArray(pp, e);
    }
    return o;
}

static cJSON *json_character(const sw_bake_report_input *in) {
    const sw_character *ch = in->ch;
    cJSON *c = cJSON_CreateObject();
    cJSON_AddStringToObject(c, "name", ch->name);
    cJSON_AddNumberToObject(c, "tets", ch->mesh.ntets);
    cJSON_AddNumberToObject(c, "verts", ch->mesh.nverts);
    cJSON_AddNumberToObject(c, "bones", ch->skel.nbones);
    cJSON_AddNumberToObject(c, "render_verts", ch->render.nverts);
    cJSON_AddNumberToObject(c, "render_tris", ch->render.ntris);
    cJSON_AddNumberToObject(c, "youngs", ch->youngs);
    cJSON_AddNumberToObject(c, "poisson", ch->poisson);
    cJSON_AddNumberToObject(c, "density", ch->density);
    cJSON_AddItemToObject(c, "mesher",
                          in->mesher ? cJSON_CreateString(in->mesher) : cJSON_CreateNull());
    sw_quality q;
    sw_tetmesh_quality(&ch->mesh, 0, &q);
    cJSON *qj = cJSON_AddObjectToObject(c, "quality");
    cJSON_AddNumberToObject(qj, "min_dihedral_deg", q.min_dihedral_deg);
    cJSON_AddNumberToObject(qj, "max_dihedral_deg", q.max_dihedral_deg);
    cJSON_AddNumberToObject(qj, "slivers", q.slivers);
    cJSON_AddNumberToObject(qj, "inverted", q.inverted);
    cJSON_AddNumberToObject(qj, "degenerate", q.degenerate);
    return c;
}

static cJSON *json_clips(const report *r) {
    cJSON *a = cJSON_CreateArray();
    for (int32_t i = 0; i < r->nclips; ++i) {
        const report_clip *c = &r->clips[i];
        cJSON *o = cJSON_CreateObject(), *f = cJSON_CreateArray(), *e = cJSON_CreateArray(),
              *b = cJSON_CreateArray();
        cJSON_AddStringToObject(o, "name", c->name);
        cJSON_AddStringToObject(o, "split", c->heldout ? "heldout" : "train");
        for (int32_t k = 0; k < c->n; ++k) {
            cJSON_AddItemToArray(f, cJSON_CreateNumber(c->frame[k]));
            cJSON_AddItemToArray(e, json_number(c->error[k]));
            cJSON_AddItemToArray(b, cJSON_CreateNumber(c->beyond[k]));
        }
        cJSON_AddItemToObject(o, "frames", f);
        cJSON_AddItemToObject(o, "error", e);
        cJSON_AddItemToObject(o, "beyond_training", b);
        cJSON_AddItemToArray(a, o);
    }
    return a;
}

static cJSON *json_domains(const sw_bake_report_input *in) {
    const sw_blob_view *v = sw_blob_get_view(in->blob);
    cJSON *a = cJSON_CreateArray();
    for (int32_t d = 0; d < v->ndomains; ++d) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "bone", v->domains[d].bone);
        cJSON_AddNumberToObject(o, "rank", v->domains[d].rank);
        cJSON_AddItemToObject(o, "energy",
                              json_number(in->res->basis_energy ? in->res->basis_energy[d] : NAN));
        cJSON_AddNumberToObject(o, "cubature", v->domains[d].cub_count);
        cJSON_AddItemToArray(a, o);
    }
    return a;
}

static cJSON *json_adaptive(const sw_adaptive_report *a) {
    if (!a || a->nrounds < 1) return cJSON_CreateNull();
    cJSON *arr = cJSON_CreateArray();
    for (int32_t k = 0; k < a->nrounds; ++k) {
        const sw_adaptive_round *rd = &a->round[k];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "train_poses", rd->ntrain);
        cJSON_AddNumberToObject(o, "added", rd->added);
        cJSON_AddNumberToObject(o, "rank", rd->rank_total);
        cJSON_AddItemToObject(o, "err_train", json_number(rd->err_train));
        cJSON_AddItemToObject(o, "err_heldout", json_number(rd->err_heldout));
        cJSON_AddItemToObject(o, "proj_err_train", json_number(rd->proj_train));
        cJSON_AddItemToObject(o, "proj_err_heldout", json_number(rd->proj_heldout));
        cJSON_AddItemToObject(o, "picks_error",
                              rd->picks_error >= 0 ? json_number(rd->picks_error)
                                                   : cJSON_CreateNull());
        cJSON_AddNumberToObject(o, "seconds", rd->seconds);
        cJSON_AddItemToArray(arr, o);
    }
    return arr;
}

/* A bone in the JSON: its index and its name in the file (null: the character has none). */
static void json_bone(cJSON *o, const sw_character *ch, int32_t bone) {
    cJSON_AddNumberToObject(o, "bone", bone);
    if (ch->bone_names)
        cJSON_AddStringToObject(o, "name", ch->bone_names[bone]);
    else
        cJSON_AddNullToObject(o, "name");
}

/* The regions of an evaluation (sw_eval_result): [{bone, name, err_share,
 * correction_share}]. */
static cJSON *json_regions(const sw_eval_result *e, const sw_character *ch) {
    cJSON *arr = cJSON_CreateArray();
    for (int32_t k = 0; k < e->nregions; ++k) {
        cJSON *o = cJSON_CreateObject();
        json_bone(o, ch, e->region_bone[k]);
        cJSON_AddNumberToObject(o, "err_share", e->region_err[k]);
        cJSON_AddNumberToObject(o, "correction_share", e->region_corr[k]);
        cJSON_AddItemToArray(arr, o);
    }
    return arr;
}

/* The contact sheet's tiles: the colour scale, and per frame its pose and each column's
 * file and distances from the reference. */
static cJSON *json_sheet(const sw_bake_report_input *in, const report *r) {
    const sw_bake_report_sheet_info *s = &r->sheet_info;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "color_scale", s->scale);
    cJSON_AddNumberToObject(o, "character_size", s->size);
    cJSON *cols = cJSON_AddArrayToObject(o, "columns");
    for (int c = 0; c < SW_SHEET_COLS; ++c)
        cJSON_AddItemToArray(cols, cJSON_CreateString(sw_bake_report_sheet_keys[c]));
    cJSON *rows = cJSON_AddArrayToObject(o, "rows");
    for (int32_t row = 0; row < s->rows; ++row) {
        int32_t k = s->pose[row];
        cJSON *e = cJSON_CreateObject(), *files = cJSON_CreateArray(), *mx = cJSON_CreateArray(),
              *mean = cJSON_CreateArray();
        cJSON_AddNumberToObject(e, "heldout_pose", k);
        cJSON_AddNumberToObject(e, "clip", in->res->heldout_clip[k]);
        cJSON_AddNumberToObject(e, "frame", in->res->heldout_frame[k]);
        for (int c = 0; c < SW_SHEET_COLS; ++c) {
            char name[64];
            sw_bake_report_tile_name(name, sizeof name, row, c);
            cJSON_AddItemToArray(files, cJSON_CreateString(name));
            cJSON_AddItemToArray(mx, json_number(s->max_dist[row][c]));
            cJSON_AddItemToArray(mean, json_number(s->mean_dist[row][c]));
        }
        cJSON_AddItemToObject(e, "files", files);
        cJSON_AddItemToObject(e, "max_dist", mx);
        cJSON_AddItemToObject(e, "mean_dist", mean);
        cJSON_AddItemToArray(rows, e);
    }
    return o;
}

/* The report's JSON in parts: the model's figures (errors, projections, the equilibrium
 * force, the levels, the springs), */
static void json_model_figures(cJSON *j, const sw_bake_report_input *in) {
    const sw_bake_result *res = in->res;
    cJSON_AddItemToObject(j, "err_train", json_number(in->err_train));
    cJSON_AddItemToObject(j, "err_heldout", json_number(in->err_heldout));
    cJSON_AddNumberToObject(j, "proj_err_train", res->train_proj_error);
    cJSON_AddNumberToObject(j, "proj_err_heldout", res->heldout_proj_error);
    cJSON_AddNumberToObject(j, "rank_trained", res->rank_trained);
    cJSON_AddNumberToObject(j, "proj_err_heldout_trained", res->heldout_proj_error_trained);
    cJSON_AddItemToObject(j, "galerkin_err_train", json_number(res->train_galerkin_error));
    cJSON_AddItemToObject(j, "galerkin_err_heldout", json_number(res->heldout_galerkin_error));
    cJSON_AddNumberToObject(j, "cubature_fit", res->cubature_error_max);
    cJSON *eq = cJSON_AddObjectToObject(j, "equilibrium_force");
    cJSON_AddNumberToObject(eq, "poses", res->force_poses);
    cJSON_AddItemToObject(eq, "err_train_without",
                          res->model_train_error >= 0 ? json_number(res->model_train_error)
                                                      : cJSON_CreateNull());
    cJSON *lod = cJSON_AddObjectToObject(j, "levels_of_detail");
    cJSON_AddNumberToObject(lod, "pose_space_modes", res->view.lod_rank);
    cJSON_AddNumberToObject(lod, "pose_space_dropped", res->lod_kept);
    cJSON_AddNumberToObject(lod, "pose_space_ridge", res->lod_ridge);
    cJSON *lerr = cJSON_AddArrayToObject(lod, "err_heldout_surface"); /* sinew_lod's order */
    for (int l = 0; l < SW_BAKE_LODS; ++l)
        cJSON_AddItemToArray(lerr, json_number(res->lod_heldout[l]));
    if (in->memory) {
        const sw_blob_memory *m = in->memory;
        cJSON *mem = cJSON_AddObjectToObject(j, "memory");
        cJSON_AddNumberToObject(mem, "blob_bytes", (double)m->blob);
        cJSON *parts = cJSON_AddObjectToObject(mem, "blob_parts");
        for (int k = 0; k < SW_NPARTS; ++k)
            cJSON_AddNumberToObject(parts, sw_blob_part_keys[k], (double)m->part[k]);
        cJSON_AddNumberToObject(mem, "instance_bytes", (double)m->instance);
        cJSON_AddNumberToObject(mem, "instance_shared_bytes", (double)m->instance_shared);
        cJSON_AddNumberToObject(mem, "workspace_bytes", (double)m->workspace);
    }
    cJSON *sp = cJSON_AddObjectToObject(j, "springs");
    cJSON_AddNumberToObject(sp, "k", res->spring_k);
    cJSON_AddNumberToObject(sp, "eh", res->spring_eh);
    cJSON *tried = cJSON_AddArrayToObject(sp, "tried");
    for (int32_t k = 0; k < res->nspring_tried; ++k) {
        cJSON *pair = cJSON_CreateArray();
        cJSON_AddItemToArray(pair, cJSON_CreateNumber(res->spring_tried_mult[k]));
        cJSON_AddItemToArray(pair, json_number(res->spring_tried_err[k]));
        cJSON_AddItemToArray(tried, pair);
    }
}

/* how the bake ran (seams, the reference's solver, the stages' times, the render mesh), */
static void json_run(cJSON *j, const sw_bake_report_input *in) {
    const sw_bake_result *res = in->res;
    if (in->eval_train && in->eval_heldout) {
        cJSON *o = cJSON_AddObjectToObject(j, "seams");
        cJSON_AddItemToObject(o, "train", json_number(in->eval_train->seam));
        cJSON_AddItemToObject(o, "heldout", json_number(in->eval_heldout->seam));
        cJSON_AddItemToObject(o, "max_train", json_number(in->eval_train->seam_max));
        cJSON_AddItemToObject(o, "max_heldout", json_number(in->eval_heldout->seam_max));
    } else {
        cJSON_AddNullToObject(j, "seams");
    }
    if (in->ref_solver && in->ref_hessian) {
        cJSON *o = cJSON_AddObjectToObject(j, "reference");
        cJSON_AddStringToObject(o, "solver", in->ref_solver);
        cJSON_AddStringToObject(o, "hessian", in->ref_hessian);
    } else {
        cJSON_AddNullToObject(j, "reference");
    }
    cJSON_AddNumberToObject(j, "joint_range_frames", in->ch->range.nframes);
    cJSON_AddNumberToObject(j, "failed_steps", in->failed_steps);
    cJSON_AddNumberToObject(j, "bake_seconds", in->bake_seconds);
    cJSON_AddNumberToObject(j, "eval_seconds", in->eval_seconds);
    cJSON *st = cJSON_AddArrayToObject(j, "stages");
    const char *names[REPORT_MAX_STAGES];
    double seconds[REPORT_MAX_STAGES];
    for (int32_t k = 0, n = report_stage_times(res, names, seconds); k < n; ++k) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", names[k]);
        cJSON_AddNumberToObject(o, "seconds", seconds[k]);
        cJSON_AddItemToArray(st, o);
    }
    if (in->ch->render.nverts > 0) { /* the bake's log warns of vertices outside */
        cJSON *rd = cJSON_AddObjectToObject(j, "render");
        cJSON_AddNumberToObject(rd, "verts", in->ch->render.nverts);
        cJSON_AddNumberToObject(rd, "outside", res->render_outside);
        cJSON_AddNumberToObject(rd, "max_outside", res->render_max_outside);
    } else
        cJSON_AddNullToObject(j, "render");
}

/* and where the error is (clips, sweeps, domains, regions, modes, the reference's spread,
 * the joints beyond training, the contact sheet). */
static void json_where(cJSON *j, const sw_bake_report_input *in, const report *r) {
    cJSON_AddItemToObject(j, "clips", json_clips(r));
    cJSON *sw = cJSON_AddObjectToObject(j, "sweeps");
    cJSON_AddNumberToObject(sw, "poses", r->sweep_poses);
    cJSON_AddNumberToObject(sw, "mean_error", r->sweep_mean);
    cJSON_AddItemToObject(j, "domains", json_domains(in));
    cJSON_AddItemToObject(j, "adaptive", json_adaptive(in->adaptive));
    if (in->eval_train && in->eval_heldout) {
        cJSON *er = cJSON_AddObjectToObject(j, "err_regions");
        cJSON_AddItemToObject(er, "train", json_regions(in->eval_train, in->ch));
        cJSON_AddItemToObject(er, "heldout", json_regions(in->eval_heldout, in->ch));
    } else {
        cJSON_AddNullToObject(j, "err_regions");
    }
    if (in->mode_err_heldout) {
        cJSON *m = cJSON_AddObjectToObject(j, "err_heldout_by_mode");
        for (int k = 0; k < SW_BAKE_MODES; ++k)
            cJSON_AddItemToObject(m, sw_self_contact_keys[k], json_number(in->mode_err_heldout[k]));
    } else {
        cJSON_AddNullToObject(j, "err_heldout_by_mode");
    }
    cJSON_AddItemToObject(j, "ref_spread", json_spread(in->spread));
    cJSON *bt = cJSON_AddArrayToObject(j, "heldout_beyond_training");
    for (int32_t k = 0; k < r->nbeyond; ++k) {
        cJSON *o = cJSON_CreateObject();
        json_bone(o, in->ch, r->beyond[k].bone);
        cJSON_AddNumberToObject(o, "heldout_deg", r->beyond[k].heldout_deg);
        cJSON_AddNumberToObject(o, "train_deg", r->beyond[k].train_deg);
        cJSON_AddItemToArray(bt, o);
    }
    if (r->sheet) {
        cJSON_AddStringToObject(j, "contact_sheet", SHEET_NAME);
        cJSON_AddItemToObject(j, "contact_sheet_tiles", json_sheet(in, r));
    } else {
        cJSON_AddNullToObject(j, "contact_sheet");
        cJSON_AddNullToObject(j, "contact_sheet_tiles");
    }
}

static char *report_json(const sw_bake_report_input *in, const report *r) {
    cJSON *j = cJSON_CreateObject();
    cJSON_AddNumberToObject(j, "sinew_bake_report", SW_BAKE_REPORT_VERSION);
    cJSON_AddItemToObject(j, "verdict", report_verdict_json(in, r));
    cJSON_AddStringToObject(j, "source", in->source ? in->source : "");
    cJSON_AddItemToObject(j, "character", json_character(in));
    json_model_figures(j, in);
    json_run(j, in);
    json_where(j, in, r);
    char *text = cJSON_Print(j);
    cJSON_Delete(j);
    return text;
}

sinew_result sw_bake_report_write(const char *dir, const sw_bake_report_input *in, sw_error *err) {
    if (!dir || !in || !in->ch || !in->res || !in->blob || !in->train_frames || !in->heldout_frames)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "report: NULL argument");
    if (!sw_tool_make_dirs(dir))
        return sw_error_set(err, SINEW_ERROR_IO, "report: cannot create the folder %s: %s", dir,
                            strerror(errno ? errno : EACCES));
    report r;
    memset(&r, 0, sizeof r);
    sinew_result sr0;
    if (in->contact_sheet && in->res->nheldout > 0) {
        sinew_result sr = sw_bake_report_sheet(dir, in->ch, in->res, in->blob,
                                               SW_BAKE_REPORT_SHEET_ROWS, &r.sheet_info, err);
        if (sr != SINEW_OK) return sr;
        r.sheet = 1;
    }
    if (in->ch->tet_stiffness && (sr0 = sw_bake_report_paint(dir, in->ch, err)) != SINEW_OK)
        return sr0;
    if (!gather(in, &r)) {
        report_free(&r);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "report: out of memory");
    }
    report_verdict_make(in, &r);
    char path[4096];
    char *json = report_json(in, &r);
    snprintf(path, sizeof path, "%s/report.json", dir);
    FILE *f = json ? fopen(path, "w") : NULL;
    int ok = f && fputs(json, f) >= 0 && fputc('\n', f) != EOF;
    if (f) ok = fclose(f) == 0 && ok;
    free(json);
    if (ok) {
        snprintf(path, sizeof path, "%s/report.html", dir);
        ok = report_write_html(path, in, &r);
    }
    report_free(&r);
    if (!ok) return sw_error_set(err, SINEW_ERROR_IO, "report: cannot write %s", path);
    return SINEW_OK;
}
