/* Building a simulation character (sw_character) from real asset files. */
#ifndef SW_CHARACTER_IO_H
#define SW_CHARACTER_IO_H

#include "clip_io.h"
#include "rig.h"
#include "sw_mesh.h"
#include "mesher.h"

/* A clip that slerps every bone from identity to the pose given as one quaternion per
 * bone (x, y, z, w; libigl hand-pose.dmat) over `nframes` and back. */
sinew_result sw_clip_from_pose_quats(const sw_skeleton *s, const double *quats, int32_t nframes,
                                     double fps, sw_clip *out, sw_error *err);

/* Whole character from files: tet mesh (.mesh/.node/.ele), .tgf skeleton, optional
 * .dmat weights (NULL: inverse-distance weights), optional motion (NULL: a clip of
 * identity frames). `motion` may be a complementary-dynamics anim .txt or a pose
 * .dmat of quaternions. */
sinew_result sw_character_from_files(const char *mesh_path, const char *tgf_path,
                                     const char *weights_path, const char *motion_path,
                                     int32_t nframes, sw_character *out, sw_error *err);

/* Each joint's range of motion from a file (sw_character.range): a .dmat pose (one
 * quaternion per bone, as sw_character_from_files takes it) or a .txt bone animation,
 * read against ch->skel and kept in ch->range (replacing any range before). Errors name
 * the file; ch is unchanged then. */
sinew_result sw_character_read_range(const char *path, sw_character *ch, sw_error *err);

/* A character from a render surface (.obj; it need not be closed for the lattice) filled
 * with about target_tets tets by `mesher` (mesher.h; report may be NULL), a .tgf
 * skeleton and optional motion as in sw_character_from_files; inverse-distance weights
 * (a caller may compute heat-diffusion weights instead, as sinew-bake does). out->render
 * is the surface itself: a bake embeds it and the blob outputs it. */
sinew_result sw_character_from_surface(const char *obj_path, int32_t target_tets, sw_mesher mesher,
                                       const char *tgf_path, const char *motion_path,
                                       int32_t nframes, sw_character *out, sw_mesher_report *report,
                                       sw_error *err);

/* The file's name without folder and extension, cut to cap - 1 bytes: a character's name. */
void sw_file_stem(const char *path, char *name, size_t cap);

/* The real assets of ../shared/data by folder name ("elephant-cd", "hand-libigl"):
 * resolves file names under data_dir and calls sw_character_from_files with the
 * asset's material (SOURCE.md / json). */
sinew_result sw_character_from_dataset(const char *data_dir, const char *name, int32_t nframes,
                                       sw_character *out, sw_error *err);
#endif
