// glTF 2.0 animations (docs/temporal.md, "glTF animation"): the channels and samplers of a
// file's `animations` (translation, rotation, scale; LINEAR with slerp for rotations, STEP,
// CUBICSPLINE), read from the file's buffers (a .glb's BIN chunk, data URIs, .bin files beside
// it) with every accessor's range checked, and evaluated on the node graph: the camera node's
// world transform at time t, animated parents included, sampled at each frame into a
// drift_camera_path (drift_camera_path_from_gltf). Every animation of the file plays at once,
// as Blender's timeline plays the actions it exported; of two channels on one node and
// property the later one wins.
//
// The scene loader (scene_gltf.c) calls drift__gltf_anim_check: what drift does not play
// (skins, morph-target weights) gets one warning each, a malformed animation a warning naming
// it. Reading is in scene_gltf_anim_read.c; meshes and lights under moving nodes are posed by
// scene_gltf_anim_nodes.c (drift_scene_animation).
#include "scene_gltf_anim.h"

#include "drift/camera_path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    drift__quat_normalize(out);
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
                slerp(VALUE(lo), VALUE(hi), (double)u, out);
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
    if (c->path == PATH_ROTATION && !drift__quat_normalize(out)) {
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

// The world transform of chain[length - 1] at time t (at rest: no channel applied).
static drift__mat4 chain_world(const gltf_anim *a, const int *chain, int length, double t,
                               bool at_rest)
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
            for (int c = 0; !at_rest && c < a->channel_count; ++c) {
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

bool drift__gltf_node_world(const gltf_anim *a, int node, double t, bool at_rest, drift__mat4 *out)
{
    int chain[DRIFT__SCENE_MAX_NODE_DEPTH], length = 0;
    if (node < 0 || node >= a->node_count || !node_chain(a, node, chain, &length)) {
        return false;
    }
    *out = chain_world(a, chain, length, t, at_rest);
    return true;
}

bool drift__gltf_node_moves(const gltf_anim *a, int node)
{
    int depth = 0;
    for (int i = node; i >= 0 && i < a->node_count && depth < DRIFT__SCENE_MAX_NODE_DEPTH;
         i = a->nodes[i].parent, ++depth) {
        if (node_animated(a, i)) {
            return true;
        }
    }
    return false;
}

bool *drift__gltf_moving_nodes(const gltf_anim *a)
{
    // 0: not known yet, 1: moves, 2: still. Each walk up stops at a known node and marks the
    // nodes it passed, so every node is walked once.
    uint8_t *state = drift_alloc(a->ctx, (size_t)a->node_count + 1);
    bool *moves = drift_alloc(a->ctx, (size_t)a->node_count + 1);
    int *path = drift_alloc(a->ctx, sizeof(int) * (DRIFT__SCENE_MAX_NODE_DEPTH + 1));
    if (!state || !moves || !path) {
        drift_free(a->ctx, state);
        drift_free(a->ctx, moves);
        drift_free(a->ctx, path);
        return NULL;
    }
    memset(state, 0, (size_t)a->node_count + 1);
    for (int c = 0; c < a->channel_count; ++c) {
        state[a->channels[c].node] = 1;
    }
    for (int i = 0; i < a->node_count; ++i) {
        int n = 0, p = i;
        while (p >= 0 && state[p] == 0 && n < DRIFT__SCENE_MAX_NODE_DEPTH) {
            path[n++] = p;
            p = a->nodes[p].parent;
        }
        uint8_t known = p >= 0 && n < DRIFT__SCENE_MAX_NODE_DEPTH ? state[p] : 2;
        for (int k = 0; k < n; ++k) {
            state[path[k]] = known;
        }
        moves[i] = state[i] == 1;
    }
    drift_free(a->ctx, state);
    drift_free(a->ctx, path);
    return moves;
}

bool drift__gltf_camera_moves(const gltf_anim *a)
{
    for (int i = 0; i < a->node_count; ++i) {
        if (a->nodes[i].camera == 0) {
            return drift__gltf_node_moves(a, i);
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
        drift__mat4 world = chain_world(a, chain, length, t, false);
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
    drift_result r = drift__gltf_anim_open(&a);
    if (r == DRIFT_OK) {
        r = camera_path(&a, camera, fps, first_frame, last_frame, out);
    }
    drift__gltf_anim_close(&a);
    return r;
}

void drift__gltf_anim_check(drift_context *ctx, const cJSON *root, const char *path)
{
    const cJSON *anims = cJSON_GetObjectItemCaseSensitive(root, "animations");
    if (!cJSON_IsArray(anims) || cJSON_GetArraySize(anims) == 0) {
        return;
    }
    gltf_anim a = { .ctx = ctx, .level = DRIFT_LOG_WARNING, .path = path };
    if (drift__gltf_anim_open(&a) != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_PARSE, path, 0,
                  "its animations cannot be read (above): `drift render --animation` will fail");
        drift__gltf_anim_close(&a);
        return;
    }
    // Node transforms move cameras, meshes and lights (scene_gltf_anim_nodes.c); skins (their
    // joints' channels) and morph-target weights are not played.
    int skinned = 0;
    for (int i = 0; i < a.node_count; ++i) {
        skinned += a.nodes[i].skinned;
    }
    if (a.channel_count > 0 && skinned > 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "%d skinned mesh node(s): skinning is not supported, they render in their "
                  "bind pose (--animation moves whole nodes only)",
                  skinned);
    }
    if (a.unsupported_channels > 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "%d morph-weight channel(s) are not supported: those meshes render at rest",
                  a.unsupported_channels);
    }
    drift__gltf_anim_close(&a);
}
