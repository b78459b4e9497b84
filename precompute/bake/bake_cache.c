/* A helper of the simulate stage (bake_simulate.c), below it: the chains of poses it
 * would solve, read from and stored to the cache folder. */
/* The simulate stage through its cache (sim_cache.h, sw_bake_params.cache_dir): the key
 * hashes every input of the full-space solves, so a file found under it holds exactly
 * the solutions this bake would compute (the reference's results do not depend on its
 * thread count). A file that cannot be used is reported and solved around. Each file is
 * one work item of a farm (sw_bake_params.shard_count): shards on many machines fill one
 * shared folder, and a bake that finds every item there only reduces. */
#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bake_state.h"
#include "blob_write.h"
#include "sim_cache.h"

/* Bump when the reference's physics or the file layout changes: a cache of the old code
 * then misses instead of handing back solutions the new code would not compute. */
#define SW_SIM_CACHE_VERSION 1

#define MIX(h, v) ((h) = sw_fnv1a((h), &(v), sizeof(v)))

/* A chain: a sequence solved from rest and the sequences that continue it (its then[]),
 * in that order; the cache keeps one file per chain, so that a bake that adds or changes
 * a clip, a sweep or the adaptive loop's poses solves only the chains that changed. */
typedef struct chain {
    sw_pose_seq *seq[3];
    int32_t n;
} chain;

static chain chain_of(sw_pose_seq *root) {
    chain c = {{root, NULL, NULL}, 1};
    for (int k = 0; k < 2; ++k)
        if (root->then[k]) c.seq[c.n++] = root->then[k];
    return c;
}

/* Everything every solve depends on but its poses: mesh, weights, material, simulator. */
static uint64_t character_key(sw_bake_state *s) {
    uint64_t h = SW_FNV_START;
    const char tag[] = "sinew simulate cache";
    h = sw_fnv1a(h, tag, sizeof tag);
    int32_t version = SW_SIM_CACHE_VERSION, nv = s->rig.nv, nt = s->rig.ch.mesh.ntets,
            nb = s->rig.nb;
    MIX(h, version);
    MIX(h, nv);
    MIX(h, nt);
    MIX(h, nb);
    h = sw_fnv1a(h, s->rig.ch.mesh.X, (size_t)nv * 3 * sizeof(double));
    h = sw_fnv1a(h, s->rig.ch.mesh.tets, (size_t)nt * 4 * sizeof(int32_t));
    h = sw_fnv1a(h, s->rig.ch.bone_of_vertex, (size_t)nv * sizeof(int32_t));
    h = sw_fnv1a(h, s->rig.ch.weights.w, (size_t)nv * nb * sizeof(double));
    MIX(h, s->rig.ch.youngs);
    MIX(h, s->rig.ch.poisson);
    MIX(h, s->rig.ch.density);
    if (s->rig.ch.tet_stiffness) /* painted (an unpainted character's key is as it was) */
        h = sw_fnv1a(h, s->rig.ch.tet_stiffness, (size_t)nt * sizeof(double));
    sw_fullsim_params fp = sw_bake_sim_params(s->p); /* field by field: no padding bytes */
    int32_t ints[] = {(int32_t)fp.integrator, fp.self_contact,    fp.ground,
                      (int32_t)fp.hessian,    (int32_t)fp.solver, fp.contact_rounds,
                      fp.contact_set_check,   fp.max_newton,      fp.pcg_max};
    double reals[] = {
        fp.dt,         fp.rayleigh_alpha, fp.rayleigh_beta, fp.gravity[0],       fp.gravity[1],
        fp.gravity[2], fp.contact_k,      fp.contact_alpha, fp.neighbour_factor, fp.ground_height,
        fp.ground_k,   fp.newton_rtol,    fp.pcg_rtol};
    h = sw_fnv1a(h, ints, sizeof ints);
    h = sw_fnv1a(h, reals, sizeof reals);
    return h;
}

/* The chain's key: the character's, then its sequences' poses in solving order. */
static uint64_t chain_key(const sw_bake_state *s, uint64_t character, const chain *c) {
    uint64_t h = character;
    int32_t n = c->n;
    MIX(h, n);
    for (int32_t i = 0; i < c->n; ++i) {
        const sw_pose_seq *q = c->seq[i];
        int32_t links[3] = {q->npose, q->then[0] != NULL, q->then[1] != NULL};
        h = sw_fnv1a(h, links, sizeof links);
        h = sw_fnv1a(h, q->T, (size_t)q->npose * 12 * s->rig.nb * sizeof(double));
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

/* Hands the cache's arrays to the chain's sequences. */
static sinew_result adopt(sw_bake_state *s, const chain *ch, sw_sim_cache *c, sw_error *err) {
    for (int32_t i = 0; i < c->nseq; ++i) {
        sw_pose_seq *q = ch->seq[i];
        sw_sim_cache_seq *e = &c->seq[i];
        memcpy(q->x, e->x, (size_t)q->npose * 3 * s->rig.nv * sizeof(double));
        memcpy(q->contact_ptr, e->contact_ptr, (size_t)(q->npose + 1) * sizeof(int32_t));
        free(q->contacts);
        q->contacts = e->contacts;
        e->contacts = NULL;
        q->ncontacts = q->contact_cap = e->ncontacts;
        q->failed = e->failed;
        q->unsettled = e->unsettled;
        q->from_cache = 1;
        if (q->failed)
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "%d training poses of a cached sequence diverged", q->failed);
    }
    return SINEW_OK;
}

/* Writes the entry as a farm's shared cache needs it: to a temporary name no other
 * writer uses (host, process, call), then renamed over `path`. rename is atomic on a
 * POSIX file system and on NFS, so a reader sees the whole entry or none, two shards
 * that solve the same item at once each rename identical bytes, and a writer killed
 * mid-write leaves only its temporary file, which no reader opens. No lock: NFS does
 * not honour every kind. */
static sinew_result write_entry(const char *path, const uint8_t *b, size_t n, sw_error *err) {
    static atomic_int calls;
    char host[64] = "host", tmp[4300];
    gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    snprintf(tmp, sizeof tmp, "%s.tmp-%s-%ld-%d", path, host, (long)getpid(),
             atomic_fetch_add(&calls, 1));
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0)
        return sw_error_set(err, SINEW_ERROR_IO, "cannot create '%s': %s", tmp, strerror(errno));
    size_t at = 0;
    int e = 0;
    while (at < n && !e) {
        ssize_t w = write(fd, b + at, n - at);
        if (w < 0 && errno != EINTR) e = errno;
        if (w > 0) at += (size_t)w;
    }
    if (!e && fsync(fd) != 0) e = errno;
    if (close(fd) != 0 && !e) e = errno;
    if (!e && rename(tmp, path) != 0) e = errno;
    if (e) {
        unlink(tmp);
        return sw_error_set(err, SINEW_ERROR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    return SINEW_OK;
}

/* Stores the chain's solutions under key (0 when it could not: reported, and only a
 * shard, whose work is the entry, fails for it). */
static int store(sw_bake_state *s, const chain *ch, uint64_t key, const char *path) {
    sw_sim_cache_seq seq[3];
    sw_sim_cache c = {key, s->rig.nv, ch->n, seq};
    sw_error e;
    uint8_t *b = NULL;
    size_t n = 0;
    for (int32_t i = 0; i < ch->n; ++i) {
        sw_pose_seq *q = ch->seq[i];
        seq[i] = (sw_sim_cache_seq){q->npose, q->failed,      q->unsettled, q->ncontacts,
                                    q->x,     q->contact_ptr, q->contacts};
    }
    sinew_result r = sw_sim_cache_encode(&c, &b, &n, &e);
    if (r == SINEW_OK) r = write_entry(path, b, n, &e);
    if (r != SINEW_OK && s->p->progress)
        fprintf(stderr, "sinew-bake: simulate cache not stored: %s\n", e.msg);
    free(b); /* the arrays are the sequences' */
    return r == SINEW_OK;
}

/* Reads the chain's file when there is a usable one (1), reporting one that is not. */
static int lookup(sw_bake_state *s, const chain *ch, uint64_t key, const char *path,
                  sinew_result *r, sw_error *err) {
    size_t n = 0;
    uint8_t *b = read_all(path, &n);
    if (!b) return 0;
    int32_t npose[3];
    for (int32_t i = 0; i < ch->n; ++i)
        npose[i] = ch->seq[i]->npose;
    sw_sim_cache c;
    sw_error e;
    sinew_result pr = sw_sim_cache_parse(b, n, path, key, s->rig.nv, ch->n, npose, &c, &e);
    free(b);
    if (pr != SINEW_OK) {
        if (s->p->progress) fprintf(stderr, "sinew-bake: simulate cache unused: %s\n", e.msg);
        return 0;
    }
    *r = adopt(s, ch, &c, err);
    sw_sim_cache_free(&c);
    return 1;
}

/* Sequence i (the training ones, then the held-out one) when it starts a chain: the
 * chain, its key and its file under dir (0: it continues another, or is empty). */
static int chain_file(sw_bake_state *s, int32_t i, uint64_t character, const char *dir, chain *ch,
                      uint64_t *key, char *path, size_t size) {
    sw_pose_seq *q = i < s->poses.ntrain_seq ? &s->poses.train[i] : &s->poses.heldout;
    if (q->continues || q->npose == 0) return 0;
    *ch = chain_of(q);
    *key = chain_key(s, character, ch);
    snprintf(path, size, "%s/simulate-%016llx.bin", dir, (unsigned long long)*key);
    return 1;
}

sinew_result sw_bake_cache_read(sw_bake_state *s, int *all, sw_error *err) {
    *all = 0;
    const char *dir = s->p->cache_dir;
    if (!dir || !dir[0]) return SINEW_OK;
    struct stat st;
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return sw_error_set(err, SINEW_ERROR_IO, "cache folder '%s': cannot create it: %s", dir,
                            strerror(errno));
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return sw_error_set(err, SINEW_ERROR_IO, "cache folder '%s' is not a folder", dir);
    uint64_t character = character_key(s), key;
    int32_t nroot = 0, hits = 0;
    sinew_result r = SINEW_OK;
    char path[4200];
    chain ch;
    for (int32_t i = 0; i <= s->poses.ntrain_seq && r == SINEW_OK; ++i)
        if (chain_file(s, i, character, dir, &ch, &key, path, sizeof path)) {
            nroot++;
            hits += lookup(s, &ch, key, path, &r, err);
        }
    *all = r == SINEW_OK && hits == nroot;
    return r;
}

int32_t sw_bake_cache_store(sw_bake_state *s) {
    const char *dir = s->p->cache_dir;
    if (!dir || !dir[0]) return 0;
    uint64_t character = character_key(s), key;
    char path[4200];
    chain ch;
    int32_t failed = 0;
    for (int32_t i = 0; i <= s->poses.ntrain_seq; ++i)
        if (chain_file(s, i, character, dir, &ch, &key, path, sizeof path) &&
            !ch.seq[0]->from_cache && !ch.seq[0]->skip)
            failed += !store(s, &ch, key, path);
    return failed;
}

sinew_result sw_bake_cache_items(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    const sw_bake_params *p = s->p;
    const int32_t nshard = p->shard_count > 0 ? p->shard_count : 1;
    uint64_t character = character_key(s), key;
    char path[4200];
    chain ch;
    int32_t n = 0;
    sw_bake_item *it = sw_bake_own(out, malloc(((size_t)s->poses.ntrain_seq + 1) * sizeof *it));
    int64_t *load = calloc((size_t)nshard, sizeof *load);
    int32_t *order = malloc(((size_t)s->poses.ntrain_seq + 1) * sizeof *order);
    if (!it || !load || !order) {
        free(load);
        free(order);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for work items");
    }
    for (int32_t i = 0; i <= s->poses.ntrain_seq; ++i)
        if (chain_file(s, i, character, "", &ch, &key, path, sizeof path)) {
            int32_t poses = 0;
            for (int32_t k = 0; k < ch.n; ++k)
                poses += ch.seq[k]->npose;
            it[n] = (sw_bake_item){key, ch.n, poses, 0, ch.seq[0]->from_cache, 0};
            order[n] = n;
            n++;
        }
    /* the most poses first (ties in the stage's order), each to the shard with the fewest
       poses so far (the lowest index of a tie): the same plan on every machine */
    for (int32_t i = 1; i < n; ++i)
        for (int32_t j = i; j > 0 && it[order[j]].poses > it[order[j - 1]].poses; --j) {
            int32_t t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
    for (int32_t i = 0; i < n; ++i) {
        int32_t best = 0;
        for (int32_t k = 1; k < nshard; ++k)
            if (load[k] < load[best]) best = k;
        it[order[i]].shard = best;
        load[best] += it[order[i]].poses;
    }
    free(load);
    free(order);
    out->items = it;
    out->nitems = n;
    out->items_character = character;
    n = 0;
    for (int32_t i = 0; i <= s->poses.ntrain_seq; ++i)
        if (chain_file(s, i, character, "", &ch, &key, path, sizeof path)) {
            ch.seq[0]->skip = p->plan_only || (p->shard_count > 0 && it[n].shard != p->shard_index);
            n++;
        }
    return SINEW_OK;
}

void sw_bake_cache_item_times(const sw_bake_state *s, sw_bake_result *out) {
    int32_t n = 0;
    for (int32_t i = 0; i <= s->poses.ntrain_seq && n < out->nitems; ++i) {
        const sw_pose_seq *q = i < s->poses.ntrain_seq ? &s->poses.train[i] : &s->poses.heldout;
        if (q->continues || q->npose == 0) continue;
        out->items[n++].seconds = q->from_cache || q->skip ? 0 : q->seconds;
    }
}
