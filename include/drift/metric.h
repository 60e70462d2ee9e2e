// drift metric: image difference metrics — MSE, RMSE, relative MSE, PSNR, SSIM and LDR-FLIP —
// and the magma heat map of a FLIP error image.
//
// Inputs are drift_image pairs of equal width and height (reference first, test second). The
// colour channels are the first three (alpha is ignored); 1- and 2-channel images are read as
// grey. Per-pixel work runs on the context's thread pool, but every sum is formed per row in
// double and the rows are combined in row order, so results are bit-identical for any thread
// count. docs/metrics.md gives the definitions, constants and units.
//
//   MSE    mean over pixels and the 3 channels of (t - r)^2, on the linear values as stored.
//   RMSE   sqrt(MSE).
//   relMSE mean of (t - r)^2 / (r^2 + 0.01) per channel, r the reference; the 0.01 keeps
//          black reference pixels from dividing by ~0.
//   PSNR   10 log10(1 / MSE), peak 1.0 on linear values; +INFINITY when MSE == 0.
//   SSIM   Wang, Bovik, Sheikh & Simoncelli 2004, eq. 13, mean over all pixels: 11x11 Gaussian
//          window (sigma 1.5), K1 = 0.01, K2 = 0.03, L = 1, on the luma of the sRGB-encoded
//          values clamped to [0, 1]. Windows are cut at the border and renormalised.
//   FLIP   LDR-FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating
//          Images", HPG 2020) at `ppd` pixels per degree. Inputs are made display-referred
//          first: linear values clamped to [0, 1], then the sRGB OETF. Per-pixel error in
//          [0, 1]; the reported value is the mean.
//
// STEP BY STEP
//   drift_metric_report rep;
//   drift_image flip_map; // optional
//   drift_metric_compare(ctx, &ref, &test, &(drift_metric_params){ 0 }, &rep, &flip_map);
//   printf("PSNR %.2f dB, FLIP %.4f\n", rep.psnr, rep.flip);
//   drift_image heat;
//   drift_metric_flip_heatmap(ctx, &flip_map, &heat);  // then drift_image_save_png(...)
//   drift_image_destroy(ctx, &heat);
//   drift_image_destroy(ctx, &flip_map);
//
// Errors: DRIFT_ERR_INVALID_ARGUMENT (invalid image, sizes differ, bad params; logged),
// DRIFT_ERR_OUT_OF_MEMORY. Outputs are zeroed on failure.
// Threads: thread-safe on distinct outputs; uses drift_parallel_for, so not re-entrant from
// inside a drift_parallel_for worker.
#ifndef DRIFT_METRIC_H
#define DRIFT_METRIC_H

#include "drift/core.h"
#include "drift/image.h"

#ifdef __cplusplus
extern "C" {
#endif

// FLIP's default observer: a 0.7 m wide 3840-pixel monitor seen from 0.7 m,
// 0.7 * 3840 / 0.7 * pi / 180 = 67.02 pixels per degree (Andersson et al. 2020, §3).
#define DRIFT_METRIC_DEFAULT_PPD 67.0206

// How to compare. The default configuration is:
//   ppd = 0 -> DRIFT_METRIC_DEFAULT_PPD pixels per degree of visual angle (FLIP only)
typedef struct drift_metric_params {
    double ppd;
} drift_metric_params;

drift_metric_params drift_metric_params_resolve(const drift_metric_params *params);

typedef struct drift_metric_report {
    double mse;
    double rmse;
    double relmse;
    double psnr; // dB; +INFINITY for identical images
    double ssim; // in [-1, 1], 1 for identical images
    double flip; // mean LDR-FLIP in [0, 1]
} drift_metric_report;

// Mean squared error over pixels and the 3 colour channels.
drift_result drift_metric_mse(drift_context *ctx, const drift_image *reference,
                              const drift_image *test, double *out_mse);
// Relative MSE, (t - r)^2 / (r^2 + 0.01) averaged; r is the reference.
drift_result drift_metric_relmse(drift_context *ctx, const drift_image *reference,
                                 const drift_image *test, double *out_relmse);
// PSNR in dB with peak 1.0; +INFINITY when the images are identical.
drift_result drift_metric_psnr(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, double *out_psnr);
// Mean SSIM (see the module comment for the exact variant).
drift_result drift_metric_ssim(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, double *out_ssim);
// LDR-FLIP. *out_mean receives the mean error; out_map (may be NULL) receives a new 1-channel
// image of per-pixel errors owned by the caller (drift_image_destroy).
drift_result drift_metric_flip(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, const drift_metric_params *params,
                               double *out_mean, drift_image *out_map);

// All metrics at once. out_flip_map may be NULL; otherwise as in drift_metric_flip.
drift_result drift_metric_compare(drift_context *ctx, const drift_image *reference,
                                  const drift_image *test, const drift_metric_params *params,
                                  drift_metric_report *out, drift_image *out_flip_map);

// Maps a 1-channel error image (values in [0, 1], clamped) to the "magma" colour map (van der
// Walt & Smith 2015, matplotlib; index round(255 e) as in the FLIP tool). *out_image receives a
// new 3-channel image of *linear* values whose sRGB encoding is the magma colour, so
// drift_image_save_png with default tone mapping writes the standard 8-bit magma colours.
drift_result drift_metric_flip_heatmap(drift_context *ctx, const drift_image *flip_map,
                                       drift_image *out_image);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_METRIC_H
