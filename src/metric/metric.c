// Pixel-wise metrics (MSE, RMSE, relMSE, PSNR), the shared row reduction and
// drift_metric_compare. SSIM lives in ssim.c, FLIP in flip.c, the heat map in heatmap.c.
#include "metric_internal.h"

#include <math.h>

// relMSE denominator offset: (t - r)^2 / (r^2 + RELMSE_EPSILON). 0.01 keeps black reference
// pixels from dividing by ~0 while leaving values near 1 almost purely relative.
#define RELMSE_EPSILON 0.01

drift_metric_params drift_metric_params_resolve(const drift_metric_params *params)
{
    drift_metric_params p = params ? *params : (drift_metric_params){ 0 };
    if (p.ppd == 0.0) {
        p.ppd = DRIFT_METRIC_DEFAULT_PPD;
    }
    return p;
}

drift_result drift__metric_check_pair(drift_context *ctx, const drift_image *reference,
                                      const drift_image *test, const char *what)
{
    if (!drift_image_is_valid(reference) || !drift_image_is_valid(test)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "%s: invalid image",
                  what);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (reference->width != test->width || reference->height != test->height) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "%s: image sizes differ: reference %dx%d, test %dx%d", what, reference->width,
                  reference->height, test->width, test->height);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
}

typedef struct row_job {
    drift__metric_row_func fn;
    drift__metric_row_job job;
    void *user;
    double *sums;
    size_t stride;
} row_job;

static void run_rows(size_t begin, size_t end, int thread_index, void *user)
{
    const row_job *j = user;
    (void)thread_index;
    for (size_t y = begin; y < end; ++y) {
        if (j->fn) {
            j->fn((int32_t)y, j->sums + y * j->stride, j->user);
        } else {
            j->job((int32_t)y, j->user);
        }
    }
}

drift_result drift__metric_sum_rows(drift_context *ctx, int32_t height, size_t stride,
                                    drift__metric_row_func fn, void *user, double *totals)
{
    size_t bytes;
    if (!drift_size_mul((size_t)height * stride, sizeof(double), &bytes)) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    double *sums = drift_alloc(ctx, bytes);
    if (!sums) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    row_job j = { .fn = fn, .user = user, .sums = sums, .stride = stride };
    drift_parallel_for(ctx, (size_t)height, 1, run_rows, &j);
    for (size_t k = 0; k < stride; ++k) {
        totals[k] = 0.0;
    }
    for (size_t y = 0; y < (size_t)height; ++y) {
        for (size_t k = 0; k < stride; ++k) {
            totals[k] += sums[y * stride + k];
        }
    }
    drift_free(ctx, sums);
    return DRIFT_OK;
}

void drift__metric_for_rows(drift_context *ctx, int32_t height, drift__metric_row_job fn,
                            void *user)
{
    row_job j = { .job = fn, .user = user };
    drift_parallel_for(ctx, (size_t)height, 1, run_rows, &j);
}

float *drift__metric_alloc_planes(drift_context *ctx, size_t count, size_t planes)
{
    size_t n, bytes;
    if (!drift_size_mul(count, planes, &n) || !drift_size_mul(n, sizeof(float), &bytes)) {
        return NULL;
    }
    return drift_alloc(ctx, bytes);
}

// --- MSE AND RELMSE ---

typedef struct pair {
    const drift_image *ref;
    const drift_image *test;
} pair;

static void squared_error_row(int32_t y, double *row, void *user)
{
    const pair *p = user;
    double se = 0.0, rel = 0.0;
    for (int32_t x = 0; x < p->ref->width; ++x) {
        float r[3], t[3];
        drift__metric_rgb(p->ref, x, y, r);
        drift__metric_rgb(p->test, x, y, t);
        for (int c = 0; c < 3; ++c) {
            double d = (double)t[c] - (double)r[c];
            se += d * d;
            rel += d * d / ((double)r[c] * (double)r[c] + RELMSE_EPSILON);
        }
    }
    row[0] = se;
    row[1] = rel;
}

static drift_result squared_errors(drift_context *ctx, const drift_image *ref,
                                   const drift_image *test, const char *what, double *out_mse,
                                   double *out_relmse)
{
    *out_mse = 0.0;
    *out_relmse = 0.0;
    drift_result r = drift__metric_check_pair(ctx, ref, test, what);
    if (r != DRIFT_OK) {
        return r;
    }
    pair p = { ref, test };
    double totals[2];
    r = drift__metric_sum_rows(ctx, ref->height, 2, squared_error_row, &p, totals);
    if (r != DRIFT_OK) {
        return r;
    }
    double n = (double)ref->width * (double)ref->height * 3.0;
    *out_mse = totals[0] / n;
    *out_relmse = totals[1] / n;
    return DRIFT_OK;
}

static double psnr_from_mse(double mse)
{
    // Peak 1.0: 10 log10(1^2 / MSE).
    return mse > 0.0 ? -10.0 * log10(mse) : (double)INFINITY;
}

drift_result drift_metric_mse(drift_context *ctx, const drift_image *reference,
                              const drift_image *test, double *out_mse)
{
    double relmse;
    return squared_errors(ctx, reference, test, "drift_metric_mse", out_mse, &relmse);
}

drift_result drift_metric_relmse(drift_context *ctx, const drift_image *reference,
                                 const drift_image *test, double *out_relmse)
{
    double mse;
    return squared_errors(ctx, reference, test, "drift_metric_relmse", &mse, out_relmse);
}

drift_result drift_metric_psnr(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, double *out_psnr)
{
    double mse, relmse;
    drift_result r = squared_errors(ctx, reference, test, "drift_metric_psnr", &mse, &relmse);
    *out_psnr = r == DRIFT_OK ? psnr_from_mse(mse) : 0.0;
    return r;
}

drift_result drift_metric_compare(drift_context *ctx, const drift_image *reference,
                                  const drift_image *test, const drift_metric_params *params,
                                  drift_metric_report *out, drift_image *out_flip_map)
{
    *out = (drift_metric_report){ 0 };
    if (out_flip_map) {
        *out_flip_map = (drift_image){ 0 };
    }
    drift_metric_report rep = { 0 };
    drift_result r =
        squared_errors(ctx, reference, test, "drift_metric_compare", &rep.mse, &rep.relmse);
    if (r == DRIFT_OK) {
        rep.rmse = sqrt(rep.mse);
        rep.psnr = psnr_from_mse(rep.mse);
        r = drift_metric_ssim(ctx, reference, test, &rep.ssim);
    }
    if (r == DRIFT_OK) {
        r = drift_metric_flip(ctx, reference, test, params, &rep.flip, out_flip_map);
    }
    if (r == DRIFT_OK) {
        *out = rep;
    }
    return r;
}
