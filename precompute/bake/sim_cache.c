/* The simulate stage's cache file (sim_cache.h). */
#include "sim_cache.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const uint8_t MAGIC[8] = {'S', 'W', 'S', 'I', 'M', 'C', 0, 1};
enum { HEAD = 8 + 8 + 4 + 4, SEQ_HEAD = 16, CONTACT = 16 + 64 };

void sw_sim_cache_free(sw_sim_cache *c) {
    if (!c) return;
    for (int32_t i = 0; c->seq && i < c->nseq; ++i) {
        free(c->seq[i].x);
        free(c->seq[i].contact_ptr);
        free(c->seq[i].contacts);
    }
    free(c->seq);
    memset(c, 0, sizeof *c);
}

/* Bytes of sequence q's arrays in the file. */
static uint64_t seq_bytes(int64_t npose, int64_t nverts, int64_t ncontacts) {
    return (uint64_t)npose * 3 * (uint64_t)nverts * 8 + (uint64_t)(npose + 1) * 4 +
           (uint64_t)ncontacts * CONTACT;
}

typedef struct {
    uint8_t *p;
} writer;

static void put(writer *w, const void *v, size_t n) {
    memcpy(w->p, v, n);
    w->p += n;
}

sinew_result sw_sim_cache_encode(const sw_sim_cache *c, uint8_t **out, size_t *size,
                                 sw_error *err) {
    *out = NULL;
    *size = 0;
    uint64_t total = HEAD + 8;
    for (int32_t i = 0; i < c->nseq; ++i)
        total += SEQ_HEAD + seq_bytes(c->seq[i].npose, c->nverts, c->seq[i].ncontacts);
    uint8_t *b = total <= SIZE_MAX ? malloc((size_t)total) : NULL;
    if (!b) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "simulate cache: out of memory");
    writer w = {b};
    put(&w, MAGIC, 8);
    put(&w, &c->key, 8);
    put(&w, &c->nverts, 4);
    put(&w, &c->nseq, 4);
    for (int32_t i = 0; i < c->nseq; ++i) {
        const sw_sim_cache_seq *q = &c->seq[i];
        int32_t h[4] = {q->npose, q->failed, q->unsettled, q->ncontacts};
        put(&w, h, sizeof h);
    }
    for (int32_t i = 0; i < c->nseq; ++i) {
        const sw_sim_cache_seq *q = &c->seq[i];
        put(&w, q->x, (size_t)q->npose * 3 * c->nverts * 8);
        put(&w, q->contact_ptr, (size_t)(q->npose + 1) * 4);
        for (int32_t k = 0; k < q->ncontacts; ++k) {
            const sw_contact *s = &q->contacts[k];
            put(&w, &s->p, 4);
            put(&w, s->tri, 12);
            put(&w, s->beta, 24);
            put(&w, &s->ka, 8);
            put(&w, s->n, 24);
            put(&w, &s->depth, 8);
        }
    }
    uint64_t h = sw_fnv1a(SW_FNV_START, b, (size_t)(w.p - b));
    put(&w, &h, 8);
    *out = b;
    *size = (size_t)total;
    return SINEW_OK;
}

typedef struct {
    const uint8_t *p, *end;
} reader;

static void get(reader *r, void *v, size_t n) {
    memcpy(v, r->p, n);
    r->p += n;
}

static int all_finite(const double *v, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* One sequence's arrays, checked. */
static sinew_result read_seq(reader *r, const char *name, int32_t i, int32_t nverts,
                             sw_sim_cache_seq *q, sw_error *err) {
    size_t nx = (size_t)q->npose * 3 * nverts;
    q->x = malloc(nx * 8 + 1);
    q->contact_ptr = malloc((size_t)(q->npose + 1) * 4);
    q->contacts = malloc((size_t)q->ncontacts * sizeof(sw_contact) + 1);
    if (!q->x || !q->contact_ptr || !q->contacts)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    get(r, q->x, nx * 8);
    if (!all_finite(q->x, (int64_t)nx))
        return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                            "%s: sequence %d: a solution is not finite", name, (int)i);
    get(r, q->contact_ptr, (size_t)(q->npose + 1) * 4);
    if (q->contact_ptr[0] != 0 || q->contact_ptr[q->npose] != q->ncontacts)
        return sw_error_set(
            err, SINEW_ERROR_CORRUPT, "%s: sequence %d: contact_ptr runs %d..%d, not 0..%d", name,
            (int)i, (int)q->contact_ptr[0], (int)q->contact_ptr[q->npose], (int)q->ncontacts);
    for (int32_t k = 0; k < q->npose; ++k)
        if (q->contact_ptr[k + 1] < q->contact_ptr[k])
            return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                "%s: sequence %d: contact_ptr decreases at pose %d", name, (int)i,
                                (int)k);
    for (int32_t k = 0; k < q->ncontacts; ++k) {
        sw_contact *s = &q->contacts[k];
        get(r, &s->p, 4);
        get(r, s->tri, 12);
        get(r, s->beta, 24);
        get(r, &s->ka, 8);
        get(r, s->n, 24);
        get(r, &s->depth, 8);
        int ok = s->p >= 0 && s->p < nverts;
        for (int j = 0; j < 3; ++j)
            ok = ok && s->tri[j] >= 0 && s->tri[j] < nverts;
        if (!ok)
            return sw_error_set(err, SINEW_ERROR_CORRUPT,
                                "%s: sequence %d contact %d: a vertex out of range [0, %d)", name,
                                (int)i, (int)k, (int)nverts);
        if (!all_finite(s->beta, 3) || !all_finite(s->n, 3) || !isfinite(s->ka) ||
            !isfinite(s->depth))
            return sw_error_set(err, SINEW_ERROR_NOT_FINITE,
                                "%s: sequence %d contact %d: a value is not finite", name, (int)i,
                                (int)k);
    }
    return SINEW_OK;
}

sinew_result sw_sim_cache_parse(const uint8_t *b, size_t n, const char *name, uint64_t key,
                                int32_t nverts, int32_t nseq, const int32_t *npose,
                                sw_sim_cache *out, sw_error *err) {
    memset(out, 0, sizeof *out);
    if (!b || n < HEAD + 8 || memcmp(b, MAGIC, 8) != 0)
        return sw_error_set(err, SINEW_ERROR_CORRUPT, "%s: not a simulate cache of this version",
                            name);
    uint64_t h;
    memcpy(&h, b + n - 8, 8);
    if (h != sw_fnv1a(SW_FNV_START, b, n - 8))
        return sw_error_set(err, SINEW_ERROR_CORRUPT,
                            "%s: checksum mismatch (damaged or truncated)", name);
    reader r = {b + 8, b + n - 8};
    sw_sim_cache c;
    memset(&c, 0, sizeof c);
    get(&r, &c.key, 8);
    get(&r, &c.nverts, 4);
    get(&r, &c.nseq, 4);
    if (c.key != key || c.nverts != nverts || c.nseq != nseq)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: made for other inputs (key %016llx, %d vertices, %d sequences; "
                            "this bake: %016llx, %d, %d)",
                            name, (unsigned long long)c.key, (int)c.nverts, (int)c.nseq,
                            (unsigned long long)key, (int)nverts, (int)nseq);
    if ((uint64_t)(r.end - r.p) < (uint64_t)nseq * SEQ_HEAD)
        return sw_error_set(err, SINEW_ERROR_CORRUPT, "%s: truncated sequence table", name);
    c.seq = calloc((size_t)nseq + 1, sizeof *c.seq);
    if (!c.seq) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    uint64_t need = 0;
    sinew_result rc = SINEW_OK;
    for (int32_t i = 0; i < nseq && rc == SINEW_OK; ++i) {
        sw_sim_cache_seq *q = &c.seq[i];
        int32_t hd[4];
        get(&r, hd, sizeof hd);
        q->npose = hd[0];
        q->failed = hd[1];
        q->unsettled = hd[2];
        q->ncontacts = hd[3];
        /* each array fits in the file (so no size below overflows) */
        int fits = q->npose >= 0 &&
                   (uint64_t)q->npose * 3 * (uint64_t)(nverts > 0 ? nverts : 0) <= n / 8 &&
                   q->ncontacts >= 0 && (uint64_t)q->ncontacts <= n / CONTACT;
        if (!fits || q->npose != npose[i] || q->failed < 0 || q->failed > q->npose ||
            q->unsettled < 0 || q->unsettled > q->npose || q->ncontacts < 0)
            rc = sw_error_set(err, SINEW_ERROR_CORRUPT,
                              "%s: sequence %d: %d poses (this bake has %d), %d failed, %d "
                              "unsettled, %d contacts",
                              name, (int)i, (int)q->npose, (int)npose[i], (int)q->failed,
                              (int)q->unsettled, (int)q->ncontacts);
        else
            need += seq_bytes(q->npose, nverts, q->ncontacts);
    }
    if (rc == SINEW_OK && need != (uint64_t)(r.end - r.p))
        rc = sw_error_set(err, SINEW_ERROR_CORRUPT,
                          "%s: %llu bytes of solutions, the table says %llu", name,
                          (unsigned long long)(r.end - r.p), (unsigned long long)need);
    for (int32_t i = 0; i < nseq && rc == SINEW_OK; ++i)
        rc = read_seq(&r, name, i, nverts, &c.seq[i], err);
    if (rc != SINEW_OK) {
        sw_sim_cache_free(&c);
        return rc;
    }
    *out = c;
    return SINEW_OK;
}
