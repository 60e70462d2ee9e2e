// The hybrid-guided denoiser (include/drift/denoise.h): a noise-free but biased image of the
// frame (the hybrid frame) and the path tracer's samples, combined by the feature denoiser
// either as a control variate (RESIDUAL: guide + the filtered signed residual) or with the
// guide as three more regression features (REGRESSION). docs/denoiser.md has the figures.
#include "feature_internal.h"

#include <math.h>

drift_result drift_denoise_guided(drift_context *ctx, const drift_denoise_inputs *in,
                                  const drift_image *guide, drift_denoise_guide_mode mode,
                                  const drift_denoise_feature_params *params, drift_image *out,
                                  drift_denoise_report *report)
{
    if (out) {
        *out = (drift_image){ 0 };
    }
    const drift_image *c = in ? in->color : NULL;
    if (!out || !c || !c->pixels || c->channels < 3 || !guide || !guide->pixels ||
        guide->channels < 3 || guide->width != c->width || guide->height != c->height ||
        (unsigned)mode >= DRIFT_GUIDE_MODE_COUNT) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: the guided denoiser needs an RGB colour and an RGB guide of its "
                  "size, and a known mode");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_denoise_feature_params p = drift_denoise_feature_params_resolve(params);
    drift_denoise_inputs part = *in; // the direct split would need the guide's direct part
    part.direct = part.direct_variance = part.indirect_variance = NULL;
    if (mode == DRIFT_GUIDE_REGRESSION) {
        if (p.method == DRIFT_DENOISE_VARIANCE_GUIDED) {
            p.method = DRIFT_DENOISE_REGRESSION_RESIDUAL; // the guide acts through the fit
        }
        return denoise_feature_guided(ctx, &part, guide, &p, out, report);
    }
    // RESIDUAL: the path tracer's variance is the residual's (the guide is deterministic).
    drift_image residual = { 0 }, filtered = { 0 };
    drift_result r = drift_image_create(ctx, c->width, c->height, 3, &residual);
    for (int32_t y = 0; r == DRIFT_OK && y < c->height; ++y) {
        for (int32_t x = 0; x < c->width; ++x) {
            const float *a = drift_image_pixel(c, x, y), *g = drift_image_pixel(guide, x, y);
            float *dst = drift_image_pixel(&residual, x, y);
            for (int k = 0; k < 3; ++k) {
                dst[k] = a[k] - (isfinite(g[k]) ? g[k] : 0.0f);
            }
        }
    }
    part.color = &residual;
    p.signed_color = true;
    r = r ? r : denoise_feature_guided(ctx, &part, NULL, &p, &filtered, report);
    r = r ? r : drift_image_create(ctx, c->width, c->height, 3, out);
    for (int32_t y = 0; r == DRIFT_OK && y < c->height; ++y) {
        for (int32_t x = 0; x < c->width; ++x) {
            const float *g = drift_image_pixel(guide, x, y),
                        *d = drift_image_pixel(&filtered, x, y);
            float *dst = drift_image_pixel(out, x, y);
            for (int k = 0; k < 3; ++k) {
                dst[k] = fmaxf((isfinite(g[k]) ? g[k] : 0.0f) + d[k], 0.0f);
            }
        }
    }
    drift_image_destroy(ctx, &residual);
    drift_image_destroy(ctx, &filtered);
    return r;
}
