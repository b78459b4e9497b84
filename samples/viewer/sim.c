/* Stepping N instances on T threads. The instances are independent (sinew.h): a worker
 * owns instances k, k + T, ...; workers are started for each batch of steps, which costs
 * tens of microseconds a frame and keeps the viewer free of a job system. */
#include "sim.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

static void log_stderr(sinew_log_level level, uint32_t id, const char *msg, void *user) {
    (void)user;
    fprintf(stderr, "sinew-view: sinew %s %u: %s\n", level == SINEW_LOG_ERROR ? "error" : "warning",
            id, msg);
}

static int create_instances(vw_sim *s, char *err, size_t errlen) {
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = s->dynamic ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
    d.logger.log = log_stderr;
    /* Against a world, flesh pressed on a collider is solved in full space where it
     * touches; a blob without the tet mesh cannot, and steps without it. */
    sinew_instance *probe = NULL;
    d.max_patch_vertices = s->world ? 2000 : 0;
    d.logger.log = NULL; /* (the probe's refusal is expected: silent) */
    if (d.max_patch_vertices && sinew_instance_create(s->blob, &d, &probe) != SINEW_OK)
        d.max_patch_vertices = 0;
    sinew_instance_destroy(probe);
    d.logger.log = log_stderr;
    for (int32_t i = 0; i < s->n; ++i) {
        sinew_result r = sinew_instance_create(s->blob, &d, &s->ch[i].inst);
        if (r == SINEW_OK && s->world) r = sinew_instance_set_world(s->ch[i].inst, s->world);
        if (r != SINEW_OK) {
            snprintf(err, errlen, "cannot create instance %d: %s", i, sinew_result_string(r));
            return 0;
        }
    }
    return 1;
}

int vw_sim_create(vw_sim *s, const sinew_blob *blob, const vw_asset *a, const vw_motion *m,
                  int32_t n, int threads, int dynamic, const sinew_world *world, int rest_pose,
                  char *err, size_t errlen) {
    memset(s, 0, sizeof *s);
    s->world = world, s->rest_pose = rest_pose;
    s->blob = blob, s->asset = a, s->motion = *m, s->n = n, s->dynamic = dynamic;
    s->threads = threads < 1 ? 1 : (threads > n ? n : threads);
    s->ch = calloc((size_t)n, sizeof *s->ch);
    if (!s->ch) return snprintf(err, errlen, "out of memory"), 0;
    size_t nv = 3 * (size_t)a->nverts;
    for (int32_t i = 0; i < n; ++i) {
        vw_char *c = &s->ch[i];
        c->pose = malloc(sizeof(float) * 12 * (size_t)a->nbones);
        c->pos = calloc(nv, sizeof(float)), c->nrm = calloc(nv, sizeof(float));
        c->skin_pos = calloc(nv, sizeof(float)), c->skin_nrm = calloc(nv, sizeof(float));
        if (!c->pose || !c->pos || !c->nrm || !c->skin_pos || !c->skin_nrm)
            return snprintf(err, errlen, "out of memory"), 0;
        /* different phases, so a crowd does not move in lockstep */
        c->phase = a->clip_duration[m->clip] > 0 ? 0.37 * i : 0;
        c->last_t = -1;
        c->stats.struct_size = sizeof c->stats;
    }
    return create_instances(s, err, errlen);
}

int vw_sim_record(vw_sim *s, const char *path, char *err, size_t errlen) {
    sinew_recorder_def rd = sinew_recorder_def_default();
    rd.path = path;
    sinew_result r = sinew_recorder_open(&rd, &s->rec);
    if (r != SINEW_OK) {
        s->rec = NULL;
        return snprintf(err, errlen, "--record-calls %s: cannot create it: %s", path,
                        sinew_result_string(r)),
               0;
    }
    /* (the world, if any, was attached at creation: its colliders are in the recording) */
    r = sinew_instance_set_recorder(s->ch[0].inst, s->rec);
    if (r != SINEW_OK) {
        sinew_recorder_close(s->rec), s->rec = NULL;
        return snprintf(err, errlen, "--record-calls %s: the instance refuses it: %s", path,
                        sinew_result_string(r)),
               0;
    }
    s->rec_path = path;
    return 1;
}

void vw_sim_flush(vw_sim *s) {
    if (s->rec) sinew_recorder_flush(s->rec);
}

/* Detaches and closes the recording; says so if the file is incomplete. */
static void stop_recording(vw_sim *s, const char *why) {
    if (!s->rec) return;
    sinew_instance_set_recorder(s->ch[0].inst, NULL);
    sinew_result r = sinew_recorder_close(s->rec);
    s->rec = NULL;
    if (r != SINEW_OK)
        fprintf(stderr, "sinew-view: --record-calls %s: writing it failed: %s\n", s->rec_path,
                sinew_result_string(r));
    else if (why)
        fprintf(stderr, "sinew-view: --record-calls %s: the recording ends here (%s)\n",
                s->rec_path, why);
}

int vw_sim_set_mode(vw_sim *s, int dynamic, char *err, size_t errlen) {
    stop_recording(s, "the instances are recreated in the other step mode");
    for (int32_t i = 0; i < s->n; ++i)
        sinew_instance_destroy(s->ch[i].inst), s->ch[i].inst = NULL;
    s->dynamic = dynamic;
    return create_instances(s, err, errlen);
}

typedef struct batch {
    vw_sim *s;
    int worker;
    double t;
    float dt;
} batch;

/* The pose of character c at simulation time t: the clip's (or the fade's), or the rest
 * pose. */
static int pose_at(const vw_sim *s, vw_char *c, double t) {
    if (!s->rest_pose) return vw_motion_pose(s->asset, &s->motion, t + c->phase, t, c->pose);
    memset(c->pose, 0, sizeof(float) * 12 * (size_t)s->asset->nbones);
    for (int32_t b = 0; b < s->asset->nbones; ++b)
        c->pose[12 * b] = c->pose[12 * b + 4] = c->pose[12 * b + 8] = 1;
    return 1;
}

static int moves(const vw_sim *s) {
    return s->motion.root_bone >= 0 || s->motion.walk != 0 || s->motion.turn != 0;
}

/* The actor's frame to the world's, for drawing. */
static void to_world(const vw_sim *s, const vw_char *c, float *pos, float *nrm) {
    for (int32_t v = 0; moves(s) && v < s->asset->nverts; ++v)
        vw_planar_apply(&c->actor, pos + 3 * v, 1), vw_planar_apply(&c->actor, nrm + 3 * v, 0);
}

void vw_sim_actor_point(const vw_sim *s, int32_t i, float p[3]) {
    if (moves(s)) vw_planar_apply(&s->ch[i].actor, p, 1);
}

static void step_one(vw_sim *s, vw_char *c, double t, float dt) {
    const vw_asset *a = s->asset;
    if (!pose_at(s, c, t)) return;
    if (moves(s) && !s->rest_pose) {
        if (c->last_t >= 0 && t > c->last_t && t - c->last_t <= 0.25)
            vw_motion_advance(a, &s->motion, c->last_t + c->phase, t + c->phase, t, &c->actor);
        double A[12];
        vw_planar_matrix(&c->actor, A);
        sinew_instance_set_actor(c->inst, A);
    }
    c->last_t = t;
    c->last = sinew_instance_set_pose(c->inst, c->pose, (uint32_t)a->nbones);
    if (c->last == SINEW_OK) c->last = sinew_instance_step(c->inst, dt);
    sinew_instance_get_stats(c->inst, &c->stats);
    sinew_instance_read_surface(c->inst, c->pos, c->nrm, (uint32_t)a->nverts);
    to_world(s, c, c->pos, c->nrm);
}

static void *worker(void *arg) {
    batch *b = arg;
    for (int32_t i = b->worker; i < b->s->n; i += b->s->threads)
        step_one(b->s, &b->s->ch[i], b->t, b->dt);
    return NULL;
}

void vw_sim_step(vw_sim *s, double t, float dt) {
    s->t = t;
    if (s->threads <= 1) {
        for (int32_t i = 0; i < s->n; ++i)
            step_one(s, &s->ch[i], t, dt);
        return;
    }
    pthread_t tid[64];
    batch b[64];
    int nt = s->threads > 64 ? 64 : s->threads, started = 0;
    for (int k = 0; k < nt; ++k)
        b[k] = (batch){s, k, t, dt};
    for (int k = 1; k < nt; ++k) {
        if (pthread_create(&tid[k], NULL, worker, &b[k]) != 0) break;
        started = k;
    }
    worker(&b[0]);
    for (int k = 1; k <= started; ++k)
        pthread_join(tid[k], NULL);
    for (int k = started + 1; k < nt; ++k) /* (a worker that did not start: its share here) */
        worker(&b[k]);
}

void vw_sim_teleport(vw_sim *s) {
    for (int32_t i = 0; i < s->n; ++i)
        sinew_instance_mark_teleport(s->ch[i].inst), s->ch[i].last_t = -1;
}

void vw_sim_skin(vw_sim *s, int dqs) {
    for (int32_t i = 0; i < s->n; ++i) {
        vw_char *c = &s->ch[i];
        if (!pose_at(s, c, s->t)) continue;
        vw_skin(s->asset, c->pose, dqs, c->skin_pos, c->skin_nrm);
        to_world(s, c, c->skin_pos, c->skin_nrm);
    }
}

void vw_sim_destroy(vw_sim *s) {
    if (s->ch) stop_recording(s, NULL);
    for (int32_t i = 0; s->ch && i < s->n; ++i) {
        vw_char *c = &s->ch[i];
        sinew_instance_destroy(c->inst);
        free(c->pose), free(c->pos), free(c->nrm), free(c->skin_pos), free(c->skin_nrm);
    }
    free(s->ch);
    memset(s, 0, sizeof *s);
}
