// drift camera paths: a camera that moves in time, from keyframes (a JSON file, docs/temporal.md)
// or from a glTF camera animation. `drift render --camera-path F.json --animation A:B` renders
// frames A..B of it; the time of frame f is f / fps.
//
// A camera path file:
//   {"fps": 24, "interpolation": "centripetal",
//    "keyframes": [{"time": 0, "position": [x, y, z], "target": [x, y, z], "fov_y": 40,
//                   "aperture_radius": 0, "focus_distance": 2.5}, ...]}
// "time" is in seconds and strictly increasing; "position" and "target" are required in every
// keyframe; "fov_y" (degrees), "aperture_radius" and "focus_distance" are optional (a key that
// lacks one takes the scene camera's value). "fps" (default 24) and "interpolation" (centripetal,
// the default: centripetal Catmull-Rom through positions and targets, Catmull-Rom through the
// scalars; or linear; or step) are optional. Errors are logged with the file and line.
//
// Ownership: a path owns its keys; drift_camera_path_free releases them.
#ifndef DRIFT_CAMERA_PATH_H
#define DRIFT_CAMERA_PATH_H

#include "drift/core.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define DRIFT_CAMERA_PATH_MAX_FILE_BYTES ((size_t)16 << 20)
#define DRIFT_CAMERA_PATH_MAX_KEYS       (1u << 20)

typedef enum drift_camera_path_interpolation {
    DRIFT_CAMERA_PATH_CENTRIPETAL = 0, // centripetal Catmull-Rom (Yuksel et al. 2011)
    DRIFT_CAMERA_PATH_LINEAR = 1,
    DRIFT_CAMERA_PATH_STEP = 2,
} drift_camera_path_interpolation;

typedef struct drift_camera_key {
    double time; // seconds
    drift_vec3 position, target;
    bool has_fov, has_aperture, has_focus;
    float fov_y; // radians
    float aperture_radius;
    float focus_distance;
    bool has_up;   // a glTF camera's roll; without it the scene camera's up
    drift_vec3 up; // unit
} drift_camera_key;

typedef struct drift_camera_path {
    drift_camera_key *keys; // count keys, strictly increasing in time
    uint32_t count;
    double fps; // > 0; 24 unless the file says
    drift_camera_path_interpolation interpolation;
} drift_camera_path;

// Reads a camera path file (at most DRIFT_CAMERA_PATH_MAX_FILE_BYTES). On failure *out is
// empty and the reason is logged with the file and line. DRIFT_ERR_PARSE (malformed JSON or
// a wrong type), DRIFT_ERR_INVALID_ARGUMENT (a value out of range, times not increasing),
// DRIFT_ERR_IO, DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_camera_path_load(drift_context *ctx, const char *path, drift_camera_path *out);
drift_result drift_camera_path_load_json_text(drift_context *ctx, const char *text, size_t length,
                                              const char *name_for_messages,
                                              drift_camera_path *out);
void drift_camera_path_free(drift_context *ctx, drift_camera_path *path); // NULL-safe

// The camera animation of a glTF 2.0 file (.gltf, .glb, either .gz), sampled at frames
// first_frame..last_frame (time = frame / fps) into keys of position, target (one unit ahead)
// and up: the world transform of the node holding camera `camera` (a name or index of the
// file's `cameras`; NULL: the first), its animated parents included. Every animation of the
// file plays at once (translation, rotation, scale; LINEAR, STEP, CUBICSPLINE). Errors are
// logged with the file: DRIFT_ERR_PARSE (malformed animations, accessors out of their
// buffers), DRIFT_ERR_INVALID_ARGUMENT (NaN or absurd values; no animation moves the camera),
// DRIFT_ERR_UNSUPPORTED (sparse accessors), DRIFT_ERR_IO, DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_camera_path_from_gltf(drift_context *ctx, const char *path, const char *camera,
                                         double fps, long first_frame, long last_frame,
                                         drift_camera_path *out);

// The camera at `time` seconds: `base` (the scene's camera: size, up, and the fields keys
// leave out) with the path's position, target, field of view, aperture and focus
// interpolated (and the up vector when the keys have one). Before the first key and after the
// last, the end keys hold.
drift_camera drift_camera_path_eval(const drift_camera_path *path, const drift_camera *base,
                                    double time);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_CAMERA_PATH_H
