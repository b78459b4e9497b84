/* Private helper of the asset readers (Medit, TetGen, OBJ, TGF, DMAT): the whole file (or
 * a caller's buffer: the sw_parse_* entries of mesh_io.h) in memory, a cursor that knows
 * its line, whitespace tokens with strict number parsing, and errors formatted
 * "path:line: what is wrong". Holding the whole file lets every reader bound a declared
 * count by the bytes that remain (an absurd count is rejected before anything is
 * allocated) and lets the DMAT reader find its binary tail. */
#ifndef SW_TEXT_READER_H
#define SW_TEXT_READER_H

#include <stddef.h>
#include <stdint.h>

#include "sw_error.h"

typedef struct sw_text_reader {
    const char *path;
    char *buf;     /* file contents followed by one NUL (the file may hold NULs too) */
    size_t len;    /* bytes in the file */
    size_t pos;    /* cursor */
    int64_t line;  /* 1-based line of the cursor */
    int64_t tline; /* line of the last token returned */
    char comment;  /* 0, or a character that comments out the rest of a line */
    sw_error *err;
} sw_text_reader;

/* Reads `path` whole. Missing or unreadable file: SINEW_ERROR_IO. */
sinew_result sw_text_open(sw_text_reader *r, const char *path, char comment, sw_error *err);
/* The same reader over `len` bytes in memory (copied, so `data` needs no NUL and may be
 * freed at once); `name` stands for the path in messages (NULL: "<text>"). */
sinew_result sw_text_open_mem(sw_text_reader *r, const char *name, const void *data, size_t len,
                              char comment, sw_error *err);
void sw_text_close(sw_text_reader *r);

/* Next token on the current line (comments skipped); returns its length, 0 at the end of
 * the line (the newline is not consumed). */
size_t sw_text_word(sw_text_reader *r, const char **tok);
/* Next token anywhere (newlines and comments skipped); 0 at the end of the file. */
size_t sw_text_token(sw_text_reader *r, const char **tok);
/* Moves the cursor past the next newline; returns 0 when the file has ended. */
int sw_text_next_line(sw_text_reader *r);
/* Skips blank and comment-only lines; returns 0 at the end of the file, else leaves the
 * cursor at the start of a line that holds a token. */
int sw_text_skip_blank_lines(sw_text_reader *r);
/* Bytes left after the cursor. */
size_t sw_text_remaining(const sw_text_reader *r);
/* The line a truncated file ended on (the last line that has any byte). */
int64_t sw_text_eof_line(const sw_text_reader *r);

/* Whole-token parsers (no leading/trailing junk); return 1 on success. The double
 * parser accepts nan/inf so that callers can report them as NOT_FINITE. */
int sw_parse_int(const char *tok, size_t n, int64_t *v);
int sw_parse_double(const char *tok, size_t n, double *v);

/* Records "path:line: <message>" with `code` and returns `code`. */
sinew_result sw_text_fail(const sw_text_reader *r, int64_t line, sinew_result code, const char *fmt,
                          ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Reads one integer (same_line: on the current line, else anywhere) into *v; `what`
 * names it in the error. PARSE on end of line/file or a non-integer token. */
sinew_result sw_text_int(sw_text_reader *r, int same_line, const char *what, int64_t *v);
/* Reads one finite double; NaN/inf is NOT_FINITE. */
sinew_result sw_text_double(sw_text_reader *r, int same_line, const char *what, double *v);
/* Reads one number of any value (ignored columns); PARSE if it is not a number. */
sinew_result sw_text_number(sw_text_reader *r, int same_line, const char *what);
/* PARSE if the current line holds another token. */
sinew_result sw_text_expect_eol(sw_text_reader *r, const char *after);
/* A declared element count: PARSE when negative, above 1e9, or when `count` entries of
 * `tokens_each` tokens cannot fit in the bytes that remain. */
sinew_result sw_text_check_count(sw_text_reader *r, int64_t count, int64_t tokens_each,
                                 const char *what);

/* Grows *p (elements of `size`) so it holds at least `need`; 0 on allocation failure. */
int sw_grow(void **p, size_t *cap, size_t need, size_t size);

/* The shared tail of the tet readers: `raw` holds 4*ntets file indices with base
 * `base` (0 or 1), `lines` the line of each tet. Checks every index (naming the base in
 * the message), repeated vertices (DEGENERATE), zero volume (DEGENERATE); reorients
 * negative tets by swapping their 2nd and 3rd vertex; converts to 0-based in place. */
sinew_result sw_text_check_tets(const sw_text_reader *r, const char *format, int64_t base,
                                int32_t nverts, const double *X, int32_t ntets, int32_t *raw,
                                const int64_t *lines);
/* sw_tetmesh_validate as a last safety net, its message prefixed with the path. */
struct sw_tetmesh;
sinew_result sw_text_validate_tets(const sw_text_reader *r, const struct sw_tetmesh *m);
#endif
