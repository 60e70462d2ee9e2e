// Depth peeling by a second ray (thesis §4.3.2, "multiple depth layers"): the second layer is
// the next surface along each pixel's camera ray behind the G-buffer's first hit. For a closed
// two-manifold solid that is where the ray leaves it, so a sample between the two layers lies
// inside the solid and one behind the second layer is in the open gap behind it.
#include "drift/ssdo.h"

typedef struct peel_job {
    const drift_accel *accel;
    const drift_gbuffer *gb;
    drift_camera_frame cam;
    drift_image *out;
} peel_job;

static void peel_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const peel_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->gb->width; ++x) {
            float *dst = drift_image_pixel(j->out, x, y);
            dst[0] = 0.0f;
            float z1 = drift_image_pixel(&j->gb->depth, x, y)[0];
            if (!(z1 > 0.0f)) {
                continue;
            }
            // The G-buffer's own ray through the pixel centre, continued past the first hit.
            drift_ray ray = drift_camera_frame_ray(&j->cam, (float)x + 0.5f, (float)y + 0.5f,
                                                   drift_vec2_make(0.5f, 0.5f));
            float cos_w = drift_vec3_dot(ray.dir, j->cam.w);
            float t1 = z1 / cos_w;
            ray.tmin = t1 * (1.0f + 1e-4f) + 1e-5f;
            ray.tmax = INFINITY;
            drift_hit hit;
            if (drift_accel_intersect(j->accel, &ray, &hit)) {
                dst[0] = hit.t * cos_w;
            }
        }
    }
}

drift_result drift_ssdo_peel(drift_context *ctx, const drift_accel *accel,
                             const drift_gbuffer *gbuffer, const drift_camera *camera,
                             drift_image *back_depth)
{
    if (!ctx || !accel || !gbuffer || !camera || !back_depth ||
        !drift_image_is_valid(&gbuffer->depth) || !drift_image_is_valid(back_depth) ||
        back_depth->width != gbuffer->width || back_depth->height != gbuffer->height) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ssdo peel: needs the accel, a G-buffer and a back-depth image of its size");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_camera camera_pinhole = *camera;
    camera_pinhole.aperture_radius = 0.0f;
    peel_job j = { .accel = accel,
                   .gb = gbuffer,
                   .cam = drift_camera_frame_make(&camera_pinhole, gbuffer->width, gbuffer->height),
                   .out = back_depth };
    drift_parallel_for(ctx, (size_t)gbuffer->height, 4, peel_rows, &j);
    return DRIFT_OK;
}
