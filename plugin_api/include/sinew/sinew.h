/* sinew — the functions of the stable C ABI an engine links against (the types are in
 * sinew_types.h, the conventions at its top). */
#ifndef SINEW_H
#define SINEW_H

#include "sinew_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Loads and validates a blob from def->path (mapped read-only) or from def->data /
 * def->data_size (used in place: at least 8-byte aligned, 64 recommended, and it must
 * outlive the blob). Every offset, count, index and value is checked first; a
 * truncated, damaged or hostile blob gives SINEW_ERROR_CORRUPT (or _VERSION,
 * _NOT_FINITE), logged with a message naming the section, never a crash. *out is written
 * only on SINEW_OK. Reads only the def fields its struct_size covers. Allocates one small
 * struct through def->allocator. Thread-safe (no shared state). */
SINEW_API sinew_result sinew_blob_load(const sinew_blob_def *def, sinew_blob **out);

/** Unmaps and frees a blob (NULL is allowed). No instance of it may still exist. */
SINEW_API void sinew_blob_destroy(sinew_blob *blob);

/** Number of skeleton bones the blob expects in a pose (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_bone_count(const sinew_blob *blob);

/** Number of output surface vertices (0 for NULL): the render mesh's when the blob embeds
 * one (in its own vertex order), else the simulation mesh's boundary's. Thread-safe. */
SINEW_API uint32_t sinew_blob_surface_vertex_count(const sinew_blob *blob);

/** Number of output surface triangles (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_surface_triangle_count(const sinew_blob *blob);

/** Copies the output surface's triangles, 3 vertex indices each, into `indices`, which
 * holds `capacity` uint32_t (at least 3 * sinew_blob_surface_triangle_count, else
 * SINEW_ERROR_CAPACITY and nothing written). Thread-safe. */
SINEW_API sinew_result sinew_blob_surface_triangles(const sinew_blob *blob, uint32_t *indices,
                                                    uint32_t capacity);

/** The collision surface: the simulation mesh's boundary, closed, edge-manifold and
 * facing out, which another character collides with (a mesh collider of a shared world,
 * sinew_world.h). Without a render mesh it is the output surface; with one it is not (a
 * render mesh may be open, split at seams or self-intersecting). Its vertex and triangle
 * counts (0 for NULL). Thread-safe. */
SINEW_API uint32_t sinew_blob_collision_vertex_count(const sinew_blob *blob);
SINEW_API uint32_t sinew_blob_collision_triangle_count(const sinew_blob *blob);

/** Copies the collision surface's triangles (3 vertex indices each, counter-clockwise seen
 * from outside) into `indices` of `capacity` uint32_t (at least 3 *
 * sinew_blob_collision_triangle_count, else SINEW_ERROR_CAPACITY and nothing written).
 * Thread-safe. */
SINEW_API sinew_result sinew_blob_collision_triangles(const sinew_blob *blob, uint32_t *indices,
                                                      uint32_t capacity);

/** Name of bone `bone` (< sinew_blob_bone_count) as the bake imported it (a glTF joint's
 * node name; "bone N" when the source had none): zero-terminated, owned by the blob and
 * valid while it lives. NULL for a NULL blob, an out-of-range bone, or a blob baked without
 * the asset description (bake it again). Thread-safe. */
SINEW_API const char *sinew_blob_bone_name(const sinew_blob *blob, uint32_t bone);

/** The index of the first bone named exactly `name` (case-sensitive), or -1 when there is
 * none, the blob has no names, or an argument is NULL. Linear in the names' bytes; map a
 * skeleton once, at load. Thread-safe. */
SINEW_API int32_t sinew_blob_find_bone(const sinew_blob *blob, const char *name);

/** Writes bone `bone`'s parent bone into *parent (-1 for a root). Every blob has it.
 * INVALID_ARGUMENT for NULL or an out-of-range bone. Thread-safe. */
SINEW_API sinew_result sinew_blob_bone_parent(const sinew_blob *blob, uint32_t bone,
                                              int32_t *parent);

/** Writes bone `bone`'s bind-pose global transform into `bind` (12 doubles: 3x3 row-major,
 * then the translation; the asset's units after the bake's import, the frame the pose's
 * transforms map from). The pose transform of a bone at its bind pose is the identity; a
 * host's skinning matrix is its bone's global transform times the inverse of this.
 * INVALID_ARGUMENT for NULL or an out-of-range bone; UNSUPPORTED for a blob without the
 * asset description. Thread-safe. */
SINEW_API sinew_result sinew_blob_bone_bind(const sinew_blob *blob, uint32_t bone, double bind[12]);

/** Number of meshes of the source file as the bake imported it (assimp's aiScene mMeshes;
 * glTF: one a primitive), 0 for NULL or a blob without the asset description. Thread-safe. */
SINEW_API uint32_t sinew_blob_source_mesh_count(const sinew_blob *blob);

/** The output map: for each output vertex (sinew_blob_surface_vertex_count of them), the
 * source mesh and the vertex within it, into `pairs` (2 int32_t a vertex: mesh, vertex;
 * -1, -1 for a vertex with no source, such as the tet boundary's) which holds `capacity`
 * int32_t (at least 2 * the vertex count, else CAPACITY and nothing written). A host that
 * imports the asset itself copies output vertex i to its mesh's vertex. INVALID_ARGUMENT for
 * NULL; UNSUPPORTED for a blob without the asset description. Thread-safe. */
SINEW_API sinew_result sinew_blob_output_sources(const sinew_blob *blob, int32_t *pairs,
                                                 uint32_t capacity);

/** Fills *out (set out->struct_size first; fields it does not cover are not written) with
 * what the blob was baked from. UNSUPPORTED for a blob without the asset description (then
 * nothing is known: bake it again); INVALID_ARGUMENT for NULL or a struct_size below 8.
 * Thread-safe. */
SINEW_API sinew_result sinew_blob_get_provenance(const sinew_blob *blob,
                                                 sinew_blob_provenance *out);

/** FNV-1a 64 of `size` bytes: what sinew_blob_provenance.source_hash holds for the source
 * asset's file. Hash the file as shipped and compare to force a re-bake when it changed.
 * 0 for NULL data with a nonzero size. Thread-safe. */
SINEW_API uint64_t sinew_hash_bytes(const void *data, size_t size);

/** Creates an instance of `blob` (which must outlive it), reserving all the memory it
 * will ever use in one block through the def's allocator (or the blob's): see
 * sinew_instance_memory_size. The instance starts at rest in the rest pose. A bad def
 * is INVALID_ARGUMENT, logged through the def's logger (or
 * the blob's). Thread-safety: any thread; instances of one blob are independent. */
SINEW_API sinew_result sinew_instance_create(const sinew_blob *blob, const sinew_instance_def *def,
                                             sinew_instance **out);

/** The bytes sinew_instance_create reserves for an instance of `blob` under `def` (NULL:
 * the defaults), into *bytes: one aligned block holding the instance, its state and
 * all its step scratch (a layout computed from the blob and the def's budgets). Never
 * allocates. Thread-safe. */
SINEW_API sinew_result sinew_instance_memory_size(const sinew_blob *blob,
                                                  const sinew_instance_def *def, size_t *bytes);

/** Releases an instance (NULL is allowed). */
SINEW_API void sinew_instance_destroy(sinew_instance *inst);

/** Back to rest: zero correction and velocity, rest pose, no pose history. */
SINEW_API sinew_result sinew_instance_reset(sinew_instance *inst);

/** Sets the pose for the next step: `bone_count` transforms (12 floats each: the 3x3
 * part row-major, then the translation) mapping the bind pose into the actor's frame
 * (sinew_instance_set_actor; without one, the world). Each 3x3 part is a rotation times
 * one uniform scale s shared by every bone (an engine's actor scale): the flesh is then
 * the rest-size character's, scaled by s. A non-finite transform is NOT_FINITE; a
 * sheared or mirrored one, a bone scaled unlike bone 0 (squash and stretch of single
 * bones is not simulated), a scale outside [1e-6, 1e6], or a scale with a collision
 * world attached is INVALID_ARGUMENT, logged naming the bone (SINEW_MSG_INSTANCE_POSE);
 * the previous pose is kept. Never allocates or locks. */
SINEW_API sinew_result sinew_instance_set_pose(sinew_instance *inst, const float *transforms,
                                               uint32_t bone_count);

/** Places the actor: `transform` (12 doubles: a rotation times a uniform scale, row-major,
 * then the translation) maps the actor's frame, which the pose's bones and the surface
 * sinew_instance_read_surface gives are in, to the world, which the collision world and
 * the inertial forces are in. Doubles, so an actor 10^5 units from the origin keeps its
 * shape to rounding: hand the bones in relative to the actor (an engine's component
 * space) and draw the surface with the actor's matrix. Default: the identity. Where the
 * actor stands and faces does not change the flesh; how it moves does (dynamic mode:
 * its acceleration). Errors as sinew_instance_set_pose; takes effect at once for the
 * pose already set. Never allocates or locks. */
SINEW_API sinew_result sinew_instance_set_actor(sinew_instance *inst, const double transform[12]);

/** Declares the pose of the next step discontinuous with the last step's: a camera cut, a
 * respawn, a switch to another animation, a ragdoll hand-off. The next step treats it as
 * a pose jump whatever its size (SINEW_STEP_TELEPORT, sinew_types.h): no velocity and no
 * inertia are taken from it. Steps detect large jumps on their own; this is for a change
 * the host knows is a cut but that looks like motion (5 degrees in 1/60 s is a joint
 * spinning at 5 rad/s). Call it before or after sinew_instance_set_pose; it holds until
 * the next step that runs (or a reset). Never allocates or locks. */
SINEW_API sinew_result sinew_instance_mark_teleport(sinew_instance *inst);

/** Advances the instance by dt seconds (0 < dt <= 1) to the current pose: quasistatic
 * or dynamic per the instance def. dt = 0 is a paused frame: SINEW_OK, nothing changes
 * (state, surface, pose history), the stats read zero with no flag; the pose set stays
 * for the next step that runs. Never allocates, locks or blocks; its cost depends
 * on the blob's cubature and surface sizes, not on the tet count. A non-finite result
 * (a non-finite solve, or an output surface beyond float range) is undone and reported
 * as SINEW_ERROR_NOT_FINITE with SINEW_STEP_FAILED: the reduced state goes back to the
 * step's start with no velocity, the surface is that state's at the current pose, and
 * the pose counts as the last one for the next step's jump test. INVALID_ARGUMENT for an
 * instance with a shared workspace (def.shared_workspace: sinew_instance_step_in). */
SINEW_API sinew_result sinew_instance_step(sinew_instance *inst, float dt);

/** Creates a step workspace for instances of `blob` (which must outlive it): the scratch
 * a step computes afresh and no later call reads, reserved in one block through the
 * def's allocator (or the blob's), sized for instances of `def` (NULL: the default;
 * its max_patch_vertices decides whether patches fit). Instances created with
 * def.shared_workspace = 1 step in it through sinew_instance_step_in; instances that
 * share one must never step at the same time (one workspace per worker thread; any
 * instance may step in any thread's workspace, with bitwise the same result). */
SINEW_API sinew_result sinew_workspace_create(const sinew_blob *blob, const sinew_instance_def *def,
                                              sinew_workspace **out);

/** The bytes sinew_workspace_create reserves for `blob` under `def` (NULL: the default). */
SINEW_API sinew_result sinew_workspace_memory_size(const sinew_blob *blob,
                                                   const sinew_instance_def *def, size_t *bytes);

/** Releases a workspace (NULL is allowed); no step may be using it. */
SINEW_API void sinew_workspace_destroy(sinew_workspace *ws);

/** sinew_instance_step in the workspace `ws` instead of the instance's own scratch (the
 * only way to step an instance created with def.shared_workspace = 1). INVALID_ARGUMENT
 * when `ws` was made for another blob, or without patches for an instance with them. */
SINEW_API sinew_result sinew_instance_step_in(sinew_instance *inst, sinew_workspace *ws, float dt);

/** The levels of detail `blob` holds: 3 when it has the pose-space level (sinew-bake
 * writes it), else 2 (SINEW_LOD_FULL and SINEW_LOD_REDUCED); 0 for NULL. */
SINEW_API uint32_t sinew_blob_lod_count(const sinew_blob *blob);

/** The level for a character covering `screen_fraction` of the screen's height (its
 * projected bounding-box height over the viewport's): SINEW_LOD_FULL from 0.25,
 * SINEW_LOD_REDUCED from 0.08, below that SINEW_LOD_POSE_SPACE (SINEW_LOD_REDUCED when
 * the blob lacks it). A NaN fraction gives SINEW_LOD_FULL. Thread-safe. */
SINEW_API sinew_lod sinew_lod_for_screen_size(const sinew_blob *blob, float screen_fraction);

/** Sets the level of detail of the next steps. The step at which the level changes shows
 * the old level's surface; the difference to the new one's, carried in bone 0's frame,
 * then fades as the character moves: each step by at most half the largest move the
 * surface makes in it, and over SINEW_LOD_BLEND_FRAMES steps at the fastest, so a change
 * moves no vertex by more than half of what the frame moves it anyway, and a character
 * standing still does not change; sinew_step_stats reports the level and the fade. Leaving
 * SINEW_LOD_POSE_SPACE starts the solve afresh from the pose-space start (no velocity: a
 * dynamic instance settles from there). INVALID_ARGUMENT for a level the blob does not hold
 * (sinew_blob_lod_count). Never allocates or locks. */
SINEW_API sinew_result sinew_instance_set_lod(sinew_instance *inst, sinew_lod level);

/** Copies the output surface of the last step into host buffers of `vertex_count`
 * (= sinew_blob_surface_vertex_count) xyz triples, in the actor's frame (the world's when
 * no actor transform was set); either buffer may be NULL. */
SINEW_API sinew_result sinew_instance_read_surface(const sinew_instance *inst, float *positions,
                                                   float *normals, uint32_t vertex_count);

/** Copies the collision surface (sinew_blob_collision_vertex_count xyz triples) of the last
 * step into `positions`, in the actor's frame as sinew_instance_read_surface: hand it to
 * sinew_world_set_mesh_vertices between frames, with the mesh collider placed at the
 * actor's transform, and the other characters see this one's flesh. A step solved at
 * SINEW_LOD_FULL or _REDUCED gives the solved boundary; before the first step (or after a
 * reset) and after a step at SINEW_LOD_POSE_SPACE it is the boundary skinned at the pose
 * (dual quaternions, no correction). A blob with a render mesh writes its boundary only
 * when asked (sinew_instance_def.collision_surface, or a world attached, or novel contact
 * on): otherwise INVALID_ARGUMENT, logged. Owner thread, after the step; never allocates. */
SINEW_API sinew_result sinew_instance_read_collision_surface(const sinew_instance *inst,
                                                             float *positions,
                                                             uint32_t vertex_count);

/** Figures of the last step; set out->struct_size first (fields it does not cover are
 * not written). */
SINEW_API sinew_result sinew_instance_get_stats(const sinew_instance *inst, sinew_step_stats *out);

/** Draws the last step's state through `draw`'s callbacks (sinew_debug_draw): with
 * SINEW_DEBUG_DRAW_CONTACTS each world contact in force (its point on the collider, a
 * point and a segment along its outward normal, SINEW_DEBUG_COLOR_WORLD_CONTACT: as many
 * as sinew_step_stats.world_contacts) and each self-contact pair in use (the vertex and
 * the triangle's normal there, SINEW_DEBUG_COLOR_SELF_CONTACT); _PATCH the condensation
 * patch's vertices (points) and its tets' faces (triangles); _COLLIDERS each collider of
 * the attached world as its oriented box (12 lines; a plane as a square around the actor);
 * _BONES each bone as a line from its parent's joint to its own (a blob without the asset
 * description: a point per bone). Call it after a step and before the next set_pose or
 * set_actor, on the instance's owner thread, outside the step. Allocates nothing and takes
 * no lock; an instance never drawn pays nothing. INVALID_ARGUMENT for NULL. */
SINEW_API sinew_result sinew_instance_debug_draw(const sinew_instance *inst,
                                                 const sinew_debug_draw *draw);

/** Opens a recorder on def->path (created or truncated), allocating its buffer through
 * def->allocator. I/O happens here (the file's preamble), in sinew_recorder_flush and
 * sinew_recorder_close, in sinew_instance_set_recorder and sinew_instance_set_world (the
 * instance's configuration, the world's colliders), and in a recorded call whose record no
 * longer fits the buffer (one write(2) of the buffer: keep it out of the step by flushing
 * between frames). IO when the file cannot be created. Any thread. */
SINEW_API sinew_result sinew_recorder_open(const sinew_recorder_def *def, sinew_recorder **out);

/** Writes the buffered records to the file (one checksummed chunk). IO when a write failed
 * (then or earlier: the first failure is kept and every later call returns it). The owner
 * thread of the instance it records. */
SINEW_API sinew_result sinew_recorder_flush(sinew_recorder *rec);

/** Ends the recording (an end record, a flush), closes the file and frees the recorder;
 * detach it from its instance first (sinew_instance_set_recorder(inst, NULL)) or destroy the
 * instance. Returns the first I/O error of the recording, if any (NULL: OK). */
SINEW_API sinew_result sinew_recorder_close(sinew_recorder *rec);

/** Attaches a recorder to an instance (NULL detaches): from now on every call the instance
 * receives (set_actor, set_pose, mark_teleport, reset, set_world with its colliders, step
 * with dt, the world's collider transforms at the step and a hash of the output surface
 * after it) is appended to the recording, with the blob's FNV-1a 64 hash and the instance's
 * def at its start. Attach right after sinew_instance_create (a world may be attached
 * before): an instance that has been posed, placed or stepped is refused with
 * INVALID_ARGUMENT (SINEW_MSG_RECORDER_REFUSED), as is a recorder already attached to
 * another. A recorded step allocates nothing and takes no lock; it hashes the surface
 * (O(surface)). Owner thread of the instance; never while it steps. */
SINEW_API sinew_result sinew_instance_set_recorder(sinew_instance *inst, sinew_recorder *rec);

#ifdef __cplusplus
}
#endif
#endif /* SINEW_H */
