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
//     w_l = exp(-|l_p - l_q| / (sigma_l' sqrt(g3x3(v)_p) + 1e-10))        (eq. 5)
//           with sigma_l' = sigma_l (1 + 1 / sqrt(n)) (see prefilter_rows)
//     w_n = max(0, n_p . n_q)^sigma_n                                      (eq. 3)
//     w_z = exp(-|z_p - z_q| / (sigma_z 2^i z_p)): a relative depth step (drift's a-trous
//           form, as the path tracer gives no screen-space depth gradient); misses only
//           mix with misses
//     w_a = exp(-ln((a_p + 0.01) / (a_q + 0.01))^2 / sigma_a^2) on albedo luminance, a
//           scale-free ratio: keeps emitters (albedo = emission, ~50x a wall's) from
//           mixing with what they light, and weakly (0.15) texels 4x apart
// g3x3 is the 3x3 Gaussian (1/4 1/2 1/4 separable) of the variance: SVGF's prefilter.
// A pixel whose normal is zero (an escaped ray) keeps its value; exp is exp_neg (exp_neg.h).
// The passes work on planes, a tap's weights over a run of a row in one loop the compiler
// vectorises, as the a-trous filter's (docs/decisions/0028).
#include "core/vectorise.h"
#include "denoise/exp_neg.h"
#include "feature_internal.h"

#include <math.h>
#include <string.h>

#define SVGF_RUN 128 // pixels of a row whose taps are weighed together

static const float b3[5] = { 1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f };
static const float g1[3] = { 0.25f, 0.5f, 0.25f };

typedef struct svgf_planes {
    float *c[3], *lum, *var; // this pass's input
} svgf_planes;

typedef struct svgf_job {
    const denoise_frame *f;
    const float *normal[3], *depth, *log_albedo;
    svgf_planes in, out;
    float *inv_sigma; // 1 / (sigma_l sqrt(g3x3(v)) + 1e-10), made by the first stage
    int32_t step;
    float inv_depth; // 1 / (sigma_z 2^i)
    float inv_albedo2;
    int normal_pow; // sigma_normal when a whole number up to 4096, else -1
    float sigma_normal;
} svgf_job;

static void prefilter_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const svgf_job *j = user;
    int32_t w = j->f->width, h = j->f->height;
    // sigma_l widened by the variance estimate's own uncertainty at few samples (a sample
    // variance of n values is off by ~sqrt(2 / (n - 1)) relative): 2x at 1 spp, 1.25x at 16.
    float sigma = j->f->params.sigma_luminance * (1.0f + 1.0f / sqrtf((float)j->f->sample_count));
    for (size_t yy = begin; yy < end; ++yy) {
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < w; ++x) {
            float s = 0.0f, sw = 0.0f;
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    int32_t qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h) {
                        continue;
                    }
                    float k = g1[dx + 1] * g1[dy + 1];
                    s += k * j->in.var[(size_t)qy * (size_t)w + (size_t)qx];
                    sw += k;
                }
            }
            j->inv_sigma[(size_t)y * (size_t)w + (size_t)x] =
                1.0f / (sigma * sqrtf(s / sw) + 1e-10f);
        }
    }
}

// One tap (kernel weight wk, the neighbour `offset` pixels away) over pixels [p, p + n).
static inline DRIFT_ALWAYS_INLINE void svgf_tap(const svgf_job *j, size_t p, ptrdiff_t offset,
                                                int32_t n, float wk, float *restrict sum0,
                                                float *restrict sum1, float *restrict sum2,
                                                float *restrict wsum, float *restrict vsum)
{
    size_t q = (size_t)((ptrdiff_t)p + offset);
    float nw[SVGF_RUN];
    const float *restrict nc0 = j->normal[0] + p, *restrict nq0 = j->normal[0] + q;
    const float *restrict nc1 = j->normal[1] + p, *restrict nq1 = j->normal[1] + q;
    const float *restrict nc2 = j->normal[2] + p, *restrict nq2 = j->normal[2] + q;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float d = nc0[i] * nq0[i] + nc1[i] * nq1[i] + nc2[i] * nq2[i];
        d = d > 0.0f ? d : 0.0f;
        nw[i] = d < 1.0f ? d : 1.0f;
    }
    if (j->normal_pow == 128) {
        DRIFT_IVDEP
        for (int32_t i = 0; i < n; ++i) {
            float d = nw[i];
            for (int k = 0; k < 7; ++k) {
                d *= d;
            }
            nw[i] = d;
        }
    } else {
        for (int32_t i = 0; i < n; ++i) {
            nw[i] = nw[i] > 0.0f ? powf(nw[i], j->sigma_normal) : 0.0f;
        }
    }
    const float *restrict zc = j->depth + p, *restrict zq = j->depth + q;
    const float *restrict ac = j->log_albedo + p, *restrict aq = j->log_albedo + q;
    const float *restrict lc = j->in.lum + p, *restrict lq = j->in.lum + q;
    const float *restrict is = j->inv_sigma + p;
    const float *restrict c0 = j->in.c[0] + q, *restrict c1 = j->in.c[1] + q;
    const float *restrict c2 = j->in.c[2] + q, *restrict vq = j->in.var + q;
    const float inv_depth = j->inv_depth, inv_albedo2 = j->inv_albedo2;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float z = zc[i] > 1e-30f ? zc[i] : 1e-30f;
        float e = fabsf(lc[i] - lq[i]) * is[i] + fabsf(zc[i] - zq[i]) * (inv_depth / z);
        float da = ac[i] - aq[i];
        e += da * da * inv_albedo2;
        float hit_c = zc[i] > 0.0f ? 1.0f : 0.0f, hit_q = zq[i] > 0.0f ? 1.0f : 0.0f;
        float keep = hit_c == hit_q ? 1.0f : 0.0f;
        keep = e <= DENOISE_EXP_CUTOFF ? keep : 0.0f;
        float w = keep * wk * nw[i] * exp_neg(e < DENOISE_EXP_CUTOFF ? e : DENOISE_EXP_CUTOFF);
        sum0[i] += w * c0[i];
        sum1[i] += w * c1[i];
        sum2[i] += w * c2[i];
        wsum[i] += w;
        vsum[i] += w * w * vq[i];
    }
}

static DRIFT_AVX2_CLONES void svgf_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const svgf_job *j = user;
    const int32_t w = j->f->width, h = j->f->height;
    const float centre = b3[2] * b3[2];
    float sum0[SVGF_RUN], sum1[SVGF_RUN], sum2[SVGF_RUN], wsum[SVGF_RUN], vsum[SVGF_RUN];
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x0 = 0; x0 < w; x0 += SVGF_RUN) {
            int32_t n = w - x0 < SVGF_RUN ? w - x0 : SVGF_RUN;
            size_t p = (size_t)y * (size_t)w + (size_t)x0;
            for (int32_t i = 0; i < n; ++i) {
                sum0[i] = centre * j->in.c[0][p + (size_t)i];
                sum1[i] = centre * j->in.c[1][p + (size_t)i];
                sum2[i] = centre * j->in.c[2][p + (size_t)i];
                wsum[i] = centre;
                vsum[i] = centre * centre * j->in.var[p + (size_t)i];
            }
            for (int dy = -2; dy <= 2; ++dy) {
                int32_t qy = y + dy * j->step;
                if (qy < 0 || qy >= h) {
                    continue;
                }
                for (int dx = -2; dx <= 2; ++dx) {
                    if (dx == 0 && dy == 0) {
                        continue;
                    }
                    int32_t shift = dx * j->step;
                    int32_t lo = -(x0 + shift) > 0 ? -(x0 + shift) : 0;
                    int32_t hi = w - x0 - shift < n ? w - x0 - shift : n;
                    if (lo >= hi) {
                        continue;
                    }
                    ptrdiff_t offset = (ptrdiff_t)dy * j->step * w + shift;
                    svgf_tap(j, p + (size_t)lo, offset, hi - lo, b3[dx + 2] * b3[dy + 2], sum0 + lo,
                             sum1 + lo, sum2 + lo, wsum + lo, vsum + lo);
                }
            }
            // wsum >= the centre tap's weight (3/8)^2 > 0.
            for (int32_t i = 0; i < n; ++i) {
                float c0 = sum0[i] / wsum[i], c1 = sum1[i] / wsum[i], c2 = sum2[i] / wsum[i];
                j->out.c[0][p + (size_t)i] = c0;
                j->out.c[1][p + (size_t)i] = c1;
                j->out.c[2][p + (size_t)i] = c2;
                j->out.lum[p + (size_t)i] = 0.2126f * c0 + 0.7152f * c1 + 0.0722f * c2;
                j->out.var[p + (size_t)i] = vsum[i] / (wsum[i] * wsum[i]);
            }
        }
    }
}

drift_result denoise_variance_guided(const denoise_frame *f, float *out)
{
    size_t n = f->pixels;
    // Planes: 2 x (c0 c1 c2 lum var) ping-pong, n0 n1 n2, inv_sigma, log albedo.
    float *mem = drift_alloc(f->ctx, n * 15 * sizeof(float));
    if (!mem) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    svgf_planes planes[2];
    for (int b = 0; b < 2; ++b) {
        float *base = mem + (size_t)b * 5 * n;
        planes[b] = (svgf_planes){ { base, base + n, base + 2 * n }, base + 3 * n, base + 4 * n };
    }
    float *normal[3] = { mem + 10 * n, mem + 11 * n, mem + 12 * n };
    float *inv_sigma = mem + 13 * n, *log_albedo = mem + 14 * n;
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            planes[0].c[k][i] = f->irr[3 * i + k];
            normal[k][i] = f->normal[3 * i + k];
        }
        planes[0].lum[i] = denoise_lum(f->irr + 3 * i);
        planes[0].var[i] = f->var[i];
        log_albedo[i] = logf(f->albedo_lum[i] + 0.01f);
    }
    const drift_denoise_feature_params *p = &f->params;
    int whole = p->sigma_normal == floorf(p->sigma_normal) && p->sigma_normal <= 4096.0f
                    ? (int)p->sigma_normal
                    : -1;
    int src = 0;
    for (int i = 0; i < p->iterations; ++i, src = 1 - src) {
        svgf_job job = { .f = f,
                         .normal = { normal[0], normal[1], normal[2] },
                         .depth = f->depth,
                         .log_albedo = log_albedo,
                         .in = planes[src],
                         .out = planes[1 - src],
                         .inv_sigma = inv_sigma,
                         .step = 1 << i,
                         .inv_depth = 1.0f / (p->sigma_depth * (float)(1 << i)),
                         .inv_albedo2 = 1.0f / (p->sigma_albedo * p->sigma_albedo),
                         .normal_pow = whole,
                         .sigma_normal = p->sigma_normal };
        drift_parallel_for(f->ctx, (size_t)f->height, 8, prefilter_rows, &job);
        drift_parallel_for(f->ctx, (size_t)f->height, 2, svgf_rows, &job);
    }
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            out[3 * i + k] = planes[src].c[k][i];
        }
    }
    drift_free(f->ctx, mem);
    return DRIFT_OK;
}
