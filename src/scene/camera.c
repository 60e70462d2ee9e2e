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

drift_camera_frame drift_camera_frame_make(const drift_camera *camera, int32_t width,
                                           int32_t height)
{
    drift_camera_frame f = { .camera = *camera, .width = width, .height = height };
    drift_vec3 forward = drift_vec3_sub(camera->target, camera->position);
    f.w = drift_vec3_normalize(forward);
    f.u = drift_vec3_normalize(drift_vec3_cross(f.w, camera->up));
    f.v = drift_vec3_cross(f.u, f.w);
    f.tan_half = tanf(0.5f * camera->fov_y);
    f.aspect = (float)width / (float)height;
    f.focus = camera->focus_distance > 0.0f ? camera->focus_distance : drift_vec3_length(forward);
    return f;
}

drift_ray drift_camera_frame_ray(const drift_camera_frame *f, float film_x, float film_y,
                                 drift_vec2 lens)
{
    const drift_camera *camera = &f->camera;
    film_x += camera->film_shift_x;
    film_y += camera->film_shift_y;
    float sx = (2.0f * film_x / (float)f->width - 1.0f) * f->tan_half * f->aspect;
    float sy = (1.0f - 2.0f * film_y / (float)f->height) * f->tan_half;
    drift_vec3 dir = drift_vec3_add(
        f->w, drift_vec3_add(drift_vec3_scale(f->u, sx), drift_vec3_scale(f->v, sy)));
    drift_ray ray = { .origin = camera->position, .tmin = 0.0f, .tmax = INFINITY };
    if (camera->aperture_radius > 0.0f) {
        // Thin lens: every ray through the lens meets the pinhole ray on the focus plane.
        drift_vec3 focus_point = drift_vec3_fma(camera->position, dir, f->focus);
        drift_vec2 d = drift_sample_disk_concentric(lens);
        drift_vec3 lens_point =
            drift_vec3_add(camera->position,
                           drift_vec3_add(drift_vec3_scale(f->u, d.x * camera->aperture_radius),
                                          drift_vec3_scale(f->v, d.y * camera->aperture_radius)));
        ray.origin = lens_point;
        dir = drift_vec3_sub(focus_point, lens_point);
    }
    ray.dir = drift_vec3_normalize(dir);
    return ray;
}

bool drift_camera_frame_project(const drift_camera_frame *f, drift_vec3 p, drift_vec2 *out_film)
{
    drift_vec3 d = drift_vec3_sub(p, f->camera.position);
    float z = drift_vec3_dot(d, f->w);
    if (!(z > 0.0f)) {
        return false;
    }
    float sx = drift_vec3_dot(d, f->u) / (z * f->tan_half * f->aspect);
    float sy = drift_vec3_dot(d, f->v) / (z * f->tan_half);
    *out_film = drift_vec2_make(0.5f * (sx + 1.0f) * (float)f->width - f->camera.film_shift_x,
                                0.5f * (1.0f - sy) * (float)f->height - f->camera.film_shift_y);
    return true;
}

drift_ray drift_camera_ray(const drift_camera *camera, int32_t width, int32_t height, float film_x,
                           float film_y, drift_vec2 lens)
{
    drift_camera_frame f = drift_camera_frame_make(camera, width, height);
    return drift_camera_frame_ray(&f, film_x, film_y, lens);
}
