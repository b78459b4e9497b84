/* A simulation character from a glTF/FBX file (scene_character.h). */
#include "scene_character.h"

#include "character_paint.h"

#include "hash.h"

#include "character_io.h"
#include "rig.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SW_SCENE_DEFAULT_TETS 20000
#define SW_SCENE_DEFAULT_TRAIN 2
/* The samples' material (samples.c: the thesis's hand, E 5000, nu 0.08, density 1) and
 * the finger sample's size at which it holds: the cube root of the finger's volume
 * (1.698 cubic units at 20K tets: 3.6 long, radius 0.45 to 0.35). */
#define SW_SCENE_E0 5000.0
#define SW_SCENE_NU 0.08
#define SW_SCENE_L0 1.193

void sw_scene_material(double size, double *youngs, double *poisson, double *density) {
    double k = size > 0 && isfinite(size) ? size / SW_SCENE_L0 : 1.0;
    *youngs = SW_SCENE_E0 * k;
    *poisson = SW_SCENE_NU;
    *density = 1.0 / k;
}

void sw_clip_split_free(sw_clip_split *s) {
    if (!s) return;
    for (int32_t i = 0; i < s->ntrain; ++i)
        sw_clip_free(&s->train[i]);
    for (int32_t i = 0; i < s->nheldout; ++i)
        sw_clip_free(&s->heldout[i]);
    free(s->train);
    free(s->heldout);
    free(s->train_names);
    free(s->heldout_names);
    memset(s, 0, sizeof *s);
}

/* "A, B, C": every name of the file, for messages. */
static void list_names(const char (*names)[64], int32_t n, char *buf, size_t cap) {
    size_t used = 0;
    buf[0] = '\0';
    for (int32_t i = 0; i < n && used + 1 < cap; ++i)
        used += (size_t)snprintf(buf + used, cap - used, "%s%s", i ? ", " : "", names[i]);
    if (n == 0) snprintf(buf, cap, "none");
}

/* Parses the comma-separated `list` into clip indices (appended to idx, marking taken[]).
 * Spaces around a name are ignored. */
static sinew_result parse_list(const char *flag, const char *list, const char (*names)[64],
                               int32_t n, unsigned char *taken, int32_t *idx, int32_t *count,
                               sw_error *err) {
    char all[1024];
    *count = 0;
    for (const char *p = list;;) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        while (len > 0 && isspace((unsigned char)*p))
            ++p, --len;
        while (len > 0 && isspace((unsigned char)p[len - 1]))
            --len;
        list_names(names, n, all, sizeof all);
        if (len == 0)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "%s: an empty clip name in '%s' (the file's clips: %s)", flag, list,
                                all);
        int32_t found = -1;
        for (int32_t i = 0; i < n && found < 0; ++i)
            if (strlen(names[i]) == len && !strncmp(names[i], p, len)) found = i;
        if (found < 0)
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "%s: no clip named '%.*s' (the file's clips: %s)", flag, (int)len,
                                p, all);
        if (taken[found])
            return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                                "%s: clip '%s' is given twice (training and held-out clips are "
                                "never mixed)",
                                flag, names[found]);
        taken[found] = 1;
        idx[(*count)++] = found;
        if (!end) break;
        p = end + 1;
    }
    return SINEW_OK;
}

/* Appends up to `want` untaken clips, longest first (ties: file order). */
static void take_longest(const int32_t *frames, int32_t n, int32_t want, unsigned char *taken,
                         int32_t *idx, int32_t *count) {
    for (int32_t k = 0; k < want; ++k) {
        int32_t best = -1;
        for (int32_t i = 0; i < n; ++i)
            if (!taken[i] && (best < 0 || frames[i] > frames[best])) best = i;
        if (best < 0) return;
        taken[best] = 1;
        idx[(*count)++] = best;
    }
}

sinew_result sw_clip_split_choose(const char (*names)[64], const int32_t *frames, int32_t n,
                                  const char *train, const char *heldout, int32_t *train_idx,
                                  int32_t *ntrain, int32_t *heldout_idx, int32_t *nheldout,
                                  sw_error *err) {
    *ntrain = *nheldout = 0;
    if (n < 0 || (n > 0 && (!names || !frames)))
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "clip split: bad arguments");
    unsigned char *taken = calloc((size_t)n + 1, 1);
    if (!taken) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "clip split: out of memory");
    sinew_result rc = SINEW_OK;
    if ((train || heldout) && n == 0)
        rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                          "%s: the file has no clips to choose from",
                          train ? "--train-clips" : "--heldout-clips");
    if (!rc && train)
        rc = parse_list("--train-clips", train, names, n, taken, train_idx, ntrain, err);
    if (!rc && heldout)
        rc = parse_list("--heldout-clips", heldout, names, n, taken, heldout_idx, nheldout, err);
    if (!rc && !train) {
        int32_t want = n - *nheldout - (heldout ? 0 : 1);
        take_longest(frames, n,
                     want < 1                        ? 1
                     : want > SW_SCENE_DEFAULT_TRAIN ? SW_SCENE_DEFAULT_TRAIN
                                                     : want,
                     taken, train_idx, ntrain);
    }
    if (!rc && !heldout) take_longest(frames, n, 1, taken, heldout_idx, nheldout);
    if (!rc && n > 0 && *ntrain == 0) {
        char all[1024];
        list_names(names, n, all, sizeof all);
        rc = sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                          "--heldout-clips holds out every clip, none is left to train on (the "
                          "file's clips: %s)",
                          all);
    }
    free(taken);
    if (rc) *ntrain = *nheldout = 0;
    return rc;
}

/* Copies clip indices idx into owned clips and names. */
static sinew_result copy_clips(const sw_imported_character *ic, const int32_t *idx, int32_t n,
                               sw_clip **clips, char (**names)[64], int32_t *count, sw_error *err) {
    *clips = calloc((size_t)n + 1, sizeof **clips);
    *names = calloc((size_t)n + 1, sizeof **names);
    if (!*clips || !*names) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int32_t i = 0; i < n; ++i) {
        const sw_clip *src = &ic->clips[idx[i]].clip;
        size_t bytes = sizeof(double) * 12 * (size_t)src->nbones * (size_t)src->nframes;
        sw_clip *c = &(*clips)[i];
        if (!(c->T = malloc(bytes ? bytes : 1)))
            return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for clips");
        memcpy(c->T, src->T, bytes);
        c->nbones = src->nbones;
        c->nframes = src->nframes;
        c->fps = src->fps;
        memcpy((*names)[i], ic->clips[idx[i]].name, 64);
        *count = i + 1; /* what sw_clip_split_free releases */
    }
    return SINEW_OK;
}

static sinew_result choose_clips(const sw_imported_character *ic,
                                 const sw_scene_character_options *o, sw_clip_split *split,
                                 sw_error *err) {
    int32_t n = ic->nclips;
    char(*names)[64] = calloc((size_t)n + 1, sizeof *names);
    int32_t *frames = calloc((size_t)n + 1, sizeof(int32_t));
    int32_t *ti = calloc((size_t)n + 1, sizeof(int32_t)),
            *hi = calloc((size_t)n + 1, sizeof(int32_t));
    sinew_result rc = SINEW_OK;
    if (!names || !frames || !ti || !hi)
        rc = sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory");
    for (int32_t i = 0; i < n && !rc; ++i) {
        memcpy(names[i], ic->clips[i].name, 64);
        frames[i] = ic->clips[i].clip.nframes;
    }
    int32_t nt = 0, nh = 0;
    if (!rc)
        rc = sw_clip_split_choose((const char(*)[64])names, frames, n, o->train_clips,
                                  o->heldout_clips, ti, &nt, hi, &nh, err);
    if (!rc) rc = copy_clips(ic, ti, nt, &split->train, &split->train_names, &split->ntrain, err);
    if (!rc)
        rc = copy_clips(ic, hi, nh, &split->heldout, &split->heldout_names, &split->nheldout, err);
    free(names);
    free(frames);
    free(ti);
    free(hi);
    return rc;
}

/* Prefixes err's message with the file's path (the helpers name the item, not the file). */
static sinew_result named(sinew_result rc, const char *path, sw_error *err) {
    if (rc && err) {
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        if (strncmp(msg, path, strlen(path))) sw_error_set(err, rc, "%s: %s", path, msg);
    }
    return rc;
}

/* out->clip: a copy of `src`, or the rest pose for one frame when src is NULL. */
static sinew_result character_clip(const sw_clip *src, int32_t nbones, sw_clip *out,
                                   sw_error *err) {
    int32_t nf = src ? src->nframes : 1;
    out->T = calloc((size_t)nbones * (size_t)nf * 12, sizeof(double));
    if (!out->T) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the clip");
    if (src)
        memcpy(out->T, src->T, sizeof(double) * 12 * (size_t)nbones * (size_t)nf);
    else
        for (int32_t b = 0; b < nbones; ++b)
            out->T[12 * b] = out->T[12 * b + 4] = out->T[12 * b + 8] = 1.0;
    out->nbones = nbones;
    out->nframes = nf;
    out->fps = src ? src->fps : 30.0;
    return SINEW_OK;
}

/* Bone-driven vertices: only bones that are some vertex's strongest influence drive
 * (rig.h, sw_select_bone_vertices_of); then every mesh piece gets an anchor. */
static sinew_result drive_vertices(sw_character *c, sw_scene_character_info *info, sw_error *err) {
    int32_t nb = c->skel.nbones, nv = c->mesh.nverts;
    unsigned char *drives = calloc((size_t)nb, 1);
    c->bone_of_vertex = malloc(sizeof(int32_t) * (size_t)nv);
    if (!drives || !c->bone_of_vertex) {
        free(drives);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for bone vertices");
    }
    for (int32_t v = 0; v < nv; ++v) {
        const double *row = c->weights.w + (size_t)v * nb;
        int32_t best = 0;
        for (int32_t b = 1; b < nb; ++b)
            if (row[b] > row[best]) best = b;
        drives[best] = 1;
    }
    for (int32_t b = 0; b < nb; ++b)
        info->undriven_bones += !drives[b];
    sinew_result rc =
        sw_select_bone_vertices_of(&c->mesh, &c->skel, &c->weights, drives, c->bone_of_vertex, err);
    free(drives);
    if (!rc)
        rc = sw_anchor_free_components(&c->mesh, &c->skel, &c->weights, c->bone_of_vertex,
                                       &info->anchored_components, err);
    return rc;
}

/* The steps after the import; ic's skeleton and render mesh move into out. */
static sinew_result build_character(const char *path, sw_imported_character *ic,
                                    const sw_scene_character_options *o, sw_character *out,
                                    sw_clip_split *split, sw_scene_character_info *info,
                                    sw_error *err) {
    sinew_result rc = choose_clips(ic, o, split, err);
    if (rc) return rc;
    sw_pool *pool = o->mesher == SW_MESHER_LATTICE ? sw_pool_create(0) : NULL;
    rc =
        sw_tetmesh_fill(&ic->render, o->target_tets, o->mesher, pool, &out->mesh, &info->mesh, err);
    sw_pool_destroy(pool);
    if (rc) return rc;
    out->skel = ic->skel; /* moved, with its names */
    memset(&ic->skel, 0, sizeof ic->skel);
    out->bone_names = ic->bone_names;
    ic->bone_names = NULL;
    out->bone_bind = ic->bone_bind;
    ic->bone_bind = NULL;
    out->nsource_meshes = ic->nsource_meshes;
    out->source_mesh_verts = ic->source_mesh_verts;
    ic->source_mesh_verts = NULL;
    if ((rc = sw_weights_from_surface(&out->mesh, &ic->render, &ic->weights, &out->weights, err)) ||
        (rc = drive_vertices(out, info, err)))
        return rc;
    const sw_clip *shown = split->nheldout ? &split->heldout[0]
                           : split->ntrain ? &split->train[0]
                                           : NULL;
    if ((rc = character_clip(shown, out->skel.nbones, &out->clip, err))) return rc;
    info->render_verts = ic->render.nverts;
    info->render_tris = ic->render.ntris;
    info->nclips = ic->nclips;
    info->unit_scale = ic->unit_scale;
    info->weight_dropped_max = ic->weight_dropped_max;
    out->render_source = malloc(2 * sizeof(int32_t) * (size_t)(ic->render.nverts + 1));
    if (!out->render_source)
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "out of memory for the vertex sources");
    for (int32_t i = 0; i < ic->render.nverts; ++i) {
        out->render_source[2 * i] = ic->render_source[i];
        out->render_source[2 * i + 1] = ic->render_source_vertex[i];
    }
    out->render_stiffness = ic->render_stiffness; /* moved, NULL when nothing is painted */
    ic->render_stiffness = NULL;
    out->render = ic->render; /* moved: the bake embeds it (sw_character.render) */
    memset(&ic->render, 0, sizeof ic->render);
    if ((rc = sw_character_paint(out, NULL, err))) return rc; /* the file's painting */
    info->size = cbrt(sw_tetmesh_volume(&out->mesh));
    sw_scene_material(info->size, &out->youngs, &out->poisson, &out->density);
    sw_file_stem(path, out->name, sizeof out->name);
    return SINEW_OK;
}

/* FNV-1a 64 of the file's bytes: what the blob says it was baked from. */
static sinew_result hash_file(const char *path, uint64_t *hash, sw_error *err) {
    FILE *f = fopen(path, "rb");
    if (!f) return sw_error_set(err, SINEW_ERROR_IO, "%s: cannot read it again to hash it", path);
    unsigned char buf[65536];
    uint64_t h = SW_FNV_START;
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        h = sw_fnv1a(h, buf, n);
    const int bad = ferror(f);
    fclose(f);
    if (bad) return sw_error_set(err, SINEW_ERROR_IO, "%s: read error while hashing it", path);
    *hash = h;
    return SINEW_OK;
}

sinew_result sw_character_from_scene(const char *path, const sw_scene_character_options *o,
                                     sw_character *out, sw_clip_split *clips,
                                     sw_scene_character_info *info, sw_error *err) {
    if (!out) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "character: out is NULL");
    memset(out, 0, sizeof *out);
    sw_clip_split split_local;
    sw_scene_character_info info_local;
    sw_clip_split *split = clips ? clips : &split_local;
    info = info ? info : &info_local;
    memset(split, 0, sizeof *split);
    memset(info, 0, sizeof *info);
    if (!path) return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "character: path is NULL");
    sw_scene_character_options opt = {0};
    if (o) opt = *o;
    if (opt.target_tets == 0) opt.target_tets = SW_SCENE_DEFAULT_TETS;
    if (opt.target_tets < 100 || opt.target_tets > 5000000)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: %d simulation tets asked (100..5000000)", path, opt.target_tets);
    sw_import_options io = {opt.fps, opt.target_height};
    sw_imported_character ic;
    sinew_result rc = sw_scene_import(path, &io, &ic, err);
    if (rc) return rc; /* the importer names the file */
    rc = named(build_character(path, &ic, &opt, out, split, info, err), path, err);
    if (!rc) rc = hash_file(path, &out->source_hash, err);
    sw_imported_character_free(&ic);
    if (rc) {
        sw_character_free(out);
        sw_clip_split_free(split);
    }
    if (split == &split_local) sw_clip_split_free(split);
    return rc;
}
