#include "drift/scene.h"

drift_camera drift_camera_look_at(drift_vec3 position, drift_vec3 target, drift_vec3 up,
                                  float fov_y, int32_t width, int32_t height)
{
    return (drift_camera){ .position = position,
                           .target = target,
                           .up = up,
                           .fov_y = fov_y,
                           .width = width,
                           .height = height };
}

drift_ray drift_camera_ray(const drift_camera *camera, int32_t width, int32_t height, float film_x,
                           float film_y, drift_vec2 lens)
{
    // Right-handed camera frame: w forward, u image-right, v image-up.
    drift_vec3 forward = drift_vec3_sub(camera->target, camera->position);
    drift_vec3 w = drift_vec3_normalize(forward);
    drift_vec3 u = drift_vec3_normalize(drift_vec3_cross(w, camera->up));
    drift_vec3 v = drift_vec3_cross(u, w);
    float tan_half = tanf(0.5f * camera->fov_y);
    float aspect = (float)width / (float)height;
    float sx = (2.0f * film_x / (float)width - 1.0f) * tan_half * aspect;
    float sy = (1.0f - 2.0f * film_y / (float)height) * tan_half;
    drift_vec3 dir = drift_vec3_add(w, drift_vec3_add(drift_vec3_scale(u, sx), drift_vec3_scale(v, sy)));
    drift_ray ray = { .origin = camera->position, .tmin = 0.0f, .tmax = INFINITY };
    if (camera->aperture_radius > 0.0f) {
        // Thin lens: every ray through the lens meets the pinhole ray on the focus plane.
        float focus = camera->focus_distance > 0.0f ? camera->focus_distance
                                                    : drift_vec3_length(forward);
        drift_vec3 focus_point = drift_vec3_fma(camera->position, dir, focus);
        drift_vec2 d = drift_sample_disk_concentric(lens);
        drift_vec3 lens_point = drift_vec3_add(
            camera->position,
            drift_vec3_add(drift_vec3_scale(u, d.x * camera->aperture_radius),
                           drift_vec3_scale(v, d.y * camera->aperture_radius)));
        ray.origin = lens_point;
        dir = drift_vec3_sub(focus_point, lens_point);
    }
    ray.dir = drift_vec3_normalize(dir);
    return ray;
}
