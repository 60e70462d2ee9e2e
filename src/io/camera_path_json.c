// Camera path files (drift/camera_path.h): cJSON parses, json_lines gives each node its line,
// and every error names the file and line.
#include "drift/camera_path.h"
#include "io/json_lines.h"
#include "io/scene_io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

typedef struct path_reader {
    drift_context *ctx;
    const char *file;
    drift__json_lines lines;
} path_reader;

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static drift_result
fail(const path_reader *r, const cJSON *node, drift_result code, const char *fmt, ...)
{
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    drift_log(r->ctx, DRIFT_LOG_ERROR, code, r->file, drift__json_lines_find(&r->lines, node), "%s",
              message);
    return code;
}

// The line and column of a syntax error at `at` (NULL: the end).
static drift_result syntax_error(const path_reader *r, const char *text, size_t length,
                                 const char *at)
{
    size_t offset = at && at >= text && at <= text + length ? (size_t)(at - text) : length;
    int line = 1;
    size_t line_start = 0;
    for (size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    }
    drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->file, line,
              "malformed JSON at column %d%s", (int)(offset - line_start) + 1,
              offset >= length ? " (unexpected end of file)" : "");
    return DRIFT_ERR_PARSE;
}

static drift_result read_number(const path_reader *r, const cJSON *obj, const char *where,
                                const char *key, double lo, double hi, bool *has, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (has) {
        *has = v != NULL;
    }
    if (!v) {
        return DRIFT_OK;
    }
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble)) {
        return fail(r, v, DRIFT_ERR_PARSE, "%s.%s must be a number", where, key);
    }
    if (!(v->valuedouble >= lo && v->valuedouble <= hi)) {
        return fail(r, v, DRIFT_ERR_INVALID_ARGUMENT, "%s.%s must be in [%g, %g], got %g", where,
                    key, lo, hi, v->valuedouble);
    }
    *out = v->valuedouble;
    return DRIFT_OK;
}

static drift_result read_vec3(const path_reader *r, const cJSON *obj, const char *where,
                              const char *key, drift_vec3 *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        return fail(r, obj, DRIFT_ERR_PARSE, "%s lacks \"%s\"", where, key);
    }
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) {
        return fail(r, v, DRIFT_ERR_PARSE, "%s.%s must be an array of 3 numbers", where, key);
    }
    float c[3];
    int k = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++k) {
        if (!cJSON_IsNumber(e) || !(fabs(e->valuedouble) <= 1e15)) {
            return fail(r, e, DRIFT_ERR_PARSE, "%s.%s[%d] must be a number in [-1e15, 1e15]", where,
                        key, k);
        }
        c[k] = (float)e->valuedouble;
    }
    *out = drift_vec3_make(c[0], c[1], c[2]);
    return DRIFT_OK;
}

static drift_result check_keys(const path_reader *r, const cJSON *obj, const char *where,
                               const char *const *allowed, size_t count)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        bool known = false;
        for (size_t k = 0; k < count && !known; ++k) {
            known = c->string && strcmp(c->string, allowed[k]) == 0;
        }
        if (!known) {
            return fail(r, c, DRIFT_ERR_PARSE, "%s: unknown key '%s'", where,
                        c->string ? c->string : "?");
        }
    }
    return DRIFT_OK;
}

static drift_result read_key(const path_reader *r, const cJSON *item, const char *where,
                             drift_camera_key *out)
{
    static const char *const keys[] = { "time",  "position",        "target",
                                        "fov_y", "aperture_radius", "focus_distance" };
    if (!cJSON_IsObject(item)) {
        return fail(r, item, DRIFT_ERR_PARSE, "%s must be an object", where);
    }
    drift_result res = check_keys(r, item, where, keys, sizeof keys / sizeof keys[0]);
    if (res != DRIFT_OK) {
        return res;
    }
    *out = (drift_camera_key){ 0 };
    bool has_time = false;
    double fov = 0.0, aperture = 0.0, focus = 0.0;
    if ((res = read_number(r, item, where, "time", -1e9, 1e9, &has_time, &out->time)) != DRIFT_OK ||
        (res = read_vec3(r, item, where, "position", &out->position)) != DRIFT_OK ||
        (res = read_vec3(r, item, where, "target", &out->target)) != DRIFT_OK ||
        (res = read_number(r, item, where, "fov_y", 0.1, 179.0, &out->has_fov, &fov)) != DRIFT_OK ||
        (res = read_number(r, item, where, "aperture_radius", 0.0, 1e9, &out->has_aperture,
                           &aperture)) != DRIFT_OK ||
        (res = read_number(r, item, where, "focus_distance", 0.0, 1e9, &out->has_focus, &focus)) !=
            DRIFT_OK) {
        return res;
    }
    if (!has_time) {
        return fail(r, item, DRIFT_ERR_PARSE, "%s lacks \"time\" (seconds)", where);
    }
    if (drift_vec3_length(drift_vec3_sub(out->target, out->position)) <= 0.0f) {
        return fail(r, item, DRIFT_ERR_INVALID_ARGUMENT, "%s: target equals position", where);
    }
    out->fov_y = (float)fov * DRIFT_PI / 180.0f;
    out->aperture_radius = (float)aperture;
    out->focus_distance = (float)focus;
    return DRIFT_OK;
}

static drift_result read_path(path_reader *r, const cJSON *root, drift_camera_path *out)
{
    static const char *const keys[] = { "fps", "interpolation", "keyframes" };
    if (!cJSON_IsObject(root)) {
        return fail(r, root, DRIFT_ERR_PARSE, "a camera path file must be an object");
    }
    drift_result res = check_keys(r, root, "the camera path", keys, sizeof keys / sizeof keys[0]);
    if (res != DRIFT_OK) {
        return res;
    }
    out->fps = 24.0;
    if ((res = read_number(r, root, "the camera path", "fps", 1e-3, 1e6, NULL, &out->fps)) !=
        DRIFT_OK) {
        return res;
    }
    const cJSON *interp = cJSON_GetObjectItemCaseSensitive(root, "interpolation");
    if (interp) {
        const char *s = cJSON_IsString(interp) ? interp->valuestring : NULL;
        if (s && strcmp(s, "centripetal") == 0) {
            out->interpolation = DRIFT_CAMERA_PATH_CENTRIPETAL;
        } else if (s && strcmp(s, "linear") == 0) {
            out->interpolation = DRIFT_CAMERA_PATH_LINEAR;
        } else if (s && strcmp(s, "step") == 0) {
            out->interpolation = DRIFT_CAMERA_PATH_STEP;
        } else {
            return fail(r, interp, DRIFT_ERR_PARSE,
                        "interpolation must be \"centripetal\", \"linear\" or \"step\"");
        }
    }
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, "keyframes");
    if (!list) {
        return fail(r, root, DRIFT_ERR_PARSE, "the camera path lacks \"keyframes\"");
    }
    int n = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : -1;
    if (n < 1 || (uint32_t)n > DRIFT_CAMERA_PATH_MAX_KEYS) {
        return fail(r, list, DRIFT_ERR_PARSE, "keyframes must be an array of 1 to %u keyframes",
                    DRIFT_CAMERA_PATH_MAX_KEYS);
    }
    out->keys = drift_alloc(r->ctx, (size_t)n * sizeof *out->keys);
    if (!out->keys) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint32_t k = 0;
    for (const cJSON *item = list->child; item; item = item->next, ++k) {
        char where[48];
        snprintf(where, sizeof where, "keyframes[%u]", k);
        if ((res = read_key(r, item, where, &out->keys[k])) != DRIFT_OK) {
            return res;
        }
        if (k > 0 && !(out->keys[k].time > out->keys[k - 1].time)) {
            return fail(r, item, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s.time (%g) must be later than the keyframe before (%g)", where,
                        out->keys[k].time, out->keys[k - 1].time);
        }
    }
    out->count = k;
    return DRIFT_OK;
}

drift_result drift_camera_path_load_json_text(drift_context *ctx, const char *text, size_t length,
                                              const char *name_for_messages, drift_camera_path *out)
{
    if (!out || (!text && length > 0)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = (drift_camera_path){ 0 };
    path_reader r = { .ctx = ctx, .file = name_for_messages ? name_for_messages : "<memory>" };
    if (length > DRIFT_CAMERA_PATH_MAX_FILE_BYTES) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, r.file, 0,
                  "file is larger than %zu bytes", DRIFT_CAMERA_PATH_MAX_FILE_BYTES);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const char *nul = length ? memchr(text, '\0', length) : NULL;
    if (nul) {
        return syntax_error(&r, text, length, nul);
    }
    char *copy = drift_alloc(ctx, length + 1);
    if (!copy) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (length) {
        memcpy(copy, text, length);
    }
    const char *parse_end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(copy, length + 1, &parse_end, true);
    drift_result res = DRIFT_OK;
    if (!root) {
        res = syntax_error(&r, copy, length, parse_end);
    } else {
        res = drift__json_lines_build(ctx, root, copy, length, &r.lines);
        if (res == DRIFT_OK) {
            res = read_path(&r, root, out);
        }
    }
    cJSON_Delete(root);
    drift_free(ctx, copy);
    drift__json_lines_free(ctx, &r.lines);
    if (res != DRIFT_OK) {
        drift_camera_path_free(ctx, out);
    }
    return res;
}

drift_result drift_camera_path_load(drift_context *ctx, const char *path, drift_camera_path *out)
{
    if (!path || !out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = (drift_camera_path){ 0 };
    char *text = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, false, path, 0, &text, &size);
    if (r == DRIFT_OK) {
        r = drift_camera_path_load_json_text(ctx, text, size, path, out);
    }
    drift_free(ctx, text);
    return r;
}
