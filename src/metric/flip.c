// LDR-FLIP: Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström & Fairchild 2020, "FLIP: A
// Difference Evaluator for Alternating Images", Proc. ACM Comput. Graph. Interact. Tech. 3(2)
// (HPG 2020). Section numbers below refer to that paper; the constants were checked against
// the authors' reference code (NVlabs/flip, python/flip_api.py).
//
// Pipeline per image pair:
//   1. Display-referred input: FLIP takes sRGB values in [0, 1]. Our images are linear, so each
//      value is clamped to [0, 1] and sRGB-encoded — and FLIP's first step decodes sRGB back to
//      linear, so the two cancel and the clamped linear value is used directly.
//   2. Linear RGB -> XYZ -> YyCxCz, the linearised CIELAB opponent space (§4.1).
//   3. Colour pipeline (§4.1): per-channel contrast sensitivity filters (Gaussians or a sum of
//      two, Table 1 constants, support set by pixels per degree), back to linear RGB, clamp to
//      the RGB cube, CIELAB, Hunt adjustment, HyAB distance, power qc = 0.7 and the re-mapping
//      of eq. 2 with cmax (HyAB between Hunt-adjusted green and blue), pc = 0.4, pt = 0.95.
//   4. Feature pipeline (§4.2): edge (first derivative of Gaussian) and point (second
//      derivative) detectors on the normalised achromatic channel (Y + 16) / 116 of the
//      unfiltered YyCxCz image, sd = 0.5 * 0.082 * ppd; ΔEf = (max(|Δ|edge||, |Δ|point||) /
//      sqrt 2)^qf with qf = 0.5 (eq. 4).
//   5. ΔE = ΔEc^(1 - ΔEf) (eq. 5).
// Every 2-D kernel here is separable (the blue-yellow CSF is a sum of two separable Gaussians),
// so the filters run as a horizontal then a vertical pass with clamp-to-edge borders, as the
// reference code's BORDER_REPLICATE.
#include "drift/math.h"
#include "metric_internal.h"

#include <math.h>

#define FLIP_PI_D 3.14159265358979323846
#define FLIP_QC   0.7f
#define FLIP_QF   0.5f
#define FLIP_PC   0.4f
#define FLIP_PT   0.95f
// Peak-to-trough width of the human edge detection filter, in degrees (§4.2).
#define FLIP_FEATURE_W 0.082

// CSF parameters (Table 1): a1, b1, a2, b2 per channel; the achromatic and red-green CSFs are
// single Gaussians (a2 = 0).
#define CSF_A_B1  0.0047
#define CSF_RG_B1 0.0053
#define CSF_BY_A1 34.1
#define CSF_BY_B1 0.04
#define CSF_BY_A2 13.5
#define CSF_BY_B2 0.025

// sRGB primaries, D65 white: linear RGB <-> XYZ, and the XYZ of white (1, 1, 1).
static const float rgb_to_xyz[9] = {
    10135552.0f / 24577794.0f, 8788810.0f / 24577794.0f, 4435075.0f / 24577794.0f,
    2613072.0f / 12288897.0f,  8788810.0f / 12288897.0f, 887015.0f / 12288897.0f,
    1425312.0f / 73733382.0f,  8788810.0f / 73733382.0f, 70074185.0f / 73733382.0f,
};
static const float xyz_to_rgb[9] = {
    3.241003275f, -1.537398934f, -0.498615861f, -0.969224334f, 1.875930071f,
    0.041554224f, 0.055639423f,  -0.204011202f, 1.057148933f,
};
static const float white_xyz[3] = { 0.950428545f, 1.0f, 1.088900371f };

static void mat3(const float m[9], const float in[3], float out[3])
{
    out[0] = m[0] * in[0] + m[1] * in[1] + m[2] * in[2];
    out[1] = m[3] * in[0] + m[4] * in[1] + m[5] * in[2];
    out[2] = m[6] * in[0] + m[7] * in[1] + m[8] * in[2];
}

static void linear_to_ycxcz(const float rgb[3], float out[3])
{
    float xyz[3];
    mat3(rgb_to_xyz, rgb, xyz);
    float x = xyz[0] / white_xyz[0], y = xyz[1] / white_xyz[1], z = xyz[2] / white_xyz[2];
    out[0] = 116.0f * y - 16.0f;
    out[1] = 500.0f * (x - y);
    out[2] = 200.0f * (y - z);
}

static float lab_f(float t)
{
    // CIELAB's cube root with the linear toe below (6/29)^3.
    const float delta = 6.0f / 29.0f;
    return t > delta * delta * delta ? cbrtf(t) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
}

// Linear RGB -> Hunt-adjusted CIELAB (§4.1: a and b scaled by 0.01 L).
static void linear_to_hunt_lab(const float rgb[3], float out[3])
{
    float xyz[3];
    mat3(rgb_to_xyz, rgb, xyz);
    float fx = lab_f(xyz[0] / white_xyz[0]);
    float fy = lab_f(xyz[1] / white_xyz[1]);
    float fz = lab_f(xyz[2] / white_xyz[2]);
    float l = 116.0f * fy - 16.0f;
    out[0] = l;
    out[1] = 0.01f * l * 500.0f * (fx - fy);
    out[2] = 0.01f * l * 200.0f * (fy - fz);
}

static float hyab(const float a[3], const float b[3])
{
    float dl = a[0] - b[0], da = a[1] - b[1], db = a[2] - b[2];
    return fabsf(dl) + sqrtf(da * da + db * db);
}

// Filtered YyCxCz -> linear RGB clamped to the unit cube -> Hunt-adjusted CIELAB.
static void filtered_to_hunt_lab(const float ycxcz[3], float out[3])
{
    float y = (ycxcz[0] + 16.0f) / 116.0f;
    float xyz[3] = { (y + ycxcz[1] / 500.0f) * white_xyz[0], y * white_xyz[1],
                     (y - ycxcz[2] / 200.0f) * white_xyz[2] };
    float rgb[3];
    mat3(xyz_to_rgb, xyz, rgb);
    for (int c = 0; c < 3; ++c) {
        rgb[c] = fminf(fmaxf(rgb[c], 0.0f), 1.0f);
    }
    linear_to_hunt_lab(rgb, out);
}

typedef struct flip_job {
    const drift_image *img[2]; // reference, test
    int32_t width, height;
    size_t count;
    float *ycc[2][3]; // unfiltered YyCxCz planes per image
    float *h[2][4];   // horizontal pass results per image (CSF: A, RG, BY1, BY2; features:
                      // edge, point, gauss)
    float *dec;       // ΔEc, then ΔE
    // CSF kernels: normalised 1-D Gaussians of radius csf_r, plus the BY mix weights.
    int csf_r;
    float *k_a, *k_rg, *k_by1, *k_by2;
    float by_mix1, by_mix2;
    // Feature kernels of radius feat_r: edge and point detectors and the normalised Gaussian.
    int feat_r;
    float *k_edge, *k_point, *k_gauss;
    float cmax;
} flip_job;

static inline int32_t clamp_index(int32_t i, int32_t n)
{
    return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

// Horizontal correlation of one row of `src` with a kernel of radius r, clamp-to-edge.
static void filter_row_h(const float *src, float *dst, int32_t width, const float *k, int r)
{
    for (int32_t x = 0; x < width; ++x) {
        float s = 0.0f;
        for (int i = -r; i <= r; ++i) {
            s += k[i + r] * src[clamp_index(x + i, width)];
        }
        dst[x] = s;
    }
}

// Vertical correlation at (x, y) of plane `src`.
static float filter_v(const float *src, int32_t x, int32_t y, int32_t width, int32_t height,
                      const float *k, int r)
{
    float s = 0.0f;
    for (int i = -r; i <= r; ++i) {
        s += k[i + r] * src[(size_t)clamp_index(y + i, height) * (size_t)width + (size_t)x];
    }
    return s;
}

static void ycxcz_row(int32_t y, void *user)
{
    flip_job *j = user;
    for (int m = 0; m < 2; ++m) {
        for (int32_t x = 0; x < j->width; ++x) {
            float rgb[3], ycc[3];
            drift__metric_rgb(j->img[m], x, y, rgb);
            for (int c = 0; c < 3; ++c) {
                rgb[c] = fminf(fmaxf(rgb[c], 0.0f), 1.0f); // display-referred; NaN -> 0
            }
            linear_to_ycxcz(rgb, ycc);
            size_t i = (size_t)y * (size_t)j->width + (size_t)x;
            for (int c = 0; c < 3; ++c) {
                j->ycc[m][c][i] = ycc[c];
            }
        }
    }
}

static void csf_h_row(int32_t y, void *user)
{
    flip_job *j = user;
    size_t row = (size_t)y * (size_t)j->width;
    for (int m = 0; m < 2; ++m) {
        filter_row_h(j->ycc[m][0] + row, j->h[m][0] + row, j->width, j->k_a, j->csf_r);
        filter_row_h(j->ycc[m][1] + row, j->h[m][1] + row, j->width, j->k_rg, j->csf_r);
        filter_row_h(j->ycc[m][2] + row, j->h[m][2] + row, j->width, j->k_by1, j->csf_r);
        filter_row_h(j->ycc[m][2] + row, j->h[m][3] + row, j->width, j->k_by2, j->csf_r);
    }
}

static void color_row(int32_t y, void *user)
{
    flip_job *j = user;
    int32_t w = j->width, h = j->height;
    int r = j->csf_r;
    for (int32_t x = 0; x < w; ++x) {
        float lab[2][3];
        for (int m = 0; m < 2; ++m) {
            float f[3];
            f[0] = filter_v(j->h[m][0], x, y, w, h, j->k_a, r);
            f[1] = filter_v(j->h[m][1], x, y, w, h, j->k_rg, r);
            f[2] = j->by_mix1 * filter_v(j->h[m][2], x, y, w, h, j->k_by1, r) +
                   j->by_mix2 * filter_v(j->h[m][3], x, y, w, h, j->k_by2, r);
            filtered_to_hunt_lab(f, lab[m]);
        }
        // Eq. 2: compress with qc, then map [0, pc cmax) to [0, pt) and the rest to [pt, 1].
        float e = powf(hyab(lab[0], lab[1]), FLIP_QC);
        float pccmax = FLIP_PC * j->cmax;
        float dec = e < pccmax ? (FLIP_PT / pccmax) * e
                               : FLIP_PT + ((e - pccmax) / (j->cmax - pccmax)) * (1.0f - FLIP_PT);
        j->dec[(size_t)y * (size_t)w + (size_t)x] = fminf(dec, 1.0f);
    }
}

static void feature_h_row(int32_t y, void *user)
{
    flip_job *j = user;
    size_t row = (size_t)y * (size_t)j->width;
    for (int m = 0; m < 2; ++m) {
        // The achromatic channel normalised to [0, 1]: (Y + 16) / 116, stored in place.
        float *ny = j->ycc[m][0] + row;
        for (int32_t x = 0; x < j->width; ++x) {
            ny[x] = (ny[x] + 16.0f) / 116.0f;
        }
        filter_row_h(ny, j->h[m][0] + row, j->width, j->k_edge, j->feat_r);
        filter_row_h(ny, j->h[m][1] + row, j->width, j->k_point, j->feat_r);
        filter_row_h(ny, j->h[m][2] + row, j->width, j->k_gauss, j->feat_r);
    }
}

static void final_row(int32_t y, double *row_sum, void *user)
{
    flip_job *j = user;
    int32_t w = j->width, h = j->height;
    int r = j->feat_r;
    double total = 0.0;
    for (int32_t x = 0; x < w; ++x) {
        float edge[2], point[2];
        for (int m = 0; m < 2; ++m) {
            // x-derivative: detector along x (horizontal pass), Gaussian along y; y-derivative:
            // Gaussian along x, detector along y.
            float ex = filter_v(j->h[m][0], x, y, w, h, j->k_gauss, r);
            float ey = filter_v(j->h[m][2], x, y, w, h, j->k_edge, r);
            float px = filter_v(j->h[m][1], x, y, w, h, j->k_gauss, r);
            float py = filter_v(j->h[m][2], x, y, w, h, j->k_point, r);
            edge[m] = sqrtf(ex * ex + ey * ey);
            point[m] = sqrtf(px * px + py * py);
        }
        // Eq. 4.
        float df = fmaxf(fabsf(edge[0] - edge[1]), fabsf(point[0] - point[1]));
        float def = powf(df * (1.0f / sqrtf(2.0f)), FLIP_QF);
        size_t i = (size_t)y * (size_t)w + (size_t)x;
        // Eq. 5.
        float e = powf(j->dec[i], 1.0f - def);
        j->dec[i] = e;
        total += (double)e;
    }
    row_sum[0] = total;
}

// 1-D Gaussian exp(-pi^2 (x / ppd)^2 / b) over [-r, r], normalised to sum 1; returns the sum
// before normalisation.
static double csf_gaussian(float *k, int r, double ppd, double b)
{
    double sum = 0.0;
    for (int i = -r; i <= r; ++i) {
        double d = (double)i / ppd;
        double v = exp(-FLIP_PI_D * FLIP_PI_D * d * d / b);
        k[i + r] = (float)v;
        sum += v;
    }
    for (int i = 0; i <= 2 * r; ++i) {
        k[i] = (float)((double)k[i] / sum);
    }
    return sum;
}

// Feature detectors (§4.2): g(x) = exp(-x^2 / (2 sd^2)); edge -x g(x); point (x^2/sd^2 - 1) g(x).
// Positive weights are scaled to sum to 1 and negative ones to -1 (as the reference code does
// for the 2-D kernel: since the sign depends on x only, the 1-D scaling is the same).
static void feature_kernels(flip_job *j, double ppd)
{
    double sd = 0.5 * FLIP_FEATURE_W * ppd;
    int r = j->feat_r;
    double gsum = 0.0, pos[2] = { 0.0, 0.0 }, neg[2] = { 0.0, 0.0 };
    double raw[2];
    for (int pass = 0; pass < 2; ++pass) {
        for (int i = -r; i <= r; ++i) {
            double x = (double)i;
            double g = exp(-x * x / (2.0 * sd * sd));
            raw[0] = -x * g;
            raw[1] = (x * x / (sd * sd) - 1.0) * g;
            if (pass == 0) {
                gsum += g;
                for (int t = 0; t < 2; ++t) {
                    if (raw[t] > 0.0) {
                        pos[t] += raw[t];
                    } else {
                        neg[t] -= raw[t];
                    }
                }
                continue;
            }
            j->k_gauss[i + r] = (float)(g / gsum);
            float *dst[2] = { j->k_edge, j->k_point };
            for (int t = 0; t < 2; ++t) {
                double s = raw[t] > 0.0 ? pos[t] : neg[t];
                dst[t][i + r] = s > 0.0 ? (float)(raw[t] / s) : 0.0f;
            }
        }
    }
}

drift_result drift_metric_flip(drift_context *ctx, const drift_image *reference,
                               const drift_image *test, const drift_metric_params *params,
                               double *out_mean, drift_image *out_map)
{
    *out_mean = 0.0;
    if (out_map) {
        *out_map = (drift_image){ 0 };
    }
    drift_result r = drift__metric_check_pair(ctx, reference, test, "drift_metric_flip");
    if (r != DRIFT_OK) {
        return r;
    }
    drift_metric_params p = drift_metric_params_resolve(params);
    if (!(p.ppd >= 1.0 && p.ppd <= 2000.0)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_metric_flip: ppd %g outside [1, 2000]", p.ppd);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }

    flip_job j = { .img = { reference, test },
                   .width = reference->width,
                   .height = reference->height,
                   .count = (size_t)reference->width * (size_t)reference->height };
    // Support of the CSF filters: 3 standard deviations of the widest Gaussian (largest b).
    j.csf_r = (int)ceil(3.0 * sqrt(CSF_BY_B1 / (2.0 * FLIP_PI_D * FLIP_PI_D)) * p.ppd);
    j.feat_r = (int)ceil(3.0 * 0.5 * FLIP_FEATURE_W * p.ppd);
    size_t csf_n = (size_t)(2 * j.csf_r + 1), feat_n = (size_t)(2 * j.feat_r + 1);

    float *kernels = drift__metric_alloc_planes(ctx, 4 * csf_n + 3 * feat_n, 1);
    float *planes = drift__metric_alloc_planes(ctx, j.count, out_map ? 14 : 15);
    drift_image map = { 0 };
    if (out_map && kernels && planes) {
        r = drift_image_create(ctx, j.width, j.height, 1, &map);
    }
    if (!kernels || !planes || r != DRIFT_OK) {
        drift_free(ctx, kernels);
        drift_free(ctx, planes);
        return r != DRIFT_OK ? r : DRIFT_ERR_OUT_OF_MEMORY;
    }
    j.k_a = kernels;
    j.k_rg = j.k_a + csf_n;
    j.k_by1 = j.k_rg + csf_n;
    j.k_by2 = j.k_by1 + csf_n;
    j.k_edge = j.k_by2 + csf_n;
    j.k_point = j.k_edge + feat_n;
    j.k_gauss = j.k_point + feat_n;
    for (int m = 0; m < 2; ++m) {
        for (int c = 0; c < 3; ++c) {
            j.ycc[m][c] = planes + (size_t)(m * 3 + c) * j.count;
        }
        for (int c = 0; c < 4; ++c) {
            j.h[m][c] = planes + (size_t)(6 + m * 4 + c) * j.count;
        }
    }
    j.dec = out_map ? map.pixels : planes + 14 * j.count;

    csf_gaussian(j.k_a, j.csf_r, p.ppd, CSF_A_B1);
    csf_gaussian(j.k_rg, j.csf_r, p.ppd, CSF_RG_B1);
    // Blue-yellow CSF: a1 sqrt(pi/b1) G1 + a2 sqrt(pi/b2) G2 (Table 1), normalised in 2-D. With
    // s_i the 1-D sum of G_i, the 2-D sum of the i-th term is a_i sqrt(pi/b_i) s_i^2.
    double s1 = csf_gaussian(j.k_by1, j.csf_r, p.ppd, CSF_BY_B1);
    double s2 = csf_gaussian(j.k_by2, j.csf_r, p.ppd, CSF_BY_B2);
    double w1 = CSF_BY_A1 * sqrt(FLIP_PI_D / CSF_BY_B1) * s1 * s1;
    double w2 = CSF_BY_A2 * sqrt(FLIP_PI_D / CSF_BY_B2) * s2 * s2;
    j.by_mix1 = (float)(w1 / (w1 + w2));
    j.by_mix2 = (float)(w2 / (w1 + w2));
    feature_kernels(&j, p.ppd);

    // cmax: the largest colour difference, between Hunt-adjusted green and blue, raised to qc.
    float green[3] = { 0.0f, 1.0f, 0.0f }, blue[3] = { 0.0f, 0.0f, 1.0f }, lg[3], lb[3];
    linear_to_hunt_lab(green, lg);
    linear_to_hunt_lab(blue, lb);
    j.cmax = powf(hyab(lg, lb), FLIP_QC);

    drift__metric_for_rows(ctx, j.height, ycxcz_row, &j);
    drift__metric_for_rows(ctx, j.height, csf_h_row, &j);
    drift__metric_for_rows(ctx, j.height, color_row, &j);
    drift__metric_for_rows(ctx, j.height, feature_h_row, &j);
    double total = 0.0;
    r = drift__metric_sum_rows(ctx, j.height, 1, final_row, &j, &total);
    drift_free(ctx, kernels);
    drift_free(ctx, planes);
    if (r != DRIFT_OK) {
        drift_image_destroy(ctx, &map);
        return r;
    }
    *out_mean = total / (double)j.count;
    if (out_map) {
        *out_map = map;
    }
    return DRIFT_OK;
}
