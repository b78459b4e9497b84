/* Exhaustive subspace self-contact (the baseline of thesis Table 3.2's "exhaustive"
 * column): every surface vertex of the tet boundary tested against the whole deformed
 * mesh at each detection, with the reference's own rule (self_detect.h), and the pairs
 * found applied with the contact law of eqs. 3.4-3.6 (penalty.h) through the subspace
 * map, as the pose-space pairs are (pose_contact.h).
 *
 * Where the pose-space mode looks up the contact sets the bake trained, this one finds
 * what touches now, whatever the pose: motion the bake never saw gets the contacts the
 * reference would. Its cost follows the mesh, not the cubature: every vertex is skinned
 * and mapped (O(nverts r)), every tet's box refit and every surface vertex queried. An
 * instance opts in with sinew_instance_def.self_contact; the arrays below exist only
 * then (sinew_instance_memory_size counts them). Allocation-free and lock-free after
 * creation. */
#ifndef SW_SELF_CONTACT_H
#define SW_SELF_CONTACT_H

#include <stdint.h>

#include "mem_plan.h"
#include "pose_contact.h"
#include "reduced_map.h"
#include "self_detect.h"

typedef struct sw_self_contacts {
    sw_self_mesh m;    /* the blob's rest, tets and tet boundary (global vertex ids) */
    int32_t *tris;     /* 3 nsurf_tris: m.tris */
    int32_t *surf;     /* the boundary's vertices, ascending: m.surf */
    int32_t *home;     /* 2 nverts: the (domain, local) copy standing for each vertex, -1: none */
    double *x;         /* 3 nverts: every vertex at the state of the last detection */
    double *vR, *vt;   /* 9 and 3 nverts: every vertex's skinning transform */
    void *bvh_scratch; /* the trees' build scratch (creation only) */
    sw_contact *found; /* nsurf: the last detection's contacts */
    /* the pairs in use, in the pose-space pairs' form (pose_contact.h): per pair the
       (domain, local) copies of p, t0, t1, t2, then b0..b2, R_p^T n, ka, and the slots'
       vertex ids (their transforms in vR, vt) */
    int32_t *verts;  /* 8 nsurf */
    double *data;    /* 7 nsurf */
    int32_t *act;    /* 4 nsurf */
    double *w, *tan; /* nsurf: each pair's weight and tangential share (1 when detected) */
    int32_t npairs;  /* pairs in use (at most nsurf) */
    /* per pair in use: 1 when a condensation patch evaluates it at the patch's positions
       instead (condense.h); NULL: none does */
    const unsigned char *in_patch;
    int64_t tests; /* candidate tets the last detection tested */
    /* the pose-pairs re-test's (sw_self_contacts_retest): the detection each vertex and
       tet was last mapped or listed in (stamp), and the candidate tets of one pair */
    int32_t *vstamp; /* nverts */
    int32_t *tstamp; /* ntets */
    int32_t *cand;   /* SW_RETEST_CANDIDATES: one pair's candidate tets */
    int32_t stamp;
    sw_reduced map; /* the detection's map: red with the transforms indexed by vertex */
} sw_self_contacts;

/* The most tets a cubature vertex is tested against: those incident to its trained
 * triangle's corners (about 30 on the samples' meshes). */
#define SW_RETEST_CANDIDATES 1024

/* Lays out the arrays for blob v in p (v must hold its tet mesh). */
void sw_self_contacts_take(sw_mem_plan *p, const sw_blob_view *v, sw_self_contacts *sc);

/* Fills the rest measures, the home copies and both trees, once at creation. A blob
 * whose tet boundary has a triangle of zero rest area is refused (no contact point on it
 * is defined). */
sinew_result sw_self_contacts_build(sw_self_contacts *sc, const sw_blob_view *v, sw_error *err);

/* Detects the contacts of the state q at the pose red was skinned with (red->bone_dq) and
 * makes them the pairs in use. Returns how many pairs are new: their vertex had none in
 * the pairs in use before. */
int32_t sw_self_contacts_detect(sw_self_contacts *sc, const sw_reduced *red, const double *q);

/* The same restricted to pairs of domains: only vertices whose home domain a has a pair in
 * `mask` (ndomains^2, row a, column b) are tested, and a contact is kept when mask[a nd + b]
 * is set for its triangle's first corner's domain b (the pose-pairs mode's fallback on
 * novel contact, pair_space.c). */
int32_t sw_self_contacts_detect_pairs(sw_self_contacts *sc, const sw_reduced *red, const double *q,
                                      const unsigned char *mask);

/* Pose-pairs mode (thesis §3.3.1): each pair ps gathered, its cubature vertex p tested at
 * the state q against the tets around its trained triangle (those incident to the
 * triangle's corners) with the rule of self_detect.h. The thesis tests a cubature vertex
 * against the other domain's every tet, because on a fine mesh p "could easily penetrate
 * a nearby triangle instead" of the trained one; the ring holds those nearby triangles
 * without mapping and refitting the whole domain each step. A pair whose p entered one of
 * them becomes a pair in use (appended, at its gathered weight and tangential share) and
 * leaves ps; the others keep their trained triangle. Maps only the vertices it reads.
 * Returns how many pairs moved. */
int32_t sw_self_contacts_retest(sw_self_contacts *sc, const sw_reduced *red, const double *q,
                                sw_pose_space *ps);

/* The pieces of a detection that maps only what it reads (the re-test's, novel_contact.h):
 * a fresh stamp and the map of red's pose; vertex gv at the state q, mapped once a stamp
 * (its position, its skinning transform in vR, vt); a contact appended to the pairs in use
 * at weight w and tangential share tan (0 when the list is full). */
void sw_self_contacts_begin(sw_self_contacts *sc, const sw_reduced *red);
const double *sw_self_contacts_map(sw_self_contacts *sc, const double *q, int32_t gv);
int32_t sw_self_contacts_add(sw_self_contacts *sc, const sw_contact *c, double w, double tan);

/* Forgets the pairs in use. */
void sw_self_contacts_clear(sw_self_contacts *sc);

/* The pairs in use as pose_contact.h evaluates them. */
sw_pair_set sw_self_contacts_pairs(const sw_self_contacts *sc);

#endif
