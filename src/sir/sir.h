// Smart Image Refinement's state, shared by its files: refine.c (lifecycle, begin/iterate,
// planes), metrics.c (the error metrics), raytrace.c (the pure ray tracer), schedule.c (the
// sort and the request list), lambda.c (the lambda fit and its file).
#ifndef DRIFT_SIR_H
#define DRIFT_SIR_H

#include "drift/refine.h"
#include "hybrid/frame_access.h"
#include "realtime/realtime.h"

// --- THE PURE RAY TRACER (raytrace.c) ---

// What every sample of one view shares. The lights are the hybrid frame's (a mesh light is
// one light), so ray tracer and raster sum the same terms.
typedef struct drift_refine_tracer {
    const drift_scene *scene;
    const drift_accel *accel;
    const drift_raster_light *lights;
    uint32_t light_count;
    drift_camera_frame camera;
    uint32_t seed;
    int32_t max_depth;      // reflection bounces
    uint32_t light_samples; // shadow rays a light (and toward the environment) at each hit:
                            // the frame's light_samples, the raster's count for U_l
    const drift_reflection_edits *reflection_edits; // the frame's: the first bounce follows e(q)
} drift_refine_tracer;

drift_refine_tracer drift_refine_tracer_make(const drift_frame_state *frame, uint32_t seed,
                                             int32_t max_depth);
// One sample of pixel (x, y): the same for a sample index whoever asks (refinement or the pure
// image), adding the rays it traced to *rays. reflection_only: only the camera hit's
// reflection term R (no emission, no direct light there: no shadow rays at the first hit),
// the same R as the full sample's, drawn from the same sampler pairs.
drift_vec3 drift_refine_trace_sample(const drift_refine_tracer *tracer, int32_t x, int32_t y,
                                     uint32_t sample, bool reflection_only, uint64_t *rays);
// Radiance back along one ray, as a reflection ray of the tracer sees it (see_emission: a
// mirror's ray; a glossy ray leaves emitters to the direct term), up to max_depth bounces.
drift_vec3 drift_refine_trace_ray(const drift_refine_tracer *tracer, drift_ray ray,
                                  bool see_emission, drift_sampler *sampler, uint64_t *rays);

// --- PENUMBRA ESTIMATE (penumbra.c) ---

// Penumbra estimate for SIR's shadow error: 1 where the light may be partly hidden from p
// (blockers in the cone to the light and an unblocked tap in their backprojected region),
// 0 in umbra and where nothing blocks. Conservative up to the tap spacing. 0 for point lights.
float drift_shadow_map_penumbra(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n);

// The same with options: light_size > 0 replaces the map's bounding radius in the cone and
// backprojection (clamped to it: a tighter bound of the light as seen from p); exhaustive taps
// every grid point instead of skipping regions the min-depth mip proves free of blockers (the
// same result, slower: for tests); taps_only taps the finest levels too instead of testing
// every texel they cover (which finds the same blockers and maybe more: for tests).
typedef struct drift_penumbra_query {
    float light_size;
    bool exhaustive;
    bool taps_only;
} drift_penumbra_query;

float drift_shadow_map_penumbra_query(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n,
                                      const drift_penumbra_query *query);

// --- METRICS (metrics.c) ---

typedef struct drift_refine_metric_params {
    float edge_threshold;
    float ao_radius;
    uint32_t ao_samples;
    float reflection_tolerance; // <= 0: unweighted reflection metrics
    uint32_t lobe_samples;
    float leak_tolerance;   // <= 0: no leak metric
    float shadow_tolerance; // <= 0: the penumbra estimate ungated
    bool half_res_penumbra; // the penumbra estimate at each 2 x 2 block's corner (same surface)
    uint32_t seed;
} drift_refine_metric_params;

// Fills out[m] (1 channel, the frame's size) for every metric from the frame's last render.
// Returns the rays the metrics cast (not counting shadow maps they had to build).
uint64_t drift_refine_compute_metrics(drift_frame_state *frame,
                                      const drift_refine_metric_params *params,
                                      drift_image out[DRIFT_METRIC_COUNT]);
// E = average or min(1, sum lambda_i E_i); written to `combined` (1 channel).
void drift_refine_combine_metrics(const drift_image metrics[DRIFT_METRIC_COUNT],
                                  drift_refine_combine combine,
                                  const float lambda[DRIFT_METRIC_COUNT], drift_image *combined);

// --- SCHEDULE (schedule.c) ---

// Sort key of an error in [0,1]: descending error ascending key; any non-zero error keys
// below zero's (DRIFT_REFINE_ZERO_KEY), however small.
#define DRIFT_REFINE_ZERO_KEY 0xffffu
uint32_t drift_refine_encode_error(float error);
// Stable LSD radix sort of pixel indices 0..count-1 by key (16 bits, two 8-bit passes).
// order and scratch hold count entries; order gets the pixels, scratch is work space.
void drift_refine_radix_sort(const uint16_t *keys, uint32_t count, uint32_t *order,
                             uint32_t *scratch);

#endif
