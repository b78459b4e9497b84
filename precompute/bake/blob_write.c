/* Blob layout: header (64 bytes), section table (26 entries, 8 more with a render mesh, 10
 * more with the condensation tet mesh, 6 more with per-pair self-contact, 1 more with the
 * pose-space equilibrium force, 5 more with the asset description), then the sections in id
 * order, each starting at a multiple of SINEW_BLOB_ALIGN; the checksum (FNV-1a 64) covers
 * everything after the header. A view without the optional groups writes exactly the 26 sections it
 * always did, byte for byte. */
#include "blob_write.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "blob_load.h"

typedef struct section_src {
    uint32_t id, elem_size;
    const void *src;
    uint64_t count;
} section_src;

static uint64_t round_up(uint64_t x) {
    return (x + SINEW_BLOB_ALIGN - 1) / SINEW_BLOB_ALIGN * SINEW_BLOB_ALIGN;
}

#define SOURCE(id, NAME, elem_size, type, field, by_meta, count, formula)                          \
    {id, elem_size, v->field, count},

/* The metas of the optional groups, filled from the view's counts. */
typedef struct group_metas {
    sinew_blob_render_meta render;
    sinew_blob_cond_meta cond;
    sinew_blob_pair_meta pair;
    sinew_blob_asset_meta asset;
    sinew_blob_lod_meta lod;
} group_metas;

/* The sections of a validated view, in id order, into s; returns their number (26, plus 8
 * with a render mesh, plus 10 with the condensation tet mesh, plus 6 with per-pair
 * self-contact, plus 1 with the equilibrium force, plus 5 with the asset description, plus
 * 1 or 2 with painted material, plus 6 with the pose-space level, plus 1 with packed
 * reduced matrices). `meta` and
 * `g` must outlive the result. */
static int list_sections(const sw_blob_view *v, const sinew_blob_meta *meta, const group_metas *g,
                         section_src s[SINEW_SECTION_ID_MAX]) {
    SW_BLOB_COUNT_LOCALS(v);
    const section_src list[SINEW_SECTION_COUNT_V1] = {{SINEW_SECTION_META, sizeof *meta, meta, 1},
                                                      SINEW_BLOB_ARRAY_SECTIONS(SOURCE)};
    memcpy(s, list, sizeof list);
    int n = SINEW_SECTION_COUNT_V1;
    if (v->nrender_verts > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_RENDER_COUNTS);
        const section_src render[] = {{SINEW_SECTION_RENDER_META, sizeof g->render, &g->render, 1},
                                      SINEW_BLOB_RENDER_ARRAY_SECTIONS(SOURCE)};
        memcpy(s + n, render, sizeof render);
        n += (int)(sizeof render / sizeof render[0]);
    }
    if (v->ntets > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_COND_COUNTS);
        const section_src cond[] = {{SINEW_SECTION_COND_META, sizeof g->cond, &g->cond, 1},
                                    SINEW_BLOB_COND_ARRAY_SECTIONS(SOURCE)};
        for (size_t i = 0; i < sizeof cond / sizeof cond[0]; ++i)
            if (cond[i].src) s[n++] = cond[i]; /* COND_TET_DMINV may be left out */
    }
    if (v->npair_groups > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_PAIR_COUNTS);
        const section_src pair[] = {{SINEW_SECTION_PAIR_META, sizeof g->pair, &g->pair, 1},
                                    SINEW_BLOB_PAIR_ARRAY_SECTIONS(SOURCE)};
        memcpy(s + n, pair, sizeof pair);
        n += (int)(sizeof pair / sizeof pair[0]);
    }
    if (v->train_force) {
        const section_src force[] = {SINEW_BLOB_FORCE_SECTIONS(SOURCE)};
        memcpy(s + n, force, sizeof force);
        n += (int)(sizeof force / sizeof force[0]);
    }
    if (v->bone_names) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_ASSET_COUNTS);
        const section_src asset[] = {{SINEW_SECTION_ASSET_META, sizeof g->asset, &g->asset, 1},
                                     SINEW_BLOB_ASSET_ARRAY_SECTIONS(SOURCE)};
        memcpy(s + n, asset, sizeof asset);
        n += (int)(sizeof asset / sizeof asset[0]);
    }
    if (v->cub_stiffness) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_COND_COUNTS);
        const section_src stiff[] = {SINEW_BLOB_STIFFNESS_SECTIONS(SOURCE)};
        const int nstiff = v->tet_stiffness ? 2 : 1; /* TET_STIFFNESS with the cond mesh */
        memcpy(s + n, stiff, (size_t)nstiff * sizeof stiff[0]);
        n += nstiff;
    }
    if (v->lod_rank > 0) {
        SW_BLOB_GROUP_COUNT_LOCALS(v, SINEW_BLOB_LOD_COUNTS);
        const section_src lod[] = {{SINEW_SECTION_LOD_META, sizeof g->lod, &g->lod, 1},
                                   SINEW_BLOB_LOD_ARRAY_SECTIONS(SOURCE)};
        memcpy(s + n, lod, sizeof lod);
        n += (int)(sizeof lod / sizeof lod[0]);
    }
    if (v->reduced_blocks) {
        const section_src blocks[] = {SINEW_BLOB_BLOCKS_SECTIONS(SOURCE)};
        memcpy(s + n, blocks, sizeof blocks);
        n += (int)(sizeof blocks / sizeof blocks[0]);
    }
    return n;
}
#undef SOURCE

sinew_result sw_blob_write_memory(const sw_blob_view *view, void **data, size_t *size,
                                  sw_error *err) {
    if (data) *data = NULL;
    if (size) *size = 0;
    if (!view || !data || !size)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "blob write: view, data and size must not be NULL");
    char msg[512];
    sinew_result r = sw_blob_validate_view(view, msg, sizeof msg);
    if (r != SINEW_OK) return sw_error_set(err, r, "blob write: invalid view: %s", msg);

    sinew_blob_meta meta;
    memset(&meta, 0, sizeof meta);
#define TO_META(field) meta.field = view->field;
    SW_BLOB_META_FIELDS(TO_META)
#undef TO_META

    group_metas g;
    memset(&g, 0, sizeof g);
#define TO_RENDER_META(field) g.render.field = view->field;
    SINEW_BLOB_RENDER_COUNTS(TO_RENDER_META)
#undef TO_RENDER_META
#define TO_COND_META(field) g.cond.field = view->field;
    SINEW_BLOB_COND_COUNTS(TO_COND_META)
#undef TO_COND_META
#define TO_PAIR_META(field) g.pair.field = view->field;
    SINEW_BLOB_PAIR_COUNTS(TO_PAIR_META)
#undef TO_PAIR_META
#define TO_ASSET_META(field) g.asset.field = view->field;
    SINEW_BLOB_ASSET_COUNTS(TO_ASSET_META)
#undef TO_ASSET_META
#define TO_LOD_META(field) g.lod.field = view->field;
    SINEW_BLOB_LOD_COUNTS(TO_LOD_META)
#undef TO_LOD_META
    g.asset.sinew_version = view->sinew_version;
    g.asset.source_hash = view->source_hash;
    g.asset.options_hash = view->options_hash;

    section_src src[SINEW_SECTION_ID_MAX];
    sinew_blob_section table[SINEW_SECTION_ID_MAX];
    const int nsec = list_sections(view, &meta, &g, src);
    /* Validated counts are bounded (blob_load.h limits), so no sum below overflows. */
    uint64_t at = round_up(sizeof(sinew_blob_header) + (uint64_t)nsec * sizeof table[0]);
    for (int i = 0; i < nsec; ++i) {
        memset(&table[i], 0, sizeof table[i]);
        table[i].id = src[i].id;
        table[i].elem_size = src[i].elem_size;
        table[i].offset = at;
        table[i].count = src[i].count;
        at = round_up(at + src[i].count * src[i].elem_size);
    }
    if (at > SIZE_MAX)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY,
                            "blob write: %llu bytes do not fit in memory", (unsigned long long)at);
    const size_t total = (size_t)at;
    uint8_t *buf = aligned_alloc(SINEW_BLOB_ALIGN, total); /* total is a multiple of 64 */
    if (!buf)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "blob write: cannot allocate %zu bytes",
                            total);
    memset(buf, 0, total); /* padding is zero */
    memcpy(buf + sizeof(sinew_blob_header), table, (size_t)nsec * sizeof table[0]);
    for (int i = 0; i < nsec; ++i)
        memcpy(buf + table[i].offset, src[i].src, (size_t)(src[i].count * src[i].elem_size));

    sinew_blob_header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, SINEW_BLOB_MAGIC, sizeof h.magic);
    /* packed reduced matrices need version 4; a blob with dense ones stays readable by a
     * version-2 runtime unless painted (3) */
    h.version = view->reduced_blocks  ? SINEW_BLOB_VERSION
                : view->cub_stiffness ? 3u
                                      : SINEW_BLOB_VERSION_MIN;
    h.header_size = (uint32_t)sizeof h;
    h.file_size = total;
    h.section_count = (uint32_t)nsec;
    h.endian_tag = SINEW_BLOB_ENDIAN_TAG;
    h.section_table_offset = sizeof h;
    h.checksum = sw_blob_checksum(buf + sizeof h, total - sizeof h);
    memcpy(buf, &h, sizeof h);

    /* Self-check: the bytes must load. A failure here is a writer bug, not the bake's. */
    sw_blob_view check;
    r = sw_blob_parse(buf, total, &check, msg, sizeof msg);
    if (r != SINEW_OK) {
        free(buf);
        return sw_error_set(err, r, "blob write: internal error, the written blob fails: %s", msg);
    }
    *data = buf;
    *size = total;
    return SINEW_OK;
}

int64_t sw_blob_pack_blocks(const sw_blob_domain *doms, int32_t nd, int32_t R, const double *A,
                            int32_t *blocks, double *packed) {
    int64_t at = 0;
    for (int32_t a = 0; a < nd; ++a)
        for (int32_t b = 0; b < nd; ++b) {
            const double *B = A + (int64_t)doms[a].q_offset * R + doms[b].q_offset;
            int32_t ra = doms[a].rank, rb = doms[b].rank, any = a == b;
            for (int32_t i = 0; i < ra && !any; ++i)
                for (int32_t j = 0; j < rb && !any; ++j)
                    any = B[(int64_t)i * R + j] != 0.0;
            blocks[a * nd + b] = any ? (int32_t)at : -1;
            if (!any) continue;
            for (int32_t i = 0; packed && i < ra; ++i)
                memcpy(packed + at + (int64_t)i * rb, B + (int64_t)i * R, (size_t)rb * sizeof *B);
            at += (int64_t)ra * rb;
        }
    return at;
}

static sinew_result io_error(sw_error *err, const char *what, const char *file, int e) {
    char why[128];
    if (strerror_r(e, why, sizeof why) != 0) snprintf(why, sizeof why, "errno %d", e);
    return sw_error_set(err, SINEW_ERROR_IO, "write: cannot %s '%s': %s", what, file, why);
}

static int write_all(int fd, const uint8_t *p, size_t n) {
    while (n > 0) {
        ssize_t w = write(fd, p, n > ((size_t)1 << 30) ? ((size_t)1 << 30) : n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

/* fsync of the folder holding `path`, so the rename itself survives a crash. Best
 * effort: some file systems refuse to fsync a directory. */
static void sync_parent(const char *path) {
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else if ((size_t)(slash - path) < sizeof dir)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else
        return;
    int fd = open(dir, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    (void)fsync(fd);
    close(fd);
}

sinew_result sw_write_file_atomic(const char *path, const uint8_t *data, size_t size,
                                  sw_error *err) {
    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (!tmp) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "write: out of memory");
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".tmp", 5);
    sinew_result r = SINEW_OK;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        r = io_error(err, "create", tmp, errno);
        free(tmp);
        return r;
    }
    if (write_all(fd, data, size) != 0)
        r = io_error(err, "write", tmp, errno);
    else if (fsync(fd) != 0)
        r = io_error(err, "fsync", tmp, errno);
    if (close(fd) != 0 && r == SINEW_OK) r = io_error(err, "close", tmp, errno);
    if (r == SINEW_OK && rename(tmp, path) != 0) {
        int e = errno;
        r = sw_error_set(err, SINEW_ERROR_IO, "write: cannot rename '%s' to '%s': ", tmp, path);
        if (err) {
            size_t used = strlen(err->msg);
            if (strerror_r(e, err->msg + used, sizeof err->msg - used) != 0)
                snprintf(err->msg + used, sizeof err->msg - used, "errno %d", e);
        }
    }
    if (r != SINEW_OK)
        unlink(tmp);
    else
        sync_parent(path);
    free(tmp);
    return r;
}

sinew_result sw_blob_write(const char *path, const sw_blob_view *view, sw_error *err) {
    if (!path || !path[0])
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "blob write: no path given");
    void *data = NULL;
    size_t size = 0;
    sinew_result r = sw_blob_write_memory(view, &data, &size, err);
    if (r != SINEW_OK) return r;
    r = sw_write_file_atomic(path, data, size, err);
    free(data);
    return r;
}

sinew_result sw_write_file_check(const char *path, sw_error *err) {
    struct stat st;
    if (!path || !path[0]) return io_error(err, "write", "", ENOENT);
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return io_error(err, "write", path, EISDIR);
    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (!tmp) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "write: out of memory");
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".tmp", 5);
    const int existed = access(tmp, F_OK) == 0;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    sinew_result r = SINEW_OK;
    if (fd < 0)
        r = io_error(err, "create", tmp, errno);
    else {
        close(fd);
        if (!existed) unlink(tmp);
    }
    free(tmp);
    return r;
}
