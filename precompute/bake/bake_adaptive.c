/* The adaptive training loop (bake_adaptive.h). */
#include "bake_adaptive.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "blob_load.h"
#include "fem_corot.h"
#include "instance.h"
#include "sinew/sinew.h"
#include "clock.h"

sw_adaptive_params sw_adaptive_params_default(void) {
    sw_adaptive_params a = {4, 64, 8, 32, 0.0};
    return a;
}

/* What the proxy reads of a blob, and its scratch. */
typedef struct scorer {
    const sw_blob_view *v;
    sinew_instance *in;
    unsigned char *free_vert; /* the vertex moves with the subspace (a basis row not 0) */
    double *x, *cnt, *f;      /* 3 nverts each (cnt: nverts) */
} scorer;

static void scorer_free(scorer *s) {
    sinew_instance_destroy(s->in);
    free(s->free_vert);
    free(s->x);
    free(s->cnt);
    free(s->f);
}

static sinew_result scorer_init(scorer *s, const sinew_blob *blob, sw_error *err) {
    memset(s, 0, sizeof *s);
    const sw_blob_view *v = s->v = sw_blob_get_view(blob);
    sinew_instance_def d = sinew_instance_def_default();
    d.max_newton_iters = SW_BAKE_EVAL_NEWTON;
    size_t n = (size_t)v->nverts;
    s->free_vert = calloc(n, 1);
    s->x = malloc(n * 3 * sizeof(double));
    s->cnt = malloc(n * sizeof(double));
    s->f = malloc(n * 3 * sizeof(double));
    sinew_result r = sinew_instance_create(blob, &d, &s->in);
    if (r != SINEW_OK || !s->free_vert || !s->x || !s->cnt || !s->f) {
        scorer_free(s);
        return sw_error_set(err, r != SINEW_OK ? r : SINEW_ERROR_OUT_OF_MEMORY,
                            "adaptive bake: no instance to score candidates with");
    }
    for (int32_t k = 0; k < v->ndomains; ++k) {
        const sw_blob_domain *D = &v->domains[k];
        const double *U = v->basis + D->basis_offset;
        for (int64_t i = 0; i < (int64_t)D->vert_count * 3 * D->rank; ++i)
            if (U[i] != 0) s->free_vert[v->domain_verts[D->vert_begin + i / (3 * D->rank)]] = 1;
    }
    return SINEW_OK;
}

/* |f|^2 over the free vertices of the full-space elastic force at x (every tet). */
static double force2(scorer *s, const double *x) {
    const sw_blob_view *v = s->v;
    memset(s->f, 0, (size_t)v->nverts * 3 * sizeof(double));
    for (int32_t t = 0; t < v->ntets; ++t) {
        double xe[12], fe[12], dm[9];
        const int32_t *tv = v->tets + 4 * (int64_t)t;
        for (int k = 0; k < 4; ++k)
            memcpy(xe + 3 * k, x + 3 * (int64_t)tv[k], 3 * sizeof(double));
        const double st = sw_blob_stiffness(v->tet_stiffness, t);
        sw_corot_eval(xe, sw_blob_tet_dminv(v, t, dm), v->tet_vol[t], st * v->mu, st * v->lambda,
                      fe, NULL, 0);
        for (int k = 0; k < 4; ++k)
            for (int i = 0; i < 3; ++i)
                s->f[3 * (int64_t)tv[k] + i] += fe[3 * k + i];
    }
    double sum = 0;
    for (int32_t i = 0; i < v->nverts; ++i)
        if (s->free_vert[i])
            for (int k = 0; k < 3; ++k)
                sum += s->f[3 * (int64_t)i + k] * s->f[3 * (int64_t)i + k];
    return sum;
}

/* The proxy at pose T: the force left at the runtime's quasistatic state over the force
 * at plain skinning (bake_adaptive.h); -1 when the step fails (never picked: the
 * reference would have to solve a pose the runtime cannot step). */
static double score(scorer *s, const double *T) {
    if (sinew_instance_reset(s->in) != SINEW_OK || sw_instance_set_pose_d(s->in, T) != SINEW_OK)
        return -1;
    for (int k = 0; k < 3; ++k) /* quasistatic steps at one pose converge to its state */
        if (sinew_instance_step(s->in, 1.0f / 30) != SINEW_OK) return -1;
    sw_instance_full_positions(s->in, s->x, s->cnt);
    double left = force2(s, s->x);
    sw_instance_dqs_positions(s->in, s->x);
    double skin = force2(s, s->x);
    return skin > 0 ? sqrt(left / skin) : 0;
}

/* Scores n candidates from `seed` and appends the `add` highest to *extra (12 nb each),
 * fewer when fewer step (*npicked). */
static sinew_result pick(const sinew_blob *blob, const sw_bake_result *res, const sw_skeleton *sk,
                         const sw_adaptive_params *a, uint64_t seed, double **extra,
                         int32_t *nextra, int32_t *npicked, sw_adaptive_round *rd, sw_error *err) {
    int32_t nb = sk->nbones, n = a->candidates;
    size_t pose = (size_t)12 * nb;
    double *T = malloc((size_t)n * pose * sizeof(double)), *sc = malloc((size_t)n * sizeof(double));
    double *local = malloc((size_t)nb * SW_RANDOM_POSE_SCRATCH * sizeof(double));
    double *grown = realloc(*extra, ((size_t)*nextra + a->add) * pose * sizeof(double));
    scorer s;
    sinew_result r = SINEW_ERROR_OUT_OF_MEMORY;
    if (grown) *extra = grown;
    if (!T || !sc || !local || !grown || (r = scorer_init(&s, blob, err)) != SINEW_OK) {
        free(T);
        free(sc);
        free(local);
        return r == SINEW_ERROR_OUT_OF_MEMORY
                   ? sw_error_set(err, r, "adaptive bake: out of memory for candidates")
                   : r;
    }
    sw_bake_random_poses(sk, res->sweep_axis, res->sweep_angle, seed, n, 1, local, T);
    rd->score_mean = rd->score_max = 0;
    for (int32_t i = 0; i < n; ++i) {
        sc[i] = score(&s, T + i * pose);
        rd->score_mean += sc[i] > 0 ? sc[i] / n : 0;
        if (sc[i] > rd->score_max) rd->score_max = sc[i];
    }
    rd->picks_score = 0;
    int32_t added = 0;
    for (; added < a->add; ++added) { /* the add highest (a failed step scores -1) */
        int32_t best = 0;
        for (int32_t i = 1; i < n; ++i)
            if (sc[i] > sc[best]) best = i;
        if (sc[best] < 0) break; /* the rest failed to step: no pose to learn from */
        rd->picks_score += sc[best];
        sc[best] = -2;
    }
    /* appended in the candidates' own order, not the scores': the picks are solved as paths
     * from rest, so a re-bake whose blob picks the same poses in another order (one that
     * changes only the cubature or the rank) names the same chains and reads them from the
     * simulate cache instead of solving them again */
    for (int32_t i = 0; i < n; ++i)
        if (sc[i] == -2)
            memcpy(*extra + (size_t)(*nextra)++ * pose, T + i * pose, pose * sizeof(double));
    rd->picks_score = added > 0 ? rd->picks_score / added : 0;
    *npicked = added;
    scorer_free(&s);
    free(T);
    free(sc);
    free(local);
    return SINEW_OK;
}

/* A fresh folder for the chains' cache when the caller gave none (removed at the end). */
static char *temp_cache(void) {
    const char *base = getenv("TMPDIR");
    char *dir = malloc(4096);
    if (!dir) return NULL;
    snprintf(dir, 4096, "%s/sinew-adaptive-XXXXXX", base && base[0] ? base : "/tmp");
    if (!mkdtemp(dir)) {
        free(dir);
        return NULL;
    }
    return dir;
}

static void remove_cache(char *dir) {
    if (!dir) return;
    DIR *d = opendir(dir);
    struct dirent *e;
    char path[8192];
    while (d && (e = readdir(d)))
        if (!strncmp(e->d_name, "simulate-", 9)) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    if (d) closedir(d);
    rmdir(dir);
    free(dir);
}

static sinew_result check(const sw_adaptive_params *a, sw_error *err) {
    if (a->rounds < 0 || a->rounds > SW_ADAPTIVE_MAX_ROUNDS || a->candidates < 1 ||
        a->candidates > 100000 || a->add < 1 || a->add > a->candidates || a->budget < 0 ||
        !(a->target >= 0) || !isfinite(a->target))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "adaptive bake: rounds %d (0..%d), candidates %d (1..100000), add %d "
                            "(1..candidates), budget %d (>= 0), target %g (>= 0)",
                            a->rounds, SW_ADAPTIVE_MAX_ROUNDS, a->candidates, a->add, a->budget,
                            a->target);
    return SINEW_OK;
}

/* The round's figures of bake `res` (blob its bytes). */
static sinew_result measure(const sinew_blob *blob, const sw_bake_result *res, int32_t added,
                            sw_adaptive_round *rd, sw_error *err) {
    sw_eval_result et, eh;
    sinew_result r = sw_bake_errors(blob, res, SINEW_SELF_CONTACT_POSE_SPACE, &et, &eh, err);
    rd->ntrain = res->ntrain;
    rd->added = added;
    rd->rank_total = res->view.rank_total;
    rd->err_train = et.correction_error;
    rd->err_heldout = eh.correction_error;
    rd->proj_train = res->train_proj_error;
    rd->proj_heldout = res->heldout_proj_error;
    rd->solved = res->simulate_solved;
    rd->picks_error = -1;
    return r;
}

/* The previous blob's error on the poses it picked: the last `n` training poses of res,
 * now solved by the reference. */
static sinew_result verify(const sinew_blob *prev, const sw_bake_result *res, int32_t n,
                           double *out, sw_error *err) {
    int32_t first = res->ntrain - n, nb = res->view.nbones, nv = res->view.nverts;
    sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                         .dt = 1.0f / 30,
                         .max_newton = SW_BAKE_EVAL_NEWTON,
                         .self_contact = SINEW_SELF_CONTACT_POSE_SPACE};
    sw_eval_result e;
    sinew_result r =
        sw_eval_correction_opts(prev, res->mass, res->train_T + (size_t)first * 12 * nb,
                                res->train_x + (size_t)first * 3 * nv, n, &o, &e, err);
    *out = e.correction_error;
    return r;
}

/* A round's bake. For a plan or a shard, its items first: when the cache held them all
 * the round is baked whole from it (the next round needs its blob), otherwise the
 * items are listed or the shard's solved, and *done says the loop stops here. */
static sinew_result farm_round(const sw_character *c, const sw_bake_params *p, sw_bake_result *res,
                               int *done, sw_error *err) {
    *done = 0;
    if (!p->plan_only && p->shard_count == 0) return sw_bake(c, p, res, err);
    sw_bake_params whole = *p;
    whole.plan_only = 1;
    whole.shard_count = 0;
    sinew_result r = sw_bake(c, &whole, res, err);
    if (r != SINEW_OK) return r;
    int32_t missing = 0;
    for (int32_t i = 0; i < res->nitems; ++i)
        missing += !res->items[i].cached;
    if (missing > 0 && p->plan_only) {
        *done = 1;
        return SINEW_OK;
    }
    sw_bake_result_free(res);
    if (missing > 0) {
        *done = 1;
        return sw_bake(c, p, res, err);
    }
    whole.plan_only = 0;
    return sw_bake(c, &whole, res, err);
}

sinew_result sw_bake_adaptive(const sw_character *c, const sw_bake_params *params,
                              const sw_adaptive_params *ap, sw_bake_result *out,
                              sw_adaptive_report *rep, sw_error *err) {
    memset(out, 0, sizeof *out);
    memset(rep, 0, sizeof *rep);
    rep->farm_round = -1;
    sw_adaptive_params a = ap ? *ap : sw_adaptive_params_default();
    sw_bake_params p = params ? *params : sw_bake_params_default();
    sinew_result r = check(&a, err);
    if (r != SINEW_OK || !c) return c ? r : sw_error_set(err, r, "no character");
    if (p.nextra_poses > 0) /* the loop's own poses go there: the caller's would be lost */
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "adaptive bake: the loop adds its own extra poses; bake with %d extra "
                            "poses of your own without it",
                            p.nextra_poses);
    char *tmp = NULL;
    if (!p.cache_dir && !(p.cache_dir = tmp = temp_cache()))
        return sw_error_set(err, SINEW_ERROR_IO, "adaptive bake: cannot make a cache folder");
    double *extra = NULL;
    int32_t nextra = 0, picked = 0;
    sinew_blob *prev = NULL;
    void *prev_mem = NULL;
    p.extra_chain = (a.add + 1) / 2; /* two paths a round: one per core */
    for (int32_t round = 0;; ++round) {
        double t0 = sw_now_seconds();
        sw_adaptive_round *rd = &rep->round[round];
        sw_bake_result res;
        sinew_blob *blob = NULL;
        void *mem = NULL;
        p.extra_poses = extra;
        p.nextra_poses = nextra;
        int done = 0; /* a farm's shard: this round's items still missing, its work done */
        if ((r = farm_round(c, &p, &res, &done, err)) != SINEW_OK) break;
        if (done) {
            rep->farm_round = round;
            *out = res;
            break;
        }
        rep->nrounds = round + 1;
        if ((r = sw_bake_result_blob(&res, &mem, &blob, err)) == SINEW_OK &&
            (r = measure(blob, &res, nextra, rd, err)) == SINEW_OK && prev && picked > 0)
            r = verify(prev, &res, picked, &rep->round[round - 1].picks_error, err);
        int last = round == a.rounds || nextra + a.add > a.budget ||
                   (a.target > 0 && rd->err_heldout <= a.target);
        picked = 0;
        if (r == SINEW_OK && !last)
            r = pick(blob, &res, &c->skel, &a, p.seed ^ (0xada9713e5eedULL + (uint64_t)round),
                     &extra, &nextra, &picked, rd, err);
        last = last || picked == 0; /* no candidate stepped: nothing to add */
        rd->seconds = sw_now_seconds() - t0;
        if (p.progress)
            fprintf(stderr,
                    "sinew-bake: adaptive round %d: %d training poses (%d added), rank %d, error "
                    "train %.4f held-out %.4f (projection %.4f / %.4f), %.1f s\n",
                    round, rd->ntrain, rd->added, rd->rank_total, rd->err_train, rd->err_heldout,
                    rd->proj_train, rd->proj_heldout, rd->seconds);
        sinew_blob_destroy(prev);
        free(prev_mem);
        prev = blob;
        prev_mem = mem;
        if (r != SINEW_OK || last) {
            if (r == SINEW_OK)
                *out = res;
            else
                sw_bake_result_free(&res);
            break;
        }
        sw_bake_result_free(&res);
    }
    sinew_blob_destroy(prev);
    free(prev_mem);
    free(extra);
    remove_cache(tmp);
    return r;
}
