/* The bake report's page (bake_report_internal.h): the verdict first, then the contact
 * sheet, the error of every clip frame, where the error is, and the details. The model's
 * terms are said in plain words, each with its technical name in a tooltip and in the
 * glossary at the end. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_report_internal.h"

#include "character_paint.h"
#include "blob_load.h"
#include "mesh_io.h"
#include "pose_space.h"

/* A plain-words row label with the technical term as its tooltip. */
static void html_term(FILE *f, const char *plain, const char *term) {
    fprintf(f, "<tr><td><span class=\"term\" title=\"");
    html_text(f, term);
    fprintf(f, "\">");
    html_text(f, plain);
    fprintf(f, "</span></td>");
}

/* The character: its meshes and material. */
static void html_character(FILE *f, const sw_bake_report_input *in) {
    const sw_character *ch = in->ch;
    sw_quality q;
    sw_tetmesh_quality(&ch->mesh, 0, &q);
    fprintf(f, "<h2>The bake in numbers</h2><table>");
    html_term(f, "simulation mesh",
              "the tetrahedral mesh the full simulation and the runtime "
              "solve on");
    fprintf(f,
            "<td>%d tets, %d vertices, %d bones; %s; dihedral angles %.1f..%.1f degrees, %d "
            "sliver(s) under 5 degrees, %d inverted</td></tr>",
            ch->mesh.ntets, ch->mesh.nverts, ch->skel.nbones,
            !in->mesher ? "the character's own tet mesh"
            : !strcmp(in->mesher, "tetgen")
                ? "TetGen's mesh of the render surface"
                : "a lattice cut by the render surface's winding number",
            q.min_dihedral_deg, q.max_dihedral_deg, q.slivers, q.inverted);
    if (ch->render.nverts)
        fprintf(f, "<tr><td>render mesh</td><td>%d vertices, %d triangles</td></tr>",
                ch->render.nverts, ch->render.ntris);
    html_term(f, "material",
              "Young's modulus E (stiffness), Poisson's ratio (volume kept), "
              "density");
    fprintf(f, "<td>stiffness E %.4g, &nu; %.3g, density %.4g</td></tr>", ch->youngs, ch->poisson,
            ch->density);
    if (ch->tet_stiffness) {
        char line[160];
        sw_character_paint_summary(ch, line, sizeof line);
        html_term(f, "painted material",
                  "the artist's stiffness multipliers carried onto the simulation tets "
                  "(--stiffness-map, a glTF _SINEW_STIFFNESS attribute)");
        fprintf(f, "<td>%s<br><img src=\"%s\" alt=\"painted stiffness\"></td></tr>", line,
                SW_BAKE_REPORT_PAINT_NAME);
    }
    html_term(f, "error (share of the flesh movement missed)",
              "correction error: the share of the physics correction (the full simulation "
              "minus plain skinning) the runtime misses");
    fprintf(f,
            "<td>training %.4f, held-out <b>%.4f</b> (0: the full simulation; 1: no better "
            "than plain skinning)</td></tr>",
            in->err_train, in->err_heldout);
    if (in->ref_solver && in->ref_hessian) {
        /* a joint range bounds random held-out poses only: clips need no bound */
        const char *bound = !report_heldout_random(in->res) ? ""
                            : ch->range.nframes > 0 ? "; random poses turn each joint within "
                                                      "its range (--joint-range)"
                                                    : "; random poses turn each joint within "
                                                      "90 degrees";
        html_term(f, "reference (the full simulation)",
                  "the full-space solves every error is measured against");
        fprintf(f, "<td>full-space solves by %s, %s element Hessians%s</td></tr>", in->ref_solver,
                in->ref_hessian, bound);
    }
}

/* How the runtime's model was built, each figure in plain words. */
static void html_model(FILE *f, const sw_bake_report_input *in) {
    const sw_bake_result *res = in->res;
    if (res->model_train_error >= 0) {
        html_term(f, "pose correction",
                  "equilibrium force: each training pose carries the "
                  "force that makes its simulated shape the runtime's "
                  "rest there");
        fprintf(f, "<td>at %d of %d training poses; training error without it %.4f</td></tr>",
                res->force_poses, res->ntrain, res->model_train_error);
    }
    if (res->view.lod_rank > 0) {
        html_term(f, "levels of detail",
                  "the held-out error on the surface of each level a game can "
                  "pick per character (sinew_instance_set_lod)");
        if (isnan(res->lod_heldout[0])) /* no held-out poses, or a level failed a step */
            fprintf(f, "<td>not measured; pose-space level of %d modes</td></tr>",
                    res->view.lod_rank);
        else
            fprintf(f,
                    "<td>full %.4f, reduced %.4f, pose-space %.4f (%d modes, no solve: what a "
                    "learned deformer costs)</td></tr>",
                    res->lod_heldout[0], res->lod_heldout[1], res->lod_heldout[2],
                    res->view.lod_rank);
    }
    if (in->memory) {
        const sw_blob_memory *m = in->memory;
        html_term(f, "memory",
                  "the blob (shared by every instance of the character) by what it holds, and "
                  "what each instance reserves; a crowd steps its instances in one shared "
                  "workspace a thread (sinew_instance_def.shared_workspace)");
        fprintf(f, "<td>blob %.2f MB (", (double)m->blob / 1e6);
        for (int k = 0; k < SW_NPARTS; ++k)
            fprintf(f, "%s%s %.2f", k ? ", " : "", sw_blob_part_names[k], (double)m->part[k] / 1e6);
        fprintf(f, "); an instance %.2f MB, or %.2f MB in a shared workspace of %.2f MB</td></tr>",
                (double)m->instance / 1e6, (double)m->instance_shared / 1e6,
                (double)m->workspace / 1e6);
    }
    html_term(f, "glue between body parts",
              "interface springs: the stiffness holding the "
              "domains' shared vertices together");
    fprintf(f, "<td>k = %.4g (%.3g E h)", res->spring_k,
            res->spring_eh > 0 ? res->spring_k / res->spring_eh : 0);
    for (int32_t k = 0; k < res->nspring_tried; ++k)
        fprintf(f, "%s%g E h: %.4f", k ? ", " : "; training error at ", res->spring_tried_mult[k],
                res->spring_tried_err[k]);
    fprintf(f, "</td></tr>");
    if (in->eval_train && in->eval_heldout) {
        html_term(f, "seams between body parts",
                  "seams between domains: how far apart the "
                  "domains' copies of a vertex are");
        fprintf(f,
                "<td>training %.4f, held-out %.4f of the correction; largest gap %.2e, %.2e of "
                "the rest diagonal</td></tr>",
                in->eval_train->seam, in->eval_heldout->seam, in->eval_train->seam_max,
                in->eval_heldout->seam_max);
    }
    html_term(f, "best the learnt flesh shapes can do",
              "basis projection error: the closest the basis comes to the reference");
    fprintf(f, "<td>training %.4f, held-out %.4f", res->train_proj_error, res->heldout_proj_error);
    if (res->rank_trained < res->view.rank_total) /* what the modes from physics add */
        fprintf(f, " (held-out %.4f with the %d trained modes alone, without the %d from physics)",
                res->heldout_proj_error_trained, res->rank_trained,
                res->view.rank_total - res->rank_trained);
    fprintf(f, "</td></tr>");
    html_term(f, "best the runtime's solver can reach with them",
              "Galerkin projection error: the same, measured in the linearised model's energy, "
              "which is what the runtime's step minimises");
    fprintf(f, "<td>training %.4f, held-out %.4f</td></tr>", res->train_galerkin_error,
            res->heldout_galerkin_error);
    html_term(f, "force sampling, worst fit",
              "cubature fit: how well the few sample tets "
              "reproduce the whole mesh's forces (0 exact)");
    fprintf(f, "<td>%.4f</td></tr>", res->cubature_error_max);
    fprintf(f,
            "<tr><td>failed steps</td><td>%d</td></tr><tr><td>bake time</td><td>%.1f s (+ "
            "%.1f s measuring)</td></tr></table>\n",
            in->failed_steps, in->bake_seconds, in->eval_seconds);
}

/* The error of every clip frame, each clip a plot on one scale with the target line. */
static void html_clips(FILE *f, const report *r) {
    double ymax = 1.25 * r->verdict.target;
    for (int32_t i = 0; i < r->nclips; ++i)
        for (int32_t k = 0; k < r->clips[i].n; ++k)
            if (isfinite(r->clips[i].error[k])) ymax = fmax(ymax, r->clips[i].error[k]);
    fprintf(f,
            "<h2>Error of every clip frame</h2><p>How much of the flesh movement the runtime "
            "misses at each frame (0: the full simulation, 1: no better than skinning). "
            "Training clips in blue, held-out clips (never trained on) in orange, all on one "
            "scale; the dashed red line is the target. A red tick under a frame marks a pose "
            "that bends a joint beyond every training pose (more than %.2f times and %.0f "
            "degrees further), which the runtime flags (SINEW_STEP_BEYOND_TRAINING).</p>"
            "<div class=\"row\">",
            SW_BEYOND_RATIO, SW_BEYOND_DEG);
    char label[64];
    snprintf(label, sizeof label, "target %.2f", r->verdict.target);
    for (int32_t i = 0; i < r->nclips; ++i) {
        const report_clip *c = &r->clips[i];
        char title[200];
        snprintf(title, sizeof title, "%s (%s, %d frames, %d beyond training)", c->name,
                 c->heldout ? "held out" : "training", c->n, c->nbeyond);
        plot_axes ax = {title, "clip frame",      "error (share missed)",
                        ymax,  r->verdict.target, label};
        svg_line(f, &ax, c->frame, c->error, c->beyond, c->n, c->heldout ? "#d2691e" : "#1f77b4");
    }
    fprintf(f,
            "</div><p>Joint sweeps and other training poses of no clip: %d, mean error "
            "%.4f.</p>\n",
            r->sweep_poses, r->sweep_mean);
}

/* The domains (body parts, one per bone that owns flesh): how many flesh shapes each
 * keeps, how much of the training motion they hold, how many sample tets feed forces. */
static int html_domains(FILE *f, const sw_bake_report_input *in) {
    const sw_blob_view *v = sw_blob_get_view(in->blob);
    int32_t nd = v->ndomains;
    double *a = malloc(sizeof(double) * 3 * ((size_t)nd + 1));
    char(*name)[24] = malloc(sizeof *name * ((size_t)nd + 1));
    const char **label = malloc(sizeof *label * ((size_t)nd + 1));
    if (!a || !name || !label) {
        free(a);
        free(name);
        free(label);
        return 0;
    }
    for (int32_t d = 0; d < nd; ++d) {
        a[d] = v->domains[d].rank;
        a[nd + d] = in->res->basis_energy ? in->res->basis_energy[d] : NAN;
        a[2 * nd + d] = v->domains[d].cub_count;
        report_bone_name(in->ch, v->domains[d].bone, name[d], sizeof name[d]);
        label[d] = name[d];
    }
    fprintf(f, "<h2>Body parts</h2><p>The runtime splits the flesh into body parts "
               "(<span class=\"term\" title=\"domains\">domains</span>, one per bone that "
               "owns flesh), each moved by a few learnt flesh shapes (<span class=\"term\" "
               "title=\"the basis rank: PCA modes of the training poses\">basis modes</span>) "
               "whose forces come from a few sample tets (<span class=\"term\" "
               "title=\"cubature\">cubature</span>). More shapes follow more motion and cost "
               "more per step.</p><div class=\"row\">");
    const plot_axes ax[3] = {
        {"flesh shapes per body part", "body part (bone)", "shapes (basis rank)", 1, NAN, NULL},
        {"share of the training motion the shapes hold", "body part (bone)",
         "share kept (PCA energy)", 1, NAN, NULL},
        {"sample tets per body part", "body part (bone)", "tets (cubature)", 1, NAN, NULL}};
    static const char *const colour[3] = {"#2ca02c", "#9467bd", "#8c564b"};
    for (int i = 0; i < 3; ++i)
        svg_bars(f, &ax[i], a + (size_t)i * nd, nd, label, colour[i]);
    fprintf(f, "</div>\n");
    free(a);
    free(name);
    free(label);
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
        for (int i = 0; i < 4; ++i) {
            plot_axes ax = {title[i], "held-out pose", "error (share missed)", ymax, NAN, NULL};
            svg_line(f, &ax, x, y + (size_t)i * s->poses, NULL, s->poses, colour[i]);
        }
    }
    fprintf(f, "</div>\n");
    free(x);
    free(y);
}

/* The joints the held-out poses bend further than any training pose: where the basis
 * extrapolates, and what training motion would cover. */
static void html_beyond(FILE *f, const sw_bake_report_input *in, const report *r) {
    if (r->nbeyond < 1) return;
    fprintf(
        f,
        "<h2>Held-out motion beyond training</h2><p>%d joint%s turn%s further in the "
        "held-out poses than in any training pose (more than %.2f times and %.0f degrees "
        "beyond). The runtime learnt the flesh of the bends it was shown: there it "
        "has to guess (extrapolate), and the held-out error says how well. Training clips "
        "that reach these bends cover them.</p><table><tr><th>bone</th><th>largest bend held-out"
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
static void html_adaptive(FILE *f, const sw_adaptive_report *a, double target) {
    if (!a || a->nrounds < 1) return;
    fprintf(f, "<h2>Adaptive training rounds</h2><p>Each round adds the random combined poses "
               "the blob steps worst to the training poses and bakes again; the picked poses' "
               "error is the blob's own on them, checked against the reference the round "
               "after.</p><table><tr><th>round</th><th>training poses (added)</th><th>rank</th>"
               "<th>error train / held-out</th><th>projection train / held-out</th>"
               "<th>picked poses' error</th><th>seconds</th></tr>");
    int32_t x[SW_ADAPTIVE_MAX_ROUNDS + 1];
    double y[SW_ADAPTIVE_MAX_ROUNDS + 1], ymax = 1.25 * target;
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
    plot_axes ax = {
        "held-out error per round", "round", "error (share missed)", ymax, target, "target"};
    svg_line(f, &ax, x, y, NULL, a->nrounds, "#d2691e");
}

/* The stage times as a horizontal bar chart, read through report_stage_times. */
static void html_stages(FILE *f, const sw_bake_result *res) {
    const char *names[REPORT_MAX_STAGES], *tips[REPORT_MAX_STAGES];
    double seconds[REPORT_MAX_STAGES];
    int32_t n = report_stage_times(res, names, seconds);
    /* what each stage does, by name, for the tooltips (a stage not listed shows its name) */
    static const char *const known[][2] = {
        {"prepare", "read the character, build its weights and masses"},
        {"embed", "place the render mesh in the simulation mesh's tets"},
        {"domains", "split the flesh into body parts, one per bone"},
        {"poses", "choose the training and held-out poses"},
        {"simulate", "solve the full simulation at every training and held-out pose"},
        {"basis", "learn each body part's flesh shapes from the solutions (PCA)"},
        {"cubature", "pick the sample tets whose forces stand for the whole mesh"},
        {"contacts", "collect the training poses' self-contacts"},
        {"reduce", "precompute the runtime's small matrices"},
        {"render", "carry the render mesh's embedding into the blob"},
        {"cond", "measure the tet mesh's conditioning for the blob"},
        {"pairs", "per pair of body parts, the contact samples"},
        {"springs", "choose the glue's stiffness between body parts"},
        {"galerkin", "measure the best the runtime's solver can reach"},
        {"equilibrium", "the pose correction of every training pose"}};
    double total = 0;
    for (int32_t k = 0; k < n; ++k) {
        tips[k] = NULL;
        for (size_t i = 0; i < sizeof known / sizeof known[0]; ++i)
            if (!strcmp(names[k], known[i][0])) tips[k] = known[i][1];
        total += isfinite(seconds[k]) ? seconds[k] : 0;
    }
    char title[96];
    snprintf(title, sizeof title,
             "seconds per stage, %.1f s in all (hover a stage for what it does)", total);
    fprintf(f, "<h2>Where the bake's time went</h2>");
    svg_hbars(f, title, seconds, n, names, tips, "s", "#7f7f7f");
}

/* The contact sheet as a table: named columns, numbered frames, each tile with its
 * largest distance from the reference, and the colour legend. */
static void html_sheet(FILE *f, const sw_bake_report_input *in, const report *r) {
    const sw_bake_report_sheet_info *s = &r->sheet_info;
    const sw_bake_result *res = in->res;
    static const char *const head[SW_SHEET_COLS] = {"reference (full simulation)",
                                                    "sinew (the runtime)", "plain skinning"};
    fprintf(f, "<h2>Held-out frames</h2><p>Frames the bake never trained on. Each surface is "
               "coloured by how far it sits from the full simulation (the reference, left): "
               "pale where it matches, red where it parts. The sinew column should look like "
               "the reference; plain skinning shows what the physics adds. The whole sheet is "
               "in <a href=\"" SHEET_NAME "\">one image</a>.</p>");
    html_ramp_legend(f, s->scale, s->size);
    fprintf(f, "<table class=\"sheet\"><tr><th></th>");
    for (int c = 0; c < SW_SHEET_COLS; ++c)
        fprintf(f, "<th>%s</th>", head[c]);
    fprintf(f, "</tr>\n");
    for (int32_t row = 0; row < s->rows; ++row) {
        int32_t k = s->pose[row], clip = res->heldout_clip[k];
        fprintf(f, "<tr><th class=\"frame\">frame %d", res->heldout_frame[k]);
        if (clip >= 0 && in->heldout_names && clip < in->nheldout_names) {
            fprintf(f, "<br>of ");
            html_text(f, in->heldout_names[clip]);
        } else if (clip < 0) {
            fprintf(f, "<br>(random pose %d)", k);
        } else {
            fprintf(f, "<br>of the held-out part");
        }
        fprintf(f, "</th>");
        for (int c = 0; c < SW_SHEET_COLS; ++c) {
            char name[64];
            sw_bake_report_tile_name(name, sizeof name, row, c);
            fprintf(f, "<td><img src=\"%s\" alt=\"%s, frame %d\"><br><span class=\"small\">", name,
                    head[c], res->heldout_frame[k]);
            if (c == SW_SHEET_REFERENCE)
                fprintf(f, "the reference itself");
            else
                fprintf(f, "largest distance %.3g (%.2g%%), mean %.3g", s->max_dist[row][c],
                        s->size > 0 ? 100 * s->max_dist[row][c] / s->size : 0,
                        s->mean_dist[row][c]);
            fprintf(f, "</span></td>");
        }
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table>\n");
}

/* The model's terms in plain words. */
static void html_glossary(FILE *f) {
    static const char *const term[][2] = {
        {"held-out motion", "clips or poses the bake never trained on; how the runtime does on "
                            "them is how it will do on new animation"},
        {"error (correction error)",
         "the share of the flesh movement the full simulation adds to skinning (the physics "
         "correction) that the runtime misses: 0 matches the simulation, 1 is no better than "
         "plain skinning"},
        {"reference", "the full simulation of the whole mesh at each pose: slow, exact, the "
                      "yardstick"},
        {"flesh shapes (basis, rank)", "the few shapes per body part the runtime moves the "
                                       "flesh with, learnt from the training poses (PCA)"},
        {"best the runtime's solver can reach (Galerkin error)",
         "the error left when the runtime's solver settles with these flesh shapes; the basis "
         "projection error is the closest the shapes themselves come"},
        {"sample tets (cubature)", "the few tets whose forces stand for the whole mesh's"},
        {"body parts (domains)", "the flesh split per bone, each with its own shapes, glued by "
                                 "interface springs"},
        {"beyond training", "a joint bent further than any training pose bent it: the runtime "
                            "extrapolates there and flags the frame"}};
    fprintf(f, "<h2>Glossary</h2><dl>");
    for (size_t i = 0; i < sizeof term / sizeof term[0]; ++i)
        fprintf(f, "<dt>%s</dt><dd>%s</dd>", term[i][0], term[i][1]);
    fprintf(f, "</dl>\n");
}

#define STYLE                                                                                      \
    "body{font-family:sans-serif;margin:2em;max-width:1400px}td{padding:2px 12px}"                 \
    "figure{display:inline-block;margin:6px}figcaption{font-size:12px}"                            \
    ".row{display:flex;flex-wrap:wrap}.small{font-size:12px;color:#555}"                           \
    ".term{border-bottom:1px dotted #888;cursor:help}"                                             \
    ".verdict{display:flex;gap:1em;padding:1em;border-radius:6px;margin-bottom:1.5em}"             \
    ".verdict .head{font-size:18px;font-weight:bold;margin-top:0}"                                 \
    ".badge{font-size:22px;font-weight:bold;padding:.4em .8em;border-radius:4px;"                  \
    "color:#fff;align-self:flex-start}.pass{background:#e8f5e9}.pass .badge{background:#2e7d32}"   \
    ".miss{background:#fdecea}.miss .badge{background:#c62828}"                                    \
    ".unknown{background:#eee}.unknown .badge{background:#777}"                                    \
    ".sheet td,.sheet th{padding:2px;text-align:center;vertical-align:top}"                        \
    ".sheet th.frame{text-align:right;vertical-align:middle;padding-right:8px}"                    \
    ".legend{margin:.5em 0 1em;width:640px;font-size:12px}.ramp{height:14px}"                      \
    ".ticks{display:flex;justify-content:space-between}dt{font-weight:bold}"

int report_write_html(const char *path, const sw_bake_report_input *in, const report *r) {
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>sinew bake report"
               "</title><style>" STYLE "</style></head><body>\n<h1>sinew bake report: ");
    html_text(f, in->source ? in->source : in->ch->name);
    fprintf(f, "</h1>\n");
    html_verdict(f, in, r);
    if (r->sheet) html_sheet(f, in, r);
    html_clips(f, r);
    html_beyond(f, in, r);
    html_regions(f, in);
    html_character(f, in);
    html_model(f, in);
    html_modes(f, in);
    html_spread(f, in);
    int ok = html_domains(f, in);
    html_adaptive(f, in->adaptive, r->verdict.target);
    html_stages(f, in->res);
    html_glossary(f);
    fprintf(f, "</body></html>\n");
    return fclose(f) == 0 && ok;
}
