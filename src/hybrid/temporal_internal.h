// Temporal reuse's parts shared by its refinements (temporal_still.c, temporal_moving.c): a
// second signal accumulated through the reprojection of drift_temporal_apply's last frame (the
// same taps, the same disocclusion tests), its variance, the variance-guided filter, and the
// error-weighted blend of a biased image with a path-traced estimate.
#ifndef DRIFT_TEMPORAL_INTERNAL_H
#define DRIFT_TEMPORAL_INTERNAL_H

#include "drift/temporal.h"

// One accumulated signal: its demodulated lighting, luminance moments and history length, in
// the current and previous frames' planes (indexed as the drift_temporal's), this frame's
// demodulated luminance and the filter's ping-pong planes (lighting and variance of the mean).
typedef struct temporal_layer {
    drift_image light[2];   // 3
    drift_image moments[2]; // 2
    drift_image length[2];  // 1
    drift_image sample_lum; // 1
    drift_image filter[2];  // 4
    int32_t max_history;
    bool has_prev; // the previous planes hold this layer's last frame
} temporal_layer;

drift_result temporal_layer_init(drift_context *ctx, int32_t width, int32_t height,
                                 int32_t max_history, temporal_layer *layer);
void temporal_layer_free(drift_context *ctx, temporal_layer *layer);

// Accumulates `color` (the frame of t's last drift_temporal_apply, demodulated by its G-buffer
// g) into `layer` through that apply's reprojection taps, estimates the variance of each
// pixel's mean and runs `passes` passes of t's variance-guided filter. Returns the filtered
// plane (4 channels: lighting, variance); *raw_variance (1 channel, may be NULL) gets the
// unfiltered variance of the mean. Call once after each drift_temporal_apply.
// `sampled` (width x height, row by row; NULL: every pixel) marks the pixels `color` holds a
// sample for: the others keep their reprojected history without a new sample (N unchanged),
// and one with no history either is unknown (variance -1 in the filter's plane) until the
// filter fills it from known neighbours; one still unknown after the passes keeps -1.
const drift_image *temporal_layer_apply(drift_temporal *t, temporal_layer *layer,
                                        const drift_gbuffer *g, const drift_image *color,
                                        const uint8_t *sampled, int32_t passes,
                                        drift_image *raw_variance);
// The layer's accumulated (unfiltered) lighting of the current frame.
const drift_image *temporal_layer_light(const drift_temporal *t, const temporal_layer *layer);
// c = e + a l per pixel over g (the first three channels of `light`); where g sees no surface,
// `misses`'s pixel.
void temporal_remodulate(drift_temporal *t, const drift_gbuffer *g, const drift_image *light,
                         const drift_image *misses, drift_image *out);
// The temporal's image size.
void temporal_size(const drift_temporal *t, int32_t *width, int32_t *height);
// The albedo the lighting is demodulated by (at least 0.01 a channel).
drift_vec3 temporal_demodulation(const drift_gbuffer *g, int32_t x, int32_t y);

// The error-weighted blend of the still and moving refinements (docs/temporal.md):
//   e_h = max(B[(Y_h - Y_p)^2] - B[v_p], 0),  e_p = denoised_error B[v_d or v_p]
//   w = e_h / (e_h + e_p),  out = (1 - w) hybrid + w denoised
// Y_h the hybrid's luminance, Y_p the raw path-traced mean's (`raw`), v_p the variance of that
// mean (1 channel), v_d the denoised image's variance where the filter estimates it
// (`denoised_variance`, 1 channel; NULL: v_p's), B a (2r+1)^2 box mean.
// scratch: 4 arrays of width x height floats (the fourth only with denoised_variance). Rows run
// on ctx's threads; every pixel is a gather, so the result does not depend on their number.
void temporal_error_blend(drift_context *ctx, const drift_image *hybrid, const drift_image *raw,
                          const drift_image *variance, const drift_image *denoised,
                          const drift_image *denoised_variance, float denoised_error,
                          int32_t radius, float *scratch[4], drift_image *out, drift_image *weight);

#endif // DRIFT_TEMPORAL_INTERNAL_H
