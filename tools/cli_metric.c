// drift diff's comparison of two loaded images (tools/cli.h): the one place `drift diff` and
// `drift report` get their numbers from, so a report's table equals drift diff's output.
#include "cli.h"
#include "drift/metric.h"

#include <math.h>

static bool pixel_finite(const drift_image *img, int32_t x, int32_t y)
{
    const float *p = drift_image_pixel(img, x, y);
    for (int32_t c = 0; c < img->channels; ++c) {
        if (!isfinite(p[c])) {
            return false;
        }
    }
    return true;
}

static void pixel_zero(drift_image *img, int32_t x, int32_t y)
{
    float *p = drift_image_pixel(img, x, y);
    for (int32_t c = 0; c < img->channels; ++c) {
        p[c] = 0.0f;
    }
}

// Sets the pixels that are NaN or infinite in either image to 0 in both (they then add no
// error) and returns how many there were.
static size_t mask_nonfinite(drift_image *a, drift_image *b)
{
    size_t count = 0;
    for (int32_t y = 0; y < a->height; ++y) {
        for (int32_t x = 0; x < a->width; ++x) {
            if (!pixel_finite(a, x, y) || !pixel_finite(b, x, y)) {
                pixel_zero(a, x, y);
                pixel_zero(b, x, y);
                ++count;
            }
        }
    }
    return count;
}

drift_result cli_compare_images(drift_context *ctx, drift_image *ref, drift_image *test, double ppd,
                                drift_metric_report *rep, drift_image *flip_map, size_t *nonfinite)
{
    *nonfinite = 0;
    if (ref->width != test->width || ref->height != test->height) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    size_t pixels = (size_t)ref->width * (size_t)ref->height;
    *nonfinite = mask_nonfinite(ref, test);
    if (*nonfinite == pixels) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r =
        drift_metric_compare(ctx, ref, test, &(drift_metric_params){ .ppd = ppd }, rep, flip_map);
    if (r == DRIFT_OK && *nonfinite > 0) {
        // The masked pixels added no error: MSE and relMSE are means over the finite ones.
        double scale = (double)pixels / (double)(pixels - *nonfinite);
        rep->mse *= scale;
        rep->relmse *= scale;
        rep->rmse = sqrt(rep->mse);
        rep->psnr = rep->mse > 0.0 ? 10.0 * log10(1.0 / rep->mse) : HUGE_VAL;
    }
    return r;
}
