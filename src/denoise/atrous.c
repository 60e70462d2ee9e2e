// The edge-avoiding a-trous filter (include/drift/denoise.h gives the weights and defaults).
#include "drift/denoise.h"

#include <math.h>
#include <string.h>

#define DENOISE_ALBEDO_MIN 1e-3f
#define DENOISE_LUM_EPS    1e-2f
#define DENOISE_EXP_CUTOFF 30.0f // exp(-30) ~ 1e-13: the tap adds nothing

drift_denoise_params drift_denoise_params_resolve(const drift_denoise_params *params)
{
    drift_denoise_params p = params ? *params : (drift_denoise_params){ 0 };
    if (p.iterations == 0) {
        p.iterations = 5;
    }
    if (p.sigma_color == 0.0f) {
        p.sigma_color = 1.0f;
    }
    if (p.sigma_normal == 0.0f) {
        p.sigma_normal = 128.0f;
    }
    if (p.sigma_albedo == 0.0f) {
        p.sigma_albedo = 0.1f;
    }
    if (p.sigma_depth == 0.0f) {
        p.sigma_depth = 0.1f;
    }
    return p;
}

typedef struct atrous_job {
    const float *in; // packed 3-channel, width * height
    float *out;
    const drift_image *albedo, *normal, *depth;
    int32_t width, height;
    int32_t step;
    float inv_color; // 1 / (sigma_color^2 2^-i); 0: no colour weight
    float sigma_normal;
    float inv_depth;  // 1 / (sigma_depth 2^i)
    float inv_albedo; // 1 / sigma_albedo^2
    int normal_pow;   // sigma_normal when it is a whole number up to 4096, else -1
} atrous_job;

static const float b3[5] = { 1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f };

// max(0, n_p . n_q)^sigma; by squaring when sigma is a whole number (`pow`, else -1).
static float normal_weight(const float *np, const float *nq, float sigma, int pow)
{
    float d = np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2];
    if (d <= 0.0f) {
        return 0.0f;
    }
    if (d >= 1.0f) {
        return 1.0f;
    }
    if (pow < 0) {
        return powf(d, sigma);
    }
    float result = 1.0f;
    for (; pow; pow >>= 1) {
        if (pow & 1) {
            result *= d;
        }
        d *= d;
    }
    return result;
}

static float luminance(const float *c)
{
    return fabsf(0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]);
}

static void atrous_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const atrous_job *j = user;
    const int32_t w = j->width, h = j->height;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const float *cp = j->in + 3 * ((size_t)y * (size_t)w + (size_t)x);
            const float *np = j->normal ? drift_image_pixel(j->normal, x, y) : NULL;
            const float *ap = j->albedo ? drift_image_pixel(j->albedo, x, y) : NULL;
            float zp = j->depth ? drift_image_pixel(j->depth, x, y)[0] : 0.0f;
            float lum_p = luminance(cp);
            float inv_depth_p = zp > 0.0f ? j->inv_depth / zp : 0.0f;
            float sum[3] = { 0.0f, 0.0f, 0.0f }, wsum = 0.0f;
            for (int dy = -2; dy <= 2; ++dy) {
                int32_t qy = y + dy * j->step;
                if (qy < 0 || qy >= h) {
                    continue;
                }
                for (int dx = -2; dx <= 2; ++dx) {
                    int32_t qx = x + dx * j->step;
                    if (qx < 0 || qx >= w) {
                        continue;
                    }
                    const float *cq = j->in + 3 * ((size_t)qy * (size_t)w + (size_t)qx);
                    float wk = b3[dx + 2] * b3[dy + 2];
                    if (dx != 0 || dy != 0) {
                        // One exponential for the depth, albedo and colour weights.
                        float e = 0.0f;
                        if (j->depth) {
                            float zq = drift_image_pixel(j->depth, qx, qy)[0];
                            if ((zp > 0.0f) != (zq > 0.0f)) {
                                continue;
                            }
                            if (zp > 0.0f) {
                                e += fabsf(zp - zq) * inv_depth_p;
                            }
                        }
                        if (ap) {
                            const float *aq = drift_image_pixel(j->albedo, qx, qy);
                            float d0 = ap[0] - aq[0], d1 = ap[1] - aq[1], d2 = ap[2] - aq[2];
                            e += (d0 * d0 + d1 * d1 + d2 * d2) * j->inv_albedo;
                        }
                        if (j->inv_color > 0.0f) {
                            float d0 = cp[0] - cq[0], d1 = cp[1] - cq[1], d2 = cp[2] - cq[2];
                            float mean = 0.5f * (lum_p + luminance(cq)) + DENOISE_LUM_EPS;
                            e += (d0 * d0 + d1 * d1 + d2 * d2) * j->inv_color / (mean * mean);
                        }
                        if (e > DENOISE_EXP_CUTOFF) {
                            continue;
                        }
                        if (np) {
                            wk *= normal_weight(np, drift_image_pixel(j->normal, qx, qy),
                                                j->sigma_normal, j->normal_pow);
                        }
                        wk *= expf(-e);
                    }
                    sum[0] += wk * cq[0];
                    sum[1] += wk * cq[1];
                    sum[2] += wk * cq[2];
                    wsum += wk;
                }
            }
            // wsum >= the centre tap's weight (3/8)^2 > 0.
            float *o = j->out + 3 * ((size_t)y * (size_t)w + (size_t)x);
            o[0] = sum[0] / wsum;
            o[1] = sum[1] / wsum;
            o[2] = sum[2] / wsum;
        }
    }
}

static bool guide_ok(drift_context *ctx, const drift_image *guide, const drift_image *color,
                     int32_t min_channels, const char *what)
{
    if (!guide) {
        return true;
    }
    if (!drift_image_is_valid(guide) || guide->width != color->width ||
        guide->height != color->height || guide->channels < min_channels) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_denoise_atrous: the %s guide is invalid or not %dx%d", what,
                  (int)color->width, (int)color->height);
        return false;
    }
    return true;
}

static float albedo_factor(const drift_image *albedo, int32_t x, int32_t y, int c)
{
    float a = drift_image_pixel(albedo, x, y)[c];
    return a < DENOISE_ALBEDO_MIN ? 1.0f : a;
}

drift_result drift_denoise_atrous(drift_context *ctx, const drift_image *color,
                                  const drift_image *albedo, const drift_image *normal,
                                  const drift_image *depth, const drift_denoise_params *params,
                                  drift_image *out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    drift_denoise_params p = drift_denoise_params_resolve(params);
    if (!color || !drift_image_is_valid(color) || color->channels < 3) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_denoise_atrous: the colour image must be a valid RGB(A) image");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!guide_ok(ctx, albedo, color, 3, "albedo") || !guide_ok(ctx, normal, color, 3, "normal") ||
        !guide_ok(ctx, depth, color, 1, "depth")) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (p.iterations < 1 || p.iterations > 10 || !(p.sigma_color > 0.0f) ||
        !(p.sigma_normal >= 0.0f) || !(p.sigma_depth > 0.0f) || !(p.sigma_albedo > 0.0f) ||
        !isfinite(p.sigma_albedo) || !isfinite(p.sigma_color) || !isfinite(p.sigma_normal) ||
        !isfinite(p.sigma_depth)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_denoise_atrous: iterations must be in [1, 10] and the sigmas positive");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const int32_t w = color->width, h = color->height;
    size_t count = (size_t)w * (size_t)h * 3;
    float *a = drift_alloc(ctx, count * sizeof(float));
    float *b = drift_alloc(ctx, count * sizeof(float));
    drift_result r = drift_image_create(ctx, w, h, 3, out);
    if (!a || !b || r != DRIFT_OK) {
        drift_free(ctx, a);
        drift_free(ctx, b);
        drift_image_destroy(ctx, out);
        return r != DRIFT_OK ? r : DRIFT_ERR_OUT_OF_MEMORY;
    }
    const bool demodulate = albedo && !p.no_demodulate;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const float *c = drift_image_pixel(color, x, y);
            float *d = a + 3 * ((size_t)y * (size_t)w + (size_t)x);
            for (int k = 0; k < 3; ++k) {
                d[k] = demodulate ? c[k] / albedo_factor(albedo, x, y, k) : c[k];
            }
        }
    }
    atrous_job job = {
        .normal = normal, .depth = depth, .width = w, .height = h, .sigma_normal = p.sigma_normal
    };
    for (int32_t i = 0; i < p.iterations; ++i) {
        job.in = a;
        job.out = b;
        job.step = 1 << i;
        float scale = ldexpf(1.0f, -i); // sigma_color^2 halved each pass
        job.inv_color = p.disable_color ? 0.0f : 1.0f / (p.sigma_color * p.sigma_color * scale);
        job.inv_depth = 1.0f / (p.sigma_depth * (float)job.step);
        drift_parallel_for(ctx, (size_t)h, 4, atrous_rows, &job);
        float *t = a;
        a = b;
        b = t;
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const float *s = a + 3 * ((size_t)y * (size_t)w + (size_t)x);
            float *o = drift_image_pixel(out, x, y);
            for (int k = 0; k < 3; ++k) {
                o[k] = demodulate ? s[k] * albedo_factor(albedo, x, y, k) : s[k];
            }
        }
    }
    drift_free(ctx, a);
    drift_free(ctx, b);
    return DRIFT_OK;
}
