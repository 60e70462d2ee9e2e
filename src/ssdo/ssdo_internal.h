// Private parts of the ssdo module shared by its files.
#ifndef DRIFT_SSDO_INTERNAL_H
#define DRIFT_SSDO_INTERNAL_H

#include "drift/ssdo.h"

#include <math.h>

#define SSDO_PI 3.14159265358979323846f
// Cone-filtered levels: level k has the lobe of N = 2^k samples.
#define SSDO_ENV_LEVELS 9

// Octahedral copies of the maps that the renders read: no trigonometry per lookup.
#define SSDO_OCT_SIZE 128

struct drift_ssdo_env {
    drift_context *ctx;
    int32_t width, height;           // of every lat-long map
    float *irradiance;               // width*height*3, E / pi
    float *cone[SSDO_ENV_LEVELS];    // width*height*3 each
    float *oct[SSDO_ENV_LEVELS + 1]; // SSDO_OCT_SIZE^2 * 3: irradiance, then the cones
};

// Octahedral map about +y (the world's up): [0,1]^2 <-> unit directions.
static inline drift_vec2 ssdo_dir_to_oct(drift_vec3 d)
{
    float a = fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
    float px = d.x / a, pz = d.z / a;
    if (d.y < 0.0f) {
        float fx = (1.0f - fabsf(pz)) * (px >= 0.0f ? 1.0f : -1.0f);
        float fz = (1.0f - fabsf(px)) * (pz >= 0.0f ? 1.0f : -1.0f);
        px = fx;
        pz = fz;
    }
    return drift_vec2_make(0.5f * (px + 1.0f), 0.5f * (pz + 1.0f));
}

static inline drift_vec3 ssdo_oct_to_dir(drift_vec2 uv)
{
    float px = 2.0f * uv.x - 1.0f, pz = 2.0f * uv.y - 1.0f;
    float y = 1.0f - fabsf(px) - fabsf(pz);
    if (y < 0.0f) {
        float fx = (1.0f - fabsf(pz)) * (px >= 0.0f ? 1.0f : -1.0f);
        float fz = (1.0f - fabsf(px)) * (pz >= 0.0f ? 1.0f : -1.0f);
        px = fx;
        pz = fz;
    }
    return drift_vec3_normalize(drift_vec3_make(px, y, pz));
}

// Lat-long coordinates of docs/conventions.md: u = phi / 2 pi, phi = atan2(-z, x) in
// [0, 2 pi); v = theta / pi from +y.
static inline drift_vec2 ssdo_dir_to_uv(drift_vec3 d)
{
    float phi = atan2f(-d.z, d.x);
    if (phi < 0.0f) {
        phi += 2.0f * SSDO_PI;
    }
    float theta = acosf(drift_clampf(d.y, -1.0f, 1.0f));
    return drift_vec2_make(phi / (2.0f * SSDO_PI), theta / SSDO_PI);
}

static inline drift_vec3 ssdo_uv_to_dir(drift_vec2 uv)
{
    float phi = uv.x * 2.0f * SSDO_PI, theta = uv.y * SSDO_PI;
    float s = sinf(theta);
    return drift_vec3_make(s * cosf(phi), cosf(theta), -s * sinf(phi));
}

static inline float ssdo_smoothstep(float a, float b, float x)
{
    float t = drift_clampf((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

#endif
