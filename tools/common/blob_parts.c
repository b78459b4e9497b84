#include "blob_parts.h"

#include <stdio.h>
#include <string.h>

#include "sinew/sinew_blob_format.h"

const char *const sw_blob_part_names[SW_NPARTS] = {"basis",
                                                   "reduced matrices",
                                                   "cubature",
                                                   "training poses",
                                                   "condensation mesh",
                                                   "pose-space level",
                                                   "mesh and skinning"};
/* distinct from every other member of the tools' JSON lines (their readers grep by name) */
const char *const sw_blob_part_keys[SW_NPARTS] = {"basis_bytes", "reduced_bytes", "cubature_bytes",
                                                  "poses_bytes", "cond_bytes",    "lod_bytes",
                                                  "mesh_bytes"};

/* The part of section id (unknown ids count as the mesh's: the rest). */
static int part_of(uint32_t id) {
    switch (id) {
    case SINEW_SECTION_BASIS:
        return SW_PART_BASIS;
    case SINEW_SECTION_SPRING_HESSIAN:
    case SINEW_SECTION_MASS:
    case SINEW_SECTION_INERTIA_S:
    case SINEW_SECTION_INERTIA_X:
    case SINEW_SECTION_INERTIA_U:
    case SINEW_SECTION_REDUCED_BLOCKS:
        return SW_PART_REDUCED;
    case SINEW_SECTION_CUB_TETS:
    case SINEW_SECTION_CUB_WEIGHT:
    case SINEW_SECTION_CUB_DMINV:
    case SINEW_SECTION_CUB_VOL:
    case SINEW_SECTION_CUB_STIFFNESS:
        return SW_PART_CUBATURE;
    case SINEW_SECTION_TRAIN_Q:
    case SINEW_SECTION_TRAIN_POSE:
    case SINEW_SECTION_CONTACT_PTR:
    case SINEW_SECTION_CONTACT_VERTS:
    case SINEW_SECTION_CONTACT_DATA:
    case SINEW_SECTION_TRAIN_FORCE:
        return SW_PART_POSES;
    case SINEW_SECTION_TET_STIFFNESS:
        return SW_PART_COND;
    default:
        break;
    }
    if (id >= SINEW_SECTION_PAIR_FIRST && id <= SINEW_SECTION_PAIR_LAST) return SW_PART_POSES;
    if (id >= SINEW_SECTION_COND_FIRST && id <= SINEW_SECTION_COND_LAST) return SW_PART_COND;
    if (id >= SINEW_SECTION_LOD_FIRST && id <= SINEW_SECTION_LOD_LAST) return SW_PART_LOD;
    return SW_PART_MESH;
}

int sw_blob_memory_measure(const void *data, size_t size, const sinew_blob *blob,
                           sw_blob_memory *m) {
    memset(m, 0, sizeof *m);
    sinew_blob_header h;
    if (size < sizeof h) return 0;
    memcpy(&h, data, sizeof h);
    m->blob = size;
    size_t counted = 0;
    for (uint32_t i = 0; i < h.section_count; ++i) {
        sinew_blob_section s;
        memcpy(&s, (const char *)data + h.section_table_offset + i * sizeof s, sizeof s);
        size_t bytes = (size_t)(s.count * s.elem_size);
        m->part[part_of(s.id)] += bytes;
        counted += bytes;
    }
    m->part[SW_PART_MESH] += size - counted; /* the header, the table and the padding */
    sinew_instance_def shared = sinew_instance_def_default();
    shared.shared_workspace = 1;
    return sinew_instance_memory_size(blob, NULL, &m->instance) == SINEW_OK &&
           sinew_instance_memory_size(blob, &shared, &m->instance_shared) == SINEW_OK &&
           sinew_workspace_memory_size(blob, &shared, &m->workspace) == SINEW_OK;
}

void sw_blob_memory_print(const sw_blob_memory *m) {
    fprintf(stderr, "  memory: blob %.2f MB (", (double)m->blob / 1e6);
    for (int k = 0; k < SW_NPARTS; ++k)
        fprintf(stderr, "%s%s %.2f", k ? ", " : "", sw_blob_part_names[k],
                (double)m->part[k] / 1e6);
    fprintf(stderr,
            "); an instance %.2f MB, or %.2f MB stepping in a shared workspace of %.2f MB a "
            "thread\n",
            (double)m->instance / 1e6, (double)m->instance_shared / 1e6,
            (double)m->workspace / 1e6);
}

void sw_blob_memory_json(const sw_blob_memory *m) {
    printf(",\"blob_bytes\":%zu,\"blob_parts\":{", m->blob);
    for (int k = 0; k < SW_NPARTS; ++k)
        printf("%s\"%s\":%zu", k ? "," : "", sw_blob_part_keys[k], m->part[k]);
    printf("},\"instance_bytes\":%zu,\"instance_shared_bytes\":%zu,\"workspace_bytes\":%zu",
           m->instance, m->instance_shared, m->workspace);
}
