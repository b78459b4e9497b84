/* sinew-bench --world: the condensed runtime (a patch budget) against the reference of the
 * same scene, frame by frame (cond_bench.h). */
#include "cond_bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#include "clock.h"
#include "instance.h"
#include "instance_internal.h"
#include "mesh_io.h"
#include "tool_common.h"

/* Passes of the scene timed; a frame's time is its fastest pass (the least disturbed by
 * the machine's other work: the per-frame ratios are what the figures are made of). */
#define COND_PASSES 3

/* The output surface's vertex colours: skin, turning red with the share of a vertex's
 * position that comes from patch vertices (its own, or its embedding tet's corners'). */
static void patch_colors(const sinew_instance *inst, double *C) {
    const sw_blob_view *v = inst->v;
    const double skin[3] = {0.80, 0.45, 0.36}, red[3] = {0.85, 0.05, 0.05};
    for (int32_t i = 0; i < sw_blob_output_verts(v); ++i) {
        double w = 0;
        if (v->nrender_verts > 0) {
            int32_t t = v->render_tet[v->render_weld[i]];
            for (int k = 0; k < 4; ++k)
                if (sw_cond_position(&inst->cond,
                                     sw_render_node_vertex(v, v->render_tets[4 * t + k])))
                    w += fabs(v->render_bary[4 * (int64_t)v->render_weld[i] + k]);
            w = w > 1 ? 1 : w;
        } else {
            int32_t c0 = v->surf_copy_ptr[i], d = v->surf_copies[2 * c0];
            w = sw_cond_position(
                    &inst->cond,
                    v->domain_verts[v->domains[d].vert_begin + v->surf_copies[2 * c0 + 1]])
                    ? 1
                    : 0;
        }
        for (int k = 0; k < 3; ++k)
            C[3 * i + k] = (1 - w) * skin[k] + w * red[k];
    }
}

/* The largest one-frame move of an output vertex between a and b (3 n each). */
static double max_jump(const double *a, const double *b, int32_t n) {
    double m = 0;
    for (int32_t i = 0; i < n; ++i)
        m = fmax(m, sqrt((a[3 * i] - b[3 * i]) * (a[3 * i] - b[3 * i]) +
                         (a[3 * i + 1] - b[3 * i + 1]) * (a[3 * i + 1] - b[3 * i + 1]) +
                         (a[3 * i + 2] - b[3 * i + 2]) * (a[3 * i + 2] - b[3 * i + 2])));
    return m;
}

/* The run's times against the reference's, and its patches' means over the frames that
 * had one; sorted: scratch of nf. */
static void summarise(int nf, const double *ms, const double *ref_ms, const double *patch_size,
                      double *sorted, sw_cond_bench *out) {
    out->speedup_worst = INFINITY;
    for (int f = 0; f < nf; ++f) {
        double s = ref_ms[f] / ms[f];
        if (getenv("SW_COND_DEBUG") && s < 50)
            fprintf(stderr, "frame %d: %.1f ms, reference %.1f ms: %.1fx\n", f, ms[f], ref_ms[f],
                    s);
        out->speedup_mean += s / nf;
        out->speedup_worst = fmin(out->speedup_worst, s);
        out->ms_max = fmax(out->ms_max, ms[f]);
        sorted[f] = ms[f];
    }
    int patch_frames = 0;
    for (int f = 0; f < nf; ++f) {
        if (patch_size[2 * f] == 0) continue;
        patch_frames++;
        out->patch_ms_mean += ms[f];
        out->patch_verts_mean += patch_size[2 * f];
        out->patch_tets_mean += patch_size[2 * f + 1];
    }
    if (patch_frames > 0) {
        out->patch_ms_mean /= patch_frames;
        out->patch_verts_mean /= patch_frames;
        out->patch_tets_mean /= patch_frames;
    }
    out->ms_median = sw_median(sorted, nf);
    out->p100_over_p50 = out->ms_median > 0 ? out->ms_max / out->ms_median : 0;
}

sinew_result sw_cond_bench_run(const sinew_blob *blob, sw_world_scene *ws, const double *T, int nf,
                               const double *x_full, const double *ref_ms,
                               const unsigned char *touch, const double *mass,
                               const sw_cond_bench_params *cp, double rho, sw_cond_bench *out,
                               sw_error *err) {
    memset(out, 0, sizeof *out);
    const sw_blob_view *v = sw_blob_get_view(blob);
    int32_t n = v->nverts, ns = sw_blob_output_verts(v);
    sinew_instance_def d = sinew_instance_def_default();
    d.max_patch_vertices = cp->budget > 0 ? cp->budget : (uint32_t)(n / 4 > 0 ? n / 4 : 1);
    d.patch_radius = (float)rho;
    out->budget = d.max_patch_vertices;
    out->rho = d.patch_radius > 0 ? d.patch_radius : 0.05;
    sinew_instance *inst;
    sinew_result r = sinew_instance_create(blob, &d, &inst);
    if (r != SINEW_OK)
        return sw_error_set(err, r,
                            "cannot create a condensed instance (a blob without the tet "
                            "mesh? bake it again)");
    sinew_instance_set_world(inst, ws->world);
    double *ms = malloc(sizeof(double) * nf), *sorted = malloc(sizeof(double) * nf);
    double *xs = malloc(sizeof(double) * 3 * n), *cnt = malloc(sizeof(double) * n),
           *xd = malloc(sizeof(double) * 3 * n);
    double *prev = malloc(sizeof(double) * 3 * ns), *ref_prev = malloc(sizeof(double) * 3 * ns),
           *ref_out = malloc(sizeof(double) * 3 * ns);
    float *pos = malloc(sizeof(float) * 3 * ns), *nrm = malloc(sizeof(float) * 3 * ns);
    double *col = malloc(sizeof(double) * 3 * ns);
    double *patch_size = calloc(2 * (size_t)nf, sizeof(double)); /* vertices, tets a frame */
    char dir[4096] = "";
    if (cp->out_dir && rho == (cp->nrho ? cp->rho[0] : 0)) {
        snprintf(dir, sizeof dir, "%s/condensed", cp->out_dir);
        if (!sw_tool_make_dirs(dir)) {
            r = sw_error_set(err, SINEW_ERROR_IO, "%s: cannot create the folder", dir);
            goto done;
        }
    }
    if (!ms || !sorted || !xs || !cnt || !xd || !prev || !ref_prev || !ref_out || !pos || !nrm ||
        !col || !patch_size) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the condensed run");
        goto done;
    }
    for (int f = 0; f < nf; ++f)
        ms[f] = INFINITY;
    double num = 0, den = 0;
    for (int pass = 0; pass < COND_PASSES; ++pass) {
        sinew_instance_reset(inst);
        uint32_t last_patch = 0;
        for (int f = 0; f < nf; ++f) {
            if ((r = sw_world_scene_at(ws, f, err)) != SINEW_OK) goto done;
            double t0 = sw_now_seconds();
            sw_instance_set_pose_d(inst, T + (size_t)f * 12 * v->nbones);
            sinew_result sr = sinew_instance_step(inst, 1.0f / 30);
            sinew_instance_read_surface(inst, pos, nrm, (uint32_t)ns);
            ms[f] = fmin(ms[f], 1e3 * (sw_now_seconds() - t0));
            if (pass > 0) continue; /* the figures of the state: the first pass */
            out->failed += sr != SINEW_OK;
            sinew_step_stats st = {.struct_size = sizeof st};
            sinew_instance_get_stats(inst, &st);
            double frac = st.patch_vertices / (double)n;
            patch_size[2 * f] = st.patch_vertices;
            patch_size[2 * f + 1] = st.patch_tets;
            out->patch_frac_mean += frac / nf;
            out->patch_frac_max = fmax(out->patch_frac_max, frac);
            out->truncated_frames += (st.budget_exceeded & SINEW_BUDGET_PATCH) != 0;
            out->pcg_iters_max =
                st.pcg_iterations > out->pcg_iters_max ? st.pcg_iterations : out->pcg_iters_max;
            const double *xo = sw_instance_surface(inst), *xf = x_full + (size_t)f * 3 * n;
            sw_output_from_full(v, xf, ref_out);
            /* a pop: the frame a patch appears or vanishes, its largest surface jump
               against the reference's largest jump at that frame */
            if (f > 0 && (st.patch_vertices > 0) != (last_patch > 0)) {
                double ref_jump = max_jump(ref_out, ref_prev, ns);
                double jump = max_jump(xo, prev, ns);
                if (ref_jump > 0) out->pop_max = fmax(out->pop_max, jump / ref_jump);
            }
            last_patch = st.patch_vertices;
            if (dir[0]) { /* the frame, its patch in red (sinew-render --frames DIR) */
                char path[4200];
                snprintf(path, sizeof path, "%s/frame_%04d.obj", dir, f);
                patch_colors(inst, col);
                if ((r = sw_write_obj_colors(path, ns, xo, col, sw_blob_output_ntris(v),
                                             sw_blob_output_tris(v), err)) != SINEW_OK)
                    goto done;
            }
            memcpy(prev, xo, sizeof(double) * 3 * ns);
            memcpy(ref_prev, ref_out, sizeof(double) * 3 * ns);
            if (!touch[f]) {
                if (getenv("SW_COND_DEBUG") && st.patch_vertices > 0)
                    fprintf(stderr,
                            "frame %d: patch %u (%d tets more at q), no contact in the reference; "
                            "status %u, %u Newton, %u PCG, %u evaluations, residual %.2g\n",
                            f, st.patch_vertices, inst->cond.nrest, st.status, st.newton_iterations,
                            st.pcg_iterations, st.potential_evals, st.residual);
                continue;
            }
            sw_instance_full_positions(inst, xs, cnt);
            sw_instance_dqs_positions(inst, xd);
            double fn = 0, fd = 0, fin = 0;
            for (int32_t i = 0; i < n; ++i)
                for (int k = 0; k < 3; ++k) {
                    double a = xs[3 * i + k] - xf[3 * i + k], b = xf[3 * i + k] - xd[3 * i + k];
                    num += mass[i] * a * a;
                    den += mass[i] * b * b;
                    fn += mass[i] * a * a;
                    fd += mass[i] * b * b;
                    if (sw_cond_position(&inst->cond, i)) fin += mass[i] * a * a;
                }
            if (getenv("SW_COND_DEBUG"))
                fprintf(stderr,
                        "frame %d: patch %u (%d tets more at q), err num %.3g (in patch %.3g) den "
                        "%.3g; status %u, %u Newton, %u PCG, %u evaluations, residual %.2g, %d "
                        "pose-space pairs in the patch\n",
                        f, st.patch_vertices, inst->cond.nrest, fn, fin, fd, st.status,
                        st.newton_iterations, st.pcg_iterations, st.potential_evals, st.residual,
                        inst->cond.np);
        }
    }
    out->err_world_cond = den > 0 ? sqrt(num / den) : 0;
    summarise(nf, ms, ref_ms, patch_size, sorted, out);
done:
    free(ms), free(sorted), free(xs), free(cnt), free(xd), free(prev), free(ref_prev);
    free(ref_out), free(pos), free(nrm), free(col), free(patch_size);
    sinew_instance_destroy(inst);
    return r;
}
