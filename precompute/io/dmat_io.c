/* libigl .dmat dense matrices and the skin-weight reader built on them.
 *
 * ASCII:  "cols rows\n" then cols*rows numbers, column-major (columns run slowest).
 * Binary: "0 0\n" (an empty ASCII matrix, so old readers stop there), then
 *         "cols rows\n" and exactly cols*rows little-endian float64, column-major.
 * (Layout as libigl readDMAT/writeDMAT: one '\n' or '\r' ends each header line.)
 * We return row-major data, so the readers transpose. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_io.h"
#include "text_reader.h"

/* Reads "cols rows" on the current line; `binary_header` requires the single
 * newline byte libigl expects right after it, and leaves the cursor past it. */
static sinew_result read_header(sw_text_reader *r, int binary_header, int64_t *cols,
                                int64_t *rows) {
    sinew_result rc = sw_text_int(r, 1, "column count", cols);
    if (!rc) rc = sw_text_int(r, 1, "row count", rows);
    if (rc) return rc;
    if (*cols < 0 || *rows < 0 || *cols > 1000000000 || *rows > 1000000000)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "bad matrix size %lld x %lld",
                            (long long)*rows, (long long)*cols);
    if (binary_header) {
        if (r->pos >= r->len || (r->buf[r->pos] != '\n' && r->buf[r->pos] != '\r'))
            return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                                "binary header must end with one newline");
        r->pos++;
        return SINEW_OK;
    }
    return sw_text_expect_eol(r, "the \"cols rows\" header");
}

static uint64_t load_le64(const unsigned char *p) {
    uint64_t u = 0;
    for (int k = 7; k >= 0; --k)
        u = (u << 8) | p[k];
    return u;
}

static sinew_result read_binary(sw_text_reader *r, int64_t *rows, int64_t *cols, double **data) {
    int64_t c, n;
    sw_text_next_line(r);
    if (!sw_text_skip_blank_lines(r))
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE,
                            "unexpected end of file: expected the binary \"cols rows\" header");
    sinew_result rc = read_header(r, 1, &c, &n);
    if (rc) return rc;
    int64_t line = r->tline + 1;
    uint64_t want = (uint64_t)c * (uint64_t)n * 8u;
    size_t have = sw_text_remaining(r);
    if (want > have)
        return sw_text_fail(r, line, SINEW_ERROR_PARSE,
                            "binary data truncated: %lld x %lld needs %llu bytes, %zu left",
                            (long long)n, (long long)c, (unsigned long long)want, have);
    if (want < have)
        return sw_text_fail(r, line, SINEW_ERROR_PARSE,
                            "%llu bytes after the %lld x %lld binary data (wrong size header?)",
                            (unsigned long long)(have - want), (long long)n, (long long)c);
    double *d = want ? malloc((size_t)want) : NULL; /* empty: NULL, as the ASCII reader */
    if (want && !d) return sw_text_fail(r, line, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    const unsigned char *p = (const unsigned char *)r->buf + r->pos;
    for (int64_t j = 0; j < (n ? c : 0); ++j) /* "1000000000 0" is empty: no empty loops */
        for (int64_t i = 0; i < n; ++i, p += 8) {
            uint64_t u = load_le64(p);
            double x;
            memcpy(&x, &u, sizeof x);
            if (!isfinite(x)) {
                free(d);
                return sw_text_fail(r, line, SINEW_ERROR_NOT_FINITE,
                                    "binary value at row %lld, column %lld is not finite",
                                    (long long)i, (long long)j);
            }
            d[i * c + j] = x;
        }
    *rows = n;
    *cols = c;
    *data = d;
    return SINEW_OK;
}

static sinew_result read_ascii(sw_text_reader *r, int64_t rows, int64_t cols, double **data) {
    sinew_result rc;
    sw_text_next_line(r);
    if ((rc = sw_text_check_count(r, rows * cols, 1, "matrix values"))) return rc;
    double *d = malloc((size_t)(rows * cols > 0 ? rows * cols : 1) * sizeof(double));
    if (!d) return sw_text_fail(r, r->tline, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int64_t j = 0; j < cols; ++j)
        for (int64_t i = 0; i < rows; ++i)
            if ((rc = sw_text_double(r, 0, "matrix value", d + i * cols + j))) {
                free(d);
                return rc;
            }
    const char *t;
    if (sw_text_token(r, &t) > 0) {
        free(d);
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "more values than the %lld x %lld header declares", (long long)rows,
                            (long long)cols);
    }
    *data = d;
    return SINEW_OK;
}

/* Parses the opened reader `r` (outputs zeroed by the caller) and closes it. */
static sinew_result read_dmat(sw_text_reader *r, int32_t *rows, int32_t *cols, double **data) {
    sinew_result rc = SINEW_OK;
    int64_t c = 0, n = 0;
    double *d = NULL;
    if (!sw_text_skip_blank_lines(r))
        rc = sw_text_fail(r, 1, SINEW_ERROR_PARSE, "empty file: expected \"cols rows\" header");
    if (!rc) rc = read_header(r, 0, &c, &n);
    if (!rc && c > INT32_MAX / (n ? n : 1)) /* product must index an int32 array */
        rc = sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "matrix %lld x %lld is too large",
                          (long long)n, (long long)c);
    if (!rc) {
        size_t save = r->pos;
        int64_t line = r->line;
        const char *t;
        if (c == 0 && n == 0 && sw_text_token(r, &t) > 0) { /* binary part follows */
            r->pos = save;
            r->line = line;
            rc = read_binary(r, &n, &c, &d);
        } else if (c * n > 0) {
            r->pos = save;
            r->line = line;
            rc = read_ascii(r, n, c, &d);
        } else if (sw_text_token(r, &t) > 0) { /* "3 0", "0 3": no values may follow */
            rc = sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                              "values after the empty %lld x %lld matrix the header declares",
                              (long long)n, (long long)c);
        }
    }
    if (!rc && c > INT32_MAX / (n ? n : 1)) {
        rc = sw_text_fail(r, 2, SINEW_ERROR_PARSE, "matrix %lld x %lld is too large", (long long)n,
                          (long long)c);
    }
    sw_text_close(r);
    if (rc) {
        free(d);
        return rc;
    }
    *rows = (int32_t)n;
    *cols = (int32_t)c;
    *data = d;
    return SINEW_OK;
}

sinew_result sw_read_dmat(const char *path, int32_t *rows, int32_t *cols, double **data,
                          sw_error *err) {
    if (rows) *rows = 0;
    if (cols) *cols = 0;
    if (data) *data = NULL;
    if (!rows || !cols || !data)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_dmat: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open(&r, path, 0, err);
    return rc ? rc : read_dmat(&r, rows, cols, data);
}

sinew_result sw_parse_dmat(const char *text, size_t len, const char *name_for_errors, int32_t *rows,
                           int32_t *cols, double **data, sw_error *err) {
    if (rows) *rows = 0;
    if (cols) *cols = 0;
    if (data) *data = NULL;
    if (!rows || !cols || !data)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_dmat: no output");
    sw_text_reader r;
    sinew_result rc = sw_text_open_mem(&r, name_for_errors, text, len, 0, err);
    return rc ? rc : read_dmat(&r, rows, cols, data);
}

static void store_le64(double x, unsigned char *p) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    for (int k = 0; k < 8; ++k)
        p[k] = (unsigned char)(u >> (8 * k));
}

sinew_result sw_write_dmat(const char *path, int32_t rows, int32_t cols, const double *data,
                           int binary, sw_error *err) {
    if (!path || rows < 0 || cols < 0 || ((int64_t)rows * cols > 0 && !data))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_write_dmat: bad arguments");
    FILE *f = fopen(path, binary ? "wb" : "w");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open for writing", path);
    if (binary) {
        fprintf(f, "0 0\n%d %d\n", cols, rows);
        unsigned char b[8];
        for (int32_t j = 0; j < cols; ++j)
            for (int32_t i = 0; i < rows; ++i) {
                store_le64(data[(size_t)i * cols + j], b);
                fwrite(b, 1, 8, f);
            }
    } else {
        fprintf(f, "%d %d\n", cols, rows);
        for (int32_t j = 0; j < cols; ++j)
            for (int32_t i = 0; i < rows; ++i)
                fprintf(f, "%.17g\n", data[(size_t)i * cols + j]);
    }
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) return sw_error_set(err, SINEW_ERROR_IO, "%s: write failed", path);
    return SINEW_OK;
}

/* Checks and normalises the rows x cols matrix `w` (owned; freed on error) read from
 * `path` as the weights of nverts x nbones. */
static sinew_result weights_from(const char *path, int32_t rows, int32_t cols, double *w,
                                 int32_t nverts, int32_t nbones, sw_weights *out, sw_error *err) {
    sinew_result rc = SINEW_OK;
    if (rows > 0 && cols < 1) { /* a vertex with no bone columns cannot be normalised */
        free(w);
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "%s:1: weights of %d vertices for no bone",
                            path, rows);
    }
    if (rows != nverts || cols != nbones) {
        free(w);
        return sw_error_set(err, SINEW_ERROR_PARSE,
                            "%s:1: weights are %d x %d, expected %d x %d (vertices x bones)", path,
                            rows, cols, nverts, nbones);
    }
    for (int32_t v = 0; v < rows; ++v) {
        double *row = w + (size_t)v * cols, sum = 0.0;
        for (int32_t b = 0; b < cols; ++b) {
            if (row[b] < -1e-6) {
                rc = sw_error_set(err, SINEW_ERROR_PARSE, "%s: vertex %d has weight %g for bone %d",
                                  path, v, row[b], b);
                break;
            }
            if (row[b] < 0.0) row[b] = 0.0; /* round-off of the weight solver */
            sum += row[b];
        }
        if (!rc && !(sum <= DBL_MAX)) { /* finite weights whose sum overflows: the row
                                            over its largest first, then over its sum */
            double top = 0.0;
            for (int32_t b = 0; b < cols; ++b)
                top = row[b] > top ? row[b] : top;
            sum = 0.0;
            for (int32_t b = 0; b < cols; ++b)
                sum += (row[b] /= top);
        }
        if (!rc && !(sum > 0.0))
            rc = sw_error_set(err, SINEW_ERROR_DEGENERATE, "%s: vertex %d has all-zero weights",
                              path, v);
        if (rc) {
            free(w);
            return rc;
        }
        for (int32_t b = 0; b < cols; ++b)
            row[b] /= sum;
    }
    out->nverts = nverts;
    out->nbones = nbones;
    out->w = w;
    return SINEW_OK;
}

sinew_result sw_read_weights(const char *path, int32_t nverts, int32_t nbones, sw_weights *out,
                             sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_read_weights: no output");
    int32_t rows, cols;
    double *w;
    sinew_result rc = sw_read_dmat(path, &rows, &cols, &w, err);
    if (rc) return rc;
    return weights_from(path, rows, cols, w, nverts, nbones, out, err);
}

sinew_result sw_parse_weights(const char *text, size_t len, const char *name_for_errors,
                              int32_t nverts, int32_t nbones, sw_weights *out, sw_error *err) {
    if (out) memset(out, 0, sizeof *out);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_parse_weights: no output");
    int32_t rows, cols;
    double *w;
    const char *name = name_for_errors ? name_for_errors : "<text>";
    sinew_result rc = sw_parse_dmat(text, len, name, &rows, &cols, &w, err);
    if (rc) return rc;
    return weights_from(name, rows, cols, w, nverts, nbones, out, err);
}
