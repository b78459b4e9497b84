/* sinew-bake: a rigged character in, a blob out (DESIGN.md §5).
 *
 *   sinew-bake (--scene NAME [--tets N] [--frames F] | --mesh FILE --skeleton FILE.tgf
 *              [--weights FILE.dmat] [--clip FILE]) --out FILE.blob
 *              [--selector greedy|importance|nnhtp] [--tol 0.05] [--max-rank R]
 *              [--compare-cubature] [--no-self-contact] [--return-path] [--threads T] [--data DIR]
 * [--json]
 *
 * Shows progress per stage on stderr and ends with a summary (per-stage time, ranks,
 * cubature sizes, training and held-out errors); with --json the last stdout line is
 * one JSON object. The blob is written atomically (temporary file + rename). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SW_TOOL_CHARACTER_ARGS
#include "tool_common.h"
#include "sw_mesh.h"

#include "bake.h"
#include "blob_write.h"
#include "character_io.h"
#include "samples.h"
#include "subspace_eval.h"

static void usage(FILE *f) {
    fprintf(
        f,
        "usage: sinew-bake (--scene NAME [--tets N] [--frames F] |\n"
        "                   --mesh FILE --skeleton FILE.tgf [--weights FILE.dmat] [--clip FILE])\n"
        "                  --out FILE.blob [--selector greedy|importance|nnhtp] [--tol T]\n"
        "                  [--max-rank R] [--spring-k K] [--compare-cubature] [--no-self-contact]\n"
        "                  [--return-path]\n"
        "                  [--threads T] [--data DIR] [--json]\n"
        "  NAME: cylinder | finger | capsule (procedural) | elephant-cd | hand-libigl\n");
}

int main(int argc, char **argv) {
    sw_character_args ca;
    sw_character_args_init(&ca);
    const char *out_path = NULL;
    int json = 0;
    sw_bake_params p = sw_bake_params_default();
    p.progress = 1;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1;
        if (sw_character_args_take(&ca, argc, argv, &i, &ok)) {
            /* a character option, consumed */
        } else if (!strcmp(a, "--out") && next)
            out_path = argv[++i];
        else if (!strcmp(a, "--threads") && next)
            ok = sw_parse_int(argv[++i], 0, 256, &p.threads);
        else if (!strcmp(a, "--max-rank") && next)
            ok = sw_parse_int(argv[++i], 1, 1024, &p.max_rank);
        else if (!strcmp(a, "--tol") && next) {
            char *end;
            p.cubature_tol = strtod(argv[++i], &end);
            ok = !*end && p.cubature_tol > 0 && p.cubature_tol < 1;
        } else if (!strcmp(a, "--selector") && next) {
            const char *s = argv[++i];
            if (!strcmp(s, "greedy"))
                p.selector = SW_CUBATURE_GREEDY;
            else if (!strcmp(s, "importance"))
                p.selector = SW_CUBATURE_IMPORTANCE;
            else if (!strcmp(s, "nnhtp"))
                p.selector = SW_CUBATURE_NNHTP;
            else
                ok = 0;
        } else if (!strcmp(a, "--spring-k") && next) {
            char *end;
            p.spring_k = strtod(argv[++i], &end);
            ok = !*end && p.spring_k > 0 && isfinite(p.spring_k);
        } else if (!strcmp(a, "--compare-cubature"))
            p.compare_selectors = 1;
        else if (!strcmp(a, "--no-self-contact"))
            p.self_contact = 0;
        else if (!strcmp(a, "--return-path"))
            p.return_path = 1;
        else if (!strcmp(a, "--json"))
            json = 1;
        else if (!sw_tool_help(a, usage))
            ok = 0;
        if (!ok) return sw_tool_bad_arg("sinew-bake", a, usage);
    }
    if (!out_path || !sw_character_args_valid(&ca)) {
        fprintf(stderr, "sinew-bake: give --out and either --scene or --mesh with --skeleton\n");
        usage(stderr);
        return 2;
    }
    sw_error err;
    sw_character ch;
    double t0 = sw_now_seconds();
    sinew_result r = sw_character_args_make(&ca, &ch, &err);
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "sinew-bake: ");
    fprintf(stderr, "sinew-bake: %s: %d tets, %d vertices, %d bones, %d clip frames\n",
            ch.name[0] ? ch.name : (ca.scene ? ca.scene : ca.mesh), ch.mesh.ntets, ch.mesh.nverts,
            ch.skel.nbones, ch.clip.nframes);
    sw_bake_result res;
    r = sw_bake(&ch, &p, &res, &err);
    if (r != SINEW_OK) {
        fprintf(stderr, "sinew-bake: %s (%s)\n", err.msg, sinew_result_string(r));
        sw_character_free(&ch);
        return 1;
    }
    if ((r = sw_blob_write(out_path, &res.view, &err)) != SINEW_OK) {
        fprintf(stderr, "sinew-bake: cannot write %s: %s (%s)\n", out_path, err.msg,
                sinew_result_string(r));
        sw_bake_result_free(&res);
        sw_character_free(&ch);
        return 1;
    }
    double bake_seconds = sw_now_seconds() - t0;
    /* evaluate the written blob against the full-space solutions */
    sinew_blob_def bd = sinew_blob_def_default();
    bd.path = out_path;
    sinew_blob *blob = NULL;
    sw_eval_result et, eh;
    memset(&et, 0, sizeof et);
    memset(&eh, 0, sizeof eh);
    double t1 = sw_now_seconds();
    if ((r = sinew_blob_load(&bd, &blob)) != SINEW_OK ||
        (r = sw_eval_correction(blob, res.mass, res.train_T, res.train_x, res.ntrain, 20, &et,
                                &err)) != SINEW_OK ||
        (r = sw_eval_correction(blob, res.mass, res.heldout_T, res.heldout_x, res.nheldout, 20, &eh,
                                &err)) != SINEW_OK) {
        fprintf(stderr, "sinew-bake: cannot evaluate the blob: %s (%s)\n", err.msg,
                sinew_result_string(r));
        sinew_blob_destroy(blob);
        sw_bake_result_free(&res);
        sw_character_free(&ch);
        return 1;
    }
    double eval_seconds = sw_now_seconds() - t1;
    const sw_blob_view *v = &res.view;
    fprintf(stderr, "sinew-bake: wrote %s\n", out_path);
    fprintf(stderr,
            "  stages (s): prepare %.2f, domains %.2f, simulate %.2f, basis %.2f, cubature %.2f, "
            "reduce %.2f; total %.2f\n",
            res.stage_seconds[0], res.stage_seconds[1], res.stage_seconds[2], res.stage_seconds[3],
            res.stage_seconds[4], res.stage_seconds[5], bake_seconds);
    fprintf(stderr, "  domains %d, total rank %d (", v->ndomains, v->rank_total);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].rank);
    fprintf(stderr, "), cubature tets %d (", v->ncub);
    for (int32_t d = 0; d < v->ndomains; ++d)
        fprintf(stderr, "%s%d", d ? " " : "", v->domains[d].cub_count);
    fprintf(stderr, "), worst cubature fit %.4f\n", res.cubature_error_max);
    fprintf(stderr,
            "  poses: %d training, %d held-out; basis projection error train %.4f held-out %.4f\n",
            res.ntrain, res.nheldout, res.train_proj_error, res.heldout_proj_error);
    if (res.train_unsettled + res.heldout_unsettled > 0)
        fprintf(
            stderr,
            "  reference: the contact round cap left the contact set unsettled in %d training and "
            "%d held-out solutions (their fold depends on the cap)\n",
            res.train_unsettled, res.heldout_unsettled);
    fprintf(stderr,
            "  correction error (subspace vs full, share of the correction missed): train %.4f, "
            "held-out %.4f (%d failed steps)\n",
            et.correction_error, eh.correction_error, et.failed + eh.failed);
    if (p.compare_selectors) {
        static const char *names[3] = {"greedy", "importance", "nnhtp"};
        for (int s = 0; s < 3; ++s)
            fprintf(stderr, "  selector %-10s %6d tets  %8.2f s  worst fit %.4f\n", names[s],
                    res.selector_points[s], res.selector_seconds[s], res.selector_error[s]);
    }
    if (json) {
        printf("{\"blob\":\"%s\",\"tets\":%d,\"verts\":%d,\"bones\":%d,\"domains\":%d,\"rank\":%d,"
               "\"cubature_tets\":%d,\"cubature_fit\":%.5f,\"train_poses\":%d,\"heldout_poses\":%d,"
               "\"proj_err_train\":%.5f,\"proj_err_heldout\":%.5f,\"err_train\":%.5f,\"err_"
               "heldout\":%.5f,"
               "\"ref_unsettled_train\":%d,\"ref_unsettled_heldout\":%d,"
               "\"bake_seconds\":%.2f,\"eval_seconds\":%.2f,\"stage_seconds\":[%.2f,%.2f,%.2f,%.2f,"
               "%.2f,%.2f]",
               out_path, ch.mesh.ntets, ch.mesh.nverts, ch.skel.nbones, v->ndomains, v->rank_total,
               v->ncub, res.cubature_error_max, res.ntrain, res.nheldout, res.train_proj_error,
               res.heldout_proj_error, et.correction_error, eh.correction_error,
               res.train_unsettled, res.heldout_unsettled, bake_seconds, eval_seconds,
               res.stage_seconds[0], res.stage_seconds[1], res.stage_seconds[2],
               res.stage_seconds[3], res.stage_seconds[4], res.stage_seconds[5]);
        if (p.compare_selectors)
            printf(",\"selectors\":{\"greedy\":[%d,%.3f,%.4f],\"importance\":[%d,%.3f,%.4f],"
                   "\"nnhtp\":[%d,%.3f,%.4f]}",
                   res.selector_points[0], res.selector_seconds[0], res.selector_error[0],
                   res.selector_points[1], res.selector_seconds[1], res.selector_error[1],
                   res.selector_points[2], res.selector_seconds[2], res.selector_error[2]);
        printf("}\n");
    }
    sinew_blob_destroy(blob);
    sw_bake_result_free(&res);
    sw_character_free(&ch);
    return 0;
}
