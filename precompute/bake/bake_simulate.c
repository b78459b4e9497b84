/* Stage "simulate" (bake.c, sw_bake_stages): reads s->rig, s->poses; writes the
 * sequences' solutions and contact sets in s->poses, and the result's train_*, heldout_*,
 * mass and sweeps. Full-space quasistatic solutions with self-contact (fullsim.h), each
 * chain of poses on its own core, each pose warm-started from the one before; the chains
 * the cache holds are read from it instead (bake_cache.c). */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "clock.h"
#include "fullsim.h"

/* Appends the simulator's contact set as pose k's (the pose-space self-contact data,
 * bake_contacts.c). Returns 0 when out of memory. */
static int keep_contacts(sw_pose_seq *q, int32_t k, const sw_fullsim *sim) {
    int32_t n;
    const sw_contact *c = sw_fullsim_contacts(sim, &n);
    if (q->ncontacts + n > q->contact_cap) {
        int32_t cap = 2 * (q->ncontacts + n) + 64;
        sw_contact *m = realloc(q->contacts, (size_t)cap * sizeof *m);
        if (!m) return 0;
        q->contacts = m;
        q->contact_cap = cap;
    }
    if (n > 0) memcpy(q->contacts + q->ncontacts, c, (size_t)n * sizeof *c);
    q->ncontacts += n;
    q->contact_ptr[k + 1] = q->ncontacts;
    return 1;
}

/* Solves q's poses in order, from the simulator's current state. */
static void simulate_seq(sw_bake_state *s, sw_fullsim *sim, sw_pose_seq *q) {
    for (int32_t k = 0; k < q->npose; ++k) {
        sw_fullsim_stats st;
        sinew_result r = sw_fullsim_step(sim, q->T + (size_t)k * 12 * s->rig.nb, &st);
        if (r == SINEW_ERROR_NOT_FINITE) q->failed++;
        q->unsettled += st.contacts_unsettled;
        memcpy(q->x + (size_t)k * 3 * s->rig.nv, sw_fullsim_positions(sim),
               (size_t)s->rig.nv * 3 * sizeof(double));
        if (!keep_contacts(q, k, sim)) q->oom = 1;
        sw_bake_progress(s, 1);
    }
}

typedef struct {
    sw_bake_state *s;
    sw_pose_seq **seqs;
    int32_t nseq;
    atomic_int next;
    atomic_int failed; /* sequences whose simulator could not be created */
} sim_ctx;

static void simulate_worker(void *vctx, int64_t begin, int64_t end, int worker) {
    (void)begin;
    (void)end;
    (void)worker;
    sim_ctx *ctx = vctx;
    sw_bake_state *s = ctx->s;
    for (;;) { /* dynamic scheduling: sequences differ a lot in cost */
        int i = atomic_fetch_add(&ctx->next, 1);
        if (i >= ctx->nseq) break;
        sw_pose_seq *q = ctx->seqs[i];
        const double t0 = sw_now_seconds();
        sw_fullsim_params fp = sw_bake_sim_params(s->p);
        /* a chained path (the clip's training then held-out frames) is the longest serial
           run: it gets every core (the simulator's results do not depend on its thread
           count), the others one each */
        fp.threads = q->then[0] || q->then[1] ? sw_pool_size(s->pool) : 1;
        sw_fullsim *sim;
        sw_error e;
        if (sw_fullsim_create(&s->rig.ch, &fp, &sim, &e) != SINEW_OK) {
            atomic_fetch_add(&ctx->failed, 1);
            continue;
        }
        simulate_seq(s, sim, q);
        for (int c = 0; c < 2; ++c)
            if (q->then[c] && q->npose > 0) {
                sw_fullsim_set_state(sim, q->T + (size_t)(q->npose - 1) * 12 * s->rig.nb,
                                     q->x + (size_t)(q->npose - 1) * 3 * s->rig.nv, NULL);
                simulate_seq(s, sim, q->then[c]);
            }
        sw_fullsim_destroy(sim);
        q->seconds = sw_now_seconds() - t0;
    }
}

/* Poses solved one after the other from q on: q's and its continuations'. */
static int64_t path_poses(const sw_pose_seq *q) {
    return q->npose + (q->then[0] ? q->then[0]->npose : 0) + (q->then[1] ? q->then[1]->npose : 0);
}

static sinew_result simulate_solve(sw_bake_state *s, sw_error *err) {
    sw_pose_seq *seqs[4096];
    int32_t n = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq && n < 4095; ++i)
        if (!s->poses.train[i].continues && !s->poses.train[i].from_cache &&
            !s->poses.train[i].skip)
            seqs[n++] = &s->poses.train[i];
    if (s->poses.heldout.npose > 0 && !s->poses.heldout.continues && !s->poses.heldout.from_cache &&
        !s->poses.heldout.skip)
        seqs[n++] = &s->poses.heldout;
    /* longest path first (stable): a long clip taken last by one worker would leave the
       others idle at the end (each path's results do not depend on the order) */
    for (int32_t i = 1; i < n; ++i)
        for (int32_t j = i; j > 0 && path_poses(seqs[j]) > path_poses(seqs[j - 1]); --j) {
            sw_pose_seq *t = seqs[j];
            seqs[j] = seqs[j - 1];
            seqs[j - 1] = t;
        }
    sim_ctx ctx;
    ctx.s = s;
    ctx.seqs = seqs;
    ctx.nseq = n;
    atomic_init(&ctx.next, 0);
    atomic_init(&ctx.failed, 0);
    int64_t poses = 0; /* the chains to solve (the others came from the cache) */
    for (int32_t i = 0; i < n; ++i)
        poses += path_poses(seqs[i]);
    s->poses.solved_poses = poses;
    sw_bake_progress_begin(s, "simulate", poses);
    /* one task per worker; each worker pulls sequences until none is left. The direct
       solver's factorisations (--solver cholmod) run on OpenBLAS: with its own threads
       beside the workers, the Fox's simulate stage spun for 524 s, with 1 it took 124 s */
    openblas_set_num_threads(1);
    sw_pool_parallel_for(s->pool, sw_pool_size(s->pool), simulate_worker, &ctx);
    if (atomic_load(&ctx.failed) > 0)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "the full-space simulator rejected the character");
    n = 0; /* the checks below: every sequence, continuations too */
    for (int32_t i = 0; i < s->poses.ntrain_seq && n < 4095; ++i)
        seqs[n++] = &s->poses.train[i];
    if (s->poses.heldout.npose > 0) seqs[n++] = &s->poses.heldout;
    for (int32_t i = 0; i < n; ++i)
        if (seqs[i]->oom)
            return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for contact sets");
    for (int32_t i = 0; i < n; ++i)
        if (seqs[i]->failed)
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "%d training poses of sequence %d diverged", seqs[i]->failed, i);
    return SINEW_OK;
}

/* Keeps the poses and full-space solutions for evaluation (sinew-bench, the report). */
static sinew_result keep_solutions(const sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    size_t pt = (size_t)12 * s->rig.nb * sizeof(double),
           px = (size_t)3 * s->rig.nv * sizeof(double);
    out->train_T = malloc((size_t)out->ntrain * pt + 1);
    out->train_x = malloc((size_t)out->ntrain * px + 1);
    out->heldout_T = malloc((size_t)out->nheldout * pt + 1);
    out->heldout_x = malloc((size_t)out->nheldout * px + 1);
    size_t pl = sizeof(int32_t);
    out->train_clip = malloc((size_t)out->ntrain * pl + 1);
    out->train_frame = malloc((size_t)out->ntrain * pl + 1);
    out->heldout_clip = malloc((size_t)out->nheldout * pl + 1);
    out->heldout_frame = malloc((size_t)out->nheldout * pl + 1);
    if (!out->train_T || !out->train_x || !out->heldout_T || !out->heldout_x || !out->train_clip ||
        !out->train_frame || !out->heldout_clip || !out->heldout_frame)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for solutions");
    int32_t k = 0;
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i)
        for (int32_t j = 0; j < s->poses.train[i].npose; ++j, ++k) {
            memcpy((char *)out->train_T + k * pt, (const char *)s->poses.train[i].T + j * pt, pt);
            memcpy((char *)out->train_x + k * px, (const char *)s->poses.train[i].x + j * px, px);
            out->train_clip[k] = s->poses.train[i].clip[j];
            out->train_frame[k] = s->poses.train[i].frame[j];
        }
    if (out->nheldout) {
        memcpy(out->heldout_T, s->poses.heldout.T, (size_t)out->nheldout * pt);
        memcpy(out->heldout_x, s->poses.heldout.x, (size_t)out->nheldout * px);
        memcpy(out->heldout_clip, s->poses.heldout.clip, (size_t)out->nheldout * pl);
        memcpy(out->heldout_frame, s->poses.heldout.frame, (size_t)out->nheldout * pl);
    }
    return SINEW_OK;
}

/* simulate: the poses' full-space solutions (through the cache), and what the result keeps
 * of them for evaluation (sinew-bench, the report). */
/* Says which items a bake that shares a cache with a farm solves itself: those no shard
 * stored (a shard that never ran, or a corrupt entry), so that the bake completes. */
static void say_missing(const sw_bake_state *s, const sw_bake_result *out) {
    int32_t hit = 0, miss = 0;
    for (int32_t i = 0; i < out->nitems; ++i)
        out->items[i].cached ? ++hit : ++miss;
    if (!s->p->progress || hit == 0 || miss == 0) return;
    fprintf(stderr,
            "sinew-bake: simulate: %d of %d work items not in the cache, solving them:", miss,
            out->nitems);
    for (int32_t i = 0; i < out->nitems; ++i)
        if (!out->items[i].cached)
            fprintf(stderr, " %d (%016llx)", i, (unsigned long long)out->items[i].key);
    fprintf(stderr, "\n");
}

sinew_result sw_bake_simulate(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    const sw_bake_params *p = s->p;
    const int farm = p->plan_only || p->shard_count > 0;
    if (p->shard_count > 0 && (!p->cache_dir || !p->cache_dir[0]))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "a shard's work goes to the cache: give a cache folder");
    if (p->shard_count > 0 && (p->shard_index < 0 || p->shard_index >= p->shard_count))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "shard %d of %d: want 0..%d",
                            p->shard_index, p->shard_count, p->shard_count - 1);
    int all = 0; /* the chains the cache holds are marked read, the rest solved */
    sinew_result r = sw_bake_cache_read(s, &all, err);
    if (r == SINEW_OK && (farm || (p->cache_dir && p->cache_dir[0])))
        r = sw_bake_cache_items(s, out, err);
    if (r == SINEW_OK && !farm) say_missing(s, out);
    if (r == SINEW_OK && !p->plan_only) r = simulate_solve(s, err);
    if (r != SINEW_OK) return r;
    const int32_t unstored = sw_bake_cache_store(s);
    if (unstored > 0 && p->shard_count > 0)
        return sw_error_set(err, SINEW_ERROR_IO,
                            "shard %d of %d: %d work items solved but not stored in '%s'",
                            p->shard_index, p->shard_count, unstored, p->cache_dir);
    if (out->nitems) sw_bake_cache_item_times(s, out);
    out->simulate_solved = (int32_t)s->poses.solved_poses;
    if (farm) return SINEW_OK; /* the items are in the cache: the reduce is another run's */
    out->simulate_cached = p->cache_dir && p->cache_dir[0] && all;
    out->return_poses = s->poses.return_poses;
    out->pair_sweep_poses = s->poses.pair_sweep_poses;
    size_t na = (size_t)s->rig.nb * 3 * sizeof(double);
    if (!(out->sweep_axis = sw_bake_own(out, malloc(na))) ||
        !(out->sweep_angle = sw_bake_own(out, malloc(na / 3))))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    memcpy(out->sweep_axis, s->poses.sweep_axis, na);
    memcpy(out->sweep_angle, s->poses.sweep_angle, na / 3);
    for (int32_t i = 0; i < s->poses.ntrain_seq; ++i) {
        out->ntrain += s->poses.train[i].npose;
        out->train_unsettled += s->poses.train[i].unsettled;
    }
    out->nheldout = s->poses.heldout.npose;
    out->heldout_after = s->poses.heldout.continues ? s->poses.train[0].npose : 0;
    out->heldout_unsettled = s->poses.heldout.unsettled;
    if ((r = keep_solutions(s, out, err)) != SINEW_OK) return r;
    if (!(out->mass = malloc((size_t)s->rig.nv * sizeof(double))))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    memcpy(out->mass, s->rig.mass, (size_t)s->rig.nv * sizeof(double));
    return SINEW_OK;
}
