/* Clips of their own in the bake (sw_bake_params.train_clips / heldout_clips) and the bake
 * report (tools/report/bake_report.h): training poses come only from training clips (and joint
 * sweeps), held-out poses only from held-out clips, each labelled with its clip and frame;
 * the report's JSON parses back (cJSON) with the bake's figures, and the page and the
 * contact sheet are written. A 1,000-tet finger: a few seconds. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bake.h"
#include "bake_fixture.h"
#include "bake_report_checks.h"
#include "mat3.h"
#include "pose_space.h"
#include "bake_report.h"
#include "samples.h"
#include "sw_test.h"

/* A text file's contents (NULL when it cannot be read). */
static char *read_text(const char *path) {
    size_t n;
    return sw_test_read_file(path, &n);
}

static double num(const cJSON *o, const char *key) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : -1e300;
}

/* The report's JSON against what the bake made. */
/* The report's heldout_beyond_training (j's) is sw_bake_beyond_training's list, *count
 * long. */
static void check_beyond(const cJSON *j, const sw_bake_result *res, const sw_skeleton *sk,
                         int32_t *count) {
    sw_joint_reach want[32];
    int32_t n = *count = sw_bake_beyond_training(res, sk, want, 32);
    const cJSON *bt = cJSON_GetObjectItemCaseSensitive(j, "heldout_beyond_training");
    ENSUREF(cJSON_IsArray(bt) && cJSON_GetArraySize(bt) == n, "%d joints beyond training", n);
    for (int32_t k = 0; k < n && cJSON_GetArraySize(bt) == n; ++k) {
        const cJSON *o = cJSON_GetArrayItem(bt, k);
        ENSURE(num(o, "bone") == want[k].bone);
        ENSURE_NEAR(num(o, "heldout_deg"), want[k].heldout_deg, 1e-9);
        ENSURE_NEAR(num(o, "train_deg"), want[k].train_deg, 1e-9);
        ENSURE(num(o, "heldout_deg") > SW_BEYOND_RATIO * num(o, "train_deg"));
        ENSURE(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(o, "name"))); /* no file names */
    }
}

/* flagged_out: the training [0] and held-out [1] frames the report marks beyond training. */
static void check_json(const char *dir, const sw_bake_result *res, const sw_blob_view *v,
                       const sw_skeleton *sk, double err_heldout, const sw_eval_result *eh,
                       const double *modes, int flagged_out[2]) {
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.json", dir);
    char *text = read_text(path);
    ENSURE(text != NULL);
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    ENSURE(j != NULL);
    if (!j) {
        free(text);
        return;
    }
    ENSURE(num(j, "sinew_bake_report") == SW_BAKE_REPORT_VERSION);
    ENSURE_NEAR(num(j, "err_heldout"), err_heldout, 1e-9);
    ENSURE_NEAR(num(j, "galerkin_err_heldout"), res->heldout_galerkin_error, 1e-9);
    /* the springs the bake chose, and the seams between the finger's domains: apart, by
       less than the correction */
    const cJSON *springs = cJSON_GetObjectItemCaseSensitive(j, "springs");
    ENSURE_NEAR(num(springs, "k"), res->spring_k, 1e-9 * res->spring_k);
    ENSURE(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(springs, "tried")) ==
           res->nspring_tried);
    /* every level's held-out error, the pose-space level's modes */
    const cJSON *lod = cJSON_GetObjectItemCaseSensitive(j, "levels_of_detail");
    const cJSON *lerr = cJSON_GetObjectItemCaseSensitive(lod, "err_heldout_surface");
    ENSURE(num(lod, "pose_space_modes") == res->view.lod_rank && res->view.lod_rank > 0);
    ENSURE(cJSON_GetArraySize(lerr) == 3);
    for (int l = 0; l < 3; ++l)
        ENSURE_NEAR(cJSON_GetArrayItem(lerr, l)->valuedouble, res->lod_heldout[l], 1e-9);
    const cJSON *seams = cJSON_GetObjectItemCaseSensitive(j, "seams");
    ENSURE_NEAR(num(seams, "heldout"), eh->seam, 1e-12);
    ENSURE_NEAR(num(seams, "max_heldout"), eh->seam_max, 1e-12);
    ENSUREF(eh->seam > 0 && eh->seam < 1 && eh->seam_max > 0 && eh->seam_max < 0.1,
            "seams %g, largest %g", eh->seam, eh->seam_max);
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(j, "character");
    ENSURE(num(ch, "tets") > 500 && num(ch, "bones") == 3);
    /* the mesh's origin (the finger's own tets: no mesher) and quality */
    ENSURE(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(ch, "mesher")));
    const cJSON *q = cJSON_GetObjectItemCaseSensitive(ch, "quality");
    ENSURE(num(q, "min_dihedral_deg") > 5 && num(q, "max_dihedral_deg") < 175 &&
           num(q, "inverted") == 0 && num(q, "slivers") == 0);
    const cJSON *clips = cJSON_GetObjectItemCaseSensitive(j, "clips");
    ENSURE(cJSON_GetArraySize(clips) == 2);
    const char *want_name[2] = {"Bend", "Return"}, *want_split[2] = {"train", "heldout"};
    int want_n[2] = {8, res->nheldout};
    for (int i = 0; i < 2 && cJSON_GetArraySize(clips) == 2; ++i) {
        const cJSON *c = cJSON_GetArrayItem(clips, i);
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(c, "name"),
                    *split = cJSON_GetObjectItemCaseSensitive(c, "split");
        ENSURE(cJSON_IsString(name) && !strcmp(name->valuestring, want_name[i]));
        ENSURE(cJSON_IsString(split) && !strcmp(split->valuestring, want_split[i]));
        ENSURE(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(c, "frames")) == want_n[i]);
        ENSURE(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(c, "error")) == want_n[i]);
    }
    const cJSON *doms = cJSON_GetObjectItemCaseSensitive(j, "domains");
    ENSURE(cJSON_GetArraySize(doms) == v->ndomains);
    const cJSON *reg = cJSON_GetObjectItemCaseSensitive(j, "err_regions");
    const cJSON *hreg = cJSON_GetObjectItemCaseSensitive(reg, "heldout");
    ENSURE(cJSON_GetArraySize(hreg) >= 1 &&
           num(cJSON_GetArrayItem(hreg, 0), "err_share") > 0); /* the largest share first */
    for (int k = 0; k < cJSON_GetArraySize(hreg); ++k) /* the sample's bones have no names */
        ENSURE(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(hreg, k), "name")));
    for (int32_t d = 0; d < v->ndomains && cJSON_GetArraySize(doms) == v->ndomains; ++d) {
        const cJSON *o = cJSON_GetArrayItem(doms, d);
        ENSURE(num(o, "rank") == v->domains[d].rank &&
               num(o, "cubature") == v->domains[d].cub_count);
        ENSURE(num(o, "energy") > 0.9 && num(o, "energy") <= 1.0);
    }
    ENSURE(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(j, "stages")) == SW_BAKE_NSTAGES);
    int32_t nbeyond;
    check_beyond(j, res, sk, &nbeyond);
    /* per frame, the joints it bends beyond training: each pose's own count, some
       held-out frame's nonzero exactly when the bake lists a joint beyond */
    int flagged[2] = {0, 0};
    for (int i = 0; i < 2 && cJSON_GetArraySize(clips) == 2; ++i) {
        const cJSON *b =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(clips, i), "beyond_training");
        ENSURE(cJSON_GetArraySize(b) == want_n[i]);
        for (int32_t k = 0, t = 0; k < want_n[i] && cJSON_GetArraySize(b) == want_n[i]; ++k) {
            const double *T = res->heldout_T + (size_t)k * 12 * sk->nbones;
            if (i == 0) { /* the k-th training pose of the clip */
                while (t < res->ntrain && res->train_clip[t] != 0)
                    ++t;
                T = res->train_T + (size_t)t++ * 12 * sk->nbones;
            }
            int32_t want = sw_bake_pose_beyond(sk, T, res->sweep_angle);
            ENSURE(cJSON_GetArrayItem(b, k)->valuedouble == want);
            flagged[i] += want > 0;
        }
    }
    ENSUREF((flagged[1] > 0) == (nbeyond > 0), "%d frames beyond training, %d joints listed",
            flagged[1], nbeyond);
    const cJSON *bm = cJSON_GetObjectItemCaseSensitive(j, "err_heldout_by_mode");
    for (int k = 0; k < SW_BAKE_MODES; ++k) {
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(bm, sw_self_contact_keys[k]);
        if (isnan(modes[k]))
            ENSURE(cJSON_IsNull(m));
        else
            ENSURE(cJSON_IsNumber(m) && fabs(m->valuedouble - modes[k]) < 1e-12);
    }
    const cJSON *sheet = cJSON_GetObjectItemCaseSensitive(j, "contact_sheet");
    ENSURE(cJSON_IsString(sheet));
    /* the adaptive loop's rounds, as given (the second not verified: null) */
    const cJSON *ad = cJSON_GetObjectItemCaseSensitive(j, "adaptive");
    ENSURE(cJSON_GetArraySize(ad) == 2);
    if (cJSON_GetArraySize(ad) == 2) {
        const cJSON *a0 = cJSON_GetArrayItem(ad, 0), *a1 = cJSON_GetArrayItem(ad, 1);
        ENSURE(num(a0, "train_poses") == 10 && num(a1, "added") == 4 && num(a1, "rank") == 24);
        ENSURE_NEAR(num(a0, "err_heldout"), 0.25, 1e-12);
        ENSURE_NEAR(num(a0, "picks_error"), 0.5, 1e-12);
        ENSURE(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(a1, "picks_error")));
    }
    flagged_out[0] = flagged[0];
    flagged_out[1] = flagged[1];
    cJSON_Delete(j);
    free(text);
}

/* a and b the same to JSON's printing (cJSON keeps 15 digits where they read back close) */
static int same(double a, double b) {
    return fabs(a - b) <= 1e-12 * fmax(1.0, fabs(b));
}

/* report.json names the reference's solver and Hessian (null when not given) and the
 * joint range's frames. */
static void check_reference_json(const char *dir, const char *solver, const char *hessian,
                                 int32_t range_frames) {
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.json", dir);
    char *text = read_text(path);
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    ENSURE(j != NULL);
    const cJSON *ref = cJSON_GetObjectItemCaseSensitive(j, "reference"),
                *frames = cJSON_GetObjectItemCaseSensitive(j, "joint_range_frames");
    if (solver) {
        const cJSON *s = cJSON_GetObjectItemCaseSensitive(ref, "solver"),
                    *h = cJSON_GetObjectItemCaseSensitive(ref, "hessian");
        ENSURE(cJSON_IsString(s) && !strcmp(s->valuestring, solver));
        ENSURE(cJSON_IsString(h) && !strcmp(h->valuestring, hessian));
    } else {
        ENSURE(cJSON_IsNull(ref));
    }
    ENSURE(cJSON_IsNumber(frames) && frames->valueint == range_frames);
    cJSON_Delete(j);
    free(text);
}

/* DIR/report.json parsed (NULL: unreadable). */
static cJSON *parse_report_json(const char *dir) {
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.json", dir);
    char *text = read_text(path);
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    free(text);
    return j;
}

/* report.json's memory (absent when m is NULL): the blob's bytes, its parts summing to them,
 * the instances' as measured; the HTML says it. */
static void check_memory_json(const char *dir, const sw_blob_memory *m) {
    cJSON *j = parse_report_json(dir);
    ENSURE(j != NULL);
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(j, "memory");
    if (!m) {
        ENSURE(o == NULL);
    } else {
        ENSURE(cJSON_IsObject(o) && num(o, "blob_bytes") == (double)m->blob &&
               num(o, "instance_bytes") == (double)m->instance &&
               num(o, "instance_shared_bytes") == (double)m->instance_shared &&
               num(o, "workspace_bytes") == (double)m->workspace);
        ENSURE(m->instance > m->instance_shared && m->instance_shared > 0 && m->workspace > 0);
        const cJSON *parts = cJSON_GetObjectItemCaseSensitive(o, "blob_parts");
        double sum = 0;
        for (int k = 0; k < SW_NPARTS; ++k) {
            ENSURE(num(parts, sw_blob_part_keys[k]) == (double)m->part[k]);
            sum += num(parts, sw_blob_part_keys[k]);
        }
        ENSUREF(sum == (double)m->blob, "parts %g of %zu bytes", sum, m->blob);
        ENSURE(m->part[SW_PART_BASIS] > 0 && m->part[SW_PART_COND] > 0);
    }
    cJSON_Delete(j);
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.html", dir);
    char *text = read_text(path);
    ENSURE(text && (strstr(text, ">memory<") != NULL) == (m != NULL));
    free(text);
}

/* DIR/report.json's ref_spread: the figures given, or null without them. */
static void check_spread_json(const char *dir, const sw_bake_spread *s) {
    cJSON *j = parse_report_json(dir);
    ENSURE(j != NULL);
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(j, "ref_spread");
    if (!s) {
        ENSURE(cJSON_IsNull(o));
    } else {
        ENSURE(cJSON_IsObject(o) && num(o, "poses") == s->poses &&
               num(o, "unconverged") == s->unconverged && num(o, "failed") == s->failed);
        ENSURE(same(num(o, "runtime"), s->runtime) && same(num(o, "from_skin"), s->from_skin) &&
               same(num(o, "from_reference"), s->from_reference) &&
               same(num(o, "polished"), s->polished) &&
               same(num(o, "polish_move"), s->polish_move));
        const cJSON *pp = cJSON_GetObjectItemCaseSensitive(o, "per_pose");
        ENSURE(cJSON_GetArraySize(pp) == s->poses);
        for (int32_t k = 0; k < s->poses && cJSON_GetArraySize(pp) == s->poses; ++k) {
            const cJSON *e = cJSON_GetArrayItem(pp, k);
            const sw_bake_spread_pose *q = &s->per_pose[k];
            ENSURE(num(e, "heldout") == q->heldout && same(num(e, "runtime"), q->runtime) &&
                   same(num(e, "from_skin"), q->from_skin) &&
                   same(num(e, "from_reference"), q->from_reference) &&
                   same(num(e, "polished"), q->polished) &&
                   same(num(e, "correction"), q->correction));
        }
    }
    cJSON_Delete(j);
}

/* The bake's blob loaded (its bytes in *mem) and measured on the bake's poses, each
 * pose's error in *fe (training poses first); 0 on any failure. */
static int blob_and_errors(const sw_bake_result *res, void **mem, sinew_blob **blob, double **fe,
                           sw_eval_result *et, sw_eval_result *eh) {
    sw_error e;
    if (sw_bake_result_blob(res, mem, blob, &e) != SINEW_OK) return 0;
    *fe = malloc(sizeof(double) * (size_t)(res->ntrain + res->nheldout + 1));
    return *fe && sw_bake_errors_frames(*blob, res, SINEW_SELF_CONTACT_POSE_SPACE, et, eh, *fe,
                                        *fe + res->ntrain, &e) == SINEW_OK;
}

TEST(clips_of_their_own_and_the_report) {
    sw_character ch, other;
    sw_error e;
    ENSURE(sw_sample_make("finger", 1000, 8, &ch, &e) == SINEW_OK);
    ENSURE(sw_sample_make("finger", 1000, 6, &other, &e) == SINEW_OK);
    /* the held-out clip: the 6-frame fold played backwards (never a training frame) */
    sw_clip held = other.clip;
    int32_t nb = held.nbones;
    double *rev = malloc(sizeof(double) * 12 * (size_t)nb * 6);
    for (int32_t f = 0; f < 6; ++f)
        memcpy(rev + (size_t)f * 12 * nb, held.T + (size_t)(5 - f) * 12 * nb,
               sizeof(double) * 12 * (size_t)nb);
    held.T = rev;
    sw_bake_params p = sw_bake_params_default();
    p.threads = 2;
    p.train_clips = &ch.clip;
    p.ntrain_clips = 1;
    p.heldout_clips = &held;
    p.nheldout_clips = 1;
    sw_bake_result res;
    sinew_result r = sw_bake(&ch, &p, &res, &e);
    ENSUREF(r == SINEW_OK, "%s", e.msg);
    if (r) return;
    ENSURE(res.nheldout == 6);
    int32_t clip_poses = 0;
    for (int32_t k = 0; k < res.ntrain; ++k) {
        ENSURE(res.train_clip[k] == 0 || res.train_clip[k] == -1);
        clip_poses += res.train_clip[k] == 0;
    }
    ENSURE(clip_poses == 8);
    for (int32_t k = 0; k < res.nheldout; ++k)
        ENSURE(res.heldout_clip[k] == 0 && res.heldout_frame[k] == k);
    void *mem = NULL;
    sinew_blob *blob = NULL;
    double *fe = NULL; /* per pose: the training poses', then the held-out ones' */
    sw_eval_result et, eh;
    ENSURE(blob_and_errors(&res, &mem, &blob, &fe, &et, &eh));
    sw_eval_result et2, eh2; /* the aggregate is sw_bake_errors' */
    ENSURE(sw_bake_errors(blob, &res, SINEW_SELF_CONTACT_POSE_SPACE, &et2, &eh2, &e) == SINEW_OK);
    ENSURE(et.correction_error == et2.correction_error);
    ENSURE(eh.correction_error == eh2.correction_error);
    static const char tn[1][64] = {"Bend"}, hn[1][64] = {"Return"};
    sw_adaptive_report arep;
    memset(&arep, 0, sizeof arep);
    arep.nrounds = 2;
    arep.round[0] =
        (sw_adaptive_round){10, 0, 20, 0.02, 0.25, 0.01, 0.1, 0.3, 0.9, 0.6, 0.5, 10, 1.0};
    arep.round[1] = (sw_adaptive_round){14, 4, 24, 0.02, 0.2, 0.01, 0.08, 0, 0, 0, -1, 4, 1.0};
    /* the held-out error in every self-contact mode: the measured mode's as given, the
       others each sw_bake_errors' held-out figure in that mode */
    double modes[SW_BAKE_MODES];
    ENSURE(sw_bake_mode_errors(blob, &res, SINEW_SELF_CONTACT_POSE_SPACE, eh.correction_error,
                               modes, &e) == SINEW_OK);
    for (int k = 0; k < SW_BAKE_MODES; ++k) {
        if (!res.view.npair_groups && (sinew_self_contact)k == SINEW_SELF_CONTACT_POSE_PAIRS) {
            ENSURE(isnan(modes[k]));
            continue;
        }
        sw_eval_result mt, mh;
        ENSURE(sw_bake_errors(blob, &res, (sinew_self_contact)k, &mt, &mh, &e) == SINEW_OK);
        ENSUREF(modes[k] == mh.correction_error, "%s: %g against %g", sw_self_contact_names[k],
                modes[k], mh.correction_error);
    }
    /* how well the held-out references are defined, at every second held-out pose */
    sw_bake_spread spread;
    ENSURE(sw_bake_reference_spread(&ch, &p, blob, &res, SINEW_SELF_CONTACT_POSE_SPACE, 2, &spread,
                                    &e) == SINEW_OK);
    ENSURE(spread.poses == res.nheldout / 2);
    /* the blob's memory by part and its instances' */
    sw_blob_memory memory;
    ENSURE(sw_blob_memory_measure(mem, (size_t)((const sinew_blob_header *)mem)->file_size, blob,
                                  &memory));
    sw_bake_report_input in = {"finger",
                               &ch,
                               &res,
                               blob,
                               tn,
                               1,
                               hn,
                               1,
                               fe,
                               fe + res.ntrain,
                               et.correction_error,
                               eh.correction_error,
                               0,
                               1.0,
                               0.5,
                               1,
                               &arep,
                               &et,
                               &eh,
                               NULL,
                               modes,
                               &spread,
                               "auto",
                               "adaptive",
                               0,
                               &memory};
    /* where the error is: shares in order, and all of it when every bone is listed */
    for (int set = 0; set < 2; ++set) {
        const sw_eval_result *ev = set ? &eh : &et;
        double sum = 0, corr = 0;
        ENSURE(ev->nregions >= 1 && ev->nregions <= SW_EVAL_REGIONS);
        for (int32_t k = 0; k < ev->nregions; ++k) {
            ENSURE(ev->region_err[k] >= 0 && ev->region_err[k] <= 1 && ev->region_corr[k] >= 0);
            if (k > 0) ENSURE(ev->region_err[k] <= ev->region_err[k - 1]);
            sum += ev->region_err[k];
            corr += ev->region_corr[k];
        }
        ENSUREF(sum <= 1 + 1e-12 && corr <= 1 + 1e-12, "shares %g %g", sum, corr);
        if (ch.skel.nbones <= SW_EVAL_REGIONS)
            ENSUREF(fabs(sum - 1) < 1e-9, "%d bones, every one listed: shares sum to %g",
                    ch.skel.nbones, sum);
    }
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/test_bake_report_out", SINEW_BINARY_DIR);
    r = sw_bake_report_write(dir, &in, &e);
    ENSUREF(r == SINEW_OK, "%s", e.msg);
    int flagged[2] = {-1, -1};
    check_json(dir, &res, &res.view, &ch.skel, eh.correction_error, &eh, modes, flagged);
    check_spread_json(dir, &spread);
    check_reference_json(dir, "auto", "adaptive", 0);
    check_memory_json(dir, &memory);
    ENSURE(flagged[0] == 0); /* a training clip never bends beyond itself */
    char verdict[16];
    check_verdict(dir, eh.correction_error, 0, &eh, verdict);
    check_sheet(dir, &res);
    check_plots(dir);
    /* had the training reached half as far, the reversed fold would bend beyond it: the
       report marks those frames (and lists the joints) as the rule says */
    for (int32_t b = 0; b < ch.skel.nbones; ++b)
        res.sweep_angle[b] *= 0.5;
    char dir2[1100];
    snprintf(dir2, sizeof dir2, "%.1000s_half", dir);
    in.target = 1e-9; /* a miss: the verdict names the joints beyond training */
    ENSURE(sw_bake_report_write(dir2, &in, &e) == SINEW_OK);
    flagged[1] = -1;
    check_json(dir2, &res, &res.view, &ch.skel, eh.correction_error, &eh, modes, flagged);
    ENSUREF(flagged[1] > 0, "%d held-out frames beyond half the training's bends", flagged[1]);
    check_verdict(dir2, eh.correction_error, in.target, &eh, verdict);
    ENSURE(!strcmp(verdict, "miss"));
    in.target = 0.999; /* a pass, whatever the error */
    ENSURE(sw_bake_report_write(dir2, &in, &e) == SINEW_OK);
    check_verdict(dir2, eh.correction_error, in.target, &eh, verdict);
    ENSURE(!strcmp(verdict, "pass"));
    in.target = 0;
    char path2[1200];
    snprintf(path2, sizeof path2, "%s/report.html", dir2);
    char *html2 = read_text(path2);
    ENSURE(html2 && strstr(html2, "stroke=\"#c00\"")); /* the marks in the plot */
    free(html2);
    for (int32_t b = 0; b < ch.skel.nbones; ++b)
        res.sweep_angle[b] *= 2;
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.html", dir);
    char *html = read_text(path);
    ENSURE(html && strstr(html, "<svg") && strstr(html, "heldout_sheet.png") &&
           strstr(html, "Return") && strstr(html, "Adaptive training rounds") &&
           strstr(html, "Where the error is") &&
           strstr(html, "Held-out error by self-contact mode") &&
           strstr(html, "How well the held-out reference is defined"));
    /* the reference row names its solver, and no bound of random poses: clips hold out */
    ENSURE(strstr(html, "full-space solves by auto, adaptive element Hessians</td>") &&
           !strstr(html, "random poses turn"));
    free(html);
    struct stat st;
    snprintf(path, sizeof path, "%.1000s/heldout_sheet.png", dir);
    ENSURE(stat(path, &st) == 0 && st.st_size > 1000);
    sw_bake_spread_free(&spread);
    free(fe);
    sinew_blob_destroy(blob);
    free(mem);
    sw_bake_result_free(&res);
    free(rev);
    sw_character_free(&other);
    sw_character_free(&ch);
}

/* Each joint's bend from rest at pose T (sw_bake_joint_reach over that one pose). */
static void bends(const sw_skeleton *sk, const double *T, double *angle) {
    for (int32_t b = 0; b < sk->nbones; ++b)
        angle[b] = 0;
    sw_bake_joint_reach(sk, T, 1, angle, NULL);
}

/* A bare skeleton (no clip): the held-out poses are random combined poses, each reached
 * from the one before in heldout_steps poses, which the report shows as a held-out set of
 * their own, each pose's error the evaluation's; no empty training clip is listed. */
TEST(random_heldout_poses_in_the_report) {
    sw_character ch;
    sw_error e;
    ENSURE(sw_sample_make("finger", 1000, 8, &ch, &e) == SINEW_OK);
    ch.clip.nframes = 0; /* the sample's clip unused: sweeps train, random poses are held out */
    sw_bake_params p = sw_bake_params_default();
    p.threads = 2;
    p.random_poses = 4;
    p.heldout_steps = 3;
    sw_bake_result res;
    sinew_result r = sw_bake(&ch, &p, &res, &e);
    ENSUREF(r == SINEW_OK, "%s", e.msg);
    if (r) {
        sw_character_free(&ch);
        return;
    }
    ENSURE(res.nheldout == 12);
    for (int32_t k = 0; k < res.nheldout; ++k)
        ENSURE(res.heldout_clip[k] < 0);
    /* every third pose is the random pose a one-step path gives; on the way to it every
       joint (turning about its own sweep axis) bends by a third of its way there at a
       time, the first from rest */
    int32_t nb = ch.skel.nbones;
    double *T1 = malloc(sizeof(double) * 4 * 12 * (size_t)nb),
           *local = malloc(sizeof(double) * SW_RANDOM_POSE_SCRATCH * (size_t)nb),
           *bend = calloc(3 * (size_t)nb, sizeof(double));
    ENSURE(T1 && local && bend);
    if (T1 && local && bend && res.nheldout == 12) {
        sw_bake_random_poses(&ch.skel, res.sweep_axis, res.sweep_angle, p.seed, 4, 1, local, T1);
        double *from = bend, *to = bend + nb, *at = bend + 2 * nb, largest = 0;
        for (int32_t k = 0; k < 4; ++k) {
            const double *end = res.heldout_T + (size_t)(3 * k + 2) * 12 * nb;
            ENSURE(!memcmp(end, T1 + (size_t)k * 12 * nb, sizeof(double) * 12 * (size_t)nb));
            bends(&ch.skel, end, to);
            for (int st = 1; st <= 3; ++st) {
                bends(&ch.skel, res.heldout_T + (size_t)(3 * k + st - 1) * 12 * nb, at);
                for (int32_t b = 0; b < nb; ++b)
                    ENSURE_NEAR(at[b], from[b] + (to[b] - from[b]) * st / 3, 1e-9);
            }
            for (int32_t b = 0; b < nb; ++b)
                largest = fmax(largest, fabs(to[b] - from[b]));
            memcpy(from, to, sizeof(double) * (size_t)nb);
        }
        ENSURE(largest > 0.1); /* the path moves */
    }
    free(T1);
    free(local);
    free(bend);
    void *mem = NULL;
    sinew_blob *blob = NULL;
    double *fe = NULL; /* per pose: the training poses', then the held-out ones' */
    sw_eval_result et, eh;
    ENSURE(blob_and_errors(&res, &mem, &blob, &fe, &et, &eh));
    sw_bake_report_input in = {"finger",
                               &ch,
                               &res,
                               blob,
                               NULL,
                               0,
                               NULL,
                               0,
                               fe,
                               fe + res.ntrain,
                               et.correction_error,
                               eh.correction_error,
                               0,
                               1.0,
                               0.5,
                               0,
                               NULL,
                               &et,
                               &eh,
                               NULL,
                               NULL,
                               NULL,
                               NULL,
                               NULL,
                               0,
                               NULL};
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/test_bake_report_random", SINEW_BINARY_DIR);
    r = sw_bake_report_write(dir, &in, &e);
    ENSUREF(r == SINEW_OK, "%s", e.msg);
    check_spread_json(dir, NULL); /* not measured: null */
    check_reference_json(dir, NULL, NULL, 0);
    check_memory_json(dir, NULL);
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.json", dir);
    char *text = read_text(path);
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    ENSURE(j != NULL);
    /* random combined poses turn each joint within its sweep: none beyond training */
    int32_t nbeyond = -1;
    check_beyond(j, &res, &ch.skel, &nbeyond);
    ENSURE(nbeyond == 0);
    const cJSON *clips = cJSON_GetObjectItemCaseSensitive(j, "clips");
    ENSURE(cJSON_GetArraySize(clips) == 1);
    if (cJSON_GetArraySize(clips) == 1) {
        const cJSON *c = cJSON_GetArrayItem(clips, 0);
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(c, "name"),
                    *split = cJSON_GetObjectItemCaseSensitive(c, "split"),
                    *frames = cJSON_GetObjectItemCaseSensitive(c, "frames"),
                    *err = cJSON_GetObjectItemCaseSensitive(c, "error");
        ENSURE(cJSON_IsString(name) && !strcmp(name->valuestring, "random combined poses"));
        ENSURE(cJSON_IsString(split) && !strcmp(split->valuestring, "heldout"));
        ENSURE(cJSON_GetArraySize(frames) == 12 && cJSON_GetArraySize(err) == 12);
        for (int k = 0; k < 12 && cJSON_GetArraySize(err) == 12; ++k) {
            ENSURE(cJSON_GetArrayItem(frames, k)->valuedouble == k);
            ENSURE_NEAR(cJSON_GetArrayItem(err, k)->valuedouble, fe[res.ntrain + k], 1e-12);
        }
    }
    cJSON_Delete(j);
    free(text);
    /* with its reference named, the page says what bounds the random poses */
    in.ref_solver = "auto";
    in.ref_hessian = "adaptive";
    char dir3[1100], path3[1200];
    snprintf(dir3, sizeof dir3, "%.1000s_ref", dir);
    ENSURE(sw_bake_report_write(dir3, &in, &e) == SINEW_OK);
    snprintf(path3, sizeof path3, "%s/report.html", dir3);
    char *html = read_text(path3);
    ENSURE(html && strstr(html, "random poses turn each joint within 90 degrees</td>"));
    free(html);
    check_ramp();
    check_font();
    char verdict[16];
    /* nothing beyond training: a miss names the bones whose flesh holds the error */
    in.target = 1e-9;
    in.contact_sheet = 1;
    ENSURE(sw_bake_report_write(dir3, &in, &e) == SINEW_OK);
    check_verdict(dir3, eh.correction_error, in.target, &eh, verdict);
    ENSURE(!strcmp(verdict, "miss"));
    check_sheet(dir3, &res);
    in.err_heldout = NAN; /* no held-out figure: no verdict either way */
    ENSURE(sw_bake_report_write(dir3, &in, &e) == SINEW_OK);
    check_verdict(dir3, NAN, in.target, &eh, verdict);
    ENSURE(!strcmp(verdict, "not_measured"));
    free(fe);
    sinew_blob_destroy(blob);
    free(mem);
    sw_bake_result_free(&res);
    sw_character_free(&ch);
}

/* A joint range (sw_character.range) bounds the sweeps and the random combined poses of
 * a bake without a clip: each joint swept to its largest turn in the range, about its
 * axis there; a joint the range leaves at rest is never bent; every pose within the
 * range. A range of another skeleton, one not finite and one that turns no joint are
 * refused, each naming the range. */
TEST(joint_range_bounds_sweeps_and_random_poses) {
    sw_character ch;
    sw_error e;
    /* frames: rest, bone 1 at 40 degrees, at 20 degrees about z; bone 2 always at rest */
    static const double turn[3 * 3] = {0, 0, 0, 0, 40, 0, 0, 20, 0};
    double range_T[3 * 12 * 3], deg = 0.017453292519943295;
    int made = finger_range_fixture(&ch, 1000, 3, turn, range_T);
    ENSURE(made);
    if (!made) return;
    const int32_t nb = 3;
    sw_bake_params p = sw_bake_params_default();
    p.threads = 2;
    p.sweep_samples = 3;
    p.random_poses = 3;
    p.heldout_steps = 2;
    sw_bake_result res;
    /* refused: another skeleton's, not finite, at rest throughout */
    ch.range = (sw_clip){nb - 1, 3, 30.0, range_T};
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "joint range") != NULL, "%s", e.msg);
    ch.range = (sw_clip){nb, 3, 30.0, range_T};
    double keep = range_T[12 * nb + 5];
    range_T[12 * nb + 5] = NAN;
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_NOT_FINITE);
    ENSUREF(strstr(e.msg, "joint range: motion frame 1") != NULL, "%s", e.msg);
    range_T[12 * nb + 5] = keep;
    ch.range = (sw_clip){nb, 1, 30.0, range_T}; /* the rest frame alone */
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "joint range turns no joint") != NULL, "%s", e.msg);
    ch.range = (sw_clip){nb, 3, 30.0, range_T};
    sinew_result r = sw_bake(&ch, &p, &res, &e);
    ch.range = (sw_clip){0, 0, 0, NULL}; /* borrowed: not the character's to free */
    ENSUREF(r == SINEW_OK, "%s", e.msg);
    if (r) {
        sw_character_free(&ch);
        return;
    }
    ENSURE_NEAR(res.sweep_angle[1], 40 * deg, 1e-12);
    ENSURE(res.sweep_angle[2] == 0);
    ENSURE_NEAR(fabs(res.sweep_axis[5]), 1, 1e-12); /* bone 1 about z */
    ENSURE(res.ntrain == 3 && res.nheldout == 6);
    double bend[3], reach = 0;
    for (int32_t k = 0; k < res.ntrain + res.nheldout; ++k) {
        const double *T = k < res.ntrain ? res.train_T + (size_t)k * 12 * nb
                                         : res.heldout_T + (size_t)(k - res.ntrain) * 12 * nb;
        bends(&ch.skel, T, bend);
        ENSUREF(bend[1] <= 40 * deg + 1e-12, "pose %d bends bone 1 by %g", k, bend[1] / deg);
        ENSUREF(bend[2] < 1e-9, "pose %d bends bone 2 by %g", k, bend[2] / deg);
        if (k < res.ntrain) reach = fmax(reach, bend[1]);
    }
    ENSURE_NEAR(reach, 40 * deg, 1e-9); /* the sweep reaches the range's end */
    sw_bake_result_free(&res);
    sw_character_free(&ch);
}

/* Held-out clips need training clips; a clip of another skeleton is named, and so is a
 * clip with a value that is not finite; so is a number of steps to the random held-out
 * poses out of range. */
TEST(bad_clip_lists_rejected) {
    sw_character ch;
    sw_error e;
    ENSURE(sw_sample_make("finger", 1000, 8, &ch, &e) == SINEW_OK);
    sw_bake_params p = sw_bake_params_default();
    sw_bake_result res;
    p.heldout_clips = &ch.clip;
    p.nheldout_clips = 1;
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "held-out clips need training clips"), "%s", e.msg);
    sw_clip wrong = ch.clip;
    wrong.nbones = 2;
    p.train_clips = &wrong;
    p.ntrain_clips = 1;
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "training clip 0: motion has 2 bones"), "%s", e.msg);
    /* a value that is not finite is named with its clip and frame, in a held-out clip and
       in the character's own clip (a caller's clips, which no reader checked) */
    const int32_t nb = ch.skel.nbones;
    const size_t nT = (size_t)12 * nb * ch.clip.nframes;
    double *T = malloc(nT * sizeof(double));
    ENSURE(T && ch.clip.nframes > 3);
    memcpy(T, ch.clip.T, nT * sizeof(double));
    T[12 * nb * 3 + 7] = NAN;
    sw_clip bad = ch.clip;
    bad.T = T;
    p.train_clips = &ch.clip;
    p.heldout_clips = &bad;
    ENSURE(sw_bake(&ch, &p, &res, &e) == SINEW_ERROR_NOT_FINITE);
    ENSUREF(strstr(e.msg, "held-out clip 0: motion frame 3 is not finite"), "%s", e.msg);
    double *own = ch.clip.T;
    ch.clip.T = T;
    sw_bake_params d = sw_bake_params_default();
    sinew_result rd = sw_bake(&ch, &d, &res, &e);
    ch.clip.T = own;
    free(T);
    ENSURE(rd == SINEW_ERROR_NOT_FINITE);
    ENSUREF(strstr(e.msg, "the character's clip: motion frame 3 is not finite"), "%s", e.msg);
    /* an absurd number of steps to the random held-out poses is named, not baked */
    sw_bake_params q = sw_bake_params_default();
    q.heldout_steps = 0;
    ENSURE(sw_bake(&ch, &q, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "10 poses in 0 steps each"), "%s", e.msg);
    q.heldout_steps = 65;
    ENSURE(sw_bake(&ch, &q, &res, &e) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(e.msg, "in 65 steps each (steps 1..64"), "%s", e.msg);
    sw_character_free(&ch);
}

SW_TEST_MAIN(CASE(clips_of_their_own_and_the_report), CASE(random_heldout_poses_in_the_report),
             CASE(joint_range_bounds_sweeps_and_random_poses), CASE(bad_clip_lists_rejected))
