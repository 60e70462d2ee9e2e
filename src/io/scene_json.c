// drift scene files (.json; format in docs/scene-format.md), parsed with cJSON.
//
// cJSON keeps no source positions, so before interpreting the tree a small scanner records
// where every JSON value starts. Values appear in the text in the same order as a pre-order
// walk of cJSON's tree, which pairs each cJSON node with its line. Messages can then name
// "file:line" for any key the reader complains about.
#include "scene_json_internal.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- SOURCE POSITIONS ---

int drift__json_line_of(const json_reader *r, const cJSON *node)
{
    return drift__json_lines_find(&r->lines, node);
}

// --- MESSAGES ---

#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
drift_result
drift__json_report(const json_reader *r, drift_log_level level, const cJSON *node,
                   drift_result code, const char *fmt, ...)
{
    char message[768];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof(message), fmt, args);
    va_end(args);
    drift_log(r->ctx, level, code, r->file, drift__json_line_of(r, node), "%s", message);
    return code;
}

// Key paths only label messages: a path too long for the buffer ends in "..." instead.
static void mark_truncation(char *out, int written)
{
    if (written < 0 || written >= KEY_PATH_MAX) {
        memcpy(out + KEY_PATH_MAX - 4, "...", 4);
    }
}

void drift__json_key_path(char *out, const char *parent, const char *key)
{
    if (parent && parent[0]) {
        mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s.%s", parent, key));
    } else {
        mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s", key));
    }
}

void drift__json_index_path(char *out, const char *parent, size_t index)
{
    mark_truncation(out, snprintf(out, KEY_PATH_MAX, "%s[%zu]", parent, index));
}

const char *drift__json_type_name(const cJSON *item)
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

drift_result drift__json_expect_object(const json_reader *r, const cJSON *item, const char *path)
{
    if (!cJSON_IsObject(item)) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be an object, not %s", path,
                    drift__json_type_name(item));
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
                drift__json_line_of(r, keys[i]) >= drift__json_line_of(r, keys[i - 1])
                    ? keys[i]
                    : keys[i - 1];
            char full[KEY_PATH_MAX];
            drift__json_key_path(full, path, later->string);
            res = FAIL(r, later, DRIFT_ERR_PARSE, "duplicate key '%s'", full);
            break;
        }
    }
    drift_free(r->ctx, keys);
    return res;
}

// Warns about keys that are not rows of `object` in the key table (scene_json_keys.c; NULL:
// any key is allowed) and fails on duplicate keys.
drift_result drift__json_check_keys(const json_reader *r, const cJSON *obj, const char *path,
                                    const char *object)
{
    drift_result res = check_duplicates(r, obj, path);
    if (res != DRIFT_OK || !object) {
        return res;
    }
    for (const cJSON *c = obj->child; c; c = c->next) {
        if (!drift__json_key_known(object, c->string)) {
            char full[KEY_PATH_MAX];
            drift__json_key_path(full, path, c->string);
            drift__json_report(r, DRIFT_LOG_WARNING, c, DRIFT_ERR_PARSE,
                               "unknown key '%s' (ignored)", full);
        }
    }
    return DRIFT_OK;
}

static drift_result missing(const json_reader *r, const cJSON *obj, const char *path,
                            const char *key)
{
    char full[KEY_PATH_MAX];
    drift__json_key_path(full, path, key);
    return FAIL(r, obj, DRIFT_ERR_PARSE, "missing required key '%s'", full);
}

drift_result drift__json_number_value(const json_reader *r, const cJSON *item, const char *path,
                                      double lo, double hi, double *out)
{
    if (!cJSON_IsNumber(item)) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be a number, not %s", path,
                    drift__json_type_name(item));
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
    drift__json_key_path(full, path, key);
    return drift__json_number_value(r, item, full, lo, hi, out);
}

drift_result drift__json_read_float(const json_reader *r, const cJSON *obj, const char *path,
                                    const char *key, bool required, double lo, double hi,
                                    float *out)
{
    double v = (double)*out;
    drift_result res = read_number(r, obj, path, key, required, lo, hi, &v);
    *out = (float)v;
    return res;
}

drift_result drift__json_read_int(const json_reader *r, const cJSON *obj, const char *path,
                                  const char *key, bool required, int32_t lo, int32_t hi,
                                  int32_t *out)
{
    double v = *out;
    drift_result res = read_number(r, obj, path, key, required, lo, hi, &v);
    if (res != DRIFT_OK) {
        return res;
    }
    if (v != floor(v)) {
        char full[KEY_PATH_MAX];
        drift__json_key_path(full, path, key);
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(obj, key), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s must be a whole number, got %g", full, v);
    }
    *out = (int32_t)v;
    return DRIFT_OK;
}

drift_result drift__json_read_vec3(const json_reader *r, const cJSON *obj, const char *path,
                                   const char *key, bool required, vec3_kind kind, drift_vec3 *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        return required ? missing(r, obj, path, key) : DRIFT_OK;
    }
    char full[KEY_PATH_MAX];
    drift__json_key_path(full, path, key);
    // Positions and directions within the scene's coordinate range (DRIFT_SCENE_COORD_MAX).
    double lo = kind == VEC3_COLOR ? 0.0 : -DRIFT_SCENE_COORD_MAX;
    double hi = kind == VEC3_COLOR ? (double)FLT_MAX : DRIFT_SCENE_COORD_MAX;
    double v[3];
    if (kind == VEC3_COLOR && cJSON_IsNumber(item)) {
        drift_result res = drift__json_number_value(r, item, full, lo, hi, &v[0]);
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
        drift__json_index_path(element, full, (size_t)k);
        drift_result res = drift__json_number_value(r, c, element, lo, hi, &v[k]);
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

drift_result drift__json_read_string(const json_reader *r, const cJSON *obj, const char *path,
                                     const char *key, bool required, const char **out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        return required ? missing(r, obj, path, key) : DRIFT_OK;
    }
    char full[KEY_PATH_MAX];
    drift__json_key_path(full, path, key);
    if (!cJSON_IsString(item) || !item->valuestring) {
        return FAIL(r, item, DRIFT_ERR_PARSE, "%s must be a string, not %s", full,
                    drift__json_type_name(item));
    }
    if (!item->valuestring[0]) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s must not be empty", full);
    }
    *out = item->valuestring;
    return DRIFT_OK;
}

// Joins a path from the file with the file's folder; fails when too long.
drift_result drift__json_resolve_path(const json_reader *r, const cJSON *node, const char *relative,
                                      char *out)
{
    if (!drift__path_join(r->base_dir, relative, out, DRIFT__PATH_MAX)) {
        return FAIL(r, node, DRIFT_ERR_INVALID_ARGUMENT, "path '%.64s...' is too long", relative);
    }
    return DRIFT_OK;
}

drift_result drift__json_load_texture(json_reader *r, const cJSON *obj, const char *path,
                                      const char *key, uint32_t *out_index)
{
    const char *rel = NULL;
    drift_result res = drift__json_read_string(r, obj, path, key, false, &rel);
    if (res != DRIFT_OK || !rel) {
        return res;
    }
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char full[DRIFT__PATH_MAX];
    res = drift__json_resolve_path(r, item, rel, full);
    if (res != DRIFT_OK) {
        return res;
    }
    return drift__texture_cache_get(r->scene, &r->textures, full, r->file,
                                    drift__json_line_of(r, item), out_index);
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
    drift_result res = drift__json_expect_object(r, root, "the scene file");
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, root, "", "scene")) != DRIFT_OK) {
        return res;
    }
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (version && (!cJSON_IsNumber(version) || version->valuedouble != 1.0)) {
        return FAIL(r, version, DRIFT_ERR_UNSUPPORTED,
                    "version must be 1 (the only version this drift reads)");
    }
    bool has_camera = false;
    if ((res = drift__json_read_materials(r, root)) != DRIFT_OK ||
        (res = drift__json_read_meshes(r, root)) != DRIFT_OK ||
        (res = drift__json_read_lights(r, root)) != DRIFT_OK ||
        (res = drift__json_read_environment(r, root)) != DRIFT_OK ||
        (res = drift__json_read_camera(r, root, &has_camera)) != DRIFT_OK) {
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
    drift_result res = drift__json_expect_object(r, item, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, item, path, "view")) != DRIFT_OK) {
        return res;
    }
    *out = (drift_camera_view){ 0 };
    const char *name = NULL;
    if ((res = drift__json_read_string(r, item, path, "name", true, &name)) != DRIFT_OK) {
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
    if ((res = drift__json_read_vec3(r, item, path, "position", false, VEC3_ANY, &out->position)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, item, path, "target", false, VEC3_ANY, &out->target)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "fov_y", false, 0.1, 179.0, &fov_deg)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "aperture_radius", false, 0.0, (double)FLT_MAX,
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
    if ((res = drift__json_expect_object(&r, root, "the views file")) != DRIFT_OK ||
        (res = CHECK_KEYS(&r, root, "", "views file")) != DRIFT_OK) {
        // reported
    } else if (!cJSON_IsArray(list)) {
        res = list ? FAIL(&r, list, DRIFT_ERR_PARSE, "views must be an array, not %s",
                          drift__json_type_name(list))
                   : missing(&r, root, "", "views");
    } else if (cJSON_GetArraySize(list) < 1 || (uint32_t)cJSON_GetArraySize(list) > capacity) {
        res = FAIL(&r, list, DRIFT_ERR_INVALID_ARGUMENT, "views must hold 1 to %u views", capacity);
    } else {
        size_t k = 0;
        for (const cJSON *item = list->child; item && res == DRIFT_OK; item = item->next, ++k) {
            char path[KEY_PATH_MAX];
            drift__json_index_path(path, "views", k);
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
