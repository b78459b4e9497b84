/* The subspace map of the step (thesis §4.4.1, eq. 4.13): a vertex copy k of domain d
 * sits at  x_k = R_k (rest_k + U_k q_d) + t_k,  with (R_k, t_k) the dual-quaternion
 * skinning transform of its vertex and U_k its rows of the domain's basis. Only the
 * "active" vertices are skinned each step: cubature tet corners, boundary surface copies,
 * render node copies (a blob with a render mesh) and pose-space contact vertices, so the cost
 * follows those counts, not the mesh.
 *
 * sw_reduced is what every reduced evaluation (cubature, contact, potential) reads and
 * accumulates into; the instance owns its arrays (one memory plan, instance.c), except
 * the active vertices' tables, which are the blob's (blob_active.h). */
#ifndef SW_REDUCED_MAP_H
#define SW_REDUCED_MAP_H

#include <stdint.h>

#include "blob_active.h"
#include "blob_view.h"
#include "dqs.h"
#include "mem_plan.h"
#include "sinew/sinew_types.h"

typedef struct sw_reduced {
    const sw_blob_view *v;
    int32_t R;    /* rank_total: the length of q */
    int32_t rmax; /* the largest domain rank */
    /* The active vertices and where each reference finds its own: the blob's tables
     * (blob_active.h, shared by its instances), bound by sw_reduced_bind_active. */
    int32_t nact;      /* active vertices */
    int32_t nact_step; /* the first nact_step: those every step reads */
    const int32_t *act_vert;
    /* The rest, surface copies only, are skinned only when read: with a world attached or
     * (no render mesh) as the output. */
    int skin_surface;
    const int32_t *cub_act;
    int32_t ncorner;
    const int32_t *corner_begin, *corner_lv, *corner_act, *cub_corner;
    const int32_t *copy_act, *contact_act, *node_copy_act;
    double *corner_x, *corner_f; /* 3 ncorner: a pass's positions and summed forces */
    double *act_R, *act_t;       /* 9 and 3 per active vertex: its skinning transform */
    double *g;                   /* R: gradient accumulator */
    double *H;                   /* R x R: Hessian accumulator */
    /* ndomains^2: the domain blocks of H that may be nonzero; H is exact zeros in every
     * other block, so that the Hessian starts from the springs' by copying their blocks
     * and clearing those marked (sw_reduced_blocks_copy) instead of all R^2 entries.
     * Diagonal blocks always may be. Whatever adds to an off-diagonal block marks it
     * (sw_reduced_mark). spring_adj: the springs' off-diagonal blocks (sw_solver.blk_adj). */
    unsigned char *H_nz;
    const unsigned char *spring_adj;
    /* Scratch of each task worker w < nworkers (one without task callbacks): */
    double *hm;       /* 10 x rmax at hm + 10 rmax w: its J^T f and J^T g_k (cubature.c) */
    double *ecub;     /* ncub: each cubature tet's weighted energy */
    int32_t nworkers; /* the task workers' count, 1 when serial */
    const sinew_task_callbacks *tasks; /* the host's job system, NULL: serial */
    double *Jc, *hc;                   /* 4 x 3 x rmax each: one contact's Jacobians and N G */
    double *svd_V;                     /* 9 per cubature tet: its last SVD rotation (warm start) */
    const sw_dualquat *bone_dq;        /* the pose of the last sw_reduced_skin */
    /* The cubature weights in use (ncub): the blob's, except while a condensation patch
     * holds some tets (0 there, the rest of their domain renormalised, condense.h). */
    const double *cub_w;
    /* The cubature Hessian's domain blocks that quasistatic steps start Newton on
     * (SW_CUB_HESSIAN_REF): the rest Hessian after a reset (sw_cubature_rest_hessian),
     * then those of the instance's last current-Hessian pass, which each such pass
     * refreshes (cubature.c). NULL where the instance never starts Newton on them. */
    double *h_ref;
} sw_reduced;

/* Lays out (or sizes: mem_plan.h) the map's accumulators: the gradient, each worker's
 * element-Hessian blocks, the Jacobians, and each cubature tet's SVD frame. */
void sw_reduced_take(sw_mem_plan *p, const sw_blob_view *v, int32_t rmax, int32_t nworkers,
                     sw_reduced *m);

/* Points m at the blob's active map a. */
void sw_reduced_bind_active(sw_reduced *m, const sw_active_map *a);

/* Skins the active vertices (the first nact_step, or all with skin_surface) with the
 * bones' dual quaternions (act_R, act_t), which m keeps (bone_dq) for vertices skinned on
 * demand. */
void sw_reduced_skin(sw_reduced *m, const sw_dualquat *bone_dq);

/* Position x of copy (domain D, local vertex lv, active index a) for the domain's
 * reduced coordinates qd (NULL: q = 0), and its Jacobian J = R U (3 x r_d, row-major)
 * when J is not NULL. */
void sw_reduced_position(const sw_reduced *m, const sw_blob_domain *D, int32_t lv, int32_t a,
                         const double *qd, double x[3], double *J);
/* Two copies of domain D at once (local vertices lv[0], lv[1], active indices a[0], a[1];
 * qd not NULL), bitwise as two calls of sw_reduced_position: each row still sums in its
 * own order, six sums side by side where one call runs three, so that the adds' latency
 * overlaps (the cubature passes place every corner this way, cubature.c). */
void sw_reduced_position_pair(const sw_reduced *m, const sw_blob_domain *D, const int32_t lv[2],
                              const int32_t a[2], const double *qd, double x0[3], double x1[3]);

/* An R x R reduced matrix read by domain blocks: a dense row-major one (dense not NULL), or
 * else the blob's constant matrix blob_matrix (SW_BLOB_MASS or SW_BLOB_SPRINGS, which may
 * store only its nonzero blocks: sw_blob_block). */
typedef struct sw_block_src {
    const double *dense;
    int blob_matrix;
} sw_block_src;
#define SW_DENSE_BLOCKS(A) ((sw_block_src){(A), 0})
#define SW_BLOB_BLOCKS(m) ((sw_block_src){NULL, (m)})

/* dst := src for R x R matrices known to be exact zeros outside their domain blocks marked
 * in dst_nz and src_nz (ndomains^2 each; diagonal blocks always count as marked): the
 * blocks src_nz marks are copied (cleared where the blob stores none), those dst_nz alone
 * marks cleared, and dst_nz := src_nz. Bitwise a full copy, at the cost of the marked
 * blocks. */
void sw_reduced_blocks_copy(const sw_blob_view *v, double *dst, unsigned char *dst_nz,
                            sw_block_src src, const unsigned char *src_nz);

/* y = A x for an R x R matrix A known to be exact zeros outside its domain blocks marked
 * in A_nz (diagonal blocks always count as marked; A_nz NULL: block diagonal) and those a
 * blob does not store: each row sums its terms in column order over those blocks alone.
 * The terms skipped are exact zeros times finite entries, so the result is bitwise the
 * dense product's (sw_matvec), at the cost of the marked blocks. */
void sw_reduced_blocks_matvec(const sw_blob_view *v, sw_block_src A, const unsigned char *A_nz,
                              const double *x, double *y);

/* Marks the blocks (a, b) and (b, a) of the Hessian as possibly nonzero (H_nz). */
static inline void sw_reduced_mark(sw_reduced *m, const sw_blob_domain *a,
                                   const sw_blob_domain *b) {
    int32_t nd = m->v->ndomains, ia = (int32_t)(a - m->v->domains),
            ib = (int32_t)(b - m->v->domains);
    m->H_nz[ia * nd + ib] = m->H_nz[ib * nd + ia] = 1;
}

/* That copy's Jacobian J = R U alone (3 x r_d, row-major). */
void sw_reduced_jacobian(const sw_reduced *m, const sw_blob_domain *D, int32_t lv, int32_t a,
                         double *J);

#endif
