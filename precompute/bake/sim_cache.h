/* The simulate stage's cache file (a re-bake redoes only what changed). The
 * full-space solutions of every pose sequence and their contact sets, under a key that
 * hashes everything they depend on (bake_cache.c), so that a bake that changes only the
 * cubature tolerance, the rank or the report reads them back instead of solving again.
 *
 * Layout (native byte order; a cache is a local file, not an interchange format):
 *   "SWSIMC\0\1", u64 key, i32 nverts, i32 nseq,
 *   per sequence: i32 npose, failed, unsettled, ncontacts,
 *   per sequence: npose * 3 nverts doubles (the solutions), npose + 1 i32 (contact_ptr),
 *                 ncontacts contacts (i32 p, tri[3]; f64 beta[3], ka, n[3], depth),
 *   u64 FNV-1a of every byte before it.
 * The reader trusts nothing: a file of another key, shape or version, truncated, with a
 * count or index out of range or a value not finite is refused with a message naming the
 * file and what is wrong, and the bake then solves as if there were none. */
#ifndef SW_SIM_CACHE_H
#define SW_SIM_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include "hash.h"
#include "self_detect.h"
#include "sw_error.h"

typedef struct sw_sim_cache_seq {
    int32_t npose, failed, unsettled, ncontacts;
    double *x;            /* npose * 3 nverts */
    int32_t *contact_ptr; /* npose + 1 */
    sw_contact *contacts; /* ncontacts */
} sw_sim_cache_seq;

typedef struct sw_sim_cache {
    uint64_t key;
    int32_t nverts, nseq;
    sw_sim_cache_seq *seq; /* nseq */
} sw_sim_cache;

/* The file's bytes for c (malloc'd into *out, *size). */
sinew_result sw_sim_cache_encode(const sw_sim_cache *c, uint8_t **out, size_t *size, sw_error *err);

/* Reads bytes [0, n) of the file `name` into out (owned arrays), which must hold `key`,
 * nverts vertices and nseq sequences of npose[i] poses each. On an error out is zeroed. */
sinew_result sw_sim_cache_parse(const uint8_t *b, size_t n, const char *name, uint64_t key,
                                int32_t nverts, int32_t nseq, const int32_t *npose,
                                sw_sim_cache *out, sw_error *err);

void sw_sim_cache_free(sw_sim_cache *c);

#endif
