/* A tiny test runner: TEST(name) { ... ENSURE(cond); ... } and a main() from
 * SW_TEST_MAIN(). Run a subset with a substring filter: ./test_x name_part.
 * Exit code: 0 all passed, 1 any failed, 77 (CTest "skipped") when every test ran
 * skipped itself with SKIP() (NEED_DATA: a real asset absent; a failure with CI=true).
 * Prints "N passed, N failed, N skipped". */
#ifndef SW_TEST_H
#define SW_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void (*sw_test_fn)(void);
typedef struct {
    const char *name;
    sw_test_fn fn;
} sw_test_case;

extern int sw_test_failed_;  /* failures in the current test */
extern int sw_test_skipped_; /* current test skipped itself */

#define ENSURE(cond)                                                                               \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "  %s:%d: ENSURE(%s) failed\n", __FILE__, __LINE__, #cond);            \
            sw_test_failed_++;                                                                     \
            return;                                                                                \
        }                                                                                          \
    } while (0)

/* ENSURE with a printf-style explanation. */
#define ENSUREF(cond, ...)                                                                         \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "  %s:%d: ENSURE(%s) failed: ", __FILE__, __LINE__, #cond);            \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fprintf(stderr, "\n");                                                                 \
            sw_test_failed_++;                                                                     \
            return;                                                                                \
        }                                                                                          \
    } while (0)

#define ENSURE_NEAR(a, b, tol)                                                                     \
    ENSUREF(fabs((double)(a) - (double)(b)) <= (tol), "%s = %.17g, %s = %.17g, tol %g", #a,        \
            (double)(a), #b, (double)(b), (double)(tol))

#define SKIP(...)                                                                                  \
    do {                                                                                           \
        fprintf(stderr, "  skipped: ");                                                            \
        fprintf(stderr, __VA_ARGS__);                                                              \
        fprintf(stderr, "\n");                                                                     \
        sw_test_skipped_ = 1;                                                                      \
        return;                                                                                    \
    } while (0)

#define TEST(name) static void name(void)

#define SW_TEST_MAIN(...)                                                                          \
    int sw_test_failed_ = 0, sw_test_skipped_ = 0;                                                 \
    int main(int argc, char **argv) {                                                              \
        static const sw_test_case cases[] = {__VA_ARGS__};                                         \
        int passed = 0, failed = 0, skipped = 0;                                                   \
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {                              \
            if (argc > 1 && !strstr(cases[i].name, argv[1])) continue;                             \
            sw_test_failed_ = 0;                                                                   \
            sw_test_skipped_ = 0;                                                                  \
            fprintf(stderr, "[ RUN  ] %s\n", cases[i].name);                                       \
            cases[i].fn();                                                                         \
            if (sw_test_failed_) {                                                                 \
                failed++;                                                                          \
                fprintf(stderr, "[ FAIL ] %s\n", cases[i].name);                                   \
            } else if (sw_test_skipped_) {                                                         \
                skipped++;                                                                         \
                fprintf(stderr, "[ SKIP ] %s\n", cases[i].name);                                   \
            } else {                                                                               \
                passed++;                                                                          \
                fprintf(stderr, "[  OK  ] %s\n", cases[i].name);                                   \
            }                                                                                      \
        }                                                                                          \
        printf("%d passed, %d failed, %d skipped\n", passed, failed, skipped);                     \
        if (failed) return 1;                                                                      \
        return (passed == 0 && skipped > 0) ? 77 : 0;                                              \
    }

#define CASE(fn)                                                                                   \
    { #fn, fn }

/* The folder of real assets (tests/CMakeLists.txt passes ../shared/data). */
#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

/* 1 when the real asset `rel` (a path below SINEW_SHARED_DATA_DIR) can be opened. */
static inline int sw_test_have_data(const char *rel) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", SINEW_SHARED_DATA_DIR, rel);
    FILE *f = fopen(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

/* 1 in CI: the environment variable CI is "true" (.ci/run runs with CI=true). */
static inline int sw_test_in_ci(void) {
    const char *ci = getenv("CI");
    return ci && strcmp(ci, "true") == 0;
}

/* The one decision of what a test that needs a real asset does without it: outside CI
 * it skips (exit 77 when every test of the file skipped); in CI it FAILS, so that CI
 * never passes by skipping the tests on real data. */
#define NEED_DATA(rel)                                                                             \
    do {                                                                                           \
        if (!sw_test_have_data(rel)) {                                                             \
            if (sw_test_in_ci()) {                                                                 \
                fprintf(stderr,                                                                    \
                        "  FAILED: the real asset %s/%s is missing and CI=true: CI must run "      \
                        "the tests on real data (put the assets in %s)\n",                         \
                        SINEW_SHARED_DATA_DIR, rel, SINEW_SHARED_DATA_DIR);                        \
                sw_test_failed_++;                                                                 \
                return;                                                                            \
            }                                                                                      \
            SKIP("%s/%s absent (real assets; CI=true makes this a failure)",                       \
                 SINEW_SHARED_DATA_DIR, rel);                                                      \
        }                                                                                          \
    } while (0)

/* The whole file at path, with a NUL after its bytes (so text can be read as a string),
 * its length in *n (0 when the file is missing or unreadable: NULL then). */
static inline char *sw_test_read_file(const char *path, size_t *n) {
    *n = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp) return NULL;
    char *buf = NULL;
    long len = fseek(fp, 0, SEEK_END) == 0 ? ftell(fp) : -1;
    if (len >= 0 && fseek(fp, 0, SEEK_SET) == 0 && (buf = malloc((size_t)len + 1))) {
        if (fread(buf, 1, (size_t)len, fp) == (size_t)len) {
            buf[len] = '\0';
            *n = (size_t)len;
        } else {
            free(buf);
            buf = NULL;
        }
    }
    fclose(fp);
    return buf;
}

#endif
