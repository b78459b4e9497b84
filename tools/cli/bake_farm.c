/* sinew-bake on a farm (bake_cli.h, docs/baking.md "Baking on a farm"): --plan writes the
 * bake's work items as a manifest, --shard I/N solves shard I's of them into --cache.
 * The items are the simulate stage's (the stages flagged `solutions`, bake.c): each a
 * chain of full-space solves and its cache entry, named by the hash of its inputs. */
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_cli.h"
#include "blob_write.h"

static const char *const tool = "sinew-bake";

/* A bake's items into `bakes`: its name, the items' keys, poses, shards, and the seconds
 * of those this run solved. NULL when out of memory. */
static cJSON *items_json(cJSON *bakes, const char *name, const sw_bake_result *res) {
    cJSON *b = cJSON_CreateObject(), *items = cJSON_CreateArray();
    if (!b || !items || !cJSON_AddItemToArray(bakes, b) ||
        !cJSON_AddItemToObject(b, "items", items))
        return NULL;
    cJSON_AddStringToObject(b, "bake", name);
    for (int k = 0; k < SW_BAKE_NSTAGES; ++k) /* the stages' wall times, by the table */
        if (sw_bake_stages[k].solutions && res->stage_seconds[k] > 0) {
            char key[48];
            snprintf(key, sizeof key, "%s_seconds", sw_bake_stages[k].name);
            cJSON_AddNumberToObject(b, key, res->stage_seconds[k]);
        }
    for (int32_t i = 0; i < res->nitems; ++i) {
        const sw_bake_item *it = &res->items[i];
        char key[24];
        snprintf(key, sizeof key, "%016llx", (unsigned long long)it->key);
        cJSON *o = cJSON_CreateObject();
        if (!o || !cJSON_AddItemToArray(items, o)) return NULL;
        cJSON_AddStringToObject(o, "key", key);
        cJSON_AddNumberToObject(o, "sequences", it->nseq);
        cJSON_AddNumberToObject(o, "poses", it->poses);
        cJSON_AddNumberToObject(o, "shard", it->shard);
        cJSON_AddBoolToObject(o, "cached", it->cached);
        if (it->seconds > 0) cJSON_AddNumberToObject(o, "seconds", it->seconds);
    }
    return b;
}

/* The manifest's character key (the hash every item shares) as text. */
static void character_text(const sw_bake_result *res, char *buf, size_t n) {
    snprintf(buf, n, "%016llx", (unsigned long long)res->items_character);
}

/* A shard given --plan FILE: the manifest must be this character's (its items share the
 * hash of the mesh, weights, material and simulator). */
static int check_plan(const char *path, const sw_bake_result *res) {
    size_t n = 0;
    FILE *f = fopen(path, "rb");
    char *text = NULL;
    if (f && fseek(f, 0, SEEK_END) == 0) {
        long len = ftell(f);
        if (len >= 0 && fseek(f, 0, SEEK_SET) == 0 && (text = malloc((size_t)len + 1)))
            n = fread(text, 1, (size_t)len, f);
    }
    if (f) fclose(f);
    if (!text) {
        fprintf(stderr, "%s: --plan %s: cannot read the manifest\n", tool, path);
        return 1;
    }
    text[n] = 0;
    cJSON *j = cJSON_Parse(text);
    free(text);
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(j, "character");
    char mine[24];
    character_text(res, mine, sizeof mine);
    int status = 0;
    if (!cJSON_IsString(c) || !cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(j, "sinew_plan"))) {
        fprintf(stderr, "%s: --plan %s: not a sinew-bake manifest\n", tool, path);
        status = 1;
    } else if (strcmp(c->valuestring, mine) != 0) {
        fprintf(stderr,
                "%s: --plan %s: the manifest is of another character or other reference "
                "options (its items' inputs hash to %s, this bake's to %s)\n",
                tool, path, c->valuestring, mine);
        status = 1;
    }
    cJSON_Delete(j);
    return status;
}

/* One bake of the run (the split, the whole clip, or the adaptive loop's round): its
 * items planned or this shard's solved, added to `bakes` under `name`. */
static int farm_bake(const bake_options *o, const sw_character *ch, int whole, cJSON *bakes,
                     cJSON *root, int *first) {
    sw_bake_result res;
    sw_adaptive_report rep;
    sw_error err;
    char name[48];
    sinew_result r = whole              ? sw_bake_whole_clip(ch, &o->p, &res, &err)
                     : o->ad.rounds > 0 ? sw_bake_adaptive(ch, &o->p, &o->ad, &res, &rep, &err)
                                        : sw_bake(ch, &o->p, &res, &err);
    if (r != SINEW_OK) return sw_tool_failed(r, &err, "%s: ", tool);
    if (o->ad.rounds > 0 && rep.farm_round < 0)
        snprintf(name, sizeof name, "adaptive: every round in the cache");
    else if (o->ad.rounds > 0)
        snprintf(name, sizeof name, "adaptive round %d", rep.farm_round);
    else
        snprintf(name, sizeof name, "%s", whole ? "whole clip" : "split");
    int status = 0;
    if (*first) {
        char key[24];
        character_text(&res, key, sizeof key);
        cJSON_AddStringToObject(root, "character", key);
        *first = 0;
    }
    if (!status && !items_json(bakes, name, &res)) {
        fprintf(stderr, "%s: out of memory\n", tool);
        status = 1;
    }
    int32_t mine = 0, solved = 0, cached = 0;
    double seconds = 0;
    for (int32_t i = 0; i < res.nitems; ++i) {
        const sw_bake_item *it = &res.items[i];
        cached += it->cached;
        mine += o->p.shard_count > 0 && it->shard == o->p.shard_index;
        solved += it->seconds > 0;
        seconds += it->seconds;
        if (o->p.shard_count > 0 && it->seconds > 0)
            fprintf(stderr, "%s: %s: item %d (%016llx): %d poses in %.2f s\n", tool, name, i,
                    (unsigned long long)it->key, it->poses, it->seconds);
    }
    if (o->p.shard_count > 0)
        fprintf(stderr,
                "%s: shard %d/%d: %s: %d items, %d of them this shard's, %d solved here in "
                "%.2f s, %d already in the cache\n",
                tool, o->p.shard_index, o->p.shard_count, name, res.nitems, mine, solved, seconds,
                cached);
    else
        fprintf(stderr, "%s: plan: %s: %d items, %d already in the cache\n", tool, name, res.nitems,
                cached);
    sw_bake_result_free(&res);
    return status;
}

int bake_farm(const bake_options *o, const sw_character *ch) {
    cJSON *root = cJSON_CreateObject(), *bakes = cJSON_CreateArray();
    if (!root || !bakes || !cJSON_AddItemToObject(root, "bakes", bakes)) {
        cJSON_Delete(root);
        cJSON_Delete(bakes);
        fprintf(stderr, "%s: out of memory\n", tool);
        return 1;
    }
    cJSON_AddNumberToObject(root, "sinew_plan", 1);
    if (o->p.shard_count > 0) {
        cJSON_AddNumberToObject(root, "shard", o->p.shard_index);
        cJSON_AddNumberToObject(root, "shards", o->p.shard_count);
    }
    int first = 1, status = 0;
    if (o->p.shard_count > 0 && o->plan_path) { /* the manifest checked before any solve */
        bake_options plan = *o;
        plan.p.plan_only = 1;
        plan.p.shard_count = 0;
        sw_bake_result res;
        sw_error err;
        sinew_result r = sw_bake(ch, &plan.p, &res, &err);
        status =
            r != SINEW_OK ? sw_tool_failed(r, &err, "%s: ", tool) : check_plan(o->plan_path, &res);
        sw_bake_result_free(&res);
    }
    if (!status) status = farm_bake(o, ch, 0, bakes, root, &first);
    /* the blob a character's only clip ships is baked again on the whole clip
       (sinew-bake.c): its items are the farm's too */
    if (!status && o->ad.rounds == 0 && sw_bake_ships_whole_clip(ch, &o->p))
        status = farm_bake(o, ch, 1, bakes, root, &first);
    char *text = status ? NULL : cJSON_PrintUnformatted(root);
    if (!status && !text) {
        fprintf(stderr, "%s: out of memory\n", tool);
        status = 1;
    }
    if (!status && o->plan_path && o->p.shard_count == 0) {
        sw_error err;
        size_t len = strlen(text);
        text[len] = '\n';
        sinew_result r = sw_write_file_atomic(o->plan_path, (const uint8_t *)text, len + 1, &err);
        text[len] = 0;
        if (r != SINEW_OK)
            status = sw_tool_failed(r, &err, "%s: --plan: ", tool);
        else
            fprintf(stderr, "%s: wrote the plan %s\n", tool, o->plan_path);
    }
    if (!status && o->json) printf("%s\n", text);
    free(text);
    cJSON_Delete(root);
    return status;
}
