/* The condensation tet mesh of a blob (sinew_blob_format.h ids 35..44): the bake
 * writes the whole tet mesh, and it loads as the mesh it was baked from, every tet in its
 * domain, the incidence lists complete, the masses those of the reduced mass, the cubature
 * tets its own; a view without it writes the blob of before; the writer and the loader
 * refuse a damaged one with a message naming the section; the synthetic character with
 * one round-trips and seeds the blob fuzzer. */
#include "bake_fixture.h"
#include "blob_synth.h"
#include "fem_corot.h"
#include "sw_test.h"

/* The condensation sections: all ten, in id order. */
#define NCOND (SINEW_SECTION_COND_LAST - SINEW_SECTION_COND_FIRST + 1)
#define NPAIR (SINEW_SECTION_PAIR_LAST - SINEW_SECTION_PAIR_FIRST + 1)

static int fx_ok = -1; /* -1 not made yet, 0 failed, 1 made */
static bake_fixture fx;

/* A capsule of 2,000 tets (two domains), baked and loaded once for the tests below. */
static int capsule_fixture(void) {
    if (fx_ok < 0) fx_ok = bake_fixture_make(&fx, "capsule", 2000, 12, 0);
    return fx_ok;
}

/* ---- the baked tet mesh ----------------------------------------------------------- */

/* Tet t's rest data recomputed from the blob's rest positions equals what the runtime reads
 * (sw_blob_tet_dminv: derived, as the bake leaves COND_TET_DMINV out) and the stored volume. */
static int same_rest_data(const sw_blob_view *v, int32_t t) {
    double Xe[12], Dm[9], buf[9], vol;
    for (int k = 0; k < 4; ++k)
        memcpy(Xe + 3 * k, v->rest + 3 * (int64_t)v->tets[4 * (int64_t)t + k], 3 * sizeof(double));
    return sw_tet_rest(Xe, Dm, &vol) && memcmp(Dm, sw_blob_tet_dminv(v, t, buf), sizeof Dm) == 0 &&
           vol == v->tet_vol[t];
}

TEST(the_bake_writes_the_whole_tet_mesh) {
    ENSURE(capsule_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    const sw_tetmesh *m = &fx.ch.mesh;
    ENSURE(hdr(fx.data)->section_count ==
           SINEW_SECTION_COUNT_V1 + NCOND - 1 + (v->npair_groups > 0 ? (uint32_t)NPAIR : 0u) +
               (v->train_force ? 1u : 0u) + (v->bone_names ? 5u : 0u) +
               (v->lod_rank > 0 ? 6u : 0u) + (v->reduced_blocks ? 1u : 0u));
    ENSURE(v->ntets == m->ntets && v->nvert_tets == 4 * m->ntets && v->nverts == m->nverts);
    ENSURE(!v->tet_dminv && !entry(fx.data, SINEW_SECTION_COND_TET_DMINV)); /* left out */
    ENSURE(v->ndomains >= 2); /* tets in more than one domain, vertices with several copies */
    ENSURE(memcmp(v->tets, m->tets, 4 * sizeof(int32_t) * (size_t)m->ntets) == 0);
    const char *diff = view_diff(v, &fx.res.view);
    ENSUREF(!diff, "the loaded view differs from the bake's in %s", diff);
    ENSURE(memcmp(v->vert_mass, fx.res.mass, sizeof(double) * (size_t)v->nverts) == 0);
    for (int32_t t = 0; t < v->ntets; ++t) {
        const sw_blob_domain *dom = &v->domains[v->tet_domain[t]];
        for (int k = 0; k < 4; ++k)
            ENSUREF(v->domain_verts[dom->vert_begin + v->tet_local[4 * t + k]] ==
                        v->tets[4 * t + k],
                    "tet %d corner %d", t, k);
        ENSUREF(same_rest_data(v, t), "tet %d: Dm^-1 or volume is not sw_tet_rest's", t);
    }
    /* each vertex's list: its incident tets, ascending, and as many as the tets say */
    int32_t *count = calloc((size_t)v->nverts, sizeof(int32_t));
    for (int64_t i = 0; i < 4 * (int64_t)v->ntets; ++i)
        count[v->tets[i]]++;
    int bad = 0;
    for (int32_t x = 0; x < v->nverts; ++x) {
        bad += v->vert_tet_ptr[x + 1] - v->vert_tet_ptr[x] != count[x];
        for (int32_t i = v->vert_tet_ptr[x]; i < v->vert_tet_ptr[x + 1]; ++i) {
            const int32_t *c = v->tets + 4 * (int64_t)v->vert_tets[i];
            bad += i > v->vert_tet_ptr[x] && v->vert_tets[i] <= v->vert_tets[i - 1];
            bad += c[0] != x && c[1] != x && c[2] != x && c[3] != x;
        }
    }
    free(count);
    ENSUREF(bad == 0, "%d wrong incidences", bad);
    for (int32_t c = 0; c < v->ncub; ++c) {
        const int32_t t = v->cub_tet_id[c];
        ENSURE(memcmp(v->tet_local + 4 * t, v->cub_tets + 4 * c, 4 * sizeof(int32_t)) == 0);
        double buf[9];
        ENSURE(memcmp(sw_blob_tet_dminv(v, t, buf), v->cub_dminv + 9 * c, 9 * sizeof(double)) == 0);
        ENSURE(v->tet_vol[t] == v->cub_vol[c]);
        ENSURE(c >= v->domains[v->tet_domain[t]].cub_begin &&
               c < v->domains[v->tet_domain[t]].cub_begin + v->domains[v->tet_domain[t]].cub_count);
    }
}

/* The masses: vertex x's is density/4 of its tets' volumes, and its split over its domain
 * copies (each copy the quarter volumes of its domain's tets) is the one the reduced mass
 * U^T M U was built from. */
TEST(the_masses_are_the_reduced_masses) {
    ENSURE(capsule_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    const double rho = fx.ch.density;
    double worst = 0, total = 0, volume = 0;
    for (int32_t x = 0; x < v->nverts; ++x) {
        double m = 0;
        for (int32_t i = v->vert_tet_ptr[x]; i < v->vert_tet_ptr[x + 1]; ++i)
            m += rho * v->tet_vol[v->vert_tets[i]] / 4;
        worst = fmax(worst, fabs(m - v->vert_mass[x]) / v->vert_mass[x]);
        total += v->vert_mass[x];
    }
    for (int32_t t = 0; t < v->ntets; ++t)
        volume += v->tet_vol[t];
    ENSUREF(worst <= 1e-12, "a vertex mass is %g from its tets' (relative)", worst);
    ENSURE_NEAR(total, rho * volume, 1e-12 * total);
    double *copy_mass = calloc((size_t)v->ndomain_verts, sizeof(double));
    for (int32_t t = 0; t < v->ntets; ++t)
        for (int k = 0; k < 4; ++k)
            copy_mass[v->domains[v->tet_domain[t]].vert_begin + v->tet_local[4 * t + k]] +=
                rho * v->tet_vol[t] / 4;
    double err = 0, scale = 0;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        const double *U = v->basis + dom->basis_offset;
        for (int32_t i = 0; i < dom->rank; ++i)
            for (int32_t j = 0; j < dom->rank; ++j) {
                double mij = 0;
                for (int32_t l = 0; l < dom->vert_count; ++l)
                    for (int a = 0; a < 3; ++a)
                        mij += copy_mass[dom->vert_begin + l] * U[(3 * l + a) * dom->rank + i] *
                               U[(3 * l + a) * dom->rank + j];
                const double stored =
                    sw_blob_reduced_entry(v, SW_BLOB_MASS, dom->q_offset + i, dom->q_offset + j);
                err = fmax(err, fabs(mij - stored));
                scale = fmax(scale, fabs(stored));
            }
    }
    free(copy_mass);
    fprintf(stderr, "    %d vertices, masses to %.2g; U^T M U from the copies' masses to %.2g\n",
            v->nverts, worst, err / scale);
    ENSUREF(err <= 1e-10 * scale, "the reduced mass is %g from the tets' (scale %g)", err, scale);
}

/* Without the tet mesh (and the per-pair sections), a view writes the 26 sections it
 * always did (and its reduced matrices' blocks), the very bytes they are in the blob with
 * it; the synthetic character's seed, written before the tet mesh existed, is still what
 * the writer writes. */
TEST(a_view_without_the_tet_mesh_writes_the_blob_of_before) {
    ENSURE(capsule_fixture());
    sw_blob_view plain = fx.res.view;
    plain.ntets = plain.nvert_tets = plain.npair_groups = plain.nlod_verts = plain.lod_rank = 0;
#define CLEAR(id, NAME, elem_size, type, field, ...) plain.field = NULL;
    SINEW_BLOB_COND_ARRAY_SECTIONS(CLEAR)
    SINEW_BLOB_PAIR_ARRAY_SECTIONS(CLEAR)
    SINEW_BLOB_FORCE_SECTIONS(CLEAR)
    SINEW_BLOB_ASSET_ARRAY_SECTIONS(CLEAR)
    SINEW_BLOB_LOD_ARRAY_SECTIONS(CLEAR)
#undef CLEAR
    size_t size = 0;
    void *data = NULL;
    sw_error err;
    ENSUREF(sw_blob_write_memory(&plain, &data, &size, &err) == SINEW_OK, "%s", err.msg);
    uint8_t *b = data, *full = fx.data;
    ENSURE(hdr(b)->section_count == SINEW_SECTION_COUNT_V1 + 1 && size < fx.size);
    for (uint32_t id = 1; id <= SINEW_SECTION_COUNT_V1; ++id) {
        const sinew_blob_section *e = entry(b, id), *f = entry(full, id);
        ENSUREF(e->count == f->count &&
                    memcmp(b + e->offset, full + f->offset, (size_t)(e->count * e->elem_size)) == 0,
                "section %s", sw_blob_section_name(id));
    }
    free(data);
    fprintf(stderr, "    capsule, %d tets: %zu bytes with the tet mesh, %zu without (+%.1f%%)\n",
            fx.res.view.ntets, fx.size, size, 100.0 * ((double)fx.size / (double)size - 1));
    static fixture f;
    fixture_init(&f, 7);
    uint8_t *synth = write_fixture(&f, &size);
    ENSURE(synth && seed_is("synth_4bones.blob", synth, size));
    free(synth);
}

/* ---- the writer and the loader ----------------------------------------------------- */

TEST(the_writer_refuses_a_damaged_tet_mesh) {
    ENSURE(capsule_fixture());
    sw_error err;
    void *data = NULL;
    size_t size = 0;
    sw_blob_view v = fx.res.view;
    v.tet_vol = NULL;
    ENSURE(sw_blob_write_memory(&v, &data, &size, &err) == SINEW_ERROR_INVALID_ARGUMENT);
    ENSUREF(strstr(err.msg, "COND_TET_VOL") && strstr(err.msg, "NULL"), "%s", err.msg);
    v = fx.res.view;
    v.ntets = 0;
    ENSURE(sw_blob_write_memory(&v, &data, &size, &err) == SINEW_ERROR_CORRUPT);
    ENSUREF(strstr(err.msg, "COND_META") && strstr(err.msg, "no tets"), "%s", err.msg);
    v = fx.res.view;
    double *mass = malloc(sizeof(double) * (size_t)v.nverts);
    memcpy(mass, v.vert_mass, sizeof(double) * (size_t)v.nverts);
    mass[v.nverts / 2] = -1;
    v.vert_mass = mass;
    ENSURE(sw_blob_write_memory(&v, &data, &size, &err) == SINEW_ERROR_CORRUPT);
    ENSUREF(strstr(err.msg, "COND_VERT_MASS") && strstr(err.msg, "must be > 0"), "%s", err.msg);
    free(mass);
    ENSURE(data == NULL);
}

/* Vertex x and position i in its list where the tet before vert_tets[i] (in id order) is not
 * one of x's: putting it there keeps the list ascending but lists a non-incident tet. */
static int non_incident_slot(const sw_blob_view *v, int32_t *xi, int32_t *ii) {
    for (int32_t x = 0; x < v->nverts; ++x) {
        const int32_t i = v->vert_tet_ptr[x];
        if (i == v->vert_tet_ptr[x + 1] || v->vert_tets[i] == 0) continue;
        const int32_t *c = v->tets + 4 * (int64_t)(v->vert_tets[i] - 1);
        if (c[0] != x && c[1] != x && c[2] != x && c[3] != x) {
            *xi = x, *ii = i;
            return 1;
        }
    }
    return 0;
}

TEST(the_loader_refuses_a_damaged_tet_mesh) {
    ENSURE(capsule_fixture());
    const sw_blob_view *v = sw_blob_get_view(fx.blob);
    const size_t n = fx.size;
    uint8_t *b = NULL;
    ENSURE(posix_memalign((void **)&b, 64, n) == 0);
#define FRESH() memcpy(b, fx.data, n)
#define I32(id) ((int32_t *)section(b, SINEW_SECTION_##id))
#define F64(id) ((double *)section(b, SINEW_SECTION_##id))
#define CMETA() ((sinew_blob_cond_meta *)section(b, SINEW_SECTION_COND_META))
    const int32_t c0 = v->cub_tet_id[0], other = c0 == 0 ? 1 : 0; /* another tet */
    int32_t stranger = 0; /* a vertex that is no corner of tet 7 */
    while (stranger == v->tets[28] || stranger == v->tets[29] || stranger == v->tets[30] ||
           stranger == v->tets[31])
        ++stranger;
    int32_t x = -1, i = -1;
    ENSURE(non_incident_slot(v, &x, &i));
    int32_t y = 0; /* a vertex with two tets at least, and a vertex after one with tets */
    while (v->vert_tet_ptr[y + 1] - v->vert_tet_ptr[y] < 2)
        ++y;

    FRESH(), CMETA()->ntets += 1, CMETA()->nvert_tets += 4;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TETS", "COND_META and META needs"));
    FRESH(), CMETA()->nvert_tets -= 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_META", "nvert_tets"));
    FRESH(), CMETA()->reserved[2] = 5;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_META", "reserved word 2"));
    FRESH(), I32(COND_TETS)[4 * 3 + 2] = v->nverts;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TETS", "tet 3 corner 2"));
    FRESH(), I32(COND_TETS)[4 * 5 + 1] = v->tets[4 * 5];
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TETS", "corners 0 and 1"));
    FRESH(), I32(COND_TETS)[4 * 7 + 3] = stranger;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_LOCAL", "COND_TETS says"));
    FRESH(), I32(COND_TET_DOMAIN)[2] = v->ndomains;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_DOMAIN", "tet 2"));
    FRESH(), I32(COND_TET_DOMAIN)[c0] = (v->tet_domain[c0] + 1) % v->ndomains;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_LOCAL", "domain"));
    FRESH(), I32(COND_TET_LOCAL)[4 * 4 + 3] = v->domains[v->tet_domain[4]].vert_count;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_LOCAL", "tet 4 corner 3"));
    FRESH(), I32(COND_TET_LOCAL)[4 * 6] = v->tet_local[4 * 6] == 0 ? 1 : 0;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_LOCAL", "is vertex"));
    /* no COND_TET_DMINV: a corner moved changes a tet's derived rest data, and its volume
       says so; a cubature tet's CUB_DMINV must be its corners' too */
    FRESH(), F64(REST)[3 * v->tets[4 * 8] + 1] += 0.01;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_VOL", "its REST corners"));
    FRESH(), F64(CUB_DMINV)[4] += 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_CUB_TET_ID", "REST corners' against"));
    FRESH(), F64(COND_TET_VOL)[9] = 0;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_VOL", "element 9 is 0"));
    FRESH(), F64(COND_TET_VOL)[9] = INFINITY;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_NOT_FINITE, "COND_TET_VOL", "element 9"));
    FRESH(), F64(COND_TET_VOL)[c0] *= 2;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_TET_VOL", "its REST corners"));
    FRESH(), I32(COND_VERT_TET_PTR)[0] = 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_TET_PTR", "runs from 1"));
    FRESH(), I32(COND_VERT_TET_PTR)[y + 1] = v->vert_tet_ptr[y] - 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_TET_PTR", "below entry"));
    FRESH(), I32(COND_VERT_TETS)[11] = v->ntets;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_TETS", "incidence 11"));
    FRESH(), I32(COND_VERT_TETS)[v->vert_tet_ptr[y]] = v->vert_tets[v->vert_tet_ptr[y] + 1];
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_TETS", "must ascend"));
    FRESH(), I32(COND_VERT_TETS)[i] -= 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_TETS", "does not have it"));
    FRESH(), F64(COND_VERT_MASS)[y] = 0;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_MASS", "must be > 0"));
    FRESH(), F64(COND_VERT_MASS)[y] = NAN;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_NOT_FINITE, "COND_VERT_MASS", "is nan"));
    FRESH(), I32(COND_CUB_TET_ID)[1] = v->ntets;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_CUB_TET_ID", "cubature tet 1"));
    FRESH(), I32(COND_CUB_TET_ID)[0] = other;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_CUB_TET_ID", "differs"));
    FRESH(), entry(b, SINEW_SECTION_COND_VERT_MASS)->count -= 1;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_MASS", "needs nverts"));
    FRESH(), entry(b, SINEW_SECTION_COND_VERT_MASS)->id = 200;
    ENSURE(parse_refuses(b, n, SINEW_ERROR_CORRUPT, "COND_VERT_MASS", "all or none"));
    FRESH(); /* all nine unknown: the blob an older bake wrote, read as one without them */
    for (uint32_t id = SINEW_SECTION_COND_FIRST; id <= SINEW_SECTION_COND_LAST; ++id)
        if (id != SINEW_SECTION_COND_TET_DMINV) entry(b, id)->id = 100 + id;
    fix_checksum(b, n);
    sw_blob_view plain;
    char msg[512];
    ENSUREF(sw_blob_parse(b, n, &plain, msg, sizeof msg) == SINEW_OK, "%s", msg);
    ENSURE(plain.ntets == 0 && plain.nvert_tets == 0 && !plain.tets && !plain.cub_tet_id);
#undef FRESH
#undef I32
#undef F64
#undef CMETA
    free(b);
}

/* ---- the synthetic character ------------------------------------------------------- */

/* The synthetic character of blob_synth.h (seed 3: its cubature tets leave a vertex in no
 * tet, of mass 0) with a render mesh and the tet mesh (all 44 sections): written, parsed
 * back the same, and the fuzz seed
 * tests/fuzz/corpus/blob_fixed/synth_cond.blob is these bytes (SINEW_WRITE_SEEDS=1 rewrites
 * it), so the blob fuzzers start from the tet mesh. */
TEST(the_synthetic_tet_mesh_round_trips_and_seeds_the_fuzzer) {
    static fixture f;
    static render_fixture r;
    static cond_fixture c;
    fixture_init(&f, 3);
    fixture_add_render(&f, &r);
    fixture_add_cond(&f, &c);
    size_t size = 0;
    sw_blob_view v;
    uint8_t *b = write_parsed(&f, &size, &v);
    ENSURE(b);
    ENSURE(hdr(b)->section_count == SINEW_SECTION_COND_LAST);
    const char *diff = view_diff(&v, &f.v);
    ENSUREF(!diff, "the parsed view differs in %s", diff);
    int32_t lone = -1; /* a vertex in no tet, of mass 0 */
    for (int32_t x = 0; x < NV; ++x)
        if (v.vert_tet_ptr[x + 1] == v.vert_tet_ptr[x] && v.vert_mass[x] == 0.0) lone = x;
    ENSURE(v.ntets == NCT && lone >= 0);
    /* ... and its mass is 0, not a made-up one */
    uint8_t *forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_COND_VERT_MASS))[lone] = 1.0;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "COND_VERT_MASS", "must be 0"));
    free(forged);
    /* a stored COND_TET_DMINV (this one's are not its corners') is read and checked */
    ENSURE(v.tet_dminv);
    forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_COND_TET_DMINV))[9 * 2 + 4] = NAN;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_NOT_FINITE, "COND_TET_DMINV", "element 22"));
    free(forged);
    ENSURE(seed_is("synth_cond.blob", b, size));
    free(b);
}

/* The same character with per-pair sections, equilibrium forces, the asset description,
 * painted material, the pose-space level and its reduced matrices by blocks as well (all
 * 65, format version 4):
 * written, parsed back the same, and the fuzz seed
 * tests/fuzz/corpus/blob_fixed/synth_pairs.blob is these bytes (SINEW_WRITE_SEEDS=1
 * rewrites it), so the blob fuzzers start from every optional section. */
TEST(the_synthetic_pair_sections_round_trip_and_seed_the_fuzzer) {
    static fixture f;
    static render_fixture r;
    static cond_fixture c;
    static pair_fixture p;
    static asset_fixture a;
    static paint_fixture pf;
    fixture_init(&f, 3);
    fixture_add_render(&f, &r);
    fixture_add_cond(&f, &c);
    fixture_add_pairs(&f, &p);
    fixture_add_asset(&f, &a);
    fixture_add_paint(&f, &c, &pf);
    static lod_fixture lf;
    fixture_add_lod(&f, &lf);
    static blocks_fixture bf;
    fixture_add_blocks(&f, &bf);
    static double force[4096];
    const int64_t nforce = (int64_t)f.v.ntrain * f.v.rank_total;
    ENSURE(nforce <= 4096);
    for (int64_t i = 0; i < nforce; ++i)
        force[i] = 0.01 * (double)(i % 7) - 0.03;
    f.v.train_force = force;
    size_t size = 0;
    sw_blob_view v;
    uint8_t *b = write_parsed(&f, &size, &v);
    ENSURE(b);
    ENSURE(hdr(b)->section_count == SINEW_SECTION_ID_MAX);
    const char *diff = view_diff(&v, &f.v);
    ENSUREF(!diff, "the parsed view differs in %s", diff);
    /* a contact listed in a group of other domains */
    uint8_t *forged = copy_exact(b, size);
    int32_t *dom = section(forged, SINEW_SECTION_PAIR_DOMAINS);
    dom[1] = (dom[1] + 1) % ND;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "PAIR_", NULL));
    free(forged);
    forged = copy_exact(b, size);
    ((int32_t *)section(forged, SINEW_SECTION_PAIR_PTR))[0] = 1;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "PAIR_PTR", "CONTACT_PTR"));
    free(forged);
    forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_PAIR_FEATURE))[3] = NAN;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_NOT_FINITE, "PAIR_FEATURE", NULL));
    free(forged);
    forged = copy_exact(b, size);
    ((sinew_blob_pair_meta *)section(forged, SINEW_SECTION_PAIR_META))->npair_groups = 10;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "PAIR_", NULL));
    free(forged);
    /* an equilibrium force that is not finite, or of another count than META's */
    forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_TRAIN_FORCE))[nforce - 1] = INFINITY;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_NOT_FINITE, "TRAIN_FORCE", NULL));
    free(forged);
    forged = copy_exact(b, size);
    entry(forged, SINEW_SECTION_TRAIN_FORCE)->count -= 1;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "TRAIN_FORCE", "ntrain rank_total"));
    free(forged);
    /* painted material: a cubature tet's multiplier not its tet's, one out of range, a count
       off, and the sections in a blob whose header says version 2 */
    ENSURE(hdr(b)->version == 4);
    forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_CUB_STIFFNESS))[1] *= 2;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "CUB_STIFFNESS", "TET_STIFFNESS"));
    free(forged);
    forged = copy_exact(b, size);
    ((double *)section(forged, SINEW_SECTION_TET_STIFFNESS))[0] = 0;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "TET_STIFFNESS", "outside"));
    free(forged);
    forged = copy_exact(b, size);
    entry(forged, SINEW_SECTION_TET_STIFFNESS)->count -= 1;
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "TET_STIFFNESS", "ntets"));
    free(forged);
    forged = copy_exact(b, size);
    hdr(forged)->version = 2; /* outside the checksum */
    ENSURE(parse_refuses(forged, size, SINEW_ERROR_CORRUPT, "STIFFNESS", "version 3"));
    free(forged);
    ENSURE(seed_is("synth_pairs.blob", b, size));
    free(b);
}

TEST(release_fixture) {
    if (fx_ok > 0) bake_fixture_free(&fx);
}

SW_TEST_MAIN(CASE(the_bake_writes_the_whole_tet_mesh), CASE(the_masses_are_the_reduced_masses),
             CASE(a_view_without_the_tet_mesh_writes_the_blob_of_before),
             CASE(the_writer_refuses_a_damaged_tet_mesh),
             CASE(the_synthetic_pair_sections_round_trip_and_seed_the_fuzzer),
             CASE(the_loader_refuses_a_damaged_tet_mesh),
             CASE(the_synthetic_tet_mesh_round_trips_and_seeds_the_fuzzer), CASE(release_fixture))
