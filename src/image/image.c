#include "drift/image.h"

#include <math.h>
#include <string.h>

drift_result drift_image_create(drift_context *ctx, int32_t width, int32_t height, int32_t channels,
                                drift_image *out_image)
{
    if (!out_image) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_image = (drift_image){ 0 };
    if (width <= 0 || height <= 0 || width > DRIFT_IMAGE_MAX_DIMENSION ||
        height > DRIFT_IMAGE_MAX_DIMENSION || channels < 1 || channels > 4) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    size_t count, bytes;
    if (!drift_size_mul((size_t)width * (size_t)height, (size_t)channels, &count) ||
        !drift_size_mul(count, sizeof(float), &bytes)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    float *pixels = drift_alloc(ctx, bytes);
    if (!pixels) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *out_image = (drift_image){ .pixels = pixels,
                                .width = width,
                                .height = height,
                                .channels = channels,
                                .stride = (ptrdiff_t)width * channels };
    return DRIFT_OK;
}

void drift_image_destroy(drift_context *ctx, drift_image *image)
{
    if (!image) {
        return;
    }
    drift_free(ctx, image->pixels);
    *image = (drift_image){ 0 };
}

drift_image drift_image_view(const drift_image *image, int32_t x, int32_t y, int32_t width,
                             int32_t height)
{
    DRIFT_ASSERT(x >= 0 && y >= 0 && x + width <= image->width && y + height <= image->height);
    return (drift_image){ .pixels = drift_image_pixel(image, x, y),
                          .width = width,
                          .height = height,
                          .channels = image->channels,
                          .stride = image->stride };
}

double drift_image_mean_luminance(const drift_image *image)
{
    double sum = 0.0;
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            sum += (double)drift_luminance(drift_image_get3(image, x, y));
        }
    }
    return sum / ((double)image->width * (double)image->height);
}

double drift_image_mean_rgb(const drift_image *image)
{
    double sum = 0.0;
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            const float *v = drift_image_pixel(image, x, y);
            sum += (double)v[0] + (double)v[1] + (double)v[2];
        }
    }
    return sum / (3.0 * (double)image->width * (double)image->height);
}

float drift_srgb_to_linear(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

float drift_linear_to_srgb(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

float drift_tonemap_value(float linear, const drift_tonemap_params *params)
{
    drift_tonemap_params p = params ? *params : (drift_tonemap_params){ 0 };
    float x = linear * exp2f(p.exposure_stops);
    if (!(x > 0.0f)) { // also maps NaN to black
        return 0.0f;
    }
    if (p.op == DRIFT_TONEMAP_REINHARD) {
        x = x / (1.0f + x);
    } else if (p.op == DRIFT_TONEMAP_FILMIC) {
        // Narkowicz's fit of the ACES reference rendering transform: a toe that keeps the
        // shadows' contrast and a shoulder that rolls highlights off to white.
        x = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    }
    return drift_linear_to_srgb(fminf(x, 1.0f));
}

float drift_image_auto_exposure(const drift_image *image)
{
    double log_sum = 0.0;
    size_t count = 0;
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            const float *p = drift_image_pixel(image, x, y);
            float lum =
                image->channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
            // Pixels with no light (an empty background) say nothing about the exposure,
            // and would pull the geometric mean towards the floor.
            if (isfinite(lum) && lum > 0.0f) {
                log_sum += log(1e-4 + (double)lum);
                count++;
            }
        }
    }
    if (count == 0) {
        return 0.0f;
    }
    double mean_log = log_sum / (double)count;
    return (float)(log2(0.18) - mean_log / log(2.0));
}

float drift_exposure_from_ev100(float ev100)
{
    return log2f(683.0f / 1.2f) - ev100;
}

float drift_ev100_from_camera(float f_number, float shutter_seconds, float iso)
{
    return log2f(f_number * f_number / shutter_seconds * 100.0f / iso);
}

void drift_image_tonemap(const drift_image *image, const drift_tonemap_params *params,
                         uint8_t *out_rgb8)
{
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            const float *p = drift_image_pixel(image, x, y);
            uint8_t *o = out_rgb8 + ((size_t)y * (size_t)image->width + (size_t)x) * 3;
            for (int c = 0; c < 3; ++c) {
                float v = image->channels >= 3 ? p[c] : p[0];
                o[c] = (uint8_t)lrintf(drift_tonemap_value(v, params) * 255.0f);
            }
        }
    }
}
