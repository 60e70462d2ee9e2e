// libFuzzer target for drift_camera_path_load_json_text: the input is a camera path file
// (drift render --camera-path). Any result code is fine; crashes, sanitizer reports and leaks
// are not. A successful load must hold 1 or more keys strictly increasing in time, and the
// camera it gives at any time must be finite.
#define _DEFAULT_SOURCE // mkstemps (fuzz_context.h)
#include "drift/camera_path.h"
#include "fuzz_context.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t total = 0;
    drift_context *ctx = fuzz_context(&total);
    if (!ctx) {
        return 0;
    }
    drift_camera_path path;
    drift_result r =
        drift_camera_path_load_json_text(ctx, (const char *)data, size, "fuzz.json", &path);
    if (r == DRIFT_OK) {
        if (path.count < 1 || !(path.fps > 0.0)) {
            __builtin_trap();
        }
        drift_camera base = drift_camera_look_at(drift_vec3_make(0, 0, 1), drift_vec3_make(0, 0, 0),
                                                 drift_vec3_make(0, 1, 0), 0.7f, 8, 8);
        double span = path.keys[path.count - 1].time - path.keys[0].time;
        for (int k = -1; k <= 9; ++k) {
            if (k >= 0 && k < (int)path.count &&
                path.keys[k > 0 ? k - 1 : 0].time > path.keys[k].time) {
                __builtin_trap();
            }
            drift_camera c =
                drift_camera_path_eval(&path, &base, path.keys[0].time + span * (double)k / 8.0);
            if (!isfinite(c.fov_y) || !isfinite(c.aperture_radius) || !isfinite(c.focus_distance)) {
                __builtin_trap();
            }
        }
    } else if (path.keys || path.count) {
        __builtin_trap();
    }
    drift_camera_path_free(ctx, &path);
    drift_context_destroy(ctx);
    return 0;
}
