// Private to src/metric: argument checks, pixel access and the deterministic row reduction
// every metric uses.
#ifndef DRIFT_METRIC_INTERNAL_H
#define DRIFT_METRIC_INTERNAL_H

#include "drift/metric.h"

#include <stddef.h>

// Logs and returns DRIFT_ERR_INVALID_ARGUMENT unless both images are valid and equal in size.
drift_result drift__metric_check_pair(drift_context *ctx, const drift_image *reference,
                                      const drift_image *test, const char *what);

// The 3 colour values of a pixel (grey for 1- and 2-channel images).
static inline void drift__metric_rgb(const drift_image *image, int32_t x, int32_t y, float out[3])
{
    const float *p = drift_image_pixel(image, x, y);
    if (image->channels >= 3) {
        out[0] = p[0];
        out[1] = p[1];
        out[2] = p[2];
    } else {
        out[0] = out[1] = out[2] = p[0];
    }
}

// Runs fn(y, sums + y * stride, user) for every row in parallel, then adds the per-row sums in
// row order: the totals are the same bits for any thread count. `totals` has `stride` entries.
typedef void (*drift__metric_row_func)(int32_t y, double *row_sums, void *user);
drift_result drift__metric_sum_rows(drift_context *ctx, int32_t height, size_t stride,
                                    drift__metric_row_func fn, void *user, double *totals);

// Calls fn(y, user) for every row in [0, height) in parallel (no reduction).
typedef void (*drift__metric_row_job)(int32_t y, void *user);
void drift__metric_for_rows(drift_context *ctx, int32_t height, drift__metric_row_job fn,
                            void *user);

// Allocates a zeroed float array of `count` * `planes` values (NULL on overflow or failure).
float *drift__metric_alloc_planes(drift_context *ctx, size_t count, size_t planes);

#endif
