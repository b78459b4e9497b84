/* The smallest engine host: built against an installed sinew (find_package(sinew) or
 * pkg-config, see samples/host/CMakeLists.txt and README.md "Linking"), it checks that
 * the library it loaded accepts the headers it was compiled with, prints the version
 * and a result string, and, given a blob path, loads the blob, creates an instance,
 * steps it once in its rest pose, reads the surface back, steps a second instance that
 * keeps no scratch of its own in a workspace (as a crowd's worker threads do) and checks
 * it gives the same surface, and hands its collision surface to a world as the mesh
 * collider another character would collide with.
 *
 * usage: sinew-host [BLOB]      exit 0 on success, 1 on any failure */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sinew/sinew.h>
#include <sinew/sinew_world.h>

/* The instance's collision surface as a mesh collider of a new world (what a second
 * character would collide with), then the world gone again. */
static int host_collider(const sinew_blob *blob, const sinew_instance *inst) {
    uint32_t nv = sinew_blob_collision_vertex_count(blob),
             nt = sinew_blob_collision_triangle_count(blob);
    float *x = calloc((size_t)nv * 3u + 1u, sizeof *x);
    uint32_t *tris = calloc((size_t)nt * 3u + 1u, sizeof *tris);
    sinew_world_def wdef = sinew_world_def_default();
    sinew_collider_def cdef = sinew_collider_def_default();
    sinew_world *world = NULL;
    sinew_collider_id id = 0;
    sinew_result r = x && tris ? SINEW_OK : SINEW_ERROR_OUT_OF_MEMORY;
    if (r == SINEW_OK) r = sinew_instance_read_collision_surface(inst, x, nv);
    if (r == SINEW_OK) r = sinew_blob_collision_triangles(blob, tris, nt * 3u);
    if (r == SINEW_OK) r = sinew_world_create(&wdef, &world);
    if (r == SINEW_OK) {
        cdef.shape = SINEW_SHAPE_MESH;
        cdef.vertices = x;
        cdef.vertex_count = nv;
        cdef.indices = tris;
        cdef.triangle_count = nt;
        r = sinew_world_add_collider(world, &cdef, &id);
    }
    if (r != SINEW_OK)
        fprintf(stderr, "host: collision surface: %s\n", sinew_result_string(r));
    else
        printf("host: collision surface of %u vertices, %u triangles taken as a mesh collider\n",
               (unsigned)nv, (unsigned)nt);
    sinew_world_destroy(world);
    free(x);
    free(tris);
    return r == SINEW_OK;
}

/* An instance without scratch of its own (def.shared_workspace) stepped in a workspace,
 * as a crowd's worker thread steps the instances it takes: the same surface, bitwise, as
 * `positions` of the instance with its own scratch. */
static int host_workspace(const sinew_blob *blob, const float *transforms, const float *positions) {
    sinew_instance_def d = sinew_instance_def_default();
    sinew_workspace *ws = NULL;
    sinew_instance *inst = NULL;
    uint32_t verts = sinew_blob_surface_vertex_count(blob), bones = sinew_blob_bone_count(blob);
    size_t state = 0, scratch = 0;
    float *x = calloc((size_t)verts * 3u + 1u, sizeof *x);
    sinew_result r = x ? SINEW_OK : SINEW_ERROR_OUT_OF_MEMORY;
    int same = 0;
    d.collision_surface = 1;
    d.shared_workspace = 1;
    if (r == SINEW_OK) r = sinew_workspace_create(blob, &d, &ws);
    if (r == SINEW_OK) r = sinew_instance_create(blob, &d, &inst);
    if (r == SINEW_OK) r = sinew_instance_set_pose(inst, transforms, bones);
    if (r == SINEW_OK) r = sinew_instance_step_in(inst, ws, 1.0f / 60.0f);
    if (r == SINEW_OK) r = sinew_instance_read_surface(inst, x, NULL, verts);
    if (r == SINEW_OK) r = sinew_instance_memory_size(blob, &d, &state);
    if (r == SINEW_OK) r = sinew_workspace_memory_size(blob, &d, &scratch);
    if (r == SINEW_OK) same = memcmp(x, positions, (size_t)verts * 3u * sizeof *x) == 0;
    if (r != SINEW_OK)
        fprintf(stderr, "host: workspace: %s\n", sinew_result_string(r));
    else if (!same)
        fprintf(stderr, "host: the instance stepped in a workspace gave another surface\n");
    else
        printf("host: stepped in a workspace: the same surface; %lu bytes an instance, %lu "
               "the workspace\n",
               (unsigned long)state, (unsigned long)scratch);
    sinew_instance_destroy(inst);
    sinew_workspace_destroy(ws);
    free(x);
    return r == SINEW_OK && same;
}

static int host_run_blob(const char *path) {
    sinew_blob_def bdef = sinew_blob_def_default();
    sinew_instance_def idef = sinew_instance_def_default();
    sinew_blob *blob = NULL;
    sinew_instance *inst = NULL;
    float *transforms = NULL, *positions = NULL;
    uint32_t bones, verts, b;
    sinew_result r;
    int ok = 0;

    bdef.path = path;
    idef.collision_surface = 1; /* (needed only under a render mesh) */
    r = sinew_blob_load(&bdef, &blob);
    if (r != SINEW_OK) {
        fprintf(stderr, "host: %s: %s\n", path, sinew_result_string(r));
        return 0;
    }
    r = sinew_instance_create(blob, &idef, &inst);
    if (r != SINEW_OK) {
        fprintf(stderr, "host: instance: %s\n", sinew_result_string(r));
        goto done;
    }
    bones = sinew_blob_bone_count(blob);
    verts = sinew_blob_surface_vertex_count(blob);
    transforms = calloc((size_t)bones * 12u + 1u, sizeof *transforms);
    positions = calloc((size_t)verts * 3u + 1u, sizeof *positions);
    if (!transforms || !positions) {
        fprintf(stderr, "host: out of memory\n");
        goto done;
    }
    for (b = 0; b < bones; b++) { /* the bind pose: identity rotations, no translation */
        transforms[b * 12u + 0u] = 1.0f;
        transforms[b * 12u + 4u] = 1.0f;
        transforms[b * 12u + 8u] = 1.0f;
    }
    if ((r = sinew_instance_set_pose(inst, transforms, bones)) != SINEW_OK ||
        (r = sinew_instance_step(inst, 1.0f / 60.0f)) != SINEW_OK ||
        (r = sinew_instance_read_surface(inst, positions, NULL, verts)) != SINEW_OK) {
        fprintf(stderr, "host: step: %s\n", sinew_result_string(r));
        goto done;
    }
    printf("host: %s: %u bones, %u surface vertices, stepped once\n", path, (unsigned)bones,
           (unsigned)verts);
    ok = host_workspace(blob, transforms, positions) && host_collider(blob, inst);
done:
    free(positions);
    free(transforms);
    sinew_instance_destroy(inst);
    sinew_blob_destroy(blob);
    return ok;
}

int main(int argc, char **argv) {
    if (!sinew_version_compatible(SINEW_VERSION)) {
        fprintf(stderr, "host: headers 0x%06lx are not compatible with library %s\n",
                (unsigned long)SINEW_VERSION, sinew_version_string());
        return 1;
    }
    printf("host: sinew %s (0x%06lx), headers 0x%06lx; SINEW_OK is \"%s\"\n",
           sinew_version_string(), (unsigned long)sinew_version(), (unsigned long)SINEW_VERSION,
           sinew_result_string(SINEW_OK));
    if (argc > 1 && !host_run_blob(argv[1])) return 1;
    return 0;
}
