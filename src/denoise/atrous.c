// The edge-avoiding a-trous filter (include/drift/denoise.h gives the weights and defaults).
#include "core/vectorise.h"
#include "denoise/exp_neg.h"
#include "drift/denoise.h"

#include <math.h>
#include <string.h>

#define DENOISE_LUM_EPS 1e-2f

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

// The passes work on planes (structure of arrays, w * h floats each) so that each tap's
// weights over a run of pixels are one branch-free loop the compiler vectorises
// (docs/decisions/0028). A missing guide is a neutral plane: depth 0 everywhere (every
// pixel "missed", so all mix), albedo 0, normal +z.
typedef struct atrous_planes {
    float *color[3];
    float *normal[3], *albedo[3], *depth;
} atrous_planes;

typedef struct atrous_job {
    atrous_planes in; // in.color: this pass's input; the guides are shared
    float *out[3];
    int32_t width, height;
    int32_t step;
    int radius;      // 2: the 5 x 5 B3-spline kernel; 1: the 3 x 3 one
    float inv_color; // 1 / (sigma_color^2 2^-i); 0: no colour weight
    float sigma_normal;
    float inv_depth;  // 1 / (sigma_depth 2^i)
    float inv_albedo; // 1 / sigma_albedo^2
    int normal_pow;   // sigma_normal when a whole number up to 4096, else -1; 1: no normals
} atrous_job;

static const float b3[5] = { 1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f };
// The 3 x 3 kernel (small_kernel): the linear B-spline, 1/4 1/2 1/4.
static const float b1[3] = { 1.0f / 4.0f, 1.0f / 2.0f, 1.0f / 4.0f };

#define ATROUS_RUN 128 // pixels of a row whose taps are weighed together

// The weights of one tap (kernel weight wk, the neighbour `offset` pixels away) over pixels
// [p, p + n) of the centre's planes, added into the run's sums.
static inline DRIFT_ALWAYS_INLINE void atrous_tap(const atrous_job *j, bool color, size_t p,
                                                  ptrdiff_t offset, int32_t n, float wk,
                                                  float *restrict sum0, float *restrict sum1,
                                                  float *restrict sum2, float *restrict wsum)
{
    const atrous_planes *g = &j->in;
    size_t q = (size_t)((ptrdiff_t)p + offset);
    const float *restrict nc0 = g->normal[0] + p, *restrict nq0 = g->normal[0] + q;
    const float *restrict nc1 = g->normal[1] + p, *restrict nq1 = g->normal[1] + q;
    const float *restrict nc2 = g->normal[2] + p, *restrict nq2 = g->normal[2] + q;
    float nw[ATROUS_RUN], power[ATROUS_RUN];
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float d = nc0[i] * nq0[i] + nc1[i] * nq1[i] + nc2[i] * nq2[i];
        d = d > 0.0f ? d : 0.0f; // fminf and fmaxf do not vectorise (their NaN rules)
        nw[i] = d < 1.0f ? d : 1.0f;
    }
    if (j->normal_pow == 128) { // the default, in one sweep: 5 passes 25 -> 22 ms at 400²
        DRIFT_IVDEP
        for (int32_t i = 0; i < n; ++i) {
            float d = nw[i];
            for (int k = 0; k < 7; ++k) {
                d *= d;
            }
            nw[i] = d;
        }
    } else if (j->normal_pow < 0) {
        for (int32_t i = 0; i < n; ++i) {
            nw[i] = nw[i] > 0.0f && nw[i] < 1.0f ? powf(nw[i], j->sigma_normal) : nw[i];
        }
    } else if (j->normal_pow != 1) {
        // d^k by squaring, one bit of k a sweep; d^0 is 1 only where d > 0.
        for (int32_t i = 0; i < n; ++i) {
            power[i] = nw[i];
            nw[i] = nw[i] > 0.0f ? 1.0f : 0.0f;
        }
        for (int k = j->normal_pow; k; k >>= 1) {
            if (k & 1) {
                for (int32_t i = 0; i < n; ++i) {
                    nw[i] *= power[i];
                }
            }
            for (int32_t i = 0; i < n; ++i) {
                power[i] *= power[i];
            }
        }
    }
    const float *restrict zc = g->depth + p, *restrict zq = g->depth + q;
    const float *restrict ac0 = g->albedo[0] + p, *restrict aq0 = g->albedo[0] + q;
    const float *restrict ac1 = g->albedo[1] + p, *restrict aq1 = g->albedo[1] + q;
    const float *restrict ac2 = g->albedo[2] + p, *restrict aq2 = g->albedo[2] + q;
    const float *restrict cc0 = g->color[0] + p, *restrict cq0 = g->color[0] + q;
    const float *restrict cc1 = g->color[1] + p, *restrict cq1 = g->color[1] + q;
    const float *restrict cc2 = g->color[2] + p, *restrict cq2 = g->color[2] + q;
    const float inv_depth = j->inv_depth, inv_albedo = j->inv_albedo, inv_color = j->inv_color;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float z = zc[i] > 1e-30f ? zc[i] : 1e-30f; // a miss (z = 0): see keep
        float e = fabsf(zc[i] - zq[i]) * (inv_depth / z);
        float a0 = ac0[i] - aq0[i], a1 = ac1[i] - aq1[i], a2 = ac2[i] - aq2[i];
        e += (a0 * a0 + a1 * a1 + a2 * a2) * inv_albedo;
        if (color) { // a constant at each call: two loops, one without the colour weight
            float c0 = cc0[i] - cq0[i], c1 = cc1[i] - cq1[i], c2 = cc2[i] - cq2[i];
            float mean = 0.5f * (fabsf(0.2126f * cc0[i] + 0.7152f * cc1[i] + 0.0722f * cc2[i]) +
                                 fabsf(0.2126f * cq0[i] + 0.7152f * cq1[i] + 0.0722f * cq2[i])) +
                         DENOISE_LUM_EPS;
            e += (c0 * c0 + c1 * c1 + c2 * c2) * inv_color / (mean * mean);
        }
        // A pixel whose ray missed mixes only with other misses; past the cutoff a tap adds
        // nothing.
        float hit_c = zc[i] > 0.0f ? 1.0f : 0.0f, hit_q = zq[i] > 0.0f ? 1.0f : 0.0f;
        float keep = hit_c == hit_q ? 1.0f : 0.0f;
        keep = e <= DENOISE_EXP_CUTOFF ? keep : 0.0f;
        float w = keep * wk * nw[i] * exp_neg(e < DENOISE_EXP_CUTOFF ? e : DENOISE_EXP_CUTOFF);
        sum0[i] += w * cq0[i];
        sum1[i] += w * cq1[i];
        sum2[i] += w * cq2[i];
        wsum[i] += w;
    }
}

static DRIFT_AVX2_CLONES void atrous_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const atrous_job *j = user;
    const int32_t w = j->width, h = j->height;
    const int radius = j->radius;
    const float *kernel = radius == 1 ? b1 : b3;
    const float centre = kernel[radius] * kernel[radius];
    float sum0[ATROUS_RUN], sum1[ATROUS_RUN], sum2[ATROUS_RUN], wsum[ATROUS_RUN];
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x0 = 0; x0 < w; x0 += ATROUS_RUN) {
            int32_t n = w - x0 < ATROUS_RUN ? w - x0 : ATROUS_RUN;
            size_t p = (size_t)y * (size_t)w + (size_t)x0;
            for (int32_t i = 0; i < n; ++i) {
                sum0[i] = centre * j->in.color[0][p + (size_t)i];
                sum1[i] = centre * j->in.color[1][p + (size_t)i];
                sum2[i] = centre * j->in.color[2][p + (size_t)i];
                wsum[i] = centre;
            }
            for (int dy = -radius; dy <= radius; ++dy) {
                int32_t qy = y + dy * j->step;
                if (qy < 0 || qy >= h) {
                    continue;
                }
                for (int dx = -radius; dx <= radius; ++dx) {
                    if (dx == 0 && dy == 0) {
                        continue;
                    }
                    // The pixels of the run whose neighbour lies inside the row: one interval.
                    int32_t shift = dx * j->step;
                    int32_t lo = -(x0 + shift) > 0 ? -(x0 + shift) : 0;
                    int32_t hi = w - x0 - shift < n ? w - x0 - shift : n;
                    if (lo >= hi) {
                        continue;
                    }
                    ptrdiff_t offset = (ptrdiff_t)dy * j->step * w + shift;
                    size_t first = p + (size_t)lo;
                    float wk = kernel[dx + radius] * kernel[dy + radius];
                    if (j->inv_color > 0.0f) {
                        atrous_tap(j, true, first, offset, hi - lo, wk, sum0 + lo, sum1 + lo,
                                   sum2 + lo, wsum + lo);
                    } else {
                        atrous_tap(j, false, first, offset, hi - lo, wk, sum0 + lo, sum1 + lo,
                                   sum2 + lo, wsum + lo);
                    }
                }
            }
            // wsum >= the centre tap's weight, (3/8)^2 or (1/2)^2, > 0.
            for (int32_t i = 0; i < n; ++i) {
                j->out[0][p + (size_t)i] = sum0[i] / wsum[i];
                j->out[1][p + (size_t)i] = sum1[i] / wsum[i];
                j->out[2][p + (size_t)i] = sum2[i] / wsum[i];
            }
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
    return drift_denoise_albedo_divisor(a);
}

// The copies into the planes (demodulated colour, the guides or their neutral values) and
// back, row by row over the threads.
typedef struct atrous_io {
    const drift_image *color, *albedo, *normal, *depth;
    bool demodulate;
    atrous_planes *planes;
    drift_image *out;
} atrous_io;

static void planes_from_images(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const atrous_io *io = user;
    const atrous_planes *planes = io->planes;
    const int32_t w = io->color->width;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            const float *c = drift_image_pixel(io->color, x, y);
            for (int k = 0; k < 3; ++k) {
                planes->color[k][i] =
                    io->demodulate ? c[k] / albedo_factor(io->albedo, x, y, k) : c[k];
                planes->normal[k][i] = io->normal ? drift_image_pixel(io->normal, x, y)[k] : k == 2;
                planes->albedo[k][i] = io->albedo ? drift_image_pixel(io->albedo, x, y)[k] : 0.0f;
            }
            planes->depth[i] = io->depth ? drift_image_pixel(io->depth, x, y)[0] : 0.0f;
        }
    }
}

static void image_from_planes(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const atrous_io *io = user;
    const atrous_planes *planes = io->planes;
    const int32_t w = io->color->width;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            float *o = drift_image_pixel(io->out, x, y);
            for (int k = 0; k < 3; ++k) {
                o[k] = io->demodulate ? planes->color[k][i] * albedo_factor(io->albedo, x, y, k)
                                      : planes->color[k][i];
            }
        }
    }
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
    size_t count = (size_t)w * (size_t)h;
    // Planes: colour ping and pong (3 each), normal (3), albedo (3), depth.
    float *block = drift_alloc(ctx, 13 * count * sizeof(float));
    drift_result r = drift_image_create(ctx, w, h, 3, out);
    if (!block || r != DRIFT_OK) {
        drift_free(ctx, block);
        drift_image_destroy(ctx, out);
        return r != DRIFT_OK ? r : DRIFT_ERR_OUT_OF_MEMORY;
    }
    atrous_planes planes;
    float *pong[3]; // each pass writes these, then they become planes.color
    for (int k = 0; k < 3; ++k) {
        planes.color[k] = block + (size_t)k * count;
        pong[k] = block + (size_t)(3 + k) * count;
        planes.normal[k] = block + (size_t)(6 + k) * count;
        planes.albedo[k] = block + (size_t)(9 + k) * count;
    }
    planes.depth = block + 12 * count;
    atrous_io io = { .color = color,
                     .albedo = albedo,
                     .normal = normal,
                     .depth = depth,
                     .demodulate = albedo && !p.no_demodulate,
                     .planes = &planes };
    drift_parallel_for(ctx, (size_t)h, 8, planes_from_images, &io);
    int normal_pow = -1;
    if (!normal) {
        normal_pow = 1; // every dot product is 1
    } else if (p.sigma_normal == floorf(p.sigma_normal) && p.sigma_normal <= 4096.0f) {
        normal_pow = (int)p.sigma_normal;
    }
    atrous_job job = { .width = w,
                       .radius = p.small_kernel ? 1 : 2,
                       .height = h,
                       .sigma_normal = p.sigma_normal,
                       .normal_pow = normal_pow,
                       .inv_albedo = albedo ? 1.0f / (p.sigma_albedo * p.sigma_albedo) : 0.0f };
    for (int32_t i = 0; i < p.iterations; ++i) {
        job.in = planes;
        for (int k = 0; k < 3; ++k) {
            job.out[k] = pong[k];
        }
        job.step = 1 << i;
        float scale = ldexpf(1.0f, -i); // sigma_color^2 halved each pass
        job.inv_color = p.disable_color ? 0.0f : 1.0f / (p.sigma_color * p.sigma_color * scale);
        job.inv_depth = 1.0f / (p.sigma_depth * (float)job.step);
        drift_parallel_for(ctx, (size_t)h, 4, atrous_rows, &job);
        for (int k = 0; k < 3; ++k) {
            float *t = planes.color[k];
            planes.color[k] = pong[k];
            pong[k] = t;
        }
    }
    io.out = out;
    drift_parallel_for(ctx, (size_t)h, 8, image_from_planes, &io);
    drift_free(ctx, block);
    return DRIFT_OK;
}
