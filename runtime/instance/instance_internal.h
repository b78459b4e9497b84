/* The instance: its state, the subsystems' views of its memory, and its last step's
 * figures. Private to runtime/instance (the phases are in step.c). */
#ifndef SW_INSTANCE_INTERNAL_H
#define SW_INSTANCE_INTERNAL_H

#include "blob_load.h"
#include "inertia.h"
#include "pose_space.h"
#include "reduced_map.h"
#include "solver.h"
#include "world_contact.h"

struct sinew_instance {
    const sw_blob_view *v;
    sinew_allocator allocator; /* frees the block */
    sinew_step_mode mode;
    double size;             /* rest bounding-box diagonal */
    sw_dualquat *bone_dq;    /* nbones: the current pose */
    sw_pose_history pose;    /* the current pose and the two before */
    sw_reduced red;          /* the subspace map and the evaluation accumulators */
    sw_pose_space ps;        /* training poses near the current one, contact pairs */
    sw_solver solver;        /* state and Newton */
    sw_world_contacts wc;    /* the collision world's candidates of the step */
    double *surf_x, *surf_n; /* 3 per output surface vertex each */
    sinew_step_stats stats;
};

/* The output surface (positions and normals) of the state q (output.c). */
void sw_instance_write_surface(sinew_instance *in);

#endif
