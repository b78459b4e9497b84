/* sinew-bench --novel (novel_bench.h). */
#include "novel_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bbox.h"
#include "blob_load.h"
#include "instance.h"
#include "mesh_io.h"
#include "selfcontact.h"
#include "subspace_eval.h"
#include "tool_common.h"

static const char *const config_key[SW_NOVEL_CONFIGS] = {"pose_space", "novel", "cond"};

/* One configuration's per-frame figures. */
typedef struct {
    sw_selfcontact *sc;
    double *x, *count;
    double pen, step_ms, novel_ms, contacts, patch_max, cluster_pairs, tests;
    int frames;
} frame_sums;

static void on_frame(void *ctx, int32_t pose, const sinew_instance *inst, const double *x_full) {
    (void)pose, (void)x_full;
    frame_sums *s = ctx;
    sw_instance_full_positions(inst, s->x, s->count);
    sw_selfcontact_detect(s->sc, s->x, NULL);
    s->pen = fmax(s->pen, sw_selfcontact_max_depth(s->sc));
    sinew_step_stats st = {.struct_size = sizeof st};
    sinew_instance_get_stats(inst, &st);
    s->step_ms += sw_step_ms(&st);
    s->novel_ms += st.ms_novel;
    s->contacts += st.novel_contacts;
    s->cluster_pairs += st.novel_cluster_pairs;
    s->tests += st.self_contact_tests;
    s->patch_max = fmax(s->patch_max, st.patch_vertices);
    s->frames++;
}

sinew_result sw_novel_bench_run(const sinew_blob *blob, const sw_character *ch, const double *T,
                                const double *full_x, int kf, sw_novel_bench *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    if (!v || v->ntets == 0 || v->nverts != ch->mesh.nverts || kf < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "--novel needs a blob with the character's tet mesh");
    sw_surface surf;
    memset(&surf, 0, sizeof surf);
    sw_selfcontact *sc = NULL;
    sinew_result r = sw_tetmesh_surface(&ch->mesh, &surf, err);
    if (r == SINEW_OK) r = sw_selfcontact_create(&ch->mesh, &surf, 1.8, 0, &sc, err);
    double *mass = calloc((size_t)v->nverts, sizeof(double));
    frame_sums s;
    memset(&s, 0, sizeof s);
    s.sc = sc;
    s.x = malloc((size_t)v->nverts * 3 * sizeof(double));
    s.count = malloc((size_t)v->nverts * sizeof(double));
    if (r == SINEW_OK && (!mass || !s.x || !s.count))
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    size_t n3 = (size_t)3 * v->nverts;
    for (int f = 0; r == SINEW_OK && f < kf; ++f) {
        sw_selfcontact_detect(sc, full_x + (size_t)f * n3, NULL);
        out->pen_self_full = fmax(out->pen_self_full, sw_selfcontact_max_depth(sc));
    }
    for (int32_t t = 0; r == SINEW_OK && t < v->ntets; ++t) /* lumped: a quarter a corner */
        for (int k = 0; k < 4; ++k)
            mass[v->tets[4 * (int64_t)t + k]] += 0.25 * v->tet_vol[t];
    double lo[3], hi[3];
    sw_bbox_empty(lo, hi);
    sw_bbox_add(lo, hi, v->nverts, v->rest);
    out->size = sw_bbox_diagonal(lo, hi);
    for (int k = 0; r == SINEW_OK && k < SW_NOVEL_CONFIGS; ++k) {
        sw_eval_options o = {.mode = SINEW_STEP_QUASISTATIC,
                             .dt = 1.0f / 30,
                             .max_newton = 0,
                             .self_contact = SINEW_SELF_CONTACT_POSE_SPACE,
                             .novel_contact = k > 0,
                             .patch_vertices = k == 2 ? (uint32_t)(v->nverts / 10 + 1) : 0,
                             .on_frame = on_frame,
                             .frame_ctx = &s};
        s.pen = s.step_ms = s.novel_ms = s.contacts = s.patch_max = s.cluster_pairs = s.tests = 0;
        s.frames = 0;
        sw_eval_result e;
        r = sw_eval_correction_frames(blob, mass, T, full_x, kf, &o, NULL, &e, err);
        if (r != SINEW_OK) break;
        int nf = s.frames > 0 ? s.frames : 1;
        out->err[k] = e.correction_error;
        out->pen_self[k] = s.pen;
        out->step_ms[k] = s.step_ms / nf;
        out->novel_ms[k] = s.novel_ms / nf;
        out->novel_contacts[k] = s.contacts / nf;
        out->patch_max[k] = s.patch_max;
        out->cluster_pairs[k] = s.cluster_pairs / nf;
        out->tests[k] = s.tests / nf;
        out->failed += e.failed;
    }
    out->frames = kf;
    free(mass);
    free(s.x);
    free(s.count);
    sw_selfcontact_destroy(sc);
    sw_surface_free(&surf);
    return r;
}

void sw_novel_bench_print(const sw_novel_bench *b, FILE *f, int json) {
    if (!json) {
        fprintf(f,
                "sinew-bench: novel contact over %d frames, deepest self-penetration "
                "reference %.4g (%.4f of the size)\n",
                b->frames, b->pen_self_full, b->pen_self_full / b->size);
        for (int k = 0; k < SW_NOVEL_CONFIGS; ++k)
            fprintf(f,
                    "             %-10s error %.4f, self-penetration %.4g, step %.3f ms, "
                    "detection %.4f ms (%.1f cluster pairs, %.0f tets tested), %.2f novel "
                    "contacts, patch up to %.0f vertices\n",
                    config_key[k], b->err[k], b->pen_self[k], b->step_ms[k], b->novel_ms[k],
                    b->cluster_pairs[k], b->tests[k], b->novel_contacts[k], b->patch_max[k]);
        return;
    }
    fprintf(f, ",\"novel_frames\":%d,\"pen_self_full\":%.6g,\"size\":%.6g", b->frames,
            b->pen_self_full, b->size);
    for (int k = 0; k < SW_NOVEL_CONFIGS; ++k)
        fprintf(f,
                ",\"pen_self_%s\":%.6g,\"err_clip_%s\":%.5f,\"step_ms_%s\":%.4f,"
                "\"novel_detect_ms_%s\":%.5f,\"novel_contacts_%s\":%.2f,\"patch_max_%s\":%.0f,"
                "\"novel_cluster_pairs_%s\":%.2f",
                config_key[k], b->pen_self[k], config_key[k], b->err[k], config_key[k],
                b->step_ms[k], config_key[k], b->novel_ms[k], config_key[k], b->novel_contacts[k],
                config_key[k], b->patch_max[k], config_key[k], b->cluster_pairs[k]);
}
