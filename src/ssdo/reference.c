// The path-traced reference of the occlusion effect: what drift_pt computes for the same
// term, so that a technique's error against it is the technique's alone. Environment light
// with visibility at the first hit is DRIFT_PT_COMPONENT_DIRECT; the one diffuse bounce is
// DRIFT_PT_COMPONENT_DIFFUSE with max depth 2 (camera -> surface -> surface -> environment).
// Samples go through each pixel centre with a pinhole, the G-buffer's footprint.
#include "drift/pt.h"
#include "drift/ssdo.h"

#include <string.h>

drift_result drift_ssdo_reference(drift_context *ctx, const drift_scene *scene,
                                  const drift_accel *accel, const drift_camera *camera,
                                  int32_t width, int32_t height, uint32_t spp, uint32_t seed,
                                  bool bounce, drift_image *out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof(*out));
    if (!ctx || !scene || !accel || !camera || spp == 0) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_pt_params params = {
        .width = width,
        .height = height,
        .seed = seed,
        .max_depth = 2,
        .components = DRIFT_PT_COMPONENT_DIRECT | (bounce ? DRIFT_PT_COMPONENT_DIFFUSE : 0u),
        .pixel_centre = true,
        .pinhole = true,
        .camera = camera,
    };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(ctx, scene, accel, &params, &pt);
    if (r != DRIFT_OK) {
        return r;
    }
    r = drift_pt_render_samples(pt, spp, NULL);
    drift_image beauty;
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    r = r ? r : drift_image_create(ctx, width, height, 3, out);
    if (r == DRIFT_OK) {
        for (int32_t y = 0; y < height; ++y) {
            for (int32_t x = 0; x < width; ++x) {
                drift_image_set3(out, x, y, drift_image_get3(&beauty, x, y));
            }
        }
    }
    drift_pt_destroy(pt);
    return r;
}
