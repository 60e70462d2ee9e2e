// The feature-guided denoiser's shared frame (include/drift/denoise.h, stages 1-6): what
// feature.c prepares and the two filters (svgf.c, bmfr.c) read.
#ifndef DRIFT_DENOISE_FEATURE_INTERNAL_H
#define DRIFT_DENOISE_FEATURE_INTERNAL_H

#include "drift/denoise.h"

typedef struct denoise_frame {
    drift_context *ctx;
    int32_t width, height;
    size_t pixels;
    uint32_t sample_count;
    drift_denoise_feature_params params;
    float *irr;        // 3 a pixel: demodulated, firefly-clamped colour (stages 2-3)
    float *var;        // 1 a pixel: variance of the demodulated luminance's mean (stage 4)
    float *normal;     // 3 a pixel: (0, 0, 1) without a normal guide
    float *depth;      // 1 a pixel: 0 without a depth guide (or where the ray escaped)
    float *albedo_lum; // 1 a pixel: luminance of the albedo (0 without one)
    float *guide;      // 3 a pixel: the guide image demodulated (denoise_feature_guided),
                       // the regression's three extra features; NULL without one
} denoise_frame;

// Luminance of an RGB triple (Rec. 709, as drift_luminance).
static inline float denoise_lum(const float *c)
{
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

// drift_denoise_feature without the direct split, with a guide image (RGB, in's size; NULL:
// none) whose demodulated channels are three more regression features (bmfr.c).
drift_result denoise_feature_guided(drift_context *ctx, const drift_denoise_inputs *in,
                                    const drift_image *guide,
                                    const drift_denoise_feature_params *params, drift_image *out,
                                    drift_denoise_report *report);

// Stage 5, each writing 3 floats a pixel of filtered irradiance into out.
drift_result denoise_variance_guided(const denoise_frame *f, float *out);
// The block fit with blocks `block` pixels wide (even).
drift_result denoise_regression(const denoise_frame *f, int32_t block, float *out);

#endif
