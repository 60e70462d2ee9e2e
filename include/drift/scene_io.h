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
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

// Largest file (after decompression) the loaders read into memory.
#define DRIFT_SCENE_MAX_FILE_BYTES ((size_t)1 << 30)

// Loads a scene file or a mesh file, chosen by extension (case-insensitive): .json, .obj,
// .gltf, .glb, .ply, or one of those followed by .gz. Returns a committed scene.
drift_result drift_scene_load(drift_context *ctx, const char *path, drift_scene **out_scene);

// The file formats drift_scene_load reads, one row each of the loaders' registry
// (src/io/scene_formats.c): the commands' --help and the docs list them from it.
typedef struct drift_scene_format {
    const char *extension; // lower case, without the dot: "json", "obj", ...
    const char *summary;   // one line: what the file is and what reads it
    bool gz;               // also read gzip-compressed, as NAME.EXT.gz
    bool mesh;             // a mesh file: a scene file's meshes may name one
} drift_scene_format;

int drift_scene_format_count(void);
const drift_scene_format *drift_scene_format_get(int index); // NULL out of range
// The format that reads `path`, by its extension (case-insensitive, looking through a
// trailing .gz when the format reads gzip), or NULL when no loader reads it.
const drift_scene_format *drift_scene_format_of(const char *path);

// Writes the scene-format reference as Markdown (docs/reference/scene-formats.md): the
// registry's formats and the tables the readers check against: the JSON files' keys, the glTF
// extensions, the OBJ/MTL statements and the Mitsuba plugins drift reads.
void drift_scene_formats_markdown(FILE *out);

// A file a scene load reads: the scene file, then each mesh file and texture it names, once
// a path, as the loader opens them (drift render refuses outputs that name one of them).
typedef void (*drift_scene_input_fn)(const char *path, void *user);

// drift_scene_load that also calls on_input(path, user) for each file it reads (on_input may
// be NULL). Paths are as the loader opened them (joined to the scene file's folder).
drift_result drift_scene_load_inputs(drift_context *ctx, const char *path,
                                     drift_scene_input_fn on_input, void *user,
                                     drift_scene **out_scene);

// drift_scene_load_inputs with the camera of a glTF file (.gltf, .glb, the scene itself) chosen
// by its name, or by its index in the file's `cameras` (`camera` NULL: the first). A camera the
// file does not have is DRIFT_ERR_INVALID_ARGUMENT, logged with the names it has; another kind
// of scene file is DRIFT_ERR_UNSUPPORTED (a JSON scene names its glTF's camera in the mesh
// entry's "camera").
drift_result drift_scene_load_camera(drift_context *ctx, const char *path, const char *camera,
                                     drift_scene_input_fn on_input, void *user,
                                     drift_scene **out_scene);

// Parses a drift scene file from memory. `text` need not be NUL-terminated. Paths in the
// file are relative to `base_dir` (NULL: the current directory). `name_for_messages` names
// the text in log messages (NULL: "<memory>"). Returns a committed scene.
drift_result drift_scene_load_json_text(drift_context *ctx, const char *text, size_t length,
                                        const char *base_dir, const char *name_for_messages,
                                        drift_scene **out_scene);

// --- glTF NODE ANIMATION ---
//
// The meshes and punctual lights of a glTF scene that its animations move (docs/temporal.md,
// "glTF animation"): node translation, rotation and scale channels, parents included, every
// animation of the file at once. Posing the scene at time t writes each moved mesh's vertices,
// normals and tangents (from the rest pose the file placed, kept here) and each moved light's
// position and direction, and commits the scene again (bounds, emissive triangles' lights);
// the caller rebuilds what copied the geometry (drift_accel, the hybrid frame's per-scene
// state: drift_hybrid_scene_changed). Skins and morph-target weights are not played (the
// loader warns). The camera's animation is drift_camera_path_from_gltf's.
//
//   drift_scene_animation *anim = NULL;
//   drift_scene_animation_from_gltf(ctx, "anim.glb", scene, &anim);   // NULL: nothing moves
//   bool moved; drift_scene_animation_pose(anim, frame / fps, &moved);
//   if (moved) { rebuild the accel ... }
typedef struct drift_scene_animation drift_scene_animation;

// Reads the animations of the glTF file `path` that `scene` was loaded from (the scene's
// meshes and lights record their nodes: drift_mesh.node). *out is NULL when no animation moves
// one of the scene's meshes or lights. Errors: those of reading the animations (logged, with
// the file), DRIFT_ERR_OUT_OF_MEMORY. The scene must outlive the animation.
drift_result drift_scene_animation_from_gltf(drift_context *ctx, const char *path,
                                             drift_scene *scene, drift_scene_animation **out);
void drift_scene_animation_destroy(drift_scene_animation *anim); // NULL-safe
// Poses the scene at `time` (seconds) and commits it; *out_moved (may be NULL) is whether any
// vertex or light changed since the last pose (the load's pose first). A node at its rest
// transform gets its rest geometry back bit for bit. Errors: a degenerate or non-finite pose
// (zero scale), logged with the time; the scene is then left at its rest pose.
drift_result drift_scene_animation_pose(drift_scene_animation *anim, double time, bool *out_moved);
// How each of the scene's meshes moved between the last two poses: out[12 m .. 12 m + 11]
// is the row-major 3 x 4 affine map taking mesh m's points now to where they were (the
// identity for a mesh that did not move), for drift_hybrid_set_mesh_motion's motion vectors.
// mesh_count must be the scene's.
drift_result drift_scene_animation_motion(const drift_scene_animation *anim, float *out,
                                          uint32_t mesh_count);
// Whether the file's first camera is animated (drift_camera_path_from_gltf plays it).
bool drift_scene_animation_camera_moves(const drift_scene_animation *anim);
// How many of the scene's meshes and lights the animation moves.
uint32_t drift_scene_animation_mesh_count(const drift_scene_animation *anim);
uint32_t drift_scene_animation_light_count(const drift_scene_animation *anim);

// --- CAMERA VIEWS ---
//
// A views file names cameras of one scene by what they change from its camera (the rows of
// `drift bench sir --views`):
//   {"views": [{"name": "high", "position": [x, y, z], "target": [x, y, z], "fov_y": 40,
//               "aperture_radius": 0}, ...]}
// Every field but "name" (letters, digits, '_', '-': it names output files) is optional.
// Errors are logged with the file and line, as for scene files.

#define DRIFT_CAMERA_VIEWS_MAX_FILE_BYTES ((size_t)1 << 20)

typedef struct drift_camera_view {
    char name[64];
    bool has_position, has_target, has_fov, has_aperture;
    drift_vec3 position, target;
    float fov_y; // radians
    float aperture_radius;
} drift_camera_view;

// Reads up to `capacity` views (more is an error) into views[0 .. *out_count).
drift_result drift_camera_views_load(drift_context *ctx, const char *path, drift_camera_view *views,
                                     uint32_t capacity, uint32_t *out_count);
drift_result drift_camera_views_load_json_text(drift_context *ctx, const char *text, size_t length,
                                               const char *name_for_messages,
                                               drift_camera_view *views, uint32_t capacity,
                                               uint32_t *out_count);
// Overrides the camera's fields the view sets.
void drift_camera_view_apply(const drift_camera_view *view, drift_camera *camera);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_SCENE_IO_H
