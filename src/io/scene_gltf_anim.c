// glTF 2.0 animations (docs/temporal.md, "glTF animation"): the channels and samplers of a
// file's `animations` (translation, rotation, scale; LINEAR with slerp for rotations, STEP,
// CUBICSPLINE), read from the file's buffers (a .glb's BIN chunk, data URIs, .bin files beside
// it) with every accessor's range checked, and evaluated on the node graph: the camera node's
// world transform at time t, animated parents included, sampled at each frame into a
// drift_camera_path (drift_camera_path_from_gltf). Every animation of the file plays at once,
// as Blender's timeline plays the actions it exported; of two channels on one node and
// property the later one wins.
//
// The scene loader (scene_gltf.c) calls drift__gltf_anim_check: a file whose animations move
// nodes other than cameras gets one warning (drift renders meshes and lights at rest), a
// malformed animation a warning naming it.
#include "drift/camera_path.h"
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ANIM_MAX_KEYS  (1u << 24) // keys of one sampler
#define ANIM_MAX_TIME  1e6        // seconds
#define ANIM_MAX_VALUE 1e12f      // |translation|, |scale| and tangents
#define ANIM_MAX_BYTES ((double)DRIFT_SCENE_MAX_FILE_BYTES)

enum {
    PATH_TRANSLATION,
    PATH_ROTATION,
    PATH_SCALE
};

enum {
    INTERP_LINEAR,
    INTERP_STEP,
    INTERP_CUBIC
};

typedef struct anim_channel {
    int node, path, interp, width; // width: 3, or 4 for rotations
    uint32_t count;                // keys
    float *times;                  // count
    float *values; // count * width; CUBICSPLINE: 3 * count * width (in-tangent, value, out)
} anim_channel;

typedef struct anim_node {
    int parent, camera; // -1: none
    bool has_matrix;
    drift__mat4 matrix; // row-major (glTF's column-major `matrix`, transposed)
    float t[3], r[4], s[3];
} anim_node;

typedef struct gltf_anim {
    drift_context *ctx;
    drift_log_level level; // errors at --animation, warnings at load
    const char *path;
    cJSON *root;
    char *file;         // the file's bytes (a .glb's BIN chunk points into it)
    const uint8_t *bin; // a .glb's BIN chunk, or NULL
    size_t bin_size;
    uint8_t **buffers; // loaded on first use, one per `buffers` entry
    size_t *buffer_sizes;
    int buffer_count;
    anim_node *nodes;
    int node_count;
    anim_channel *channels;
    int channel_count;
    int unsupported_channels; // morph target weights, extensions' targets
} gltf_anim;

#define FAIL(a, code, ...) \
    (drift_log((a)->ctx, (a)->level, (code), (a)->path, 0, __VA_ARGS__), (code))

static uint32_t read_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

// A non-negative integer member (absent: `fallback`, or false when `fallback` < 0).
static bool get_index(const cJSON *obj, const char *key, double max, double fallback, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        *out = fallback;
        return fallback >= 0.0;
    }
    double d = cJSON_IsNumber(v) ? v->valuedouble : -1.0;
    if (!(d >= 0.0 && d <= max && d == floor(d))) {
        return false;
    }
    *out = d;
    return true;
}

// n finite numbers of an array member into out; absent: true and out untouched.
static bool get_floats(const cJSON *obj, const char *key, float *out, int n)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        return true;
    }
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n) {
        return false;
    }
    for (int i = 0; i < n; ++i) {
        const cJSON *e = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(e) || !(fabs(e->valuedouble) <= (double)ANIM_MAX_VALUE)) {
            return false;
        }
        out[i] = (float)e->valuedouble;
    }
    return true;
}

static bool normalize_quat(float q[4])
{
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(n > 1e-12f) || !isfinite(n)) {
        return false;
    }
    for (int i = 0; i < 4; ++i) {
        q[i] /= n;
    }
    return true;
}

static int base64_digit(char c)
{
    if (c >= 'A' && c <= 'Z') {
        return c - 'A';
    }
    if (c >= 'a' && c <= 'z') {
        return c - 'a' + 26;
    }
    if (c >= '0' && c <= '9') {
        return c - '0' + 52;
    }
    return c == '+' || c == '-' ? 62 : c == '/' || c == '_' ? 63 : -1;
}

// Decodes base64 text (padding optional) into a new buffer; false on a bad character.
static bool base64_decode(drift_context *ctx, const char *text, uint8_t **out, size_t *out_size)
{
    size_t n = strlen(text);
    uint8_t *data = drift_alloc(ctx, n / 4 * 3 + 3);
    if (!data) {
        return false;
    }
    size_t size = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = 0; i < n && text[i] != '='; ++i) {
        int d = base64_digit(text[i]);
        if (d < 0) {
            drift_free(ctx, data);
            return false;
        }
        acc = (acc << 6) | (uint32_t)d;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            data[size++] = (uint8_t)(acc >> bits);
        }
    }
    *out = data;
    *out_size = size;
    return true;
}

// Buffer `index`: the .glb's BIN chunk, a data URI or a file beside the glTF file.
static drift_result load_buffer(gltf_anim *a, int index, const uint8_t **out, size_t *out_size)
{
    const cJSON *buffer =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(a->root, "buffers"), index);
    double length = 0.0;
    if (!cJSON_IsObject(buffer) || !get_index(buffer, "byteLength", ANIM_MAX_BYTES, -1, &length)) {
        return FAIL(a, DRIFT_ERR_PARSE, "buffers[%d]: no byteLength", index);
    }
    if (!a->buffers[index]) {
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(buffer, "uri");
        uint8_t *data = NULL;
        size_t size = 0;
        if (!uri) {
            if (index != 0 || !a->bin) {
                return FAIL(a, DRIFT_ERR_PARSE, "buffers[%d] has no uri (and is not a .glb's)",
                            index);
            }
            *out = a->bin;
            *out_size = a->bin_size;
        } else if (!cJSON_IsString(uri)) {
            return FAIL(a, DRIFT_ERR_PARSE, "buffers[%d].uri is not a string", index);
        } else if (strncmp(uri->valuestring, "data:", 5) == 0) {
            const char *comma = strstr(uri->valuestring, ";base64,");
            if (!comma || !base64_decode(a->ctx, comma + 8, &data, &size)) {
                return FAIL(a, DRIFT_ERR_PARSE, "buffers[%d]: not a base64 data URI", index);
            }
        } else {
            char full[DRIFT__PATH_MAX];
            const char *slash = strrchr(a->path, '/');
            int dir = slash ? (int)(slash - a->path + 1) : 0;
            if (snprintf(full, sizeof full, "%.*s%s", dir, a->path, uri->valuestring) >=
                (int)sizeof full) {
                return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT, "buffers[%d]: uri too long", index);
            }
            char *bytes = NULL;
            drift_result r = drift__read_file(a->ctx, full, false, a->path, 0, &bytes, &size);
            if (r != DRIFT_OK) {
                return r;
            }
            data = (uint8_t *)bytes;
        }
        if (uri) {
            a->buffers[index] = data;
            a->buffer_sizes[index] = size;
        }
    }
    if (a->buffers[index]) {
        *out = a->buffers[index];
        *out_size = a->buffer_sizes[index];
    }
    if ((double)*out_size < length) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "buffers[%d] holds %zu bytes, less than its byteLength %.0f", index, *out_size,
                    length);
    }
    return DRIFT_OK;
}

// Accessor `index` as `width` floats an element (float, or for rotations normalized
// integers), every byte of it inside its buffer view and buffer; values finite and bounded.
static drift_result read_accessor(gltf_anim *a, const cJSON *sampler, const char *key,
                                  const char *what, int width, bool normalized_ok,
                                  uint32_t *out_count, float **out)
{
    const cJSON *accessors = cJSON_GetObjectItemCaseSensitive(a->root, "accessors");
    int n_accessors = cJSON_IsArray(accessors) ? cJSON_GetArraySize(accessors) : 0;
    double ai = 0.0;
    if (!get_index(sampler, key, (double)n_accessors - 1.0, -1, &ai)) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s.%s is not an accessor index (there are %d)", what, key,
                    n_accessors);
    }
    const cJSON *acc = cJSON_GetArrayItem(accessors, (int)ai);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(acc, "type");
    static const char *const types[] = { "", "SCALAR", "", "VEC3", "VEC4" };
    if (!cJSON_IsString(type) || strcmp(type->valuestring, types[width]) != 0) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: accessors[%.0f] must be a %s", what, ai, types[width]);
    }
    if (cJSON_GetObjectItemCaseSensitive(acc, "sparse")) {
        return FAIL(a, DRIFT_ERR_UNSUPPORTED, "%s: accessors[%.0f] is sparse (not supported)", what,
                    ai);
    }
    double component = 0.0, count = 0.0, offset = 0.0, vi = 0.0;
    const cJSON *normalized = cJSON_GetObjectItemCaseSensitive(acc, "normalized");
    if (!get_index(acc, "componentType", 1e5, -1, &component) ||
        !get_index(acc, "count", ANIM_MAX_KEYS, -1, &count) || count < 1.0 ||
        !get_index(acc, "byteOffset", ANIM_MAX_BYTES, 0, &offset)) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "%s: accessors[%.0f] needs componentType and a count of 1 to %u", what, ai,
                    ANIM_MAX_KEYS);
    }
    int bytes = component == 5126                        ? 4
                : component == 5120 || component == 5121 ? 1
                : component == 5122 || component == 5123 ? 2
                                                         : 0;
    if (bytes == 0 || (bytes != 4 && !(normalized_ok && cJSON_IsTrue(normalized)))) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "%s: accessors[%.0f] has componentType %.0f; animations use floats (5126)%s",
                    what, ai, component, normalized_ok ? " or normalized integers" : "");
    }
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(a->root, "bufferViews");
    int n_views = cJSON_IsArray(views) ? cJSON_GetArraySize(views) : 0;
    if (!get_index(acc, "bufferView", (double)n_views - 1.0, -1, &vi)) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: accessors[%.0f] has no valid bufferView", what, ai);
    }
    const cJSON *view = cJSON_GetArrayItem(views, (int)vi);
    const cJSON *buffers = cJSON_GetObjectItemCaseSensitive(a->root, "buffers");
    double bi = 0.0, view_offset = 0.0, view_length = 0.0, stride = 0.0;
    double element = (double)(bytes * width);
    if (!get_index(view, "buffer", (double)a->buffer_count - 1.0, -1, &bi) ||
        !get_index(view, "byteOffset", ANIM_MAX_BYTES, 0, &view_offset) ||
        !get_index(view, "byteLength", ANIM_MAX_BYTES, -1, &view_length) ||
        !get_index(view, "byteStride", 252, element, &stride) || stride < element) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "%s: bufferViews[%.0f] needs a buffer (of %d), a byteLength and a "
                    "byteStride of at least %.0f",
                    what, vi, cJSON_GetArraySize(buffers), element);
    }
    if (offset + stride * (count - 1.0) + element > view_length) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "%s: accessors[%.0f] (%.0f elements) runs past the end of bufferViews[%.0f]",
                    what, ai, count, vi);
    }
    const uint8_t *data = NULL;
    size_t size = 0;
    drift_result r = load_buffer(a, (int)bi, &data, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if (view_offset + view_length > (double)size) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: bufferViews[%.0f] runs past the end of buffers[%.0f]",
                    what, vi, bi);
    }
    size_t n = (size_t)count * (size_t)width;
    float *values = drift_alloc(a->ctx, n * sizeof(float));
    if (!values) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    const uint8_t *p = data + (size_t)view_offset + (size_t)offset;
    for (size_t e = 0; e < (size_t)count; ++e) {
        for (int c = 0; c < width; ++c) {
            const uint8_t *q = p + e * (size_t)stride + (size_t)(c * bytes);
            float v = 0.0f;
            if (component == 5126) {
                uint32_t u = read_u32(q);
                memcpy(&v, &u, sizeof v);
            } else if (component == 5120) {
                v = fmaxf((float)(int8_t)q[0] / 127.0f, -1.0f);
            } else if (component == 5121) {
                v = (float)q[0] / 255.0f;
            } else if (component == 5122) {
                v = fmaxf((float)(int16_t)(q[0] | q[1] << 8) / 32767.0f, -1.0f);
            } else {
                v = (float)(q[0] | q[1] << 8) / 65535.0f;
            }
            if (!(fabsf(v) <= ANIM_MAX_VALUE)) {
                drift_free(a->ctx, values);
                return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT,
                            "%s: accessors[%.0f] element %zu holds %g (NaN, infinite or absurd)",
                            what, ai, e, (double)v);
            }
            values[e * (size_t)width + (size_t)c] = v;
        }
    }
    *out_count = (uint32_t)count;
    *out = values;
    return DRIFT_OK;
}

static drift_result parse_nodes(gltf_anim *a)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(a->root, "nodes");
    int n = cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0;
    if (n == 0) {
        return DRIFT_OK;
    }
    a->nodes = drift_alloc(a->ctx, (size_t)n * sizeof(anim_node));
    if (!a->nodes) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    a->node_count = n;
    for (int i = 0; i < n; ++i) {
        a->nodes[i] = (anim_node){
            .parent = -1, .camera = -1, .r = { 0.0f, 0.0f, 0.0f, 1.0f }, .s = { 1.0f, 1.0f, 1.0f }
        };
    }
    for (int i = 0; i < n; ++i) {
        const cJSON *node = cJSON_GetArrayItem(nodes, i);
        anim_node *d = &a->nodes[i];
        float m[16];
        double camera = -1.0;
        if (!cJSON_IsObject(node) || !get_floats(node, "translation", d->t, 3) ||
            !get_floats(node, "rotation", d->r, 4) || !get_floats(node, "scale", d->s, 3) ||
            !get_floats(node, "matrix", m, 16) || !normalize_quat(d->r) ||
            (!get_index(node, "camera", 1e9, -1.0, &camera) && camera != -1.0)) {
            return FAIL(a, DRIFT_ERR_PARSE,
                        "nodes[%d]: translation, rotation, scale or matrix malformed (finite "
                        "numbers, a non-zero quaternion) or camera not an index",
                        i);
        }
        d->camera = cJSON_GetObjectItemCaseSensitive(node, "camera") ? (int)camera : -1;
        if (cJSON_GetObjectItemCaseSensitive(node, "matrix")) {
            d->has_matrix = true;
            for (int r = 0; r < 4; ++r) {
                for (int c = 0; c < 4; ++c) {
                    d->matrix.m[r * 4 + c] = m[c * 4 + r];
                }
            }
        }
    }
    for (int i = 0; i < n; ++i) {
        const cJSON *child;
        cJSON_ArrayForEach(
            child, cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(nodes, i), "children"))
        {
            double c = cJSON_IsNumber(child) ? child->valuedouble : -1.0;
            if (!(c >= 0.0 && c < (double)n && c == floor(c)) || (int)c == i ||
                a->nodes[(int)c].parent >= 0) {
                return FAIL(a, DRIFT_ERR_PARSE,
                            "nodes[%d].children: not a node index, or a node with two parents", i);
            }
            a->nodes[(int)c].parent = i;
        }
    }
    return DRIFT_OK;
}

static drift_result parse_channel(gltf_anim *a, const cJSON *anim, int ai, const cJSON *channel,
                                  int ci)
{
    char what[96];
    snprintf(what, sizeof what, "animations[%d].channels[%d]", ai, ci);
    const cJSON *target = cJSON_GetObjectItemCaseSensitive(channel, "target");
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(target, "path");
    if (!cJSON_IsObject(target) || !cJSON_IsString(path)) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: no target.path", what);
    }
    int kind = strcmp(path->valuestring, "translation") == 0 ? PATH_TRANSLATION
               : strcmp(path->valuestring, "rotation") == 0  ? PATH_ROTATION
               : strcmp(path->valuestring, "scale") == 0     ? PATH_SCALE
                                                             : -1;
    double node = 0.0;
    if (kind < 0 || !cJSON_GetObjectItemCaseSensitive(target, "node")) {
        a->unsupported_channels++; // "weights", or an extension's target
        return DRIFT_OK;
    }
    if (!get_index(target, "node", (double)a->node_count - 1.0, -1, &node)) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: target.node is not a node index (there are %d)", what,
                    a->node_count);
    }
    if (a->nodes[(int)node].has_matrix) {
        return FAIL(a, DRIFT_ERR_PARSE,
                    "%s: nodes[%.0f] has a matrix; glTF animates TRS nodes only", what, node);
    }
    const cJSON *samplers = cJSON_GetObjectItemCaseSensitive(anim, "samplers");
    double si = 0.0;
    if (!get_index(channel, "sampler", (double)cJSON_GetArraySize(samplers) - 1.0, -1, &si)) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: sampler is not an index of samplers", what);
    }
    const cJSON *sampler = cJSON_GetArrayItem(samplers, (int)si);
    const cJSON *interp = cJSON_GetObjectItemCaseSensitive(sampler, "interpolation");
    const char *iname = cJSON_IsString(interp) ? interp->valuestring : interp ? "?" : "LINEAR";
    anim_channel c = { .node = (int)node,
                       .path = kind,
                       .width = kind == PATH_ROTATION ? 4 : 3,
                       .interp = strcmp(iname, "LINEAR") == 0        ? INTERP_LINEAR
                                 : strcmp(iname, "STEP") == 0        ? INTERP_STEP
                                 : strcmp(iname, "CUBICSPLINE") == 0 ? INTERP_CUBIC
                                                                     : -1 };
    if (c.interp < 0) {
        return FAIL(a, DRIFT_ERR_PARSE, "%s: interpolation '%s' is not LINEAR, STEP or CUBICSPLINE",
                    what, iname);
    }
    snprintf(what, sizeof what, "animations[%d].samplers[%.0f]", ai, si);
    uint32_t out_count = 0;
    drift_result r = read_accessor(a, sampler, "input", what, 1, false, &c.count, &c.times);
    if (r == DRIFT_OK) {
        r = read_accessor(a, sampler, "output", what, c.width, kind == PATH_ROTATION, &out_count,
                          &c.values);
    }
    uint32_t per_key = c.interp == INTERP_CUBIC ? 3u : 1u;
    if (r == DRIFT_OK && (uint64_t)out_count != (uint64_t)c.count * per_key) {
        r = FAIL(a, DRIFT_ERR_PARSE, "%s: %u outputs for %u times (%s needs %u a time)", what,
                 out_count, c.count, iname, per_key);
    }
    for (uint32_t k = 0; r == DRIFT_OK && k < c.count; ++k) {
        if (!((double)c.times[k] >= 0.0 && (double)c.times[k] <= ANIM_MAX_TIME) ||
            (k > 0 && !(c.times[k] > c.times[k - 1]))) {
            r = FAIL(a, DRIFT_ERR_INVALID_ARGUMENT,
                     "%s: input time %u (%g s) must be in [0, %g] and later than the one before",
                     what, k, (double)c.times[k], ANIM_MAX_TIME);
        }
        if (r == DRIFT_OK && kind == PATH_ROTATION && c.interp != INTERP_CUBIC &&
            !normalize_quat(c.values + (size_t)k * 4)) {
            r = FAIL(a, DRIFT_ERR_INVALID_ARGUMENT, "%s: rotation %u is a zero quaternion", what,
                     k);
        }
    }
    if (r != DRIFT_OK) {
        drift_free(a->ctx, c.times);
        drift_free(a->ctx, c.values);
        return r;
    }
    a->channels[a->channel_count++] = c;
    return DRIFT_OK;
}

static drift_result parse_animations(gltf_anim *a)
{
    const cJSON *anims = cJSON_GetObjectItemCaseSensitive(a->root, "animations");
    if (anims && !cJSON_IsArray(anims)) {
        return FAIL(a, DRIFT_ERR_PARSE, "animations is not an array");
    }
    size_t total = 0;
    const cJSON *anim;
    cJSON_ArrayForEach(anim, anims)
    {
        const cJSON *channels = cJSON_GetObjectItemCaseSensitive(anim, "channels");
        if (!cJSON_IsArray(channels) ||
            !cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(anim, "samplers"))) {
            return FAIL(a, DRIFT_ERR_PARSE, "an animation needs channels and samplers arrays");
        }
        total += (size_t)cJSON_GetArraySize(channels);
    }
    if (total > 0 && !(a->channels = drift_alloc(a->ctx, total * sizeof(anim_channel)))) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    int ai = 0;
    cJSON_ArrayForEach(anim, anims)
    {
        int ci = 0;
        const cJSON *channel;
        cJSON_ArrayForEach(channel, cJSON_GetObjectItemCaseSensitive(anim, "channels"))
        {
            drift_result r = parse_channel(a, anim, ai, channel, ci++);
            if (r != DRIFT_OK) {
                return r;
            }
        }
        ++ai;
    }
    return DRIFT_OK;
}

static void anim_close(gltf_anim *a)
{
    for (int i = 0; i < a->channel_count; ++i) {
        drift_free(a->ctx, a->channels[i].times);
        drift_free(a->ctx, a->channels[i].values);
    }
    for (int i = 0; i < a->buffer_count; ++i) {
        drift_free(a->ctx, a->buffers[i]);
    }
    drift_free(a->ctx, a->channels);
    drift_free(a->ctx, a->buffers);
    drift_free(a->ctx, a->buffer_sizes);
    drift_free(a->ctx, a->nodes);
    drift_free(a->ctx, a->file);
    cJSON_Delete(a->root);
}

// Reads the file (a .gltf, or a .glb's JSON and BIN chunks), its nodes and animations.
static drift_result anim_open(gltf_anim *a)
{
    size_t len = strlen(a->path), size = 0;
    bool gz = len > 3 && strcmp(a->path + len - 3, ".gz") == 0;
    drift_result r = drift__read_file(a->ctx, a->path, gz, a->path, 0, &a->file, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    const uint8_t *p = (const uint8_t *)a->file;
    const char *json = a->file;
    size_t json_length = size;
    if (size >= 4 && memcmp(p, "glTF", 4) == 0) {
        uint32_t jl = size >= 20 ? read_u32(p + 12) : 0;
        if (size < 20 || memcmp(p + 16, "JSON", 4) != 0 || jl > size - 20) {
            return FAIL(a, DRIFT_ERR_PARSE, "not a glTF 2.0 binary (.glb)");
        }
        json = a->file + 20;
        json_length = jl;
        size_t bin_at = 20 + (((size_t)jl + 3u) & ~(size_t)3u);
        if (bin_at + 8 <= size && memcmp(p + bin_at + 4, "BIN\0", 4) == 0 &&
            read_u32(p + bin_at) <= size - bin_at - 8) {
            a->bin = p + bin_at + 8;
            a->bin_size = read_u32(p + bin_at);
        }
    }
    a->root = cJSON_ParseWithLength(json, json_length);
    if (!cJSON_IsObject(a->root)) {
        return FAIL(a, DRIFT_ERR_PARSE, "not a glTF 2.0 file (malformed JSON)");
    }
    const cJSON *buffers = cJSON_GetObjectItemCaseSensitive(a->root, "buffers");
    a->buffer_count = cJSON_IsArray(buffers) ? cJSON_GetArraySize(buffers) : 0;
    if (a->buffer_count > 0) {
        a->buffers = drift_alloc(a->ctx, (size_t)a->buffer_count * sizeof(uint8_t *));
        a->buffer_sizes = drift_alloc(a->ctx, (size_t)a->buffer_count * sizeof(size_t));
        if (!a->buffers || !a->buffer_sizes) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        memset(a->buffers, 0, (size_t)a->buffer_count * sizeof(uint8_t *));
    }
    r = parse_nodes(a);
    return r == DRIFT_OK ? parse_animations(a) : r;
}

static void lerp_n(const float *x, const float *y, float u, float *out, int n)
{
    for (int i = 0; i < n; ++i) {
        out[i] = x[i] + u * (y[i] - x[i]);
    }
}

// Spherical linear interpolation of unit quaternions, by the shorter arc.
static void slerp(const float *x, const float *y, double u, float *out)
{
    double d = 0.0;
    for (int i = 0; i < 4; ++i) {
        d += (double)x[i] * (double)y[i];
    }
    double sign = d < 0.0 ? -1.0 : 1.0;
    d = fabs(d);
    double wx = 1.0 - u, wy = u;
    if (d < 0.9995) {
        double theta = acos(d);
        wx = sin((1.0 - u) * theta) / sin(theta);
        wy = sin(u * theta) / sin(theta);
    }
    for (int i = 0; i < 4; ++i) {
        out[i] = (float)(wx * (double)x[i] + sign * wy * (double)y[i]);
    }
    normalize_quat(out);
}

static void channel_eval(const anim_channel *c, double t, float *out)
{
    int w = c->width;
    bool cubic = c->interp == INTERP_CUBIC;
    const float *v = c->values;
#define VALUE(k) (v + ((size_t)(k) * (cubic ? 3u : 1u) + (cubic ? 1u : 0u)) * (size_t)w)
    uint32_t n = c->count;
    if (!(t > (double)c->times[0]) || n == 1) {
        memcpy(out, VALUE(0), sizeof(float) * (size_t)w);
    } else if (t >= (double)c->times[n - 1]) {
        memcpy(out, VALUE(n - 1), sizeof(float) * (size_t)w);
    } else {
        uint32_t lo = 0, hi = n - 1; // times[lo] <= t < times[hi]
        while (hi - lo > 1) {
            uint32_t mid = lo + (hi - lo) / 2;
            if ((double)c->times[mid] <= t) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        double td = (double)c->times[hi] - (double)c->times[lo];
        float u = (float)((t - (double)c->times[lo]) / td);
        if (c->interp == INTERP_STEP) {
            memcpy(out, VALUE(lo), sizeof(float) * (size_t)w);
        } else if (!cubic) {
            if (c->path == PATH_ROTATION) {
                slerp(VALUE(lo), VALUE(hi), u, out);
            } else {
                lerp_n(VALUE(lo), VALUE(hi), u, out, w);
            }
        } else {
            // Hermite: the value and out-tangent at lo, the value and in-tangent at hi.
            const float *b = VALUE(lo) + w, *a = VALUE(hi) - w;
            float s2 = u * u, s3 = s2 * u, dt = (float)td;
            for (int i = 0; i < w; ++i) {
                out[i] = (2.0f * s3 - 3.0f * s2 + 1.0f) * VALUE(lo)[i] +
                         dt * (s3 - 2.0f * s2 + u) * b[i] +
                         (-2.0f * s3 + 3.0f * s2) * VALUE(hi)[i] + dt * (s3 - s2) * a[i];
            }
        }
    }
#undef VALUE
    if (c->path == PATH_ROTATION && !normalize_quat(out)) {
        out[0] = out[1] = out[2] = 0.0f;
        out[3] = 1.0f;
    }
}

// T · R · S, row-major.
static drift__mat4 trs_matrix(const float *t, const float *q, const float *s)
{
    float x = q[0], y = q[1], z = q[2], w = q[3];
    float r[3][3] = { { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w) },
                      { 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w) },
                      { 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) } };
    drift__mat4 m = drift__mat4_identity();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            m.m[i * 4 + j] = r[i][j] * s[j];
        }
        m.m[i * 4 + 3] = t[i];
    }
    return m;
}

// The ancestors of `node` and itself, root first; false on a cycle or an absurd depth.
static bool node_chain(const gltf_anim *a, int node, int *chain, int *length)
{
    int n = 0;
    for (int i = node; i >= 0; i = a->nodes[i].parent) {
        if (n >= DRIFT__SCENE_MAX_NODE_DEPTH) {
            return false;
        }
        chain[n++] = i;
    }
    for (int i = 0; i < n / 2; ++i) {
        int t = chain[i];
        chain[i] = chain[n - 1 - i];
        chain[n - 1 - i] = t;
    }
    *length = n;
    return true;
}

// The world transform of chain[length - 1] at time t.
static drift__mat4 chain_world(const gltf_anim *a, const int *chain, int length, double t)
{
    drift__mat4 world = drift__mat4_identity();
    for (int i = 0; i < length; ++i) {
        const anim_node *n = &a->nodes[chain[i]];
        drift__mat4 local = n->matrix;
        if (!n->has_matrix) {
            float trs[3][4];
            memcpy(trs[0], n->t, sizeof n->t);
            memcpy(trs[1], n->r, sizeof n->r);
            memcpy(trs[2], n->s, sizeof n->s);
            for (int c = 0; c < a->channel_count; ++c) {
                if (a->channels[c].node == chain[i]) {
                    channel_eval(&a->channels[c], t, trs[a->channels[c].path]);
                }
            }
            local = trs_matrix(trs[0], trs[1], trs[2]);
        }
        world = drift__mat4_mul(&world, &local);
    }
    return world;
}

static bool node_animated(const gltf_anim *a, int node)
{
    for (int c = 0; c < a->channel_count; ++c) {
        if (a->channels[c].node == node) {
            return true;
        }
    }
    return false;
}

static drift_result camera_path(gltf_anim *a, const char *selector, double fps, long first,
                                long last, drift_camera_path *out)
{
    const cJSON *cameras = cJSON_GetObjectItemCaseSensitive(a->root, "cameras");
    int count = cJSON_IsArray(cameras) ? cJSON_GetArraySize(cameras) : 0;
    int camera = -1;
    char *end = NULL;
    long index = selector ? strtol(selector, &end, 10) : 0;
    if (!selector || (end != selector && *end == '\0')) {
        camera = index >= 0 && index < count ? (int)index : -1;
    }
    for (int i = 0; selector && camera < 0 && i < count; ++i) {
        const cJSON *name =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cameras, i), "name");
        camera = cJSON_IsString(name) && strcmp(name->valuestring, selector) == 0 ? i : -1;
    }
    int node = -1;
    for (int i = 0; camera >= 0 && node < 0 && i < a->node_count; ++i) {
        node = a->nodes[i].camera == camera ? i : -1;
    }
    if (node < 0) {
        return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT, "no node holds camera '%s' (the file has %d)",
                    selector ? selector : "0", count);
    }
    int chain[DRIFT__SCENE_MAX_NODE_DEPTH], length = 0;
    if (!node_chain(a, node, chain, &length)) {
        return FAIL(a, DRIFT_ERR_PARSE, "the parents of nodes[%d] form a cycle", node);
    }
    bool moves = false;
    for (int i = 0; i < length; ++i) {
        moves = moves || node_animated(a, chain[i]);
    }
    if (!moves) {
        return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT,
                    "no animation moves the camera's node (nodes[%d]) or its parents: "
                    "--animation needs one, or --camera-path",
                    node);
    }
    uint32_t keys = (uint32_t)(last - first + 1);
    if (first < 0 || last < first || keys > DRIFT_CAMERA_PATH_MAX_KEYS || !(fps > 0.0)) {
        return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT, "frames %ld:%ld at %g fps: out of range", first,
                    last, fps);
    }
    out->keys = drift_alloc(a->ctx, keys * sizeof(drift_camera_key));
    if (!out->keys) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    out->count = keys;
    out->fps = fps;
    out->interpolation = DRIFT_CAMERA_PATH_LINEAR;
    for (uint32_t k = 0; k < keys; ++k) {
        double t = (double)(first + (long)k) / fps;
        drift__mat4 world = chain_world(a, chain, length, t);
        drift_vec3 eye = drift__mat4_point(&world, drift_vec3_make(0.0f, 0.0f, 0.0f));
        drift_vec3 look = drift__mat4_vector(&world, drift_vec3_make(0.0f, 0.0f, -1.0f));
        drift_vec3 up = drift__mat4_vector(&world, drift_vec3_make(0.0f, 1.0f, 0.0f));
        float ll = drift_vec3_length(look), lu = drift_vec3_length(up);
        if (!(ll > 1e-12f && lu > 1e-12f && isfinite(ll) && isfinite(lu) && isfinite(eye.x) &&
              isfinite(eye.y) && isfinite(eye.z))) {
            drift_camera_path_free(a->ctx, out);
            return FAIL(a, DRIFT_ERR_INVALID_ARGUMENT,
                        "the camera's transform at frame %ld (t = %g s) is degenerate (a zero "
                        "scale) or not finite",
                        first + (long)k, t);
        }
        look = drift_vec3_scale(look, 1.0f / ll);
        out->keys[k] = (drift_camera_key){ .time = t,
                                           .position = eye,
                                           .target = drift_vec3_add(eye, look),
                                           .has_up = true,
                                           .up = drift_vec3_scale(up, 1.0f / lu) };
    }
    return DRIFT_OK;
}

drift_result drift_camera_path_from_gltf(drift_context *ctx, const char *path, const char *camera,
                                         double fps, long first_frame, long last_frame,
                                         drift_camera_path *out)
{
    *out = (drift_camera_path){ 0 };
    gltf_anim a = { .ctx = ctx, .level = DRIFT_LOG_ERROR, .path = path };
    drift_result r = anim_open(&a);
    if (r == DRIFT_OK) {
        r = camera_path(&a, camera, fps, first_frame, last_frame, out);
    }
    anim_close(&a);
    return r;
}

void drift__gltf_anim_check(drift_context *ctx, const cJSON *root, const char *path)
{
    const cJSON *anims = cJSON_GetObjectItemCaseSensitive(root, "animations");
    if (!cJSON_IsArray(anims) || cJSON_GetArraySize(anims) == 0) {
        return;
    }
    gltf_anim a = { .ctx = ctx, .level = DRIFT_LOG_WARNING, .path = path };
    if (anim_open(&a) != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_PARSE, path, 0,
                  "its animations cannot be read (above): `drift render --animation` will fail");
        anim_close(&a);
        return;
    }
    // Nodes that move and hold no camera, nor a camera below them: drift renders them at rest.
    bool *above_camera = drift_alloc(ctx, (size_t)a.node_count + 1);
    int moving = 0, first = -1;
    if (above_camera) {
        memset(above_camera, 0, (size_t)a.node_count + 1);
        for (int j = 0; j < a.node_count; ++j) {
            int depth = 0;
            for (int p = j; a.nodes[j].camera >= 0 && p >= 0 && !above_camera[p] &&
                            depth < DRIFT__SCENE_MAX_NODE_DEPTH;
                 p = a.nodes[p].parent, ++depth) {
                above_camera[p] = true;
            }
        }
        for (int i = 0; i < a.node_count; ++i) {
            if (node_animated(&a, i) && !above_camera[i]) {
                first = moving++ == 0 ? i : first;
            }
        }
        drift_free(ctx, above_camera);
    }
    if (moving > 0 || a.unsupported_channels > 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "animation of %d node(s) that hold no camera (the first: nodes[%d]) and %d "
                  "morph-weight channel(s) is not supported: they render at rest; "
                  "--animation moves the camera only",
                  moving, first, a.unsupported_channels);
    }
    anim_close(&a);
}
