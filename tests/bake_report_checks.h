/* Checks of the bake report's parts an artist reads first (test_bake_report.c): the
 * verdict (consistent with the figures, naming the joints to train further on a miss),
 * the contact sheet (named columns, numbered frames, a legend, surfaces coloured by their
 * distance from the reference: none on the reference itself, some where the others part
 * from it) and the plots' axis names, target line and stage times. */
#ifndef SW_BAKE_REPORT_CHECKS_H
#define SW_BAKE_REPORT_CHECKS_H

#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_report.h"
#include "sw_test.h"
#include "text5x7.h"

/* DIR/name parsed (NULL when it cannot be read or parsed). */
static cJSON *report_load_json(const char *dir) {
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.json", dir);
    size_t n;
    char *text = sw_test_read_file(path, &n);
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    free(text);
    return j;
}

static char *report_load_html(const char *dir) {
    char path[1100];
    snprintf(path, sizeof path, "%.1000s/report.html", dir);
    size_t n;
    return sw_test_read_file(path, &n);
}

static const char *json_str(const cJSON *o, const char *key) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsString(v) ? v->valuestring : "";
}

/* The verdict of DIR's report: pass exactly when the held-out error is within the target
 * (target_given in (0, 1), else the default); on a miss, advice and the joints to add
 * motion for: the joints beyond training when there are any, else the bones whose flesh
 * holds the held-out error (eh's regions). The status into status[16] ("" when absent). */
static void check_verdict(const char *dir, double err_heldout, double target_given,
                          const sw_eval_result *eh, char *status) {
    status[0] = 0;
    cJSON *j = report_load_json(dir);
    char *html = report_load_html(dir);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(j, "verdict");
    ENSURE(j && html && cJSON_IsObject(v));
    if (!j || !html || !cJSON_IsObject(v)) goto done;
    double target = target_given > 0 && target_given < 1 ? target_given : SW_BAKE_REPORT_TARGET;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(v, "target"),
                *pass = cJSON_GetObjectItemCaseSensitive(v, "pass");
    ENSURE(cJSON_IsNumber(t) && fabs(t->valuedouble - target) <= 1e-12 * target);
    ENSURE(!strcmp(json_str(v, "target_source"), target == target_given ? "given" : "default"));
    snprintf(status, 16, "%s", json_str(v, "status"));
    const char *want = !isfinite(err_heldout)  ? "not_measured"
                       : err_heldout <= target ? "pass"
                                               : "miss";
    ENSUREF(!strcmp(status, want), "verdict %s, held-out %g against %g", status, err_heldout,
            target);
    ENSURE(!strcmp(want, "not_measured")
               ? cJSON_IsNull(pass)
               : cJSON_IsBool(pass) && cJSON_IsTrue(pass) == !strcmp(want, "pass"));
    const char *head = json_str(v, "headline"), *advice = json_str(v, "advice");
    const char *word = !strcmp(want, "pass") ? "Pass" : !strcmp(want, "miss") ? "Miss" : "Not";
    ENSUREF(!strncmp(head, word, strlen(word)), "headline '%s'", head);
    /* first on the page: the verdict's box before any section */
    char box[64];
    snprintf(box, sizeof box, "class=\"verdict %s\"",
             !strcmp(want, "pass")   ? "pass"
             : !strcmp(want, "miss") ? "miss"
                                     : "unknown");
    const char *at = strstr(html, box), *h2 = strstr(html, "<h2");
    ENSUREF(at && (!h2 || at < h2), "the verdict %s first on the page", box);
    const cJSON *add = cJSON_GetObjectItemCaseSensitive(v, "add_motion"),
                *bt = cJSON_GetObjectItemCaseSensitive(j, "heldout_beyond_training");
    int nadd = cJSON_GetArraySize(add), nbt = cJSON_GetArraySize(bt);
    if (strcmp(want, "miss")) {
        ENSURE(nadd == 0 && !strcmp(json_str(v, "add_motion_for"), "none"));
    } else if (nbt > 0) { /* the joints beyond training, as the report lists them */
        ENSURE(strlen(advice) > 40 && strstr(advice, "further than any training pose"));
        ENSURE(!strcmp(json_str(v, "add_motion_for"), "joints_beyond_training") && nadd == nbt);
        for (int k = 0; k < nadd && nadd == nbt; ++k)
            ENSURE(
                cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(add, k), "bone")->valuedouble ==
                cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(bt, k), "bone")->valuedouble);
    } else { /* the bones that hold the error, each with its share, largest first */
        ENSURE(strlen(advice) > 40 && strstr(advice, "Most of the error is in the flesh around"));
        ENSURE(!strcmp(json_str(v, "add_motion_for"), "joints_with_error") && nadd >= 1 &&
               nadd <= eh->nregions);
        for (int k = 0; k < nadd && nadd <= eh->nregions; ++k) {
            const cJSON *o = cJSON_GetArrayItem(add, k);
            ENSURE(cJSON_GetObjectItemCaseSensitive(o, "bone")->valuedouble == eh->region_bone[k]);
            /* cJSON prints 15 digits where they read back within an ulp */
            ENSURE(fabs(cJSON_GetObjectItemCaseSensitive(o, "err_share")->valuedouble -
                        eh->region_err[k]) <= 1e-12 &&
                   eh->region_err[k] >= 0.1);
        }
    }
done:
    cJSON_Delete(j);
    free(html);
}

/* Pixels of an RGB PNG sinew's writer made (stored deflate blocks, filter 0) whose red
 * exceeds their blue by more than 60 (the ramp's warm end; the pale start, the ground and
 * the background never do); -1 when it cannot be read. */
static long warm_pixels(const char *path) {
    size_t n;
    uint8_t *f = (uint8_t *)sw_test_read_file(path, &n);
    if (!f || n < 33) return free(f), -1;
#define BE32(p) ((uint32_t)(p)[0] << 24 | (uint32_t)(p)[1] << 16 | (uint32_t)(p)[2] << 8 | (p)[3])
    uint32_t w = BE32(f + 16);
    uint8_t *z = malloc(n), *raw = malloc(n);
    size_t zlen = 0, out = 0;
    for (size_t pos = 8; z && raw && pos + 12 <= n;) {
        uint32_t len = BE32(f + pos);
        if (!memcmp(f + pos + 4, "IDAT", 4) && pos + 12 + len <= n)
            memcpy(z + zlen, f + pos + 8, len), zlen += len;
        pos += 12 + (size_t)len;
    }
    for (size_t zp = 2; z && raw && zp + 5 <= zlen;) { /* after the zlib header */
        unsigned last = z[zp] & 1, len = z[zp + 1] | (unsigned)z[zp + 2] << 8;
        if (zp + 5 + len > zlen) break;
        memcpy(raw + out, z + zp + 5, len);
        out += len;
        zp += 5 + len;
        if (last) break;
    }
#undef BE32
    long warm = z && raw ? 0 : -1;
    for (size_t row = 0; warm >= 0 && (row + 1) * (1 + 3 * (size_t)w) <= out; ++row)
        for (uint32_t x = 0; x < w; ++x) {
            const uint8_t *p = raw + row * (1 + 3 * (size_t)w) + 1 + 3 * (size_t)x;
            warm += p[0] > p[2] + 60;
        }
    free(f);
    free(z);
    free(raw);
    return warm;
}

/* The ramp and the colouring by distance: pale at the reference, warmer further away,
 * saturating at the scale; a triangle moved off the reference coloured apart from one
 * that was not. */
static void check_ramp(void) {
    float c0[3], c1[3], c2[3], c3[3];
    sw_bake_report_ramp(0, c0);
    sw_bake_report_ramp(0.5, c1);
    sw_bake_report_ramp(1, c2);
    sw_bake_report_ramp(7, c3);
    ENSURE(!memcmp(c0, sw_bake_report_ramp_stops[0], sizeof c0));
    ENSURE(!memcmp(c3, c2, sizeof c0)); /* past the scale: the top colour */
    ENSURE(c0[0] - c0[2] < 0.1f && c1[0] - c1[2] > 0.3f && c2[0] - c2[2] > 0.5f);
    /* two triangles, the second's far corner 0.5 off the reference (scale 1) */
    const double ref[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    double X[12];
    memcpy(X, ref, sizeof X);
    X[11] = 1.5; /* vertex 3 moved 1.5 along z: the second triangle's mean distance 0.5 */
    const int32_t tris[6] = {0, 1, 2, 1, 3, 2};
    float rgb[6];
    sw_bake_report_diff_colors(4, X, ref, 2, tris, 1.0, rgb);
    ENSURE(fabsf(rgb[0] - rgb[2]) < 0.1f); /* on the reference: pale */
    ENSUREF(rgb[3] - rgb[5] > 0.3f, "%g %g %g", rgb[3], rgb[4], rgb[5]); /* off it: warm */
}

/* The sheet's own labels (text5x7.h): a glyph's pixels where its bits are, at its scale,
 * clipped at the image's edge, and widths of 6 font pixels a character less the last gap. */
static void check_font(void) {
    uint8_t img[3 * 20 * 20];
    memset(img, 255, sizeof img);
    static const uint8_t ink[3] = {0, 0, 0};
    sw_draw_text(img, 20, 20, 1, 1, 2, "0", ink); /* 19 set bits in the 0 glyph */
    int dark = 0;
    for (int p = 0; p < 20 * 20; ++p)
        dark += img[3 * p] == 0;
    ENSUREF(dark == 4 * 19, "%d pixels", dark);
    sw_draw_text(img, 20, 20, 15, 15, 2, "0", ink); /* mostly off the image: no write past it */
    ENSURE(sw_text_width("AB", 2) == 22 && sw_text_width("", 3) == 0);
}

/* The contact sheet: the figures in the JSON (a row a held-out pose, the reference column
 * at distance 0, the scale the largest distance), its labels on the page, and tiles
 * coloured by distance (no warm pixel on the reference, some on the others). */
static void check_sheet(const char *dir, const sw_bake_result *res) {
    cJSON *j = report_load_json(dir);
    char *html = report_load_html(dir);
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(j, "contact_sheet_tiles"),
                *rows = cJSON_GetObjectItemCaseSensitive(s, "rows");
    int32_t nrows =
        res->nheldout < SW_BAKE_REPORT_SHEET_ROWS ? res->nheldout : SW_BAKE_REPORT_SHEET_ROWS;
    ENSURE(html && cJSON_GetArraySize(rows) == nrows);
    if (!html || cJSON_GetArraySize(rows) != nrows) goto done;
    ENSURE(strstr(html, "<th>reference (full simulation)</th><th>sinew (the runtime)</th>"
                        "<th>plain skinning</th>") &&
           strstr(html, "distance from the reference") && strstr(html, "class=\"ramp\""));
    double scale = cJSON_GetObjectItemCaseSensitive(s, "color_scale")->valuedouble, largest = 0;
    long warm[SW_SHEET_COLS] = {0, 0, 0};
    for (int32_t row = 0; row < nrows; ++row) {
        const cJSON *o = cJSON_GetArrayItem(rows, row);
        int32_t k = cJSON_GetObjectItemCaseSensitive(o, "heldout_pose")->valueint;
        ENSURE(k >= 0 && k < res->nheldout);
        if (k < 0 || k >= res->nheldout) continue;
        ENSURE(cJSON_GetObjectItemCaseSensitive(o, "frame")->valueint == res->heldout_frame[k]);
        char label[64];
        snprintf(label, sizeof label, "<th class=\"frame\">frame %d", res->heldout_frame[k]);
        ENSUREF(strstr(html, label) != NULL, "row %d numbered: %s", row, label);
        const cJSON *mx = cJSON_GetObjectItemCaseSensitive(o, "max_dist");
        ENSURE(cJSON_GetArrayItem(mx, SW_SHEET_REFERENCE)->valuedouble == 0);
        for (int c = 0; c < SW_SHEET_COLS; ++c) {
            largest = fmax(largest, cJSON_GetArrayItem(mx, c)->valuedouble);
            char name[64], path[1200];
            sw_bake_report_tile_name(name, sizeof name, row, c);
            ENSURE(strstr(html, name) != NULL);
            snprintf(path, sizeof path, "%.1000s/%s", dir, name);
            long w = warm_pixels(path);
            ENSUREF(w >= 0, "%s readable", path);
            warm[c] += w;
        }
    }
    ENSURE(scale > 0 && fabs(scale - largest) <= 1e-12 * scale);
    ENSUREF(warm[SW_SHEET_REFERENCE] == 0 && warm[SW_SHEET_SKINNING] > 0,
            "warm pixels: reference %ld, sinew %ld, skinning %ld", warm[0], warm[1], warm[2]);
done:
    cJSON_Delete(j);
    free(html);
}

/* The plots: axis names, the target line, every stage named in the stage times. */
static void check_plots(const char *dir) {
    char *html = report_load_html(dir);
    ENSURE(html && strstr(html, ">clip frame<") && strstr(html, ">error (share missed)<") &&
           strstr(html, "class=\"target\"") && strstr(html, "Where the bake's time went"));
    cJSON *j = report_load_json(dir);
    const cJSON *st = cJSON_GetObjectItemCaseSensitive(j, "stages");
    for (int k = 0; html && k < cJSON_GetArraySize(st); ++k) {
        char label[64];
        snprintf(label, sizeof label, ">%s</text>", json_str(cJSON_GetArrayItem(st, k), "name"));
        ENSUREF(strstr(html, label) != NULL, "stage %s labelled", label);
    }
    /* plain words, the model's term kept in a tooltip */
    ENSURE(html && strstr(html, "best the runtime's solver can reach") &&
           strstr(html, "title=\"Galerkin projection error"));
    cJSON_Delete(j);
    free(html);
}

#endif
