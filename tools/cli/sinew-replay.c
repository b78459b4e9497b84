/* sinew-replay --blob B --recording R [--surface-out F] [--json]: plays a recording a host
 * made with sinew_recorder (sinew.h) back against the blob it was made with, call by call,
 * and checks each step's output surface bitwise against the hash recorded beside it. It
 * reports the steps replayed, how many differ and the first that does; with --surface-out
 * it writes the last step's surface as OBJ. Exit 0 bitwise equal, 1 a step differs or the
 * replay failed (a damaged recording, another blob: the message says which), 2 bad
 * arguments. */
#include <stdio.h>
#include <stdlib.h>

#include "clock.h"
#include "mesh_io.h"
#include "recording.h"
#include "tool_common.h"

static const char *tool = "sinew-replay";

/* The recording's bytes, parsed; 0 with a message on failure. */
static int load_recording(const char *path, sw_recording *rec) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: cannot open %s\n", tool, path);
        return 0;
    }
    size_t cap = 1 << 20, n = 0;
    unsigned char *d = malloc(cap);
    for (size_t k; d && (k = fread(d + n, 1, cap - n, f)) > 0;) {
        n += k;
        unsigned char *bigger = n == cap ? realloc(d, cap *= 2) : d;
        if (!bigger) free(d);
        d = bigger;
    }
    fclose(f);
    if (!d) {
        fprintf(stderr, "%s: out of memory reading %s\n", tool, path);
        return 0;
    }
    sw_error err;
    sinew_result r = sw_recording_parse(d, n, rec, &err);
    free(d);
    if (r != SINEW_OK)
        fprintf(stderr, "%s: %s: %s (%s)\n", tool, path, err.msg, sinew_result_string(r));
    return r == SINEW_OK;
}

/* The last step's surface as OBJ (its positions in the actor's frame). */
static int write_surface(const sinew_blob *blob, const float *x, const char *path) {
    uint32_t nv = sinew_blob_surface_vertex_count(blob),
             nt = sinew_blob_surface_triangle_count(blob);
    double *X = malloc(sizeof(double) * 3 * (nv ? nv : 1));
    int32_t *T = malloc(sizeof(int32_t) * 3 * (nt ? nt : 1));
    sw_error err;
    sw_error_clear(&err);
    sinew_result r = X && T ? SINEW_OK : SINEW_ERROR_OUT_OF_MEMORY;
    if (r == SINEW_OK) r = sinew_blob_surface_triangles(blob, (uint32_t *)T, 3 * nt);
    for (uint32_t i = 0; r == SINEW_OK && i < 3 * nv; ++i)
        X[i] = x[i];
    if (r == SINEW_OK) r = sw_write_obj(path, (int32_t)nv, X, (int32_t)nt, T, &err);
    if (r != SINEW_OK)
        fprintf(stderr, "%s: cannot write %s: %s (%s)\n", tool, path, err.msg,
                sinew_result_string(r));
    free(X);
    free(T);
    return r == SINEW_OK;
}

static void report(const sw_replay_report *rep, double seconds, int json) {
    if (rep->differing == 0)
        printf("%u steps replayed bitwise equal in %.2f s\n", rep->steps, seconds);
    else
        printf("%u steps replayed in %.2f s: %u differ, the first step %lld (recorded surface "
               "hash %016llx, replayed %016llx)\n",
               rep->steps, seconds, rep->differing, (long long)rep->first_diff,
               (unsigned long long)rep->want, (unsigned long long)rep->got);
    if (json)
        printf("{\"steps\": %u, \"differing\": %u, \"first_differing\": %lld, \"seconds\": %.4f}\n",
               rep->steps, rep->differing, (long long)rep->first_diff, seconds);
}

int main(int argc, char **argv) {
    const char *blob_path = NULL, *rec_path = NULL, *surface_out = NULL;
    int json = 0;
    const sw_flag flags[] = {
        {SW_STR("--blob", &blob_path, "B", "the blob the recording was made with")},
        {SW_STR("--recording", &rec_path, "R", "the recording (sinew_recorder's file)")},
        {SW_STR("--surface-out", &surface_out, "F",
                "write the last step's surface (the actor's frame) to F as OBJ")},
        {SW_SET("--json", &json, 1, "print one JSON object as the last line")},
    };
    const sw_flag_group groups[] = {{NULL, flags, SW_FLAGS_N(flags)}};
    const sw_tool_cli cli = {tool,
                             "sinew-replay --blob B --recording R [--surface-out F] [--json]\n",
                             groups,
                             1,
                             "exit status: 0 bitwise equal, 1 a step differs or the replay "
                             "failed, 2 bad arguments\n",
                             NULL,
                             0};
    if (sw_flags_parse(&cli, argc, argv)) return 2;
    if (!blob_path || !rec_path) {
        sw_flags_usage(&cli, stderr);
        return 2;
    }
    sinew_blob_def bd = sinew_blob_def_default();
    bd.path = blob_path;
    sinew_blob *blob = NULL;
    sinew_result r = sinew_blob_load(&bd, &blob);
    if (r != SINEW_OK) {
        fprintf(stderr, "%s: cannot load %s (%s)\n", tool, blob_path, sinew_result_string(r));
        return 1;
    }
    sw_recording rec;
    if (!load_recording(rec_path, &rec)) {
        sinew_blob_destroy(blob);
        return 1;
    }
    float *x = surface_out ? malloc(sizeof(float) * 3 * (rec.surface ? rec.surface : 1)) : NULL;
    sw_replay_report rep;
    double t0 = sw_now_seconds();
    sinew_logger lg = sinew_logger_default();
    r = sw_recording_replay(blob, &rec, &lg, x, &rep);
    double seconds = sw_now_seconds() - t0;
    int ok = r == SINEW_OK;
    if (!ok)
        fprintf(stderr, "%s: %s: %s (%s)\n", tool, rec_path, rep.msg, sinew_result_string(r));
    else
        report(&rep, seconds, json);
    if (ok && surface_out) ok = write_surface(blob, x, surface_out);
    free(x);
    sw_recording_free(&rec);
    sinew_blob_destroy(blob);
    return ok && rep.differing == 0 ? 0 : 1;
}
