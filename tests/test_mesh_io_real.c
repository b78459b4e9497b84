/* The mesh readers on the real assets of ../shared/data, with the counts their SOURCE.md
 * states (tet meshes with their surfaces and quality, surfaces, skeletons, weight and
 * animation matrices, every asset of the folder), a truncation sweep over a real file,
 * and random byte flips in small files of every format. The synthetic readers, writers
 * and round trips are in test_mesh_io.c; the shared fixtures in mesh_io_fixture.h. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>

#include "mesh_io.h"
#include "sw_test.h"

#include "mesh_io_fixture.h"

/* ---- real assets --------------------------------------------------------------- */

static const char *data_path(const char *rel) {
    static char buf[4][512];
    static int slot;
    char *p = buf[slot++ % 4];
    snprintf(p, 512, "%s/%s", SINEW_SHARED_DATA_DIR, rel);
    return p;
}

static const struct {
    const char *rel;
    int32_t nverts, ntets, nsurf;
} k_meshes[] = {
    {"elephant-cd/elephant.mesh", 494, 1502, 790},
    {"hand-libigl/hand.mesh", 7234, 29998, 9556},
    {"fish-cd/fish.mesh", 6142, 21708, 8914},
};

TEST(real_tet_meshes) {
    NEED_DATA("elephant-cd/elephant.mesh");
    for (size_t i = 0; i < sizeof k_meshes / sizeof k_meshes[0]; ++i) {
        sw_tetmesh m;
        sw_error e;
        sw_surface s;
        ENSUREF(sw_read_tetmesh(data_path(k_meshes[i].rel), &m, &e) == SINEW_OK, "%s", e.msg);
        ENSURE(m.nverts == k_meshes[i].nverts && m.ntets == k_meshes[i].ntets);
        ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
        ENSURE(sw_tetmesh_surface(&m, &s, &e) == SINEW_OK);
        ENSUREF(s.ntris == k_meshes[i].nsurf, "%s: %d boundary faces", k_meshes[i].rel, s.ntris);
        ENSUREF(surface_closed(&s, m.nverts), "%s surface not closed", k_meshes[i].rel);
        double vt = total_volume(&m), vs = enclosed_volume(&s, m.X);
        ENSUREF(fabs(vt - vs) <= 1e-9 * fabs(vt), "%s: tets %.17g, surface %.17g", k_meshes[i].rel,
                vt, vs);
        for (int32_t k = 1; k < s.nverts; ++k)
            ENSURE(s.verts[k - 1] < s.verts[k]);
        sw_quality q;
        sw_tetmesh_quality(&m, 0, &q);
        fprintf(stderr,
                "  %s: %d v, %d tets, %d surface tris / %d surface v; dihedral %.3f..%.3f deg, "
                "volume %.3g..%.3g, %d slivers (<5 deg), %d degenerate, %d inverted\n",
                k_meshes[i].rel, m.nverts, m.ntets, s.ntris, s.nverts, q.min_dihedral_deg,
                q.max_dihedral_deg, q.min_volume, q.max_volume, q.slivers, q.degenerate,
                q.inverted);
        ENSURE(q.ntets == m.ntets && q.inverted == 0 && q.min_volume > 0);
        ENSURE(q.min_dihedral_deg > 0 && q.max_dihedral_deg < 180);
        sw_surface_free(&s);
        sw_tetmesh_free(&m);
    }
}

static const struct {
    const char *rel;
    int32_t a, b; /* obj: verts, tris; tgf: joints, bones; dmat: rows, cols */
} k_assets[] = {
    {"arm-libigl/arm.obj", 8311, 16618},
    {"elephant-cd/elephant.obj", 635, 1266},
    {"elephant-libigl/elephant.obj", 6034, 12064},
    {"fish-cd/fish.obj", 3200, 6396},
    {"arm-libigl/arm.tgf", 5, 4},
    {"elephant-cd/elephant.tgf", 25, 24},
    {"elephant-libigl/elephant.tgf", 25, 24},
    {"fish-cd/fish.tgf", 2, 0},
    {"hand-libigl/hand.tgf", 21, 20},
    {"arm-libigl/arm-weights.dmat", 8311, 4},
    {"elephant-cd/elephant.dmat", 494, 24},
    {"elephant-libigl/elephant-weights.dmat", 6034, 24},
    {"elephant-libigl/elephant-anim.dmat", 288, 457},
    {"fish-cd/fish.dmat", 6142, 2},
    {"hand-libigl/hand-pose.dmat", 80, 1},
};

static int ends_with(const char *s, const char *suf) {
    size_t n = strlen(s), k = strlen(suf);
    return n >= k && strcmp(s + n - k, suf) == 0;
}

TEST(real_surfaces_skeletons_and_matrices) {
    NEED_DATA("elephant-cd/elephant.mesh");
    for (size_t i = 0; i < sizeof k_assets / sizeof k_assets[0]; ++i) {
        const char *p = data_path(k_assets[i].rel);
        sw_error e;
        int32_t a = -1, b = -1;
        if (ends_with(p, ".obj")) {
            sw_trimesh m;
            ENSUREF(sw_read_obj(p, &m, &e) == SINEW_OK, "%s", e.msg);
            a = m.nverts, b = m.ntris;
            sw_trimesh_free(&m);
        } else if (ends_with(p, ".tgf")) {
            sw_skeleton s;
            ENSUREF(sw_read_tgf(p, &s, &e) == SINEW_OK, "%s", e.msg);
            a = s.njoints, b = s.nbones;
            if (s.nbones) ENSUREF(sw_skeleton_validate(&s, &e) == SINEW_OK, "%s", e.msg);
            int roots = 0;
            for (int32_t k = 0; k < s.nbones; ++k)
                roots += s.parent[k] < 0;
            ENSURE(s.nbones == 0 || roots >= 1);
            sw_skeleton_free(&s);
        } else {
            double *d;
            ENSUREF(sw_read_dmat(p, &a, &b, &d, &e) == SINEW_OK, "%s", e.msg);
            if (strstr(p, "weights") || ends_with(p, "elephant.dmat") ||
                ends_with(p, "fish.dmat")) {
                double worst = 0;
                for (int32_t r = 0; r < a; ++r) {
                    double sum = 0;
                    for (int32_t c = 0; c < b; ++c)
                        sum += d[(size_t)r * b + c];
                    worst = fmax(worst, fabs(sum - 1));
                }
                ENSUREF(worst < 1e-3, "%s: weight rows sum off by %g", p, worst);
                sw_weights w;
                ENSUREF(sw_read_weights(p, a, b, &w, &e) == SINEW_OK, "%s", e.msg);
                sw_weights_free(&w);
            }
            free(d);
        }
        ENSUREF(a == k_assets[i].a && b == k_assets[i].b, "%s: %d x %d", k_assets[i].rel, a, b);
    }
}

/* Every .mesh/.obj/.tgf/.dmat under the data folder reads, and is one we check above. */
TEST(real_every_asset_reads) {
    NEED_DATA("elephant-cd/elephant.mesh");
    DIR *top = opendir(SINEW_SHARED_DATA_DIR);
    ENSURE(top);
    struct dirent *de;
    int seen = 0, fail = 0;
    while ((de = readdir(top)) != NULL && !fail) {
        if (de->d_name[0] == '.') continue;
        char sub[600];
        snprintf(sub, sizeof sub, "%s/%s", SINEW_SHARED_DATA_DIR, de->d_name);
        DIR *d = opendir(sub);
        if (!d) continue;
        struct dirent *fe;
        while ((fe = readdir(d)) != NULL && !fail) {
            char rel[520], full[900];
            snprintf(rel, sizeof rel, "%s/%s", de->d_name, fe->d_name);
            snprintf(full, sizeof full, "%s/%s", sub, fe->d_name);
            sw_error e;
            sinew_result rc = SINEW_OK;
            int known = 0;
            if (ends_with(rel, ".mesh")) {
                sw_tetmesh m;
                rc = sw_read_medit(full, &m, &e);
                sw_tetmesh_free(&m);
                for (size_t i = 0; i < sizeof k_meshes / sizeof k_meshes[0]; ++i)
                    known |= strcmp(rel, k_meshes[i].rel) == 0;
            } else if (ends_with(rel, ".obj") || ends_with(rel, ".tgf") ||
                       ends_with(rel, ".dmat")) {
                if (ends_with(rel, ".obj")) {
                    sw_trimesh m;
                    rc = sw_read_obj(full, &m, &e);
                    sw_trimesh_free(&m);
                } else if (ends_with(rel, ".tgf")) {
                    sw_skeleton s;
                    rc = sw_read_tgf(full, &s, &e);
                    sw_skeleton_free(&s);
                } else {
                    int32_t r, c;
                    double *x = NULL;
                    rc = sw_read_dmat(full, &r, &c, &x, &e);
                    free(x);
                }
                for (size_t i = 0; i < sizeof k_assets / sizeof k_assets[0]; ++i)
                    known |= strcmp(rel, k_assets[i].rel) == 0;
            } else {
                continue;
            }
            seen++;
            if (rc != SINEW_OK) fprintf(stderr, "  %s: %s\n", rel, e.msg);
            if (!known) fprintf(stderr, "  %s: not in the expected-count tables\n", rel);
            fail = rc != SINEW_OK || !known;
        }
        closedir(d);
    }
    closedir(top);
    ENSURE(!fail);
    ENSUREF(seen == 18, "saw %d assets", seen);
}

/* Cut elephant.mesh at ~200 offsets: every prefix fails cleanly with PARSE, except the
 * ones that keep all the data (then it must read the whole mesh). */
TEST(real_truncation_sweep) {
    NEED_DATA("elephant-cd/elephant.mesh");
    size_t n;
    char *full = sw_test_read_file(data_path("elephant-cd/elephant.mesh"), &n);
    ENSURE(full && n > 1000);
    size_t data_end = n;
    while (data_end > 0 && (full[data_end - 1] == '\n' || full[data_end - 1] == ' '))
        data_end--;
    for (int k = 0; k <= 201; ++k) {
        size_t cut =
            k <= 199 ? (size_t)((double)n * k / 199.0 + (k % 7)) : (k == 200 ? data_end : n);
        if (cut > n) cut = n;
        const char *p = write_bytes("cut.mesh", full, cut);
        sw_tetmesh m;
        sw_error e;
        sinew_result rc = sw_read_medit(p, &m, &e);
        if (cut >= data_end) {
            ENSUREF(rc == SINEW_OK && m.ntets == 1502, "cut %zu/%zu: %s", cut, n, e.msg);
        } else {
            ENSUREF(rc == SINEW_ERROR_PARSE && strstr(e.msg, "cut.mesh:"), "cut %zu/%zu: rc %d %s",
                    cut, n, rc, e.msg);
            ENSURE(all_zero(&m, sizeof m));
        }
        sw_tetmesh_free(&m);
    }
    free(full);
}

/* Random byte flips in small files of every format: any outcome but a crash, a leak or
 * a half-filled output; successes must still be valid. */
TEST(byte_flips_never_crash) {
    char dm[64];
    double A[6] = {1, 2, 3, 4, 5, 6};
    sw_error e;
    ENSURE(sw_write_dmat(tmp_path("flip_src.dmat"), 2, 3, A, 1, &e) == SINEW_OK);
    size_t dn;
    char *dsrc = sw_test_read_file(tmp_path("flip_src.dmat"), &dn);
    ENSURE(dsrc && dn < sizeof dm);
    memcpy(dm, dsrc, dn);
    free(dsrc);
    const struct {
        const char *name, *text;
        size_t len;
    } src[] = {
        {"flip.mesh", k_medit, strlen(k_medit)}, {"flip.obj", k_obj, strlen(k_obj)},
        {"flip.tgf", k_tgf, strlen(k_tgf)},      {"flip.dmat", dm, dn},
        {"flip.node", k_node1, strlen(k_node1)},
    };
    int outcomes[16] = {0};
    for (size_t f = 0; f < sizeof src / sizeof src[0]; ++f) {
        char buf[1024];
        for (int it = 0; it < 400; ++it) {
            memcpy(buf, src[f].text, src[f].len);
            int flips = 1 + (int)(rnd() % 3);
            for (int j = 0; j < flips; ++j) {
                size_t at = rnd() % src[f].len;
                buf[at] = (it & 1) ? (char)(rnd() & 0xff) : (char)(buf[at] ^ (1 << (rnd() % 8)));
            }
            const char *p = write_bytes(src[f].name, buf, src[f].len);
            sinew_result rc;
            sw_error_clear(&e);
            if (f == 0 || f == 4) {
                sw_tetmesh m;
                rc = f == 0 ? sw_read_medit(p, &m, &e)
                            : sw_read_tetgen(p, write_text("flip.ele", k_ele1), &m, &e);
                if (rc == SINEW_OK)
                    ENSURE(sw_tetmesh_validate(&m, 0, &e) == SINEW_OK);
                else
                    ENSURE(all_zero(&m, sizeof m));
                sw_tetmesh_free(&m);
            } else if (f == 1) {
                sw_trimesh m;
                rc = sw_read_obj(p, &m, &e);
                if (rc == SINEW_OK)
                    for (int32_t i = 0; i < 3 * m.ntris; ++i)
                        ENSURE(m.tris[i] >= 0 && m.tris[i] < m.nverts);
                else
                    ENSURE(all_zero(&m, sizeof m));
                sw_trimesh_free(&m);
            } else if (f == 2) {
                sw_skeleton s;
                rc = sw_read_tgf(p, &s, &e);
                if (rc == SINEW_OK && s.nbones) ENSURE(sw_skeleton_validate(&s, &e) == SINEW_OK);
                if (rc != SINEW_OK) ENSURE(all_zero(&s, sizeof s));
                sw_skeleton_free(&s);
            } else {
                int32_t r, c;
                double *d;
                rc = sw_read_dmat(p, &r, &c, &d, &e);
                if (rc == SINEW_OK)
                    for (int32_t i = 0; i < r * c; ++i)
                        ENSURE(isfinite(d[i]));
                free(d);
            }
            ENSURE(rc >= 0 && rc < 16);
            outcomes[rc]++;
            /* (a flipped .node may surface as an index error in the .ele) */
            if (rc != SINEW_OK)
                ENSUREF(strstr(e.msg, f == 4 ? "/flip." : src[f].name), "%s", e.msg);
            ENSURE(rc == SINEW_OK || rc == SINEW_ERROR_PARSE || rc == SINEW_ERROR_NOT_FINITE ||
                   rc == SINEW_ERROR_DEGENERATE);
        }
    }
    fprintf(stderr, "  byte flips: %d ok, %d parse, %d not finite, %d degenerate\n", outcomes[0],
            outcomes[SINEW_ERROR_PARSE], outcomes[SINEW_ERROR_NOT_FINITE],
            outcomes[SINEW_ERROR_DEGENERATE]);
    ENSURE(outcomes[SINEW_ERROR_PARSE] > 0 && outcomes[SINEW_OK] > 0);
}

SW_TEST_MAIN(CASE(real_tet_meshes), CASE(real_surfaces_skeletons_and_matrices),
             CASE(real_every_asset_reads), CASE(real_truncation_sweep),
             CASE(byte_flips_never_crash))
