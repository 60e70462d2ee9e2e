// --aaf-denoise (drift_aaf_settings.denoise): AAF's noisy per-pixel estimates through the
// path tracer's feature-guided denoiser (drift_denoise_feature, docs/denoiser.md) instead of,
// or before, AAF's own axis-aligned filter. The guides are the G-buffer's normal and depth;
// no albedo: the shadow term is a visibility and the lobes' estimates are already divided by
// their lobe's albedo, so neither carries texture to demodulate. The variance comes from the
// pixel's own samples, n(x) of them (the adaptive pass gives pixels very different counts).
#include "aaf/aaf.h"
#include "drift/denoise.h"

// Variance of the mean of a pixel's light-weighted visibility v over n rays: a Bernoulli
// variance, v taken as (n v + 1/2) / (n + 1) so that a pixel whose few rays all agreed (v 0
// or 1 from 2 rays in a penumbra) is not taken as noise-free and left out of the filter.
// Sobol points integrate a pixel's visibility of a quad light with an error near 1/n, not
// 1/sqrt(n) (aaf.h): their variance is the Bernoulli one over n again. (With the Bernoulli
// variance alone the denoiser blurred the Cornell box's contact shadows: FLIP 0.0080 against
// 0.0058 at 4 spp, the unfiltered samples 0.0049.)
float drift_aaf_visibility_variance(float v, float n, bool random)
{
    if (!(n > 0.0f)) {
        return 0.0f;
    }
    float p = (n * v + 0.5f) / (n + 1.0f);
    float var = p * (1.0f - p) / n;
    return random ? var : var / n;
}

drift_result drift_aaf_denoise_estimate(drift_frame_state *f, const drift_image *in,
                                        const drift_image *variance, drift_image *out)
{
    drift_image color = { 0 }, filtered = { 0 };
    const drift_image *rgb = in;
    drift_result r = DRIFT_OK;
    if (in->channels == 1) { // the denoiser filters RGB: the visibility in all three
        r = drift_image_create(f->ctx, in->width, in->height, 3, &color);
        for (int32_t y = 0; r == DRIFT_OK && y < in->height; ++y) {
            for (int32_t x = 0; x < in->width; ++x) {
                drift_image_set3(&color, x, y, drift_vec3_splat(drift_image_pixel(in, x, y)[0]));
            }
        }
        rgb = &color;
    }
    const drift_denoise_inputs inputs = { .color = rgb,
                                          .normal = &f->gbuffer.normal,
                                          .depth = &f->gbuffer.depth,
                                          .variance = variance,
                                          .sample_count = f->params.spp };
    if (r == DRIFT_OK) {
        r = drift_denoise_feature(f->ctx, &inputs, NULL, &filtered, NULL);
    }
    for (int32_t y = 0; r == DRIFT_OK && y < in->height; ++y) {
        for (int32_t x = 0; x < in->width; ++x) {
            const float *from = drift_image_pixel(&filtered, x, y);
            float *to = drift_image_pixel(out, x, y);
            for (int32_t c = 0; c < out->channels; ++c) {
                to[c] = from[c];
            }
        }
    }
    drift_image_destroy(f->ctx, &filtered);
    drift_image_destroy(f->ctx, &color);
    return r;
}
