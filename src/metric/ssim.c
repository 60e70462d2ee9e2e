// Structural similarity (Wang, Bovik, Sheikh & Simoncelli 2004, "Image Quality Assessment:
// From Error Visibility to Structural Similarity", IEEE TIP 13(4)).
//
// The variant: §III-C's 11x11 circular-symmetric Gaussian window with sigma 1.5, K1 = 0.01,
// K2 = 0.03 and dynamic range L = 1, computed on one channel — the luma of the display values
// (linear input clamped to [0, 1], sRGB-encoded, Rec.709 weights), since SSIM was designed and
// validated on gamma-encoded greyscale. The mean SSIM (eq. 17, MSSIM) is taken over every
// pixel; at the border the window is cut to the image and its weights renormalised, which
// keeps images smaller than the window meaningful (Wang's MATLAB code instead drops a 5-pixel
// border).
#include "drift/math.h"
#include "metric_internal.h"

#include <math.h>

#define SSIM_RADIUS 5
#define SSIM_SIGMA  1.5
#define SSIM_K1     0.01
#define SSIM_K2     0.03

typedef struct ssim_job {
    const drift_image *ref;
    const drift_image *test;
    int32_t width, height;
    float *luma_a, *luma_b;           // display luma planes
    float *ha, *hb, *haa, *hbb, *hab; // horizontally filtered moments
    double weight[2 * SSIM_RADIUS + 1];
} ssim_job;

static float display_luma(const drift_image *image, int32_t x, int32_t y)
{
    float rgb[3];
    drift__metric_rgb(image, x, y, rgb);
    float s[3];
    for (int c = 0; c < 3; ++c) {
        // fmaxf/fminf also send NaN to 0.
        s[c] = drift_linear_to_srgb(fminf(fmaxf(rgb[c], 0.0f), 1.0f));
    }
    return drift_luminance(drift_vec3_make(s[0], s[1], s[2]));
}

static void luma_row(int32_t y, void *user)
{
    ssim_job *j = user;
    size_t row = (size_t)y * (size_t)j->width;
    for (int32_t x = 0; x < j->width; ++x) {
        j->luma_a[row + (size_t)x] = display_luma(j->ref, x, y);
        j->luma_b[row + (size_t)x] = display_luma(j->test, x, y);
    }
}

static void horizontal_row(int32_t y, void *user)
{
    ssim_job *j = user;
    size_t row = (size_t)y * (size_t)j->width;
    const float *a = j->luma_a + row, *b = j->luma_b + row;
    for (int32_t x = 0; x < j->width; ++x) {
        double wsum = 0.0, sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
        for (int k = -SSIM_RADIUS; k <= SSIM_RADIUS; ++k) {
            int32_t xx = x + k;
            if (xx < 0 || xx >= j->width) {
                continue;
            }
            double w = j->weight[k + SSIM_RADIUS];
            double va = (double)a[xx], vb = (double)b[xx];
            wsum += w;
            sa += w * va;
            sb += w * vb;
            saa += w * va * va;
            sbb += w * vb * vb;
            sab += w * va * vb;
        }
        size_t i = row + (size_t)x;
        j->ha[i] = (float)(sa / wsum);
        j->hb[i] = (float)(sb / wsum);
        j->haa[i] = (float)(saa / wsum);
        j->hbb[i] = (float)(sbb / wsum);
        j->hab[i] = (float)(sab / wsum);
    }
}

static void ssim_row(int32_t y, double *row_sum, void *user)
{
    const ssim_job *j = user;
    const double c1 = (SSIM_K1 * 1.0) * (SSIM_K1 * 1.0);
    const double c2 = (SSIM_K2 * 1.0) * (SSIM_K2 * 1.0);
    double total = 0.0;
    for (int32_t x = 0; x < j->width; ++x) {
        double wsum = 0.0, ma = 0.0, mb = 0.0, eaa = 0.0, ebb = 0.0, eab = 0.0;
        for (int k = -SSIM_RADIUS; k <= SSIM_RADIUS; ++k) {
            int32_t yy = y + k;
            if (yy < 0 || yy >= j->height) {
                continue;
            }
            double w = j->weight[k + SSIM_RADIUS];
            size_t i = (size_t)yy * (size_t)j->width + (size_t)x;
            wsum += w;
            ma += w * (double)j->ha[i];
            mb += w * (double)j->hb[i];
            eaa += w * (double)j->haa[i];
            ebb += w * (double)j->hbb[i];
            eab += w * (double)j->hab[i];
        }
        ma /= wsum;
        mb /= wsum;
        // Wang 2004 eqs. 14-15 (local statistics), as E[xy] - E[x]E[y].
        double var_a = eaa / wsum - ma * ma;
        double var_b = ebb / wsum - mb * mb;
        double cov = eab / wsum - ma * mb;
        // Wang 2004 eq. 13.
        total += ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) /
                 ((ma * ma + mb * mb + c1) * (var_a + var_b + c2));
    }
    row_sum[0] = total;
}

drift_result drift_metric_ssim(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, double *out_ssim)
{
    *out_ssim = 0.0;
    drift_result r = drift__metric_check_pair(ctx, reference, test, "drift_metric_ssim");
    if (r != DRIFT_OK) {
        return r;
    }
    ssim_job j = {
        .ref = reference, .test = test, .width = reference->width, .height = reference->height
    };
    for (int k = -SSIM_RADIUS; k <= SSIM_RADIUS; ++k) {
        j.weight[k + SSIM_RADIUS] = exp(-(double)(k * k) / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
    }
    size_t count = (size_t)j.width * (size_t)j.height;
    float *planes = drift__metric_alloc_planes(ctx, count, 7);
    if (!planes) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    j.luma_a = planes;
    j.luma_b = planes + count;
    j.ha = planes + 2 * count;
    j.hb = planes + 3 * count;
    j.haa = planes + 4 * count;
    j.hbb = planes + 5 * count;
    j.hab = planes + 6 * count;
    drift__metric_for_rows(ctx, j.height, luma_row, &j);
    drift__metric_for_rows(ctx, j.height, horizontal_row, &j);
    double total = 0.0;
    r = drift__metric_sum_rows(ctx, j.height, 1, ssim_row, &j, &total);
    drift_free(ctx, planes);
    if (r == DRIFT_OK) {
        *out_ssim = total / (double)count;
    }
    return r;
}
