/* The recorder and its replay (sinew_recorder, sinew-replay): a 1,000-frame dynamic
 * session of the finger on a table with a ball poking along it, a reset of the actor's
 * place, a declared teleport and a paused frame replays bitwise, step by step; recorded
 * steps allocate and lock nothing; a recording with one record left out replays but
 * differs from that step on; a damaged, cut or foreign recording is refused with a
 * message saying what is wrong. A session under a mesh collider whose vertices the host
 * moves every step, ignoring another collider part of the time, replays bitwise too; a
 * version-1 recording still reads and replays. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "hash.h"
#include "recording.h"
#include "rt_interpose.h"
#include "sw_test.h"
#include "world_fixture.h"

#define FRAMES 1000
#define TELEPORT_AT 600

static char g_path[512];
static uint64_t g_hash[FRAMES]; /* the surface hash the session saw after each step */
static int g_lod;               /* the session changes its level of detail */

static void session_pose(const bake_fixture *f, int s, float *pose) {
    /* a jump of the clip at the teleport: frames from the other end */
    bake_fixture_pose(f, s < TELEPORT_AT ? s : s + f->ch.clip.nframes / 2, pose);
}

/* What a run of the session saw. */
typedef struct session {
    uint64_t hash[FRAMES]; /* the surface hash after each step */
    sw_rt_counts counts;   /* allocations and locks inside the steps */
    uint64_t contacts;     /* world contacts, summed over the steps */
    uint32_t teleports;    /* steps flagged SINEW_STEP_TELEPORT */
    double step_seconds;   /* wall clock inside sinew_instance_step */
} session;

/* Runs the session, recorded into g_path when `record` is set; 1 on success. */
static int run_session(moving_scene *m, int record, session *out) {
    const bake_fixture *f = m->f;
    uint32_t nb = (uint32_t)f->ch.skel.nbones;
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    sinew_instance *inst;
    if (sinew_instance_create(f->blob, &d, &inst) != SINEW_OK) return 0;
    if (sinew_instance_set_world(inst, m->w) != SINEW_OK) return 0;
    sinew_recorder_def rd = sinew_recorder_def_default();
    rd.path = g_path;
    rd.buffer_bytes = 1u << 16; /* small: the session fills it many times */
    sinew_recorder *rec = NULL;
    if (record && sinew_recorder_open(&rd, &rec) != SINEW_OK) return 0;
    if (record && sinew_instance_set_recorder(inst, rec) != SINEW_OK) return 0;
    float *pose = malloc(sizeof(float) * 12 * nb);
    double actor[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    memset(out, 0, sizeof *out);
    int ok = 1;
    for (int s = 0; s < FRAMES && ok; ++s) {
        sinew_transform t;
        ball_at(s, &t);
        sinew_world_set_collider_transform(m->w, m->ball, &t);
        actor[10] = s < 300 ? 0.0 : 0.01; /* the actor lifts a little at frame 300 */
        if (s == 0 || s == 300) ok &= sinew_instance_set_actor(inst, actor) == SINEW_OK;
        if (s == TELEPORT_AT) ok &= sinew_instance_mark_teleport(inst) == SINEW_OK;
        /* levels of detail: cheaper for a while, back in the middle of a fade, and again */
        static const int lod_at[] = {150, 180, 184, 450, 520};
        static const sinew_lod lod_to[] = {SINEW_LOD_POSE_SPACE, SINEW_LOD_REDUCED, SINEW_LOD_FULL,
                                           SINEW_LOD_POSE_SPACE, SINEW_LOD_FULL};
        for (int k = 0; k < 5 && g_lod; ++k)
            if (s == lod_at[k]) ok &= sinew_instance_set_lod(inst, lod_to[k]) == SINEW_OK;
        session_pose(f, s, pose);
        ok &= sinew_instance_set_pose(inst, pose, nb) == SINEW_OK;
        float dt = s == 700 ? 0.0f : (s % 3 ? 1.0f / 60 : 1.0f / 50); /* a pause, uneven dt */
        double t0 = sw_now_seconds();
        sw_rt_count_begin();
        sinew_instance_step(inst, dt);
        sw_rt_counts c = sw_rt_count_end();
        out->step_seconds += sw_now_seconds() - t0;
        out->counts.allocs += c.allocs;
        out->counts.frees += c.frees;
        out->counts.locks += c.locks;
        out->hash[s] = sw_instance_surface_hash(inst);
        sinew_step_stats st;
        st.struct_size = sizeof st;
        sinew_instance_get_stats(inst, &st);
        out->contacts += st.world_contacts;
        out->teleports += (st.status & SINEW_STEP_TELEPORT) != 0;
        if (rec && s % 100 == 99) ok &= sinew_recorder_flush(rec) == SINEW_OK;
    }
    ok &= sinew_instance_set_recorder(inst, NULL) == SINEW_OK;
    if (rec) ok &= sinew_recorder_close(rec) == SINEW_OK;
    free(pose);
    sinew_instance_destroy(inst);
    return ok;
}

/* The records of each type in a parsed recording. */
static void count_records(const sw_recording *r, uint32_t n[SW_REC_LOD + 1]) {
    memset(n, 0, sizeof(uint32_t) * (SW_REC_LOD + 1));
    size_t pos = 0;
    sw_rec_record one;
    while (sw_recording_next(r, &pos, &one))
        if (one.type <= SW_REC_LOD) n[one.type]++;
}

static unsigned char *read_all(size_t *n) {
    return (unsigned char *)sw_test_read_file(g_path, n);
}

/* A recording of format `version` of the records `stream` (size n) in one chunk, as the
 * recorder writes them. */
static unsigned char *rechunk_as(uint32_t version, const unsigned char *stream, size_t n,
                                 size_t *out_n) {
    unsigned char *d = malloc(SW_REC_PREAMBLE_BYTES + SW_REC_CHUNK_BYTES + n);
    static const unsigned char pre[8] = {'S', 'I', 'N', 'E', 'W', 'R', 'E', 'C'};
    uint32_t u[4] = {version, 0x01020304u, SW_REC_CHUNK_TAG, (uint32_t)n};
    uint64_t h = sw_fnv1a(SW_FNV_START, stream, n);
    memcpy(d, pre, 8);
    memcpy(d + 8, u, 16);
    memcpy(d + 24, &h, 8);
    memcpy(d + 32, stream, n);
    *out_n = 32 + n;
    return d;
}

static unsigned char *rechunk(const unsigned char *stream, size_t n, size_t *out_n) {
    return rechunk_as(SW_REC_VERSION, stream, n, out_n);
}

/* The recorded steps allocated and locked nothing (where the interposer counts them). */
static void ensure_no_allocs_or_locks(const sw_rt_counts *c) {
    unsigned active = sw_rt_interpose_active();
    if (active & SW_RT_CAT_ALLOCS)
        ENSUREF(c->allocs == 0 && c->frees == 0, "allocs %llu", (unsigned long long)c->allocs);
    if (active & SW_RT_CAT_LOCKS) ENSURE(c->locks == 0);
}

/* With SINEW_WRITE_SEEDS set, the recording d (n bytes) becomes the fuzzer's seed `name`
 * (tests/fuzz/corpus/recording). Returns 0 when it could not be written. */
static int write_seed(const char *name, const unsigned char *d, size_t n) {
    if (!getenv("SINEW_WRITE_SEEDS")) return 1;
    char path[512];
    snprintf(path, sizeof path, "%s/tests/fuzz/corpus/recording/%s", SINEW_SOURCE_DIR, name);
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(d, 1, n, fp) == n;
    return fp && fclose(fp) == 0 && ok;
}

TEST(a_session_with_pokes_and_a_teleport_replays_bitwise) {
    moving_scene m;
    ENSURE(moving_scene_make(&m));
    snprintf(g_path, sizeof g_path, "%s/tests/test_record_replay.rec", SINEW_BINARY_DIR);
    static session plain, recorded; /* (big: off the stack) */
    ENSURE(run_session(&m, 0, &plain));
    double t0 = sw_now_seconds();
    ENSURE(run_session(&m, 1, &recorded));
    double t_rec = sw_now_seconds() - t0;
    fprintf(stderr,
            "    the session: %.1f world contacts a step, %u teleports flagged; steps %.3f s "
            "unrecorded, %.3f s recorded\n",
            recorded.contacts / (double)FRAMES, recorded.teleports, plain.step_seconds,
            recorded.step_seconds);
    ENSURE(recorded.contacts > FRAMES && recorded.teleports >= 1); /* it poked, and jumped */
    /* recording changes nothing the host sees */
    ENSURE(memcmp(plain.hash, recorded.hash, sizeof plain.hash) == 0);
    memcpy(g_hash, recorded.hash, sizeof g_hash);
    ensure_no_allocs_or_locks(&recorded.counts);
    size_t n;
    unsigned char *data = read_all(&n);
    ENSURE(data);
    sw_recording rec;
    sw_error err;
    ENSUREF(sw_recording_parse(data, n, &rec, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rec.steps == FRAMES);
    sw_replay_report rep;
    t0 = sw_now_seconds();
    ENSUREF(sw_recording_replay(m.f->blob, &rec, NULL, NULL, &rep) == SINEW_OK, "%s", rep.msg);
    double t_rep = sw_now_seconds() - t0;
    fprintf(stderr,
            "    %u steps recorded in %.2f s (%zu bytes), replayed in %.2f s: %u differ "
            "(first %lld)\n",
            rec.steps, t_rec, n, t_rep, rep.differing, (long long)rep.first_diff);
    ENSURE(rep.steps == FRAMES && rep.differing == 0 && rep.first_diff == -1);
    /* the recorded hashes are the session's own */
    size_t pos = 0;
    sw_rec_record r;
    int s = 0, same = 1;
    while (sw_recording_next(&rec, &pos, &r))
        if (r.type == SW_REC_STEP) same &= sw_rec_u64(r.p + 16) == g_hash[s++];
    ENSURE(same && s == FRAMES);
    /* for sinew-replay's tests (tests/CMakeLists.txt): the blob beside the recording, and a
       copy of the recording with one bit flipped */
    char path[600];
    snprintf(path, sizeof path, "%s/tests/test_record_replay.blob", SINEW_BINARY_DIR);
    FILE *fp = fopen(path, "wb");
    ENSURE(fp && fwrite(m.f->data, 1, m.f->size, fp) == m.f->size && fclose(fp) == 0);
    snprintf(path, sizeof path, "%s/tests/test_record_replay.tampered.rec", SINEW_BINARY_DIR);
    data[n / 2] ^= 0x10;
    fp = fopen(path, "wb");
    ENSURE(fp && fwrite(data, 1, n, fp) == n && fclose(fp) == 0);
    sw_recording_free(&rec);
    free(data);
    sinew_world_destroy(m.w);
}

static int parse_says(const unsigned char *d, size_t n, const char *what);

/* The session changing its level of detail: every change recorded (LOD records, format 3)
 * and replayed bitwise, no allocation or lock in a step at any level. */
TEST(a_session_changing_its_level_of_detail_replays_bitwise) {
    moving_scene m;
    ENSURE(moving_scene_make(&m));
    char keep[512];
    memcpy(keep, g_path, sizeof keep);
    snprintf(g_path, sizeof g_path, "%s/tests/test_record_replay_lod.rec", SINEW_BINARY_DIR);
    static session recorded;
    g_lod = 1;
    int ran = run_session(&m, 1, &recorded);
    g_lod = 0;
    ENSURE(ran);
    ensure_no_allocs_or_locks(&recorded.counts);
    size_t n;
    unsigned char *data = read_all(&n);
    ENSURE(data);
    sw_recording rec;
    sw_error err;
    ENSUREF(sw_recording_parse(data, n, &rec, &err) == SINEW_OK, "%s", err.msg);
    uint32_t count[SW_REC_LOD + 1];
    count_records(&rec, count);
    ENSURE(rec.version == 3 && count[SW_REC_LOD] == 5); /* every change of level */
    sw_replay_report rep;
    ENSUREF(sw_recording_replay(m.f->blob, &rec, NULL, NULL, &rep) == SINEW_OK, "%s", rep.msg);
    ENSURE(rep.steps == FRAMES && rep.differing == 0);
    /* a version-2 reader knows no LOD record: a version-2 file holding one is refused */
    size_t n2;
    unsigned char *v2 = rechunk_as(2, rec.stream, rec.size, &n2);
    ENSURE(parse_says(v2, n2, "does not add up"));
    free(v2);
    sw_recording_free(&rec);
    free(data);
    remove(g_path);
    memcpy(g_path, keep, sizeof keep);
    sinew_world_destroy(m.w);
}

/* The replay must notice a record that went missing: without the pose set before step
 * DROP_AT, that step and the ones after it differ. */
#define DROP_AT 400
TEST(a_recording_without_one_pose_differs_from_there) {
    size_t n;
    unsigned char *data = read_all(&n);
    ENSURE(data);
    sw_recording rec;
    sw_error err;
    ENSURE(sw_recording_parse(data, n, &rec, &err) == SINEW_OK);
    unsigned char *cut = malloc(rec.size);
    size_t pos = 0, at = 0, m = 0;
    sw_rec_record r;
    int steps = 0, dropped = 0;
    while (at = pos, sw_recording_next(&rec, &pos, &r)) {
        if (r.type == SW_REC_POSE && steps == DROP_AT && !dropped) {
            dropped = 1;
            continue;
        }
        steps += r.type == SW_REC_STEP;
        memcpy(cut + m, rec.stream + at, pos - at);
        m += pos - at;
    }
    ENSURE(dropped);
    size_t n2;
    unsigned char *d2 = rechunk(cut, m, &n2);
    sw_recording rec2;
    ENSUREF(sw_recording_parse(d2, n2, &rec2, &err) == SINEW_OK, "%s", err.msg);
    sw_replay_report rep;
    ENSURE(sw_recording_replay(fixture()->blob, &rec2, NULL, NULL, &rep) == SINEW_OK);
    fprintf(stderr, "    without the pose of step %d: %u steps differ, the first %lld\n", DROP_AT,
            rep.differing, (long long)rep.first_diff);
    ENSURE(rep.differing > 0 && rep.first_diff == DROP_AT);
    sw_recording_free(&rec2);
    sw_recording_free(&rec);
    free(d2);
    free(cut);
    free(data);
}

static int parse_says(const unsigned char *d, size_t n, const char *what) {
    sw_recording rec;
    sw_error err;
    sinew_result r = sw_recording_parse(d, n, &rec, &err);
    fprintf(stderr, "    %s\n", err.msg);
    return r != SINEW_OK && err.code == r && strstr(err.msg, what) != NULL;
}

TEST(damaged_recordings_are_refused_clearly) {
    size_t n;
    unsigned char *data = read_all(&n);
    ENSURE(data);
    unsigned char *d = malloc(n);
    memcpy(d, data, n);
    d[n / 2] ^= 0x10; /* one bit in some chunk */
    ENSURE(parse_says(d, n, "checksum mismatch"));
    ENSURE(parse_says(data, n - 5, "truncated"));
    ENSURE(parse_says(data, 7, "not a sinew recording"));
    memcpy(d, data, n);
    d[8] = 99; /* the format version */
    ENSURE(parse_says(d, n, "format version 99"));
    /* a recording cut at a chunk boundary has no END */
    size_t first = SW_REC_PREAMBLE_BYTES + SW_REC_CHUNK_BYTES + sw_rec_u32(data + 20);
    ENSURE(parse_says(data, first, "no END record"));
    /* against another blob */
    sw_recording rec;
    sw_error err;
    ENSURE(sw_recording_parse(data, n, &rec, &err) == SINEW_OK);
    bake_fixture other;
    ENSURE(bake_fixture_make(&other, "finger", 1500, 12, 0));
    sw_replay_report rep;
    ENSURE(sw_recording_replay(other.blob, &rec, NULL, NULL, &rep) != SINEW_OK);
    fprintf(stderr, "    %s\n", rep.msg);
    ENSURE(strstr(rep.msg, "another blob") != NULL);
    bake_fixture_free(&other);
    sw_recording_free(&rec);
    free(d);
    free(data);
}

TEST(a_recorder_attaches_only_to_a_fresh_instance) {
    const bake_fixture *f = fixture();
    ENSURE(f);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
    char path[600];
    snprintf(path, sizeof path, "%s.late", g_path);
    sinew_recorder_def rd = sinew_recorder_def_default();
    rd.path = path;
    rd.logger = sinew_logger_silent();
    sinew_recorder *rec;
    ENSURE(sinew_recorder_open(&rd, &rec) == SINEW_OK);
    ENSURE(sinew_instance_set_recorder(inst, rec) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSURE(sinew_recorder_close(rec) == SINEW_OK);
    rd.path = "/nonexistent-dir/x.rec";
    ENSURE(sinew_recorder_open(&rd, &rec) == SINEW_ERROR_IO);
    sinew_instance_destroy(inst);
    remove(path);
}

/* The fuzzer's version-1 seed (SINEW_WRITE_SEEDS=1 rewrites it): three steps of the
 * finger against the table and the ball, a pose and a teleport. */
TEST(a_short_recording_is_the_fuzzers_seed) {
    moving_scene m;
    ENSURE(moving_scene_make(&m));
    const bake_fixture *f = m.f;
    uint32_t nb = (uint32_t)f->ch.skel.nbones;
    char path[600];
    snprintf(path, sizeof path, "%s.short", g_path);
    sinew_instance *inst;
    ENSURE(sinew_instance_create(f->blob, NULL, &inst) == SINEW_OK);
    ENSURE(sinew_instance_set_world(inst, m.w) == SINEW_OK);
    sinew_recorder_def rd = sinew_recorder_def_default();
    rd.path = path;
    sinew_recorder *rec;
    ENSURE(sinew_recorder_open(&rd, &rec) == SINEW_OK);
    ENSURE(sinew_instance_set_recorder(inst, rec) == SINEW_OK);
    float pose[12 * 8];
    ENSURE(nb <= 8);
    for (int s = 0; s < 3; ++s) {
        bake_fixture_pose(f, 4 * s, pose);
        ENSURE(sinew_instance_set_pose(inst, pose, nb) == SINEW_OK);
        if (s == 2) ENSURE(sinew_instance_mark_teleport(inst) == SINEW_OK);
        ENSURE(sinew_instance_step(inst, 1.0f / 60) == SINEW_OK);
    }
    sinew_instance_destroy(inst); /* (detaches the recorder) */
    ENSURE(sinew_recorder_close(rec) == SINEW_OK);
    size_t n;
    unsigned char *d = (unsigned char *)sw_test_read_file(path, &n);
    ENSURE(d && n < 4096);
    sw_recording r;
    sw_error err;
    ENSUREF(sw_recording_parse(d, n, &r, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(r.steps == 3);
    sw_replay_report rep;
    ENSURE(sw_recording_replay(f->blob, &r, NULL, NULL, &rep) == SINEW_OK && rep.differing == 0);
    sw_recording_free(&r);
    /* it has no record version 2 added, so it is a version-1 recording once its preamble
       says so: it reads and replays the same, and the seed stays one of version 1 */
    const uint32_t v1 = 1;
    memcpy(d + 8, &v1, sizeof v1);
    ENSUREF(sw_recording_parse(d, n, &r, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(r.version == 1 && r.steps == 3);
    ENSURE(sw_recording_replay(f->blob, &r, NULL, NULL, &rep) == SINEW_OK && rep.differing == 0);
    sw_recording_free(&r);
    ENSURE(write_seed("short.rec", d, n));
    free(d);
    remove(path);
    sinew_world_destroy(m.w);
}

/* A closed box's 12 triangles, counter-clockwise seen from outside (vertex j takes hi on
 * axis k when bit k of j is set). */
static const uint32_t box_tris[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                      2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};

/* The lid at step s, as another character's surface would be given: a box over the finger
 * that slides along it, presses into its top by a depth that changes, and shears. */
static void lid_vertices(int s, float v[24]) {
    float x0 = 0.3f + 0.1f * (float)(s % 12), depth = 0.03f + 0.01f * (float)(s % 4);
    const float lo[3] = {x0, 0.45f - depth, -0.6f}, hi[3] = {x0 + 0.9f, 1.0f, 0.6f};
    for (int j = 0; j < 8; ++j) {
        for (int k = 0; k < 3; ++k)
            v[3 * j + k] = (j >> k) & 1 ? hi[k] : lo[k];
        v[3 * j + 2] += 0.02f * (float)(s % 5) * v[3 * j]; /* a shear of z along x */
    }
}

/* What a run of the deforming session saw. */
typedef struct deform_run {
    uint64_t hash[60];
    sw_rt_counts counts;
    uint32_t lid_steps, table_steps; /* steps with a force on the lid, on the table */
} deform_run;

/* Whether the instance's last step pushed collider id. */
static int pushed(const sinew_instance *inst, sinew_collider_id id) {
    float F[3], M[3];
    return sinew_instance_collider_force(inst, id, F, M) == SINEW_OK &&
           (F[0] != 0 || F[1] != 0 || F[2] != 0);
}

/* The finger under a lid whose vertices move every step but every seventh, over the table
 * it ignores except in steps [20, 40) (ignored before the recording starts, the world
 * attached again at 30 and at 50) and a ball that moves; recorded into `path` unless
 * NULL. 1 on success. */
static int run_deforming(const char *path, int steps, deform_run *out) {
    const bake_fixture *f = fixture();
    sinew_collider_id table, lid, ball;
    sinew_world *w = f ? table_world(0.05, 0.3f, &table) : NULL;
    if (!w) return 0;
    float v[24];
    lid_vertices(0, v);
    sinew_collider_def c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_MESH;
    c.vertices = v;
    c.vertex_count = 8;
    c.indices = box_tris;
    c.triangle_count = 12;
    int ok = sinew_world_add_collider(w, &c, &lid) == SINEW_OK;
    c = sinew_collider_def_default();
    c.shape = SINEW_SHAPE_SPHERE;
    c.radius = 0.2f;
    ball_at(0, &c.transform);
    ok &= sinew_world_add_collider(w, &c, &ball) == SINEW_OK;
    sinew_instance_def d = sinew_instance_def_default();
    d.mode = SINEW_STEP_DYNAMIC;
    sinew_instance *inst = NULL;
    ok &= sinew_instance_create(f->blob, &d, &inst) == SINEW_OK;
    ok &= ok && sinew_instance_set_world(inst, w) == SINEW_OK;
    ok &= ok && sinew_instance_ignore_collider(inst, table) == SINEW_OK;
    sinew_recorder_def rd = sinew_recorder_def_default();
    rd.path = path;
    sinew_recorder *rec = NULL;
    if (ok && path) ok &= sinew_recorder_open(&rd, &rec) == SINEW_OK;
    if (rec) ok &= sinew_instance_set_recorder(inst, rec) == SINEW_OK;
    uint32_t nb = (uint32_t)f->ch.skel.nbones;
    float *pose = malloc(sizeof(float) * 12 * nb);
    memset(out, 0, sizeof *out);
    for (int s = 0; s < steps && ok; ++s) {
        sinew_transform t;
        ball_at(s, &t);
        if (s % 2) { /* placed in doubles off the float grid: only a PLACE record holds it */
            double pos[3] = {t.position[0] + 1e-9, t.position[1], t.position[2]};
            double rot[4] = {t.rotation[0], t.rotation[1], t.rotation[2], t.rotation[3]};
            ok &= sinew_world_set_collider_transform_d(w, ball, pos, rot) == SINEW_OK;
        } else {
            ok &= sinew_world_set_collider_transform(w, ball, &t) == SINEW_OK;
        }
        lid_vertices(s, v);
        if (s % 7 != 3) ok &= sinew_world_set_mesh_vertices(w, lid, v, 8) == SINEW_OK;
        if (s == 20 || s == 40)
            ok &= sinew_instance_ignore_collider(inst, s == 20 ? 0 : table) == SINEW_OK;
        if (s == 30 || s == 50) ok &= sinew_instance_set_world(inst, w) == SINEW_OK;
        bake_fixture_pose(f, s, pose);
        ok &= sinew_instance_set_pose(inst, pose, nb) == SINEW_OK;
        sw_rt_count_begin();
        sinew_instance_step(inst, 1.0f / 60);
        sw_rt_counts k = sw_rt_count_end();
        out->counts.allocs += k.allocs;
        out->counts.frees += k.frees;
        out->counts.locks += k.locks;
        out->hash[s] = sw_instance_surface_hash(inst);
        out->lid_steps += pushed(inst, lid);
        out->table_steps += pushed(inst, table);
    }
    sinew_instance_destroy(inst); /* (detaches the recorder) */
    if (rec) ok &= sinew_recorder_close(rec) == SINEW_OK;
    free(pose);
    sinew_world_destroy(w);
    return ok;
}

#define DEFORM_STEPS 60
TEST(a_deforming_mesh_a_double_placement_and_an_ignored_collider_replay_bitwise) {
    char path[600];
    snprintf(path, sizeof path, "%s.deforming", g_path);
    static deform_run plain, recorded;
    ENSURE(run_deforming(NULL, DEFORM_STEPS, &plain));
    ENSURE(run_deforming(path, DEFORM_STEPS, &recorded));
    fprintf(stderr, "    %u steps pushed the lid, %u the table (ignored in 40 of %d)\n",
            recorded.lid_steps, recorded.table_steps, DEFORM_STEPS);
    /* both matter: the lid is touched, and the table only while it is not ignored */
    ENSURE(recorded.lid_steps > DEFORM_STEPS / 2);
    ENSURE(recorded.table_steps > 0 && recorded.table_steps <= 20);
    ENSURE(memcmp(plain.hash, recorded.hash, sizeof plain.hash) == 0);
    ensure_no_allocs_or_locks(&recorded.counts);
    size_t n;
    unsigned char *data = (unsigned char *)sw_test_read_file(path, &n);
    ENSURE(data);
    sw_recording rec;
    sw_error err;
    ENSUREF(sw_recording_parse(data, n, &rec, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(rec.version == SW_REC_VERSION && rec.steps == DEFORM_STEPS);
    sw_replay_report rep;
    ENSUREF(sw_recording_replay(fixture()->blob, &rec, NULL, NULL, &rep) == SINEW_OK, "%s",
            rep.msg);
    fprintf(stderr, "    replayed %u steps: %u differ (first %lld)\n", rep.steps, rep.differing,
            (long long)rep.first_diff);
    ENSURE(rep.steps == DEFORM_STEPS && rep.differing == 0 && rep.first_diff == -1);
    uint32_t count[SW_REC_LOD + 1];
    count_records(&rec, count);
    fprintf(stderr, "    %u MESH, %u IGNORE, %u WORLD records\n", count[SW_REC_MESH],
            count[SW_REC_IGNORE], count[SW_REC_WORLD]);
    /* a MESH for every step whose lid moved (every one but 9), except the two that attach
       the world again after the move (the WORLD record holds the vertices); an IGNORE at
       attaching, at 20, 40 and 50 */
    ENSURE(count[SW_REC_MESH] == DEFORM_STEPS - 9 - 2);
    ENSURE(count[SW_REC_IGNORE] == 4 && count[SW_REC_WORLD] == 3);
    /* a PLACE before every odd step: the ball placed in doubles off the float grid */
    ENSUREF(count[SW_REC_PLACE] == DEFORM_STEPS / 2, "%u PLACE records", count[SW_REC_PLACE]);
    size_t pos = 0;
    sw_rec_record r;
    int s = 0, same = 1;
    while (sw_recording_next(&rec, &pos, &r))
        if (r.type == SW_REC_STEP) same &= sw_rec_u64(r.p + 16) == recorded.hash[s++];
    ENSURE(same && s == DEFORM_STEPS);
    /* a version-1 reader knows neither record: a version-1 file holding them is refused */
    size_t n1;
    unsigned char *v1 = rechunk_as(1, rec.stream, rec.size, &n1);
    ENSURE(parse_says(v1, n1, "does not add up"));
    free(v1);
    sw_recording_free(&rec);
    free(data);
    remove(path);
}

/* Version 1 (before MESH and IGNORE) still reads and replays; later versions are refused
 * with the versions this library reads. */
TEST(a_version_1_recording_still_replays) {
    size_t n;
    unsigned char *data = read_all(&n); /* the session's: no meshes, no ignored collider */
    ENSURE(data);
    sw_recording rec;
    sw_error err;
    ENSURE(sw_recording_parse(data, n, &rec, &err) == SINEW_OK);
    size_t n1;
    unsigned char *v1 = rechunk_as(1, rec.stream, rec.size, &n1);
    sw_recording r1;
    ENSUREF(sw_recording_parse(v1, n1, &r1, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(r1.version == 1 && r1.steps == FRAMES);
    sw_replay_report rep;
    ENSURE(sw_recording_replay(fixture()->blob, &r1, NULL, NULL, &rep) == SINEW_OK);
    ENSURE(rep.steps == FRAMES && rep.differing == 0);
    sw_recording_free(&r1);
    /* the fuzzer's version-1 seed (a_short_recording_is_the_fuzzers_seed) */
    size_t ns;
    unsigned char *seed = (unsigned char *)sw_test_read_file(
        SINEW_SOURCE_DIR "/tests/fuzz/corpus/recording/short.rec", &ns);
    ENSURE(seed && sw_rec_u32(seed + 8) == 1);
    ENSUREF(sw_recording_parse(seed, ns, &r1, &err) == SINEW_OK, "%s", err.msg);
    ENSURE(r1.version == 1 && r1.steps == 3);
    sw_recording_free(&r1);
    free(seed);
    free(v1);
    v1 = rechunk_as(SW_REC_VERSION + 1, rec.stream, rec.size, &n1);
    ENSURE(parse_says(v1, n1, "reads versions 1 to 3"));
    free(v1);
    sw_recording_free(&rec);
    free(data);
}

/* The fuzzer's version-2 seed (SINEW_WRITE_SEEDS=1 rewrites it): three steps of the
 * deforming session, so MESH and IGNORE records. */
TEST(a_short_deforming_recording_is_a_fuzzer_seed) {
    char path[600];
    snprintf(path, sizeof path, "%s.short-deforming", g_path);
    static deform_run run;
    ENSURE(run_deforming(path, 3, &run));
    size_t n;
    unsigned char *d = (unsigned char *)sw_test_read_file(path, &n);
    ENSURE(d && n < 4096);
    sw_recording r;
    sw_error err;
    ENSUREF(sw_recording_parse(d, n, &r, &err) == SINEW_OK, "%s", err.msg);
    uint32_t count[SW_REC_LOD + 1];
    count_records(&r, count);
    ENSURE(r.steps == 3 && count[SW_REC_MESH] == 3 && count[SW_REC_IGNORE] == 1);
    sw_replay_report rep;
    ENSURE(sw_recording_replay(fixture()->blob, &r, NULL, NULL, &rep) == SINEW_OK &&
           rep.differing == 0);
    sw_recording_free(&r);
    ENSURE(write_seed("deforming.rec", d, n));
    free(d);
    remove(path);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(a_session_with_pokes_and_a_teleport_replays_bitwise),
             CASE(a_recording_without_one_pose_differs_from_there),
             CASE(a_session_changing_its_level_of_detail_replays_bitwise),
             CASE(damaged_recordings_are_refused_clearly),
             CASE(a_recorder_attaches_only_to_a_fresh_instance),
             CASE(a_short_recording_is_the_fuzzers_seed),
             CASE(a_deforming_mesh_a_double_placement_and_an_ignored_collider_replay_bitwise),
             CASE(a_version_1_recording_still_replays),
             CASE(a_short_deforming_recording_is_a_fuzzer_seed), CASE(release_fixture))
