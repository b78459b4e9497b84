/* Two characters as one (character_pair.h). */
#include "character_pair.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sinew_result sw_character_pair(const sw_character *a, const double offset[3], sw_character *out,
                               sw_error *err) {
    memset(out, 0, sizeof *out);
    const int32_t nv = a->mesh.nverts, nt = a->mesh.ntets, nb = a->skel.nbones,
                  nj = a->skel.njoints;
    if (!a->bone_of_vertex || a->weights.nverts != nv || a->weights.nbones != nb || nv < 1)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "character pair: the character has no weights or driven vertices");
    sw_character *o = out;
    snprintf(o->name, sizeof o->name, "%.50s pair", a->name);
    o->mesh.nverts = 2 * nv;
    o->mesh.ntets = 2 * nt;
    o->mesh.X = malloc(sizeof(double) * 6 * (size_t)nv);
    o->mesh.tets = malloc(sizeof(int32_t) * 8 * (size_t)nt);
    o->skel.njoints = 2 * nj;
    o->skel.nbones = 2 * nb;
    o->skel.joints = malloc(sizeof(double) * 6 * (size_t)nj);
    o->skel.bones = malloc(sizeof(int32_t) * 4 * (size_t)nb);
    o->skel.parent = malloc(sizeof(int32_t) * 2 * (size_t)nb);
    o->weights.nverts = 2 * nv;
    o->weights.nbones = 2 * nb;
    o->weights.w = calloc((size_t)4 * nv * nb, sizeof(double));
    o->bone_of_vertex = malloc(sizeof(int32_t) * 2 * (size_t)nv);
    if (a->tet_stiffness) o->tet_stiffness = malloc(sizeof(double) * 2 * (size_t)nt);
    if (!o->mesh.X || !o->mesh.tets || !o->skel.joints || !o->skel.bones || !o->skel.parent ||
        !o->weights.w || !o->bone_of_vertex || (a->tet_stiffness && !o->tet_stiffness)) {
        sw_character_free(o);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "character pair: out of memory");
    }
    for (int c = 0; c < 2; ++c) {
        for (int32_t v = 0; v < nv; ++v) {
            for (int k = 0; k < 3; ++k)
                o->mesh.X[3 * ((size_t)c * nv + v) + k] =
                    a->mesh.X[3 * (size_t)v + k] + (c ? offset[k] : 0.0);
            const int32_t b = a->bone_of_vertex[v];
            o->bone_of_vertex[(size_t)c * nv + v] = b < 0 ? -1 : b + c * nb;
            memcpy(o->weights.w + ((size_t)c * nv + v) * 2 * nb + (size_t)c * nb,
                   a->weights.w + (size_t)v * nb, sizeof(double) * (size_t)nb);
        }
        for (int64_t i = 0; i < 4 * (int64_t)nt; ++i)
            o->mesh.tets[(size_t)c * 4 * nt + i] = a->mesh.tets[i] + c * nv;
        for (int32_t j = 0; j < nj; ++j)
            for (int k = 0; k < 3; ++k)
                o->skel.joints[3 * ((size_t)c * nj + j) + k] =
                    a->skel.joints[3 * (size_t)j + k] + (c ? offset[k] : 0.0);
        for (int32_t b = 0; b < nb; ++b) {
            o->skel.bones[2 * ((size_t)c * nb + b)] = a->skel.bones[2 * b] + c * nj;
            o->skel.bones[2 * ((size_t)c * nb + b) + 1] = a->skel.bones[2 * b + 1] + c * nj;
            o->skel.parent[(size_t)c * nb + b] =
                a->skel.parent[b] < 0 ? -1 : a->skel.parent[b] + c * nb;
        }
        if (a->tet_stiffness)
            memcpy(o->tet_stiffness + (size_t)c * nt, a->tet_stiffness,
                   sizeof(double) * (size_t)nt);
    }
    o->youngs = a->youngs;
    o->poisson = a->poisson;
    o->density = a->density;
    return SINEW_OK;
}

void sw_character_pair_transforms(int32_t nbones, const double *Ta, const double *Tb,
                                  const double offset[3], double *T) {
    memcpy(T, Ta, sizeof(double) * 12 * (size_t)nbones);
    for (int32_t b = 0; b < nbones; ++b) {
        const double *S = Tb + 12 * (size_t)b;
        double *D = T + 12 * ((size_t)nbones + b);
        memcpy(D, S, 9 * sizeof(double));
        for (int i = 0; i < 3; ++i) /* x -> S (x - offset) */
            D[9 + i] = S[9 + i] -
                       (S[3 * i] * offset[0] + S[3 * i + 1] * offset[1] + S[3 * i + 2] * offset[2]);
    }
}
