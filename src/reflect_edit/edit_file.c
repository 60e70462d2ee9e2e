// Edit files (.edit.json; format in docs/reflection-editing.md), read with cJSON. As for
// scene files, src/io/json_lines.c pairs every cJSON node with the line its value starts on,
// so each complaint names "file:line".
#include "drift/file.h"
#include "io/json_lines.h"
#include "reflect_edit/reflect_edit_internal.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// An edit file larger than this is not an edit file.
#define MAX_EDIT_FILE_BYTES (16u << 20)
#define MAX_MASK_VERTICES   (1u << 24)

typedef struct reader {
    drift_context *ctx;
    const drift_scene *scene;
    const char *file;
    drift__json_lines lines; // every node's line
} reader;

// --- SOURCE POSITIONS ---

static int line_of(const reader *r, const cJSON *node)
{
    return drift__json_lines_find(&r->lines, node);
}

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static drift_result
fail(const reader *r, const cJSON *node, const char *fmt, ...)
{
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof(message), fmt, args);
    va_end(args);
    drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->file, line_of(r, node), "%s", message);
    return DRIFT_ERR_PARSE;
}

// --- VALUES ---

static drift_result read_number(const reader *r, const cJSON *node, const char *what, float lo,
                                float *out)
{
    // Positions beyond DRIFT_SCENE_COORD_MAX reached Embree and aborted it.
    if (!cJSON_IsNumber(node) || !(fabs(node->valuedouble) <= DRIFT_SCENE_COORD_MAX)) {
        return fail(r, node, "%s must be a finite number within +-%g", what, DRIFT_SCENE_COORD_MAX);
    }
    if (node->valuedouble < (double)lo) {
        return fail(r, node, "%s must be at least %g", what, (double)lo);
    }
    *out = (float)node->valuedouble;
    return DRIFT_OK;
}

static drift_result read_vec3(const reader *r, const cJSON *node, const char *what, drift_vec3 *out)
{
    if (!cJSON_IsArray(node) || cJSON_GetArraySize(node) != 3) {
        return fail(r, node, "%s must be an array of 3 numbers", what);
    }
    float v[3];
    int i = 0;
    for (const cJSON *c = node->child; c; c = c->next, ++i) {
        drift_result res = read_number(r, c, what, -INFINITY, &v[i]);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    *out = drift_vec3_make(v[0], v[1], v[2]);
    return DRIFT_OK;
}

static drift_result read_mesh(const reader *r, const cJSON *node, uint32_t *out)
{
    if (cJSON_IsString(node)) {
        for (uint32_t m = 0; m < r->scene->mesh_count; ++m) {
            if (strcmp(r->scene->meshes[m].name, node->valuestring) == 0) {
                *out = m;
                return DRIFT_OK;
            }
        }
        char names[256] = "";
        for (uint32_t m = 0; m < r->scene->mesh_count; ++m) {
            size_t used = strlen(names);
            snprintf(names + used, sizeof(names) - used, "%s'%s'", m ? ", " : "",
                     r->scene->meshes[m].name);
        }
        return fail(r, node, "unknown mesh '%s' (the scene's meshes: %s)", node->valuestring,
                    names);
    }
    if (cJSON_IsNumber(node) && node->valuedouble >= 0.0 &&
        node->valuedouble < (double)r->scene->mesh_count &&
        node->valuedouble == floor(node->valuedouble)) {
        *out = (uint32_t)node->valuedouble;
        return DRIFT_OK;
    }
    return fail(r, node, "mesh must be a mesh name or index of the scene");
}

// Every key of `object` must be one of `allowed` (NULL-terminated).
static drift_result check_keys(const reader *r, const cJSON *object, const char *what,
                               const char *const *allowed)
{
    for (const cJSON *c = object->child; c; c = c->next) {
        bool known = false;
        for (const char *const *k = allowed; *k && !known; ++k) {
            known = strcmp(*k, c->string) == 0;
        }
        if (!known) {
            return fail(r, c, "unknown key '%s' in %s", c->string, what);
        }
    }
    return DRIFT_OK;
}

static const cJSON *require(const reader *r, const cJSON *object, const char *key, const char *what,
                            drift_result *res)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(object, key);
    if (!c && *res == DRIFT_OK) {
        *res = fail(r, object, "%s needs \"%s\"", what, key);
    }
    return c;
}

// --- CONSTRAINTS AND REGIONS ---

static drift_result read_constraint(const reader *r, const cJSON *node, uint32_t index,
                                    drift_reflection_edits *edits)
{
    char what[64];
    snprintf(what, sizeof(what), "constraints[%u]", index);
    if (!cJSON_IsObject(node)) {
        return fail(r, node, "%s must be an object", what);
    }
    static const char *const keys[] = { "mesh", "point", "target", "view", NULL };
    drift_result res = check_keys(r, node, what, keys);
    drift_reflection_constraint c = { 0 };
    const cJSON *mesh = require(r, node, "mesh", what, &res);
    const cJSON *point = require(r, node, "point", what, &res);
    const cJSON *target = require(r, node, "target", what, &res);
    const cJSON *view = require(r, node, "view", what, &res);
    if (res != DRIFT_OK || (res = read_mesh(r, mesh, &c.mesh)) != DRIFT_OK ||
        (res = read_vec3(r, point, "point", &c.point)) != DRIFT_OK ||
        (res = read_vec3(r, target, "target", &c.target)) != DRIFT_OK ||
        (res = read_vec3(r, view, "view", &c.view)) != DRIFT_OK) {
        return res;
    }
    if (drift_reflection_edits_add_constraint(edits, &c) != DRIFT_OK) {
        return fail(r, node, "%s was refused", what);
    }
    return DRIFT_OK;
}

static drift_result read_region(const reader *r, const cJSON *node, uint32_t index,
                                drift_reflection_edits *edits)
{
    char what[64];
    snprintf(what, sizeof(what), "regions[%u]", index);
    if (!cJSON_IsObject(node)) {
        return fail(r, node, "%s must be an object", what);
    }
    static const char *const keys[] = { "type",   "mesh",     "centre", "radius",
                                        "border", "vertices", NULL };
    drift_result res = check_keys(r, node, what, keys);
    const cJSON *type = require(r, node, "type", what, &res);
    if (res != DRIFT_OK) {
        return res;
    }
    static const char *const type_names[DRIFT_EDIT_REGION_TYPE_COUNT] = { "euclidean", "geodesic",
                                                                          "mask" };
    drift_reflection_region region = { .type = DRIFT_EDIT_REGION_TYPE_COUNT };
    for (int t = 0; t < DRIFT_EDIT_REGION_TYPE_COUNT && cJSON_IsString(type); ++t) {
        if (strcmp(type->valuestring, type_names[t]) == 0) {
            region.type = (drift_edit_region_type)t;
        }
    }
    if (region.type == DRIFT_EDIT_REGION_TYPE_COUNT) {
        return fail(r, type, "%s.type must be \"euclidean\", \"geodesic\" or \"mask\"", what);
    }
    const cJSON *border = require(r, node, "border", what, &res);
    if (res != DRIFT_OK || (res = read_number(r, border, "border", 0.0f, &region.border))) {
        return res;
    }
    if (region.type != DRIFT_EDIT_REGION_EUCLIDEAN) {
        const cJSON *mesh = require(r, node, "mesh", what, &res);
        if (res != DRIFT_OK || (res = read_mesh(r, mesh, &region.mesh)) != DRIFT_OK) {
            return res;
        }
    }
    uint32_t *vertices = NULL;
    if (region.type == DRIFT_EDIT_REGION_MASK) {
        const cJSON *list = require(r, node, "vertices", what, &res);
        if (res != DRIFT_OK) {
            return res;
        }
        int count = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0;
        if (count <= 0 || (unsigned)count > MAX_MASK_VERTICES) {
            return fail(r, list, "%s.vertices must be a non-empty array of vertex indices", what);
        }
        vertices = drift_alloc(r->ctx, (size_t)count * sizeof(uint32_t));
        if (!vertices) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        uint32_t limit = r->scene->meshes[region.mesh].vertex_count, i = 0;
        for (const cJSON *c = list->child; c; c = c->next, ++i) {
            if (!cJSON_IsNumber(c) || !(c->valuedouble >= 0.0) ||
                !(c->valuedouble < (double)limit) || c->valuedouble != floor(c->valuedouble)) {
                drift_free(r->ctx, vertices);
                return fail(r, c, "%s.vertices: not a vertex index of mesh '%s'", what,
                            r->scene->meshes[region.mesh].name);
            }
            vertices[i] = (uint32_t)c->valuedouble;
        }
        region.mask_vertices = vertices;
        region.mask_vertex_count = i;
    } else {
        const cJSON *centre = require(r, node, "centre", what, &res);
        const cJSON *radius = require(r, node, "radius", what, &res);
        if (res != DRIFT_OK || (res = read_vec3(r, centre, "centre", &region.centre)) ||
            (res = read_number(r, radius, "radius", 0.0f, &region.radius))) {
            return res;
        }
    }
    res = drift_reflection_edits_add_region(edits, &region);
    drift_free(r->ctx, vertices);
    return res == DRIFT_OK ? DRIFT_OK : fail(r, node, "%s was refused", what);
}

static drift_result read_root(const reader *r, const cJSON *root, drift_reflection_edits *edits)
{
    if (!cJSON_IsObject(root)) {
        return fail(r, root, "an edit file is a JSON object");
    }
    static const char *const keys[] = { "distance", "constraints", "regions", NULL };
    drift_result res = check_keys(r, root, "the edit file", keys);
    if (res != DRIFT_OK) {
        return res;
    }
    const cJSON *distance = cJSON_GetObjectItemCaseSensitive(root, "distance");
    if (distance) {
        if (cJSON_IsString(distance) && strcmp(distance->valuestring, "geodesic") == 0) {
            drift_reflection_edits_set_distance(edits, DRIFT_EDIT_DISTANCE_GEODESIC);
        } else if (!cJSON_IsString(distance) || strcmp(distance->valuestring, "euclidean") != 0) {
            return fail(r, distance, "distance must be \"euclidean\" or \"geodesic\"");
        }
    }
    const cJSON *lists[2] = { cJSON_GetObjectItemCaseSensitive(root, "constraints"),
                              cJSON_GetObjectItemCaseSensitive(root, "regions") };
    const uint32_t limits[2] = { DRIFT_EDIT_MAX_CONSTRAINTS, DRIFT_EDIT_MAX_REGIONS };
    for (int l = 0; l < 2; ++l) {
        if (!lists[l]) {
            continue;
        }
        if (!cJSON_IsArray(lists[l]) || (uint32_t)cJSON_GetArraySize(lists[l]) > limits[l]) {
            return fail(r, lists[l], "%s must be an array of at most %u entries",
                        l == 0 ? "constraints" : "regions", limits[l]);
        }
        uint32_t i = 0;
        for (const cJSON *c = lists[l]->child; c; c = c->next, ++i) {
            res = l == 0 ? read_constraint(r, c, i, edits) : read_region(r, c, i, edits);
            if (res != DRIFT_OK) {
                return res;
            }
        }
    }
    return DRIFT_OK;
}

drift_result drift_reflection_edits_parse(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, const char *text, size_t length,
                                          const char *name, drift_reflection_edits **out_edits)
{
    if (!out_edits || !text) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_edits = NULL;
    reader r = { .ctx = ctx, .scene = scene, .file = name ? name : "<edits>" };
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, length, &end, false);
    if (!root) {
        int line = 1;
        for (const char *p = text; end && p < end && p < text + length; ++p) {
            line += *p == '\n';
        }
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r.file, line,
                  "not valid JSON (NaN and infinities are not JSON numbers)");
        return DRIFT_ERR_PARSE;
    }
    drift__json_lines_build(ctx, root, text, length, &r.lines); // no map: lines read 0
    drift_reflection_edits *edits = NULL;
    drift_result res = drift_reflection_edits_create(ctx, scene, accel, &edits);
    if (res == DRIFT_OK) {
        res = read_root(&r, root, edits);
    }
    if (res == DRIFT_OK) {
        res = drift_reflection_edits_commit(edits);
        if (res != DRIFT_OK) {
            // Point at the constraint commit could not place.
            const cJSON *node = cJSON_GetObjectItemCaseSensitive(root, "constraints");
            node = node && edits->failed_constraint >= 0
                       ? cJSON_GetArrayItem(node, edits->failed_constraint)
                       : root;
            drift_log(ctx, DRIFT_LOG_ERROR, res, r.file, line_of(&r, node),
                      "constraint %d: its point must be on its mesh and seen from its view",
                      edits->failed_constraint);
        }
    }
    drift__json_lines_free(ctx, &r.lines);
    cJSON_Delete(root);
    if (res != DRIFT_OK) {
        drift_reflection_edits_destroy(edits);
        return res;
    }
    *out_edits = edits;
    return DRIFT_OK;
}

drift_result drift_reflection_edits_load(drift_context *ctx, const drift_scene *scene,
                                         const drift_accel *accel, const char *path,
                                         drift_reflection_edits **out_edits)
{
    if (!path || !out_edits) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_edits = NULL;
    char why[128];
    FILE *f = drift_input_fopen(path, why, sizeof why);
    if (!f) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "cannot open: %s", why);
        return DRIFT_ERR_IO;
    }
    char *text = drift_alloc(ctx, MAX_EDIT_FILE_BYTES + 1);
    size_t length = text ? fread(text, 1, MAX_EDIT_FILE_BYTES + 1, f) : 0;
    bool failed = ferror(f) != 0;
    fclose(f);
    if (!text) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (failed || length > MAX_EDIT_FILE_BYTES) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0,
                  failed ? "cannot read" : "larger than an edit file can be");
        drift_free(ctx, text);
        return DRIFT_ERR_IO;
    }
    drift_result res =
        drift_reflection_edits_parse(ctx, scene, accel, text, length, path, out_edits);
    drift_free(ctx, text);
    return res;
}

// --- WRITING ---

static cJSON *vec3_json(drift_vec3 v)
{
    const double values[3] = { (double)v.x, (double)v.y, (double)v.z };
    return cJSON_CreateDoubleArray(values, 3);
}

static cJSON *mesh_json(const drift_scene *scene, uint32_t mesh)
{
    const char *name = scene->meshes[mesh].name;
    for (uint32_t m = 0; m < scene->mesh_count && name[0]; ++m) {
        if (m != mesh && strcmp(scene->meshes[m].name, name) == 0) {
            return cJSON_CreateNumber(mesh); // the name is not unique: the index
        }
    }
    return name[0] ? cJSON_CreateString(name) : cJSON_CreateNumber(mesh);
}

drift_result drift_reflection_edits_save(const drift_reflection_edits *edits, const char *path)
{
    if (!edits || !path) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "distance",
                            edits->distance == DRIFT_EDIT_DISTANCE_GEODESIC ? "geodesic"
                                                                            : "euclidean");
    cJSON *constraints = cJSON_AddArrayToObject(root, "constraints");
    for (uint32_t i = 0; i < edits->constraint_count; ++i) {
        const drift_reflection_constraint *c = &edits->constraints[i].desc;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToObject(o, "mesh", mesh_json(edits->scene, c->mesh));
        cJSON_AddItemToObject(o, "point", vec3_json(c->point));
        cJSON_AddItemToObject(o, "target", vec3_json(c->target));
        cJSON_AddItemToObject(o, "view", vec3_json(c->view));
        cJSON_AddItemToArray(constraints, o);
    }
    cJSON *regions = cJSON_AddArrayToObject(root, "regions");
    static const char *const type_names[DRIFT_EDIT_REGION_TYPE_COUNT] = { "euclidean", "geodesic",
                                                                          "mask" };
    for (uint32_t i = 0; i < edits->region_count; ++i) {
        const drift_reflection_region *g = &edits->regions[i].desc;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "type", type_names[g->type]);
        if (g->type != DRIFT_EDIT_REGION_EUCLIDEAN) {
            cJSON_AddItemToObject(o, "mesh", mesh_json(edits->scene, g->mesh));
        }
        if (g->type == DRIFT_EDIT_REGION_MASK) {
            cJSON *list = cJSON_AddArrayToObject(o, "vertices");
            for (uint32_t v = 0; v < g->mask_vertex_count; ++v) {
                cJSON_AddItemToArray(list, cJSON_CreateNumber(g->mask_vertices[v]));
            }
        } else {
            cJSON_AddItemToObject(o, "centre", vec3_json(g->centre));
            cJSON_AddNumberToObject(o, "radius", (double)g->radius);
        }
        cJSON_AddNumberToObject(o, "border", (double)g->border);
        cJSON_AddItemToArray(regions, o);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    char temp[4096];
    int n = snprintf(temp, sizeof(temp), "%s.tmp", path);
    drift_result res = DRIFT_OK;
    FILE *f = n > 0 && (size_t)n < sizeof(temp) ? fopen(temp, "wb") : NULL;
    if (!f || fputs(text, f) < 0 || fputc('\n', f) == EOF) {
        res = DRIFT_ERR_IO;
    }
    if (f && fclose(f) != 0) {
        res = DRIFT_ERR_IO;
    }
    if (res == DRIFT_OK && rename(temp, path) != 0) {
        res = DRIFT_ERR_IO;
    }
    if (res != DRIFT_OK) {
        if (f) {
            remove(temp);
        }
        drift_log(edits->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "cannot write");
    }
    cJSON_free(text);
    return res;
}
