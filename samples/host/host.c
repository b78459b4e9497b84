/* The smallest engine host: built against an installed sinew (find_package(sinew) or
 * pkg-config, see samples/host/CMakeLists.txt and README.md "Linking"), it checks that
 * the library it loaded accepts the headers it was compiled with, prints the version
 * and a result string, and, given a blob path, loads the blob, creates an instance,
 * steps it once in its rest pose, reads the surface back, and hands its collision
 * surface to a world as the mesh collider another character would collide with.
 *
 * usage: sinew-host [BLOB]      exit 0 on success, 1 on any failure */
#include <stdio.h>
#include <stdlib.h>

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
    ok = host_collider(blob, inst);
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
