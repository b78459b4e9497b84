/* sinew-bench --instances N (crowd_bench.h): the host side of a crowd. The library's step
 * stays lock-free; the workers here meet at a mutex/condition barrier twice a frame (the
 * frame's start and end), as a game's job system would around its skinning jobs. The
 * instances keep no scratch (def.shared_workspace): each worker steps whichever it takes
 * in its own workspace. */
#include "crowd_bench.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "clock.h"
#include "instance.h"
#include "tool_common.h"

enum { CROWD_WARMUP = 5, CROWD_MIN_FRAMES = 30 };

/* A reusable barrier whose count can shrink while threads wait on it (when a worker
 * thread cannot be created, the ones that were can still be released and joined). */
typedef struct barrier {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int count, waiting;
    unsigned gen;
} barrier;

static void barrier_wait(barrier *b) {
    pthread_mutex_lock(&b->mu);
    unsigned gen = b->gen;
    if (++b->waiting >= b->count) {
        b->waiting = 0;
        b->gen++;
        pthread_cond_broadcast(&b->cv);
    } else {
        while (gen == b->gen)
            pthread_cond_wait(&b->cv, &b->mu);
    }
    pthread_mutex_unlock(&b->mu);
}

/* Sets the count, releasing the waiters when as many as it wait already. */
static void barrier_set_count(barrier *b, int count) {
    pthread_mutex_lock(&b->mu);
    b->count = count;
    if (b->waiting > 0 && b->waiting >= count) {
        b->waiting = 0;
        b->gen++;
        pthread_cond_broadcast(&b->cv);
    }
    pthread_mutex_unlock(&b->mu);
}

/* One instance of the crowd and its host buffers. */
typedef struct member {
    sinew_instance *inst;
    float *pos, *nrm;
    int offset; /* clip frames it plays ahead of instance 0 */
    double k0;  /* its distance from the camera path's start, in character sizes */
} member;

/* Levels by distance (--lod auto): the instances stand from CROWD_NEAR to CROWD_FAR
 * character sizes from the camera, evenly, and the camera walks CROWD_WALK sizes a frame
 * through them (distances wrap), so levels change every few frames; a 60 degree field of
 * view makes a character k sizes away 1 / (2 k tan 30) of the screen high. */
#define CROWD_NEAR 1.0
#define CROWD_FAR 40.0
#define CROWD_WALK 0.25

/* The level member m's screen size picks at `frame`. */
static sinew_lod member_lod(const sinew_blob *blob, const member *m, int frame) {
    double span = CROWD_FAR - CROWD_NEAR;
    double k = CROWD_NEAR + fmod(m->k0 - CROWD_NEAR + CROWD_WALK * frame, span);
    return sinew_lod_for_screen_size(blob, (float)(1.0 / (2.0 * k * tan(0.5235987755982988))));
}

typedef struct crowd {
    const sw_character *ch;
    const sinew_blob *blob;
    int lod_auto; /* levels by distance */
    member *m;
    sinew_workspace **ws; /* one a thread */
    int nws;
    int n, nf;
    uint32_t ns;
    float dt;
    int frame, quit; /* written by the main thread before the start barrier only */
    atomic_int next; /* the next instance of this frame a worker takes */
    barrier start, done;
} crowd;

typedef struct worker {
    crowd *c;
    sinew_workspace *ws; /* the scratch of the instances this worker steps */
    long failed;
    pthread_t th;
} worker;

/* An instance's frame: the work the bench times for a lone instance (sub_ms). */
static int member_frame(const crowd *c, member *m, int frame, sinew_workspace *ws) {
    int f = (frame + m->offset) % c->nf;
    if (c->lod_auto) sinew_instance_set_lod(m->inst, member_lod(c->blob, m, frame));
    sw_instance_set_pose_d(m->inst, c->ch->clip.T + (size_t)f * 12 * c->ch->skel.nbones);
    int failed = sinew_instance_step_in(m->inst, ws, c->dt) != SINEW_OK;
    sinew_instance_read_surface(m->inst, m->pos, m->nrm, c->ns);
    return failed;
}

/* Instances taken one at a time from the frame's shared counter until none is left (a
 * job system's work stealing; each instance's result does not depend on who steps it). */
static void step_share(worker *w) {
    long failed = 0;
    for (int i; (i = atomic_fetch_add_explicit(&w->c->next, 1, memory_order_relaxed)) < w->c->n;)
        failed += member_frame(w->c, &w->c->m[i], w->c->frame, w->ws);
    w->failed += failed;
}

static void *worker_main(void *p) {
    worker *w = p;
    for (;;) {
        barrier_wait(&w->c->start);
        if (w->c->quit) return NULL;
        step_share(w);
        barrier_wait(&w->c->done);
    }
}

/* The crowd from rest on T threads (the main thread is worker 0): `warm` untimed frames,
 * then ms[0 .. frames-1], each frame's wall ms for all instances. */
static sinew_result crowd_run(crowd *c, int T, sinew_workspace **ws, int warm, int frames,
                              double *ms, long *failed, sw_error *err) {
    worker *w = calloc((size_t)T, sizeof *w);
    if (!w) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the crowd");
    for (int t = 0; t < T; ++t)
        w[t].ws = ws[t];
    for (int i = 0; i < c->n; ++i)
        sinew_instance_reset(c->m[i].inst);
    c->quit = 0;
    barrier_set_count(&c->start, T);
    barrier_set_count(&c->done, T);
    int started = 1;
    for (int t = 0; t < T; ++t)
        w[t].c = c;
    for (; started < T; ++started)
        if (pthread_create(&w[started].th, NULL, worker_main, &w[started]) != 0) break;
    sinew_result r = SINEW_OK;
    if (started < T) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "cannot create crowd thread %d of %d",
                         started + 1, T);
    } else {
        for (int f = 0; f < warm + frames; ++f) {
            c->frame = f;
            atomic_store_explicit(&c->next, 0, memory_order_relaxed); /* before the barrier */
            double t0 = sw_now_seconds();
            barrier_wait(&c->start);
            step_share(&w[0]);
            barrier_wait(&c->done);
            if (f >= warm) ms[f - warm] = 1e3 * (sw_now_seconds() - t0);
        }
    }
    c->quit = 1;
    barrier_set_count(&c->start, started); /* releases the workers to see quit */
    barrier_wait(&c->start);
    for (int t = 1; t < started; ++t)
        pthread_join(w[t].th, NULL);
    for (int t = 0; t < T; ++t)
        *failed += w[t].failed;
    free(w);
    return r;
}

static void crowd_free(crowd *c) {
    for (int t = 0; c->ws && t < c->nws; ++t)
        sinew_workspace_destroy(c->ws[t]);
    free(c->ws);
    for (int i = 0; c->m && i < c->n; ++i) {
        sinew_instance_destroy(c->m[i].inst);
        free(c->m[i].pos);
        free(c->m[i].nrm);
    }
    free(c->m);
    pthread_mutex_destroy(&c->start.mu);
    pthread_cond_destroy(&c->start.cv);
    pthread_mutex_destroy(&c->done.mu);
    pthread_cond_destroy(&c->done.cv);
}

static sinew_result crowd_make(const sw_character *ch, const sinew_blob *blob, int n, int T,
                               int lod_auto, crowd *c, sw_error *err) {
    memset(c, 0, sizeof *c);
    c->ch = ch;
    c->blob = blob;
    c->lod_auto = lod_auto;
    c->n = n;
    c->nf = ch->clip.nframes;
    c->ns = sinew_blob_surface_vertex_count(blob);
    c->dt = 1.0f / (float)(ch->clip.fps > 0 ? ch->clip.fps : 30);
    pthread_mutex_init(&c->start.mu, NULL);
    pthread_cond_init(&c->start.cv, NULL);
    pthread_mutex_init(&c->done.mu, NULL);
    pthread_cond_init(&c->done.cv, NULL);
    c->m = calloc((size_t)n, sizeof *c->m);
    c->ws = calloc((size_t)T, sizeof *c->ws);
    if (!c->m || !c->ws)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the crowd");
    sinew_instance_def d = sinew_instance_def_default();
    d.shared_workspace = 1;
    for (; c->nws < T; ++c->nws) {
        sinew_result r = sinew_workspace_create(blob, &d, &c->ws[c->nws]);
        if (r != SINEW_OK)
            return sw_error_set(err, r, "cannot create crowd workspace %d of %d: %s", c->nws + 1, T,
                                sinew_result_string(r));
    }
    for (int i = 0; i < n; ++i) {
        member *m = &c->m[i];
        m->offset = (int)((long)i * c->nf / n);
        m->k0 = CROWD_NEAR + (CROWD_FAR - CROWD_NEAR) * (i + 0.5) / n;
        m->pos = malloc(sizeof(float) * 3 * c->ns);
        m->nrm = malloc(sizeof(float) * 3 * c->ns);
        if (!m->pos || !m->nrm)
            return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the crowd");
        sinew_result r = sinew_instance_create(blob, &d, &m->inst);
        if (r != SINEW_OK)
            return sw_error_set(err, r, "cannot create crowd instance %d of %d: %s", i + 1, n,
                                sinew_result_string(r));
    }
    return SINEW_OK;
}

/* The instances at each level over the timed frames, a frame's mean. */
static void level_counts(const crowd *c, int warm, int frames, double *at) {
    for (int l = 0; l < 3; ++l)
        at[l] = 0;
    for (int f = warm; f < warm + frames; ++f)
        for (int i = 0; i < c->n; ++i)
            at[c->lod_auto ? member_lod(c->blob, &c->m[i], f) : SINEW_LOD_FULL] += 1.0 / frames;
}

sinew_result sw_crowd_bench_run(const sw_character *ch, const sinew_blob *blob, int instances,
                                int threads, int lod_auto, sw_crowd_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    long nproc = sysconf(_SC_NPROCESSORS_ONLN);
    int T = threads > 0 ? threads : nproc > 0 ? (int)nproc : 1;
    int frames = ch->clip.nframes > CROWD_MIN_FRAMES ? ch->clip.nframes : CROWD_MIN_FRAMES;
    out->instances = instances;
    out->threads = T;
    out->warmup_frames = CROWD_WARMUP;
    out->frames = frames;
    crowd c;
    double *ms = malloc(sizeof(double) * (size_t)frames);
    sinew_result r = ms ? crowd_make(ch, blob, instances, T, lod_auto, &c, err)
                        : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    if (r == SINEW_OK) { /* a lone instance: instance 0's motion, nothing else running */
        member *m0 = &c.m[0];
        sinew_instance_reset(m0->inst);
        for (int f = 0; f < CROWD_WARMUP + frames; ++f) {
            double t0 = sw_now_seconds();
            out->failed += member_frame(&c, m0, f, c.ws[0]);
            if (f >= CROWD_WARMUP) ms[f - CROWD_WARMUP] = 1e3 * (sw_now_seconds() - t0);
        }
        double sum = 0;
        for (int f = 0; f < frames; ++f)
            sum += ms[f];
        out->lone_ms = sum / frames;
        out->lone_median_ms = sw_median(ms, frames);
        r = crowd_run(&c, 1, c.ws, CROWD_WARMUP, frames, ms, &out->failed, err);
    }
    if (r == SINEW_OK) {
        out->ms_1thread = sw_median(ms, frames);
        r = crowd_run(&c, T, c.ws, CROWD_WARMUP, frames, ms, &out->failed, err);
    }
    if (r == SINEW_OK) {
        sinew_instance_def d = sinew_instance_def_default();
        d.shared_workspace = 1;
        size_t ib = 0, wb = 0;
        sinew_instance_memory_size(blob, &d, &ib);
        sinew_workspace_memory_size(blob, &d, &wb);
        out->instance_bytes = ib;
        out->workspace_bytes = wb;
        out->crowd_bytes = (double)ib * instances + (double)wb * T;
        out->ms = sw_median(ms, frames);
        out->us_per_instance = 1e3 * out->ms / instances;
        out->scaling = out->ms > 0 ? out->ms_1thread / out->ms : 0;
        out->vs_lone = out->lone_ms > 0 ? out->ms * T / instances / out->lone_ms : 0;
        out->lod_auto = lod_auto;
        level_counts(&c, CROWD_WARMUP, frames, out->at_level);
    }
    if (ms) crowd_free(&c);
    free(ms);
    return r;
}
