/* sinew-bench's baseline: plain dual-quaternion skinning of the blob's output surface
 * (positions and area-weighted normals over its own triangles; the render mesh's own
 * vertices when the blob embeds one), the cost a host pays today. Each output vertex
 * reads its rest position and 4 influences: a boundary vertex is a simulation vertex with
 * its own; a render vertex takes its embedding's rest position and the influences of the
 * simulation vertex it weighs most (the blob keeps no render-vertex weights; the cost is a
 * 4-influence blend a vertex either way). */
#ifndef SW_DQS_BENCH_H
#define SW_DQS_BENCH_H

#include "blob_view.h"
#include "sw_mesh.h"

/* The median ms a frame over the clip's first `frames` poses, each frame's least time over
 * `passes` plays of them (1: one play); -1 when out of memory. */
double sw_dqs_bench_ms(const sw_blob_view *v, const sw_clip *clip, int frames, int passes);

#endif
