/* Self-contact nobody trained (DESIGN.md §4.4-4.6; the detection of thesis §3.3.1 with
 * the condensed region of §4.3-4.5): the pose-space pairs hold the contact the bake's
 * training poses had; where two parts of the body meet that no training pose pressed
 * together (a fist past its sweeps, a forelimb against the chest), nothing does. This
 * detection finds such contact at a cost that follows what is near, not the mesh:
 *  - broad: the output surface's clusters (world_contact.h, median splits of each
 *    domain's surface copies) with their boxes from the last step's output carried by the
 *    bones' motion since, taken in bone 0's frame (so that no heading changes them); a
 *    sweep along that frame's x over those boxes gives the pairs of clusters of
 *    different domains that overlap. Clusters that are neighbours in the rest pose (their
 *    rest boxes within the reach of the reference's neighbour rule: one stretch of skin
 *    across a joint) overlap whenever the joint bends; the skin folding there is the
 *    joint's own, which the training held as far as it bent the joint, so such pairs are
 *    tested only while a joint bends beyond the training (where the neighbour rule, per
 *    vertex, tells the skin folding from a contact).
 *  - narrow: each copy of one cluster inside the other's box, at the step's start state,
 *    is tested with the reference's rule (self_detect.h) against the tets of the other
 *    cluster's layer (the tets incident to its surface vertices), their boxes first.
 * A vertex the pose-space pairs in use already hold is not novel. The contacts found
 * become the pairs in use of the detection's pair list (self_contact.h), evaluated in
 * the subspace, or, where a condensation patch covers them, at the patch's positions
 * (condense.h); they seed that patch. Allocation-free after creation. */
#ifndef SW_NOVEL_CONTACT_H
#define SW_NOVEL_CONTACT_H

#include <stdint.h>

#include "mem_plan.h"
#include "pose_space.h"
#include "self_contact.h"
#include "world_contact.h"

/* The novel contacts one step keeps at most (the deepest win). */
#define SW_NOVEL_MAX_CONTACTS 512

typedef struct sw_novel {
    int32_t ncl;         /* the surface clusters (those of wc) */
    double frame[12];    /* bone 0's pose this step: the frame the boxes are taken in */
    int32_t *cl_dom;     /* ncl: each cluster's domain */
    double *cl_now;      /* 6 ncl: this step's broad-phase boxes */
    double *cl_grow;     /* ncl: their growth past the carried last output (-1: mapped) */
    int32_t *order;      /* ncl: the clusters sorted by their box's low x (kept between
                            steps, so the insertion sort sees an order almost sorted) */
    int32_t *layer_ptr;  /* ncl + 1 */
    int32_t *layer_tets; /* the tets incident to each cluster's surface vertices */
    int32_t max_layer;   /* the largest layer */
    double *layer_box;   /* 6 per layer tet: its box this step (when cl_boxed says so) */
    int32_t *cl_boxed;   /* ncl: the stamp of the step its layer's boxes were taken */
    double *cl_rest;     /* 6 ncl: its rest box grown by half the neighbour rule's reach */
    int32_t *cand;       /* max_layer: one vertex's candidate tets (scratch) */
    int32_t *held;       /* nverts: stamp of the vertices a pose-space pair in use holds */
    int32_t *best;       /* nverts: stamp of the vertex's contact in hits */
    int32_t *best_i;     /* nverts: that contact's index */
    int32_t stamp;
    sw_self_hit *hits; /* SW_NOVEL_MAX_CONTACTS */
    int32_t nhits;
    int32_t dropped;       /* contacts the budget left out */
    int32_t cluster_pairs; /* pairs the broad phase passed on */
    int64_t tests;         /* candidate tets tested by barycentrics */
} sw_novel;

/* Lays out the arrays for blob v (its tet mesh) in p; ncl the clusters' bound. */
void sw_novel_take(sw_mem_plan *p, const sw_blob_view *v, int32_t ncl, sw_novel *nv);

/* Creation: the clusters' domains, layers and rest boxes (wc built, sc built; sc's tet
 * stamps are borrowed and left cleared). */
void sw_novel_build(sw_novel *nv, const sw_blob_view *v, const sw_world_contacts *wc,
                    sw_self_contacts *sc);

/* Detects the novel contacts at the state q of the pose red was skinned with, the cluster
 * boxes of the last output (wc->cl_box) grown by the bones' motion since (T_last: the
 * last output's pose, NULL when there is none: every box is taken at q), and makes them
 * sc's pairs in use (weight and tangential share 1). ps: the pose-space pairs in use;
 * near: test the rest neighbours too (a joint bends beyond the training). Returns how
 * many. */
int32_t sw_novel_detect(sw_novel *nv, sw_self_contacts *sc, sw_world_contacts *wc,
                        const sw_reduced *red, const double *q, const sw_pose_space *ps,
                        const double *T, const double *T_last, int near);

#endif
