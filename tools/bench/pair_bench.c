/* sinew-bench --pair (pair_bench.h). */
#include "pair_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bbox.h"
#include "blob_load.h"
#include "character_pair.h"
#include "clock.h"
#include "instance.h"
#include "mesh_io.h"
#include "selfcontact.h"
#include "sinew/sinew_world.h"
#include "subspace_eval.h"
#include "tool_common.h"

/* The second copy's distance from the first, in thicknesses: apart at the first frame,
 * overlapping by 15% of the thickness (without contact) at the last. */
#define SEP_START 1.15
#define SEP_END 0.85
/* How far apart the two bodies rest in the two-body reference, in thicknesses (the
 * detector projects a penetrating point onto the nearest rest surface: its own body's). */
#define REST_APART 3.0

/* The scene: the side axis e, the thickness along it, the rest offset of the reference's
 * second body, and the merged detector of penetration between the two. */
typedef struct scene {
    const sw_character *ch;
    const double *T;
    int nf;
    int32_t nv, nb;
    double e[3], w, rest_off[3];
    sw_character pair;
    sw_surface surf;
    sw_selfcontact *sc;
    double *x2; /* 6 nv: both copies' positions */
} scene;

/* The axis across the bending plane: of the rest box's two shorter axes, the one along
 * which the clip moves the flesh least (each vertex carried by its strongest bone, summed
 * over the frames: a clip may come back to rest). */
static void side_axis(scene *s) {
    const sw_character *ch = s->ch;
    double lo[3], hi[3], motion[3] = {0, 0, 0};
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, ch->mesh.nverts, ch->mesh.X);
    for (int f = 0; f < s->nf; ++f) {
        const double *Tf = s->T + (size_t)f * 12 * s->nb;
        for (int32_t v = 0; v < s->nv; ++v) {
            const double *w = ch->weights.w + (size_t)v * s->nb, *X = ch->mesh.X + 3 * (size_t)v;
            int32_t b = 0;
            for (int32_t k = 1; k < s->nb; ++k)
                if (w[k] > w[b]) b = k;
            const double *M = Tf + 12 * (size_t)b;
            for (int i = 0; i < 3; ++i)
                motion[i] += fabs(M[3 * i] * X[0] + M[3 * i + 1] * X[1] + M[3 * i + 2] * X[2] +
                                  M[9 + i] - X[i]);
        }
    }
    int lng = 0;
    for (int i = 1; i < 3; ++i)
        if (hi[i] - lo[i] > hi[lng] - lo[lng]) lng = i;
    int a = (lng + 1) % 3, c = (lng + 2) % 3, ax = motion[a] <= motion[c] ? a : c;
    memset(s->e, 0, sizeof s->e);
    s->e[ax] = 1;
    s->w = hi[ax] - lo[ax];
    for (int i = 0; i < 3; ++i)
        s->rest_off[i] = REST_APART * s->w * s->e[i];
}

/* The second copy's bone transforms at frame f: the clip's, moved along e. */
static void second_pose(const scene *s, int f, double *Tb) {
    const double t = s->nf > 1 ? (double)f / (s->nf - 1) : 1.0,
                 d = s->w * (SEP_START + (SEP_END - SEP_START) * t);
    memcpy(Tb, s->T + (size_t)f * 12 * s->nb, sizeof(double) * 12 * (size_t)s->nb);
    for (int32_t b = 0; b < s->nb; ++b)
        for (int i = 0; i < 3; ++i)
            Tb[12 * (size_t)b + 9 + i] += d * s->e[i];
}

/* The deepest penetration of one copy into the other at positions x2 (both copies);
 * *touch when there is any. */
static double pair_depth(scene *s, const double *x2, int *touch) {
    sw_selfcontact_detect(s->sc, x2, NULL);
    int32_t n;
    const sw_contact *c = sw_selfcontact_list(s->sc, &n);
    double d = 0;
    *touch = 0;
    for (int32_t i = 0; i < n; ++i)
        if ((c[i].p < s->nv) != (c[i].tri[0] < s->nv)) {
            d = fmax(d, c[i].depth);
            *touch = 1;
        }
    return d;
}

static sinew_result scene_init(scene *s, const sw_character *ch, const double *T, int nf,
                               sw_error *err) {
    memset(s, 0, sizeof *s);
    s->ch = ch, s->T = T, s->nf = nf, s->nv = ch->mesh.nverts, s->nb = ch->skel.nbones;
    side_axis(s);
    sinew_result r = sw_character_pair(ch, s->rest_off, &s->pair, err);
    if (r == SINEW_OK) r = sw_tetmesh_surface(&s->pair.mesh, &s->surf, err);
    if (r == SINEW_OK) r = sw_selfcontact_create(&s->pair.mesh, &s->surf, 1.8, 0, &s->sc, err);
    if (r == SINEW_OK && !(s->x2 = malloc(sizeof(double) * 6 * (size_t)s->nv)))
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--pair: out of memory");
    return r;
}

static void scene_free(scene *s) {
    sw_selfcontact_destroy(s->sc);
    sw_surface_free(&s->surf);
    sw_character_free(&s->pair);
    free(s->x2);
}

/* The two-body reference over the clip: both copies' positions a frame into x_full. */
static sinew_result run_reference(scene *s, const sw_fullsim_params *fp, double *x_full,
                                  double *mass, sw_pair_bench *out, sw_error *err) {
    sw_fullsim *sim;
    sinew_result r = sw_fullsim_create(&s->pair, fp, &sim, err);
    if (r != SINEW_OK) return r;
    memcpy(mass, sw_fullsim_masses(sim), sizeof(double) * 2 * (size_t)s->nv);
    double *Tb = malloc(sizeof(double) * 12 * (size_t)s->nb),
           *Tp = malloc(sizeof(double) * 24 * (size_t)s->nb),
           *ms = malloc(sizeof(double) * (size_t)s->nf);
    if (!Tb || !Tp || !ms)
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--pair: out of memory");
    const size_t n6 = 6 * (size_t)s->nv;
    for (int f = 0; r == SINEW_OK && f < s->nf; ++f) {
        second_pose(s, f, Tb);
        sw_character_pair_transforms(s->nb, s->T + (size_t)f * 12 * s->nb, Tb, s->rest_off, Tp);
        sw_fullsim_stats st;
        sinew_result sr = sw_fullsim_step(sim, Tp, &st);
        out->ref_failed += sr != SINEW_OK && sr != SINEW_ERROR_NOT_CONVERGED;
        ms[f] = 1e3 * st.seconds;
        memcpy(x_full + (size_t)f * n6, sw_fullsim_positions(sim), n6 * sizeof(double));
        int touch;
        out->pen_pair_full =
            fmax(out->pen_pair_full, pair_depth(s, x_full + (size_t)f * n6, &touch));
        out->contact_frames_full += touch;
    }
    if (ms) out->full_ms = sw_median(ms, s->nf);
    free(Tb), free(Tp), free(ms);
    sw_fullsim_destroy(sim);
    return r;
}

/* Two instances with the budget of patch vertices `patch` (0: none); with a world (each
 * the other's collider) unless `lone`. */
typedef struct runtime_pair {
    sinew_instance *inst[2];
    sinew_world *world;
    sinew_collider_id id[2];
    float *pos;
    uint32_t *tris, ns, nt;
} runtime_pair;

static void pair_free(runtime_pair *p) {
    for (int k = 0; k < 2; ++k)
        sinew_instance_destroy(p->inst[k]);
    sinew_world_destroy(p->world);
    free(p->pos), free(p->tris);
    memset(p, 0, sizeof *p);
}

static sinew_result step_both(runtime_pair *p, const scene *s, int f, double *Tb) {
    second_pose(s, f, Tb);
    sinew_result r = sw_instance_set_pose_d(p->inst[0], s->T + (size_t)f * 12 * s->nb);
    if (r == SINEW_OK) r = sw_instance_set_pose_d(p->inst[1], Tb);
    for (int k = 0; k < 2 && r == SINEW_OK; ++k)
        r = sinew_instance_step(p->inst[k], 1.0f / 30);
    return r;
}

/* Each collision surface into the other's view: the colliders hold the last completed
 * step's. */
static sinew_result publish(runtime_pair *p) {
    sinew_result r = SINEW_OK;
    for (int k = 0; k < 2 && r == SINEW_OK; ++k) {
        r = sinew_instance_read_collision_surface(p->inst[k], p->pos, p->ns);
        if (r == SINEW_OK) r = sinew_world_set_mesh_vertices(p->world, p->id[k], p->pos, p->ns);
    }
    return r;
}

static sinew_result pair_make(runtime_pair *p, const sinew_blob *blob, uint32_t patch, int lone,
                              const scene *s, double *Tb, sw_error *err) {
    memset(p, 0, sizeof *p);
    sinew_instance_def d = sinew_instance_def_default();
    d.max_patch_vertices = patch;
    d.collision_surface = 1; /* (a render mesh's boundary, read before a world is attached) */
    sinew_result r = SINEW_OK;
    for (int k = 0; k < 2 && r == SINEW_OK; ++k)
        r = sinew_instance_create(blob, &d, &p->inst[k]);
    if (r != SINEW_OK || lone)
        return r ? sw_error_set(err, r, "--pair: cannot create an instance") : r;
    p->ns = sinew_blob_collision_vertex_count(blob);
    p->nt = sinew_blob_collision_triangle_count(blob);
    p->pos = malloc(sizeof(float) * 3 * p->ns);
    p->tris = malloc(sizeof(uint32_t) * 3 * p->nt);
    if (!p->pos || !p->tris)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--pair: out of memory");
    sinew_world_def wd = sinew_world_def_default();
    if ((r = sinew_blob_collision_triangles(blob, p->tris, 3 * p->nt)) ||
        (r = sinew_world_create(&wd, &p->world)) || (r = step_both(p, s, 0, Tb)))
        return sw_error_set(err, r, "--pair: cannot make the world");
    /* the colliders start as the first frame's surfaces, apart */
    for (int k = 0; k < 2 && r == SINEW_OK; ++k) {
        sinew_collider_def c = sinew_collider_def_default();
        c.shape = SINEW_SHAPE_MESH;
        if ((r = sinew_instance_read_collision_surface(p->inst[k], p->pos, p->ns))) break;
        c.vertices = p->pos;
        c.vertex_count = p->ns;
        c.indices = p->tris;
        c.triangle_count = p->nt;
        r = sinew_world_add_collider(p->world, &c, &p->id[k]);
    }
    for (int k = 0; k < 2 && r == SINEW_OK; ++k) {
        sinew_instance_reset(p->inst[k]);
        if ((r = sinew_instance_set_world(p->inst[k], p->world)) == SINEW_OK)
            r = sinew_instance_ignore_collider(p->inst[k], p->id[k]);
    }
    return r ? sw_error_set(err, r, "--pair: cannot set the colliders up") : r;
}

/* One configuration over the clip: its penetration, error, contact frames and frame
 * times (ms, nf; the steps and, with a world, the two surface copies). */
static sinew_result run_runtime(const sinew_blob *blob, scene *s, uint32_t patch, int lone,
                                const double *x_full, const double *mass, double *pen,
                                double *err_out, int *contact_frames, double *ms, double *pub_ms,
                                unsigned char *touched, sw_pair_bench *out, sw_error *err) {
    double *Tb = malloc(sizeof(double) * 12 * (size_t)s->nb), *cnt = malloc(sizeof(double) * s->nv);
    if (!Tb || !cnt) {
        free(Tb), free(cnt);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--pair: out of memory");
    }
    runtime_pair p;
    sw_eval_acc acc[2];
    memset(acc, 0, sizeof acc);
    sinew_result r = pair_make(&p, blob, patch, lone, s, Tb, err);
    for (int k = 0; k < 2 && r == SINEW_OK; ++k)
        r = sw_eval_acc_init(&acc[k], blob, mass + (size_t)k * s->nv, err);
    double balance = 0;
    int balanced = 0;
    for (int f = 0; r == SINEW_OK && f < s->nf; ++f) {
        const double t0 = sw_now_seconds();
        sinew_result sr = step_both(&p, s, f, Tb);
        const double t1 = sw_now_seconds();
        if (sr == SINEW_OK && !lone) sr = publish(&p);
        ms[f] = 1e3 * (sw_now_seconds() - t0);
        if (pub_ms) pub_ms[f] = 1e3 * (sw_now_seconds() - t1);
        out->sub_failed += sr != SINEW_OK;
        if (lone) continue;
        for (int k = 0; k < 2; ++k) {
            sw_instance_full_positions(p.inst[k], s->x2 + 3 * (size_t)k * s->nv, cnt);
            sw_eval_acc_add(&acc[k], p.inst[k],
                            x_full + (size_t)f * 6 * s->nv + 3 * (size_t)k * s->nv);
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(p.inst[k], &st);
            out->patch_frac_max = fmax(out->patch_frac_max, (double)st.patch_vertices / s->nv);
            if (touched) touched[f] |= st.world_contacts > 0;
            if (patch > 0 && !lone) { /* the touching pair's steps, phase by phase */
                const double n = 2.0 * s->nf;
                out->phase_ms[0] += st.ms_world / n, out->phase_ms[1] += st.ms_oracle / n;
                out->phase_ms[2] += st.ms_solve / n, out->phase_ms[3] += st.ms_output / n;
                out->pcg_iterations += st.pcg_iterations / n;
            }
        }
        int touch;
        *pen = fmax(*pen, pair_depth(s, s->x2, &touch));
        *contact_frames += touch;
        float fa[3], fb[3], ta[3], tb[3];
        if (sinew_instance_collider_force(p.inst[0], p.id[1], fa, ta) == SINEW_OK &&
            sinew_instance_collider_force(p.inst[1], p.id[0], fb, tb) == SINEW_OK) {
            double sum = 0, na = 0, nb = 0;
            for (int i = 0; i < 3; ++i) {
                sum += (double)(fa[i] + fb[i]) * (fa[i] + fb[i]);
                na += (double)fa[i] * fa[i];
                nb += (double)fb[i] * fb[i];
            }
            if (na > 0 && nb > 0) {
                balance += sqrt(sum) / (sqrt(na) + sqrt(nb));
                ++balanced;
            }
        }
    }
    if (!lone && patch > 0) {
        out->force_frames = balanced;
        out->force_balance = balanced > 0 ? balance / balanced : NAN;
    }
    if (r == SINEW_OK && !lone) {
        sw_eval_acc both = acc[0];
        both.num += acc[1].num, both.den += acc[1].den, both.frames += acc[1].frames;
        sw_eval_result e;
        sw_eval_acc_result(&both, &e);
        *err_out = e.correction_error;
    }
    for (int k = 0; k < 2; ++k)
        if (acc[k].xs) sw_eval_acc_free(&acc[k]);
    pair_free(&p);
    free(Tb), free(cnt);
    return r;
}

sinew_result sw_pair_bench_run(const sinew_blob *blob, const sw_character *ch, const double *T,
                               int nf, const sw_fullsim_params *fp, sw_pair_bench *out,
                               sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || v->nverts != ch->mesh.nverts || nf < 2)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "--pair needs the character's blob and 2 or more clip frames");
    scene s;
    sinew_result r = scene_init(&s, ch, T, nf, err);
    const size_t n6 = 6 * (size_t)ch->mesh.nverts;
    double *x_full = malloc(sizeof(double) * n6 * (size_t)nf),
           *mass = malloc(sizeof(double) * 2 * (size_t)ch->mesh.nverts),
           *ms[4] = {malloc(sizeof(double) * nf), malloc(sizeof(double) * nf),
                     malloc(sizeof(double) * nf), malloc(sizeof(double) * nf)};
    unsigned char *touched = calloc((size_t)nf, 1);
    if (r == SINEW_OK && (!x_full || !mass || !ms[0] || !ms[1] || !ms[2] || !ms[3] || !touched))
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "--pair: out of memory");
    out->frames = nf;
    out->thickness = s.w;
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, ch->mesh.nverts, ch->mesh.X);
    out->size = sw_bbox_diagonal(lo, hi);
    if (r == SINEW_OK) r = run_reference(&s, fp, x_full, mass, out, err);
    const uint32_t budget = (uint32_t)(ch->mesh.nverts / 10 + 1);
    if (r == SINEW_OK)
        r = run_runtime(blob, &s, 0, 0, x_full, mass, &out->pen_pair_sub, &out->err_pair_sub,
                        &out->contact_frames_sub, ms[0], NULL, NULL, out, err);
    if (r == SINEW_OK)
        r = run_runtime(blob, &s, budget, 0, x_full, mass, &out->pen_pair_cond, &out->err_pair_cond,
                        &out->contact_frames_cond, ms[1], ms[3], touched, out, err);
    double unused_pen = 0, unused_err = 0;
    int unused_frames = 0;
    if (r == SINEW_OK)
        r = run_runtime(blob, &s, budget, 1, x_full, mass, &unused_pen, &unused_err, &unused_frames,
                        ms[2], NULL, NULL, out, err);
    if (r == SINEW_OK) {
        /* the frames the pair touches (either instance in contact with the other) */
        int n = 0;
        for (int f = 0; f < nf; ++f)
            if (touched[f]) {
                for (int k = 1; k < 4; ++k)
                    ms[k][n] = ms[k][f];
                ++n;
            }
        out->touch_frames = n;
        out->pair_ms = n ? sw_median(ms[1], n) : NAN;
        out->publish_ms = n ? sw_median(ms[3], n) : NAN;
        out->lone_ms = n ? sw_median(ms[2], n) : NAN;
        out->pair_cost_vs_lone = out->lone_ms > 0 ? out->pair_ms / out->lone_ms : NAN;
    }
    free(x_full), free(mass), free(touched);
    for (int k = 0; k < 4; ++k)
        free(ms[k]);
    scene_free(&s);
    return r;
}

void sw_pair_bench_print(const sw_pair_bench *b, FILE *f, int json) {
    if (!json) {
        fprintf(
            f,
            "sinew-bench: pair over %d frames (thickness %.4g): deepest penetration "
            "reference %.4g (%d frames touching), subspace %.4g (%d), patches %.4g (%d); "
            "error subspace %.4f, patches %.4f; pair frame %.3f ms against two lone "
            "steps %.3f ms (%.2fx, medians over the %d frames the pair touches; the two surface "
            "copies %.3f ms; a step's mean world %.3f, oracle %.3f, solve %.3f, output %.3f "
            "ms, %.0f CG iterations); force balance %.3f over %d "
            "frames; patch up to %.3f of the "
            "vertices\n",
            b->frames, b->thickness, b->pen_pair_full, b->contact_frames_full, b->pen_pair_sub,
            b->contact_frames_sub, b->pen_pair_cond, b->contact_frames_cond, b->err_pair_sub,
            b->err_pair_cond, b->pair_ms, b->lone_ms, b->pair_cost_vs_lone, b->touch_frames,
            b->publish_ms, b->phase_ms[0], b->phase_ms[1], b->phase_ms[2], b->phase_ms[3],
            b->pcg_iterations, b->force_balance, b->force_frames, b->patch_frac_max);
        return;
    }
    fprintf(f,
            ",\"pair_frames\":%d,\"pair_thickness\":%.6g,\"pen_pair_full\":%.6g,"
            "\"pen_pair_sub\":%.6g,\"pen_pair_cond\":%.6g,\"pair_contact_frames_full\":%d,"
            "\"pair_contact_frames_sub\":%d,\"pair_contact_frames_cond\":%d,"
            "\"err_pair_sub\":%.5f,\"err_pair_cond\":%.5f,\"pair_full_ms\":%.3f,"
            "\"pair_ms\":%.4f,\"pair_lone_ms\":%.4f,\"pair_cost_vs_lone\":%.4f,"
            "\"pair_touch_frames\":%d,\"pair_publish_ms\":%.4f,\"pair_world_ms\":%.4f,\"pair_"
            "oracle_ms\":%.4f,"
            "\"pair_solve_ms\":%.4f,\"pair_output_ms\":%.4f,\"pair_pcg_iterations\":%.1f,"
            "\"pair_force_balance\":%.5f,\"pair_force_frames\":%d,\"patch_frac_max\":%.5f,"
            "\"pair_ref_failed\":%d",
            b->frames, b->thickness, b->pen_pair_full, b->pen_pair_sub, b->pen_pair_cond,
            b->contact_frames_full, b->contact_frames_sub, b->contact_frames_cond, b->err_pair_sub,
            b->err_pair_cond, b->full_ms, b->pair_ms, b->lone_ms, b->pair_cost_vs_lone,
            b->touch_frames, b->publish_ms, b->phase_ms[0], b->phase_ms[1], b->phase_ms[2],
            b->phase_ms[3], b->pcg_iterations, b->force_balance, b->force_frames, b->patch_frac_max,
            b->ref_failed);
}
