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
//   moving_history   = 0 -> 8 frames at most where the pixel moved since the last frame
//   moments_alpha    = 0 -> 0.2
//   depth_tolerance  = 0 -> 0.05 (relative)
//   normal_tolerance = 0 -> 0.9 (cosine)
//   filter_passes    = 0 -> 3; no_filter = true: none
//   phi_luminance    = 0 -> 4
//   depth_sigma      = 0 -> 1
//   no_still_refine  = false: a still camera's frames refine toward the path tracer (the
//                      drivers' drift_still_refine, below); true: the temporal image alone
//   moving_refine    = false; true: the drivers' drift_moving_refine (below) refines every
//                      frame, moving or not, toward reprojected path-traced samples
//   moving_refine_history = 0 -> 32 frames (its accumulation's floor alpha = 1 / 32)
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

#include "drift/accel.h"
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
    bool no_still_refine; // true: a still camera shows the temporal image alone (below)
    // false (the default, --still-refine progressive): once the camera stands, the drivers stop
    // rendering the hybrid frame and spend each frame on still_spp path-traced samples; true
    // (--still-refine on): they keep rendering it and blend the samples in
    // (drift_still_refine_settings.keeps_hybrid)
    bool still_keeps_hybrid;
    uint32_t still_spp; // 0 -> 4 (progressive) or 1 (on): path-traced samples a still frame
    // 0: off; 1: every frame refines toward reprojected path-traced samples; 2: the same with
    // their residual against the hybrid frame (drift_moving_refine, below; the drivers')
    int32_t moving_refine;
    int32_t moving_refine_history; // 0 -> 32: the path-traced accumulation's frames at most
    int32_t moving_refine_scale;   // 0, 1: a path-traced sample a pixel; 2: at half size
    int32_t moving_refine_period;  // 0, 1: every pixel every frame; P in 2, 4, 8, 16: 1/P of the
                                   // pixels a frame, each every P frames (a 4x4 Bayer order)
    int32_t moving_refine_passes;  // 0 -> 5: a-trous passes over its accumulation
    // 0: the history is resampled at each pixel's reprojected point by its 2 x 2 bilinear taps
    // (a moving camera's long history blurs: each frame filters it again); 1: by the 4 x 4
    // Catmull-Rom taps where all 16 show the pixel's surface, clamped to the 2 x 2 taps' range
    // (else bilinear), as TAA resamples (--temporal-resample)
    int32_t history_resample;
    // 0 -> 8: the frames a pixel that moved (its motion vector over MOVING_PIXELS) averages
    // at most, when below max_history. Each frame resamples a moving history bilinearly, so a
    // long one blurs; a still pixel keeps max_history and converges (--temporal-moving-history)
    int32_t moving_history;
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

// --- STILL REFINEMENT (--still-refine on|off; docs/temporal.md "Still camera") ---
//
// The temporal history converges to the hybrid frame's mean, which keeps the techniques' bias
// (ISM's one clamped bounce, shadow maps). Once the camera stands still, each frame also adds
// `spp` samples of drift's path tracer (drift/pt.h; through the unjittered camera, its own
// pixel jitter) to an accumulation, denoises it (drift_denoise_feature, `--denoise on`'s
// filter) and shows, per pixel, the blend of the two that the estimated errors favour:
//   Y_h the temporal image's luminance, Y_p and v_p the raw path-traced mean's and the
//   variance of that mean (DRIFT_PT_AOV_VARIANCE); over a (2r+1)^2 box window B:
//     hybrid error^2   e_h = max(B[(Y_h - Y_p)^2] - B[v_p], 0)   (its bias^2 plus its noise)
//     path error^2     e_p = denoised_error x B[v_p]             (what the filter leaves)
//     w = e_h / (e_h + e_p);  shown = (1 - w) hybrid + w denoised
// so the image moves to the path tracer as its error falls below the hybrid's, and converges
// to the reference. The first frame after a change of camera (or a reset: new techniques, a
// moved scene) starts the accumulation over and shows the hybrid alone; below 2 samples (no
// variance yet) the hybrid is shown. Bit-identical for any thread count (the path tracer's
// and the denoiser's guarantee; the blend is a gather).
typedef struct drift_still_refine_settings {
    uint32_t spp;         // 0 -> 4 path-traced samples a pixel each still frame (1 keeping hybrid)
    uint32_t seed;        // the path tracer's seed
    int32_t max_depth;    // 0 -> the path tracer's default (8)
    float denoised_error; // 0 -> 0.25: the denoised mean's error^2 over the raw mean's variance
    int32_t radius;       // 0 -> 4: the error windows' half-width in pixels
    // false (the default, --still-refine progressive): from the second still frame on the
    // drivers render no hybrid frame (drift_still_refine_needs_hybrid is false): the frame's time
    // goes to `spp` path-traced samples, the last temporal image is only the start, and the path
    // tracer's weight is at least n / (n + fade_samples) after n samples (fading the hybrid out by
    // sample count, so the image converges to the denoised path tracer). fade_samples 1, 4,
    // 16 at 400^2 after 4 samples: Cornell box 0.035, 0.042, 0.053 FLIP, Breakfast Room
    // 0.096, 0.099, 0.110 (docs/lab/2026-12-07-issue-47-s6.md): the path tracer's quick.
    // true (--still-refine on): every still frame renders the hybrid frame and blends `spp`
    // path-traced samples in where their error is the lower.
    bool keeps_hybrid;
    uint32_t fade_samples; // 0 -> 1
} drift_still_refine_settings;

typedef struct drift_still_refine drift_still_refine;

// Whether a frame of `params` can be refined: not under the frame's own glare pass or reflection
// edits (a constraint), which the path tracer does not render (the image would move to one
// without them).
bool drift_still_refine_applies(const drift_hybrid_params *params);
// scene and accel are borrowed and must outlive the object. Errors: DRIFT_ERR_INVALID_ARGUMENT
// (a size below 1, radius above 32), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_still_refine_create(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, int32_t width, int32_t height,
                                       const drift_still_refine_settings *settings,
                                       drift_still_refine **out);
void drift_still_refine_destroy(drift_still_refine *s); // NULL-safe
// Forgets the accumulation (new techniques, a moved scene): the next frame starts over.
void drift_still_refine_reset(drift_still_refine *s);
// One frame: `camera` is the frame's camera before drift_temporal_prepare's jitter (a camera
// unlike the last call's restarts the accumulation), `hybrid` the temporal image
// (drift_temporal_image). DRIFT_ERR_CANCELLED leaves the last image.
drift_result drift_still_refine_apply(drift_still_refine *s, const drift_camera *camera,
                                      const drift_image *hybrid, const atomic_bool *cancel);
// Whether this frame needs a new hybrid (temporal) image: false only for a progressive
// refinement whose camera stands where the last apply's did (its accumulation goes on).
bool drift_still_refine_needs_hybrid(const drift_still_refine *s, const drift_camera *camera);
// The shown image (RGB), the path tracer's weight per pixel (1 channel) and its samples.
const drift_image *drift_still_refine_image(const drift_still_refine *s);
const drift_image *drift_still_refine_weight(const drift_still_refine *s);
uint32_t drift_still_refine_samples(const drift_still_refine *s);

// --- MOVING REFINEMENT (--moving-refine on|off; docs/temporal.md "Moving camera") ---
//
// The still refinement for a camera that moves, in the manner of SVGF: each frame adds one
// path-traced sample a pixel (drift_pt through the frame's unjittered camera, a new seed a
// frame), demodulated by the hybrid frame's G-buffer, to an accumulation that is reprojected
// with the temporal history's own taps (drift_temporal_apply's motion vectors and depth,
// normal and material tests: no second reprojection), N = min(N_prev + 1, max_history), with
// its luminance moments; the accumulation is filtered by the temporal's variance-guided
// a-trous filter (filter_passes), which also estimates the filtered value's variance v_d, and
// blended with the temporal image per pixel by the still refinement's form with the filtered
// image in the raw mean's place: e_h = max(B[(Y_h - Y_d)^2] - B[v_d], 0), e_p = B[v_d],
// w = e_h / (e_h + e_p) over a (2r+1)^2 window (against the raw mean of a few one-sample
// frames the hybrid's bias drowned in the noise: weights of 0.1-0.2). Where the history is
// short (disocclusions, the first frames) the 7x7 spatial variance of this frame's samples
// stands in, large at one sample, so the hybrid is shown there. With `residual` the layer
// accumulates (sample - hybrid frame) and the candidate is hybrid + filtered residual.
// Call drift_moving_refine_apply after each drift_temporal_apply of the same temporal (its
// taps are that frame's); drift_temporal_reset goes with drift_moving_refine_reset.
// Bit-identical for any thread count (the path tracer's guarantee; the rest are gathers).
typedef struct drift_moving_refine_settings {
    uint32_t seed;         // frame k's path tracer takes seed + k (k counts applies)
    int32_t max_depth;     // 0 -> the path tracer's default (8)
    int32_t max_history;   // 0 -> 32
    int32_t filter_passes; // 0 -> 5 a-trous passes (one sample a frame is noisy)
    int32_t radius;        // 0 -> 4: the error windows' half-width in pixels
    // true: accumulate and filter the residual (path-traced sample - the hybrid frame) and
    // show hybrid + residual where the blend favours it (a control variate: the hybrid's
    // structure stays, the filter smooths only its bias and the path tracer's noise)
    bool residual;
    // 0, 1: a sample for every pixel; 2: the path tracer at half the width and height (a
    // quarter of the rays), each pixel taking the sample of the nearest half-size pixel whose
    // hit distance is closest to its G-buffer point's (a guided upsampling)
    int32_t scale;
    // 0, 1: every pixel gets a sample every frame. P = 2, 4, 8 or 16: a pixel gets one every P
    // frames, 1/P of them a frame, spread by the 4x4 Bayer matrix (P = 4: one pixel of each 2x2
    // quad); the others keep their reprojected history (not a new sample: N does not grow) and
    // the filter fills those that have none. The path tracer's cost a frame falls to 1/P.
    int32_t period;
} drift_moving_refine_settings;

typedef struct drift_moving_refine drift_moving_refine;

// scene, accel and temporal are borrowed. Errors: DRIFT_ERR_INVALID_ARGUMENT (settings out of
// range: max_history 1..4096, filter_passes 0..8, radius 0..32, scale 0..2, period 0, 1, 2,
// 4, 8 or 16; period above 1 with scale 2),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_moving_refine_create(drift_context *ctx, const drift_scene *scene,
                                        const drift_accel *accel, drift_temporal *temporal,
                                        const drift_moving_refine_settings *settings,
                                        drift_moving_refine **out);
void drift_moving_refine_destroy(drift_moving_refine *m); // NULL-safe
void drift_moving_refine_reset(drift_moving_refine *m);
// One frame: `gbuffer` and `frame` the G-buffer and colour drift_temporal_apply was just
// given, `camera` the frame's camera before drift_temporal_prepare's jitter, `hybrid` the
// temporal image.
// DRIFT_ERR_CANCELLED leaves the last image.
drift_result drift_moving_refine_apply(drift_moving_refine *m, const drift_gbuffer *gbuffer,
                                       const drift_camera *camera, const drift_image *frame,
                                       const drift_image *hybrid, const atomic_bool *cancel);
// The shown image (RGB), the path tracer's weight per pixel (1 channel), and the filtered
// path-traced accumulation alone (RGB).
const drift_image *drift_moving_refine_image(const drift_moving_refine *m);
const drift_image *drift_moving_refine_weight(const drift_moving_refine *m);
const drift_image *drift_moving_refine_path(const drift_moving_refine *m);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_TEMPORAL_H
