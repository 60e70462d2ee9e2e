// drift denoise: the edge-avoiding a-trous wavelet filter (Dammertz, Sewtz, Hanika & Lensch
// 2010, "Edge-Avoiding A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG
// 2010; the spatial filter of SVGF, Schied et al. 2017) over a noisy path-traced image, guided
// by the first hit's albedo, normal and depth (drift_pt_resolve's AOVs).
//
// Each of `iterations` passes convolves with the 5x5 B3-spline kernel (1/16, 1/4, 3/8, 1/4,
// 1/16) whose taps are 2^i pixels apart in pass i ("holes"), and multiplies each tap's kernel
// weight by three edge-stopping weights (taps outside the image are dropped and the weights
// renormalised):
//   colour  exp(-|c_p - c_q|^2 / (sigma_color^2 2^-i)) on the current pass's colours (the
//           demodulated ones when albedo is given), as Dammertz's sigma_rt halved each pass;
//           the distance is taken relative to the pair's mean luminance, |c_p - c_q|^2 /
//           ((lum_p + lum_q) / 2 + 1e-2)^2, so that one sigma fits dim and bright regions
//           alike (and a black noisy pixel still mixes with its bright neighbours)
//   normal  max(0, n_p . n_q)^sigma_normal (SVGF's form)
//   depth   exp(-|z_p - z_q| / (sigma_depth 2^i z_p)): a relative depth difference, scaled
//           with the tap distance so that slanted planes stay connected; a pixel whose ray
//           missed (z = 0) only mixes with other misses
// With albedo, the filter works on c / albedo (per channel; albedo below 1e-3 is taken as 1)
// and multiplies the result back (Zimmer et al. 2015, SVGF §4): texture detail is kept and
// only the lighting is smoothed. Any guide may be NULL (its weight is then 1).
//
//   albedo  exp(-|a_p - a_q|^2 / sigma_albedo^2): keeps texture and material edges
// Defaults (params zeroed): iterations 5, sigma_color 1, sigma_normal 128, sigma_depth 0.1,
// sigma_albedo 0.1, albedo demodulation on when albedo is given. sigma_color 1 is the best
// ꟻLIP of {0.5, 1, 4, 16, no colour weight} on the Cornell box at 2 spp (docs/frontier.md):
// without a variance estimate (SVGF's temporal part), a looser colour weight lets the
// emitter bleed into the ceiling (the path tracer's albedo AOV does not tell them apart).
//
// With small_kernel each pass takes the 3x3 linear B-spline (1/4, 1/2, 1/4) instead: 9 taps,
// not 25, for a footprint of 2^(n+1) - 1 pixels after n passes (the hybrid frame's filter of
// the environment light, drift_hybrid_params.environment_filter).
//
// Every output pixel is a gather over the previous pass alone, so the result is bit-identical
// for any thread count. A constant image (with constant guides) comes back unchanged up to
// float rounding.
//
// STEP BY STEP
//   drift_image out;                                           // made by the call
//   drift_denoise_atrous(ctx, &beauty, &albedo, &normal, &depth, NULL, &out);
//   ... drift_image_save_exr ... drift_image_destroy(ctx, &out);
//
// Errors: DRIFT_ERR_INVALID_ARGUMENT (invalid colour, a guide of another size, bad params;
// logged), DRIFT_ERR_OUT_OF_MEMORY. *out is zeroed on failure.
// Threads: uses drift_parallel_for, so not re-entrant from inside a worker.
#ifndef DRIFT_DENOISE_H
#define DRIFT_DENOISE_H

#include "drift/core.h"
#include "drift/image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct drift_denoise_params {
    int32_t iterations; // 0 -> 5 (kernel footprint 2^(n+1)+1 pixels); at most 10
    float sigma_color;  // 0 -> 1: relative colour distance, halved in variance each pass
    float sigma_normal; // 0 -> 128: exponent of the normal dot product
    float sigma_depth;  // 0 -> 0.1: relative depth difference per tap step
    float sigma_albedo; // 0 -> 0.1: albedo difference (keeps emitters and texture edges)
    bool no_demodulate; // true: filter the colour as it is even when albedo is given
    bool disable_color; // true: no colour weight (a guide-only cross-bilateral filter)
    bool small_kernel;  // true: the 3x3 kernel (1/4, 1/2, 1/4): 9 taps a pass, not 25
} drift_denoise_params;

drift_denoise_params drift_denoise_params_resolve(const drift_denoise_params *params);

// The albedo the filter divides the colour by and multiplies back: below 1e-3 (black, or an
// emitter's) it is 1, so that such a pixel's colour is filtered as it is. Also the hybrid
// frame's, where it carries the environment's light from pixel to pixel (docs/hybrid.md).
static inline float drift_denoise_albedo_divisor(float albedo)
{
    return albedo < 1e-3f ? 1.0f : albedo;
}

// Filters the first three channels of `color` into *out, a new 3-channel image of the same
// size (the caller destroys it). albedo and normal are read as RGB, depth as its first channel.
drift_result drift_denoise_atrous(drift_context *ctx, const drift_image *color,
                                  const drift_image *albedo, const drift_image *normal,
                                  const drift_image *depth, const drift_denoise_params *params,
                                  drift_image *out);

// --- THE FEATURE-GUIDED DENOISER (`drift render --denoise on`) ---
//
// drift's best denoiser for the path tracer (docs/denoiser.md). The input is the path
// tracer's beauty with its guides at the first non-delta vertex (DRIFT_PT_AOV_FEATURE_*) and
// the per-pixel variance of the mean (DRIFT_PT_AOV_VARIANCE, running moments). Stages:
//   1. sanitise: a non-finite value of any input is taken as 0 and counted (a warning gives
//      the count, drift_denoise_report.nonfinite); negative colour is taken as 0
//   2. demodulate: irradiance = colour / albedo per channel (drift_denoise_albedo_divisor),
//      so textures are multiplied back sharp at the end (Zimmer et al. 2015)
//   3. fireflies: a pixel's demodulated luminance above mean + 3 sd of its 5x5 window
//      (itself included), plus 3 sd of its own mean from 4 samples on, is scaled down to it
//      (its chroma kept). Scale-free, so HDR-safe; a lone 1-spp firefly keeps ~60 %.
//   4. variance v_p of the demodulated luminance's mean: the pixel's own (variance AOV over
//      the albedo luminance squared); below 4 samples (or without a variance image) at
//      least the 7x7 window's variance over n (SVGF §4.1's spatial estimate, unweighted)
//   5. the filter (method):
//      VARIANCE_GUIDED  SVGF's spatial filter (Schied et al. 2017, §4.2): `iterations`
//        a-trous passes of the 5x5 B3 kernel, taps 2^i apart, each weighed by
//          luminance exp(-|l_p - l_q| / (sigma_luminance (1 + 1/sqrt(n)) sqrt(g3x3(v_p))))
//          normal    max(0, n_p . n_q)^sigma_normal
//          depth     exp(-|z_p - z_q| / (sigma_depth 2^i z_p))
//          albedo    exp(-ln((a_p + 0.01) / (a_q + 0.01))^2 / sigma_albedo^2) (luminances)
//        with the variance carried through each pass (sum w^2 v / (sum w)^2): where the
//        samples agree (many spp) the luminance weight closes and little is blurred
//      REGRESSION  blockwise first-order feature regression (BMFR, Koskela et al. 2019):
//        in 32x32 blocks, overlapping by half and blended with tent weights, the
//        irradiance is fitted per channel by least squares (ridge 1e-3) to the features
//        1, normal, depth, depth^2, x, y, x^2, y^2 (scaled to [-1, 1] in the block)
//      REGRESSION_RESIDUAL  REGRESSION's fit (in residual_block blocks), plus the residual
//        (irradiance - fit) filtered VARIANCE_GUIDED with sigma_luminance_residual: the fit
//        carries the smooth light the luminance weight would break into blotches at few
//        samples, the residual filter the detail a low-order fit cannot follow
//   6. remodulate: times the albedo divisor again; clamped to >= 0
// With the direct part given (drift_denoise_inputs.direct), stages 1-6 run on the direct part
// and on the rest apart, and the two are summed: the direct part by `method`
// (sigma_luminance_direct), the rest by REGRESSION_RESIDUAL when `method` is VARIANCE_GUIDED
// (else by `method`; with indirect_variance_guided by VARIANCE_GUIDED, sigma_luminance_indirect).
// That default is never worse than the raw image on the 17 corpus scenes at 1, 4 and 16 spp;
// REGRESSION alone (without BMFR's temporal part) is worse at 16 spp on most
// (docs/lab/2026-12-07-issue-48-s3.md). Every output pixel is a gather (or a block fit) over
// the previous stage alone: bit-identical for any thread count.
typedef enum drift_denoise_method {
    DRIFT_DENOISE_VARIANCE_GUIDED = 0,
    DRIFT_DENOISE_REGRESSION,
    DRIFT_DENOISE_REGRESSION_RESIDUAL,
    DRIFT_DENOISE_METHOD_COUNT
} drift_denoise_method;

typedef struct drift_denoise_feature_params {
    drift_denoise_method method;
    int32_t iterations;             // 0 -> 4 (variance-guided passes); at most 10
    float sigma_luminance;          // 0 -> 4 (SVGF's sigma_l)
    float sigma_luminance_direct;   // 0 -> 4: sigma_l of the direct part when it is apart
    float sigma_luminance_indirect; // 0 -> 8: sigma_l of the rest when the direct part is apart
                                    // and filtered VARIANCE_GUIDED (indirect_variance_guided)
    float sigma_luminance_residual; // 0 -> 64 below 16 spp, 32 from 16: sigma_l of
                                    // REGRESSION_RESIDUAL's second step
    int32_t residual_block;         // 0 -> 64 px below 16 spp, 32 from 16: REGRESSION_RESIDUAL's
                                    // blocks (even, 8..128)
    bool indirect_variance_guided;  // true: the rest as the direct part, VARIANCE_GUIDED alone
    float sigma_normal;             // 0 -> 128
    float sigma_depth;              // 0 -> 0.1
    float sigma_albedo;             // 0 -> 1
    bool no_firefly_clamp;          // true: skip stage 3
    bool signed_color;              // true: the colour may be negative (a residual, as
                                    // drift_denoise_guided filters): stages 1 and 6 and the
                                    // regression keep the sign; not with a direct part
} drift_denoise_feature_params;

drift_denoise_feature_params
drift_denoise_feature_params_resolve(const drift_denoise_feature_params *params);

// The inputs, all of one size: color, albedo, normal RGB; depth, variance 1 channel.
// albedo, normal, depth may be NULL (neutral guide); variance may be NULL (then the spatial
// estimate of stage 4 is used whatever sample_count says).
typedef struct drift_denoise_inputs {
    const drift_image *color, *albedo, *normal, *depth, *variance;
    uint32_t sample_count; // samples per pixel behind color (0 is taken as 1)
    // Optional, all three or none: color's direct part (RGB, DRIFT_PT_AOV_DIRECT) and the
    // variances of the direct part's and of the rest's mean luminance. With them the direct
    // part and the rest (color - direct) are filtered apart, each by its own variance, and
    // summed (SVGF §4): sharp shadows of the little-noisy direct light are not blurred by the
    // noise of the indirect.
    const drift_image *direct, *direct_variance, *indirect_variance;
} drift_denoise_inputs;

typedef struct drift_denoise_report {
    uint64_t nonfinite;   // input values that were NaN or infinite (taken as 0)
    uint64_t clamped;     // pixels the firefly rule scaled down
    double mean_variance; // the mean over pixels of stage 4's variance (demodulated units)
} drift_denoise_report;

// Filters in->color into *out (a new 3-channel image; the caller destroys it). report may be
// NULL. Errors: DRIFT_ERR_INVALID_ARGUMENT (no colour, sizes differ, bad params; logged),
// DRIFT_ERR_OUT_OF_MEMORY. *out is zeroed on failure.
drift_result drift_denoise_feature(drift_context *ctx, const drift_denoise_inputs *in,
                                   const drift_denoise_feature_params *params, drift_image *out,
                                   drift_denoise_report *report);

// --- THE HYBRID-GUIDED DENOISER (src/denoise/guided.c, docs/denoiser.md) ---
//
// Combines a biased but noise-free image of the same frame, `guide` (the hybrid frame: sharp
// shadows, reflections and contact, low-frequency bias), with the path tracer's noisy
// unbiased samples (in, as drift_denoise_feature takes them):
//   RESIDUAL    out = guide + F(colour - guide), clamped to >= 0: the signed residual
//               (signed_color) filtered by the feature denoiser with params' method, a control
//               variate: where the guide is right the residual is zero-mean noise and filters
//               to ~0, keeping the guide's structure; its bias is what the filter keeps. With
//               the path tracer's direct part (in->direct and both variances) the residual is
//               split as drift_denoise_feature splits the colour: direct - (guide -
//               guide_indirect) at sigma_luminance_direct, and (colour - direct) -
//               guide_indirect at sigma_luminance_indirect, both by `method`. guide_indirect: the
//               guide's indirect part (the hybrid frame's "indirect" plane); NULL: none.
//   REGRESSION  the guide's demodulated RGB (by the path tracer's albedo) as three more
//               features of the block regression, REGRESSION_RESIDUAL (fit + filtered residual):
//               the fit scales the guide's shadows and highlights per block. No direct part.
// Either converges to the path tracer's mean as its samples grow (the filter's bias aside): the
// guide's bias is in the residual the filter keeps. At 128² REGRESSION measured worse than
// RESIDUAL at every spp on three fit scenes of the corpus; RESIDUAL is on par with
// drift_denoise_feature at equal spp over the corpus, and at equal time pays the guide
// (docs/denoiser.md).
typedef enum drift_denoise_guide_mode {
    DRIFT_GUIDE_RESIDUAL = 0,
    DRIFT_GUIDE_REGRESSION,
    DRIFT_GUIDE_MODE_COUNT
} drift_denoise_guide_mode;

// out: a new 3-channel image (the caller destroys it); params may be NULL (the feature
// denoiser's defaults). Errors as drift_denoise_feature's; a guide of another size, an unknown
// mode, a direct part without both variances or with REGRESSION: DRIFT_ERR_INVALID_ARGUMENT.
drift_result drift_denoise_guided(drift_context *ctx, const drift_denoise_inputs *in,
                                  const drift_image *guide, const drift_image *guide_indirect,
                                  drift_denoise_guide_mode mode,
                                  const drift_denoise_feature_params *params, drift_image *out,
                                  drift_denoise_report *report);

#ifdef __cplusplus
}
#endif

#endif // DRIFT_DENOISE_H
