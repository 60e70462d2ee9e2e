// glTF animations, read (docs/temporal.md, "glTF animation"): a file's nodes (rest transforms,
// parents, cameras) and its animations' channels, their samplers' accessors read from the
// file's buffers (a .glb's BIN chunk, base64 data URIs, .bin files beside it) with every byte
// range checked and every value finite and bounded. scene_gltf_anim.c evaluates them.
#include "scene_gltf_anim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

bool drift__quat_normalize(float q[4])
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
            !get_floats(node, "matrix", m, 16) || !drift__quat_normalize(d->r) ||
            (!get_index(node, "camera", 1e9, -1.0, &camera) && camera != -1.0)) {
            return FAIL(a, DRIFT_ERR_PARSE,
                        "nodes[%d]: translation, rotation, scale or matrix malformed (finite "
                        "numbers, a non-zero quaternion) or camera not an index",
                        i);
        }
        d->camera = cJSON_GetObjectItemCaseSensitive(node, "camera") ? (int)camera : -1;
        d->has_mesh = cJSON_GetObjectItemCaseSensitive(node, "mesh") != NULL;
        d->skinned = cJSON_GetObjectItemCaseSensitive(node, "skin") != NULL;
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
            !drift__quat_normalize(c.values + (size_t)k * 4)) {
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

void drift__gltf_anim_close(gltf_anim *a)
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
drift_result drift__gltf_anim_open(gltf_anim *a)
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
