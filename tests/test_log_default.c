/* The default logger: without a hook, errors and warnings go to stderr, so a damaged blob
 * says why ("checksum mismatch") where it used to say only SINEW_ERROR_CORRUPT; info and
 * debug do not; SINEW_LOG_NONE (sinew_logger_silent) silences it; a host's hook still gets
 * every message instead. stderr is pointed at a file for each case. */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "blob_load.h"
#include "blob_write.h"
#include "log.h"
#include "sinew/sinew.h"
#include "sw_test.h"

#include "blob_synth.h"

static fixture g_fix;

/* Runs load_damaged with `lg`, stderr sent to a file; returns what was printed (static). */
static const char *captured(const sinew_logger *lg, sinew_result *r) {
    static char text[2048];
    char path[] = "/tmp/sinew_log_XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) return NULL;
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    dup2(fd, STDERR_FILENO);

    size_t size = 0;
    fixture_init(&g_fix, 9);
    uint8_t *b = write_fixture(&g_fix, &size);
    b[size - 1] ^= 0x40; /* one flipped bit in the last section */
    sinew_blob_def d = sinew_blob_def_default();
    d.data = b;
    d.data_size = size;
    d.logger = *lg;
    sinew_blob *blob = NULL;
    *r = sinew_blob_load(&d, &blob);
    sw_log(lg, SINEW_LOG_INFO, 0, "an info line");
    sw_log(lg, SINEW_LOG_WARNING, 0, "a warning line");
    free(b);

    dup2(saved, STDERR_FILENO);
    close(saved);
    ssize_t n = pread(fd, text, sizeof text - 1, 0);
    text[n > 0 ? n : 0] = '\0';
    close(fd);
    unlink(path);
    return text;
}

TEST(the_default_logger_prints_errors_and_warnings) {
    sinew_logger lg = sinew_logger_default();
    sinew_result r;
    const char *out = captured(&lg, &r);
    ENSURE(out && r == SINEW_ERROR_CORRUPT);
    fprintf(stderr, "  printed: %s", out);
    ENSURE(strstr(out, "sinew: error: sinew_blob_load: '<host buffer>': blob header: checksum "
                       "mismatch"));
    ENSURE(strstr(out, "sinew: warning: a warning line\n"));
    ENSURE(!strstr(out, "an info line"));
}

TEST(sinew_log_none_silences_it) {
    sinew_logger lg = sinew_logger_silent();
    sinew_result r;
    const char *out = captured(&lg, &r);
    ENSURE(out && r == SINEW_ERROR_CORRUPT && out[0] == '\0');
}

static int g_calls;
static void hook(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    (void)level, (void)id, (void)msg, (void)user;
    g_calls++;
}

TEST(a_host_hook_replaces_it) {
    sinew_logger lg = sinew_logger_default();
    lg.log = hook;
    lg.max_level = SINEW_LOG_INFO;
    sinew_result r;
    const char *out = captured(&lg, &r);
    ENSURE(out && r == SINEW_ERROR_CORRUPT && out[0] == '\0');
    ENSURE(g_calls == 3); /* the load's error, the info and the warning */
}

SW_TEST_MAIN(CASE(the_default_logger_prints_errors_and_warnings), CASE(sinew_log_none_silences_it),
             CASE(a_host_hook_replaces_it))
