/* Stage "domains" (bake.c, sw_bake_stages): reads s->rig; writes s->domains. */
/* Skeletal domains (thesis §2.3, §4.4.1; DESIGN.md §8): a tet goes to the strongest
 * bone of the majority of its vertices; a bone whose tets hold less than fold_share of
 * the mesh's volume passes them to its parent (fold_bones); bones that own no tet get no
 * domain. A domain's
 * vertex copies are the vertices of its tets; a vertex in several domains is an
 * interface vertex, duplicated and tied by springs (bake_reduce.c). */
#include <stdlib.h>
#include <string.h>

#include "bake_state.h"
#include "fem_corot.h"

static int32_t strongest_bone(const sw_bake_state *s, int32_t v) {
    const double *w = s->rig.weights + (size_t)v * s->rig.nb;
    int32_t best = 0;
    for (int32_t b = 1; b < s->rig.nb; ++b)
        if (w[b] > w[best]) best = b;
    return best;
}

/* Majority of the four vertices' strongest bones; a tie goes to the bone with the
 * larger summed weight over the tet, then the lower id (deterministic). */
static int32_t tet_bone(const sw_bake_state *s, const int32_t *tet) {
    int32_t bones[4], votes[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k)
        bones[k] = strongest_bone(s, tet[k]);
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            votes[k] += bones[j] == bones[k];
    int32_t best = 0;
    for (int k = 1; k < 4; ++k) {
        if (votes[k] < votes[best]) continue;
        if (votes[k] > votes[best]) {
            best = k;
            continue;
        }
        double wk = 0, wb = 0;
        for (int j = 0; j < 4; ++j) {
            wk += s->rig.weights[(size_t)tet[j] * s->rig.nb + bones[k]];
            wb += s->rig.weights[(size_t)tet[j] * s->rig.nb + bones[best]];
        }
        if (wk > wb || (wk == wb && bones[k] < bones[best])) best = k;
    }
    return bones[best];
}

/* Bones carrying almost no flesh (a tail's tip, a toe, the Fox's ear) join their parent's
 * domain, deepest bones first, so a chain of small bones folds into the first ancestor
 * with enough of its own and theirs: bone_of_tet maps bones to bones in place. A domain
 * costs a block of the reduced Hessian, its springs to its neighbours and a cubature of
 * its own however little it holds, and its rank is bounded by its shapes, not its size.
 * Folding by volume, not by tet count, keeps the errors (docs/notes). Off by default: it never
 * lowered a held-out error, and with few training poses it costs accuracy (test_reduced_heldout.c).
 * Returns 0 when out of memory. */
static int fold_bones(const sw_bake_state *s, int32_t *bone_of_tet) {
    const sw_skeleton *sk = &s->rig.ch.skel;
    int32_t nb = s->rig.nb, maxdepth = 0;
    double *vol = calloc((size_t)nb, sizeof(double)), total = 0;
    int32_t *depth = malloc((size_t)nb * sizeof(int32_t)),
            *to = malloc((size_t)nb * sizeof(int32_t));
    if (!vol || !depth || !to) {
        free(vol), free(depth), free(to);
        return 0;
    }
    for (int32_t t = 0; t < s->rig.nt; ++t) {
        double Xe[12], Dm[9], v = 0;
        for (int k = 0; k < 4; ++k)
            memcpy(Xe + 3 * k, s->rig.ch.mesh.X + 3 * (int64_t)s->rig.ch.mesh.tets[4 * t + k], 24);
        if (!sw_tet_rest(Xe, Dm, &v)) v = 0; /* a flat tet holds no flesh */
        vol[bone_of_tet[t]] += v;
        total += v;
    }
    for (int32_t b = 0; b < nb; ++b) {
        to[b] = b;
        depth[b] = sw_bone_depth(sk, b);
        if (depth[b] > maxdepth) maxdepth = depth[b];
    }
    for (int32_t d = maxdepth; d > 0; --d)
        for (int32_t b = 0; b < nb; ++b) {
            if (depth[b] != d || !(vol[b] > 0) || vol[b] >= s->p->fold_share * total) continue;
            int32_t p = sk->parent[b];
            vol[p] += vol[b];
            vol[b] = 0;
            for (int32_t c = 0; c < nb; ++c) /* b and what folded into it before */
                if (to[c] == b) to[c] = p;
        }
    for (int32_t t = 0; t < s->rig.nt; ++t)
        bone_of_tet[t] = to[bone_of_tet[t]];
    free(vol), free(depth), free(to);
    return 1;
}

/* Each tet's domain: the bone it belongs to (folded, where fold_share asks), domains
 * numbered in bone order over the bones that own tets; each domain's tet list. 0 when out
 * of memory. */
static int tet_domains(sw_bake_state *s, int32_t *domain_of_bone) {
    const int32_t *tets = s->rig.ch.mesh.tets;
    for (int32_t b = 0; b < s->rig.nb; ++b)
        domain_of_bone[b] = -1;
    for (int32_t t = 0; t < s->rig.nt; ++t)
        s->domains.tet_domain[t] = tet_bone(s, tets + 4 * t);
    if (s->p->fold_share > 0 && !fold_bones(s, s->domains.tet_domain)) return 0;
    for (int32_t t = 0; t < s->rig.nt; ++t)
        domain_of_bone[s->domains.tet_domain[t]] = 1;
    s->domains.nd = 0;
    for (int32_t b = 0; b < s->rig.nb; ++b)
        if (domain_of_bone[b] > 0) {
            s->domains.domain_bone[s->domains.nd] = b;
            domain_of_bone[b] = s->domains.nd++;
        }
    for (int32_t t = 0; t < s->rig.nt; ++t) {
        s->domains.tet_domain[t] = domain_of_bone[s->domains.tet_domain[t]];
        s->domains.dom_tet_ptr[s->domains.tet_domain[t] + 1]++;
    }
    for (int32_t d = 0; d < s->domains.nd; ++d)
        s->domains.dom_tet_ptr[d + 1] += s->domains.dom_tet_ptr[d];
    int32_t *fill = malloc((size_t)s->domains.nd * sizeof(int32_t));
    if (!fill) return 0;
    memcpy(fill, s->domains.dom_tet_ptr, (size_t)s->domains.nd * sizeof(int32_t));
    for (int32_t t = 0; t < s->rig.nt; ++t)
        s->domains.dom_tets[fill[s->domains.tet_domain[t]]++] = t;
    free(fill);
    return 1;
}

/* Each domain's copies of the vertices of its tets: two passes (count, fill), vertices
 * ascending per domain. */
static sinew_result vertex_copies(sw_bake_state *s, int32_t *mark, sw_error *err) {
    const int32_t *tets = s->rig.ch.mesh.tets;
    int64_t ncopies = 0;
    for (int pass = 0; pass < 2; ++pass) {
        ncopies = 0;
        for (int32_t d = 0; d < s->domains.nd; ++d) {
            for (int32_t v = 0; v < s->rig.nv; ++v)
                mark[v] = 0;
            for (int32_t i = s->domains.dom_tet_ptr[d]; i < s->domains.dom_tet_ptr[d + 1]; ++i)
                for (int k = 0; k < 4; ++k)
                    mark[tets[4 * s->domains.dom_tets[i] + k]] = 1;
            if (pass == 1) s->domains.dom_vert_ptr[d] = (int32_t)ncopies;
            for (int32_t v = 0; v < s->rig.nv; ++v)
                if (mark[v]) {
                    if (pass == 1) s->domains.dom_verts[ncopies] = v;
                    ncopies++;
                }
        }
        if (pass == 0) {
            if (ncopies > INT32_MAX)
                return sw_error_set(err, SINEW_ERROR_UNSUPPORTED, "too many vertex copies");
            s->domains.dom_verts = malloc((size_t)ncopies * sizeof(int32_t));
            s->domains.copy_mass = calloc((size_t)ncopies, sizeof(double));
            if (!s->domains.dom_verts || !s->domains.copy_mass)
                return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for copies");
        }
    }
    s->domains.dom_vert_ptr[s->domains.nd] = (int32_t)ncopies;
    return SINEW_OK;
}

/* Each copy's lumped mass from its own domain's tets. */
static void copy_masses(sw_bake_state *s, int32_t *mark) {
    const int32_t *tets = s->rig.ch.mesh.tets;
    for (int32_t d = 0; d < s->domains.nd; ++d) {
        int32_t base = s->domains.dom_vert_ptr[d], n = s->domains.dom_vert_ptr[d + 1] - base;
        for (int32_t k = 0; k < n; ++k)
            mark[s->domains.dom_verts[base + k]] = base + k;
        for (int32_t i = s->domains.dom_tet_ptr[d]; i < s->domains.dom_tet_ptr[d + 1]; ++i) {
            const int32_t *q = tets + 4 * s->domains.dom_tets[i];
            double Xe[12], Dm[9], vol;
            for (int k = 0; k < 4; ++k)
                memcpy(Xe + 3 * k, s->rig.ch.mesh.X + 3 * (int64_t)q[k], 24);
            sw_tet_rest(Xe, Dm, &vol);
            for (int k = 0; k < 4; ++k)
                s->domains.copy_mass[mark[q[k]]] += s->rig.ch.density * vol / 4.0;
        }
    }
}

sinew_result sw_bake_domains(sw_bake_state *s, sw_bake_result *out, sw_error *err) {
    (void)out;
    int32_t *domain_of_bone = malloc((size_t)s->rig.nb * sizeof(int32_t));
    int32_t *mark = malloc((size_t)s->rig.nv * sizeof(int32_t));
    s->domains.tet_domain = malloc((size_t)s->rig.nt * sizeof(int32_t));
    s->domains.domain_bone = malloc((size_t)s->rig.nb * sizeof(int32_t));
    s->domains.dom_tet_ptr = calloc((size_t)s->rig.nb + 1, sizeof(int32_t));
    s->domains.dom_tets = malloc((size_t)s->rig.nt * sizeof(int32_t));
    s->domains.dom_vert_ptr = calloc((size_t)s->rig.nb + 1, sizeof(int32_t));
    const int held = domain_of_bone && mark && s->domains.tet_domain && s->domains.domain_bone &&
                     s->domains.dom_tet_ptr && s->domains.dom_tets && s->domains.dom_vert_ptr;
    sinew_result r =
        held && tet_domains(s, domain_of_bone)
            ? vertex_copies(s, mark, err)
            : sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for domains");
    if (r == SINEW_OK) copy_masses(s, mark);
    free(domain_of_bone);
    free(mark);
    return r;
}
