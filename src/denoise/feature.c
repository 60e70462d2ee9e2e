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
        p.iterations = 5;
    }
    if (p.sigma_luminance == 0.0f) {
        p.sigma_luminance = 4.0f;
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
                f->irr[3 * i + k] = fmaxf(finite_or_zero(c[k], &bad), 0.0f) / div[k];
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

// --- STAGE 3: FIREFLIES ---

typedef struct firefly_job {
    const denoise_frame *f;
    float *irr_out;
    uint8_t *clamped; // a pixel
} firefly_job;

static void firefly_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    firefly_job *job = user;
    const denoise_frame *f = job->f;
    int32_t w = f->width, h = f->height;
    for (size_t yy = begin; yy < end; ++yy) {
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            double s = 0.0, s2 = 0.0;
            int count = 0;
            for (int32_t qy = y - 2; qy <= y + 2; ++qy) {
                for (int32_t qx = x - 2; qx <= x + 2; ++qx) {
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h) {
                        continue;
                    }
                    double l = denoise_lum(f->irr + 3 * ((size_t)qy * (size_t)w + (size_t)qx));
                    s += l;
                    s2 += l * l;
                    ++count;
                }
            }
            double mean = s / count, sd = sqrt(fmax(s2 / count - mean * mean, 0.0));
            double own = f->sample_count >= 4 ? sqrt((double)f->var[i]) : 0.0;
            double limit = mean + 3.0 * sd + 3.0 * own;
            const float *c = f->irr + 3 * i;
            float l = denoise_lum(c);
            float scale = (double)l > limit && l > 0.0f ? (float)(limit / (double)l) : 1.0f;
            job->clamped[i] = scale < 1.0f;
            for (int k = 0; k < 3; ++k) {
                job->irr_out[3 * i + k] = c[k] * scale;
            }
        }
    }
}

// --- STAGE 4: VARIANCE BELOW 4 SAMPLES ---

typedef struct spatial_job {
    const denoise_frame *f;
    float *var_out;
} spatial_job;

// The 7x7 moments of the demodulated luminance, each tap weighed by the normal and depth
// weights of stage 5 (so that the variance does not straddle edges): sigma^2 / n.
static void spatial_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    spatial_job *job = user;
    const denoise_frame *f = job->f;
    int32_t w = f->width, h = f->height;
    float inv_n = 1.0f / (float)f->sample_count;
    for (size_t yy = begin; yy < end; ++yy) {
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < w; ++x) {
            size_t p = (size_t)y * (size_t)w + (size_t)x;
            const float *np = f->normal + 3 * p;
            float zp = f->depth[p];
            double sw = 0.0, s = 0.0, s2 = 0.0;
            for (int32_t qy = y - 3; qy <= y + 3; ++qy) {
                for (int32_t qx = x - 3; qx <= x + 3; ++qx) {
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h) {
                        continue;
                    }
                    size_t q = (size_t)qy * (size_t)w + (size_t)qx;
                    const float *nq = f->normal + 3 * q;
                    float dot = denoise_normal_dot(np, nq);
                    float zq = f->depth[q];
                    float wz = (zp > 0.0f) != (zq > 0.0f) ? 0.0f
                               : zp > 0.0f                ? expf(-fabsf(zp - zq) / (0.1f * zp))
                                                          : 1.0f;
                    float d2 = dot * dot, d4 = d2 * d2, d8 = d4 * d4;
                    double wgt = dot > 0.0f ? (double)(d8 * d8 * wz) : 0.0; // dot^16
                    double l = denoise_lum(f->irr + 3 * q);
                    sw += wgt;
                    s += wgt * l;
                    s2 += wgt * l * l;
                }
            }
            double mean = s / sw, var = fmax(s2 / sw - mean * mean, 0.0);
            job->var_out[p] = fmaxf(f->var[p], (float)var * inv_n);
        }
    }
}

// --- THE CALL ---

static void frame_free(denoise_frame *f)
{
    drift_free(f->ctx, f->irr);
    drift_free(f->ctx, f->var);
    drift_free(f->ctx, f->normal);
    drift_free(f->ctx, f->depth);
    drift_free(f->ctx, f->albedo_lum);
}

drift_result drift_denoise_feature(drift_context *ctx, const drift_denoise_inputs *in,
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
        !same_size(c, in->depth, 1) || !same_size(c, in->variance, 1) ||
        (unsigned)p.method >= DRIFT_DENOISE_METHOD_COUNT || p.iterations < 1 || p.iterations > 10 ||
        !(p.sigma_luminance > 0.0f) || !(p.sigma_normal > 0.0f) || !(p.sigma_depth > 0.0f) ||
        !(p.sigma_albedo > 0.0f)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: the colour must be RGB, every guide of its size and the params in "
                  "range (iterations 1..10, sigmas > 0)");
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
    float *scratch = drift_alloc(ctx, f.pixels * 3 * sizeof(float));
    uint64_t *row_bad = drift_alloc(ctx, (size_t)f.height * sizeof(uint64_t));
    uint8_t *clamped = drift_alloc(ctx, f.pixels);
    drift_result r = DRIFT_ERR_OUT_OF_MEMORY;
    if (!f.irr || !f.var || !f.normal || !f.depth || !f.albedo_lum || !scratch || !row_bad ||
        !clamped) {
        goto done;
    }
    prepare_job pj = { in, &f, row_bad };
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
        spatial_job sj = { &f, scratch };
        drift_parallel_for(ctx, (size_t)f.height, 4, spatial_rows, &sj);
        memcpy(f.var, scratch, f.pixels * sizeof(float));
    }
    double variance_sum = 0.0;
    for (size_t i = 0; i < f.pixels; ++i) {
        variance_sum += (double)f.var[i];
    }
    if (!p.no_firefly_clamp) {
        firefly_job fj = { &f, scratch, clamped };
        drift_parallel_for(ctx, (size_t)f.height, 4, firefly_rows, &fj);
        float *t = f.irr;
        f.irr = scratch;
        scratch = t;
        for (size_t i = 0; i < f.pixels; ++i) {
            clamp_count += clamped[i];
        }
    }
    r = p.method == DRIFT_DENOISE_REGRESSION ? denoise_regression(&f, scratch)
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
                    dst[k] = fmaxf(scratch[3 * i + k], 0.0f) * div;
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
    drift_free(ctx, clamped);
    return r;
}
