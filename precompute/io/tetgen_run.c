/* TetGen as a separate program (tetgen_run.h). */
#include "tetgen_run.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"
#include "mesh_io.h"

#define SW_TETGEN_RUNS 4 /* runs to steer the count to the target */

extern char **environ;

typedef struct {
    double x[3];
    int32_t i;
} keyed_vertex;

static int cmp_position(const void *a, const void *b) {
    const keyed_vertex *p = a, *q = b;
    for (int k = 0; k < 3; ++k)
        if (p->x[k] != q->x[k]) return p->x[k] < q->x[k] ? -1 : 1;
    return p->i < q->i ? -1 : p->i > q->i;
}

static int cmp_u64(const void *a, const void *b) {
    uint64_t p = *(const uint64_t *)a, q = *(const uint64_t *)b;
    return p < q ? -1 : p > q;
}

sinew_result sw_surface_closure(const sw_trimesh *s, int32_t **weld_of, int32_t *nwelded,
                                int32_t *open_edges, int32_t *nonmanifold_edges,
                                int32_t *degenerate, sw_error *err) {
    *weld_of = NULL;
    *nwelded = *open_edges = *nonmanifold_edges = *degenerate = 0;
    sinew_result rc = sw_trimesh_validate(s, "tetgen", err);
    if (rc) return rc;
    keyed_vertex *kv = malloc((size_t)s->nverts * sizeof *kv);
    int32_t *w = malloc((size_t)s->nverts * sizeof *w);
    uint64_t *e = malloc((size_t)s->ntris * 3 * sizeof *e);
    if (!kv || !w || !e) {
        free(kv);
        free(w);
        free(e);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tetgen: out of memory");
    }
    for (int32_t i = 0; i < s->nverts; ++i) {
        memcpy(kv[i].x, s->X + 3 * (int64_t)i, sizeof kv[i].x);
        kv[i].i = i;
    }
    qsort(kv, (size_t)s->nverts, sizeof *kv, cmp_position);
    int32_t n = 0;
    for (int32_t i = 0; i < s->nverts; ++i) {
        if (i > 0 && memcmp(kv[i].x, kv[i - 1].x, sizeof kv[i].x)) n++;
        w[kv[i].i] = n;
    }
    n++;
    size_t ne = 0; /* undirected edges as (lo << 32 | hi) */
    for (int32_t t = 0; t < s->ntris; ++t) {
        int32_t c[3];
        for (int k = 0; k < 3; ++k)
            c[k] = w[s->tris[3 * (int64_t)t + k]];
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            (*degenerate)++;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            uint32_t a = (uint32_t)c[k], b = (uint32_t)c[(k + 1) % 3];
            e[ne++] = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
        }
    }
    qsort(e, ne, sizeof *e, cmp_u64);
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && e[j] == e[i])
            j++;
        *open_edges += j - i == 1;
        *nonmanifold_edges += j - i > 2;
        i = j;
    }
    free(kv);
    free(e);
    *weld_of = w;
    *nwelded = n;
    return SINEW_OK;
}

/* The welded surface as OFF (degenerate triangles left out). */
static sinew_result write_off(const char *path, const sw_trimesh *s, const int32_t *w, int32_t n,
                              int32_t ndegenerate, sw_error *err) {
    FILE *f = fopen(path, "w");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "tetgen: cannot write %s", path);
    double *P = malloc((size_t)n * 3 * sizeof(double));
    if (!P) {
        fclose(f);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "tetgen: out of memory");
    }
    for (int32_t i = 0; i < s->nverts; ++i)
        memcpy(P + 3 * (int64_t)w[i], s->X + 3 * (int64_t)i, 3 * sizeof(double));
    fprintf(f, "OFF\n%d %d 0\n", n, s->ntris - ndegenerate);
    for (int32_t i = 0; i < n; ++i)
        fprintf(f, "%.17g %.17g %.17g\n", P[3 * i], P[3 * i + 1], P[3 * i + 2]);
    for (int32_t t = 0; t < s->ntris; ++t) {
        const int32_t *c = s->tris + 3 * (int64_t)t;
        int32_t a = w[c[0]], b = w[c[1]], d = w[c[2]];
        if (a != b && b != d && a != d) fprintf(f, "3 %d %d %d\n", a, b, d);
    }
    free(P);
    int bad = ferror(f);
    if (fclose(f) || bad) return sw_error_set(err, SINEW_ERROR_IO, "tetgen: cannot write %s", path);
    return SINEW_OK;
}

/* `program switches off_path`, its output to log_path: 0 when it exited 0, else -1 when it
 * could not be started (errno-like code in *why) or its wait status. */
static int spawn_wait(const char *program, const char *switches, const char *off_path,
                      const char *log_path, int *why) {
    char *argv[] = {(char *)program, (char *)switches, (char *)off_path, NULL};
    posix_spawn_file_actions_t fa;
    *why = 0;
    if ((*why = posix_spawn_file_actions_init(&fa))) return -1;
    posix_spawn_file_actions_addopen(&fa, 1, log_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid;
    *why = posix_spawnp(&pid, program, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (*why) return -1;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return (*why = errno), -1;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? 0 : status;
}

/* The log's first line naming `word` into msg (1), or with word NULL its last non-empty
 * line; msg is left alone when no line names the word (0). */
static int log_line(const char *log_path, const char *word, char *msg, size_t cap) {
    FILE *f = fopen(log_path, "r");
    if (!f) return 0;
    char line[512];
    int found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        size_t l = strlen(line);
        while (l > 0 && (line[l - 1] == '\n' || line[l - 1] == '\r' || line[l - 1] == ' '))
            line[--l] = 0;
        const char *t = line + strspn(line, " !");
        found = word && strstr(t, word);
        if (*t && (!word || found)) snprintf(msg, cap, "%s", t);
    }
    fclose(f);
    return found;
}

/* One meshing run with the volume bound a. When TetGen fails (it aborts without flushing
 * its messages on a self-intersecting surface), a second run with -d (detect
 * intersections only) says why. */
static sinew_result run_tetgen(const char *program, const char *off_path, const char *log_path,
                               double a, sw_error *err) {
    char switches[64], msg[512];
    snprintf(switches, sizeof switches, "-pq1.414/10a%.9g", a);
    int why, st = spawn_wait(program, switches, off_path, log_path, &why);
    if (st == 0) return SINEW_OK;
    if (st < 0 || (WIFEXITED(st) && WEXITSTATUS(st) == 127))
        return sw_error_set(err, SINEW_ERROR_IO,
                            "tetgen: cannot run '%s' (%s; Debian package tetgen)", program,
                            why ? strerror(why) : "not found");
    msg[0] = 0;
    log_line(log_path, NULL, msg, sizeof msg);
    if (spawn_wait(program, "-d", off_path, log_path, &why) == 0)
        log_line(log_path, "intersect", msg, sizeof msg);
    return sw_error_set(err, SINEW_ERROR_IO, "tetgen: '%s' failed (%s %d): %s", program,
                        WIFSIGNALED(st) ? "signal" : "exit",
                        WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st),
                        msg[0] ? msg : "no message");
}

/* The folder is the bake's own (mkdtemp): everything TetGen left there goes, whatever
 * its switches wrote (the -d diagnosis writes surface.1.smesh, other builds .face/.edge). */
static void remove_dir(const char *dir) {
    DIR *d = opendir(dir);
    if (d) {
        char path[4400];
        for (struct dirent *e; (e = readdir(d));) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
        closedir(d);
    }
    rmdir(dir);
}

sinew_result sw_tetmesh_by_tetgen(const sw_trimesh *surf, int32_t target_tets, const char *program,
                                  sw_tetmesh *out, sw_tetgen_report *report, sw_error *err) {
    double t0 = sw_now_seconds();
    sw_tetgen_report rep_local, *rep = report ? report : &rep_local;
    memset(rep, 0, sizeof *rep);
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "tetgen: out is NULL");
    memset(out, 0, sizeof *out);
    if (target_tets < 100 || target_tets > 5000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tetgen: %d tets requested (100..5000000)", target_tets);
    int32_t *w, n, open, nonmanifold, degenerate;
    sinew_result rc = sw_surface_closure(surf, &w, &n, &open, &nonmanifold, &degenerate, err);
    if (rc) return rc;
    if (open || nonmanifold) {
        free(w);
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "tetgen: the surface is not closed (%d open and %d non-manifold "
                            "edges after welding %d vertices into %d); TetGen needs a closed "
                            "surface, the lattice mesher takes any",
                            open, nonmanifold, surf->nverts, n);
    }
    double V = fabs(sw_trimesh_signed_volume(surf));
    if (!(V > 0)) {
        free(w);
        return sw_error_set(err, SINEW_ERROR_DEGENERATE, "tetgen: the surface encloses no volume");
    }
    const char *base = getenv("TMPDIR");
    char dir[4096], off[4200], node[4200], ele[4200], log_path[4200];
    snprintf(dir, sizeof dir, "%s/sinew-tetgen-XXXXXX", base && base[0] ? base : "/tmp");
    if (!mkdtemp(dir)) {
        free(w);
        return sw_error_set(err, SINEW_ERROR_IO, "tetgen: cannot create a folder %s (%s)", dir,
                            strerror(errno));
    }
    snprintf(off, sizeof off, "%s/surface.off", dir);
    snprintf(node, sizeof node, "%s/surface.1.node", dir);
    snprintf(ele, sizeof ele, "%s/surface.1.ele", dir);
    snprintf(log_path, sizeof log_path, "%s/tetgen.log", dir);
    rc = write_off(off, surf, w, n, degenerate, err);
    free(w);
    rep->welded_verts = n;
    /* The count falls with the volume bound as about its -0.75 power where the bound
     * rules (the quality refinement near the surface's sharp features sets a floor), and a
     * mean tet is about a sixth of the bound: start at 6 V / target, then steer the bound
     * by the power law fitted to the last two runs; keep the run nearest the target. */
    double a = 6.0 * V / target_tets, la = 0, ln = 0, p = -0.75;
    sw_tetmesh best = {0}, run_mesh = {0};
    for (int run = 0; !rc && run < SW_TETGEN_RUNS; ++run) {
        if ((rc = run_tetgen(program ? program : "tetgen", off, log_path, a, err)) ||
            (rc = sw_read_tetgen(node, ele, &run_mesh, err)))
            break;
        double ratio = (double)run_mesh.ntets / target_tets;
        if (!best.ntets || fabs(log(ratio)) < fabs(log((double)best.ntets / target_tets))) {
            sw_tetmesh_free(&best);
            best = run_mesh;
            rep->max_volume = a;
        } else {
            sw_tetmesh_free(&run_mesh);
        }
        memset(&run_mesh, 0, sizeof run_mesh);
        rep->runs = run + 1;
        if (fabs(log(ratio)) < log(1.15)) break;
        double n = log(ratio * target_tets);
        if (getenv("SW_TG_DEBUG"))
            fprintf(stderr, "tetgen run a=%g n=%d\n", a, (int)(ratio * target_tets + 0.5));
        if (run > 0 && fabs(log(a) - la) > 1e-9) {
            double fit = (n - ln) / (log(a) - la);
            if (fit > -0.05) break; /* at the floor: a smaller bound adds no tets */
            p = fmax(-2.0, fmin(fit, -0.25));
        }
        la = log(a);
        ln = n;
        a *= exp(-log(ratio) / p);
    }
    *out = best;
    remove_dir(dir);
    if (rc) {
        sw_tetmesh_free(out);
        return rc;
    }
    rep->volume = sw_tetmesh_volume(out);
    rep->seconds = sw_now_seconds() - t0;
    return SINEW_OK;
}
