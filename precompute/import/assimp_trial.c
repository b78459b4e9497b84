/* assimp read in a child process first (assimp_trial.h). */
#include "assimp_trial.h"

#include <assimp/cimport.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* The child's exit codes when assimp returned: with a scene, without one. Anything else,
 * a signal above all, is a death. */
enum { TRIAL_SCENE = 0, TRIAL_NO_SCENE = 3 };

/* The child: the crash signals back to their default (a sanitizer's or libFuzzer's handler
 * would report the crash as the parent's own), stderr into the pipe, stdout discarded, and
 * assimp's verdict as the exit code. _exit: the parent's buffers and atexit work stay the
 * parent's. */
static void trial_child(int wfd, const char *path, const void *data, size_t len, const char *hint,
                        unsigned flags, double seconds) {
    static const int sigs[] = {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGALRM};
    struct sigaction dfl;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; ++i)
        sigaction(sigs[i], &dfl, NULL);
    int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, STDOUT_FILENO);
    dup2(wfd, STDERR_FILENO);
    struct itimerval limit; /* SIGALRM's default action ends the child */
    memset(&limit, 0, sizeof limit);
    limit.it_value.tv_sec = (time_t)seconds;
    limit.it_value.tv_usec = (suseconds_t)((seconds - (double)(time_t)seconds) * 1e6);
    if (limit.it_value.tv_sec == 0 && limit.it_value.tv_usec == 0) limit.it_value.tv_usec = 1;
    setitimer(ITIMER_REAL, &limit, NULL);
    const struct aiScene *sc =
        path ? aiImportFile(path, flags)
             : aiImportFileFromMemory(data, (unsigned)len, flags, hint ? hint : "");
    _exit(sc ? TRIAL_SCENE : TRIAL_NO_SCENE);
}

/* What the child wrote last on stderr, read to the end (so that it never blocks on a full
 * pipe): its last non-empty line, at most `cap` - 1 characters of it. */
static void read_last_line(int rfd, char *line, size_t cap) {
    char tail[512];
    size_t n = 0;
    line[0] = 0;
    for (;;) {
        char buf[256];
        ssize_t got = read(rfd, buf, sizeof buf);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        for (ssize_t i = 0; i < got; ++i) { /* keep the last sizeof tail bytes */
            if (n == sizeof tail) {
                memmove(tail, tail + sizeof tail / 2, sizeof tail / 2);
                n = sizeof tail / 2;
            }
            tail[n++] = buf[i];
        }
    }
    while (n > 0 && (tail[n - 1] == '\n' || tail[n - 1] == '\r' || tail[n - 1] == ' '))
        --n;
    size_t b = n;
    while (b > 0 && tail[b - 1] != '\n')
        --b;
    size_t k = n - b < cap - 1 ? n - b : cap - 1;
    for (size_t i = 0; i < k; ++i) /* printable only: it goes into a message */
        line[i] = tail[b + i] >= 32 && tail[b + i] < 127 ? tail[b + i] : '?';
    line[k] = 0;
}

sinew_result sw_assimp_trial(const char *path, const void *data, size_t len, const char *hint,
                             unsigned flags, double seconds, const char *name, sw_error *err) {
    if (!(seconds > 0) || seconds > 1e6)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: assimp's trial read given %g s (wants (0, 1e6])", name, seconds);
    int fds[2];
    if (pipe(fds) != 0)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot start assimp's trial read: %s", name,
                            strerror(errno));
    /* A host that ignores SIGCHLD has its children reaped at once, and waitpid would find
       none: the default disposition while the child lives, the host's again after. */
    struct sigaction host_chld, dfl;
    sigaction(SIGCHLD, NULL, &host_chld);
    const int reaps = host_chld.sa_handler == SIG_IGN || (host_chld.sa_flags & SA_NOCLDWAIT);
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    if (reaps) sigaction(SIGCHLD, &dfl, NULL);
    fflush(NULL); /* nothing buffered is written twice */
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]), close(fds[1]);
        if (reaps) sigaction(SIGCHLD, &host_chld, NULL);
        return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot start assimp's trial read: %s", name,
                            strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        trial_child(fds[1], path, data, len, hint, flags, seconds);
    }
    close(fds[1]);
    char last[200];
    read_last_line(fds[0], last, sizeof last);
    close(fds[0]);
    int status = 0;
    pid_t w;
    while ((w = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
    }
    const int wait_errno = errno;
    if (reaps) sigaction(SIGCHLD, &host_chld, NULL);
    if (w < 0)
        return sw_error_set(err, SINEW_ERROR_IO, "%s: assimp's trial read was lost: %s", name,
                            strerror(wait_errno));
    if (WIFEXITED(status) &&
        (WEXITSTATUS(status) == TRIAL_SCENE || WEXITSTATUS(status) == TRIAL_NO_SCENE))
        return SINEW_OK;
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM)
        return sw_error_set(err, SINEW_ERROR_PARSE,
                            "%s: assimp did not finish reading it in %g s: the file is damaged, "
                            "or holds a structure this assimp cannot read; export it again",
                            name, seconds);
    char how[64];
    if (WIFSIGNALED(status))
        snprintf(how, sizeof how, "signal %d, %s", WTERMSIG(status), strsignal(WTERMSIG(status)));
    else
        snprintf(how, sizeof how, "exit status %d", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return sw_error_set(err, SINEW_ERROR_PARSE,
                        "%s: assimp died reading it (%s%s%s%s): the file is damaged, or holds "
                        "a structure this assimp cannot read; export it again",
                        name, how, last[0] ? ": \"" : "", last, last[0] ? "\"" : "");
}
