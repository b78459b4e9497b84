/* Stage "reduce" (bake.c, sw_bake_stages): reads s->rig, s->domains, s->basis, s->cubature,
 * s->contacts; writes s->reduce and the view's reduced sections. */
/* The constant reduced matrices and the blob view (bake.h "reduce").
 *   springs (eqs. 4.17-4.20): a vertex in domains i and j has copies that skinning
 *     moves with the same (R_v, t_v), so its spring energy k/2 |U_i q_i - U_j q_j|^2
 *     is exactly quadratic in q with a constant Hessian, precomputed here;
 *   mass: U^T M U per domain with each copy's mass from its own domain's tets;
 *   inertia: the projections the runtime needs for the inertial forces of a domain
 *     riding its bone (blob_view.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "blob_write.h"
#include "fem_corot.h"
#include "mesh_io.h"
#include "vec3.h"

#define OWN(ptr, n, type)                                                                          \
    ((ptr) = sw_bake_own(out, calloc((size_t)(n) > 0 ? (size_t)(n) : 1, sizeof(type))))

/* Mean rest edge length over the tets' edges. */
static double mean_edge(const sw_tetmesh *m) {
    static const int e[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    double sum = 0;
    for (int32_t t = 0; t < m->ntets; ++t)
        for (int k = 0; k < 6; ++k) {
            const double *a = m->X + 3 * m->tets[4 * t + e[k][0]],
                         *b = m->X + 3 * m->tets[4 * t + e[k][1]];
            sum += sw_v3_dist(a, b);
        }
    return m->ntets > 0 ? sum / (6.0 * m->ntets) : 0;
}

/* Interface springs (eq. 4.20) at unit stiffness into the R x R spring Hessian: a vertex with
 * copies in several domains ties each to its hub, the copy in the domain whose bone is nearest the
 * skeleton's root (the lower domain on a tie), by k/2 |U_i q_i - U_j q_j|^2. Every pair
 * of copies tied instead (k(k-1)/2 springs, not k - 1) coupled sibling domains that
 * meet only at their parent's vertices, and the reduced Hessian's block graph then
 * follows the mesh's corners, not the skeleton: the hub ties keep the factor's blocks to
 * the skeleton's graph, at the same errors (docs/notes). */
static void add_interface_springs(const sw_bake_state *s, const sw_blob_domain *doms,
                                  const int32_t *copy_ptr_v, const int32_t *copy_list,
                                  double *spring) {
    int32_t R = s->basis.rank_total;
    for (int32_t gv = 0; gv < s->rig.nv; ++gv) {
        int32_t hub = copy_ptr_v[gv], hub_depth = INT32_MAX;
        for (int32_t a = copy_ptr_v[gv]; a < copy_ptr_v[gv + 1]; ++a) {
            int32_t d = sw_bone_depth(&s->rig.ch.skel, s->domains.domain_bone[copy_list[2 * a]]);
            if (d < hub_depth) hub_depth = d, hub = a; /* copies are in domain order */
        }
        for (int32_t b = copy_ptr_v[gv]; b < copy_ptr_v[gv + 1]; ++b) {
            if (b == hub) continue;
            int32_t a = hub;
            int32_t di = copy_list[2 * a], li = copy_list[2 * a + 1];
            int32_t dj = copy_list[2 * b], lj = copy_list[2 * b + 1];
            int32_t ri = s->basis.rank[di], rj = s->basis.rank[dj];
            const double *Ui = s->basis.U[di] + (size_t)3 * li * ri,
                         *Uj = s->basis.U[dj] + (size_t)3 * lj * rj;
            int32_t oi = doms[di].q_offset, oj = doms[dj].q_offset;
            for (int c = 0; c < 3; ++c) {
                for (int32_t x = 0; x < ri; ++x) {
                    double ux = Ui[c * ri + x];
                    if (ux == 0) continue;
                    for (int32_t y = 0; y < ri; ++y)
                        spring[(int64_t)(oi + x) * R + oi + y] += ux * Ui[c * ri + y];
                    for (int32_t y = 0; y < rj; ++y) {
                        spring[(int64_t)(oi + x) * R + oj + y] -= ux * Uj[c * rj + y];
                        spring[(int64_t)(oj + y) * R + oi + x] -= ux * Uj[c * rj + y];
                    }
                }
                for (int32_t x = 0; x < rj; ++x) {
                    double ux = Uj[c * rj + x];
                    if (ux == 0) continue;
                    for (int32_t y = 0; y < rj; ++y)
                        spring[(int64_t)(oj + x) * R + oj + y] += ux * Uj[c * rj + y];
                }
            }
        }
    }
}

/* The view's domains, basis, cubature tets, reduced mass and inertial projections, per
 * domain (blob_view.h); local_of: nverts ints of scratch. */
static void fill_domains(const sw_bake_state *s, sw_blob_domain *doms, double *basis,
                         int32_t *cub_tets, double *cub_weight, double *cub_dminv, double *cub_vol,
                         double *mass, double *ins, double *inx, double *inu, int32_t *local_of) {
    const int32_t R = s->basis.rank_total, nd = s->domains.nd;
    int32_t qoff = 0, cub = 0;
    int64_t boff = 0, ioff = 0;
    for (int32_t d = 0; d < nd; ++d) {
        int32_t base = s->domains.dom_vert_ptr[d], n = s->domains.dom_vert_ptr[d + 1] - base,
                r_d = s->basis.rank[d];
        sw_blob_domain *D = &doms[d];
        memset(D, 0, sizeof *D);
        D->bone = s->domains.domain_bone[d];
        D->vert_begin = base;
        D->vert_count = n;
        D->rank = r_d;
        /* the inertia modes come last (bake_basis.c): held in quasistatic steps */
        D->inertia_count = s->p->inertia_modes ? r_d - s->basis.rank_dynamic[d] : 0;
        D->q_offset = qoff;
        D->cub_begin = cub;
        D->cub_count = s->cubature.n[d];
        D->basis_offset = boff;
        D->inertia_offset = ioff;
        const double *U = s->basis.U[d];
        memcpy(basis + boff, U, (size_t)n * 3 * r_d * sizeof(double));
        for (int32_t k = 0; k < n; ++k)
            local_of[s->domains.dom_verts[base + k]] = k;
        for (int32_t i = 0; i < s->cubature.n[d]; ++i, ++cub) {
            int32_t tet = s->domains.dom_tets[s->domains.dom_tet_ptr[d] + s->cubature.local[d][i]];
            double Xe[12];
            for (int k = 0; k < 4; ++k) {
                int32_t gv = s->rig.ch.mesh.tets[4 * (int64_t)tet + k];
                cub_tets[4 * cub + k] = local_of[gv];
                memcpy(Xe + 3 * k, s->rig.ch.mesh.X + 3 * (int64_t)gv, 24);
            }
            sw_tet_rest(Xe, cub_dminv + 9 * cub, cub_vol + cub);
            cub_weight[cub] = s->cubature.w[d][i];
        }
        for (int32_t k = 0; k < n; ++k) {
            double m = s->domains.copy_mass[base + k];
            const double *Uk = U + (size_t)3 * k * r_d,
                         *X = s->rig.ch.mesh.X + 3 * (int64_t)s->domains.dom_verts[base + k];
            for (int32_t i = 0; i < r_d; ++i) {
                for (int a = 0; a < 3; ++a) {
                    double u = m * Uk[a * r_d + i];
                    if (u == 0) continue;
                    ins[3 * (qoff + i) + a] += u;
                    for (int bb = 0; bb < 3; ++bb)
                        inx[9 * (qoff + i) + 3 * a + bb] += u * X[bb];
                    for (int bb = 0; bb < 3; ++bb)
                        for (int32_t j = 0; j < r_d; ++j)
                            inu[ioff + (int64_t)(3 * a + bb) * r_d * r_d + (int64_t)i * r_d + j] +=
                                u * Uk[bb * r_d + j];
                    for (int32_t j = 0; j < r_d; ++j)
                        mass[(int64_t)(qoff + i) * R + qoff + j] += u * Uk[a * r_d + j];
                }
            }
        }
        qoff += r_d;
        boff += (int64_t)n * 3 * r_d;
        ioff += 9 * (int64_t)r_d * r_d;
    }
}

/* The pose-space sections of the view: the training poses' projections and pose
 * features (the pose-space interpolation's samples) and their self-contact pairs. */
static sinew_result pose_sections(const sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    const int32_t R = s->basis.rank_total;
    double *tq, *tp;
    OWN(tq, (int64_t)s->basis.ntrain * R, double);
    OWN(tp, (int64_t)s->basis.ntrain * 4 * s->rig.nb, double);
    if (!tq || !tp) {
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    }
    memcpy(tq, s->basis.train_q, (size_t)s->basis.ntrain * R * sizeof(double));
    memcpy(tp, s->basis.train_pose, (size_t)s->basis.ntrain * 4 * s->rig.nb * sizeof(double));
    v->ntrain = s->basis.ntrain;
    v->train_q = tq;
    v->train_pose = tp;
    int32_t *cp, *cv;
    double *cd;
    OWN(cp, s->basis.ntrain + 1, int32_t);
    OWN(cv, 8 * (int64_t)s->contacts.ncontacts, int32_t);
    OWN(cd, 7 * (int64_t)s->contacts.ncontacts, double);
    if (!cp || !cv || !cd) {
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    }
    memcpy(cp, s->contacts.contact_ptr, (size_t)(s->basis.ntrain + 1) * sizeof(int32_t));
    memcpy(cv, s->contacts.contact_verts, (size_t)s->contacts.ncontacts * 8 * sizeof(int32_t));
    memcpy(cd, s->contacts.contact_data, (size_t)s->contacts.ncontacts * 7 * sizeof(double));
    v->ncontacts = s->contacts.ncontacts;
    v->contact_ptr = cp;
    v->contact_verts = cv;
    v->contact_data = cd;
    return SINEW_OK;
}

/* The rig's sections: rest positions, skinning, the bones' parents and joints. */
static sinew_result rig_sections(const sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    double *rest, *skin_weight, *joints;
    int32_t *skin_bone, *parent;
    OWN(rest, 3 * s->rig.nv, double);
    OWN(skin_bone, 4 * s->rig.nv, int32_t);
    OWN(skin_weight, 4 * s->rig.nv, double);
    OWN(parent, s->rig.nb, int32_t);
    OWN(joints, 6 * s->rig.nb, double);
    if (!rest || !skin_bone || !skin_weight || !parent || !joints)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    memcpy(rest, s->rig.ch.mesh.X, (size_t)s->rig.nv * 3 * sizeof(double));
    memcpy(skin_bone, s->rig.skin_bone, (size_t)s->rig.nv * 4 * sizeof(int32_t));
    memcpy(skin_weight, s->rig.skin_weight, (size_t)s->rig.nv * 4 * sizeof(double));
    for (int32_t b = 0; b < s->rig.nb; ++b) {
        parent[b] = s->rig.ch.skel.parent[b];
        memcpy(joints + 6 * b, s->rig.ch.skel.joints + 3 * s->rig.ch.skel.bones[2 * b],
               3 * sizeof(double));
        memcpy(joints + 6 * b + 3, s->rig.ch.skel.joints + 3 * s->rig.ch.skel.bones[2 * b + 1],
               3 * sizeof(double));
    }
    v->nverts = s->rig.nv;
    v->nbones = s->rig.nb;
    v->rest = rest;
    v->skin_bone = skin_bone;
    v->skin_weight = skin_weight;
    v->bone_parent = parent;
    v->bone_joints = joints;
    return SINEW_OK;
}

/* Each mesh vertex's copies (domain, local), in domain order: copy_list from
 * copy_ptr_v[v] to copy_ptr_v[v + 1] (nv + 1 entries, zeroed); fill: nv scratch. */
static void vertex_copies(const sw_bake_state *s, int32_t *copy_ptr_v, int32_t *copy_list,
                          int32_t *fill) {
    const int32_t nd = s->domains.nd;
    for (int32_t d = 0; d < nd; ++d)
        for (int32_t k = s->domains.dom_vert_ptr[d]; k < s->domains.dom_vert_ptr[d + 1]; ++k)
            copy_ptr_v[s->domains.dom_verts[k] + 1]++;
    for (int32_t i = 0; i < s->rig.nv; ++i)
        copy_ptr_v[i + 1] += copy_ptr_v[i];
    memcpy(fill, copy_ptr_v, (size_t)s->rig.nv * sizeof(int32_t));
    for (int32_t d = 0; d < nd; ++d)
        for (int32_t k = s->domains.dom_vert_ptr[d]; k < s->domains.dom_vert_ptr[d + 1]; ++k) {
            int32_t gv = s->domains.dom_verts[k], at = fill[gv]++;
            copy_list[2 * at] = d;
            copy_list[2 * at + 1] = k - s->domains.dom_vert_ptr[d];
        }
}

/* The output surface: the tet mesh's boundary, each vertex the mean of its copies
 * (vertex_copies'); surf_index: nv scratch. */
static sinew_result surface_sections(const sw_bake_state *s, const sw_surface *surf,
                                     const int32_t *copy_ptr_v, const int32_t *copy_list,
                                     int32_t *surf_index, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    int32_t *surf_tris, *copy_ptr, *copies;
    OWN(surf_tris, 3 * surf->ntris, int32_t);
    OWN(copy_ptr, surf->nverts + 1, int32_t);
    if (!surf_tris || !copy_ptr)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    for (int32_t i = 0; i < s->rig.nv; ++i)
        surf_index[i] = -1;
    for (int32_t i = 0; i < surf->nverts; ++i)
        surf_index[surf->verts[i]] = i;
    for (int32_t i = 0; i < 3 * surf->ntris; ++i)
        surf_tris[i] = surf_index[surf->tris[i]];
    int32_t nsc = 0;
    for (int32_t i = 0; i < surf->nverts; ++i) {
        int32_t gv = surf->verts[i];
        copy_ptr[i] = nsc;
        nsc += copy_ptr_v[gv + 1] - copy_ptr_v[gv];
    }
    copy_ptr[surf->nverts] = nsc;
    if (!OWN(copies, 2 * nsc, int32_t))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    for (int32_t i = 0; i < surf->nverts; ++i) {
        int32_t gv = surf->verts[i];
        memcpy(copies + 2 * copy_ptr[i], copy_list + 2 * copy_ptr_v[gv],
               (size_t)(copy_ptr_v[gv + 1] - copy_ptr_v[gv]) * 2 * sizeof(int32_t));
    }
    v->nsurf_verts = surf->nverts;
    v->nsurf_tris = surf->ntris;
    v->surf_tris = surf_tris;
    v->surf_copy_ptr = copy_ptr;
    v->surf_copies = copies;
    v->nsurf_copies = nsc;
    return SINEW_OK;
}

/* A painted character's stiffness multiplier of each cubature tet (none unpainted). */
static sinew_result painted_cubature(const sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    if (!s->rig.ch.tet_stiffness) return SINEW_OK;
    double *stiff;
    if (!OWN(stiff, out->view.ncub, double))
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    for (int32_t d = 0, c = 0; d < s->domains.nd; ++d)
        for (int32_t i = 0; i < s->cubature.n[d]; ++i)
            stiff[c++] = s->rig.ch.tet_stiffness[s->domains.dom_tets[s->domains.dom_tet_ptr[d] +
                                                                     s->cubature.local[d][i]]];
    out->view.cub_stiffness = stiff;
    return SINEW_OK;
}

/* The view's mass and springs by domain blocks (blob version 4), from the dense mass and
 * the springs at unit stiffness: the springs stage scales s->reduce.spring_unit_packed
 * into the view's s->reduce.spring. */
static sinew_result reduced_blocks(sw_bake_state *s, const sw_blob_domain *doms, const double *mass,
                                   sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    int32_t R = s->basis.rank_total, nd = s->domains.nd;
    int32_t *blocks;
    double *mass_packed, *spring;
    OWN(blocks, 2 * (int64_t)nd * nd, int32_t);
    if (!blocks) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    int64_t nmass = sw_blob_pack_blocks(doms, nd, R, mass, blocks, NULL),
            nspring =
                sw_blob_pack_blocks(doms, nd, R, s->reduce.spring_unit, blocks + nd * nd, NULL);
    OWN(mass_packed, nmass, double);
    OWN(spring, nspring, double);
    s->reduce.spring_unit_packed = malloc((size_t)nspring * sizeof(double) + 1);
    if (!mass_packed || !spring || !s->reduce.spring_unit_packed)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
    sw_blob_pack_blocks(doms, nd, R, mass, blocks, mass_packed);
    sw_blob_pack_blocks(doms, nd, R, s->reduce.spring_unit, blocks + nd * nd,
                        s->reduce.spring_unit_packed);
    v->reduced_blocks = blocks;
    v->mass = mass_packed;
    v->nmass = nmass;
    v->spring_hessian = s->reduce.spring = spring;
    v->nspring_hessian = s->reduce.nspring = nspring;
    return SINEW_OK;
}

sinew_result sw_bake_reduce(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    sw_blob_view *v = &out->view;
    int32_t R = s->basis.rank_total, nd = s->domains.nd, ncopies = s->domains.dom_vert_ptr[nd];
    /* the interface springs at unit stiffness per copy pair, and the stiffness of one
       vertex of the mesh, E h (a fixed k would lock the interface of a fine mesh, whose
       domains' bases cannot match there exactly): sw_bake_springs scales them (bake_springs.c) */
    s->reduce.spring_eh = s->rig.ch.youngs * mean_edge(&s->rig.ch.mesh);
    sw_surface surf;
    memset(&surf, 0, sizeof surf);
    sinew_result r = sw_tetmesh_surface(&s->rig.ch.mesh, &surf, err);
    if (r != SINEW_OK) return r;

    int32_t ncub = 0;
    int64_t nbasis = 0, ninertia = 0;
    for (int32_t d = 0; d < nd; ++d) {
        ncub += s->cubature.n[d];
        nbasis += (int64_t)(s->domains.dom_vert_ptr[d + 1] - s->domains.dom_vert_ptr[d]) * 3 *
                  s->basis.rank[d];
        ninertia += 9 * (int64_t)s->basis.rank[d] * s->basis.rank[d];
    }
    double *basis, *cub_weight, *cub_dminv, *cub_vol, *mass, *ins, *inx, *inu;
    int32_t *dverts, *cub_tets;
    sw_blob_domain *doms;
    OWN(doms, nd, sw_blob_domain);
    OWN(dverts, ncopies, int32_t);
    OWN(basis, nbasis, double);
    OWN(cub_tets, 4 * ncub, int32_t);
    OWN(cub_weight, ncub, double);
    OWN(cub_dminv, 9 * ncub, double);
    OWN(cub_vol, ncub, double);
    mass = calloc((size_t)R * R, sizeof(double)); /* dense here, by blocks in the view */
    OWN(ins, 3 * R, double);
    OWN(inx, 9 * R, double);
    OWN(inu, ninertia, double);
    int32_t *copy_ptr_v = calloc((size_t)s->rig.nv + 1, sizeof(int32_t)); /* copies per vertex */
    int32_t *copy_list = malloc((size_t)ncopies * 2 * sizeof(int32_t));
    int32_t *surf_index = malloc((size_t)s->rig.nv * sizeof(int32_t));
    if (!doms || !dverts || !basis || !cub_tets || !cub_weight || !cub_dminv || !cub_vol || !mass ||
        !ins || !inx || !inu || !copy_ptr_v || !copy_list || !surf_index) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the blob");
        goto done;
    }
    if ((r = rig_sections(s, out, err)) != SINEW_OK) goto done;
    memcpy(dverts, s->domains.dom_verts, (size_t)ncopies * sizeof(int32_t));
    fill_domains(s, doms, basis, cub_tets, cub_weight, cub_dminv, cub_vol, mass, ins, inx, inu,
                 surf_index);
    vertex_copies(s, copy_ptr_v, copy_list, surf_index);
    if (!(s->reduce.spring_unit = calloc((size_t)R * R + 1, sizeof(double)))) {
        r = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the springs");
        goto done;
    }
    add_interface_springs(s, doms, copy_ptr_v, copy_list, s->reduce.spring_unit);
    if ((r = reduced_blocks(s, doms, mass, out, err)) != SINEW_OK) goto done;
    r = surface_sections(s, &surf, copy_ptr_v, copy_list, surf_index, out, err);
    if (r != SINEW_OK) goto done;

    v->ndomains = nd;
    v->rank_total = R;
    v->ndomain_verts = ncopies;
    v->ncub = ncub;
    sw_lame(s->rig.ch.youngs, s->rig.ch.poisson, &v->mu, &v->lambda);
    v->rayleigh_alpha = s->p->rayleigh_alpha; /* thesis §2.1.3 */
    v->rayleigh_beta = s->p->rayleigh_beta;
    v->contact_k = 1e6; /* the training simulations' penalty (fullsim default) */
    v->domains = doms;
    v->domain_verts = dverts;
    v->basis = basis;
    v->nbasis = nbasis;
    v->cub_tets = cub_tets;
    v->cub_weight = cub_weight;
    v->cub_dminv = cub_dminv;
    v->cub_vol = cub_vol;
    if ((r = painted_cubature(s, out, err)) != SINEW_OK) goto done;
    v->inertia_s = ins;
    v->inertia_x = inx;
    v->inertia_u = inu;
    v->ninertia_u = ninertia;
    r = pose_sections(s, out, err);
done:
    free(mass);
    free(copy_ptr_v);
    free(copy_list);
    free(surf_index);
    sw_surface_free(&surf);
    return r;
}
