/* The bake report: figures gathered once, written as JSON (libcjson) and as one HTML
 * page with inline SVG (bake_report.h).
 *
 * report.json (schema 1):
 *   sinew_bake_report  1
 *   source, character {name, tets, verts, bones, render_verts, render_tris, youngs,
 *                      poisson, density, mesher (null: the character's own tet mesh),
 *                      quality {min_dihedral_deg, max_dihedral_deg, slivers, inverted,
 *                      degenerate} (sw_tetmesh_quality)}
 *   err_train, err_heldout, proj_err_train, proj_err_heldout, galerkin_err_train,
 *   galerkin_err_heldout (null: not definite), cubature_fit, failed_steps
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
 *   reference {solver, hessian}: what solved the full-space references (null: not given)
 *   joint_range_frames: the frames of the character's joint range that bound its sweeps
 *              and random poses (sw_character.range; 0: none, 90 degrees a joint) */
#include "bake_report.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "blob_load.h"
#include "mesh_io.h"
#include "pose_space.h"
#include "tool_common.h"

#define SHEET_NAME "heldout_sheet.png"

/* One clip's frames in the report: the poses of `split` labelled `label`. */
typedef struct report_clip {
    char name[80];
    int heldout;
    int32_t n;
    int32_t *frame;
    double *error;
    int32_t *beyond; /* per frame: joints bent beyond training (sw_bake_pose_beyond) */
    int32_t nbeyond; /* frames with any */
} report_clip;

#define REPORT_BEYOND 32 /* joints listed beyond training, at most */

typedef struct report {
    report_clip *clips;
    int32_t nclips;
    int32_t sweep_poses;
    double sweep_mean;
    sw_joint_reach beyond[REPORT_BEYOND]; /* sw_bake_beyond_training's, largest first */
    int32_t nbeyond, nbeyond_all;
} report;

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

/* Whether the held-out poses are random combined poses (no clip to hold out). */
static int heldout_random(const sw_bake_result *res) {
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
            int32_t label = s && heldout_random(res) ? -1 : i;
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

static char *report_json(const sw_bake_report_input *in, const report *r, int sheet) {
    const sw_bake_result *res = in->res;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddNumberToObject(j, "sinew_bake_report", SW_BAKE_REPORT_VERSION);
    cJSON_AddStringToObject(j, "source", in->source ? in->source : "");
    cJSON_AddItemToObject(j, "character", json_character(in));
    cJSON_AddItemToObject(j, "err_train", json_number(in->err_train));
    cJSON_AddItemToObject(j, "err_heldout", json_number(in->err_heldout));
    cJSON_AddNumberToObject(j, "proj_err_train", res->train_proj_error);
    cJSON_AddNumberToObject(j, "proj_err_heldout", res->heldout_proj_error);
    cJSON_AddItemToObject(j, "galerkin_err_train", json_number(res->train_galerkin_error));
    cJSON_AddItemToObject(j, "galerkin_err_heldout", json_number(res->heldout_galerkin_error));
    cJSON_AddNumberToObject(j, "cubature_fit", res->cubature_error_max);
    cJSON *eq = cJSON_AddObjectToObject(j, "equilibrium_force");
    cJSON_AddNumberToObject(eq, "poses", res->force_poses);
    cJSON_AddItemToObject(eq, "err_train_without",
                          res->model_train_error >= 0 ? json_number(res->model_train_error)
                                                      : cJSON_CreateNull());
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
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k) { /* the bake's table (bake.h) */
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", sw_bake_stages[k].name);
        cJSON_AddNumberToObject(o, "seconds", res->stage_seconds[k]);
        cJSON_AddItemToArray(st, o);
    }
    if (in->ch->render.nverts > 0) { /* the bake's log warns of vertices outside */
        cJSON *rd = cJSON_AddObjectToObject(j, "render");
        cJSON_AddNumberToObject(rd, "verts", in->ch->render.nverts);
        cJSON_AddNumberToObject(rd, "outside", res->render_outside);
        cJSON_AddNumberToObject(rd, "max_outside", res->render_max_outside);
    } else
        cJSON_AddNullToObject(j, "render");
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
    if (sheet)
        cJSON_AddStringToObject(j, "contact_sheet", SHEET_NAME);
    else
        cJSON_AddNullToObject(j, "contact_sheet");
    char *text = cJSON_Print(j);
    cJSON_Delete(j);
    return text;
}

/* s with &, <, >, " escaped for HTML text and attributes. */
static void html_text(FILE *f, const char *s) {
    for (; *s; ++s)
        switch (*s) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        default:
            fputc(*s, f);
        }
}

#define PLOT_W 420
#define PLOT_H 150
#define PAD 34

/* A line plot of y over x (n points; NaN points skipped) with y from 0 to ymax, the x axis
 * named xname; a red tick under every point whose mark is nonzero (NULL: none). */
static void svg_line(FILE *f, const char *title, const char *xname, const int32_t *x,
                     const double *y, const int32_t *mark, int32_t n, double ymax,
                     const char *colour) {
    fprintf(f, "<figure><figcaption>");
    html_text(f, title);
    fprintf(f, "</figcaption><svg width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">", PLOT_W,
            PLOT_H, PLOT_W, PLOT_H);
    int32_t xmin = n ? x[0] : 0, xmax = n ? x[n - 1] : 1;
    if (xmax <= xmin) xmax = xmin + 1;
    double sx = (PLOT_W - 2.0 * PAD) / (xmax - xmin), sy = (PLOT_H - 2.0 * PAD) / ymax;
    fprintf(f,
            "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"#888\"/>"
            "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"#888\"/>",
            PAD, PLOT_H - PAD, PLOT_W - PAD, PLOT_H - PAD, PAD, PAD, PAD, PLOT_H - PAD);
    fprintf(f,
            "<text x=\"2\" y=\"%d\" font-size=\"10\">%.2g</text><text x=\"2\" y=\"%d\" "
            "font-size=\"10\">0</text><text x=\"%d\" y=\"%d\" font-size=\"10\">%s %d</text>"
            "<text x=\"%d\" y=\"%d\" font-size=\"10\" text-anchor=\"end\">%d</text>",
            PAD + 4, ymax, PLOT_H - PAD, PAD, PLOT_H - PAD + 14, xname, xmin, PLOT_W - PAD,
            PLOT_H - PAD + 14, xmax);
    for (int32_t k = 0; mark && k < n; ++k)
        if (mark[k])
            fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#c00\"/>",
                    PAD + sx * (x[k] - xmin), PLOT_H - PAD + 2, PAD + sx * (x[k] - xmin),
                    PLOT_H - PAD + 6);
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", colour);
    for (int32_t k = 0; k < n; ++k)
        if (isfinite(y[k]))
            fprintf(f, "%.1f,%.1f ", PAD + sx * (x[k] - xmin),
                    PLOT_H - PAD - sy * fmin(y[k], ymax));
    fprintf(f, "\"/></svg></figure>\n");
}

/* A bar chart of v[0..n) labelled by index (or labels when not NULL). */
static void svg_bars(FILE *f, const char *title, const double *v, int32_t n,
                     const char *const *labels, const char *colour) {
    double vmax = 0;
    for (int32_t k = 0; k < n; ++k)
        vmax = fmax(vmax, isfinite(v[k]) ? v[k] : 0);
    if (!(vmax > 0)) vmax = 1;
    int w = PAD + (n > 0 ? n : 1) * 22 + PAD;
    w = w < PLOT_W ? PLOT_W : w;
    fprintf(f, "<figure><figcaption>");
    html_text(f, title);
    fprintf(f, "</figcaption><svg width=\"%d\" height=\"%d\">", w, PLOT_H);
    double sy = (PLOT_H - 2.0 * PAD) / vmax;
    for (int32_t k = 0; k < n; ++k) {
        double h = isfinite(v[k]) ? sy * v[k] : 0;
        fprintf(f,
                "<rect x=\"%d\" y=\"%.1f\" width=\"16\" height=\"%.1f\" fill=\"%s\"><title>%.4g"
                "</title></rect><text x=\"%d\" y=\"%d\" font-size=\"9\">",
                PAD + 22 * k, PLOT_H - PAD - h, h, colour, v[k], PAD + 22 * k, PLOT_H - PAD + 12);
        if (labels)
            html_text(f, labels[k]);
        else
            fprintf(f, "%d", k);
        fprintf(f, "</text><text x=\"%d\" y=\"%.1f\" font-size=\"8\">%.3g</text>", PAD + 22 * k,
                PLOT_H - PAD - h - 3, v[k]);
    }
    fprintf(f, "</svg></figure>\n");
}

static void html_summary(FILE *f, const sw_bake_report_input *in) {
    const sw_character *ch = in->ch;
    fprintf(f, "<h1>sinew bake report: ");
    html_text(f, in->source ? in->source : ch->name);
    fprintf(f, "</h1>\n<table>");
    sw_quality q;
    sw_tetmesh_quality(&ch->mesh, 0, &q);
    fprintf(f,
            "<tr><td>simulation mesh</td><td>%d tets, %d vertices, %d bones; %s; dihedral "
            "angles %.1f..%.1f degrees, %d sliver(s) under 5 degrees, %d inverted</td></tr>",
            ch->mesh.ntets, ch->mesh.nverts, ch->skel.nbones,
            !in->mesher ? "the character's own tet mesh"
            : !strcmp(in->mesher, "tetgen")
                ? "TetGen's mesh of the render surface"
                : "a lattice cut by the render surface's winding number",
            q.min_dihedral_deg, q.max_dihedral_deg, q.slivers, q.inverted);
    if (ch->render.nverts)
        fprintf(f, "<tr><td>render mesh</td><td>%d vertices, %d triangles</td></tr>",
                ch->render.nverts, ch->render.ntris);
    fprintf(f, "<tr><td>material</td><td>E %.4g, &nu; %.3g, density %.4g</td></tr>", ch->youngs,
            ch->poisson, ch->density);
    fprintf(f,
            "<tr><td>correction error</td><td>training %.4f, held-out <b>%.4f</b> (the share of "
            "the physics correction the runtime misses; 0 exact, 1 no better than "
            "skinning)</td></tr>",
            in->err_train, in->err_heldout);
    if (in->ref_solver && in->ref_hessian) {
        /* a joint range bounds random held-out poses only: clips need no bound */
        const char *bound = !heldout_random(in->res) ? ""
                            : ch->range.nframes > 0  ? "; random poses turn each joint within "
                                                       "its range (--joint-range)"
                                                     : "; random poses turn each joint within "
                                                       "90 degrees";
        fprintf(f,
                "<tr><td>reference</td><td>full-space solves by %s, %s element "
                "Hessians%s</td></tr>",
                in->ref_solver, in->ref_hessian, bound);
    }
    if (in->res->model_train_error >= 0)
        fprintf(f,
                "<tr><td>equilibrium force</td><td>at %d of %d training poses (each pose's "
                "projected solution made the runtime's equilibrium there); training error "
                "without it %.4f</td></tr>",
                in->res->force_poses, in->res->ntrain, in->res->model_train_error);
    fprintf(f, "<tr><td>interface springs</td><td>k = %.4g (%.3g E h)", in->res->spring_k,
            in->res->spring_eh > 0 ? in->res->spring_k / in->res->spring_eh : 0);
    for (int32_t k = 0; k < in->res->nspring_tried; ++k)
        fprintf(f, "%s%g E h: %.4f", k ? ", " : "; training error at ",
                in->res->spring_tried_mult[k], in->res->spring_tried_err[k]);
    fprintf(f, "</td></tr>");
    if (in->eval_train && in->eval_heldout)
        fprintf(f,
                "<tr><td>seams between domains</td><td>training %.4f, held-out %.4f of the "
                "correction; largest gap %.2e, %.2e of the rest diagonal</td></tr>",
                in->eval_train->seam, in->eval_heldout->seam, in->eval_train->seam_max,
                in->eval_heldout->seam_max);
    fprintf(f,
            "<tr><td>basis projection error</td><td>training %.4f, held-out %.4f</td></tr>"
            "<tr><td>the same in the linearised model's energy (Galerkin: what the step can "
            "reach)</td><td>training %.4f, held-out %.4f</td></tr>"
            "<tr><td>worst cubature fit</td><td>%.4f</td></tr><tr><td>failed steps</td><td>%d"
            "</td></tr><tr><td>bake time</td><td>%.1f s (+ %.1f s evaluation)</td></tr></table>\n",
            in->res->train_proj_error, in->res->heldout_proj_error, in->res->train_galerkin_error,
            in->res->heldout_galerkin_error, in->res->cubature_error_max, in->failed_steps,
            in->bake_seconds, in->eval_seconds);
}

static void html_clips(FILE *f, const report *r) {
    double ymax = 0.05;
    for (int32_t i = 0; i < r->nclips; ++i)
        for (int32_t k = 0; k < r->clips[i].n; ++k)
            if (isfinite(r->clips[i].error[k])) ymax = fmax(ymax, r->clips[i].error[k]);
    fprintf(f,
            "<h2>Correction error of every clip frame</h2><p>Training clips in blue, "
            "held-out clips (never trained on) in orange; same scale. A red tick marks a "
            "frame that bends a joint beyond every training pose (more than %.2f times "
            "and %.0f degrees further), as the runtime flags it "
            "(SINEW_STEP_BEYOND_TRAINING).</p><div class=\"row\">",
            SW_BEYOND_RATIO, SW_BEYOND_DEG);
    for (int32_t i = 0; i < r->nclips; ++i) {
        const report_clip *c = &r->clips[i];
        char title[200];
        snprintf(title, sizeof title, "%s (%s, %d frames, %d beyond training)", c->name,
                 c->heldout ? "held out" : "training", c->n, c->nbeyond);
        svg_line(f, title, "frame", c->frame, c->error, c->beyond, c->n, ymax,
                 c->heldout ? "#d2691e" : "#1f77b4");
    }
    fprintf(f,
            "</div><p>Joint sweeps and other training poses of no clip: %d, mean error "
            "%.4f.</p>\n",
            r->sweep_poses, r->sweep_mean);
}

static int html_domains(FILE *f, const sw_bake_report_input *in) {
    const sw_blob_view *v = sw_blob_get_view(in->blob);
    int32_t nd = v->ndomains;
    double *a = malloc(sizeof(double) * 3 * ((size_t)nd + 1));
    if (!a) return 0;
    for (int32_t d = 0; d < nd; ++d) {
        a[d] = v->domains[d].rank;
        a[nd + d] = in->res->basis_energy ? in->res->basis_energy[d] : NAN;
        a[2 * nd + d] = v->domains[d].cub_count;
    }
    fprintf(f, "<h2>Domains (one per bone that owns flesh)</h2><div class=\"row\">");
    svg_bars(f, "basis rank per domain", a, nd, NULL, "#2ca02c");
    svg_bars(f, "PCA energy kept per domain", a + nd, nd, NULL, "#9467bd");
    svg_bars(f, "cubature tets per domain", a + 2 * nd, nd, NULL, "#8c564b");
    fprintf(f, "</div>\n");
    free(a);
    return 1;
}

/* A bone in a table cell: its index and its name in the file, when it has one. */
static void html_bone(FILE *f, const sw_character *ch, int32_t bone) {
    fprintf(f, "<td>%d ", bone);
    if (ch->bone_names) html_text(f, ch->bone_names[bone]);
    fprintf(f, "</td>");
}

/* Where the error is: the bones whose vertices hold most of it, training and held-out. */
static void html_regions(FILE *f, const sw_bake_report_input *in) {
    if (!in->eval_train || !in->eval_heldout) return;
    fprintf(f, "<h2>Where the error is</h2><p>The vertices split by their strongest bone: "
               "the bones whose vertices hold the largest share of the squared error, with "
               "their share of the squared physics correction. A share of the error far above "
               "the share of the correction is a region the subspace misses; both near 1 is a "
               "region that holds all the physics, e.g. flesh too loosely held by its bone."
               "</p><table><tr><th>poses</th><th>bone</th><th>share of the error</th>"
               "<th>share of the correction</th></tr>\n");
    for (int set = 0; set < 2; ++set) {
        const sw_eval_result *e = set ? in->eval_heldout : in->eval_train;
        for (int32_t k = 0; k < e->nregions; ++k) {
            fprintf(f, "<tr><td>%s</td>", set ? "held-out" : "training");
            html_bone(f, in->ch, e->region_bone[k]);
            fprintf(f, "<td>%.3f</td><td>%.3f</td></tr>\n", e->region_err[k], e->region_corr[k]);
        }
    }
    fprintf(f, "</table>\n");
}

/* The held-out error in each self-contact mode an instance can take. */
static void html_modes(FILE *f, const sw_bake_report_input *in) {
    if (!in->mode_err_heldout) return;
    fprintf(f, "<h2>Held-out error by self-contact mode</h2><p>The same held-out poses stepped "
               "with each self-contact mode of <code>sinew_instance_def.self_contact</code>: "
               "pose-space applies the contact of the nearest training poses (cheapest; suits "
               "motion like the training clips), pose-pairs that of the nearest sample of "
               "each pair of domains and detects the rest, exhaustive detects every contact "
               "(suits combinations of joints no training pose holds).</p><table><tr>");
    for (int k = 0; k < SW_BAKE_MODES; ++k)
        fprintf(f, "<th>%s</th>", sw_self_contact_names[k]);
    fprintf(f, "</tr><tr>");
    for (int k = 0; k < SW_BAKE_MODES; ++k)
        if (isfinite(in->mode_err_heldout[k]))
            fprintf(f, "<td>%.4f</td>", in->mode_err_heldout[k]);
        else
            fprintf(f, "<td>&ndash;</td>");
    fprintf(f, "</tr></table>\n");
}

/* How well the held-out references are defined: full-space solves from other starts. */
static void html_spread(FILE *f, const sw_bake_report_input *in) {
    const sw_bake_spread *s = in->spread;
    if (!s || s->poses < 1) return;
    fprintf(f,
            "<h2>How well the held-out reference is defined</h2><p>The reference solved each "
            "held-out pose from the pose before it. At %d of them the full-space simulator "
            "solved the pose again from other starts; each is measured as the runtime's "
            "error is (the share of the correction). Where the solves from plain skinning and "
            "from the runtime's state land near the reference, it is the one equilibrium of "
            "the pose and the held-out error is the runtime's alone; where they land far "
            "from it the flesh rests in more than one, and the error also says which one the "
            "runtime found.</p><table>"
            "<tr><td>the runtime at these poses</td><td>%.4f</td></tr>"
            "<tr><td>the simulator from plain skinning</td><td>%.4f</td></tr>"
            "<tr><td>the simulator from the reference (its own precision)</td><td>%.4f</td></tr>"
            "<tr><td>the simulator from the runtime's state</td><td>%.4f (it moved the "
            "runtime's state %.4f)</td></tr></table><p>%d of the solves ended unconverged, "
            "%d poses were left out. Per held-out pose, same scale:</p><div class=\"row\">\n",
            s->poses, s->runtime, s->from_skin, s->from_reference, s->polished, s->polish_move,
            s->unconverged, s->failed);
    int32_t *x = malloc(sizeof(int32_t) * (size_t)s->poses);
    double *y = malloc(sizeof(double) * 4 * (size_t)s->poses), ymax = 0.05;
    if (x && y) {
        for (int32_t k = 0; k < s->poses; ++k) {
            const sw_bake_spread_pose *q = &s->per_pose[k];
            const double v[4] = {q->runtime, q->from_skin, q->from_reference, q->polished};
            x[k] = q->heldout;
            for (int i = 0; i < 4; ++i) {
                y[(size_t)i * s->poses + k] = v[i];
                if (isfinite(v[i])) ymax = fmax(ymax, v[i]);
            }
        }
        static const char *const title[4] = {"the runtime", "the simulator from plain skinning",
                                             "the simulator from the reference",
                                             "the simulator from the runtime's state"};
        static const char *const colour[4] = {"#d2691e", "#7f7f7f", "#2ca02c", "#1f77b4"};
        for (int i = 0; i < 4; ++i)
            svg_line(f, title[i], "held-out pose", x, y + (size_t)i * s->poses, NULL, s->poses,
                     ymax, colour[i]);
    }
    fprintf(f, "</div>\n");
    free(x);
    free(y);
}

/* The joints the held-out poses bend further than any training pose: where the basis
 * extrapolates, and what training motion would cover. */
static void html_beyond(FILE *f, const sw_bake_report_input *in, const report *r) {
    if (r->nbeyond < 1) return;
    fprintf(f,
            "<h2>Held-out motion beyond training</h2><p>%d joint%s turn%s further in the "
            "held-out poses than in any training pose (more than %.2f times and %.0f degrees "
            "beyond). The subspace learnt the flesh of the bends it was shown: there it "
            "extrapolates, and the held-out error says how well. Training clips that reach "
            "these bends cover them.</p><table><tr><th>bone</th><th>largest bend held-out"
            "</th><th>largest bend in training</th></tr>\n",
            r->nbeyond_all, r->nbeyond_all == 1 ? "" : "s", r->nbeyond_all == 1 ? "s" : "",
            SW_BEYOND_RATIO, SW_BEYOND_DEG);
    for (int32_t k = 0; k < r->nbeyond; ++k) {
        fprintf(f, "<tr>");
        html_bone(f, in->ch, r->beyond[k].bone);
        fprintf(f, "<td>%.1f&deg;</td><td>%.1f&deg;</td></tr>\n", r->beyond[k].heldout_deg,
                r->beyond[k].train_deg);
    }
    fprintf(f, "</table>\n");
}

/* The adaptive loop's rounds: a table and the held-out error per round. */
static void html_adaptive(FILE *f, const sw_adaptive_report *a) {
    if (!a || a->nrounds < 1) return;
    fprintf(f, "<h2>Adaptive training rounds</h2><p>Each round adds the random combined poses "
               "the blob steps worst to the training poses and bakes again; the picked poses' "
               "error is the blob's own on them, checked against the reference the round "
               "after.</p><table><tr><th>round</th><th>training poses (added)</th><th>rank</th>"
               "<th>error train / held-out</th><th>projection train / held-out</th>"
               "<th>picked poses' error</th><th>seconds</th></tr>");
    int32_t x[SW_ADAPTIVE_MAX_ROUNDS + 1];
    double y[SW_ADAPTIVE_MAX_ROUNDS + 1], ymax = 0.05;
    for (int32_t k = 0; k < a->nrounds; ++k) {
        const sw_adaptive_round *rd = &a->round[k];
        fprintf(f,
                "<tr><td>%d</td><td>%d (%d)</td><td>%d</td><td>%.4f / %.4f</td><td>%.4f / "
                "%.4f</td><td>",
                k, rd->ntrain, rd->added, rd->rank_total, rd->err_train, rd->err_heldout,
                rd->proj_train, rd->proj_heldout);
        if (rd->picks_error >= 0)
            fprintf(f, "%.4f", rd->picks_error);
        else
            fprintf(f, "&ndash;");
        fprintf(f, "</td><td>%.1f</td></tr>", rd->seconds);
        x[k] = k;
        y[k] = rd->err_heldout;
        if (isfinite(y[k])) ymax = fmax(ymax, y[k]);
    }
    fprintf(f, "</table>");
    svg_line(f, "held-out correction error per round", "round", x, y, NULL, a->nrounds, ymax,
             "#d2691e");
}

static int write_html(const char *path, const sw_bake_report_input *in, const report *r,
                      int sheet) {
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>sinew bake report"
               "</title><style>body{font-family:sans-serif;margin:2em;max-width:1400px}"
               "td{padding:2px 12px}figure{display:inline-block;margin:6px}"
               "figcaption{font-size:12px}.row{display:flex;flex-wrap:wrap}</style></head>"
               "<body>\n");
    html_summary(f, in);
    html_clips(f, r);
    html_regions(f, in);
    html_modes(f, in);
    html_spread(f, in);
    html_beyond(f, in, r);
    int ok = html_domains(f, in);
    html_adaptive(f, in->adaptive);
    fprintf(f, "<h2>Stage times</h2>");
    const char *stage_names[SW_BAKE_NSTAGES]; /* the bake's table (bake.h) */
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k)
        stage_names[k] = sw_bake_stages[k].name;
    svg_bars(f, "seconds per stage", in->res->stage_seconds, SW_BAKE_NSTAGES, stage_names,
             "#7f7f7f");
    if (sheet)
        fprintf(f, "<h2>Held-out frames</h2><p>Each row one held-out frame: the runtime, the "
                   "full-space reference, plain skinning.</p><img src=\"" SHEET_NAME
                   "\" alt=\"contact sheet\" style=\"max-width:100%%\">\n");
    fprintf(f, "</body></html>\n");
    return fclose(f) == 0 && ok;
}

sinew_result sw_bake_report_write(const char *dir, const sw_bake_report_input *in, sw_error *err) {
    if (!dir || !in || !in->ch || !in->res || !in->blob || !in->train_frames || !in->heldout_frames)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "report: NULL argument");
    if (!sw_tool_make_dirs(dir))
        return sw_error_set(err, SINEW_ERROR_IO, "report: cannot create the folder %s: %s", dir,
                            strerror(errno ? errno : EACCES));
    char path[4096];
    int sheet = 0;
    if (in->contact_sheet && in->res->nheldout > 0) {
        snprintf(path, sizeof path, "%s/%s", dir, SHEET_NAME);
        sinew_result r = sw_bake_report_sheet(path, in->ch, in->res, in->blob, 4, err);
        if (r != SINEW_OK) return r;
        sheet = 1;
    }
    report r;
    memset(&r, 0, sizeof r);
    if (!gather(in, &r)) {
        report_free(&r);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "report: out of memory");
    }
    char *json = report_json(in, &r, sheet);
    snprintf(path, sizeof path, "%s/report.json", dir);
    FILE *f = json ? fopen(path, "w") : NULL;
    int ok = f && fputs(json, f) >= 0 && fputc('\n', f) != EOF;
    if (f) ok = fclose(f) == 0 && ok;
    free(json);
    if (ok) {
        snprintf(path, sizeof path, "%s/report.html", dir);
        ok = write_html(path, in, &r, sheet);
    }
    report_free(&r);
    if (!ok) return sw_error_set(err, SINEW_ERROR_IO, "report: cannot write %s", path);
    return SINEW_OK;
}
