// The whole-frame path tracer that the equal-time frontier (drift bench frontier) and
// drift report's cells compare against: every effect, max depth RENDER_WHOLE_FRAME_DEPTH.
// Here, below both commands, so that drift report does not reach up into bench/.
#include "drift/pt.h"
#include "render.h"

// A copy of the first three channels of `src` into a new image.
static drift_result copy_rgb(drift_context *ctx, const drift_image *src, drift_image *out)
{
    drift_result r = drift_image_create(ctx, src->width, src->height, 3, out);
    for (int32_t y = 0; r == DRIFT_OK && y < src->height; ++y) {
        for (int32_t x = 0; x < src->width; ++x) {
            drift_image_set3(out, x, y, drift_image_get3(src, x, y));
        }
    }
    return r;
}

drift_result render_whole_frame_pt(drift_context *ctx, const drift_scene *scene,
                                   const drift_accel *accel, int32_t width, int32_t height,
                                   uint32_t spp, uint32_t seed, const atomic_bool *cancel,
                                   drift_image *out, uint64_t *rays)
{
    drift_pt_params params = {
        .width = width, .height = height, .seed = seed, .max_depth = RENDER_WHOLE_FRAME_DEPTH
    };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(ctx, scene, accel, &params, &pt);
    r = r ? r : drift_pt_render_samples(pt, spp, cancel);
    drift_image beauty;
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    r = r ? r : copy_rgb(ctx, &beauty, out);
    if (r == DRIFT_OK && rays) {
        drift_pt_stats st = drift_pt_get_stats(pt);
        *rays = st.camera_rays + st.shadow_rays + st.bounce_rays;
    }
    drift_pt_destroy(pt);
    return r;
}

drift_result render_whole_frame_reference(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, int32_t width, int32_t height,
                                          uint32_t spp, drift_image *out)
{
    return render_whole_frame_pt(ctx, scene, accel, width, height, spp, RENDER_WHOLE_FRAME_REF_SEED,
                                 NULL, out, NULL);
}
