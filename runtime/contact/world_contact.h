/* Contact of the flesh with the collision world inside the step (DESIGN.md §4.5, thesis
 * §3.3.1 with a collider's surface as the contact surface): the output surface's vertex
 * copies against the world's colliders, with the penalty and friction of
 * world_penalty.h in the reduced Newton.
 *
 * Detection is two-phase and its cost follows the copies near colliders, not the mesh:
 *  - broad: the surface copies are grouped, when the blob loads, into clusters of at most
 *    SW_WORLD_CLUSTER copies (median splits of each domain's copies in rest space;
 *    blob_clusters.h). Each cluster's box is taken from the last step's output, carried
 *    by its dominant bone's motion since and grown by how far the other bones that skin
 *    it move apart from it, plus the detection radius; only clusters whose grown box
 *    meets a collider's box go on.
 *  - narrow: each copy of those clusters, at the step's start state, is queried against
 *    each collider whose box holds it (collision.h); a copy within the detection radius
 *    becomes a candidate with its frozen law (world_penalty.h).
 * Without a valid last output (the first step, after a reset or a teleport) every
 * cluster goes to the narrow phase once. */
#ifndef SW_WORLD_CONTACT_H
#define SW_WORLD_CONTACT_H

#include <stdint.h>

#include "blob_clusters.h"
#include "mem_plan.h"
#include "reduced_map.h"
#include "sinew/sinew_world.h"
#include "world_penalty.h"

/* One (surface copy, collider) candidate of the step. */
typedef struct sw_world_cand {
    sw_world_pair law;
    int32_t copy; /* surface copy index */
    int32_t slot; /* the collider's slot */
    sinew_collider_id id;
    int32_t active; /* in contact (gap > 0) at the step's solution */
    int32_t next;   /* the copy's next candidate (another collider), or -1 */
    int32_t patch;  /* the copy's vertex's index in a condensation patch, or -1 */
    double f[3];    /* force on the vertex copy at the solution */
} sw_world_cand;

typedef struct sw_world_contacts {
    const sinew_world *world;
    sinew_collider_id ignore; /* a collider the instance never touches (its own surface), or 0 */
    int32_t max_cand, ncand, dropped;
    sw_world_cand *cand; /* max_cand */
    /* the blob's clusters (blob_clusters.h), bound by sw_world_contacts_build */
    int32_t ncl;
    const int32_t *cl_begin, *cl_copy, *cl_bone0;
    const uint64_t *cl_bones;
    const double *copy_area, *dom_umax;
    double *cl_box;           /* 6 per cluster: its copies' box at the last output */
    int32_t *copy_first;      /* nsurf_copies: the copy's first candidate, or -1 */
    unsigned char *dom_moved; /* ndomains: moved by the radius since detection */
    double *q_detect;         /* R: the state of the last detection */
    double *bone_motion;      /* 12 per bone: each bone's motion since the last output */
    double *copy_x;           /* 3 per copy: positions at the last output */
    int32_t *cl_pass;         /* ncl: the clusters the last broad phase passed */
    int32_t npass;
    const double *patch_x; /* a condensation patch's vertex positions (NULL: none), where
                              the candidates with patch >= 0 are (condense.h) */
    int boxes_valid;       /* cl_box holds the last output */
    double radius;         /* detection radius (world units) */
    /* The step's frame in the world (12: R row-major, t; the instance's, pose.c), or NULL
     * for the world's own: positions here (copies, laws, boxes) are in it, the colliders
     * in the world; a query's answer comes back snapped to `grid` (sw_pose_grid), as the
     * pose is, so a world moved with the character gives the step the same laws. */
    const double *frame;
    double grid;
    uint32_t queries; /* collider queries of the last detection */
} sw_world_contacts;

/* Lays out the candidate budget and the broad phase's per-cluster boxes (the clusters are
 * the blob's) and per-copy positions. */
void sw_world_contacts_take(sw_mem_plan *p, const sw_blob_view *v, int32_t ncl, int32_t max_world,
                            sw_world_contacts *wc);

/* Binds the blob's clusters cl and forgets every candidate (copy_first laid out by the
 * instance). Creation time; no allocation. */
void sw_world_contacts_build(sw_world_contacts *wc, const sw_blob_view *v,
                             const sw_surface_clusters *cl);

/* Forgets the candidates (O(candidates)). */
void sw_world_contacts_clear(sw_world_contacts *wc);

/* Candidates at the state q for the pose T (12 per bone) and the pose of the last output
 * T_last (NULL: no valid last output). Returns the candidates found; wc->dropped counts
 * those over the budget. */
int32_t sw_world_contacts_detect(sw_world_contacts *wc, const sw_reduced *red, const double *q,
                                 const double *T, const double *T_last);

/* Appends the copies that penetrate a collider at q without being candidates yet (a
 * second detection round after a solve), reading their positions at q from copy_x (the
 * output wrote them); returns how many were added. */
int32_t sw_world_contacts_add_missed(sw_world_contacts *wc, const sw_reduced *red, const double *q);

/* What sw_world_contacts_at does with a copy's candidates. */
typedef enum sw_wc_at_mode {
    SW_WC_AT_DETECT = 0, /* laws taken again at x (closest point, normal, friction cap), and
                            the colliders x is within the detection radius of added */
    SW_WC_AT_MISSED = 1, /* after a solve: only the colliders x entered are added, the laws
                            stay */
    SW_WC_AT_REPLANE = 2 /* within a solve: each law's plane turned to the collider's normal
                            at x's closest point, its anchor (the friction's stick point)
                            projected onto it, its friction cap from the normal force at
                            x; colliders within the radius added */
} sw_wc_at_mode;

/* Surface copy i sitting at x instead of its subspace position (a condensation patch's
 * vertex, condense.h): its candidates and laws as mode says. Returns how many were
 * added. */
int32_t sw_world_contacts_at(sw_world_contacts *wc, int32_t i, const double x[3], double blob_k,
                             sw_wc_at_mode mode);

/* The world contact energy at q of the candidates outside a condensation patch (those
 * in one are the patch's, condense.h); with want_grad its gradient into red->g, with
 * want_hess its (domain-diagonal) Hessian blocks into red->H. */
double sw_world_contact_eval(sw_reduced *red, const sw_world_contacts *wc, const double *q,
                             int want_grad, int want_hess);

/* Records each candidate's force and activity at the solution q (the readback), a patch
 * candidate's at its patch position. */
void sw_world_contacts_finish(sw_world_contacts *wc, sw_reduced *red, const double *q);

/* The broad phase's pieces, shared with the novel self-contact's (novel_contact.h): each
 * bone's rigid motion from the pose T0 (the last output's) to T, into wc->bone_motion;
 * cluster c's box at the last output carried by its dominant bone's motion and grown by
 * the other bones' and the detection radius; returns that growth (a copy of c lies
 * within it of where the dominant bone's motion carries its last output position). */
void sw_world_clusters_motion(sw_world_contacts *wc, int32_t nbones, const double *T,
                              const double *T0);
double sw_world_cluster_box(const sw_world_contacts *wc, const sw_blob_view *v, int32_t c,
                            double box[6]);
/* That growth alone, for cluster c's points within rho of ctr at the last output (world
 * units; a ball, so the growth does not depend on the axes the box is taken on). */
double sw_world_cluster_spread(const sw_world_contacts *wc, const sw_blob_view *v, int32_t c,
                               const double ctr[3], double rho);

/* Takes the cluster boxes from the copies' output positions wc->copy_x. */
void sw_world_contacts_update_boxes(sw_world_contacts *wc);

#endif
