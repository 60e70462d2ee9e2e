// Private to src/sir/metrics*.c: what the reflection metrics (metrics_reflection.c) and the
// shadow and DOF metrics with their driver (metrics.c) share.
#ifndef DRIFT_SIR_METRICS_INTERNAL_H
#define DRIFT_SIR_METRICS_INTERNAL_H

#include "sir/sir.h"

#include <math.h>

// A polygonal light's corners (a quad's four, a triangle's three, a small emissive mesh's
// vertices): the shadow metric bounds the light by them instead of its bounding sphere.
#define MAX_CORNERS 64

// A metric's value is its expected display-value error over this (the lambda fit's scale of
// the real error), so it orders pixels as the error does.
#define REAL_ERROR_SCALE 0.1f
// A raster shadow this close to 0 or 1 claims an umbra or full light.
#define CERTAIN_SHADOW 0.001f
// Penumbra pixels whose raster shadows differ by more are not averaged together: across a
// narrow contact shadow PCSS is too bright on one side and too dark on the other.
#define SIMILAR_SHADOW 0.15f
// The square over which the expected reflection error is averaged: 5 x 5 pixels.
#define EXPECTED_RADIUS 2

typedef struct light_shape {
    uint32_t count; // 0: use the bounding sphere
    bool planar;    // one-sided and every part faces `direction`: nothing lights its back
    drift_vec3 corner[MAX_CORNERS];
} light_shape;

// What a penumbra pixel's shadow rays say of the raster's shadow there.
typedef struct penumbra_check {
    drift_vec3 delta;  // the raster's estimated shadow error, summed over the area lights
    float raster;      // the raster's shadow S_l, averaged over those lights
    bool contradicted; // its own rays saw what a raster claiming certainty denies
} penumbra_check;

typedef struct metric_job {
    const drift_refine_metric_params *params;
    drift_image *out;
    float ao_radius;
    uint64_t ao_rays;
    light_shape *shapes;    // one a frame light, or NULL: bounding spheres
    float *expected;        // a pixel's expected reflection error (-1: not reflective), or NULL
    penumbra_check *checks; // a pixel: the raster's shadow checked by rays
    float *coarse;          // the penumbra estimate at each 2 x 2 block's corner pixel, a light
} metric_job;

static inline float drift__sir_display(float v)
{
    return powf(drift_clampf(v, 0.0f, 1.0f), 1.0f / 2.2f);
}

// How far the displayed pixel `base` moves when `delta` is added (largest channel, display
// values: clamp to [0,1], gamma 1/2.2, as the real error is measured).
static inline float drift__sir_display_change(drift_vec3 base, drift_vec3 delta)
{
    drift_vec3 moved = drift_vec3_add(base, delta);
    return fmaxf(fmaxf(fabsf(drift__sir_display(moved.x) - drift__sir_display(base.x)),
                       fabsf(drift__sir_display(moved.y) - drift__sir_display(base.y))),
                 fabsf(drift__sir_display(moved.z) - drift__sir_display(base.z)));
}

// Reflection metrics (metrics_reflection.c), run through drift_pass_for_each_pixel with a
// metric_job: a pixel's expected reflection error (job->expected), its 5 x 5 average, and the
// five reflection metrics.
void drift__sir_expected_error_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                     void *user);
void drift__sir_smooth_expected(const float *in, int32_t w, int32_t h, int32_t radius, float *out);
void drift__sir_reflection_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                 void *user);

#endif // DRIFT_SIR_METRICS_INTERNAL_H
