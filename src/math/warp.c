#include "drift/math.h"

drift_vec2 drift_sample_disk_concentric(drift_vec2 u)
{
    // Shirley & Chiu 1997: map concentric squares to concentric circles.
    float a = 2.0f * u.x - 1.0f;
    float b = 2.0f * u.y - 1.0f;
    if (a == 0.0f && b == 0.0f) {
        return (drift_vec2){ 0.0f, 0.0f };
    }
    float r, phi;
    if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = (DRIFT_PI / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (DRIFT_PI / 2.0f) - (DRIFT_PI / 4.0f) * (a / b);
    }
    return (drift_vec2){ r * cosf(phi), r * sinf(phi) };
}

drift_vec3 drift_sample_cosine_hemisphere(drift_vec2 u)
{
    // Malley's method: project the uniform disk up to the hemisphere.
    drift_vec2 d = drift_sample_disk_concentric(u);
    float z = sqrtf(drift_maxf(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return (drift_vec3){ d.x, d.y, z };
}

drift_vec3 drift_sample_uniform_sphere(drift_vec2 u)
{
    float z = 1.0f - 2.0f * u.x;
    float r = sqrtf(drift_maxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * DRIFT_PI * u.y;
    return (drift_vec3){ r * cosf(phi), r * sinf(phi), z };
}

drift_vec3 drift_sample_uniform_cone(drift_vec2 u, float cos_max)
{
    float cos_theta = (1.0f - u.x) + u.x * cos_max;
    float sin_theta = sqrtf(drift_maxf(0.0f, 1.0f - cos_theta * cos_theta));
    float phi = 2.0f * DRIFT_PI * u.y;
    return (drift_vec3){ sin_theta * cosf(phi), sin_theta * sinf(phi), cos_theta };
}

drift_vec2 drift_sample_triangle(drift_vec2 u)
{
    // Heitz 2019, "A Low-Distortion Map Between Triangle and Square".
    float b0, b1;
    if (u.y > u.x) {
        b0 = u.x / 2.0f;
        b1 = u.y - b0;
    } else {
        b1 = u.y / 2.0f;
        b0 = u.x - b1;
    }
    return (drift_vec2){ b0, b1 };
}
