/* A tiny test runner: TEST(name) { ... ENSURE(cond); ... } and a main() from
 * SW_TEST_MAIN(). Run a subset with a substring filter: ./test_x name_part.
 * Exit code: 0 all passed, 1 any failed, 77 (CTest "skipped") when every test ran
 * skipped itself with SKIP(). Prints "N passed, N failed, N skipped". */
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

/* Path of a real asset under ../shared/data, or NULL when that folder is absent. */
#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif

#endif
