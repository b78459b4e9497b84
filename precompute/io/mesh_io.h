/* Readers and writers of mesh, skeleton, weight and motion files, surface extraction
 * and the element quality report.
 *
 * Every reader validates as it parses and rejects malformed input with
 * SINEW_ERROR_PARSE (or NOT_FINITE / DEGENERATE / IO) and a message of the form
 * "path:line: what is wrong": truncated files, wrong counts, out-of-range indices,
 * 0/1-based confusion, NaN coordinates, zero-volume tets. On error the output struct
 * is left zeroed and nothing leaks.
 *
 * Every reader has a from-memory twin, sw_parse_*, that reads `len` bytes of `text` (no
 * NUL needed; the bytes are copied) with the same rules and messages, naming the text
 * `name_for_errors` where the path would be (NULL: "<text>"). The fuzz harnesses of
 * tests/fuzz/ call these. */
#ifndef SW_MESH_IO_H
#define SW_MESH_IO_H

#include <stddef.h>

#include "sw_mesh.h"

/* Medit .mesh (1-based): Vertices and Tetrahedra blocks; other blocks skipped.
 * Negatively oriented tets are reoriented (two vertices swapped); zero-volume tets
 * are an error. */
sinew_result sw_read_medit(const char *path, sw_tetmesh *out, sw_error *err);
sinew_result sw_parse_medit(const char *text, size_t len, const char *name_for_errors,
                            sw_tetmesh *out, sw_error *err);
/* TetGen .node + .ele (0- or 1-based, as the .node's first index says). */
sinew_result sw_read_tetgen(const char *node_path, const char *ele_path, sw_tetmesh *out,
                            sw_error *err);
/* Names NULL: "<node>" and "<ele>". */
sinew_result sw_parse_tetgen(const char *node_text, size_t node_len, const char *node_name,
                             const char *ele_text, size_t ele_len, const char *ele_name,
                             sw_tetmesh *out, sw_error *err);
/* Dispatch on the extension: ".mesh" -> Medit; ".node" or ".ele" -> TetGen with the
 * sibling file of the same stem. */
sinew_result sw_read_tetmesh(const char *path, sw_tetmesh *out, sw_error *err);
sinew_result sw_write_medit(const char *path, const sw_tetmesh *m, sw_error *err);

/* Wavefront OBJ surface: v and f lines (polygons fan-triangulated, v/vt/vn and
 * negative indices accepted), other lines ignored. */
sinew_result sw_read_obj(const char *path, sw_trimesh *out, sw_error *err);
sinew_result sw_parse_obj(const char *text, size_t len, const char *name_for_errors,
                          sw_trimesh *out, sw_error *err);
sinew_result sw_write_obj(const char *path, int32_t nverts, const double *X, int32_t ntris,
                          const int32_t *tris, sw_error *err);
/* The same with vertex colours: sw_read_obj_colors gives the file's "v x y z r g b"
 * colours (3 per vertex, clamped to [0, 1], the caller frees them) in *colors, NULL when
 * not every vertex has one; sw_write_obj_colors writes C (3 per vertex) so, or none when
 * C is NULL (sinew-render colours a triangle by its corners' mean). */
sinew_result sw_read_obj_colors(const char *path, sw_trimesh *out, double **colors, sw_error *err);
sinew_result sw_write_obj_colors(const char *path, int32_t nverts, const double *X, const double *C,
                                 int32_t ntris, const int32_t *tris, sw_error *err);

/* libigl .tgf: joint lines "index x y z", a "#" separator, edge lines "a b [flags...]"
 * (1-based). Bones keep file order; parents are derived from shared joints. */
sinew_result sw_read_tgf(const char *path, sw_skeleton *out, sw_error *err);
sinew_result sw_parse_tgf(const char *text, size_t len, const char *name_for_errors,
                          sw_skeleton *out, sw_error *err);

/* libigl .dmat, ASCII ("cols rows" header, column-major values) or binary ("0 0"
 * header line followed by the binary one). Returns a row-major rows x cols array. */
sinew_result sw_read_dmat(const char *path, int32_t *rows, int32_t *cols, double **data,
                          sw_error *err);
sinew_result sw_parse_dmat(const char *text, size_t len, const char *name_for_errors, int32_t *rows,
                           int32_t *cols, double **data, sw_error *err);
sinew_result sw_write_dmat(const char *path, int32_t rows, int32_t cols, const double *data,
                           int binary, sw_error *err);

/* Skin weights from a .dmat with one row per vertex and one column per bone; rows
 * are checked (finite, >= 0 within 1e-6, not all zero) and normalised to sum 1. */
sinew_result sw_read_weights(const char *path, int32_t nverts, int32_t nbones, sw_weights *out,
                             sw_error *err);
sinew_result sw_parse_weights(const char *text, size_t len, const char *name_for_errors,
                              int32_t nverts, int32_t nbones, sw_weights *out, sw_error *err);

/* Boundary faces of a tet mesh (faces owned by exactly one tet), outward CCW. */
sinew_result sw_tetmesh_surface(const sw_tetmesh *m, sw_surface *out, sw_error *err);

typedef struct sw_quality {
    int32_t ntets;
    double min_dihedral_deg, max_dihedral_deg;
    double min_volume, max_volume; /* signed */
    int32_t degenerate;            /* |volume| <= eps * mean |volume| */
    int32_t inverted;              /* volume < 0 (and not degenerate) */
    int32_t slivers;               /* min dihedral below 5 degrees */
} sw_quality;

/* Element quality report; `eps` is relative to the mean volume (0 means 1e-12). */
void sw_tetmesh_quality(const sw_tetmesh *m, double eps, sw_quality *q);
#endif
