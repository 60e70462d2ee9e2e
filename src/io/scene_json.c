// drift scene files (.json; format in docs/scene-format.md), parsed with cJSON.
//
// cJSON keeps no source positions, so before interpreting the tree a small scanner records
// where every JSON value starts. Values appear in the text in the same order as a pre-order
// walk of cJSON's tree, which pairs each cJSON node with its line. Messages can then name
// "file:line" for any key the reader complains about.
#include "io/json_lines.h"
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Largest counts a scene file may list (far above real scenes; keeps a hostile file small).
#define MAX_JSON_MESHES    65536
#define MAX_JSON_MATERIALS 65536
#define KEY_PATH_MAX       256

typedef struct json_reader {
    drift_context *ctx;
    drift_scene *scene;
    const char *file;        // name in messages
    const char *base_dir;    // paths in the file are relative to this
    drift__json_lines lines; // every node's line
    uint32_t material_count; // the file's materials: scene materials 0 .. material_count - 1
    drift__texture_cache textures;
    bool file_camera_found;
    drift_camera file_camera;
} json_reader;

// --- SOURCE POSITIONS ---

static int line_of(const json_reader *r, const cJSON *node)
{
    return drift__json_lines_find(&r->lines, node);
}

// --- MESSAGES ---

#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
static drift_result
report(const json_reader *r, drift_log_level level, const cJSON *node, drift_result code,
       const char *fmt, ...)
{
    char message[768];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof(message), fmt, args);
    va_end(args);
    drift_log(r->ctx, level, code, r->file, line_of(r, node), "%s", message);
    return code;
}

#define FAIL(r, node, code, ...) report((r), DRIFT_LOG_ERROR, (node), (code), __VA_ARGS__)

// Key paths only label messages: a path too long for the buffer ends in "..." instead.
static void mark_truncation(char *out, int written)
{
    if (written < 0 || written >= KEY_PATH_MAX) {
        memcpy(out + KEY_PATH_MAX - 4, "...", 4);
    }
}

static void key_path(char *out, const char *parent, const char *key)
{
    if (parent && parent[0]) {
        mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s.%s", parent, key));
    } else {
        mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s", key));
    }
}

static void index_path(char *out, const char *parent, size_t index)
{
    mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s[%zu]", parent, index));
}

static const char *type_name(const cJSON *item)
{
    if (cJSON_IsObject(item)) {
        return "an object";
    }
    if (cJSON_IsArray(item)) {
        return "an array";
    }
    if (cJSON_IsString(item)) {
        return "a string";
    }
    if (cJSON_IsNumber(item)) {
        return "a number";
    }
    if (cJSON_IsBool(item)) {
        return "a boolean";
    }
    return "null";
}

// --- TYPED READS ---
// Each reads obj[key] into *out. Absent optional keys leave *out as it is. Wrong JSON
// types are DRIFT_ERR_PARSE; values out of range are DRIFT_ERR_INVALID_ARGUMENT.

static drift_result expect_object(const json_reader *r, const cJSON *item, const char *path)
{
    if (!cJSON_IsObject(item)) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be an object, not %s", path,
                    type_name(item));
    }
    return DRIFT_OK;
}

static int compare_key(const void *a, const void *b)
{
    return strcmp((*(const cJSON *const *)a)->string, (*(const cJSON *const *)b)->string);
}

// Duplicate keys are errors: cJSON would silently use the first. Sorting keeps this
// O(n log n) for objects with many keys (a materials table).
static drift_result check_duplicates(const json_reader *r, const cJSON *obj, const char *path)
{
    size_t n = 0;
    for (const cJSON *c = obj->child; c; c = c->next) {
        n++;
    }
    if (n < 2) {
        return DRIFT_OK;
    }
    const cJSON **keys = drift_alloc(r->ctx, n * sizeof(const cJSON *));
    if (!keys) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    size_t i = 0;
    for (const cJSON *c = obj->child; c; c = c->next) {
        keys[i++] = c;
    }
    qsort(keys, n, sizeof(const cJSON *), compare_key);
    drift_result res = DRIFT_OK;
    for (i = 1; i < n; ++i) {
        if (strcmp(keys[i - 1]->string, keys[i]->string) == 0) {
            // Report the later of the two in the file.
            const cJSON *later =
                line_of(r, keys[i]) >= line_of(r, keys[i - 1]) ? keys[i] : keys[i - 1];
            char full[KEY_PATH_MAX];
            key_path(full, path, later->string);
            res = FAIL(r, later, DRIFT_ERR_PARSE, "duplicate key '%s'", full);
            break;
        }
    }
    drift_free(r->ctx, keys);
    return res;
}

// Warns about keys that are not rows of `object` in the key table (scene_json_keys.c; NULL:
// any key is allowed) and fails on duplicate keys.
static drift_result check_keys(const json_reader *r, const cJSON *obj, const char *path,
                               const char *object)
{
    drift_result res = check_duplicates(r, obj, path);
    if (res != DRIFT_OK || !object) {
        return res;
    }
    for (const cJSON *c = obj->child; c; c = c->next) {
        if (!drift__json_key_known(object, c->string)) {
            char full[KEY_PATH_MAX];
            key_path(full, path, c->string);
            report(r, DRIFT_LOG_WARNING, c, DRIFT_ERR_PARSE, "unknown key '%s' (ignored)", full);
        }
    }
    return DRIFT_OK;
}

#define CHECK_KEYS(r, obj, path, object) check_keys((r), (obj), (path), (object))

static drift_result missing(const json_reader *r, const cJSON *obj, const char *path,
                            const char *key)
{
    char full[KEY_PATH_MAX];
    key_path(full, path, key);
    return FAIL(r, obj, DRIFT_ERR_PARSE, "missing required key '%s'", full);
}

static drift_result number_value(const json_reader *r, const cJSON *item, const char *path,
                                 double lo, double hi, double *out)
{
    if (!cJSON_IsNumber(item)) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be a number, not %s", path, type_name(item));
    }
    double v = item->valuedouble;
    if (!isfinite(v)) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s is not a finite number", path);
    }
    if (v < lo || v > hi) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s = %g is outside [%g, %g]", path, v, lo,
                    hi);
    }
    *out = v;
    return DRIFT_OK;
}

static drift_result read_number(const json_reader *r, const cJSON *obj, const char *path,
                                const char *key, bool required, double lo, double hi, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        return required ? missing(r, obj, path, key) : DRIFT_OK;
    }
    char full[KEY_PATH_MAX];
    key_path(full, path, key);
    return number_value(r, item, full, lo, hi, out);
}

static drift_result read_float(const json_reader *r, const cJSON *obj, const char *path,
                               const char *key, bool required, double lo, double hi, float *out)
{
    double v = (double)*out;
    drift_result res = read_number(r, obj, path, key, required, lo, hi, &v);
    *out = (float)v;
    return res;
}

static drift_result read_int(const json_reader *r, const cJSON *obj, const char *path,
                             const char *key, bool required, int32_t lo, int32_t hi, int32_t *out)
{
    double v = *out;
    drift_result res = read_number(r, obj, path, key, required, lo, hi, &v);
    if (res != DRIFT_OK) {
        return res;
    }
    if (v != floor(v)) {
        char full[KEY_PATH_MAX];
        key_path(full, path, key);
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(obj, key), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s must be a whole number, got %g", full, v);
    }
    *out = (int32_t)v;
    return DRIFT_OK;
}

typedef enum vec3_kind {
    VEC3_ANY,      // position: any finite value
    VEC3_COLOR,    // colour: components >= 0; a single number means grey
    VEC3_DIRECTION // direction: not all zero
} vec3_kind;

static drift_result read_vec3(const json_reader *r, const cJSON *obj, const char *path,
                              const char *key, bool required, vec3_kind kind, drift_vec3 *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        return required ? missing(r, obj, path, key) : DRIFT_OK;
    }
    char full[KEY_PATH_MAX];
    key_path(full, path, key);
    // Positions and directions within the scene's coordinate range (DRIFT_SCENE_COORD_MAX).
    double lo = kind == VEC3_COLOR ? 0.0 : -DRIFT_SCENE_COORD_MAX;
    double hi = kind == VEC3_COLOR ? (double)FLT_MAX : DRIFT_SCENE_COORD_MAX;
    double v[3];
    if (kind == VEC3_COLOR && cJSON_IsNumber(item)) {
        drift_result res = number_value(r, item, full, lo, hi, &v[0]);
        if (res != DRIFT_OK) {
            return res;
        }
        *out = drift_vec3_splat((float)v[0]);
        return DRIFT_OK;
    }
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be an array of 3 numbers%s", full,
                    kind == VEC3_COLOR ? " (or one number)" : "");
    }
    int k = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++k) {
        char element[KEY_PATH_MAX];
        index_path(element, full, (size_t)k);
        drift_result res = number_value(r, c, element, lo, hi, &v[k]);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    drift_vec3 result = drift_vec3_make((float)v[0], (float)v[1], (float)v[2]);
    if (kind == VEC3_DIRECTION && !(drift_vec3_length(result) > 0.0f)) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s must not be the zero vector", full);
    }
    *out = result;
    return DRIFT_OK;
}

static drift_result read_string(const json_reader *r, const cJSON *obj, const char *path,
                                const char *key, bool required, const char **out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        return required ? missing(r, obj, path, key) : DRIFT_OK;
    }
    char full[KEY_PATH_MAX];
    key_path(full, path, key);
    if (!cJSON_IsString(item) || !item->valuestring) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be a string, not %s", full, type_name(item));
    }
    if (!item->valuestring[0]) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s must not be empty", full);
    }
    *out = item->valuestring;
    return DRIFT_OK;
}

// Joins a path from the file with the file's folder; fails when too long.
static drift_result resolve_path(const json_reader *r, const cJSON *node, const char *relative,
                                 char *out)
{
    if (!drift__path_join(r->base_dir, relative, out, DRIFT__PATH_MAX)) {
        return FAIL(r, node, DRIFT_ERR_INVALID_ARGUMENT, "path '%.64s...' is too long", relative);
    }
    return DRIFT_OK;
}

static drift_result load_texture(json_reader *r, const cJSON *obj, const char *path,
                                 const char *key, uint32_t *out_index)
{
    const char *rel = NULL;
    drift_result res = read_string(r, obj, path, key, false, &rel);
    if (res != DRIFT_OK || !rel) {
        return res;
    }
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char full[DRIFT__PATH_MAX];
    res = resolve_path(r, item, rel, full);
    if (res != DRIFT_OK) {
        return res;
    }
    return drift__texture_cache_get(r->scene, &r->textures, full, r->file, line_of(r, item),
                                    out_index);
}

// --- MATERIALS ---

// type "ggx" (docs/materials.md): diffuse is the base colour; roughness is glTF's perceptual
// roughness (alpha = roughness^2); metal names a measured conductor (and makes it metallic).
static drift_result read_ggx_material(json_reader *r, const cJSON *item, const char *path)
{
    const char *unused = cJSON_HasObjectItem(item, "specular")            ? "specular"
                         : cJSON_HasObjectItem(item, "exponent")          ? "exponent"
                         : cJSON_HasObjectItem(item, "diffuse_roughness") ? "diffuse_roughness"
                                                                          : NULL;
    if (unused) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, unused), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s: a ggx material takes no '%s'", path, unused);
    }
    drift_material m = drift_material_make(drift_vec3_splat(0.8f));
    snprintf(m.name, sizeof(m.name), "%s", item->string);
    m.type = DRIFT_MATERIAL_GGX;
    float roughness = 0.5f;
    const char *metal = NULL;
    drift_result res;
    if ((res = read_vec3(r, item, path, "diffuse", false, VEC3_COLOR, &m.diffuse)) != DRIFT_OK ||
        (res = read_vec3(r, item, path, "emission", false, VEC3_COLOR, &m.emission)) != DRIFT_OK ||
        (res = load_texture(r, item, path, "diffuse_texture", &m.diffuse_texture)) != DRIFT_OK ||
        (res = read_float(r, item, path, "roughness", false, 0.0, 1.0, &roughness)) != DRIFT_OK ||
        (res = read_float(r, item, path, "metallic", false, 0.0, 1.0, &m.ggx.metallic)) !=
            DRIFT_OK ||
        (res = read_float(r, item, path, "transmission", false, 0.0, 1.0, &m.ggx.transmission)) !=
            DRIFT_OK ||
        (res = read_float(r, item, path, "ior", false, 1.0, 10.0, &m.ggx.ior)) != DRIFT_OK ||
        (res = read_vec3(r, item, path, "edge_tint", false, VEC3_COLOR, &m.ggx.edge_tint)) !=
            DRIFT_OK ||
        (res = read_string(r, item, path, "metal", false, &metal)) != DRIFT_OK) {
        return res;
    }
    m.ggx.alpha = roughness * roughness;
    const cJSON *thin = cJSON_GetObjectItemCaseSensitive(item, "thin");
    if (thin && !cJSON_IsBool(thin)) {
        return FAIL(r, thin, DRIFT_ERR_PARSE, "%s.thin must be true or false", path);
    }
    m.ggx.thin = cJSON_IsTrue(thin);
    if (metal && !drift_ggx_named_metal(metal, &m.ggx)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "metal"), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.metal '%s' is not one of Au, Ag, Cu, Al (gold, silver, copper, aluminium)",
                    path, metal);
    }
    res = drift_scene_add_material(r->scene, &m, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s is not valid", path);
    }
    return DRIFT_OK;
}

static drift_result read_material(json_reader *r, const cJSON *item)
{
    char path[KEY_PATH_MAX];
    key_path(path, "materials", item->string);
    drift_result res = expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    res = CHECK_KEYS(r, item, path, "material");
    if (res != DRIFT_OK) {
        return res;
    }
    if (strlen(item->string) >= DRIFT_NAME_MAX) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT,
                    "material name '%.32s...' is longer than %d bytes", item->string,
                    DRIFT_NAME_MAX - 1);
    }
    const char *type = "diffuse";
    res = read_string(r, item, path, "type", false, &type);
    if (res != DRIFT_OK) {
        return res;
    }
    bool is_diffuse = strcmp(type, "diffuse") == 0;
    bool is_glossy = strcmp(type, "glossy") == 0;
    bool is_mirror = strcmp(type, "mirror") == 0;
    const cJSON *type_item = cJSON_GetObjectItemCaseSensitive(item, "type");
    if (strcmp(type, "ggx") == 0) {
        return read_ggx_material(r, item, path);
    }
    if (!is_diffuse && !is_glossy && !is_mirror) {
        return FAIL(r, type_item, DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.type '%s' is not one of diffuse, glossy, mirror, ggx", path, type);
    }
    static const char *const ggx_only[] = { "roughness", "metallic",  "transmission", "ior",
                                            "metal",     "edge_tint", "thin" };
    for (size_t k = 0; k < sizeof(ggx_only) / sizeof(ggx_only[0]); ++k) {
        if (cJSON_HasObjectItem(item, ggx_only[k])) {
            return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, ggx_only[k]),
                        DRIFT_ERR_INVALID_ARGUMENT, "%s: a %s material takes no '%s'", path, type,
                        ggx_only[k]);
        }
    }
    // Keys that the type has no use for are mistakes, not something to ignore quietly.
    const char *unused = NULL;
    if (is_diffuse && cJSON_HasObjectItem(item, "specular")) {
        unused = "specular";
    } else if (!is_glossy && cJSON_HasObjectItem(item, "exponent")) {
        unused = "exponent";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse")) {
        unused = "diffuse";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse_texture")) {
        unused = "diffuse_texture";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse_roughness")) {
        unused = "diffuse_roughness";
    }
    if (unused) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, unused), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s: a %s material takes no '%s'", path, type, unused);
    }
    drift_material m = drift_material_make(drift_vec3_splat(is_diffuse ? 0.8f : 0.0f));
    snprintf(m.name, sizeof(m.name), "%s", item->string);
    m.type = is_mirror ? DRIFT_MATERIAL_MIRROR : DRIFT_MATERIAL_DEFAULT;
    if (is_mirror) {
        m.specular = drift_vec3_splat(1.0f);
    }
    if ((res = read_vec3(r, item, path, "diffuse", false, VEC3_COLOR, &m.diffuse)) != DRIFT_OK ||
        (res = read_vec3(r, item, path, "specular", is_glossy, VEC3_COLOR, &m.specular)) !=
            DRIFT_OK ||
        (res = read_float(r, item, path, "exponent", is_glossy, 1e-3, 1e7, &m.exponent)) !=
            DRIFT_OK ||
        (res = read_vec3(r, item, path, "emission", false, VEC3_COLOR, &m.emission)) != DRIFT_OK ||
        (res = load_texture(r, item, path, "diffuse_texture", &m.diffuse_texture)) != DRIFT_OK ||
        (res = read_float(r, item, path, "diffuse_roughness", false, 0.0, 1.0,
                          &m.diffuse_roughness)) != DRIFT_OK) {
        return res;
    }
    // A diffuse roughness asks for Burley's diffuse (what glTF and Blender materials use).
    if (cJSON_HasObjectItem(item, "diffuse_roughness")) {
        m.diffuse_model = DRIFT_DIFFUSE_BURLEY;
    }
    res = drift_scene_add_material(r->scene, &m, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s is not valid", path);
    }
    return DRIFT_OK;
}

static drift_result read_materials(json_reader *r, const cJSON *root)
{
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(root, "materials");
    if (!materials) {
        return DRIFT_OK;
    }
    drift_result res = expect_object(r, materials, "materials");
    if (res != DRIFT_OK) {
        return res;
    }
    int count = cJSON_GetArraySize(materials);
    if (count > MAX_JSON_MATERIALS) {
        return FAIL(r, materials, DRIFT_ERR_INVALID_ARGUMENT,
                    "materials lists %d materials (at most %d)", count, MAX_JSON_MATERIALS);
    }
    // Material names are keys, so duplicates are caught by check_keys' duplicate test.
    res = check_keys(r, materials, "materials", NULL);
    if (res != DRIFT_OK) {
        return res;
    }
    // They are read before anything else adds materials, so the n-th is scene material n.
    for (const cJSON *c = materials->child; c; c = c->next) {
        res = read_material(r, c);
        if (res != DRIFT_OK) {
            return res;
        }
        r->material_count++;
    }
    return DRIFT_OK;
}

static bool find_material(const json_reader *r, const char *name, uint32_t *out_index)
{
    // Names are whole (read_material rejects any DRIFT_NAME_MAX would cut) and unique.
    for (uint32_t i = 0; i < r->material_count; ++i) {
        if (strcmp(r->scene->materials[i].name, name) == 0) {
            *out_index = i;
            return true;
        }
    }
    return false;
}

// --- MESHES ---

// Rotation by `degrees` about `axis` (right-handed: counter-clockwise looking down the axis).
static drift__mat4 mat4_rotation(drift_vec3 axis, float degrees)
{
    drift_vec3 a = drift_vec3_normalize(axis);
    float t = degrees * DRIFT_PI / 180.0f;
    float c = cosf(t), s = sinf(t), k = 1.0f - c;
    return (drift__mat4){
        { k * a.x * a.x + c, k * a.x * a.y - s * a.z, k * a.x * a.z + s * a.y, 0.0f, //
          k * a.x * a.y + s * a.z, k * a.y * a.y + c, k * a.y * a.z - s * a.x, 0.0f, //
          k * a.x * a.z - s * a.y, k * a.y * a.z + s * a.x, k * a.z * a.z + c, 0.0f, //
          0.0f, 0.0f, 0.0f, 1.0f }
    };
}

// "transform": { translate, rotate: { axis, degrees }, scale } (applied scale, rotate,
// translate) or { matrix: 16 numbers, row-major }.
static drift_result read_transform(const json_reader *r, const cJSON *obj, const char *parent,
                                   drift__mat4 *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, "transform");
    *out = drift__mat4_identity();
    if (!item) {
        return DRIFT_OK;
    }
    char path[KEY_PATH_MAX];
    key_path(path, parent, "transform");
    drift_result res = expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    res = CHECK_KEYS(r, item, path, "transform");
    if (res != DRIFT_OK) {
        return res;
    }
    const cJSON *matrix = cJSON_GetObjectItemCaseSensitive(item, "matrix");
    if (matrix) {
        char mpath[KEY_PATH_MAX];
        key_path(mpath, path, "matrix");
        if (cJSON_HasObjectItem(item, "translate") || cJSON_HasObjectItem(item, "rotate") ||
            cJSON_HasObjectItem(item, "scale")) {
            return FAIL(r, matrix, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s: give either matrix or translate/rotate/scale, not both", path);
        }
        if (!cJSON_IsArray(matrix) || cJSON_GetArraySize(matrix) != 16) {
            return FAIL(r, matrix, DRIFT_ERR_PARSE, "%s must be an array of 16 numbers", mpath);
        }
        int k = 0;
        for (const cJSON *c = matrix->child; c; c = c->next, ++k) {
            char element[KEY_PATH_MAX];
            index_path(element, mpath, (size_t)k);
            double v;
            res = number_value(r, c, element, -(double)FLT_MAX, (double)FLT_MAX, &v);
            if (res != DRIFT_OK) {
                return res;
            }
            out->m[k] = (float)v;
        }
        if (out->m[12] != 0.0f || out->m[13] != 0.0f || out->m[14] != 0.0f || out->m[15] != 1.0f) {
            return FAIL(r, matrix, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s must be affine (last row 0 0 0 1; the matrix is row-major)", mpath);
        }
        return DRIFT_OK;
    }
    drift_vec3 translate = drift_vec3_splat(0.0f), scale = drift_vec3_splat(1.0f);
    if ((res = read_vec3(r, item, path, "translate", false, VEC3_ANY, &translate)) != DRIFT_OK) {
        return res;
    }
    const cJSON *scale_item = cJSON_GetObjectItemCaseSensitive(item, "scale");
    if (scale_item) {
        char spath[KEY_PATH_MAX];
        key_path(spath, path, "scale");
        if (cJSON_IsNumber(scale_item)) {
            double s;
            res = number_value(r, scale_item, spath, -(double)FLT_MAX, (double)FLT_MAX, &s);
            scale = drift_vec3_splat((float)s);
        } else {
            res = read_vec3(r, item, path, "scale", false, VEC3_ANY, &scale);
        }
        if (res != DRIFT_OK) {
            return res;
        }
        if (scale.x == 0.0f || scale.y == 0.0f || scale.z == 0.0f) {
            return FAIL(r, scale_item, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s must be non-zero on every axis", spath);
        }
    }
    drift__mat4 rotation = drift__mat4_identity();
    const cJSON *rotate = cJSON_GetObjectItemCaseSensitive(item, "rotate");
    if (rotate) {
        char rpath[KEY_PATH_MAX];
        key_path(rpath, path, "rotate");
        if ((res = expect_object(r, rotate, rpath)) != DRIFT_OK ||
            (res = CHECK_KEYS(r, rotate, rpath, "transform.rotate")) != DRIFT_OK) {
            return res;
        }
        drift_vec3 axis = drift_vec3_make(0, 1, 0);
        float degrees = 0.0f;
        if ((res = read_vec3(r, rotate, rpath, "axis", true, VEC3_DIRECTION, &axis)) != DRIFT_OK ||
            (res = read_float(r, rotate, rpath, "degrees", true, -1e6, 1e6, &degrees)) !=
                DRIFT_OK) {
            return res;
        }
        rotation = mat4_rotation(axis, degrees);
    }
    drift__mat4 s = { { scale.x, 0, 0, 0, 0, scale.y, 0, 0, 0, 0, scale.z, 0, 0, 0, 0, 1 } };
    drift__mat4 t = { { 1, 0, 0, translate.x, //
                        0, 1, 0, translate.y, //
                        0, 0, 1, translate.z, //
                        0, 0, 0, 1 } };
    drift__mat4 rs = drift__mat4_mul(&rotation, &s);
    *out = drift__mat4_mul(&t, &rs);
    return DRIFT_OK;
}

static drift_result read_mesh(json_reader *r, const cJSON *item, const char *path)
{
    drift_result res = expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    if ((res = CHECK_KEYS(r, item, path, "mesh")) != DRIFT_OK) {
        return res;
    }
    const char *rel = NULL, *material_name = NULL, *camera = NULL;
    if ((res = read_string(r, item, path, "path", true, &rel)) != DRIFT_OK ||
        (res = read_string(r, item, path, "material", false, &material_name)) != DRIFT_OK ||
        (res = read_string(r, item, path, "camera", false, &camera)) != DRIFT_OK) {
        return res;
    }
    const cJSON *path_item = cJSON_GetObjectItemCaseSensitive(item, "path");
    uint32_t material = DRIFT_INVALID_INDEX;
    if (material_name && !find_material(r, material_name, &material)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "material"),
                    DRIFT_ERR_INVALID_ARGUMENT, "%s.material '%s' is not in materials", path,
                    material_name);
    }
    drift__mat4 transform;
    if ((res = read_transform(r, item, path, &transform)) != DRIFT_OK) {
        return res;
    }
    char ext[16];
    bool gz = false;
    drift__path_extension(rel, ext, sizeof(ext), &gz);
    if (!drift__is_mesh_extension(ext)) {
        char formats[128];
        drift__scene_formats_text(formats, sizeof formats, true);
        return FAIL(r, path_item, DRIFT_ERR_UNSUPPORTED, "%s.path '%s': meshes must be %s", path,
                    rel, formats);
    }
    char full[DRIFT__PATH_MAX];
    if ((res = resolve_path(r, path_item, rel, full)) != DRIFT_OK) {
        return res;
    }
    drift__import_info info;
    drift__import_params params = { .path = full,
                                    .where = r->file,
                                    .line = line_of(r, path_item),
                                    .transform = &transform,
                                    .material_override = material,
                                    .textures = &r->textures,
                                    .camera = camera };
    res = drift__scene_import_mesh_file(r->scene, &params, &info);
    if (res != DRIFT_OK) {
        return res;
    }
    if (info.has_camera && !r->file_camera_found) {
        r->file_camera_found = true;
        r->file_camera = info.camera;
    }
    return DRIFT_OK;
}

static drift_result read_meshes(json_reader *r, const cJSON *root)
{
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    if (!meshes) {
        return DRIFT_OK;
    }
    if (!cJSON_IsArray(meshes)) {
        return FAIL(r, meshes, DRIFT_ERR_PARSE, "meshes must be an array, not %s",
                    type_name(meshes));
    }
    if (cJSON_GetArraySize(meshes) > MAX_JSON_MESHES) {
        return FAIL(r, meshes, DRIFT_ERR_INVALID_ARGUMENT, "meshes lists more than %d files",
                    MAX_JSON_MESHES);
    }
    size_t i = 0;
    for (const cJSON *c = meshes->child; c; c = c->next, ++i) {
        char path[KEY_PATH_MAX];
        index_path(path, "meshes", i);
        drift_result res = read_mesh(r, c, path);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    return DRIFT_OK;
}

// --- LIGHTS ---

static drift_result read_light(json_reader *r, const cJSON *item, const char *path)
{
    drift_result res = expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    const char *type = NULL;
    if ((res = read_string(r, item, path, "type", true, &type)) != DRIFT_OK) {
        return res;
    }
    drift_light l = { 0 };
    if (strcmp(type, "point") == 0) {
        l.type = DRIFT_LIGHT_POINT;
        if ((res = CHECK_KEYS(r, item, path, "light point")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "position", true, VEC3_ANY, &l.position)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "intensity", true, VEC3_COLOR, &l.color)) != DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "spot") == 0) {
        l.type = DRIFT_LIGHT_SPOT;
        float inner = 0.0f, outer = 0.0f;
        if ((res = CHECK_KEYS(r, item, path, "light spot")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "position", true, VEC3_ANY, &l.position)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "direction", true, VEC3_DIRECTION, &l.direction)) !=
                DRIFT_OK ||
            (res = read_vec3(r, item, path, "intensity", true, VEC3_COLOR, &l.color)) != DRIFT_OK ||
            (res = read_float(r, item, path, "outer_angle", true, 0.0, 180.0, &outer)) !=
                DRIFT_OK ||
            (res = read_float(r, item, path, "inner_angle", false, 0.0, 180.0, &inner)) !=
                DRIFT_OK) {
            return res;
        }
        l.spot_inner = inner * DRIFT_PI / 180.0f;
        l.spot_outer = outer * DRIFT_PI / 180.0f;
    } else if (strcmp(type, "directional") == 0) {
        l.type = DRIFT_LIGHT_DIRECTIONAL;
        if ((res = CHECK_KEYS(r, item, path, "light directional")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "direction", true, VEC3_DIRECTION, &l.direction)) !=
                DRIFT_OK ||
            (res = read_vec3(r, item, path, "irradiance", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "quad") == 0) {
        l.type = DRIFT_LIGHT_QUAD;
        if ((res = CHECK_KEYS(r, item, path, "light quad")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "corner", true, VEC3_ANY, &l.position)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "edge_u", true, VEC3_ANY, &l.edge_u)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "edge_v", true, VEC3_ANY, &l.edge_v)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) != DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "disk") == 0) {
        l.type = DRIFT_LIGHT_DISK;
        if ((res = CHECK_KEYS(r, item, path, "light disk")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "center", true, VEC3_ANY, &l.position)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "normal", true, VEC3_DIRECTION, &l.direction)) !=
                DRIFT_OK ||
            (res = read_float(r, item, path, "radius", true, -(double)FLT_MAX, (double)FLT_MAX,
                              &l.radius)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) != DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "sphere") == 0) {
        l.type = DRIFT_LIGHT_SPHERE;
        if ((res = CHECK_KEYS(r, item, path, "light sphere")) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "center", true, VEC3_ANY, &l.position)) != DRIFT_OK ||
            (res = read_float(r, item, path, "radius", true, -(double)FLT_MAX, (double)FLT_MAX,
                              &l.radius)) != DRIFT_OK ||
            (res = read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) != DRIFT_OK) {
            return res;
        }
    } else {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "type"), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.type '%s' is not one of point, spot, directional, quad, disk, sphere", path,
                    type);
    }
    // drift_scene_add_light checks the values (zero area, cone angles) and logs the reason;
    // this adds where in the file the light is.
    res = drift_scene_add_light(r->scene, &l, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s (%s light) is not valid", path, type);
    }
    return DRIFT_OK;
}

static drift_result read_lights(json_reader *r, const cJSON *root)
{
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (!lights) {
        return DRIFT_OK;
    }
    if (!cJSON_IsArray(lights)) {
        return FAIL(r, lights, DRIFT_ERR_PARSE, "lights must be an array, not %s",
                    type_name(lights));
    }
    size_t i = 0;
    for (const cJSON *c = lights->child; c; c = c->next, ++i) {
        char path[KEY_PATH_MAX];
        index_path(path, "lights", i);
        drift_result res = read_light(r, c, path);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    return DRIFT_OK;
}

// --- ENVIRONMENT AND CAMERA ---

static drift_result read_environment(json_reader *r, const cJSON *root)
{
    const cJSON *env = cJSON_GetObjectItemCaseSensitive(root, "environment");
    if (!env) {
        return DRIFT_OK;
    }
    const char *path = "environment";
    drift_result res = expect_object(r, env, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, env, path, "environment")) != DRIFT_OK) {
        return res;
    }
    bool has_map = cJSON_HasObjectItem(env, "map");
    if (has_map && cJSON_HasObjectItem(env, "color")) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(env, "color"), DRIFT_ERR_INVALID_ARGUMENT,
                    "environment: give either color or map (scaled by multiplier), not both");
    }
    if (!has_map && cJSON_HasObjectItem(env, "multiplier")) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(env, "multiplier"),
                    DRIFT_ERR_INVALID_ARGUMENT, "environment.multiplier needs a map");
    }
    drift_environment e = { .color = drift_vec3_splat(has_map ? 1.0f : 0.0f),
                            .texture = DRIFT_INVALID_INDEX };
    if ((res = read_vec3(r, env, path, "color", false, VEC3_COLOR, &e.color)) != DRIFT_OK ||
        (res = read_vec3(r, env, path, "multiplier", false, VEC3_COLOR, &e.color)) != DRIFT_OK ||
        (res = load_texture(r, env, path, "map", &e.texture)) != DRIFT_OK) {
        return res;
    }
    r->scene->environment = e;
    return DRIFT_OK;
}

static drift_result read_camera(json_reader *r, const cJSON *root, bool *out_found)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    *out_found = cam != NULL;
    if (!cam) {
        return DRIFT_OK;
    }
    const char *path = "camera";
    drift_result res = expect_object(r, cam, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, cam, path, "camera")) != DRIFT_OK) {
        return res;
    }
    drift_camera c = { .up = drift_vec3_make(0, 1, 0), .width = 512, .height = 512 };
    float fov_deg = 45.0f;
    if ((res = read_vec3(r, cam, path, "position", true, VEC3_ANY, &c.position)) != DRIFT_OK ||
        (res = read_vec3(r, cam, path, "target", true, VEC3_ANY, &c.target)) != DRIFT_OK ||
        (res = read_vec3(r, cam, path, "up", false, VEC3_DIRECTION, &c.up)) != DRIFT_OK ||
        (res = read_float(r, cam, path, "fov_y", false, 1e-3, 179.0, &fov_deg)) != DRIFT_OK ||
        (res = read_float(r, cam, path, "aperture_radius", false, 0.0, (double)FLT_MAX,
                          &c.aperture_radius)) != DRIFT_OK ||
        (res = read_float(r, cam, path, "focus_distance", false, 0.0, (double)FLT_MAX,
                          &c.focus_distance)) != DRIFT_OK ||
        (res = read_int(r, cam, path, "width", false, 1, DRIFT_IMAGE_MAX_DIMENSION, &c.width)) !=
            DRIFT_OK ||
        (res = read_int(r, cam, path, "height", false, 1, DRIFT_IMAGE_MAX_DIMENSION, &c.height)) !=
            DRIFT_OK) {
        return res;
    }
    c.fov_y = fov_deg * DRIFT_PI / 180.0f;
    // Commit rejects these too, but without saying where in the file they are.
    drift_vec3 forward = drift_vec3_sub(c.target, c.position);
    if (!(drift_vec3_length(forward) > 0.0f) || !isfinite(drift_vec3_length(forward))) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(cam, "target"), DRIFT_ERR_INVALID_ARGUMENT,
                    "camera.target must differ from camera.position");
    }
    if (!(drift_vec3_length(drift_vec3_cross(drift_vec3_normalize(forward),
                                             drift_vec3_normalize(c.up))) > 1e-6f)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(cam, "up"), DRIFT_ERR_INVALID_ARGUMENT,
                    "camera.up must not be parallel to the view direction");
    }
    r->scene->camera = c;
    return DRIFT_OK;
}

// --- ENTRY POINT ---

static drift_result report_syntax_error(const json_reader *r, const char *text, size_t length,
                                        const char *error_at)
{
    size_t offset = error_at && error_at >= text ? (size_t)(error_at - text) : 0;
    if (offset > length) {
        offset = length;
    }
    int line = 1;
    size_t line_start = 0;
    for (size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            line++;
            line_start = i + 1;
        }
    }
    char near[24];
    size_t n = 0;
    for (size_t i = offset; i < length && n < 20 && text[i] != '\n'; ++i) {
        unsigned char c = (unsigned char)text[i];
        near[n++] = c >= 32 && c < 127 ? (char)c : '?';
    }
    near[n] = '\0';
    int column = (int)(offset - line_start) + 1;
    // The logger gets file and line; the column goes in the text ("file:line: ... column").
    drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->file, line,
              "malformed JSON at column %d%s%s%s", column,
              offset >= length ? " (unexpected end of file)" : ", near '", n ? near : "",
              offset >= length ? "" : "'");
    return DRIFT_ERR_PARSE;
}

static drift_result read_scene(json_reader *r, const cJSON *root)
{
    drift_result res = expect_object(r, root, "the scene file");
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, root, "", "scene")) != DRIFT_OK) {
        return res;
    }
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (version && (!cJSON_IsNumber(version) || version->valuedouble != 1.0)) {
        return FAIL(r, version, DRIFT_ERR_UNSUPPORTED,
                    "version must be 1 (the only version this drift reads)");
    }
    bool has_camera = false;
    if ((res = read_materials(r, root)) != DRIFT_OK || (res = read_meshes(r, root)) != DRIFT_OK ||
        (res = read_lights(r, root)) != DRIFT_OK || (res = read_environment(r, root)) != DRIFT_OK ||
        (res = read_camera(r, root, &has_camera)) != DRIFT_OK) {
        return res;
    }
    if (!has_camera) {
        r->scene->camera = r->file_camera_found
                               ? r->file_camera
                               : drift__framing_camera(drift__scene_mesh_bounds(r->scene));
    }
    res = drift_scene_commit(r->scene);
    if (res != DRIFT_OK) {
        drift_log(r->ctx, DRIFT_LOG_ERROR, res, r->file, 0, "the scene is not valid (see above)");
        return res;
    }
    if (r->scene->light_count == 0 && !drift_scene_has_environment(r->scene)) {
        drift_log(r->ctx, DRIFT_LOG_WARNING, DRIFT_OK, r->file, 0,
                  "the scene has no lights, emitters or environment: it will render black");
    }
    return DRIFT_OK;
}

// Checks, copies and parses the text and indexes its lines: on success *out_copy (the
// terminated text the tree points into) and *out_root are the caller's to free.
static drift_result parse_document(json_reader *r, const char *text, size_t length,
                                   size_t max_bytes, char **out_copy, cJSON **out_root)
{
    *out_copy = NULL;
    *out_root = NULL;
    if (length > max_bytes) {
        drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, r->file, 0,
                  "file is larger than %zu bytes", max_bytes);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // cJSON reads up to a NUL, so an embedded NUL would hide the rest of the file.
    const char *nul = length ? memchr(text, '\0', length) : NULL;
    if (nul) {
        return report_syntax_error(r, text, length, nul);
    }
    // A terminated copy: the caller's text need not be NUL-terminated, and cJSON's
    // require_null_terminated check then rejects trailing garbage.
    char *copy = drift_alloc(r->ctx, length + 1);
    if (!copy) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (length) {
        memcpy(copy, text, length);
    }
    const char *parse_end = NULL;
    // return_parse_end points where cJSON_GetErrorPtr would, without cJSON's global state.
    cJSON *root = cJSON_ParseWithLengthOpts(copy, length + 1, &parse_end, true);
    if (!root) {
        drift_result res = report_syntax_error(r, copy, length, parse_end);
        drift_free(r->ctx, copy);
        return res;
    }
    drift_result res = drift__json_lines_build(r->ctx, root, copy, length, &r->lines);
    if (res != DRIFT_OK) {
        cJSON_Delete(root);
        drift_free(r->ctx, copy);
        return res;
    }
    *out_copy = copy;
    *out_root = root;
    return DRIFT_OK;
}

drift_result drift_scene_load_json_text(drift_context *ctx, const char *text, size_t length,
                                        const char *base_dir, const char *name_for_messages,
                                        drift_scene **out_scene)
{
    return drift__scene_load_json_text(ctx, text, length, base_dir, name_for_messages, NULL, NULL,
                                       out_scene);
}

drift_result drift__scene_load_json_text(drift_context *ctx, const char *text, size_t length,
                                         const char *base_dir, const char *name_for_messages,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene)
{
    if (!out_scene) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_scene = NULL;
    if (!text && length > 0) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    json_reader r = { .ctx = ctx,
                      .file = name_for_messages ? name_for_messages : "<memory>",
                      .base_dir = base_dir,
                      .textures = { .on_input = on_input, .user = user } };
    char *copy;
    cJSON *root;
    drift_result res = parse_document(&r, text, length, DRIFT_SCENE_MAX_FILE_BYTES, &copy, &root);
    if (res == DRIFT_OK) {
        res = drift_scene_create(ctx, &r.scene);
    }
    if (res == DRIFT_OK) {
        res = read_scene(&r, root);
    }
    cJSON_Delete(root);
    drift_free(ctx, copy);
    drift__json_lines_free(ctx, &r.lines);
    drift__texture_cache_clear(ctx, &r.textures);
    if (res != DRIFT_OK) {
        drift_scene_destroy(r.scene);
        return res;
    }
    *out_scene = r.scene;
    return DRIFT_OK;
}

// --- CAMERA VIEWS ---

// One view: a name of letters, digits, '_' and '-' (it names output files) and the camera
// fields it overrides.
static drift_result read_view(const json_reader *r, const cJSON *item, const char *path,
                              drift_camera_view *out)
{
    drift_result res = expect_object(r, item, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, item, path, "view")) != DRIFT_OK) {
        return res;
    }
    *out = (drift_camera_view){ 0 };
    const char *name = NULL;
    if ((res = read_string(r, item, path, "name", true, &name)) != DRIFT_OK) {
        return res;
    }
    static const char allowed[] =
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-";
    if (strlen(name) >= sizeof out->name || strspn(name, allowed) != strlen(name)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "name"), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.name must be 1-%zu letters, digits, '_' or '-'", path,
                    sizeof out->name - 1);
    }
    snprintf(out->name, sizeof out->name, "%s", name);
    float fov_deg = 0.0f;
    out->has_position = cJSON_GetObjectItemCaseSensitive(item, "position") != NULL;
    out->has_target = cJSON_GetObjectItemCaseSensitive(item, "target") != NULL;
    out->has_fov = cJSON_GetObjectItemCaseSensitive(item, "fov_y") != NULL;
    out->has_aperture = cJSON_GetObjectItemCaseSensitive(item, "aperture_radius") != NULL;
    if ((res = read_vec3(r, item, path, "position", false, VEC3_ANY, &out->position)) != DRIFT_OK ||
        (res = read_vec3(r, item, path, "target", false, VEC3_ANY, &out->target)) != DRIFT_OK ||
        (res = read_float(r, item, path, "fov_y", false, 0.1, 179.0, &fov_deg)) != DRIFT_OK ||
        (res = read_float(r, item, path, "aperture_radius", false, 0.0, (double)FLT_MAX,
                          &out->aperture_radius)) != DRIFT_OK) {
        return res;
    }
    out->fov_y = fov_deg * DRIFT_PI / 180.0f;
    return DRIFT_OK;
}

drift_result drift_camera_views_load_json_text(drift_context *ctx, const char *text, size_t length,
                                               const char *name_for_messages,
                                               drift_camera_view *views, uint32_t capacity,
                                               uint32_t *out_count)
{
    if (!out_count || (!text && length > 0) || (!views && capacity > 0)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_count = 0;
    json_reader r = { .ctx = ctx, .file = name_for_messages ? name_for_messages : "<memory>" };
    char *copy;
    cJSON *root;
    drift_result res =
        parse_document(&r, text, length, DRIFT_CAMERA_VIEWS_MAX_FILE_BYTES, &copy, &root);
    if (res != DRIFT_OK) {
        return res;
    }
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, "views");
    if ((res = expect_object(&r, root, "the views file")) != DRIFT_OK ||
        (res = CHECK_KEYS(&r, root, "", "views file")) != DRIFT_OK) {
        // reported
    } else if (!cJSON_IsArray(list)) {
        res = list ? FAIL(&r, list, DRIFT_ERR_PARSE, "views must be an array, not %s",
                          type_name(list))
                   : missing(&r, root, "", "views");
    } else if (cJSON_GetArraySize(list) < 1 || (uint32_t)cJSON_GetArraySize(list) > capacity) {
        res = FAIL(&r, list, DRIFT_ERR_INVALID_ARGUMENT, "views must hold 1 to %u views", capacity);
    } else {
        size_t k = 0;
        for (const cJSON *item = list->child; item && res == DRIFT_OK; item = item->next, ++k) {
            char path[KEY_PATH_MAX];
            index_path(path, "views", k);
            res = read_view(&r, item, path, &views[k]);
        }
        *out_count = res == DRIFT_OK ? (uint32_t)k : 0;
    }
    cJSON_Delete(root);
    drift_free(ctx, copy);
    drift__json_lines_free(ctx, &r.lines);
    return res;
}

drift_result drift_camera_views_load(drift_context *ctx, const char *path, drift_camera_view *views,
                                     uint32_t capacity, uint32_t *out_count)
{
    if (!path || !out_count) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_count = 0;
    char *text = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, false, path, 0, &text, &size);
    if (r == DRIFT_OK) {
        r = drift_camera_views_load_json_text(ctx, text, size, path, views, capacity, out_count);
    }
    drift_free(ctx, text);
    return r;
}

void drift_camera_view_apply(const drift_camera_view *view, drift_camera *camera)
{
    if (view->has_position) {
        camera->position = view->position;
    }
    if (view->has_target) {
        camera->target = view->target;
    }
    if (view->has_fov) {
        camera->fov_y = view->fov_y;
    }
    if (view->has_aperture) {
        camera->aperture_radius = view->aperture_radius;
    }
}
