/* The simulate stage through its cache (sim_cache.h, sw_bake_params.cache_dir): the key
 * hashes every input of the full-space solves, so a file found under it holds exactly
 * the solutions this bake would compute (the reference's results do not depend on its
 * thread count). A file that cannot be used is reported and solved around. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bake_internal.h"
#include "blob_write.h"
#include "sim_cache.h"

/* Bump when the reference's physics or the file layout changes: a cache of the old code
 * then misses instead of handing back solutions the new code would not compute. */
#define SW_SIM_CACHE_VERSION 1

#define MIX(h, v) ((h) = sw_fnv1a((h), &(v), sizeof(v)))

/* The sequences in the file's order: the training ones, then the held-out one. */
static sw_pose_seq *seq_at(sw_bake_state *s, int32_t i) {
    return i < s->ntrain_seq ? &s->train[i] : &s->heldout;
}

/* The index of sequence q in that order (-1: none). */
static int32_t seq_index(sw_bake_state *s, const sw_pose_seq *q) {
    for (int32_t i = 0; q && i <= s->ntrain_seq; ++i)
        if (seq_at(s, i) == q) return i;
    return -1;
}

static uint64_t simulate_key(sw_bake_state *s) {
    uint64_t h = SW_FNV_START;
    const char tag[] = "sinew simulate cache";
    h = sw_fnv1a(h, tag, sizeof tag);
    int32_t version = SW_SIM_CACHE_VERSION, nv = s->nv, nt = s->ch.mesh.ntets, nb = s->nb;
    MIX(h, version);
    MIX(h, nv);
    MIX(h, nt);
    MIX(h, nb);
    h = sw_fnv1a(h, s->ch.mesh.X, (size_t)nv * 3 * sizeof(double));
    h = sw_fnv1a(h, s->ch.mesh.tets, (size_t)nt * 4 * sizeof(int32_t));
    h = sw_fnv1a(h, s->ch.bone_of_vertex, (size_t)nv * sizeof(int32_t));
    h = sw_fnv1a(h, s->ch.weights.w, (size_t)nv * nb * sizeof(double));
    MIX(h, s->ch.youngs);
    MIX(h, s->ch.poisson);
    MIX(h, s->ch.density);
    sw_fullsim_params fp = sw_bake_sim_params(s); /* field by field: no padding bytes */
    int32_t ints[] = {(int32_t)fp.integrator, fp.self_contact,    fp.ground,
                      (int32_t)fp.hessian,    (int32_t)fp.solver, fp.contact_rounds,
                      fp.contact_set_check,   fp.max_newton,      fp.pcg_max};
    double reals[] = {
        fp.dt,         fp.rayleigh_alpha, fp.rayleigh_beta, fp.gravity[0],       fp.gravity[1],
        fp.gravity[2], fp.contact_k,      fp.contact_alpha, fp.neighbour_factor, fp.ground_height,
        fp.ground_k,   fp.newton_rtol,    fp.pcg_rtol};
    h = sw_fnv1a(h, ints, sizeof ints);
    h = sw_fnv1a(h, reals, sizeof reals);
    int32_t nseq = s->ntrain_seq + 1;
    MIX(h, nseq);
    for (int32_t i = 0; i < nseq; ++i) { /* the poses, and which path continues which */
        const sw_pose_seq *q = seq_at(s, i);
        int32_t links[3] = {q->npose, seq_index(s, q->then[0]), seq_index(s, q->then[1])};
        h = sw_fnv1a(h, links, sizeof links);
        h = sw_fnv1a(h, q->T, (size_t)q->npose * 12 * nb * sizeof(double));
    }
    return h;
}

/* The file's bytes (malloc'd), or NULL when it cannot be read (errno says why). */
static uint8_t *read_all(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    uint8_t *b = NULL;
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (len >= 0 && fseek(f, 0, SEEK_SET) == 0 && (b = malloc((size_t)len + 1)) &&
        fread(b, 1, (size_t)len, f) != (size_t)len) {
        free(b);
        b = NULL;
    }
    fclose(f);
    *n = b ? (size_t)len : 0;
    return b;
}

/* Hands the cache's arrays to the sequences. */
static sinew_result adopt(sw_bake_state *s, sw_sim_cache *c, sw_error *err) {
    for (int32_t i = 0; i < c->nseq; ++i) {
        sw_pose_seq *q = seq_at(s, i);
        sw_sim_cache_seq *e = &c->seq[i];
        memcpy(q->x, e->x, (size_t)q->npose * 3 * s->nv * sizeof(double));
        memcpy(q->contact_ptr, e->contact_ptr, (size_t)(q->npose + 1) * sizeof(int32_t));
        free(q->contacts);
        q->contacts = e->contacts;
        e->contacts = NULL;
        q->ncontacts = q->contact_cap = e->ncontacts;
        q->failed = e->failed;
        q->unsettled = e->unsettled;
        if (q->failed)
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "%d training poses of sequence %d diverged (cached)", q->failed, i);
    }
    return SINEW_OK;
}

/* Stores the sequences' solutions under key (a failure is only reported: the bake
 * itself has what it needs). */
static void store(sw_bake_state *s, uint64_t key, const char *path) {
    int32_t nseq = s->ntrain_seq + 1;
    sw_sim_cache c = {key, s->nv, nseq, calloc((size_t)nseq, sizeof(sw_sim_cache_seq))};
    sw_error e;
    uint8_t *b = NULL;
    size_t n = 0;
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (c.seq) {
        for (int32_t i = 0; i < nseq; ++i) {
            sw_pose_seq *q = seq_at(s, i);
            c.seq[i] = (sw_sim_cache_seq){q->npose, q->failed,      q->unsettled, q->ncontacts,
                                          q->x,     q->contact_ptr, q->contacts};
        }
        r = sw_sim_cache_encode(&c, &b, &n, &e);
        if (r == SINEW_OK) r = sw_write_file_atomic(path, b, n, &e);
    }
    if (r != SINEW_OK && s->p->progress)
        fprintf(stderr, "sinew-bake: simulate cache not stored: %s\n", e.msg);
    free(b);
    free(c.seq); /* the arrays are the sequences' */
}

sinew_result sw_bake_simulate_cached(sw_bake_state *s, int *cached, sw_error *err) {
    *cached = 0;
    const char *dir = s->p->cache_dir;
    if (!dir || !dir[0]) return sw_bake_simulate(s, err);
    struct stat st;
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return sw_error_set(err, SINEW_ERROR_IO, "cache folder '%s': cannot create it: %s", dir,
                            strerror(errno));
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return sw_error_set(err, SINEW_ERROR_IO, "cache folder '%s' is not a folder", dir);
    uint64_t key = simulate_key(s);
    char path[4200];
    snprintf(path, sizeof path, "%s/simulate-%016llx.bin", dir, (unsigned long long)key);
    size_t n = 0;
    uint8_t *b = read_all(path, &n);
    if (b) {
        int32_t nseq = s->ntrain_seq + 1, *npose = malloc((size_t)nseq * sizeof(int32_t));
        sw_sim_cache c;
        sw_error e;
        sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
        if (npose) {
            for (int32_t i = 0; i < nseq; ++i)
                npose[i] = seq_at(s, i)->npose;
            r = sw_sim_cache_parse(b, n, path, key, s->nv, nseq, npose, &c, &e);
        }
        free(npose);
        free(b);
        if (r == SINEW_OK) {
            r = adopt(s, &c, err);
            sw_sim_cache_free(&c);
            *cached = r == SINEW_OK;
            return r;
        }
        if (s->p->progress) fprintf(stderr, "sinew-bake: simulate cache unused: %s\n", e.msg);
    }
    sinew_result r = sw_bake_simulate(s, err);
    if (r == SINEW_OK) store(s, key, path);
    return r;
}
