// The feature-guided denoiser: stages 1-4 and 6 (include/drift/denoise.h); the filters of
// stage 5 are svgf.c (variance-guided) and bmfr.c (regression).
#include "feature_internal.h"

#include <math.h>
#include <string.h>

drift_denoise_feature_params
drift_denoise_feature_params_resolve(const drift_denoise_feature_params *params)
{
    drift_denoise_feature_params p = params ? *params : (drift_denoise_feature_params){ 0 };
    if (p.iterations == 0) {
        p.iterations = 4;
    }
    if (p.sigma_luminance == 0.0f) {
        p.sigma_luminance = 4.0f;
    }
    if (p.sigma_luminance_direct == 0.0f) {
        p.sigma_luminance_direct = 4.0f;
    }
    if (p.sigma_luminance_indirect == 0.0f) {
        p.sigma_luminance_indirect = 8.0f;
    }
    if (p.sigma_normal == 0.0f) {
        p.sigma_normal = 128.0f;
    }
    if (p.sigma_depth == 0.0f) {
        p.sigma_depth = 0.1f;
    }
    if (p.sigma_albedo == 0.0f) {
        p.sigma_albedo = 1.0f;
    }
    return p;
}

static bool same_size(const drift_image *a, const drift_image *b, int channels)
{
    return !b ||
           (b->pixels && b->width == a->width && b->height == a->height && b->channels >= channels);
}

// --- STAGES 1-2: SANITISE AND DEMODULATE ---

typedef struct prepare_job {
    const drift_denoise_inputs *in;
    const drift_image *guide;
    denoise_frame *f;
    uint64_t *nonfinite; // a row
} prepare_job;

static float finite_or_zero(float v, uint64_t *count)
{
    if (isfinite(v)) {
        return v;
    }
    ++*count;
    return 0.0f;
}

static void prepare_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    prepare_job *job = user;
    const drift_denoise_inputs *in = job->in;
    denoise_frame *f = job->f;
    for (size_t y = begin; y < end; ++y) {
        uint64_t bad = 0;
        for (int32_t x = 0; x < f->width; ++x) {
            size_t i = y * (size_t)f->width + (size_t)x;
            const float *c = drift_image_pixel(in->color, x, (int32_t)y);
            float a[3] = { 1.0f, 1.0f, 1.0f }, n[3] = { 0.0f, 0.0f, 1.0f };
            if (in->albedo) {
                const float *src = drift_image_pixel(in->albedo, x, (int32_t)y);
                for (int k = 0; k < 3; ++k) {
                    a[k] = fmaxf(finite_or_zero(src[k], &bad), 0.0f);
                }
            }
            if (in->normal) {
                const float *src = drift_image_pixel(in->normal, x, (int32_t)y);
                for (int k = 0; k < 3; ++k) {
                    n[k] = finite_or_zero(src[k], &bad);
                }
                float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                for (int k = 0; k < 3; ++k) {
                    n[k] = len > 1e-6f ? n[k] / len : 0.0f; // averaged normals renormalised
                }
            }
            float z = in->depth ? finite_or_zero(*drift_image_pixel(in->depth, x, (int32_t)y), &bad)
                                : 0.0f;
            float v = in->variance
                          ? finite_or_zero(*drift_image_pixel(in->variance, x, (int32_t)y), &bad)
                          : 0.0f;
            float div[3];
            for (int k = 0; k < 3; ++k) {
                div[k] = drift_denoise_albedo_divisor(a[k]);
                float ck = finite_or_zero(c[k], &bad);
                f->irr[3 * i + k] = (f->params.signed_color ? ck : fmaxf(ck, 0.0f)) / div[k];
                if (f->guide) {
                    float g = finite_or_zero(drift_image_pixel(job->guide, x, (int32_t)y)[k], &bad);
                    f->guide[3 * i + k] = fmaxf(g, 0.0f) / div[k];
                }
                f->normal[3 * i + k] = n[k];
            }
            f->depth[i] = fmaxf(z, 0.0f);
            f->albedo_lum[i] = in->albedo ? denoise_lum(a) : 0.0f;
            float dl = denoise_lum(div);
            f->var[i] = fmaxf(v, 0.0f) / (dl * dl);
        }
        job->nonfinite[y] = bad;
    }
}

// --- STAGES 3-4: BOX MOMENTS ---

// The mean and mean square of the demodulated luminance over the (2r+1)^2 box around every
// pixel (clipped at the image's edges), by separable running sums in double precision: O(1)
// a pixel, and the same bits for any thread count (one thread).
static void box_moments(const denoise_frame *f, int r, float *mean, float *mean_sq, double *row_sum,
                        double *row_sum_sq)
{
    int32_t w = f->width, h = f->height;
    for (int32_t y = 0; y < h; ++y) { // horizontal sums of l and l^2
        double s = 0.0, s2 = 0.0;
        const float *irr = f->irr + 3 * (size_t)y * (size_t)w;
        for (int32_t x = 0; x < r && x < w; ++x) {
            double l = (double)denoise_lum(irr + 3 * x);
            s += l;
            s2 += l * l;
        }
        for (int32_t x = 0; x < w; ++x) {
            if (x + r < w) {
                double l = (double)denoise_lum(irr + 3 * (x + r));
                s += l;
                s2 += l * l;
            }
            if (x - r - 1 >= 0) {
                double l = (double)denoise_lum(irr + 3 * (x - r - 1));
                s -= l;
                s2 -= l * l;
            }
            row_sum[(size_t)y * (size_t)w + (size_t)x] = s;
            row_sum_sq[(size_t)y * (size_t)w + (size_t)x] = s2;
        }
    }
    for (int32_t x = 0; x < w; ++x) { // vertical sums of those, over the box's pixel count
        int32_t cols = (x + r < w ? x + r : w - 1) - (x - r > 0 ? x - r : 0) + 1;
        for (int32_t y = 0; y < h; ++y) {
            int32_t y0 = y - r > 0 ? y - r : 0, y1 = y + r < h ? y + r : h - 1;
            double s = 0.0, s2 = 0.0;
            for (int32_t q = y0; q <= y1; ++q) {
                s += row_sum[(size_t)q * (size_t)w + (size_t)x];
                s2 += row_sum_sq[(size_t)q * (size_t)w + (size_t)x];
            }
            double count = (double)(cols * (y1 - y0 + 1));
            mean[(size_t)y * (size_t)w + (size_t)x] = (float)(s / count);
            mean_sq[(size_t)y * (size_t)w + (size_t)x] = (float)(s2 / count);
        }
    }
}

// Stage 4 below 4 samples: SVGF's spatial estimate (§4.1), the 7x7 variance of the
// demodulated luminance, over n; at least the pixel's own estimate.
static void spatial_variance(denoise_frame *f, const float *mean, const float *mean_sq)
{
    float inv_n = 1.0f / (float)f->sample_count;
    for (size_t i = 0; i < f->pixels; ++i) {
        float var = fmaxf(mean_sq[i] - mean[i] * mean[i], 0.0f);
        f->var[i] = fmaxf(f->var[i], var * inv_n);
    }
}

// Stage 3: the firefly rule over the 5x5 moments (drift/denoise.h). Returns the count.
static uint64_t clamp_fireflies(denoise_frame *f, const float *mean, const float *mean_sq)
{
    uint64_t count = 0;
    for (size_t i = 0; i < f->pixels; ++i) {
        float sd = sqrtf(fmaxf(mean_sq[i] - mean[i] * mean[i], 0.0f));
        float own = f->sample_count >= 4 ? sqrtf(f->var[i]) : 0.0f;
        float limit = mean[i] + 3.0f * sd + 3.0f * own;
        float *c = f->irr + 3 * i;
        float l = denoise_lum(c);
        if (l > limit && l > 0.0f) {
            float scale = limit / l;
            c[0] *= scale;
            c[1] *= scale;
            c[2] *= scale;
            ++count;
        }
    }
    return count;
}

// --- STAGE 5, REGRESSION_RESIDUAL ---

// The block fit, plus the residual f->irr - fit filtered VARIANCE_GUIDED at
// sigma_luminance_residual (f->irr is left holding the residual).
static drift_result regression_residual(denoise_frame *f, float *out)
{
    float *fit = drift_alloc(f->ctx, f->pixels * 3 * sizeof(float));
    if (!fit) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    int32_t block = f->params.residual_block;
    if (block == 0) { // larger blocks average more noise; at 16 spp they lose detail
        block = f->sample_count < 16 ? 64 : 32;
    }
    drift_result r = denoise_regression(f, block, fit);
    if (r == DRIFT_OK) {
        for (size_t i = 0; i < 3 * f->pixels; ++i) {
            f->irr[i] -= fit[i];
        }
        float sigma = f->params.sigma_luminance_residual; // 0: by the spp, as the blocks
        f->params.sigma_luminance = sigma > 0.0f ? sigma : f->sample_count < 16 ? 64.0f : 32.0f;
        r = denoise_variance_guided(f, out);
    }
    for (size_t i = 0; r == DRIFT_OK && i < 3 * f->pixels; ++i) {
        out[i] += fit[i];
    }
    drift_free(f->ctx, fit);
    return r;
}

// --- THE CALL ---

static void frame_free(denoise_frame *f)
{
    drift_free(f->ctx, f->irr);
    drift_free(f->ctx, f->var);
    drift_free(f->ctx, f->normal);
    drift_free(f->ctx, f->depth);
    drift_free(f->ctx, f->albedo_lum);
    drift_free(f->ctx, f->guide);
}

drift_result denoise_feature_guided(drift_context *ctx, const drift_denoise_inputs *in,
                                    const drift_image *guide,
                                    const drift_denoise_feature_params *params, drift_image *out,
                                    drift_denoise_report *report)
{
    if (out) {
        *out = (drift_image){ 0 };
    }
    if (report) {
        *report = (drift_denoise_report){ 0 };
    }
    drift_denoise_feature_params p = drift_denoise_feature_params_resolve(params);

    const drift_image *c = in ? in->color : NULL;
    if (!out || !c || !c->pixels || c->channels < 3 || c->width <= 0 || c->height <= 0 ||
        !same_size(c, in->albedo, 3) || !same_size(c, in->normal, 3) ||
        !same_size(c, in->depth, 1) || !same_size(c, in->variance, 1) || !same_size(c, guide, 3) ||
        (unsigned)p.method >= DRIFT_DENOISE_METHOD_COUNT || p.iterations < 1 || p.iterations > 10 ||
        !(p.sigma_luminance > 0.0f) || !(p.sigma_luminance_direct > 0.0f) ||
        !(p.sigma_luminance_indirect > 0.0f) || !(p.sigma_luminance_residual >= 0.0f) ||
        p.residual_block < 0 || p.residual_block > 128 || p.residual_block % 2 ||
        (p.residual_block > 0 && p.residual_block < 8) || !(p.sigma_normal > 0.0f) ||
        !(p.sigma_depth > 0.0f) || !(p.sigma_albedo > 0.0f)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: the colour must be RGB, every guide of its size and the params in "
                  "range (iterations 1..10, sigmas > 0, residual_block 0 or even 8..128)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    denoise_frame f = { .ctx = ctx,
                        .width = c->width,
                        .height = c->height,
                        .pixels = (size_t)c->width * (size_t)c->height,
                        .sample_count = in->sample_count ? in->sample_count : 1,
                        .params = p };
    f.irr = drift_alloc(ctx, f.pixels * 3 * sizeof(float));
    f.var = drift_alloc(ctx, f.pixels * sizeof(float));
    f.normal = drift_alloc(ctx, f.pixels * 3 * sizeof(float));
    f.depth = drift_alloc(ctx, f.pixels * sizeof(float));
    f.albedo_lum = drift_alloc(ctx, f.pixels * sizeof(float));
    f.guide = guide ? drift_alloc(ctx, f.pixels * 3 * sizeof(float)) : NULL;
    float *scratch = drift_alloc(ctx, f.pixels * 3 * sizeof(float));
    uint64_t *row_bad = drift_alloc(ctx, (size_t)f.height * sizeof(uint64_t));
    double *sums = drift_alloc(ctx, f.pixels * 2 * sizeof(double));
    drift_result r = DRIFT_ERR_OUT_OF_MEMORY;
    if (!f.irr || !f.var || !f.normal || !f.depth || !f.albedo_lum || !scratch || !row_bad ||
        !sums || (guide && !f.guide)) {
        goto done;
    }
    prepare_job pj = { in, guide, &f, row_bad };
    drift_parallel_for(ctx, (size_t)f.height, 4, prepare_rows, &pj);
    uint64_t nonfinite = 0, clamp_count = 0;
    for (int32_t y = 0; y < f.height; ++y) {
        nonfinite += row_bad[y];
    }
    if (nonfinite) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_OK, NULL, 0,
                  "denoise: %llu input values were NaN or infinite and were taken as 0",
                  (unsigned long long)nonfinite);
    }
    if (f.sample_count < 4 || !in->variance) {
        box_moments(&f, 3, scratch, scratch + f.pixels, sums, sums + f.pixels);
        spatial_variance(&f, scratch, scratch + f.pixels);
    }
    double variance_sum = 0.0;
    for (size_t i = 0; i < f.pixels; ++i) {
        variance_sum += (double)f.var[i];
    }
    if (!p.no_firefly_clamp) {
        box_moments(&f, 2, scratch, scratch + f.pixels, sums, sums + f.pixels);
        clamp_count = clamp_fireflies(&f, scratch, scratch + f.pixels);
    }
    r = p.method == DRIFT_DENOISE_REGRESSION            ? denoise_regression(&f, 32, scratch)
        : p.method == DRIFT_DENOISE_REGRESSION_RESIDUAL ? regression_residual(&f, scratch)
                                                        : denoise_variance_guided(&f, scratch);
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, c->width, c->height, 3, out);
    }
    if (r == DRIFT_OK) { // stage 6: remodulate
        for (int32_t y = 0; y < f.height; ++y) {
            for (int32_t x = 0; x < f.width; ++x) {
                size_t i = (size_t)y * (size_t)f.width + (size_t)x;
                const float *a = in->albedo ? drift_image_pixel(in->albedo, x, y) : NULL;
                float *dst = drift_image_pixel(out, x, y);
                for (int k = 0; k < 3; ++k) {
                    float div = a && isfinite(a[k])
                                    ? drift_denoise_albedo_divisor(fmaxf(a[k], 0.0f))
                                    : 1.0f;
                    float v = scratch[3 * i + k];
                    dst[k] = (p.signed_color ? v : fmaxf(v, 0.0f)) * div;
                }
            }
        }
        if (report) {
            report->nonfinite = nonfinite;
            report->clamped = clamp_count;
            report->mean_variance = variance_sum / (double)f.pixels;
        }
    }
done:
    frame_free(&f);
    drift_free(ctx, scratch);
    drift_free(ctx, row_bad);
    drift_free(ctx, sums);
    return r;
}

// With a direct part: the rest (colour - direct, at least 0) and the direct part filtered
// apart, each with its own variance, and summed; the rest by REGRESSION_RESIDUAL unless asked
// otherwise (drift/denoise.h).
drift_result drift_denoise_feature(drift_context *ctx, const drift_denoise_inputs *in,
                                   const drift_denoise_feature_params *params, drift_image *out,
                                   drift_denoise_report *report)
{
    if (!in || (!in->direct && !in->direct_variance && !in->indirect_variance)) {
        return denoise_feature_guided(ctx, in, NULL, params, out, report);
    }
    if (out) {
        *out = (drift_image){ 0 };
    }
    const drift_image *c = in->color;
    drift_denoise_feature_params resolved = drift_denoise_feature_params_resolve(params);
    if (resolved.signed_color) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: a signed colour takes no direct part");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!out || !c || !c->pixels || c->channels < 3 || !in->direct || !in->direct_variance ||
        !in->indirect_variance || !same_size(c, in->direct, 3) ||
        !same_size(c, in->direct_variance, 1) || !same_size(c, in->indirect_variance, 1)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: the direct part needs both variances, all of the colour's size");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_image rest = { 0 }, direct_out = { 0 };
    drift_result r = drift_image_create(ctx, c->width, c->height, 3, &rest);
    for (int32_t y = 0; r == DRIFT_OK && y < c->height; ++y) {
        for (int32_t x = 0; x < c->width; ++x) {
            const float *a = drift_image_pixel(c, x, y), *d = drift_image_pixel(in->direct, x, y);
            float *dst = drift_image_pixel(&rest, x, y);
            for (int k = 0; k < 3; ++k) {
                float v = a[k] - d[k]; // NaN stays NaN: counted by the filter
                dst[k] = v < 0.0f ? 0.0f : v;
            }
        }
    }
    drift_denoise_inputs part = *in;
    part.direct = part.direct_variance = part.indirect_variance = NULL;
    drift_denoise_report rep_rest = { 0 }, rep_direct = { 0 };
    if (r == DRIFT_OK) {
        part.color = &rest;
        part.variance = in->indirect_variance;
        drift_denoise_feature_params pi = drift_denoise_feature_params_resolve(params);
        pi.sigma_luminance = pi.sigma_luminance_indirect;
        if (pi.method == DRIFT_DENOISE_VARIANCE_GUIDED && !pi.indirect_variance_guided) {
            pi.method = DRIFT_DENOISE_REGRESSION_RESIDUAL;
        }
        r = denoise_feature_guided(ctx, &part, NULL, &pi, out, &rep_rest);
    }
    if (r == DRIFT_OK) {
        part.color = in->direct;
        part.variance = in->direct_variance;
        drift_denoise_feature_params pd = drift_denoise_feature_params_resolve(params);
        pd.sigma_luminance = pd.sigma_luminance_direct;
        r = denoise_feature_guided(ctx, &part, NULL, &pd, &direct_out, &rep_direct);
    }
    if (r == DRIFT_OK) {
        for (int32_t y = 0; y < c->height; ++y) {
            for (int32_t x = 0; x < c->width; ++x) {
                float *dst = drift_image_pixel(out, x, y);
                const float *d = drift_image_pixel(&direct_out, x, y);
                for (int k = 0; k < 3; ++k) {
                    dst[k] += d[k];
                }
            }
        }
        if (report) {
            report->nonfinite = rep_rest.nonfinite + rep_direct.nonfinite;
            report->clamped = rep_rest.clamped + rep_direct.clamped;
            report->mean_variance = rep_rest.mean_variance + rep_direct.mean_variance;
        }
    } else {
        drift_image_destroy(ctx, out);
    }
    drift_image_destroy(ctx, &rest);
    drift_image_destroy(ctx, &direct_out);
    return r;
}
