// Private to src/io/scene_gltf_anim*.c: a glTF file's nodes and animation channels, read by
// scene_gltf_anim_read.c (buffers, accessors, nodes, channels; every range checked),
// evaluated by scene_gltf_anim.c (a node's world transform at a time, the camera path) and
// played on a scene's meshes and lights by scene_gltf_anim_nodes.c.
#ifndef DRIFT_SCENE_GLTF_ANIM_H
#define DRIFT_SCENE_GLTF_ANIM_H

#include "scene_io_internal.h"

#include <cjson/cJSON.h>

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
    bool has_mesh, skinned; // a `mesh`; a `skin` (drift draws skinned meshes at rest)
    drift__mat4 matrix;     // row-major (glTF's column-major `matrix`, transposed)
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

// Logs `code` against the file (an error, or a warning at load) and yields it.
#define FAIL(a, code, ...) \
    (drift_log((a)->ctx, (a)->level, (code), (a)->path, 0, __VA_ARGS__), (code))

// Reads a->path (ctx, level and path set): its JSON, a .glb's BIN chunk, nodes and animations.
// Errors are logged at a->level; drift__gltf_anim_close frees what it read, whatever the result.
drift_result drift__gltf_anim_open(gltf_anim *a);
void drift__gltf_anim_close(gltf_anim *a);
// The world transform of nodes[node] at time t (its parents' included), or with at_rest the
// nodes' own transforms, no channel applied (what the scene loader placed); false when its
// parents form a cycle or are deeper than DRIFT__SCENE_MAX_NODE_DEPTH.
bool drift__gltf_node_world(const gltf_anim *a, int node, double t, bool at_rest, drift__mat4 *out);
// Whether a channel moves nodes[node] or one of its parents.
bool drift__gltf_node_moves(const gltf_anim *a, int node);
// For each node, whether a channel moves it or one of its parents (node_count entries,
// drift_free it), in time linear in the nodes and channels; NULL when out of memory.
bool *drift__gltf_moving_nodes(const gltf_anim *a);
// Whether a channel moves the node of the file's first camera (or its parents).
bool drift__gltf_camera_moves(const gltf_anim *a);
// Normalizes a quaternion; false when it is zero or not finite.
bool drift__quat_normalize(float q[4]);

#endif // DRIFT_SCENE_GLTF_ANIM_H
