// drift temporal: reuse across frames in the manner of SVGF (Schied et al. 2017, "Spatiotemporal
// Variance-Guided Filtering"). Each frame's noisy radiance is reprojected into the next frame by
// the hybrid frame's motion vectors, accumulated where the history still shows the same surface,
// and filtered by an edge-avoiding a-trous wavelet whose colour weight follows the variance
// estimated from the accumulated moments. docs/temporal.md has the equations and the figures.
//
// Per frame, for a pixel p that sees a surface (depth > 0, material m, normal n, world point X):
//   1. demodulate: the lighting l = (c - e) / max(a, 0.01) per channel (c colour, e emission,
//      a albedo); misses (depth 0) pass through untouched
//   2. reproject: q = p + motion(p) in the previous frame; each of q's four bilinear taps is kept
//      when its material equals m, its normal n' has n.n' >= normal_tolerance, and its world
//      point X' lies within depth_tolerance x p's depth of X's tangent plane (|n.(X' - X)|: a
//      plane test, so that sub-pixel offsets along a slanted surface keep their history).
//      No tap kept: a disocclusion, the history restarts (length 1)
//   3. accumulate: N = min(N_prev + 1, max_history), alpha = 1 / N; l_acc = lerp(l_hist, l,
//      alpha), moments (mu1, mu2) of the luminance with max(alpha, moments_alpha); the variance
//      of the mean is max(mu2 - mu1^2, 0) / N (below 4 frames the 7x7 spatial moments stand in)
//   4. filter: filter_passes a-trous passes (5x5 B3-spline, steps 1, 2, 4, ...) with SVGF's
//      weights: depth exp(-|z_p - z_q| / (depth_sigma 2^i z_p)), normal max(0, n_p.n_q)^128,
//      luminance exp(-|l_p - l_q| / (phi_luminance sqrt(var_p) + 1e-4)); the variance is
//      filtered with squared weights. The history keeps the unfiltered l_acc, so a still
//      camera converges to the mean of its frames (the reference when each frame is unbiased)
//   5. remodulate: c' = e + a l_filtered
//
// Settings (zeroed: the defaults; one place, so that they can become a knob-table row):
//   max_history      = 0 -> 32 frames (the accumulation's floor is alpha = 1 / 32)
//   moments_alpha    = 0 -> 0.2
//   depth_tolerance  = 0 -> 0.05 (relative)
//   normal_tolerance = 0 -> 0.9 (cosine)
//   filter_passes    = 0 -> 3; no_filter = true: none
//   phi_luminance    = 0 -> 4
//   depth_sigma      = 0 -> 1
//
// STEP BY STEP
//   drift_temporal *t = NULL;
//   drift_temporal_create(ctx, width, height, &(drift_temporal_settings){ 0 }, &t);
//   each frame: drift_hybrid_render(frame, &camera, NULL);
//               drift_temporal_apply(t, drift_hybrid_gbuffer(frame), &camera,
//                                    drift_hybrid_image(frame));
//               const drift_image *out = drift_temporal_image(t);
//   drift_temporal_destroy(t);
// A jump (a cut, changed techniques): drift_temporal_reset.
// Every pixel is a gather over the previous frame and pass: bit-identical for any thread count.
#ifndef DRIFT_TEMPORAL_H
#define DRIFT_TEMPORAL_H

#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct drift_temporal_settings {
    int32_t max_history;
    float moments_alpha;
    float depth_tolerance;
    float normal_tolerance;
    int32_t filter_passes;
    bool no_filter;
    float phi_luminance;
    float depth_sigma;
} drift_temporal_settings;

// The settings with every 0 replaced by its default.
drift_temporal_settings drift_temporal_settings_resolve(const drift_temporal_settings *s);

typedef struct drift_temporal drift_temporal;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (a size below 1, settings out of range: max_history 1..4096,
// moments_alpha, depth_tolerance and normal_tolerance in (0, 1], filter_passes 0..8),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_temporal_create(drift_context *ctx, int32_t width, int32_t height,
                                   const drift_temporal_settings *settings, drift_temporal **out);
void drift_temporal_destroy(drift_temporal *t); // NULL-safe
// Forgets the history: the next frame starts over.
void drift_temporal_reset(drift_temporal *t);

// Accumulates and filters one frame: `gbuffer` (its motion relative to the previous call's
// camera), the `camera` it was rendered with (the motion vectors carry its move; kept for
// drivers and later tests), and its noisy `color` (3 channels, the frame's size).
// DRIFT_ERR_INVALID_ARGUMENT on a size mismatch.
drift_result drift_temporal_apply(drift_temporal *t, const drift_gbuffer *gbuffer,
                                  const drift_camera *camera, const drift_image *color);
// Whether a driver of temporal reuse should give each frame of `params` a new seed (so that
// the history averages independent samples): true unless a chosen technique keeps state built
// from the seed that a new seed rebuilds (indirect micro: the point hierarchy; reflections
// micro and envmap: the hierarchy, the probes). Those keep their seed, and the frames differ by
// their sub-pixel offsets (and the camera's move) alone. Indirect ism and ir reseed: a new seed
// draws a new set of VPLs from the cached scene points (drift_ism_set_seed), so that the
// history gathers a different VPL set every frame (interleaving VPLs across frames).
bool drift_temporal_reseeds(const drift_hybrid_params *params);
// Frame k of a history (k = 0 after a reset) set up the one way the viewer and `drift render`
// (--animation, --frames with --temporal on) do: the seed base_seed + k when
// drift_temporal_reseeds(frame's params) (else the frame's seed is left alone), and the
// jitter of frame k added to *camera's film shift. Errors: drift_hybrid_set_params'.
drift_result drift_temporal_prepare(drift_hybrid *frame, uint32_t base_seed, uint32_t k,
                                    drift_camera *camera);
// Frame k's sub-pixel offset in pixels, in [-0.5, 0.5)^2: the Halton (2, 3) point k + 1, so
// that the history's samples cover the pixel's box filter evenly (add it to the camera's
// film_shift_x, film_shift_y).
drift_vec2 drift_temporal_jitter(uint32_t frame);

// The last frame's result (RGB) and each pixel's history length in frames (1 channel; 0 where
// the pixel sees no surface, 1 where its history was rejected).
const drift_image *drift_temporal_image(const drift_temporal *t);
const drift_image *drift_temporal_history(const drift_temporal *t);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_TEMPORAL_H
