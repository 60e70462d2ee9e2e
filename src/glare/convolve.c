// Convolution of the HDR frame with the RGB PSF (Ritschel 2009, thesis §8.4 step 4): per
// channel FFT(image) FFT(PSF), then the inverse FFT, on buffers zero-padded to at least
// W + K/2 so that the image region holds the linear, not the circular, convolution.
#include "glare_internal.h"

#include <string.h>

void drift__glare_conv_release(drift_context *ctx, drift__glare_conv *c)
{
    drift__glare_rfft_destroy(ctx, c->forward);
    drift__glare_rfft_destroy(ctx, c->inverse);
    drift_free(ctx, c->real);
    drift_free(ctx, c->spectrum);
    for (int32_t i = 0; i < 3; ++i) {
        drift_free(ctx, c->psf_spectrum[i]);
    }
    memset(c, 0, sizeof(*c));
}

static drift_result conv_prepare(drift_context *ctx, drift__glare_conv *c, int32_t pw, int32_t ph)
{
    drift__glare_conv_release(ctx, c);
    size_t real = 0, spec = 0;
    if (!drift_size_mul((size_t)pw, (size_t)ph, &real) ||
        !drift_size_mul((size_t)(pw / 2 + 1), (size_t)ph, &spec) ||
        !drift_size_mul(real, sizeof(float), &real) ||
        !drift_size_mul(spec, sizeof(drift__cpx), &spec)) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_result r = drift__glare_rfft_create(ctx, pw, ph, false, &c->forward);
    if (r == DRIFT_OK) {
        r = drift__glare_rfft_create(ctx, pw, ph, true, &c->inverse);
    }
    if (r == DRIFT_OK) {
        c->real = drift_alloc(ctx, real);
        c->spectrum = drift_alloc(ctx, spec);
        size_t kernel = drift__glare_rfft_kernel_floats(c->forward) * sizeof(float);
        for (int32_t i = 0; i < 3; ++i) {
            c->psf_spectrum[i] = drift_alloc(ctx, kernel);
        }
        if (!c->real || !c->spectrum || !c->psf_spectrum[0] || !c->psf_spectrum[1] ||
            !c->psf_spectrum[2]) {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
    }
    if (r != DRIFT_OK) {
        drift__glare_conv_release(ctx, c);
        return r;
    }
    c->width = pw;
    c->height = ph;
    return DRIFT_OK;
}

drift_result drift__glare_convolve(drift_context *ctx, drift__glare_conv *c, const drift_image *in,
                                   const float *psf, int32_t k, bool psf_changed,
                                   const drift_image *out)
{
    // With the PSF's centre at the origin, taps reach k/2 either way: spill off one edge wraps
    // into the padding, never into the image, as long as the padded size is >= W + k/2.
    int32_t pw = drift__glare_fft_size(in->width + k / 2);
    int32_t ph = drift__glare_fft_size(in->height + k / 2);
    drift_result r = DRIFT_OK;
    if (pw != c->width || ph != c->height) {
        if ((r = conv_prepare(ctx, c, pw, ph)) != DRIFT_OK) {
            return r;
        }
        psf_changed = true;
    }
    size_t real_count = (size_t)pw * (size_t)ph;
    if (psf_changed || c->psf_k != k) {
        // The PSF with its centre (k/2, k/2) moved to the origin, wrapped; its spectrum kept in
        // the layout the convolution's column blocks read.
        for (int32_t ch = 0; ch < 3; ++ch) {
            memset(c->real, 0, real_count * sizeof(float));
            for (int32_t v = 0; v < k; ++v) {
                int32_t y = ((v - k / 2) % ph + ph) % ph;
                for (int32_t u = 0; u < k; ++u) {
                    int32_t x = ((u - k / 2) % pw + pw) % pw;
                    c->real[(size_t)y * (size_t)pw + (size_t)x] =
                        psf[((size_t)v * (size_t)k + (size_t)u) * 3 + (size_t)ch];
                }
            }
            drift__glare_rfft_forward(c->forward, c->real, ph, c->spectrum);
            drift__glare_rfft_kernel_layout(c->forward, c->spectrum, c->psf_spectrum[ch]);
        }
        c->psf_k = k;
    }
    const float norm = 1.0f / (float)real_count; // the inverse is unnormalised
    for (int32_t ch = 0; ch < 3; ++ch) {
        drift__glare_rfft_convolve(c->forward, c->inverse, in, ch, c->psf_spectrum[ch], norm,
                                   c->spectrum, out);
    }
    if (in->channels == 4 && out->pixels != in->pixels) {
        for (int32_t y = 0; y < in->height; ++y) {
            for (int32_t x = 0; x < in->width; ++x) {
                drift_image_pixel(out, x, y)[3] = drift_image_pixel(in, x, y)[3];
            }
        }
    }
    return DRIFT_OK;
}
