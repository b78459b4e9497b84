/* The viewer's characters: N sinew instances of one blob, each playing the clip at its own
 * phase, stepped on T threads. */
#ifndef SW_VIEWER_SIM_H
#define SW_VIEWER_SIM_H

#include <sinew/sinew.h>
#include <sinew/sinew_world.h>

#include "motion.h"
#include "viewer.h"

typedef struct vw_char {
    sinew_instance *inst;
    float *pose;      /* 12 nbones */
    float *pos, *nrm; /* sinew's surface */
    float *skin_pos, *skin_nrm;
    sinew_step_stats stats;
    sinew_result last;
    double phase;    /* seconds added to the clip time */
    vw_planar actor; /* where the actor stands (root motion, walking) */
    double last_t;   /* simulation time of the last step, or -1 */
} vw_char;

typedef struct vw_sim {
    const sinew_blob *blob;
    const vw_asset *asset;
    vw_motion motion;
    int threads, dynamic;
    const sinew_world *world; /* or NULL; set before vw_sim_create's instances */
    int rest_pose;            /* hold the rest pose (a world file's "pose": "rest") */
    int32_t n;
    vw_char *ch;
    double t;            /* clip time of the last step */
    sinew_recorder *rec; /* the first instance's recording, or NULL */
    const char *rec_path;
} vw_sim;

int vw_sim_create(vw_sim *s, const sinew_blob *blob, const vw_asset *a, const vw_motion *m,
                  int32_t n, int threads, int dynamic, const sinew_world *world, int rest_pose,
                  char *err, size_t errlen);
/* Records every call the first instance receives into path (sinew_recorder), for
 * sinew-replay: call it right after vw_sim_create, before any step. */
int vw_sim_record(vw_sim *s, const char *path, char *err, size_t errlen);
/* Writes the recording's buffered calls (between frames, outside the step). */
void vw_sim_flush(vw_sim *s);
/* Recreates the instances in the other step mode (instances are created in one mode); a
 * recording ends there (a recorder belongs to one instance). */
int vw_sim_set_mode(vw_sim *s, int dynamic, char *err, size_t errlen);
/* Advances every character to simulation time t by dt seconds (a jump back, or of more
 * than a quarter second, is a cut: the actor does not move across it). */
void vw_sim_step(vw_sim *s, double t, float dt);
void vw_sim_teleport(vw_sim *s);
/* Character i's actor frame to the world's, for a point drawn in it. */
void vw_sim_actor_point(const vw_sim *s, int32_t i, float p[3]);
/* Fills every character's skinned surface at its last pose. */
void vw_sim_skin(vw_sim *s, int dqs);
void vw_sim_destroy(vw_sim *s);

#endif
