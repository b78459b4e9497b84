/* The optional condensation tet mesh of a blob (sinew_blob_format.h, ids 35..44): its
 * sections' presence and counts (layer 1, sw_blob_cond_fill) and its indices, incidences
 * and values (layer 2, sw_blob_cond_validate, shared with the writer), in the manner of
 * blob_render.c. Every check is one pass over its arrays (O(size), no allocation): the
 * incidence lists are proven complete by counting, not by searching (check_incidence). */
#include <string.h>

#include "blob_check.h"

#define fail sw_blob_fail

_Static_assert(sizeof(sinew_blob_cond_meta) == 32, "COND_META is 32 bytes");

static sinew_result check_counts(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->ntets < 1 || v->ntets > SW_BLOB_MAX_COUNT)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section COND_META: ntets = %d outside [1, %d]", v->ntets,
                    SW_BLOB_MAX_COUNT);
    if (v->nvert_tets != 4 * (int64_t)v->ntets)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section COND_META: nvert_tets = %d, not 4 ntets = %lld (every tet has "
                    "four corners)",
                    v->nvert_tets, 4 * (long long)v->ntets);
    return SINEW_OK;
}

sinew_result sw_blob_cond_fill(const uint8_t *bytes, const sinew_blob_section *s,
                               const int found_in[], sw_blob_view *v, char *msg, size_t ms) {
    /* COND_TET_DMINV alone may be left out (the bake leaves it out: sw_blob_tet_dminv derives
     * it from REST). Where it is, COND_META's entry stands in for it in the group's
     * presence and count checks, and the view's field stays NULL. */
    int found[SINEW_SECTION_ID_MAX + 1];
    memcpy(found, found_in, sizeof found);
    const int dminv = found[SINEW_SECTION_COND_TET_DMINV] >= 0;
    if (!dminv) found[SINEW_SECTION_COND_TET_DMINV] = found[SINEW_SECTION_COND_META];
    sinew_blob_cond_meta m;
    int present;
    sinew_result r =
        sw_blob_group_meta(bytes, s, found, SINEW_SECTION_COND_FIRST, SINEW_SECTION_COND_LAST,
                           "the condensation tet mesh's", &m, sizeof m,
                           sizeof m.reserved / sizeof m.reserved[0], &present, msg, ms);
    if (r != SINEW_OK || !present) return r; /* none: the view's fields stay 0 / NULL */
#define FROM_META(name) v->name = m.name;
    SINEW_BLOB_COND_COUNTS(FROM_META)
#undef FROM_META
    if ((r = check_counts(v, msg, ms)) != SINEW_OK) return r;
    SW_BLOB_COUNT_LOCALS(v); /* nverts, ncub */
    SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_COND_COUNTS);
    sw_blob_count_expect expect[] = {SINEW_BLOB_COND_ARRAY_SECTIONS(SW_BLOB_EXPECT_ROW)};
    for (size_t i = 0; i < sizeof expect / sizeof expect[0]; ++i)
        if (expect[i].id == SINEW_SECTION_COND_TET_DMINV) expect[i].by_meta &= dminv;
    if ((r = sw_blob_check_counts(s, found, expect, sizeof expect / sizeof expect[0],
                                  "COND_META and META", msg, ms)) != SINEW_OK)
        return r;
    SINEW_BLOB_COND_ARRAY_SECTIONS(SW_BLOB_POINT_ROW)
    if (!dminv) v->tet_dminv = NULL;
    return SINEW_OK;
}

/* Each tet: four distinct corners, a domain, and local indices into that domain's copies
 * that are copies of those corners (so the tet's corners all live in its domain). */
static sinew_result check_tets(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r;
    if ((r = sw_blob_check_indices(SINEW_SECTION_COND_TETS, "tet", 4, v->tets, v->ntets, "vertex",
                                   v->nverts, msg, ms)) ||
        (r = sw_blob_check_indices(SINEW_SECTION_COND_TET_DOMAIN, "tet", 1, v->tet_domain, v->ntets,
                                   "domain", v->ndomains, msg, ms)))
        return r;
    for (int32_t t = 0; t < v->ntets; ++t) {
        const int32_t *c = v->tets + 4 * (int64_t)t, *l = v->tet_local + 4 * (int64_t)t;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                if (c[a] == c[b])
                    return fail(msg, ms, SINEW_ERROR_CORRUPT,
                                "blob section COND_TETS: tet %d: corners %d and %d are both "
                                "vertex %d",
                                t, a, b, c[a]);
        const int32_t d = v->tet_domain[t];
        const sw_blob_domain *dom = &v->domains[d];
        for (int k = 0; k < 4; ++k) {
            if (l[k] < 0 || l[k] >= dom->vert_count)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section COND_TET_LOCAL: tet %d corner %d: local vertex %d "
                            "outside [0, %d) of domain %d",
                            t, k, l[k], dom->vert_count, d);
            const int32_t gv = v->domain_verts[(int64_t)dom->vert_begin + l[k]];
            if (gv != c[k])
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section COND_TET_LOCAL: tet %d corner %d: local vertex %d of "
                            "domain %d is vertex %d, COND_TETS says vertex %d",
                            t, k, l[k], d, gv, c[k]);
        }
    }
    return SINEW_OK;
}

/* The vertex-to-tet lists: pointers from 0 to nvert_tets without decreasing, each list's
 * tets in range, strictly ascending, each with the vertex as a corner. That makes the
 * listed (vertex, tet) pairs distinct true incidences; as there are nvert_tets = 4 ntets of
 * them and every tet has four distinct corners (check_tets), no incidence is left out. */
static sinew_result check_incidence(const sw_blob_view *v, char *msg, size_t ms) {
    const int32_t *ptr = v->vert_tet_ptr;
    if (ptr[0] != 0 || ptr[v->nverts] != v->nvert_tets)
        return fail(msg, ms, SINEW_ERROR_CORRUPT,
                    "blob section COND_VERT_TET_PTR: runs from %d to %d, must run from 0 to "
                    "nvert_tets = %d",
                    ptr[0], ptr[v->nverts], v->nvert_tets);
    for (int32_t x = 0; x < v->nverts; ++x)
        if (ptr[x + 1] < ptr[x])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section COND_VERT_TET_PTR: entry %d (%d) below entry %d (%d)", x + 1,
                        ptr[x + 1], x, ptr[x]);
    sinew_result r = sw_blob_check_indices(SINEW_SECTION_COND_VERT_TETS, "incidence", 1,
                                           v->vert_tets, v->nvert_tets, "tet", v->ntets, msg, ms);
    if (r != SINEW_OK) return r;
    for (int32_t x = 0; x < v->nverts; ++x)
        for (int32_t i = ptr[x]; i < ptr[x + 1]; ++i) {
            const int32_t t = v->vert_tets[i];
            if (i > ptr[x] && t <= v->vert_tets[i - 1])
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section COND_VERT_TETS: vertex %d: tet %d after tet %d (must "
                            "ascend)",
                            x, t, v->vert_tets[i - 1]);
            const int32_t *c = v->tets + 4 * (int64_t)t;
            if (c[0] != x && c[1] != x && c[2] != x && c[3] != x)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section COND_VERT_TETS: vertex %d: tet %d (corners %d %d %d %d) "
                            "does not have it as a corner",
                            x, t, c[0], c[1], c[2], c[3]);
        }
    return SINEW_OK;
}

/* Lumped masses: a vertex with a tet has mass > 0; one in no tet has none (0), and no
 * full-space patch ever reaches it. */
static sinew_result check_mass(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r =
        sw_blob_check_finite(SINEW_SECTION_COND_VERT_MASS, v->vert_mass, v->nverts, msg, ms);
    if (r != SINEW_OK) return r;
    for (int32_t x = 0; x < v->nverts; ++x) {
        const int lone = v->vert_tet_ptr[x + 1] == v->vert_tet_ptr[x];
        const double m = v->vert_mass[x];
        if (lone ? m != 0.0 : !(m > 0.0))
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section COND_VERT_MASS: vertex %d (in %d tets) has mass %g, must "
                        "be %s",
                        x, v->vert_tet_ptr[x + 1] - v->vert_tet_ptr[x], m, lone ? "0" : "> 0");
    }
    return SINEW_OK;
}

/* Without COND_TET_DMINV, every tet's REST corners are invertible (sw_blob_tet_dminv
 * derives its Dm^-1 from them) and give its stored volume, bit for bit, as the bake's do:
 * the volume ties the derived rest data to what the bake computed. After check_tets. */
static sinew_result check_rest(const sw_blob_view *v, char *msg, size_t ms) {
    for (int32_t t = 0; !v->tet_dminv && t < v->ntets; ++t) {
        double X[12], dm[9], vol = 0;
        for (int k = 0; k < 4; ++k)
            memcpy(X + 3 * k, v->rest + 3 * (int64_t)v->tets[4 * (int64_t)t + k], 24);
        if (!sw_tet_rest(X, dm, &vol) || vol != v->tet_vol[t])
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section COND_TET_VOL: tet %d has volume %.17g, its REST corners "
                        "%.17g%s",
                        t, v->tet_vol[t], vol, vol > 0 ? "" : " (degenerate)");
    }
    return SINEW_OK;
}

/* Cubature tet c of domain d is tet cub_tet_id[c]: of domain d, with cub_tets' row as its
 * local corners and cub_dminv / cub_vol as its rest data (the bake computes both with the
 * same function from the same corners: equal, not close). */
static sinew_result check_cubature(const sw_blob_view *v, char *msg, size_t ms) {
    sinew_result r = sw_blob_check_indices(SINEW_SECTION_COND_CUB_TET_ID, "cubature tet", 1,
                                           v->cub_tet_id, v->ncub, "tet", v->ntets, msg, ms);
    if (r != SINEW_OK) return r;
    for (int32_t d = 0; d < v->ndomains; ++d) {
        const sw_blob_domain *dom = &v->domains[d];
        for (int32_t c = dom->cub_begin; c < dom->cub_begin + dom->cub_count; ++c) {
            const int32_t t = v->cub_tet_id[c];
            const char *what = NULL;
            if (v->tet_domain[t] != d)
                what = "domain";
            else if (memcmp(v->tet_local + 4 * (int64_t)t, v->cub_tets + 4 * (int64_t)c,
                            4 * sizeof(int32_t)) != 0)
                what = "local corners (COND_TET_LOCAL against CUB_TETS)";
            else if (v->tet_vol[t] != v->cub_vol[c])
                what = "volume (COND_TET_VOL against CUB_VOL)";
            double buf[9];
            const double *dm = what ? NULL : sw_blob_tet_dminv(v, t, buf);
            for (int k = 0; k < 9 && !what; ++k)
                if (dm[k] != v->cub_dminv[9 * (int64_t)c + k])
                    what = v->tet_dminv ? "rest Dm^-1 (COND_TET_DMINV against CUB_DMINV)"
                                        : "rest Dm^-1 (its REST corners' against CUB_DMINV)";
            if (what)
                return fail(msg, ms, SINEW_ERROR_CORRUPT,
                            "blob section COND_CUB_TET_ID: cubature tet %d (domain %d) is tet %d "
                            "(domain %d), which differs from it in its %s",
                            c, d, t, v->tet_domain[t], what);
        }
    }
    return SINEW_OK;
}

sinew_result sw_blob_cond_validate(const sw_blob_view *v, char *msg, size_t ms) {
    if (v->ntets == 0) {
        if (v->nvert_tets != 0)
            return fail(msg, ms, SINEW_ERROR_CORRUPT,
                        "blob section COND_META: no tets, but %d vertex-tet incidences",
                        v->nvert_tets);
        return SINEW_OK;
    }
    sinew_result r = check_counts(v, msg, ms);
    if (r != SINEW_OK) return r;
    sw_blob_array_ref arrays[] = {SINEW_BLOB_COND_ARRAY_SECTIONS(SW_BLOB_ARRAY_REF_ROW)};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i)
        if (arrays[i].id == SINEW_SECTION_COND_TET_DMINV) arrays[i].p = ""; /* may be NULL */
    if ((r = sw_blob_check_arrays(arrays, sizeof arrays / sizeof arrays[0], msg, ms)) ||
        (v->tet_dminv && (r = sw_blob_check_finite(SINEW_SECTION_COND_TET_DMINV, v->tet_dminv,
                                                   9 * (int64_t)v->ntets, msg, ms))) ||
        (r = sw_blob_check_finite(SINEW_SECTION_COND_TET_VOL, v->tet_vol, v->ntets, msg, ms)) ||
        (r = sw_blob_check_positive(SINEW_SECTION_COND_TET_VOL, v->tet_vol, v->ntets, 1, msg,
                                    ms)) ||
        (r = check_tets(v, msg, ms)) || (r = check_incidence(v, msg, ms)) ||
        (r = check_mass(v, msg, ms)) || (r = check_rest(v, msg, ms)))
        return r;
    return check_cubature(v, msg, ms);
}
