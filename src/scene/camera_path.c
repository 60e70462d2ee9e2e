// Camera paths in time (drift/camera_path.h): which keyframes bracket a time, and the
// centripetal Catmull-Rom spline (Yuksel, Schaefer and Keyser 2011) through them. Positions and
// targets use the centripetal parameterisation (no cusps or self-intersections within a
// segment); the scalars use the uniform Catmull-Rom, clamped to their valid ranges.
#include "drift/camera_path.h"

#include "drift/math.h"

#include <math.h>
#include <stdlib.h>

void drift_camera_path_free(drift_context *ctx, drift_camera_path *path)
{
    if (!path) {
        return;
    }
    drift_free(ctx, path->keys);
    *path = (drift_camera_path){ 0 };
}

static drift_vec3 lerp3(drift_vec3 a, drift_vec3 b, float u)
{
    return drift_vec3_add(drift_vec3_scale(a, 1.0f - u), drift_vec3_scale(b, u));
}

// The knot step of the centripetal parameterisation, |b - a|^0.5, kept away from zero so that
// repeated points do not divide by zero.
static float knot_step(drift_vec3 a, drift_vec3 b)
{
    return fmaxf(sqrtf(drift_vec3_length(drift_vec3_sub(b, a))), 1e-6f);
}

// The centripetal Catmull-Rom segment p1 -> p2 at u in [0, 1] (Barry and Goldman's pyramid).
static drift_vec3 centripetal(drift_vec3 p0, drift_vec3 p1, drift_vec3 p2, drift_vec3 p3, float u)
{
    if (drift_vec3_length(drift_vec3_sub(p2, p1)) < 1e-12f) {
        return p1;
    }
    float t0 = 0.0f;
    float t1 = t0 + knot_step(p0, p1);
    float t2 = t1 + knot_step(p1, p2);
    float t3 = t2 + knot_step(p2, p3);
    float t = t1 + u * (t2 - t1);
    drift_vec3 a1 = lerp3(p0, p1, (t - t0) / (t1 - t0));
    drift_vec3 a2 = lerp3(p1, p2, (t - t1) / (t2 - t1));
    drift_vec3 a3 = lerp3(p2, p3, (t - t2) / (t3 - t2));
    drift_vec3 b1 = lerp3(a1, a2, (t - t0) / (t2 - t0));
    drift_vec3 b2 = lerp3(a2, a3, (t - t1) / (t3 - t1));
    return lerp3(b1, b2, (t - t1) / (t2 - t1));
}

static float catmull_rom(float p0, float p1, float p2, float p3, float u)
{
    float u2 = u * u, u3 = u2 * u;
    return 0.5f * (2.0f * p1 + (p2 - p0) * u + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * u2 +
                   (3.0f * p1 - p0 - 3.0f * p2 + p3) * u3);
}

static float key_fov(const drift_camera_key *k, const drift_camera *base)
{
    return k->has_fov ? k->fov_y : base->fov_y;
}

static float key_aperture(const drift_camera_key *k, const drift_camera *base)
{
    return k->has_aperture ? k->aperture_radius : base->aperture_radius;
}

static float key_focus(const drift_camera_key *k, const drift_camera *base)
{
    if (k->has_focus) {
        return k->focus_distance;
    }
    // 0 means "at the target": resolve it per key so that interpolation stays smooth.
    return base->focus_distance > 0.0f ? base->focus_distance
                                       : drift_vec3_length(drift_vec3_sub(k->target, k->position));
}

// The keys' up vectors between k1 and k2 (a glTF camera's roll), or the base camera's.
static drift_vec3 key_up(const drift_camera_key *k1, const drift_camera_key *k2, float u,
                         drift_vec3 base)
{
    if (!k1->has_up || !k2->has_up) {
        return k1->has_up ? k1->up : base;
    }
    drift_vec3 up = lerp3(k1->up, k2->up, u);
    return drift_vec3_length(up) > 1e-6f ? drift_vec3_normalize(up) : k1->up;
}

drift_camera drift_camera_path_eval(const drift_camera_path *path, const drift_camera *base,
                                    double time)
{
    drift_camera c = *base;
    if (!path || path->count == 0) {
        return c;
    }
    const drift_camera_key *k = path->keys;
    uint32_t n = path->count;
    // The segment [i, i + 1] holding the time (binary search); the ends hold outside.
    uint32_t i = 0;
    float u = 0.0f;
    if (!(time > k[0].time)) {
        i = 0;
        u = 0.0f;
    } else if (time >= k[n - 1].time) {
        i = n - 1;
        u = 0.0f;
    } else {
        uint32_t lo = 0, hi = n - 1; // k[lo].time < time < k[hi].time
        while (hi - lo > 1) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (k[mid].time <= time) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        i = lo;
        u = (float)((time - k[lo].time) / (k[hi].time - k[lo].time));
    }
    if (i == n - 1 || path->interpolation == DRIFT_CAMERA_PATH_STEP || u <= 0.0f) {
        c.position = k[i].position;
        c.target = k[i].target;
        c.up = key_up(&k[i], &k[i], 0.0f, base->up);
        c.fov_y = key_fov(&k[i], base);
        c.aperture_radius = key_aperture(&k[i], base);
        c.focus_distance = key_focus(&k[i], base);
        return c;
    }
    const drift_camera_key *k1 = &k[i], *k2 = &k[i + 1];
    c.up = key_up(k1, k2, u, base->up);
    if (path->interpolation == DRIFT_CAMERA_PATH_LINEAR) {
        c.position = lerp3(k1->position, k2->position, u);
        c.target = lerp3(k1->target, k2->target, u);
        c.fov_y = key_fov(k1, base) + u * (key_fov(k2, base) - key_fov(k1, base));
        c.aperture_radius =
            key_aperture(k1, base) + u * (key_aperture(k2, base) - key_aperture(k1, base));
        c.focus_distance = key_focus(k1, base) + u * (key_focus(k2, base) - key_focus(k1, base));
        return c;
    }
    // Centripetal: the neighbours, or a reflection of the segment at either end.
    drift_vec3 p0 = i > 0 ? k[i - 1].position
                          : drift_vec3_sub(drift_vec3_scale(k1->position, 2.0f), k2->position);
    drift_vec3 p3 = i + 2 < n ? k[i + 2].position
                              : drift_vec3_sub(drift_vec3_scale(k2->position, 2.0f), k1->position);
    drift_vec3 q0 =
        i > 0 ? k[i - 1].target : drift_vec3_sub(drift_vec3_scale(k1->target, 2.0f), k2->target);
    drift_vec3 q3 = i + 2 < n ? k[i + 2].target
                              : drift_vec3_sub(drift_vec3_scale(k2->target, 2.0f), k1->target);
    c.position = centripetal(p0, k1->position, k2->position, p3, u);
    c.target = centripetal(q0, k1->target, k2->target, q3, u);
    const drift_camera_key *k0 = i > 0 ? &k[i - 1] : k1;
    const drift_camera_key *k3 = i + 2 < n ? &k[i + 2] : k2;
    float fov =
        catmull_rom(key_fov(k0, base), key_fov(k1, base), key_fov(k2, base), key_fov(k3, base), u);
    float aperture = catmull_rom(key_aperture(k0, base), key_aperture(k1, base),
                                 key_aperture(k2, base), key_aperture(k3, base), u);
    float focus = catmull_rom(key_focus(k0, base), key_focus(k1, base), key_focus(k2, base),
                              key_focus(k3, base), u);
    c.fov_y = drift_clampf(fov, 1e-3f, DRIFT_PI - 1e-3f);
    c.aperture_radius = fmaxf(aperture, 0.0f);
    c.focus_distance = fmaxf(focus, 0.0f);
    return c;
}
