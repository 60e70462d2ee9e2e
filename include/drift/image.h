// drift image: planar-or-interleaved float images as plain data, and tone mapping.
//
// A drift_image is a view: pixels, size, channel count and a row stride in floats. An image
// made by drift_image_create owns its pixels and goes back through drift_image_destroy;
// views made by drift_image_view never own anything.
//
// STEP BY STEP
//   drift_image img;
//   if (drift_image_create(ctx, 640, 480, 3, &img) != DRIFT_OK) { ... }
//   drift_image_pixel(&img, x, y)[0] = 1.0f;
//   uint8_t *srgb = ...;  drift_image_tonemap(&img, &(drift_tonemap_params){ 0 }, srgb);
//   drift_image_destroy(ctx, &img);
//
// Threads: functions are thread-safe on distinct images.
#ifndef DRIFT_IMAGE_H
#define DRIFT_IMAGE_H

#include "drift/core.h"
#include "drift/math.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Largest width or height any drift image may have (loaders check before allocating).
#define DRIFT_IMAGE_MAX_DIMENSION 32768

typedef struct drift_image {
    float *pixels; // row-major, channels interleaved, origin top-left
    int32_t width;
    int32_t height;
    int32_t channels; // 1..4
    ptrdiff_t stride; // floats between the starts of two rows
} drift_image;

// Allocates a zeroed image. Errors: DRIFT_ERR_INVALID_ARGUMENT (size 0, over
// DRIFT_IMAGE_MAX_DIMENSION, channels outside 1..4), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_image_create(drift_context *ctx, int32_t width, int32_t height, int32_t channels,
                                drift_image *out_image);
// Frees the pixels of an image from drift_image_create and zeroes *image. NULL-safe.
void drift_image_destroy(drift_context *ctx, drift_image *image);
// A non-owning view of a rectangle of `image`.
drift_image drift_image_view(const drift_image *image, int32_t x, int32_t y, int32_t width,
                             int32_t height);
// The mean luminance (drift_luminance) over every pixel of an RGB image.
double drift_image_mean_luminance(const drift_image *image);
// The mean of the first three channels over every pixel of an RGB image.
double drift_image_mean_rgb(const drift_image *image);

static inline float *drift_image_pixel(const drift_image *image, int32_t x, int32_t y)
{
    return image->pixels + (ptrdiff_t)y * image->stride + (ptrdiff_t)x * image->channels;
}

// The first three channels of a pixel as a vector (images with 3 or 4 channels).
static inline drift_vec3 drift_image_get3(const drift_image *image, int32_t x, int32_t y)
{
    const float *p = drift_image_pixel(image, x, y);
    return (drift_vec3){ p[0], p[1], p[2] };
}

static inline void drift_image_set3(const drift_image *image, int32_t x, int32_t y, drift_vec3 v)
{
    float *p = drift_image_pixel(image, x, y);
    p[0] = v.x;
    p[1] = v.y;
    p[2] = v.z;
}

static inline bool drift_image_is_valid(const drift_image *image)
{
    return image && image->pixels && image->width > 0 && image->height > 0 &&
           image->channels >= 1 && image->channels <= 4;
}

typedef enum drift_tonemap_operator {
    DRIFT_TONEMAP_DEFAULT = 0, // DRIFT_TONEMAP_CLAMP
    DRIFT_TONEMAP_CLAMP,       // exposure, then clamp to [0,1]
    DRIFT_TONEMAP_REINHARD,    // exposure, then x / (1 + x) per channel (Reinhard 2002, eq. 3)
    DRIFT_TONEMAP_FILMIC,      // exposure, then the ACES filmic curve fit of Narkowicz (2015)
    DRIFT_TONEMAP_COUNT
} drift_tonemap_operator;

// How to tone map. The default configuration is:
//   exposure_stops = 0 (scale 2^0 = 1), op = clamp, then the sRGB transfer curve.
typedef struct drift_tonemap_params {
    float exposure_stops;
    drift_tonemap_operator op;
} drift_tonemap_params;

// Linear -> display value in [0,1] (exposure, operator, sRGB OETF).
float drift_tonemap_value(float linear, const drift_tonemap_params *params);
// Automatic exposure, as a camera's averaging meter: the stops that bring the image's mean log
// luminance (Rec. 709 Y; the geometric mean of 1e-4 + Y over the finite pixels with Y > 0, as
// Reinhard et al. 2002, eq. 1) to middle grey, 0.18. 0 for an image with no light.
float drift_image_auto_exposure(const drift_image *image);
// Photographic exposure: the stops for a camera at EV100 `ev100` (Lagarde & de Rousiers 2014,
// "Moving Frostbite to PBR", §5.1: a luminance of 1.2 · 2^EV100 cd/m² saturates the sensor).
// drift's radiance is W/(m² sr); times 683 lm/W it is taken as cd/m², so the stops are
// log2(683 / 1.2) − EV100.
float drift_exposure_from_ev100(float ev100);
// EV100 of a camera with f-number N, shutter time t seconds and sensitivity ISO S:
// log2(N² / t · 100 / S).
float drift_ev100_from_camera(float f_number, float shutter_seconds, float iso);
// sRGB electro-optical transfer function pair (IEC 61966-2-1).
float drift_srgb_to_linear(float v);
float drift_linear_to_srgb(float v);
// Writes width*height*3 bytes of sRGB (grey for 1 channel; alpha dropped).
void drift_image_tonemap(const drift_image *image, const drift_tonemap_params *params,
                         uint8_t *out_rgb8);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_IMAGE_H
