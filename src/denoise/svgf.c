// Stage 5, variance-guided: the spatial filter of SVGF (Schied, Kaplanyan, Wyman, Patney,
// Chaitanya, Burgess, Liu, Dachsbacher, Lefohn & Salvi 2017, "Spatiotemporal
// Variance-Guided Filtering: Real-Time Reconstruction for Path-Traced Global Illumination",
// HPG 2017, §4.2-4.3) on the demodulated irradiance, with the per-pixel variance of the
// samples (the path tracer's running moments) in place of SVGF's temporal moments.
//
// Pass i (i = 0 .. iterations-1) is an a-trous step of the 5x5 B3-spline kernel h with taps
// 2^i pixels apart:
//   c'_p = sum_q h(q) w(p, q) c_q / sum_q h(q) w(p, q)
//   v'_p = sum_q h(q)^2 w(p, q)^2 v_q / (sum_q h(q) w(p, q))^2          (SVGF eq. 4)
//   w(p, q) = w_l w_n w_z w_a:
//     w_l = exp(-|l_p - l_q| / (sigma_l sqrt(g3x3(v)_p) + 1e-10))         (eq. 5)
//     w_n = max(0, n_p . n_q)^sigma_n                                      (eq. 3)
//     w_z = exp(-|z_p - z_q| / (sigma_z 2^i z_p)): a relative depth step (drift's a-trous
//           form, as the path tracer gives no screen-space depth gradient); misses only
//           mix with misses
//     w_a = exp(-(|a_p - a_q| / max(a_p, a_q, 0.05))^2 / sigma_a^2) on albedo luminance:
//           keeps emitters (albedo = emission) from bleeding into what they light
// g3x3 is the 3x3 Gaussian (1/4 1/2 1/4 separable) of the variance: SVGF's prefilter.
#include "feature_internal.h"

#include <math.h>
#include <string.h>

static const float b3[5] = { 1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f };
static const float g1[3] = { 0.25f, 0.5f, 0.25f };

typedef struct svgf_job {
    const denoise_frame *f;
    const float *c_in, *v_in;
    float *v_blur; // g3x3(v_in), made by the job's first stage
    float *c_out, *v_out;
    int32_t step;
    float inv_depth; // 1 / (sigma_z 2^i)
} svgf_job;

// dot^e for e a whole number (sigma_normal 128: seven squarings instead of a powf).
static float power(float dot, float e, int whole)
{
    if (whole < 0) {
        return powf(dot, e);
    }
    float r = 1.0f;
    for (int n = whole; n; n >>= 1) {
        if (n & 1) {
            r *= dot;
        }
        dot *= dot;
    }
    return r;
}

static float variance_prefilter(const denoise_frame *f, const float *v, int32_t x, int32_t y)
{
    float s = 0.0f, sw = 0.0f;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            int32_t qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= f->width || qy >= f->height) {
                continue;
            }
            float k = g1[dx + 1] * g1[dy + 1];
            s += k * v[(size_t)qy * (size_t)f->width + (size_t)qx];
            sw += k;
        }
    }
    return s / sw;
}

static void prefilter_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const svgf_job *job = user;
    for (size_t y = begin; y < end; ++y) {
        for (int32_t x = 0; x < job->f->width; ++x) {
            job->v_blur[y * (size_t)job->f->width + (size_t)x] =
                variance_prefilter(job->f, job->v_in, x, (int32_t)y);
        }
    }
}

static void svgf_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const svgf_job *job = user;
    const denoise_frame *f = job->f;
    const drift_denoise_feature_params *p = &f->params;
    int32_t w = f->width, h = f->height, step = job->step;
    float inv_albedo2 = 1.0f / (p->sigma_albedo * p->sigma_albedo);
    int whole = p->sigma_normal == floorf(p->sigma_normal) && p->sigma_normal <= 4096.0f
                    ? (int)p->sigma_normal
                    : -1;
    for (size_t yy = begin; yy < end; ++yy) {
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < w; ++x) {
            size_t pi = (size_t)y * (size_t)w + (size_t)x;
            const float *cp = job->c_in + 3 * pi;
            const float *np = f->normal + 3 * pi;
            float lp = denoise_lum(cp), zp = f->depth[pi], ap = f->albedo_lum[pi];
            float sigma = p->sigma_luminance * sqrtf(job->v_blur[pi]) + 1e-10f;
            float inv_sigma = 1.0f / sigma;
            double sw = 0.0, sv = 0.0, sc[3] = { 0.0, 0.0, 0.0 };
            for (int ky = -2; ky <= 2; ++ky) {
                int32_t qy = y + ky * step;
                if (qy < 0 || qy >= h) {
                    continue;
                }
                for (int kx = -2; kx <= 2; ++kx) {
                    int32_t qx = x + kx * step;
                    if (qx < 0 || qx >= w) {
                        continue;
                    }
                    size_t qi = (size_t)qy * (size_t)w + (size_t)qx;
                    const float *cq = job->c_in + 3 * qi;
                    const float *nq = f->normal + 3 * qi;
                    float zq = f->depth[qi], aq = f->albedo_lum[qi];
                    float e = fabsf(lp - denoise_lum(cq)) * inv_sigma;
                    if ((zp > 0.0f) != (zq > 0.0f)) {
                        continue; // a miss only mixes with misses
                    }
                    if (zp > 0.0f) {
                        e += fabsf(zp - zq) / zp * job->inv_depth;
                    }
                    float amax = fmaxf(fmaxf(ap, aq), 0.05f);
                    float da = (ap - aq) / amax;
                    e += da * da * inv_albedo2;
                    float dot = denoise_normal_dot(np, nq);
                    if (e > 30.0f || dot <= 0.0f) {
                        continue;
                    }
                    double wgt = (double)(b3[kx + 2] * b3[ky + 2] * expf(-e) *
                                          power(dot, p->sigma_normal, whole));
                    sw += wgt;
                    sv += wgt * wgt * (double)job->v_in[qi];
                    for (int k = 0; k < 3; ++k) {
                        sc[k] += wgt * (double)cq[k];
                    }
                }
            }
            // The centre tap has weight h(0)^2 > 0 (e = 0, dot = 1): sw > 0.
            for (int k = 0; k < 3; ++k) {
                job->c_out[3 * pi + k] = (float)(sc[k] / sw);
            }
            job->v_out[pi] = (float)(sv / (sw * sw));
        }
    }
}

drift_result denoise_variance_guided(const denoise_frame *f, float *out)
{
    float *c[2] = { drift_alloc(f->ctx, f->pixels * 3 * sizeof(float)), out };
    float *v[2] = { drift_alloc(f->ctx, f->pixels * sizeof(float)),
                    drift_alloc(f->ctx, f->pixels * sizeof(float)) };
    float *v_blur = drift_alloc(f->ctx, f->pixels * sizeof(float));
    if (!c[0] || !v[0] || !v[1] || !v_blur) {
        drift_free(f->ctx, v_blur);
        drift_free(f->ctx, c[0]);
        drift_free(f->ctx, v[0]);
        drift_free(f->ctx, v[1]);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    // Ping-pong so that the last pass writes into out: pass i reads buffer src, writes dst.
    int iterations = f->params.iterations;
    int dst = (iterations % 2 == 1) ? 1 : 0; // c[1] is out
    memcpy(c[1 - dst], f->irr, f->pixels * 3 * sizeof(float));
    memcpy(v[1 - dst], f->var, f->pixels * sizeof(float));
    for (int i = 0; i < iterations; ++i) {
        int src = 1 - dst;
        svgf_job job = { .f = f,
                         .c_in = c[src],
                         .v_in = v[src],
                         .c_out = c[dst],
                         .v_out = v[dst],
                         .v_blur = v_blur,
                         .step = 1 << i,
                         .inv_depth = 1.0f / (f->params.sigma_depth * (float)(1 << i)) };
        drift_parallel_for(f->ctx, (size_t)f->height, 8, prefilter_rows, &job);
        drift_parallel_for(f->ctx, (size_t)f->height, 2, svgf_rows, &job);
        dst = src;
    }
    drift_free(f->ctx, c[0]);
    drift_free(f->ctx, v[0]);
    drift_free(f->ctx, v[1]);
    drift_free(f->ctx, v_blur);
    return DRIFT_OK;
}
