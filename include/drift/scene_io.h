// drift scene_io: scene files in. A drift scene file (.json, docs/scene-format.md) or a
// mesh file that assimp reads (.obj, .gltf, .glb, .ply, and any of those gzip-compressed as
// .gz) becomes a committed drift_scene.
//
// STEP BY STEP
//   drift_scene *scene = NULL;
//   drift_result r = drift_scene_load(ctx, "scenes/cornell-box/cornell_box.json", &scene);
//   if (r != DRIFT_OK) { ... the logger got "file:line" and the reason ... }
//   ... render ...
//   drift_scene_destroy(scene);
//
// A bare mesh file has no camera or lights of its own, so loading one adds what it lacks:
//   - no camera in the file: a 45 degree, 512x512 camera on the +z side of the bounds
//     centre, far enough for the bounding sphere to fit the field of view;
//   - no lights and no emissive materials: a directional light from over the camera's
//     shoulder (irradiance pi) and a constant environment of 0.2.
// Scene files (.json) get no default lights: what the file says is what renders.
//
// Errors (the logger gets the input file and, for scene files, the JSON line):
//   DRIFT_ERR_IO               file missing, unreadable, or not a regular file
//   DRIFT_ERR_PARSE            malformed JSON / mesh file, wrong JSON types, missing keys
//   DRIFT_ERR_INVALID_ARGUMENT values out of range (NaN/Inf, negative sizes, zero-area
//                              lights, absurd image sizes, unknown material names)
//   DRIFT_ERR_UNSUPPORTED      an extension this loader does not read
//   DRIFT_ERR_OUT_OF_MEMORY
// *out_scene is NULL on failure and nothing leaks.
//
// Threads: loading is thread-safe for distinct contexts; one context may load several scenes
// at once as long as its logger and allocator are thread-safe.
#ifndef DRIFT_SCENE_IO_H
#define DRIFT_SCENE_IO_H

#include "drift/core.h"
#include "drift/scene.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Largest file (after decompression) the loaders read into memory.
#define DRIFT_SCENE_MAX_FILE_BYTES ((size_t)1 << 30)

// Loads a scene file or a mesh file, chosen by extension (case-insensitive): .json, .obj,
// .gltf, .glb, .ply, or one of those followed by .gz. Returns a committed scene.
drift_result drift_scene_load(drift_context *ctx, const char *path, drift_scene **out_scene);

// Parses a drift scene file from memory. `text` need not be NUL-terminated. Paths in the
// file are relative to `base_dir` (NULL: the current directory). `name_for_messages` names
// the text in log messages (NULL: "<memory>"). Returns a committed scene.
drift_result drift_scene_load_json_text(drift_context *ctx, const char *text, size_t length,
                                        const char *base_dir, const char *name_for_messages,
                                        drift_scene **out_scene);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_SCENE_IO_H
