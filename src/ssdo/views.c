// Additional cameras (thesis §4.3.3): depth buffers of the scene from beside the viewer, so that
// blockers outside the viewer's image (or hidden in it) still occlude. The thesis rasterises
// four cameras aimed at the viewer's centre of interest, offset by hand-chosen displacements
// scaled by the scene's bounding-sphere radius, at a lower resolution; we cast one ray a
// texel (drift has no rasteriser) and add a guard band: every view has twice the viewer's
// tan(fov/2), and view 0 sits at the eye.
#include "drift/ssdo.h"

#include <math.h>
#include <string.h>

#define VIEW_OFFSET 0.25f // x the bounding-sphere radius

typedef struct views_job {
    const drift_accel *accel;
    drift_camera_frame cam;
    drift_image *out;
} views_job;

static void view_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const views_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->out->width; ++x) {
            drift_ray ray = drift_camera_frame_ray(&j->cam, (float)x + 0.5f, (float)y + 0.5f,
                                                   drift_vec2_make(0.5f, 0.5f));
            drift_hit hit;
            float z = 0.0f;
            if (drift_accel_intersect(j->accel, &ray, &hit)) {
                z = hit.t * drift_vec3_dot(ray.dir, j->cam.w);
            }
            drift_image_pixel(j->out, x, y)[0] = z;
        }
    }
}

// The first hit along `ray` within tmax, or tmax.
static float free_distance(const drift_accel *accel, drift_vec3 origin, drift_vec3 dir, float tmax)
{
    drift_ray ray = { .origin = origin, .dir = dir, .tmin = 0.0f, .tmax = tmax };
    drift_hit hit;
    return drift_accel_intersect(accel, &ray, &hit) ? hit.t : tmax;
}

void drift_ssdo_views_destroy(drift_context *ctx, drift_ssdo_view *views, int32_t count)
{
    for (int32_t k = 0; views && k < count; ++k) {
        drift_image_destroy(ctx, &views[k].depth);
    }
}

drift_result drift_ssdo_views_render(drift_context *ctx, const drift_scene *scene,
                                     const drift_accel *accel, const drift_camera *camera,
                                     int32_t count, int32_t width, int32_t height,
                                     drift_ssdo_view *views)
{
    if (!ctx || !scene || !accel || !camera || !views || count < 1 ||
        count > DRIFT_SSDO_MAX_VIEWS || width < 1 || height < 1) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ssdo views: needs the scene, its accel, a camera, 1..%d views and a size",
                  DRIFT_SSDO_MAX_VIEWS);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    memset(views, 0, sizeof(*views) * (size_t)count);
    drift_camera_frame eye = drift_camera_frame_make(camera, width, height);
    float radius = 0.5f * drift_scene_extent(scene);
    // The centre of interest: where the viewer's centre ray meets the scene (or one radius on).
    drift_vec3 from = camera->position;
    float t = free_distance(accel, from, eye.w, INFINITY);
    drift_vec3 target = drift_vec3_fma(from, eye.w, isfinite(t) ? t : radius);
    float fov = 2.0f * atanf(2.0f * eye.tan_half);
    const drift_vec3 moves[DRIFT_SSDO_MAX_VIEWS] = { drift_vec3_splat(0.0f), eye.u,
                                                     drift_vec3_neg(eye.u), eye.v,
                                                     drift_vec3_neg(eye.v) };
    for (int32_t k = 0; k < count; ++k) {
        drift_vec3 position = from;
        if (!drift_vec3_is_zero(moves[k])) {
            // Stay in the viewer's free space: stop short of any surface on the way.
            float go = VIEW_OFFSET * radius;
            go = 0.9f * free_distance(accel, from, moves[k], go);
            position = drift_vec3_fma(from, moves[k], go);
        }
        drift_vec3 up = fabsf(drift_vec3_dot(drift_vec3_normalize(drift_vec3_sub(target, position)),
                                             eye.v)) < 0.999f
                            ? eye.v
                            : eye.u;
        views[k].camera = drift_camera_look_at(position, target, up, fov, width, height);
        drift_result r = drift_image_create(ctx, width, height, 1, &views[k].depth);
        if (r != DRIFT_OK) {
            drift_ssdo_views_destroy(ctx, views, k);
            return r;
        }
        views_job j = { .accel = accel,
                        .cam = drift_camera_frame_make(&views[k].camera, width, height),
                        .out = &views[k].depth };
        drift_parallel_for(ctx, (size_t)height, 4, view_rows, &j);
    }
    return DRIFT_OK;
}
