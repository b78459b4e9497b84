/* Line-tracking tokenizer shared by every asset reader (see text_reader.h). */
#include "text_reader.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sw_mesh.h"

/* Files above this are refused: every count we store is int32 anyway. */
#define SW_TEXT_MAX_BYTES ((size_t)1 << 31)

sinew_result sw_text_open(sw_text_reader *r, const char *path, char comment, sw_error *err) {
    memset(r, 0, sizeof *r);
    r->path = path ? path : "(null)";
    r->err = err;
    r->comment = comment;
    r->line = r->tline = 1;
    if (!path) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "no file path given");
    FILE *f = fopen(path, "rb");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap + 1);
    int oom = !buf;
    while (!oom) {
        if (len == cap) {
            if (cap >= SW_TEXT_MAX_BYTES) {
                free(buf);
                fclose(f);
                return sw_error_set(err, SINEW_ERROR_IO, "%s: file larger than %zu bytes", path,
                                    SW_TEXT_MAX_BYTES);
            }
            char *nb = realloc(buf, 2 * cap + 1);
            if (!nb) {
                oom = 1;
                break;
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) break;
    }
    if (oom) {
        free(buf);
        fclose(f);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory reading file", path);
    }
    int bad = ferror(f);
    int saved = errno;
    fclose(f);
    if (bad) {
        free(buf);
        return sw_error_set(err, SINEW_ERROR_IO, "%s: read error: %s", path, strerror(saved));
    }
    buf[len] = '\0';
    r->buf = buf;
    r->len = len;
    return SINEW_OK;
}

sinew_result sw_text_open_mem(sw_text_reader *r, const char *name, const void *data, size_t len,
                              char comment, sw_error *err) {
    memset(r, 0, sizeof *r);
    r->path = name ? name : "<text>";
    r->err = err;
    r->comment = comment;
    r->line = r->tline = 1;
    if (!data && len)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "%s: no text given", r->path);
    if (len > SW_TEXT_MAX_BYTES)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: text larger than %zu bytes", r->path,
                            SW_TEXT_MAX_BYTES);
    char *buf = malloc(len + 1);
    if (!buf)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory reading text",
                            r->path);
    if (len) memcpy(buf, data, len);
    buf[len] = '\0';
    r->buf = buf;
    r->len = len;
    return SINEW_OK;
}

void sw_text_close(sw_text_reader *r) {
    if (!r) return;
    free(r->buf);
    r->buf = NULL;
    r->len = r->pos = 0;
}

static int is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/* Skips blanks and a comment on the current line; stops at '\n' or the end. */
static void skip_blanks(sw_text_reader *r) {
    while (r->pos < r->len && is_blank(r->buf[r->pos]))
        r->pos++;
    if (r->comment && r->pos < r->len && r->buf[r->pos] == r->comment)
        while (r->pos < r->len && r->buf[r->pos] != '\n')
            r->pos++;
}

static size_t take_token(sw_text_reader *r, const char **tok) {
    size_t start = r->pos;
    while (r->pos < r->len && !is_blank(r->buf[r->pos]) && r->buf[r->pos] != '\n' &&
           !(r->comment && r->buf[r->pos] == r->comment))
        r->pos++;
    *tok = r->buf + start;
    r->tline = r->line;
    return r->pos - start;
}

size_t sw_text_word(sw_text_reader *r, const char **tok) {
    skip_blanks(r);
    *tok = r->buf + r->pos;
    if (r->pos >= r->len || r->buf[r->pos] == '\n') {
        r->tline = r->line;
        return 0;
    }
    return take_token(r, tok);
}

size_t sw_text_token(sw_text_reader *r, const char **tok) {
    for (;;) {
        skip_blanks(r);
        if (r->pos >= r->len) {
            *tok = r->buf + r->pos;
            r->tline = sw_text_eof_line(r);
            return 0;
        }
        if (r->buf[r->pos] != '\n') return take_token(r, tok);
        r->pos++;
        r->line++;
    }
}

int sw_text_next_line(sw_text_reader *r) {
    while (r->pos < r->len && r->buf[r->pos] != '\n')
        r->pos++;
    if (r->pos >= r->len) return 0;
    r->pos++;
    r->line++;
    return r->pos < r->len;
}

int sw_text_skip_blank_lines(sw_text_reader *r) {
    for (;;) {
        skip_blanks(r);
        if (r->pos >= r->len) return 0;
        if (r->buf[r->pos] != '\n') {
            /* back to the line start so that callers read the line from its beginning */
            while (r->pos > 0 && r->buf[r->pos - 1] != '\n')
                r->pos--;
            return 1;
        }
        r->pos++;
        r->line++;
    }
}

size_t sw_text_remaining(const sw_text_reader *r) {
    return r->len - r->pos;
}

int64_t sw_text_eof_line(const sw_text_reader *r) {
    int64_t line = 1;
    for (size_t i = 0; i < r->len; ++i)
        if (r->buf[i] == '\n' && i + 1 < r->len) line++;
    return line;
}

/* Copies a token into a NUL-terminated scratch buffer (tokens longer than any sane
 * number are rejected), so that strtod/strtoll can never run past the token. */
static int copy_token(const char *tok, size_t n, char *out, size_t cap) {
    if (n == 0 || n >= cap) return 0;
    memcpy(out, tok, n);
    out[n] = '\0';
    return strlen(out) == n; /* an embedded NUL byte is garbage */
}

int sw_parse_int(const char *tok, size_t n, int64_t *v) {
    char s[32], *end;
    if (!copy_token(tok, n, s, sizeof s)) return 0;
    if (!((s[0] >= '0' && s[0] <= '9') || s[0] == '-' || s[0] == '+')) return 0;
    errno = 0;
    long long x = strtoll(s, &end, 10);
    if (errno == ERANGE || *end != '\0' || end == s) return 0;
    *v = (int64_t)x;
    return 1;
}

int sw_parse_double(const char *tok, size_t n, double *v) {
    char s[128], *end;
    if (!copy_token(tok, n, s, sizeof s)) return 0;
    /* strtod would also skip leading blanks and take hex; a token has no blanks, and we
     * want only decimal numbers and nan/inf spellings. */
    if (strchr(s, 'x') || strchr(s, 'X')) return 0;
    double x = strtod(s, &end); /* ERANGE underflow (denormals) is fine; overflow = inf */
    if (*end != '\0' || end == s) return 0;
    *v = x;
    return 1;
}

sinew_result sw_text_fail(const sw_text_reader *r, int64_t line, sinew_result code, const char *fmt,
                          ...) {
    if (!r->err) return code;
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return sw_error_set(r->err, code, "%s:%lld: %s", r->path, (long long)line, what);
}

/* A token quoted for a message: at most 24 bytes, non-printables as '?'. */
static void quote(const char *tok, size_t n, char out[32]) {
    size_t k = n < 24 ? n : 24;
    for (size_t i = 0; i < k; ++i)
        out[i] = (tok[i] >= 32 && tok[i] < 127) ? tok[i] : '?';
    if (n > k) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = '\0';
}

static sinew_result missing(sw_text_reader *r, int same_line, const char *what) {
    if (r->pos >= r->len)
        return sw_text_fail(r, sw_text_eof_line(r), SINEW_ERROR_PARSE,
                            "unexpected end of file: expected %s", what);
    (void)same_line;
    return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "line ends early: expected %s", what);
}

sinew_result sw_text_int(sw_text_reader *r, int same_line, const char *what, int64_t *v) {
    const char *t;
    size_t n = same_line ? sw_text_word(r, &t) : sw_text_token(r, &t);
    if (n == 0) return missing(r, same_line, what);
    if (!sw_parse_int(t, n, v)) {
        char q[32];
        quote(t, n, q);
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "expected %s (an integer), found '%s'",
                            what, q);
    }
    return SINEW_OK;
}

sinew_result sw_text_double(sw_text_reader *r, int same_line, const char *what, double *v) {
    const char *t;
    size_t n = same_line ? sw_text_word(r, &t) : sw_text_token(r, &t);
    if (n == 0) return missing(r, same_line, what);
    char q[32];
    if (!sw_parse_double(t, n, v)) {
        quote(t, n, q);
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "expected %s (a number), found '%s'",
                            what, q);
    }
    if (!isfinite(*v)) {
        quote(t, n, q);
        return sw_text_fail(r, r->tline, SINEW_ERROR_NOT_FINITE, "%s is not finite ('%s')", what,
                            q);
    }
    return SINEW_OK;
}

sinew_result sw_text_number(sw_text_reader *r, int same_line, const char *what) {
    const char *t;
    double v;
    size_t n = same_line ? sw_text_word(r, &t) : sw_text_token(r, &t);
    if (n == 0) return missing(r, same_line, what);
    if (!sw_parse_double(t, n, &v)) {
        char q[32];
        quote(t, n, q);
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "expected %s (a number), found '%s'",
                            what, q);
    }
    return SINEW_OK;
}

sinew_result sw_text_expect_eol(sw_text_reader *r, const char *after) {
    const char *t;
    size_t n = sw_text_word(r, &t);
    if (n == 0) return SINEW_OK;
    char q[32];
    quote(t, n, q);
    return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "unexpected token '%s' after %s", q, after);
}

sinew_result sw_text_check_count(sw_text_reader *r, int64_t count, int64_t tokens_each,
                                 const char *what) {
    if (count < 0)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "negative %s count %lld", what,
                            (long long)count);
    if (count > 1000000000)
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE, "absurd %s count %lld (above 1e9)",
                            what, (long long)count);
    /* every token takes at least one byte and one separator */
    int64_t need = count * tokens_each * 2 - 1;
    if (count > 0 && need > (int64_t)sw_text_remaining(r))
        return sw_text_fail(r, r->tline, SINEW_ERROR_PARSE,
                            "%lld %s cannot fit in the %zu bytes left in the file (truncated?)",
                            (long long)count, what, sw_text_remaining(r));
    return SINEW_OK;
}

int sw_grow(void **p, size_t *cap, size_t need, size_t size) {
    if (need <= *cap) return 1;
    size_t nc = *cap ? *cap : 64;
    while (nc < need)
        nc *= 2;
    void *np = realloc(*p, nc * size);
    if (!np) return 0;
    *p = np;
    *cap = nc;
    return 1;
}

sinew_result sw_text_check_tets(const sw_text_reader *r, const char *format, int64_t base,
                                int32_t nverts, const double *X, int32_t ntets, int32_t *raw,
                                const int64_t *lines) {
    for (int32_t t = 0; t < ntets; ++t) {
        int32_t *q = raw + 4 * (size_t)t;
        for (int k = 0; k < 4; ++k) {
            if (q[k] < base || (int64_t)q[k] >= base + nverts)
                return sw_text_fail(r, lines[t], SINEW_ERROR_PARSE,
                                    "tet %d references vertex %d, outside %lld..%lld (%s indices "
                                    "are %lld-based)",
                                    t + (int32_t)base, q[k], (long long)base,
                                    (long long)(base + nverts - 1), format, (long long)base);
            q[k] -= (int32_t)base;
        }
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < k; ++j)
                if (q[j] == q[k])
                    return sw_text_fail(r, lines[t], SINEW_ERROR_DEGENERATE,
                                        "tet %d repeats vertex %lld", t + (int32_t)base,
                                        (long long)(q[k] + base));
        double vol = sw_tet_signed_volume(X + 3 * (size_t)q[0], X + 3 * (size_t)q[1],
                                          X + 3 * (size_t)q[2], X + 3 * (size_t)q[3]);
        if (!isfinite(vol)) /* finite coordinates whose products overflow */
            return sw_text_fail(r, lines[t], SINEW_ERROR_NOT_FINITE,
                                "tet %d has a volume that overflows (coordinates too large)",
                                t + (int32_t)base);
        if (vol == 0.0)
            return sw_text_fail(r, lines[t], SINEW_ERROR_DEGENERATE, "tet %d has zero volume",
                                t + (int32_t)base);
        if (vol < 0.0) { /* our convention is det > 0 (sw_mesh.h): swap two vertices */
            int32_t s = q[1];
            q[1] = q[2];
            q[2] = s;
        }
    }
    return SINEW_OK;
}

sinew_result sw_text_validate_tets(const sw_text_reader *r, const sw_tetmesh *m) {
    sw_error e;
    sw_error_clear(&e);
    sinew_result rc = sw_tetmesh_validate(m, 0.0, &e);
    if (rc) return sw_error_set(r->err, rc, "%s: %s", r->path, e.msg);
    return SINEW_OK;
}
