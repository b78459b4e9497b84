/* The public blob API: load (map a file or use a host buffer in place), validate
 * (blob_load.c), query, destroy. The blob's bytes are never copied: the view points
 * into the mapping or the host's buffer. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "alloc.h"
#include "blob_load.h"
#include "def_read.h"
#include "log.h"

/* Maps `path` read-only; on success (map, size) describe the mapping. */
static sinew_result map_file(const char *path, const sinew_logger *lg, void **map, size_t *size) {
    char why[128];
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        int e = errno;
        if (strerror_r(e, why, sizeof why) != 0) snprintf(why, sizeof why, "errno %d", e);
        if (fd >= 0) close(fd);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_IO, "sinew_blob_load: cannot open '%s': %s",
               path, why);
        return SINEW_ERROR_IO;
    }
    if (!S_ISREG(st.st_mode) || st.st_size < 0 || (uint64_t)st.st_size > SIZE_MAX) {
        close(fd);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_IO,
               "sinew_blob_load: '%s' is not a regular file of a mappable size", path);
        return SINEW_ERROR_IO;
    }
    if ((uint64_t)st.st_size < sizeof(sinew_blob_header)) {
        close(fd);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_INVALID,
               "sinew_blob_load: '%s': blob header: the file has %lld bytes, shorter than "
               "the 64-byte header",
               path, (long long)st.st_size);
        return SINEW_ERROR_CORRUPT;
    }
    void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
    int e = errno;
    close(fd); /* the mapping stays valid */
    if (p == MAP_FAILED) {
        if (strerror_r(e, why, sizeof why) != 0) snprintf(why, sizeof why, "errno %d", e);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_IO, "sinew_blob_load: cannot map '%s': %s", path,
               why);
        return SINEW_ERROR_IO;
    }
    *map = p;
    *size = (size_t)st.st_size;
    return SINEW_OK;
}

SINEW_API sinew_result sinew_blob_load(const sinew_blob_def *def, sinew_blob **out) {
    if (!def || !out) return SINEW_ERROR_INVALID_ARGUMENT;
    /* the fields every caller has: path, data and data_size */
    sinew_blob_def d = sinew_blob_def_default();
    if (sw_def_read(&d, sizeof d, def, offsetof(sinew_blob_def, data_size) + sizeof(size_t)) !=
        SINEW_OK)
        return SINEW_ERROR_INVALID_ARGUMENT;
    const sinew_logger *lg = &d.logger;
    if (sw_allocator_check(&d.allocator) != SINEW_OK) {
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_INVALID_ARGUMENT,
               "sinew_blob_load: allocator.alloc and allocator.free must both be set or "
               "both be NULL");
        return SINEW_ERROR_INVALID_ARGUMENT;
    }
    if ((d.path == NULL) == (d.data == NULL)) {
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_INVALID_ARGUMENT,
               "sinew_blob_load: give exactly one of def->path and def->data");
        return SINEW_ERROR_INVALID_ARGUMENT;
    }

    void *map = NULL;
    size_t size = d.data_size;
    const void *data = d.data;
    if (d.path) {
        sinew_result r = map_file(d.path, lg, &map, &size);
        if (r != SINEW_OK) return r;
        data = map;
    }

    char msg[512];
    sw_blob_view view;
    sinew_result r = sw_blob_parse(data, size, &view, msg, sizeof msg);
    if (r != SINEW_OK) {
        if (map) munmap(map, size);
        sw_log(lg, SINEW_LOG_ERROR,
               r == SINEW_ERROR_INVALID_ARGUMENT ? SINEW_MSG_BLOB_INVALID_ARGUMENT
                                                 : SINEW_MSG_BLOB_INVALID,
               "sinew_blob_load: '%s': %s", d.path ? d.path : "<host buffer>", msg);
        return r;
    }

    /* the struct, then what its instances share: the pose index, the surface clusters and
       the active map (blob_pose_index.h, blob_clusters.h, blob_active.h) */
    const size_t head = (sizeof(sinew_blob) + 7) / 8 * 8,
                 poses = (sw_pose_index_bytes(&view) + 7) / 8 * 8,
                 clusters = sw_surface_clusters_bytes(&view),
                 bytes = head + poses + clusters + sw_active_map_bytes(&view);
    sinew_blob *blob = sw_alloc(&d.allocator, bytes, SW_ALLOC_ALIGN);
    if (!blob) {
        if (map) munmap(map, size);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_OUT_OF_MEMORY,
               "sinew_blob_load: out of memory (%zu bytes)", bytes);
        return SINEW_ERROR_OUT_OF_MEMORY;
    }
    sw_pose_index_build(&view, (char *)blob + head, &blob->poses);
    sw_surface_clusters_build(&view, (char *)blob + head + poses, &blob->clusters);
    sw_active_map_build(&view, (char *)blob + head + poses + clusters, &blob->act);
    if (sw_coll_surface_build(&view, &d.allocator, &blob->coll) != SINEW_OK) {
        sw_free(&d.allocator, blob);
        if (map) munmap(map, size);
        sw_log(lg, SINEW_LOG_ERROR, SINEW_MSG_BLOB_OUT_OF_MEMORY,
               "sinew_blob_load: out of memory (the collision surface of %d triangles)",
               view.nsurf_tris);
        return SINEW_ERROR_OUT_OF_MEMORY;
    }
    blob->view = view;
    blob->data = data;
    blob->size = size;
    blob->map = map;
    blob->map_size = map ? size : 0;
    blob->allocator = d.allocator;
    blob->logger = d.logger;
    sw_log(lg, SINEW_LOG_INFO, SINEW_MSG_BLOB_LOADED,
           "sinew_blob_load: '%s': %zu bytes %s; %d vertices, %d bones, %d domains, rank %d, "
           "%d cubature tets, %d surface vertices, %d triangles%s",
           d.path ? d.path : "<host buffer>", size, map ? "mapped" : "in place", view.nverts,
           view.nbones, view.ndomains, view.rank_total, view.ncub, sw_blob_output_verts(&view),
           sw_blob_output_ntris(&view), view.nrender_verts ? " (the embedded render mesh)" : "");
    *out = blob;
    return SINEW_OK;
}

SINEW_API void sinew_blob_destroy(sinew_blob *blob) {
    if (!blob) return;
    if (blob->map) munmap(blob->map, blob->map_size);
    sinew_allocator a = blob->allocator;
    sw_coll_surface_free(&a, &blob->coll);
    sw_free(&a, blob);
}

const sw_blob_view *sw_blob_get_view(const sinew_blob *blob) {
    return blob ? &blob->view : NULL;
}

SINEW_API uint32_t sinew_blob_bone_count(const sinew_blob *blob) {
    return blob ? (uint32_t)blob->view.nbones : 0u;
}

/* The output surface is the render mesh when the blob has one (blob_view.h). */
SINEW_API uint32_t sinew_blob_surface_vertex_count(const sinew_blob *blob) {
    return blob ? (uint32_t)sw_blob_output_verts(&blob->view) : 0u;
}

SINEW_API uint32_t sinew_blob_surface_triangle_count(const sinew_blob *blob) {
    return blob ? (uint32_t)sw_blob_output_ntris(&blob->view) : 0u;
}

SINEW_API sinew_result sinew_blob_surface_triangles(const sinew_blob *blob, uint32_t *indices,
                                                    uint32_t capacity) {
    if (!blob || !indices) return SINEW_ERROR_INVALID_ARGUMENT;
    const uint64_t n = 3 * (uint64_t)sw_blob_output_ntris(&blob->view);
    const int32_t *tris = sw_blob_output_tris(&blob->view);
    if (capacity < n) return SINEW_ERROR_CAPACITY;
    /* Validated at load: every index is in [0, output vertices). */
    for (uint64_t i = 0; i < n; ++i)
        indices[i] = (uint32_t)tris[i];
    return SINEW_OK;
}

/* The collision surface is the tet boundary split into sheets (blob_collision.h),
 * whatever the output is. */
SINEW_API uint32_t sinew_blob_collision_vertex_count(const sinew_blob *blob) {
    return blob ? (uint32_t)blob->coll.nverts : 0u;
}

SINEW_API uint32_t sinew_blob_collision_triangle_count(const sinew_blob *blob) {
    return blob ? (uint32_t)blob->coll.ntris : 0u;
}

SINEW_API sinew_result sinew_blob_collision_triangles(const sinew_blob *blob, uint32_t *indices,
                                                      uint32_t capacity) {
    if (!blob || !indices) return SINEW_ERROR_INVALID_ARGUMENT;
    const uint64_t n = 3 * (uint64_t)blob->coll.ntris;
    if (capacity < n) return SINEW_ERROR_CAPACITY;
    for (uint64_t i = 0; i < n; ++i)
        indices[i] = (uint32_t)blob->coll.tris[i];
    return SINEW_OK;
}

/* The asset description's names are back to back, each ended by a zero (validated). */
SINEW_API const char *sinew_blob_bone_name(const sinew_blob *blob, uint32_t bone) {
    if (!blob || !blob->view.bone_names || bone >= (uint32_t)blob->view.nbones) return NULL;
    const char *p = blob->view.bone_names;
    for (uint32_t b = 0; b < bone; ++b)
        p += strlen(p) + 1;
    return p;
}

SINEW_API int32_t sinew_blob_find_bone(const sinew_blob *blob, const char *name) {
    if (!blob || !name || !blob->view.bone_names) return -1;
    const char *p = blob->view.bone_names;
    for (int32_t b = 0; b < blob->view.nbones; ++b) {
        if (strcmp(p, name) == 0) return b;
        p += strlen(p) + 1;
    }
    return -1;
}

SINEW_API sinew_result sinew_blob_bone_parent(const sinew_blob *blob, uint32_t bone,
                                              int32_t *parent) {
    if (!blob || !parent || bone >= (uint32_t)blob->view.nbones)
        return SINEW_ERROR_INVALID_ARGUMENT;
    *parent = blob->view.bone_parent[bone];
    return SINEW_OK;
}

SINEW_API sinew_result sinew_blob_bone_bind(const sinew_blob *blob, uint32_t bone,
                                            double bind[12]) {
    if (!blob || !bind || bone >= (uint32_t)blob->view.nbones) return SINEW_ERROR_INVALID_ARGUMENT;
    if (!blob->view.bone_bind) return SINEW_ERROR_UNSUPPORTED;
    memcpy(bind, blob->view.bone_bind + 12 * (size_t)bone, 12 * sizeof(double));
    return SINEW_OK;
}

SINEW_API uint32_t sinew_blob_source_mesh_count(const sinew_blob *blob) {
    return blob ? (uint32_t)blob->view.nsource_meshes : 0u;
}

SINEW_API sinew_result sinew_blob_output_sources(const sinew_blob *blob, int32_t *pairs,
                                                 uint32_t capacity) {
    if (!blob || !pairs) return SINEW_ERROR_INVALID_ARGUMENT;
    if (!blob->view.output_source) return SINEW_ERROR_UNSUPPORTED;
    const uint64_t n = 2 * (uint64_t)blob->view.noutput_verts;
    if (capacity < n) return SINEW_ERROR_CAPACITY;
    memcpy(pairs, blob->view.output_source, (size_t)n * sizeof(int32_t));
    return SINEW_OK;
}

SINEW_API sinew_result sinew_blob_get_provenance(const sinew_blob *blob,
                                                 sinew_blob_provenance *out) {
    if (!blob || !out || out->struct_size < 8) return SINEW_ERROR_INVALID_ARGUMENT;
    if (!blob->view.bone_names) return SINEW_ERROR_UNSUPPORTED;
    const sw_blob_view *v = &blob->view;
    sinew_blob_provenance p;
    memset(&p, 0, sizeof p);
    p.struct_size = out->struct_size < sizeof p ? out->struct_size : (uint32_t)sizeof p;
    p.sinew_version = v->sinew_version;
    p.source_hash = v->source_hash;
    p.options_hash = v->options_hash;
    sinew_blob_header h; /* the blob's own version, which may predate the runtime's */
    memcpy(&h, blob->data, sizeof h);
    p.format_version = h.version;
    memcpy(out, &p, p.struct_size);
    return SINEW_OK;
}

SINEW_API uint64_t sinew_hash_bytes(const void *data, size_t size) {
    if (!data && size) return 0;
    return sw_blob_checksum(data ? data : "", size);
}
