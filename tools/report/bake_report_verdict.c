/* The bake report's verdict (bake_report_internal.h): the first thing an artist reads.
 * The held-out error (the share of the physics correction the runtime misses on motion it
 * never trained on) against a target, pass or miss, and on a miss what motion to add and
 * for which joints. Joints the held-out motion bends further than any training pose come
 * first: there the learnt shapes extrapolate, and motion that reaches those bends is what
 * covers them. Without such joints the held-out motion combines bends the training never
 * showed together, and the bones whose flesh holds the error say which. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bake_report_internal.h"

/* appends to buf (n bytes) as snprintf does, never past its end */
#define APPEND(buf, ...)                                                                           \
    do {                                                                                           \
        size_t used_ = strlen(buf);                                                                \
        if (used_ < sizeof(buf)) snprintf((buf) + used_, sizeof(buf) - used_, __VA_ARGS__);        \
    } while (0)

/* The joints to add motion for: those beyond training, else the bones with the error. */
static void pick_joints(const sw_bake_report_input *in, report *r) {
    report_verdict *v = &r->verdict;
    v->add_beyond = r->nbeyond > 0;
    v->nadd = 0;
    if (v->add_beyond) {
        for (int32_t k = 0; k < r->nbeyond; ++k)
            v->add_bone[v->nadd++] = r->beyond[k].bone;
    } else if (in->eval_heldout) {
        const sw_eval_result *e = in->eval_heldout;
        /* the bones that together hold most of the error (at least a tenth each) */
        for (int32_t k = 0; k < e->nregions && v->nadd < VERDICT_JOINTS; ++k)
            if (e->region_err[k] >= 0.1) {
                v->add_share[v->nadd] = e->region_err[k];
                v->add_bone[v->nadd++] = e->region_bone[k];
            }
    }
}

/* The advice on a miss: what motion to add, for which joints, in plain words. */
static void advise_miss(const sw_bake_report_input *in, report *r) {
    report_verdict *v = &r->verdict;
    char name[80];
    if (v->add_beyond) {
        APPEND(v->advice,
               "The held-out motion bends %d joint%s further than any training pose, so the "
               "runtime has to guess the flesh there: ",
               r->nbeyond_all, r->nbeyond_all == 1 ? "" : "s");
        int32_t shown = v->nadd < VERDICT_JOINTS ? v->nadd : VERDICT_JOINTS;
        for (int32_t k = 0; k < shown; ++k) {
            report_bone_name(in->ch, r->beyond[k].bone, name, sizeof name);
            APPEND(v->advice, "%s%s (%.0f degrees held-out, %.0f in training)",
                   k == 0                                      ? ""
                   : k == shown - 1 && r->nbeyond_all == shown ? " and "
                                                               : ", ",
                   name, r->beyond[k].heldout_deg, r->beyond[k].train_deg);
        }
        if (r->nbeyond_all > shown)
            APPEND(v->advice, " and %d more (see Held-out motion beyond training)",
                   r->nbeyond_all - shown);
        APPEND(v->advice,
               ". Add training motion that bends %s as far as the held-out motion "
               "does (for example a clip like the held-out one), then bake again.",
               r->nbeyond_all == 1 ? "this joint" : "these joints");
    } else if (v->nadd > 0) {
        APPEND(v->advice, "Every joint stays within the bends the training showed, so the "
                          "runtime misses how they combine. Most of the error is in the flesh "
                          "around ");
        for (int32_t k = 0; k < v->nadd; ++k) {
            report_bone_name(in->ch, v->add_bone[k], name, sizeof name);
            APPEND(v->advice, "%s%s (%.0f%%)",
                   k == 0             ? ""
                   : k == v->nadd - 1 ? " and "
                                      : ", ",
                   name, 100 * v->add_share[k]);
        }
        APPEND(v->advice,
               ". Add training motion that moves %s together the way the held-out "
               "motion does, or let the bake look for such poses itself "
               "(--adaptive 3).",
               v->nadd == 1 ? "this joint and its neighbours" : "these joints");
    } else {
        APPEND(v->advice, "Add training motion like the held-out motion, or let the bake look "
                          "for poses it misses (--adaptive 3).");
    }
    if (isfinite(in->err_train) && in->err_train > v->target)
        APPEND(v->advice,
               " It also misses %.0f%% on its own training motion: it keeps too few flesh "
               "shapes (raise --max-rank).",
               100 * in->err_train);
}

void report_verdict_make(const sw_bake_report_input *in, report *r) {
    report_verdict *v = &r->verdict;
    memset(v, 0, sizeof *v);
    v->target_given = in->target > 0 && in->target < 1;
    v->target = v->target_given ? in->target : SW_BAKE_REPORT_TARGET;
    if (in->res->nheldout < 1 || !isfinite(in->err_heldout)) {
        v->status = VERDICT_NOT_MEASURED;
        snprintf(v->headline, sizeof v->headline,
                 "Not measured: the bake had no held-out motion to try the result on.");
        snprintf(v->advice, sizeof v->advice,
                 "Name a clip to hold out (--heldout-clips) to learn how the character moves "
                 "on motion it was not trained on.");
        return;
    }
    v->status = in->err_heldout <= v->target ? VERDICT_PASS : VERDICT_MISS;
    snprintf(v->headline, sizeof v->headline,
             "%s: on motion it never trained on, the runtime misses %.1f%% of the flesh "
             "movement the full simulation adds to skinning (target: at most %.0f%%).",
             v->status == VERDICT_PASS ? "Pass" : "Miss", 100 * in->err_heldout, 100 * v->target);
    if (v->status == VERDICT_MISS) {
        pick_joints(in, r);
        advise_miss(in, r);
    } else if (r->nbeyond_all > 0) {
        APPEND(v->advice,
               "%d joint%s bend%s further in the held-out motion than in training; the runtime "
               "flags such frames (SINEW_STEP_BEYOND_TRAINING).",
               r->nbeyond_all, r->nbeyond_all == 1 ? "" : "s", r->nbeyond_all == 1 ? "s" : "");
    }
    if (in->failed_steps > 0)
        APPEND(v->advice, " %d step%s failed to solve while measuring.", in->failed_steps,
               in->failed_steps == 1 ? "" : "s");
}

cJSON *report_verdict_json(const sw_bake_report_input *in, const report *r) {
    const report_verdict *v = &r->verdict;
    cJSON *o = cJSON_CreateObject();
    static const char *const status[3] = {"not_measured", "miss", "pass"};
    cJSON_AddStringToObject(o, "status", status[v->status + 1]);
    if (v->status == VERDICT_NOT_MEASURED)
        cJSON_AddNullToObject(o, "pass");
    else
        cJSON_AddBoolToObject(o, "pass", v->status == VERDICT_PASS);
    cJSON_AddItemToObject(o, "err_heldout",
                          isfinite(in->err_heldout) ? cJSON_CreateNumber(in->err_heldout)
                                                    : cJSON_CreateNull());
    cJSON_AddNumberToObject(o, "target", v->target);
    cJSON_AddStringToObject(o, "target_source", v->target_given ? "given" : "default");
    cJSON_AddStringToObject(o, "headline", v->headline);
    cJSON_AddStringToObject(o, "advice", v->advice);
    cJSON_AddStringToObject(o, "add_motion_for",
                            v->nadd == 0    ? "none"
                            : v->add_beyond ? "joints_beyond_training"
                                            : "joints_with_error");
    cJSON *a = cJSON_AddArrayToObject(o, "add_motion");
    for (int32_t k = 0; k < v->nadd; ++k) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddNumberToObject(j, "bone", v->add_bone[k]);
        if (in->ch->bone_names)
            cJSON_AddStringToObject(j, "name", in->ch->bone_names[v->add_bone[k]]);
        else
            cJSON_AddNullToObject(j, "name");
        if (v->add_beyond) {
            cJSON_AddNumberToObject(j, "heldout_deg", r->beyond[k].heldout_deg);
            cJSON_AddNumberToObject(j, "train_deg", r->beyond[k].train_deg);
        } else {
            cJSON_AddNumberToObject(j, "err_share", v->add_share[k]);
        }
        cJSON_AddItemToArray(a, j);
    }
    return o;
}

void html_verdict(FILE *f, const sw_bake_report_input *in, const report *r) {
    const report_verdict *v = &r->verdict;
    static const char *const cls[3] = {"unknown", "miss", "pass"};
    static const char *const word[3] = {"NOT MEASURED", "MISS", "PASS"};
    fprintf(f, "<div class=\"verdict %s\"><div class=\"badge\">%s</div><div><p class=\"head\">",
            cls[v->status + 1], word[v->status + 1]);
    html_text(f, v->headline);
    fprintf(f, "</p>");
    if (v->advice[0]) {
        fprintf(f, "<p>");
        html_text(f, v->advice);
        fprintf(f, "</p>");
    }
    if (v->status != VERDICT_NOT_MEASURED)
        fprintf(f,
                "<p class=\"small\">Held-out error %.3f against a target of %.3f (%s). On the "
                "training motion: %.3f. 0 is the full simulation, 1 is no better than plain "
                "skinning.</p>",
                in->err_heldout, v->target,
                v->target_given ? "given to the bake" : "sinew's default", in->err_train);
    fprintf(f, "</div></div>\n");
}
