// The viewer's camera controller: fly, orbit, look and dolly on a drift_camera. The camera
// keeps its up vector, and pitching stops short of looking straight along it.
#include "view/view_internal.h"

#include <math.h>

#define ORBIT_RADIANS_PER_PIXEL 0.005f
#define MOVE_FRACTION           0.02f // of the scene's bounding-box diagonal, per key press
#define DOLLY_FACTOR            0.9f  // distance to the target times this per wheel notch
// How close (|cos|) the view direction may come to the up vector before pitching stops.
#define MAX_COS_TO_UP 0.995f

float drift_view_camera_step(const drift_scene *scene)
{
    float diagonal = drift_bounds3_is_empty(scene->bounds) ? 0.0f : drift_scene_extent(scene);
    if (!(diagonal > 0.0f) || !isfinite(diagonal)) {
        diagonal = drift_vec3_length(drift_vec3_sub(scene->camera.target, scene->camera.position));
    }
    return diagonal > 0.0f && isfinite(diagonal) ? MOVE_FRACTION * diagonal : 0.1f;
}

// Rotates v about the unit axis k by angle (Rodrigues).
static drift_vec3 rotate(drift_vec3 v, drift_vec3 k, float angle)
{
    float c = cosf(angle), s = sinf(angle);
    drift_vec3 r = drift_vec3_scale(v, c);
    r = drift_vec3_fma(r, drift_vec3_cross(k, v), s);
    return drift_vec3_fma(r, k, drift_vec3_dot(k, v) * (1.0f - c));
}

typedef struct camera_axes {
    drift_vec3 forward, right, up;
    float distance; // to the target
} camera_axes;

static bool camera_axes_of(const drift_camera *camera, camera_axes *out)
{
    drift_vec3 to_target = drift_vec3_sub(camera->target, camera->position);
    out->distance = drift_vec3_length(to_target);
    out->up = drift_vec3_normalize(camera->up);
    if (!(out->distance > 0.0f) || drift_vec3_is_zero(out->up)) {
        return false;
    }
    out->forward = drift_vec3_scale(to_target, 1.0f / out->distance);
    drift_vec3 right = drift_vec3_cross(out->forward, out->up);
    if (!(drift_vec3_length(right) > 1e-6f)) {
        return false;
    }
    out->right = drift_vec3_normalize(right);
    return true;
}

// Moves camera and target together by `amount` along `direction`.
static void camera_translate(drift_camera *camera, drift_vec3 direction, float amount)
{
    drift_vec3 delta = drift_vec3_scale(direction, amount);
    camera->position = drift_vec3_add(camera->position, delta);
    camera->target = drift_vec3_add(camera->target, delta);
}

bool drift_view_camera_fly(drift_camera *camera, drift_view_key key, float step)
{
    camera_axes axes;
    if (!camera_axes_of(camera, &axes)) {
        return false;
    }
    drift_vec3 direction;
    switch (key) {
    case DRIFT_VIEW_KEY_FORWARD:
    case DRIFT_VIEW_KEY_BACK:
        direction = axes.forward;
        break;
    case DRIFT_VIEW_KEY_LEFT:
    case DRIFT_VIEW_KEY_RIGHT:
        direction = axes.right;
        break;
    case DRIFT_VIEW_KEY_UP:
    case DRIFT_VIEW_KEY_DOWN:
        direction = axes.up;
        break;
    default:
        return false;
    }
    bool ahead =
        key == DRIFT_VIEW_KEY_FORWARD || key == DRIFT_VIEW_KEY_RIGHT || key == DRIFT_VIEW_KEY_UP;
    camera_translate(camera, direction, ahead ? step : -step);
    return true;
}

// Turns `v` (the view direction, or the offset from the target) by yaw about up and pitch
// about right, refusing a pitch that would bring it within acos(MAX_COS_TO_UP) of up.
static drift_vec3 turn(drift_vec3 v, const camera_axes *axes, float yaw, float pitch)
{
    v = rotate(v, axes->up, yaw);
    drift_vec3 right = drift_vec3_normalize(drift_vec3_cross(v, axes->up));
    drift_vec3 pitched = rotate(v, right, pitch);
    float cos_up = drift_vec3_dot(drift_vec3_normalize(pitched), axes->up);
    return fabsf(cos_up) < MAX_COS_TO_UP ? pitched : v;
}

bool drift_view_camera_drag(drift_camera *camera, drift_view_event_type type, float dx, float dy)
{
    camera_axes axes;
    if (!isfinite(dx) || !isfinite(dy) || (dx == 0.0f && dy == 0.0f) ||
        !camera_axes_of(camera, &axes)) {
        return false;
    }
    float yaw = -dx * ORBIT_RADIANS_PER_PIXEL, pitch = -dy * ORBIT_RADIANS_PER_PIXEL;
    if (type == DRIFT_VIEW_EVENT_ORBIT) {
        // The camera circles the target; dragging right swings it to the left, so the scene
        // appears to turn with the mouse. Pitch is negated for the same reason.
        drift_vec3 offset = drift_vec3_sub(camera->position, camera->target);
        camera->position = drift_vec3_add(camera->target, turn(offset, &axes, yaw, -pitch));
    } else {
        drift_vec3 direction = drift_vec3_sub(camera->target, camera->position);
        camera->target = drift_vec3_add(camera->position, turn(direction, &axes, yaw, pitch));
    }
    return true;
}

bool drift_view_camera_dolly(drift_camera *camera, float notches, float step)
{
    camera_axes axes;
    if (!isfinite(notches) || notches == 0.0f || !camera_axes_of(camera, &axes)) {
        return false;
    }
    float distance = axes.distance * powf(DOLLY_FACTOR, notches);
    float min_distance = 1e-3f * step;
    if (distance < min_distance) {
        distance = min_distance;
    }
    camera->position = drift_vec3_fma(camera->target, axes.forward, -distance);
    return true;
}
