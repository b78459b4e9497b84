/* Building a simulation character (sw_character) from real asset files, and the
 * motion formats of ../shared/data. */
#ifndef SW_CHARACTER_IO_H
#define SW_CHARACTER_IO_H

#include "sw_mesh.h"

/* Complementary-dynamics bone animation (elephant-cd/elephant_anim.txt; format in its
 * SOURCE.md): per-frame Euler angles per bone -> per-frame bone transforms (rest ->
 * world) for skeleton `s`. */
sinew_result sw_read_cd_anim(const char *path, const sw_skeleton *s, double fps, sw_clip *out,
                             sw_error *err);

/* A clip that slerps every bone from identity to the pose given as one quaternion per
 * bone (x, y, z, w; libigl hand-pose.dmat) over `nframes` and back. */
sinew_result sw_clip_from_pose_quats(const sw_skeleton *s, const double *quats, int32_t nframes,
                                     double fps, sw_clip *out, sw_error *err);

/* Simple skin weights when an asset has none: inverse distance to bone segments
 * (w ~ 1/d^4), normalised. (The bake owns heat-diffusion weights.) */
sinew_result sw_weights_inverse_distance(const sw_tetmesh *m, const sw_skeleton *s, sw_weights *out,
                                         sw_error *err);

/* Chooses the vertices driven kinematically by each bone ("inside the bone"): those
 * close to the bone's segment relative to the flesh thickness around it, at least a
 * few per bone so the problem is never singular. Writes bone_of_vertex (nverts). */
sinew_result sw_select_bone_vertices(const sw_tetmesh *m, const sw_skeleton *s, const sw_weights *w,
                                     int32_t *bone_of_vertex, sw_error *err);

/* Whole character from files: tet mesh (.mesh/.node/.ele), .tgf skeleton, optional
 * .dmat weights (NULL: inverse-distance weights), optional motion (NULL: a clip of
 * identity frames). `motion` may be a complementary-dynamics anim .txt or a pose
 * .dmat of quaternions. */
sinew_result sw_character_from_files(const char *mesh_path, const char *tgf_path,
                                     const char *weights_path, const char *motion_path,
                                     int32_t nframes, sw_character *out, sw_error *err);

/* The real assets of ../shared/data by folder name ("elephant-cd", "hand-libigl"):
 * resolves file names under data_dir and calls sw_character_from_files with the
 * asset's material (SOURCE.md / json). */
sinew_result sw_character_from_dataset(const char *data_dir, const char *name, int32_t nframes,
                                       sw_character *out, sw_error *err);
#endif
