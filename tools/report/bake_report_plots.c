/* The bake report's plots as inline SVG (bake_report_internal.h): every plot names what
 * its axes measure, with units, and draws its target where it has one, so that a reader
 * sees at once whether a curve is good enough. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bake_report_internal.h"

#define PLOT_W 460
#define PLOT_H 200
#define PAD_L 56 /* room for the y ticks and the rotated y label */
#define PAD_R 12
#define PAD_T 12
#define PAD_B 40 /* room for the x ticks and the x label */

void html_text(FILE *f, const char *s) {
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

/* The frame of a plot: caption, axes, y ticks at 0, half and ymax, the axes' names and
 * the target line; `below` more pixels under the x axis for long tick labels. Returns the
 * y scale (pixels a unit). */
static double svg_frame(FILE *f, const plot_axes *ax, int w, int below) {
    int h = PLOT_H + below;
    fprintf(f, "<figure><figcaption>");
    html_text(f, ax->title);
    fprintf(f, "</figcaption><svg width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">", w, h, w, h);
    int y0 = PLOT_H - PAD_B;
    double sy = (y0 - PAD_T) / ax->ymax;
    fprintf(f,
            "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"#888\"/>"
            "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"#888\"/>",
            PAD_L, y0, w - PAD_R, y0, PAD_L, PAD_T, PAD_L, y0);
    for (int k = 0; k <= 2; ++k) {
        double v = ax->ymax * k / 2;
        fprintf(f,
                "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#888\"/>"
                "<text x=\"%d\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\">%.3g</text>",
                PAD_L - 4, y0 - sy * v, PAD_L, y0 - sy * v, PAD_L - 6, y0 - sy * v + 3, v);
    }
    fprintf(f, "<text x=\"%d\" y=\"%d\" font-size=\"11\" text-anchor=\"middle\">",
            (PAD_L + w - PAD_R) / 2, h - 6);
    html_text(f, ax->xname);
    fprintf(f,
            "</text><text x=\"12\" y=\"%d\" font-size=\"11\" text-anchor=\"middle\" "
            "transform=\"rotate(-90 12 %d)\">",
            (PAD_T + y0) / 2, (PAD_T + y0) / 2);
    html_text(f, ax->yname);
    fprintf(f, "</text>");
    if (isfinite(ax->target) && ax->target <= ax->ymax) {
        double y = y0 - sy * ax->target;
        fprintf(f,
                "<line class=\"target\" x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" "
                "stroke=\"#c00\" stroke-dasharray=\"5,3\"/><text x=\"%d\" y=\"%.1f\" "
                "font-size=\"10\" fill=\"#c00\" text-anchor=\"end\">",
                PAD_L, y, w - PAD_R, y, w - PAD_R, y - 3);
        html_text(f, ax->target_label ? ax->target_label : "target");
        fprintf(f, "</text>");
    }
    return sy;
}

void svg_line(FILE *f, const plot_axes *ax, const int32_t *x, const double *y, const int32_t *mark,
              int32_t n, const char *colour) {
    double sy = svg_frame(f, ax, PLOT_W, 0);
    int y0 = PLOT_H - PAD_B;
    int32_t xmin = n ? x[0] : 0, xmax = n ? x[n - 1] : 1;
    if (xmax <= xmin) xmax = xmin + 1;
    double sx = (PLOT_W - PAD_L - PAD_R) / (double)(xmax - xmin);
    fprintf(f,
            "<text x=\"%d\" y=\"%d\" font-size=\"10\" text-anchor=\"middle\">%d</text>"
            "<text x=\"%d\" y=\"%d\" font-size=\"10\" text-anchor=\"middle\">%d</text>",
            PAD_L, y0 + 13, xmin, PLOT_W - PAD_R, y0 + 13, xmax);
    for (int32_t k = 0; mark && k < n; ++k)
        if (mark[k])
            fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#c00\"/>",
                    PAD_L + sx * (x[k] - xmin), y0 + 2, PAD_L + sx * (x[k] - xmin), y0 + 6);
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", colour);
    for (int32_t k = 0; k < n; ++k)
        if (isfinite(y[k]))
            fprintf(f, "%.1f,%.1f ", PAD_L + sx * (x[k] - xmin), y0 - sy * fmin(y[k], ax->ymax));
    fprintf(f, "\"/></svg></figure>\n");
}

void svg_bars(FILE *f, const plot_axes *ax, const double *v, int32_t n, const char *const *labels,
              const char *colour) {
    plot_axes a = *ax;
    a.ymax = 0;
    for (int32_t k = 0; k < n; ++k)
        a.ymax = fmax(a.ymax, isfinite(v[k]) ? v[k] : 0);
    if (!(a.ymax > 0)) a.ymax = 1;
    /* names stand slanted under their bars, so that long bone names never overlap */
    int step = 24, w = PAD_L + (n > 0 ? n : 1) * step + PAD_R, below = labels ? 64 : 0;
    w = w < PLOT_W ? PLOT_W : w;
    double sy = svg_frame(f, &a, w, below);
    int y0 = PLOT_H - PAD_B;
    for (int32_t k = 0; k < n; ++k) {
        double h = isfinite(v[k]) ? sy * v[k] : 0;
        int x = PAD_L + 4 + step * k;
        fprintf(f,
                "<rect x=\"%d\" y=\"%.1f\" width=\"%d\" height=\"%.1f\" fill=\"%s\"><title>%.4g"
                "</title></rect>",
                x, y0 - h, step - 8, h, colour, v[k]);
        int lx = x + (step - 8) / 2;
        if (labels) {
            fprintf(f,
                    "<text x=\"%d\" y=\"%d\" font-size=\"9\" text-anchor=\"end\" "
                    "transform=\"rotate(-40 %d %d)\"><title>",
                    lx, y0 + 10, lx, y0 + 10);
            html_text(f, labels[k]);
            char cut[16];
            snprintf(cut, sizeof cut, "%.14s", labels[k]);
            fprintf(f, "</title>");
            html_text(f, cut);
            if (strlen(labels[k]) > 14) fprintf(f, "&hellip;");
        } else {
            fprintf(f, "<text x=\"%d\" y=\"%d\" font-size=\"9\" text-anchor=\"middle\">%d", lx,
                    y0 + 12, k);
        }
        fprintf(f,
                "</text><text x=\"%d\" y=\"%.1f\" font-size=\"8\" text-anchor=\"middle\">%.3g"
                "</text>",
                x + (step - 8) / 2, y0 - h - 3, v[k]);
    }
    fprintf(f, "</svg></figure>\n");
}

#define HBAR_LABEL 110 /* the labels' column */
#define HBAR_ROW 20

void svg_hbars(FILE *f, const char *title, const double *v, int32_t n, const char *const *labels,
               const char *const *tips, const char *unit, const char *colour) {
    double vmax = 0, total = 0;
    for (int32_t k = 0; k < n; ++k)
        if (isfinite(v[k])) vmax = fmax(vmax, v[k]), total += v[k];
    if (!(vmax > 0)) vmax = 1;
    int w = PLOT_W + 120, h = HBAR_ROW * (n > 0 ? n : 1) + 8, bar_w = w - HBAR_LABEL - 130;
    fprintf(f, "<figure><figcaption>");
    html_text(f, title);
    fprintf(f, "</figcaption><svg width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">", w, h, w, h);
    for (int32_t k = 0; k < n; ++k) {
        double b = isfinite(v[k]) ? bar_w * v[k] / vmax : 0;
        int y = 4 + HBAR_ROW * k;
        fprintf(f, "<g><title>");
        html_text(f, tips && tips[k] ? tips[k] : labels[k]);
        fprintf(f, "</title><text x=\"%d\" y=\"%d\" font-size=\"12\" text-anchor=\"end\">",
                HBAR_LABEL - 6, y + 13);
        html_text(f, labels[k]);
        fprintf(f,
                "</text><rect x=\"%d\" y=\"%d\" width=\"%.1f\" height=\"%d\" fill=\"%s\"/>"
                "<text x=\"%.1f\" y=\"%d\" font-size=\"11\">%.3g %s (%.0f%%)</text></g>",
                HBAR_LABEL, y + 2, b, HBAR_ROW - 6, colour, HBAR_LABEL + b + 5, y + 13, v[k], unit,
                total > 0 && isfinite(v[k]) ? 100 * v[k] / total : 0);
    }
    fprintf(f, "</svg></figure>\n");
}

void html_ramp_legend(FILE *f, double scale, double size) {
    fprintf(f, "<div class=\"legend\"><div>distance from the reference, in the character's "
               "length units (and as a share of its size)</div><div class=\"ramp\" "
               "style=\"background:linear-gradient(to right");
    for (int k = 0; k < SW_BAKE_REPORT_RAMP_STOPS; ++k) {
        const float *c = sw_bake_report_ramp_stops[k];
        fprintf(f, ",rgb(%d,%d,%d)", (int)lrintf(255 * c[0]), (int)lrintf(255 * c[1]),
                (int)lrintf(255 * c[2]));
    }
    fprintf(f, ")\"></div><div class=\"ticks\">");
    for (int k = 0; k <= 4; ++k) {
        double d = scale * k / 4;
        fprintf(f, "<span>%s%.3g", k == 4 ? "&ge; " : "", d);
        if (size > 0) fprintf(f, " (%.2g%%)", 100 * d / size);
        fprintf(f, "</span>");
    }
    fprintf(f, "</div></div>\n");
}
