/* libFuzzer harness for the blob parser (STYLE.md §9: a fuzz harness for every loader).
 * Built by tests/CMakeLists.txt (sinew_fuzz_harness) when clang has libFuzzer; by hand:
 *
 *   clang -std=c17 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
 *     -Iplugin_api/include -Iruntime/blob -Iruntime/math \
 *     tests/fuzz/fuzz_blob.c runtime/blob/blob_load.c runtime/blob/blob_render.c \
 *     runtime/blob/blob_cond.c -lm -o build-fuzz-blob
 *   mkdir -p /tmp/blob-corpus && ./build-fuzz-blob -max_len=65536 /tmp/blob-corpus
 *
 * Two flavours, chosen at compile time:
 *   fuzz_blob        the parser alone, on the bytes as given: random bytes almost never
 *                    pass the checksum, so this mostly fuzzes the header and table checks;
 *   fuzz_blob_fixed  (fuzz_blob_fixed.c: SW_FUZZ_FIX_CHECKSUM and SW_FUZZ_STEP, linked
 *                    with the whole runtime) overwrites the checksum field before parsing,
 *                    so mutations reach the semantic checks (hostile blobs), and steps
 *                    accepted blobs: an instance in each step mode (and one in the
 *                    pose-pairs self-contact mode when the blob has per-pair sections),
 *                    the rest pose and a bent one, a few steps each, the surface read back. A step
 * that reports success must leave a finite surface; nothing may crash. Stepping costs ~50 times the
 * parse, so one accepted input in SW_FUZZ_STEP_EVERY (chosen by a hash of its bytes, so a crash
 *                    reproduces) is stepped; every one is parsed, validated and walked.
 *
 * Every input is copied into a 64-byte aligned buffer of exactly its size, so that ASan
 * reports a read one byte past it. An accepted blob is re-validated and every index
 * chain a runtime follows is walked (the optional render mesh's and condensation tet
 * mesh's and the per-pair sections' too), the contact references and the tets' incidences with
 * explicit checks (a wrong index into one buffer mostly lands inside another section, unseen by
 * ASan). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "blob_load.h"
#ifdef SW_FUZZ_STEP
#include <math.h>

#include "sinew/sinew.h"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static double walk(const sw_blob_view *v) {
    const int64_t R = v->rank_total;
    double s = 0.0;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        s += v->bone_joints[6 * dom->bone + 5];
        for (int32_t k = 0; k < dom->vert_count; ++k) {
            int32_t x = v->domain_verts[dom->vert_begin + k];
            s += v->rest[3 * x + 2];
            for (int j = 0; j < 4; ++j) {
                int32_t b = v->skin_bone[4 * x + j];
                for (int32_t p = v->bone_parent[b]; p >= 0; p = v->bone_parent[p])
                    s += 1.0;
                s += v->skin_weight[4 * x + j];
            }
            s += v->basis[dom->basis_offset + (3 * k + 2) * dom->rank + dom->rank - 1];
        }
        for (int32_t i = 0; i < dom->rank; ++i)
            s += v->mass[(dom->q_offset + i) * R + R - 1] +
                 v->inertia_x[9 * (dom->q_offset + i) + 8];
        s += v->inertia_u[dom->inertia_offset + 9 * dom->rank * dom->rank - 1];
        for (int32_t c = dom->cub_begin; c < dom->cub_begin + dom->cub_count; ++c)
            for (int k = 0; k < 4; ++k)
                s += v->rest[3 * v->domain_verts[dom->vert_begin + v->cub_tets[4 * c + k]]];
    }
    for (int32_t t = 0; t < 3 * v->nsurf_tris; ++t) {
        int32_t sv = v->surf_tris[t];
        for (int32_t c = v->surf_copy_ptr[sv]; c < v->surf_copy_ptr[sv + 1]; ++c) {
            const sw_blob_domain *dom = &v->domains[v->surf_copies[2 * c]];
            s += v->rest[3 * v->domain_verts[dom->vert_begin + v->surf_copies[2 * c + 1]]];
        }
    }
    /* the render mesh: every triangle's vertices through their tets' nodes and copies */
    for (int64_t t = 0; t < 3 * (int64_t)v->nrender_tris; ++t) {
        int32_t rv = v->render_weld[v->render_tris[t]];
        if (v->render_weld[rv] != rv) abort();
        s += v->render_bary[4 * (int64_t)rv + 3];
        for (int k = 0; k < 4; ++k) {
            int32_t n = v->render_tets[4 * (int64_t)v->render_tet[rv] + k];
            for (int32_t c = v->render_node_ptr[n]; c < v->render_node_ptr[n + 1]; ++c) {
                const sw_blob_domain *dom = &v->domains[v->render_node_copies[2 * (int64_t)c]];
                s += v->rest[3 *
                             (int64_t)v->domain_verts[dom->vert_begin +
                                                      v->render_node_copies[2 * (int64_t)c + 1]]];
            }
        }
    }
    /* the condensation tet mesh: every tet's corners through its domain's copies, every
       vertex's tets, every cubature tet's tet */
    for (int64_t t = 0; t < v->ntets; ++t) {
        const sw_blob_domain *dom = &v->domains[v->tet_domain[t]];
        for (int k = 0; k < 4; ++k) {
            int32_t gv = v->domain_verts[dom->vert_begin + v->tet_local[4 * t + k]];
            if (gv != v->tets[4 * t + k]) abort();
            s += v->rest[3 * (int64_t)gv] * v->vert_mass[gv];
        }
        s += (v->tet_dminv ? v->tet_dminv[9 * t + 8] : 1.0) * v->tet_vol[t];
    }
    for (int32_t x = 0; x < v->nverts && v->ntets > 0; ++x)
        for (int32_t i = v->vert_tet_ptr[x]; i < v->vert_tet_ptr[x + 1]; ++i) {
            const int32_t *c = v->tets + 4 * (int64_t)v->vert_tets[i];
            if (c[0] != x && c[1] != x && c[2] != x && c[3] != x) abort();
        }
    for (int32_t c = 0; c < v->ncub && v->ntets > 0; ++c)
        if (v->tet_vol[v->cub_tet_id[c]] != v->cub_vol[c]) abort();
    /* the pose-space contacts: every training pose's range, every reference of its pairs */
    if (v->contact_ptr[0] != 0 || v->contact_ptr[v->ntrain] != v->ncontacts) abort();
    for (int32_t t = 0; t < v->ntrain; ++t) {
        s += v->train_q[(int64_t)R * t + R - 1] +
             v->train_pose[(int64_t)4 * v->nbones * (t + 1) - 1];
        if (v->contact_ptr[t + 1] < v->contact_ptr[t]) abort();
        for (int32_t c = v->contact_ptr[t]; c < v->contact_ptr[t + 1]; ++c) {
            for (int k = 0; k < 4; ++k) {
                int32_t d = v->contact_verts[8 * (int64_t)c + 2 * k];
                int32_t l = v->contact_verts[8 * (int64_t)c + 2 * k + 1];
                if (d < 0 || d >= v->ndomains || l < 0 || l >= v->domains[d].vert_count) abort();
                s += v->rest[3 * (int64_t)v->domain_verts[v->domains[d].vert_begin + l]];
            }
            if (!(v->contact_data[7 * (int64_t)c + 6] > 0)) abort();
        }
    }
    /* the per-pair contact: every group's map, every pose's features and pairs of it, each
       pair's vertex and triangle in the group's domains */
    for (int32_t g = 0; g < v->npair_groups; ++g) {
        const int32_t a = v->pair_domains[2 * g], b = v->pair_domains[2 * g + 1];
        s += v->pair_map[72 * (int64_t)g + 71] + v->bone_joints[6 * v->domains[a].bone] +
             v->bone_joints[6 * v->domains[b].bone];
        for (int32_t t = 0; t < v->ntrain; ++t) {
            const int64_t i = (int64_t)t * v->npair_groups + g;
            s += v->pair_feature[6 * ((int64_t)g * v->ntrain + t) + 5];
            for (int32_t c = v->pair_ptr[i]; c < v->pair_ptr[i + 1]; ++c) {
                if (c < v->contact_ptr[t] || c >= v->contact_ptr[t + 1]) abort();
                if (v->contact_verts[8 * (int64_t)c] != a ||
                    v->contact_verts[8 * (int64_t)c + 2] != b)
                    abort();
                if (!(v->pair_weight[c] >= 0)) abort();
                s += v->pair_weight[c];
            }
        }
    }
    return s;
}

#ifdef SW_FUZZ_STEP
/* Pose of bone b: the rest pose (bent = 0) or every bone turned about its own axis and a
 * bend axis, with a shift (rigid: an exact rotation in doubles, rounded to float). */
static void pose(float *T, int32_t nbones, double bent) {
    for (int32_t b = 0; b < nbones; ++b) {
        double a = bent * (0.3 + 0.2 * (b % 3)), c = cos(a), s = sin(a);
        const double R[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
        for (int i = 0; i < 9; ++i)
            T[12 * b + i] = (float)R[i];
        T[12 * b + 9] = (float)(0.1 * bent);
        T[12 * b + 10] = (float)(-0.05 * bent * b);
        T[12 * b + 11] = 0.0f;
    }
}

#define SW_FUZZ_STEP_EVERY 32

static uint64_t fnv1a(const uint8_t *p, size_t n) {
    uint64_t h = 1469598103934665603ULL;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ p[i]) * 1099511628211ULL;
    return h;
}

/* An accepted blob, stepped: quasistatic then dynamic, rest pose and a bent one. */
static void step_blob(const void *data, size_t size, const sw_blob_view *v) {
    sinew_blob_def bd = sinew_blob_def_default();
    bd.data = data;
    bd.data_size = size;
    bd.logger.max_level = SINEW_LOG_ERROR;
    sinew_blob *blob = NULL;
    if (sinew_blob_load(&bd, &blob) != SINEW_OK) abort(); /* sw_blob_parse accepted it */
    const int32_t nb = v->nbones, ns = sw_blob_output_verts(v);
    float *T = malloc((size_t)12 * nb * sizeof(float));
    float *pos = malloc((size_t)3 * ns * sizeof(float)),
          *nrm = malloc((size_t)3 * ns * sizeof(float));
    for (int mode = 0; mode < 3 && T && pos && nrm; ++mode) {
        if (mode == 2 && v->npair_groups == 0) break;
        sinew_instance_def d = sinew_instance_def_default();
        d.mode = mode == 1 ? SINEW_STEP_DYNAMIC : SINEW_STEP_QUASISTATIC;
        if (mode == 2) d.self_contact = SINEW_SELF_CONTACT_POSE_PAIRS; /* per-pair contact */
        d.max_newton_iters = 3;
        sinew_instance *in = NULL;
        if (sinew_instance_create(blob, &d, &in) != SINEW_OK) continue; /* e.g. too large */
        const double bends[4] = {0.0, 0.6, 1.2, 0.0};
        for (int f = 0; f < 4; ++f) {
            pose(T, nb, bends[f]);
            if (sinew_instance_set_pose(in, T, (uint32_t)nb) != SINEW_OK) abort();
            if (sinew_instance_step(in, 1.0f / 30.0f) != SINEW_OK) continue;
            if (sinew_instance_read_surface(in, pos, nrm, (uint32_t)ns) != SINEW_OK) abort();
            for (int64_t i = 0; i < 3 * (int64_t)ns; ++i)
                if (!isfinite(pos[i]) || !isfinite(nrm[i])) abort(); /* OK but not finite */
        }
        sinew_instance_destroy(in);
    }
    free(nrm);
    free(pos);
    free(T);
    sinew_blob_destroy(blob);
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    void *copy = NULL;
    if (posix_memalign(&copy, 64, size ? size : 1) != 0) return 0;
    memcpy(copy, data, size);
#ifdef SW_FUZZ_FIX_CHECKSUM
    if (size >= sizeof(sinew_blob_header)) {
        uint64_t sum = sw_blob_checksum((uint8_t *)copy + 64, size - 64);
        memcpy((uint8_t *)copy + offsetof(sinew_blob_header, checksum), &sum, sizeof sum);
    }
#endif
    sw_blob_view v;
    char msg[512];
    if (sw_blob_parse(copy, size, &v, msg, sizeof msg) == SINEW_OK) {
        if (sw_blob_validate_view(&v, msg, sizeof msg) != SINEW_OK) abort();
        volatile double sink = walk(&v);
        (void)sink;
#ifdef SW_FUZZ_STEP
        if (fnv1a(data, size) % SW_FUZZ_STEP_EVERY == 0) step_blob(copy, size, &v);
#endif
    }
    free(copy);
    return 0;
}
