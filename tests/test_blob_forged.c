/* Forged blobs, field by field: every count and index of the training and
 * contact sections (TRAIN_Q, TRAIN_POSE, CONTACT_PTR, CONTACT_VERTS, CONTACT_DATA and
 * META's ntrain and ncontacts), and the fields of the other sections that
 * test_blob_hostile.c's forged cases leave out (META's other counts and material, the
 * domain records' ranges and sums, the remaining negative indices). Each case changes one
 * field of a valid synthetic blob (blob_synth.h), or one count with the sections it sizes
 * moved to the end of the file and grown, fixes the checksum up, and checks that
 * sw_blob_parse and sinew_blob_load both refuse it with the expected code, that the
 * message (and the load's log line) names the section and the element, and that the view
 * is untouched. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sw_test.h"

#include "blob_synth.h"

static fixture g_fix; /* views point into it: never copied */

/* ---- forging ----------------------------------------------------------------------- */

static sinew_blob_meta *meta(uint8_t *b) {
    return section(b, SINEW_SECTION_META);
}

static sw_blob_domain *dom(uint8_t *b, int d) {
    return (sw_blob_domain *)section(b, SINEW_SECTION_DOMAINS) + d;
}

/* Section `id` moved to the end of the blob with `count` elements (its old ones first,
 * zeros after): *b is reallocated, the table, the header's file_size and *size follow. */
static void grow(uint8_t **b, size_t *size, uint32_t id, uint64_t count) {
    const sinew_blob_section *e = entry(*b, id);
    const size_t old = (size_t)(e->count * e->elem_size), add = (size_t)(count * e->elem_size);
    const size_t big = *size + (add + 63) / 64 * 64;
    uint8_t *n = NULL;
    if (posix_memalign((void **)&n, 64, big) != 0) abort();
    memset(n, 0, big);
    memcpy(n, *b, *size);
    memcpy(n + *size, *b + e->offset, old < add ? old : add);
    entry(n, id)->offset = *size;
    entry(n, id)->count = count;
    hdr(n)->file_size = big;
    free(*b);
    *b = n;
    *size = big;
}

static void set_count(uint8_t *b, uint32_t id, uint64_t count) {
    entry(b, id)->count = count;
}

static void f_ntrain_more(uint8_t **b, size_t *size) { /* a third pose, no contact ptr fix */
    meta(*b)->ntrain = NTR + 1;
    grow(b, size, SINEW_SECTION_TRAIN_Q, (NTR + 1) * RT);
    grow(b, size, SINEW_SECTION_TRAIN_POSE, (NTR + 1) * 4 * NB);
    grow(b, size, SINEW_SECTION_CONTACT_PTR, NTR + 2);
}
static void f_ncontacts_more(uint8_t **b, size_t *size) {
    meta(*b)->ncontacts = 3;
    grow(b, size, SINEW_SECTION_CONTACT_VERTS, 8 * 3);
    grow(b, size, SINEW_SECTION_CONTACT_DATA, 7 * 3);
}
static void f_ncontacts_less(uint8_t **b, size_t *size) {
    (void)size;
    meta(*b)->ncontacts = 1;
    set_count(*b, SINEW_SECTION_CONTACT_VERTS, 8);
    set_count(*b, SINEW_SECTION_CONTACT_DATA, 7);
}
static void f_rank_more(uint8_t **b, size_t *size) { /* ranks sum to RT, META says RT + 1 */
    const uint64_t r = RT + 1;
    meta(*b)->rank_total = (int32_t)r;
    grow(b, size, SINEW_SECTION_SPRING_HESSIAN, r * r);
    grow(b, size, SINEW_SECTION_MASS, r * r);
    grow(b, size, SINEW_SECTION_INERTIA_S, 3 * r);
    grow(b, size, SINEW_SECTION_INERTIA_X, 9 * r);
    grow(b, size, SINEW_SECTION_TRAIN_Q, NTR * r);
}
static void f_rank_less(uint8_t **b, size_t *size) { /* the last domain's rank runs past */
    (void)size;
    const uint64_t r = RT - 1;
    meta(*b)->rank_total = (int32_t)r;
    set_count(*b, SINEW_SECTION_SPRING_HESSIAN, r * r);
    set_count(*b, SINEW_SECTION_MASS, r * r);
    set_count(*b, SINEW_SECTION_INERTIA_S, 3 * r);
    set_count(*b, SINEW_SECTION_INERTIA_X, 9 * r);
    set_count(*b, SINEW_SECTION_TRAIN_Q, NTR * r);
}
static void f_ncub_more(uint8_t **b, size_t *size) {
    meta(*b)->ncub = NCUB + 1;
    grow(b, size, SINEW_SECTION_CUB_TETS, 4 * (NCUB + 1));
    grow(b, size, SINEW_SECTION_CUB_WEIGHT, NCUB + 1);
    grow(b, size, SINEW_SECTION_CUB_DMINV, 9 * (NCUB + 1));
    grow(b, size, SINEW_SECTION_CUB_VOL, NCUB + 1);
}
static void f_ndv_more(uint8_t **b, size_t *size) {
    meta(*b)->ndomain_verts = NDV + 1;
    grow(b, size, SINEW_SECTION_DOMAIN_VERTS, NDV + 1);
}
static void f_basis_more(uint8_t **b, size_t *size) {
    grow(b, size, SINEW_SECTION_BASIS, NBASIS + 1);
}
static void f_inertia_u_less(uint8_t **b, size_t *size) {
    (void)size;
    set_count(*b, SINEW_SECTION_INERTIA_U, NIU - 1);
}
static void f_copies_none(uint8_t **b, size_t *size) {
    (void)size;
    set_count(*b, SINEW_SECTION_SURF_COPIES, 0);
}

/* What a case changes: one int32 or double element of a section, one int32 or double
 * field of META (by offset), or anything (fn). */
enum { K_I32, K_F64, K_META_I32, K_META_F64, K_FN };

typedef struct forge_case {
    const char *name;
    int kind;
    uint32_t id;
    int64_t index; /* element, or META byte offset */
    int64_t ival;
    double dval;
    void (*fn)(uint8_t **b, size_t *size);
    sinew_result code;
    const char *needle, *needle2;
} forge_case;

#define CORRUPT SINEW_ERROR_CORRUPT
#define NOT_FINITE SINEW_ERROR_NOT_FINITE
#define I32(name, ID, i, val, code, n1, n2)                                                        \
    { name, K_I32, SINEW_SECTION_##ID, i, val, 0, NULL, code, n1, n2 }
#define F64(name, ID, i, val, code, n1, n2)                                                        \
    { name, K_F64, SINEW_SECTION_##ID, i, 0, val, NULL, code, n1, n2 }
#define META_I(field, val, n2)                                                                     \
    {                                                                                              \
        "META " #field " = " #val, K_META_I32, 0, offsetof(sinew_blob_meta, field), val, 0, NULL,  \
            CORRUPT, "META", n2                                                                    \
    }
#define META_F(field, val, code, n2)                                                               \
    {                                                                                              \
        "META " #field " = " #val, K_META_F64, 0, offsetof(sinew_blob_meta, field), 0, val, NULL,  \
            code, "META", n2                                                                       \
    }
#define FN(name, f, code, n1, n2)                                                                  \
    { name, K_FN, 0, 0, 0, 0, f, code, n1, n2 }

static const forge_case k_cases[] = {
    /* META: the training and contact counts */
    META_I(ntrain, 0, "ntrain = 0"),
    META_I(ntrain, -1, "ntrain = -1"),
    META_I(ntrain, 1000001, "ntrain = 1000001"),
    META_I(ntrain, INT32_MIN, "ntrain"),
    {"META ntrain + 1 (sections unchanged)", K_META_I32, 0, offsetof(sinew_blob_meta, ntrain),
     NTR + 1, 0, NULL, CORRUPT, "TRAIN_Q", "ntrain rank_total"},
    META_I(ncontacts, -1, "ncontacts = -1"),
    META_I(ncontacts, 50000001, "ncontacts = 50000001"),
    {"META ncontacts + 1 (sections unchanged)", K_META_I32, 0, offsetof(sinew_blob_meta, ncontacts),
     3, 0, NULL, CORRUPT, "CONTACT_VERTS", "8 ncontacts"},
    FN("ntrain + 1 with grown sections", f_ntrain_more, CORRUPT, "CONTACT_PTR", "ncontacts = 2"),
    FN("ncontacts + 1 with grown sections", f_ncontacts_more, CORRUPT, "CONTACT_PTR",
       "ncontacts = 3"),
    FN("ncontacts - 1 with shrunk sections", f_ncontacts_less, CORRUPT, "CONTACT_PTR",
       "from 0 to 2"),
    /* META: the other counts and the material */
    META_I(nbones, 0, "nbones = 0"),
    META_I(nbones, 65537, "nbones = 65537"),
    META_I(rank_total, 0, "rank_total = 0"),
    META_I(rank_total, 32769, "rank_total = 32769"),
    META_I(ndomain_verts, 0, "ndomain_verts = 0"),
    META_I(nsurf_verts, -1, "nsurf_verts = -1"),
    META_I(nsurf_tris, 0, "nsurf_tris = 0"),
    META_I(nsurf_tris, 50000001, "nsurf_tris = 50000001"),
    META_F(lambda, NAN, NOT_FINITE, "lambda"),
    META_F(lambda, -1e5, CORRUPT, "unstable"),
    META_F(rayleigh_alpha, -0.5, CORRUPT, "rayleigh_alpha"),
    META_F(rayleigh_beta, INFINITY, NOT_FINITE, "rayleigh_beta"),
    META_F(contact_k, -1e-3, CORRUPT, "contact_k"),
    META_F(contact_k, NAN, NOT_FINITE, "contact_k"),
    /* TRAIN_Q, TRAIN_POSE: finiteness */
    F64("train_q NaN", TRAIN_Q, NTR *RT - 1, NAN, NOT_FINITE, "TRAIN_Q", "element 17"),
    F64("train_q +inf", TRAIN_Q, 0, INFINITY, NOT_FINITE, "TRAIN_Q", "element 0"),
    F64("train_pose -inf", TRAIN_POSE, 4 * NB * NTR - 1, -INFINITY, NOT_FINITE, "TRAIN_POSE",
        "element 31"),
    F64("train_pose NaN", TRAIN_POSE, 4 * NB + 2, NAN, NOT_FINITE, "TRAIN_POSE", "element 18"),
    /* CONTACT_PTR (fixture: 0, 2, 2) */
    I32("contact ptr first 1", CONTACT_PTR, 0, 1, CORRUPT, "CONTACT_PTR", "from 1 to 2"),
    I32("contact ptr first -1", CONTACT_PTR, 0, -1, CORRUPT, "CONTACT_PTR", "from -1 to 2"),
    I32("contact ptr last 1", CONTACT_PTR, NTR, 1, CORRUPT, "CONTACT_PTR", "from 0 to 1"),
    I32("contact ptr last past ncontacts", CONTACT_PTR, NTR, 3, CORRUPT, "CONTACT_PTR",
        "from 0 to 3"),
    I32("contact ptr middle past the end", CONTACT_PTR, 1, 3, CORRUPT, "CONTACT_PTR",
        "entry 2 (2) below entry 1 (3)"),
    I32("contact ptr middle negative", CONTACT_PTR, 1, -1, CORRUPT, "CONTACT_PTR",
        "entry 1 (-1) below entry 0 (0)"),
    I32("contact ptr middle INT32_MAX", CONTACT_PTR, 1, INT32_MAX, CORRUPT, "CONTACT_PTR",
        "below entry 1 (2147483647)"),
    /* CONTACT_DATA: b0 b1 b2, normal, area */
    F64("contact barycentric NaN", CONTACT_DATA, 7, NAN, NOT_FINITE, "CONTACT_DATA", "element 7"),
    F64("contact normal inf", CONTACT_DATA, 4, INFINITY, NOT_FINITE, "CONTACT_DATA", "element 4"),
    F64("contact area NaN", CONTACT_DATA, 13, NAN, NOT_FINITE, "CONTACT_DATA", "element 13"),
    F64("contact area 0", CONTACT_DATA, 6, 0.0, CORRUPT, "CONTACT_DATA", "contact 0 has area"),
    F64("contact area < 0", CONTACT_DATA, 13, -0.5, CORRUPT, "CONTACT_DATA", "contact 1 has area"),
    /* DOMAINS: the fields and sums test_blob_hostile.c does not forge */
    FN("domains rank sum < rank_total", f_rank_more, CORRUPT, "DOMAINS", "ranks sum to 9"),
    FN("rank runs past rank_total", f_rank_less, CORRUPT, "DOMAINS", "rank 4 runs past"),
    FN("domains cubature sum < ncub", f_ncub_more, CORRUPT, "DOMAINS", "own 8 cubature tets"),
    FN("domains copies sum < ndomain_verts", f_ndv_more, CORRUPT, "DOMAINS", "hold 17 vertex"),
    FN("basis longer than the domains", f_basis_more, CORRUPT, "BASIS", "holds 151"),
    FN("inertia_u shorter than the domains", f_inertia_u_less, CORRUPT, "INERTIA_U", "holds 260"),
    FN("no surface copies", f_copies_none, CORRUPT, "SURF_COPIES", "0 copies outside"),
    /* other sections' negative and first indices */
    I32("surf copy ptr first", SURF_COPY_PTR, 0, 1, CORRUPT, "SURF_COPY_PTR", "element 0 is 1"),
    I32("surf tri negative", SURF_TRIS, 4, -1, CORRUPT, "SURF_TRIS", "triangle 1 corner 1"),
    I32("surf copy domain -1", SURF_COPIES, 4, -1, CORRUPT, "SURF_COPIES", "copy 2: domain -1"),
    I32("surf copy local -1", SURF_COPIES, 5, -1, CORRUPT, "SURF_COPIES", "copy 2: local"),
    I32("domain vert negative", DOMAIN_VERTS, 3, -1, CORRUPT, "DOMAIN_VERTS", "vertex -1"),
    I32("skin bone negative", SKIN_BONE, 4 * 3 + 2, -1, CORRUPT, "SKIN_BONE",
        "vertex 3 influence 2"),
};

/* Domain record fields (int32 at a byte offset of domain d). */
static const struct {
    const char *name;
    int d;
    size_t off;
    int32_t val;
    const char *needle2;
} k_domain_cases[] = {
    {"vert_begin", 1, offsetof(sw_blob_domain, vert_begin), 5, "domain 1: vert_begin 5"},
    {"vert_count 0", 0, offsetof(sw_blob_domain, vert_count), 0, "domain 0: vert_count 0"},
    {"cub_begin", 2, offsetof(sw_blob_domain, cub_begin), 4, "domain 2: cub_begin 4"},
    {"rank too big", 0, offsetof(sw_blob_domain, rank), SW_BLOB_MAX_RANK + 1, "rank 1025"},
    {"bone -1", 1, offsetof(sw_blob_domain, bone), -1, "domain 1: bone -1"},
    {"cub_count past ncub", 2, offsetof(sw_blob_domain, cub_count), 4, "cub_count 4"},
};

/* ---- checking ---------------------------------------------------------------------- */

typedef struct log_line {
    int calls;
    uint32_t id;
    char text[1024];
} log_line;

static void keep_log(sinew_log_level level, uint32_t id, const char *message, void *user) {
    log_line *l = user;
    (void)level;
    l->calls++;
    l->id = id;
    snprintf(l->text, sizeof l->text, "%s", message);
}

/* 1 when both the parser and the public loader refuse `b` with `code`, naming both
 * needles (in the message and the log line), without touching the view; prints why not. */
static int refused(const char *name, const uint8_t *b, size_t size, sinew_result code,
                   const char *n1, const char *n2) {
    uint8_t *copy = copy_exact(b, size);
    char msg[512];
    sw_blob_view v;
    memset(&v, 0xAB, sizeof v);
    sinew_result r = sw_blob_parse(copy, size, &v, msg, sizeof msg);
    int untouched = 1;
    for (size_t k = 0; k < sizeof v; ++k)
        untouched &= ((const unsigned char *)&v)[k] == 0xAB;
    log_line log = {0, 0, ""};
    sinew_blob_def def = sinew_blob_def_default();
    def.data = copy;
    def.data_size = size;
    def.logger.log = keep_log;
    def.logger.user = &log;
    sinew_blob *h = NULL;
    sinew_result lr = sinew_blob_load(&def, &h);
    if (h) sinew_blob_destroy(h);
    free(copy);
    int ok = r == code && lr == code && untouched && contains(msg, n1) && contains(msg, n2) &&
             log.calls == 1 && log.id == SINEW_MSG_BLOB_INVALID && contains(log.text, n1) &&
             contains(log.text, n2);
    if (!ok)
        fprintf(stderr,
                "  %s: parse %d, load %d (expected %d), view %s\n    message '%s'\n    log "
                "(%d lines, id %u) '%s'\n    should name '%s' and '%s'\n",
                name, (int)r, (int)lr, (int)code, untouched ? "untouched" : "WRITTEN", msg,
                log.calls, (unsigned)log.id, log.text, n1, n2);
    return ok;
}

/* The fixture blob (fresh 64-aligned copy each call). */
static uint8_t *fresh(size_t *size) {
    fixture_init(&g_fix, 15);
    return write_fixture(&g_fix, size);
}

/* ---- tests ------------------------------------------------------------------------- */

TEST(the_fixture_loads_and_walks) {
    size_t size = 0;
    uint8_t *b = fresh(&size);
    ENSURE(b != NULL);
    sw_blob_view v;
    char msg[512];
    ENSUREF(sw_blob_parse(b, size, &v, msg, sizeof msg) == SINEW_OK, "%s", msg);
    double acc = 0.0;
    ENSURE(walk_view(&v, b, size, &acc));
    ENSURE(v.ntrain == NTR && v.ncontacts == 2 && v.contact_ptr[1] == 2);
    /* grow() keeps a blob valid: only the counts it is asked for change */
    grow(&b, &size, SINEW_SECTION_CONTACT_DATA, 7 * 2);
    fix_checksum(b, size);
    ENSUREF(sw_blob_parse(b, size, &v, msg, sizeof msg) == SINEW_OK, "%s", msg);
    ENSURE(walk_view(&v, b, size, &acc));
    free(b);
}

TEST(forged_fields_are_refused_and_named) {
    int failed = 0;
    for (size_t i = 0; i < sizeof k_cases / sizeof k_cases[0]; ++i) {
        const forge_case *c = &k_cases[i];
        size_t size = 0;
        uint8_t *b = fresh(&size);
        ENSURE(b != NULL);
        switch (c->kind) {
        case K_I32:
            ((int32_t *)section(b, c->id))[c->index] = (int32_t)c->ival;
            break;
        case K_F64:
            ((double *)section(b, c->id))[c->index] = c->dval;
            break;
        case K_META_I32: {
            int32_t x = (int32_t)c->ival;
            memcpy((uint8_t *)meta(b) + c->index, &x, sizeof x);
            break;
        }
        case K_META_F64:
            memcpy((uint8_t *)meta(b) + c->index, &c->dval, sizeof c->dval);
            break;
        default:
            c->fn(&b, &size);
            break;
        }
        fix_checksum(b, size);
        failed += !refused(c->name, b, size, c->code, c->needle, c->needle2);
        free(b);
    }
    ENSUREF(failed == 0, "%d of %zu cases", failed, sizeof k_cases / sizeof k_cases[0]);
}

TEST(forged_domain_records_are_refused_and_named) {
    int failed = 0;
    for (size_t i = 0; i < sizeof k_domain_cases / sizeof k_domain_cases[0]; ++i) {
        size_t size = 0;
        uint8_t *b = fresh(&size);
        ENSURE(b != NULL);
        memcpy((uint8_t *)dom(b, k_domain_cases[i].d) + k_domain_cases[i].off,
               &k_domain_cases[i].val, sizeof(int32_t));
        fix_checksum(b, size);
        failed += !refused(k_domain_cases[i].name, b, size, CORRUPT, "DOMAINS",
                           k_domain_cases[i].needle2);
        free(b);
    }
    ENSURE(failed == 0);
}

/* Every (domain, local vertex) reference of a contact: p, t0, t1, t2 of contact 1, each
 * with a domain below 0 and at ndomains, a local vertex below 0 and at its domain's
 * vertex count. */
TEST(every_contact_vertex_reference_is_checked) {
    int failed = 0, n = 0;
    for (int k = 0; k < 4; ++k)
        for (int form = 0; form < 4; ++form, ++n) {
            size_t size = 0;
            uint8_t *b = fresh(&size);
            ENSURE(b != NULL);
            int32_t *cv = (int32_t *)section(b, SINEW_SECTION_CONTACT_VERTS) + 8 + 2 * k;
            const char *what[4] = {"domain -1", "domain = ndomains", "local -1",
                                   "local = vert_count"};
            switch (form) {
            case 0:
                cv[0] = -1;
                break;
            case 1:
                cv[0] = ND;
                break;
            case 2:
                cv[1] = -1;
                break;
            default:
                cv[1] = dom(b, cv[0])->vert_count;
                break;
            }
            fix_checksum(b, size);
            char name[96], needle[48], needle2[48];
            snprintf(name, sizeof name, "contact 1 vertex %d: %s", k, what[form]);
            snprintf(needle, sizeof needle, "contact 1 vertex %d:", k);
            snprintf(needle2, sizeof needle2, "(domain %d, local %d)", cv[0], cv[1]);
            failed += !refused(name, b, size, CORRUPT, needle, needle2);
            free(b);
        }
    ENSUREF(failed == 0, "%d of %d cases", failed, n);
}

/* The table entries of the training and contact sections: a count one short, a count
 * that overflows the file, an offset past the end, a misaligned offset, a wrong element
 * size, an overlap, a second entry with the same id, a missing entry. */
TEST(training_and_contact_table_entries_are_checked) {
    static const uint32_t ids[] = {SINEW_SECTION_TRAIN_Q, SINEW_SECTION_TRAIN_POSE,
                                   SINEW_SECTION_CONTACT_PTR, SINEW_SECTION_CONTACT_VERTS,
                                   SINEW_SECTION_CONTACT_DATA};
    const char *forms[] = {"count - 1", "count 2^61", "offset past the end", "offset + 8",
                           "elem_size", "overlap",    "duplicate id",        "missing"};
    const char *needles[] = {"META needs", "past the end", "outside", "multiple of 64",
                             "elem_size",  "overlaps",     "twice",   "missing"};
    int failed = 0, n = 0;
    for (size_t s = 0; s < sizeof ids / sizeof ids[0]; ++s)
        for (int form = 0; form < 8; ++form, ++n) {
            size_t size = 0;
            uint8_t *b = fresh(&size);
            ENSURE(b != NULL);
            sinew_blob_section *e = entry(b, ids[s]);
            const char *name = sw_blob_section_name(ids[s]);
            switch (form) {
            case 0:
                e->count -= 1;
                break;
            case 1:
                e->count = 1ull << 61;
                break;
            case 2:
                e->offset = size + 64;
                break;
            case 3:
                e->offset += 8;
                break;
            case 4:
                e->elem_size = e->elem_size == 8 ? 4 : 8;
                break;
            case 5:
                e->offset = entry(b, SINEW_SECTION_REST)->offset;
                break;
            case 6: /* this entry claims the REST id: REST appears twice */
                e->id = SINEW_SECTION_REST;
                name = "REST";
                break;
            default:
                e->id = 4000 + ids[s];
                break;
            }
            fix_checksum(b, size);
            char what[96];
            snprintf(what, sizeof what, "%s %s", sw_blob_section_name(ids[s]), forms[form]);
            failed += !refused(what, b, size, CORRUPT, name, needles[form]);
            free(b);
        }
    ENSUREF(failed == 0, "%d of %d cases", failed, n);
}

SW_TEST_MAIN(CASE(the_fixture_loads_and_walks), CASE(forged_fields_are_refused_and_named),
             CASE(forged_domain_records_are_refused_and_named),
             CASE(every_contact_vertex_reference_is_checked),
             CASE(training_and_contact_table_entries_are_checked))
