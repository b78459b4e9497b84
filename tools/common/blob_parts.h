/* A blob's bytes by what they hold, and what its instances reserve: the memory lines of
 * sinew-bake's summary, its --json and sinew-bench's. */
#ifndef SW_BLOB_PARTS_H
#define SW_BLOB_PARTS_H

#include <stddef.h>

#include "sinew/sinew.h"

enum {
    SW_PART_BASIS,    /* BASIS */
    SW_PART_REDUCED,  /* the reduced mass, springs and inertia terms */
    SW_PART_CUBATURE, /* the cubature tets and their weights */
    SW_PART_POSES,    /* the training poses: solutions, forces, contacts, pair features */
    SW_PART_COND,     /* the condensation tet mesh */
    SW_PART_LOD,      /* the pose-space level */
    SW_PART_MESH,     /* the rest: rest positions, skinning, surfaces, names, the table */
    SW_NPARTS
};

/* The parts' names as the summary and the JSON write them. */
extern const char *const sw_blob_part_names[SW_NPARTS];
extern const char *const sw_blob_part_keys[SW_NPARTS];

typedef struct sw_blob_memory {
    size_t blob;            /* the blob's bytes */
    size_t part[SW_NPARTS]; /* of them, by part (summing to blob) */
    size_t instance;        /* an instance with the default def */
    size_t instance_shared; /* one stepping in a shared workspace (def.shared_workspace) */
    size_t workspace;       /* such a workspace, one a worker thread */
} sw_blob_memory;

/* The memory of the blob whose bytes are data (size bytes, as the writer wrote them) and
 * which loads as `blob`. 0 when the runtime refuses a size query. */
int sw_blob_memory_measure(const void *data, size_t size, const sinew_blob *blob,
                           sw_blob_memory *m);

/* One line on stderr: "  memory: blob ... MB (basis ..., ...); an instance ... MB, ...". */
void sw_blob_memory_print(const sw_blob_memory *m);

/* The JSON members (each after a comma): blob_bytes, blob_parts {...}, instance_bytes,
 * instance_shared_bytes, workspace_bytes. */
void sw_blob_memory_json(const sw_blob_memory *m);

#endif
