/* World files: the colliders of a scene (sinew_world.h's shapes) and their keyframed
 * rigid motion, as JSON (read with Debian's libcjson). The reader produces plain data
 * (sinew_collider_def plus owned arrays and keys); it never calls the world's functions.
 *
 * Schema version 1 (samples/worlds/README.md shows examples):
 *   {"sinew_world": 1,              required, the integer 1 (else SINEW_ERROR_VERSION)
 *    "frames": 30,                  optional, the scene length (integer >= 1)
 *    "pose": "clip",                optional: "clip" (default: the character plays its
 *                                   clip) or "rest" (it holds its rest pose while the
 *                                   colliders move)
 *    "colliders": [ {...}, ... ]}   required, at most SW_WORLD_MAX_COLLIDERS (may be empty)
 * A collider:
 *   "name"       optional string (< 64 bytes, unique); default "collider<i>"
 *   "shape"      required: "plane" | "sphere" | "capsule" | "box" | "hull" | "mesh"
 *   plane:   "normal" [x,y,z] (nonzero; stored normalised), "offset" (signed distance of
 *            the plane from the origin along the unit normal)
 *   sphere:  "radius" > 0
 *   capsule: "radius" > 0, "half_height" >= 0 (along the local y axis)
 *   box:     "half_extents" [x,y,z], each > 0
 *   hull:    "points" [[x,y,z], ...], 4 ..= SW_WORLD_MAX_HULL_POINTS, not all coplanar
 *   mesh:    "obj" a path relative to the world file's folder (OBJ, polygons
 *            fan-triangulated by sw_read_obj; zero-area triangles rejected)
 *   "stiffness" >= 0, "friction" >= 0   optional, 0 by default (sinew_collider_def)
 *   "motion" [{"frame": f, "position": [x,y,z], "rotation": [w,x,y,z]}, ...]  optional:
 *            1 ..= SW_WORLD_MAX_KEYS keys, frames strictly increasing integers >= 0, all
 *            three fields required per key, rotations nonzero (stored normalised).
 * Every shape parameter is required; a key that does not belong to the collider's shape,
 * an unknown key anywhere, or a repeated key is an error (typos are caught).
 *
 * Errors: every failure returns a sinew_result and leaves a message that names the file,
 * the collider (its name and index) and the field, e.g.
 *   world.json: collider "ball" (#1): "radius": must be a positive finite number
 * PARSE for malformed JSON (with line:column), INVALID_ARGUMENT for missing or unknown
 * keys, wrong types and ranges, NOT_FINITE for numbers beyond float range (cJSON reads
 * 1e999 as infinity), DEGENERATE for a zero normal, zero quaternion, coplanar hull or
 * zero-area mesh triangle, IO for unreadable files, VERSION for another schema version,
 * UNSUPPORTED for a mesh collider when the text has no folder to resolve it against.
 * On error the output is zeroed and nothing leaks. */
#ifndef SW_WORLD_IO_H
#define SW_WORLD_IO_H

#include <stddef.h>
#include <stdint.h>

#include "sinew/sinew_world.h"
#include "sw_error.h"

#define SW_WORLD_SCHEMA_VERSION 1
#define SW_WORLD_MAX_FILE_BYTES ((size_t)256 << 20)
#define SW_WORLD_MAX_COLLIDERS 4096
#define SW_WORLD_MAX_HULL_POINTS 4096
#define SW_WORLD_MAX_KEYS 100000
#define SW_WORLD_NAME_MAX 64

/* One keyframe: the collider's rigid transform (collider frame -> world) on a clip frame. */
typedef struct sw_world_key {
    int32_t frame;
    double position[3];
    double rotation[4]; /* unit quaternion w, x, y, z */
} sw_world_key;

typedef struct sw_world_collider_spec {
    char name[SW_WORLD_NAME_MAX];
    /* Shape parameters, stiffness, friction, and transform = the motion at frame 0. Its
     * points / vertices / indices point into the arrays below. */
    sinew_collider_def def;
    float *points;      /* hull: 3 * def.point_count (owned) */
    float *vertices;    /* mesh: 3 * def.vertex_count (owned) */
    uint32_t *indices;  /* mesh: 3 * def.triangle_count (owned) */
    sw_world_key *keys; /* nkeys, frames strictly increasing; NULL when not moving */
    int32_t nkeys;
} sw_world_collider_spec;

typedef struct sw_world_file {
    char path[1024]; /* the name used in messages (the path for sw_world_file_read) */
    sw_world_collider_spec *colliders;
    int32_t ncolliders;
    int32_t frames; /* the "frames" entry, -1 if absent */
    int rest_pose;  /* "pose": "rest" */
} sw_world_file;

/* Reads a world file (at most SW_WORLD_MAX_FILE_BYTES); mesh paths are relative to its
 * folder. */
sinew_result sw_world_file_read(const char *path, sw_world_file *out, sw_error *err);

/* Parses `len` bytes of JSON (no NUL needed). `base_dir` resolves mesh paths; NULL
 * rejects mesh colliders (UNSUPPORTED). `name_for_errors` names the text in messages
 * (NULL: "<world>"). The fuzz harness's entry. */
sinew_result sw_world_file_parse(const char *text, size_t len, const char *base_dir,
                                 const char *name_for_errors, sw_world_file *out, sw_error *err);

/* Frees every owned array and zeroes the struct; a zeroed struct is a no-op. */
void sw_world_file_free(sw_world_file *w);

/* The rigid transform of a collider at (fractional) frame f: positions interpolated
 * linearly, rotations by slerp along the shorter arc (normalised), held before the first
 * key and after the last; no keys means the identity. A NaN frame gives the first key. */
void sw_world_collider_at(const sw_world_collider_spec *c, double frame, sinew_transform *out);

/* The largest key frame over all colliders; 0 when none moves. */
int32_t sw_world_file_last_key_frame(const sw_world_file *w);

#endif
