// The edge-avoiding a-trous filter (include/drift/denoise.h gives the weights and defaults).
#include "core/scratch.h"
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
    float *out[3];    // the sums of colour, then (each row once done) the filtered colour
    float *wsum;      // the sums of weights
    float *lum;       // |luminance| of in.color, per pixel (the colour weight's mean)
    float *inv_z;     // inv_depth / max(z, 1e-30), per pixel (the depth weight's scale)
    int32_t width, height;
    int32_t step;
    int32_t band;    // rows a band: bands run in parallel, each recomputes the pairs above it
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

// The normal weight max(n_p . n_q, 0)^sigma_normal of pixels [p, p + n) and their neighbours
// `offset` away: symmetric in p and q (the same products summed in the same order).
static inline DRIFT_ALWAYS_INLINE void
normal_weights(const atrous_job *j, size_t p, ptrdiff_t offset, int32_t n, float *restrict nw)
{
    const atrous_planes *g = &j->in;
    size_t q = (size_t)((ptrdiff_t)p + offset);
    const float *restrict nc0 = g->normal[0] + p, *restrict nq0 = g->normal[0] + q;
    const float *restrict nc1 = g->normal[1] + p, *restrict nq1 = g->normal[1] + q;
    const float *restrict nc2 = g->normal[2] + p, *restrict nq2 = g->normal[2] + q;
    float power[ATROUS_RUN];
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
}

// One tap (kernel weight wk, the neighbour `offset` pixels away) of pixels [p, p + n), added
// into their sums: the taps of a pixel's own row, whose pairs are not shared (below).
static inline DRIFT_ALWAYS_INLINE void atrous_tap(const atrous_job *j, bool color, size_t p,
                                                  ptrdiff_t offset, int32_t n, float wk)
{
    const atrous_planes *g = &j->in;
    size_t q = (size_t)((ptrdiff_t)p + offset);
    float nw[ATROUS_RUN];
    normal_weights(j, p, offset, n, nw);
    const float *restrict zc = g->depth + p, *restrict zq = g->depth + q;
    const float *restrict sc = j->inv_z + p;
    const float *restrict lc = j->lum + p, *restrict lq = j->lum + q;
    const float *restrict ac0 = g->albedo[0] + p, *restrict aq0 = g->albedo[0] + q;
    const float *restrict ac1 = g->albedo[1] + p, *restrict aq1 = g->albedo[1] + q;
    const float *restrict ac2 = g->albedo[2] + p, *restrict aq2 = g->albedo[2] + q;
    const float *restrict cc0 = g->color[0] + p, *restrict cq0 = g->color[0] + q;
    const float *restrict cc1 = g->color[1] + p, *restrict cq1 = g->color[1] + q;
    const float *restrict cc2 = g->color[2] + p, *restrict cq2 = g->color[2] + q;
    float *restrict sum0 = j->out[0] + p, *restrict sum1 = j->out[1] + p,
                    *restrict sum2 = j->out[2] + p, *restrict wsum = j->wsum + p;
    const float inv_albedo = j->inv_albedo, inv_color = j->inv_color;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float e = fabsf(zc[i] - zq[i]) * sc[i]; // a miss (z = 0): see keep
        float a0 = ac0[i] - aq0[i], a1 = ac1[i] - aq1[i], a2 = ac2[i] - aq2[i];
        e += (a0 * a0 + a1 * a1 + a2 * a2) * inv_albedo;
        if (color) { // a constant at each call: two loops, one without the colour weight
            float c0 = cc0[i] - cq0[i], c1 = cc1[i] - cq1[i], c2 = cc2[i] - cq2[i];
            float mean = 0.5f * (lc[i] + lq[i]) + DENOISE_LUM_EPS;
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

// A pair of taps at once: pixels [p, p + n) and their neighbours q `offset` away, q in a row
// below. The normal, albedo and colour terms are symmetric in p and q and computed once; the
// depth term (|z_p - z_q| over the centre's z) and the cutoff are each side's own. Each
// weight is the same float operations in the same order as atrous_tap's: the same bits. With
// `mine`, p's sums take q's colour now; q's weights go to wq for its sums later, in order.
static inline DRIFT_ALWAYS_INLINE void atrous_pair(const atrous_job *j, bool color, bool mine,
                                                   size_t p, ptrdiff_t offset, int32_t n, float wk,
                                                   float *restrict wq)
{
    const atrous_planes *g = &j->in;
    size_t q = (size_t)((ptrdiff_t)p + offset);
    float nw[ATROUS_RUN];
    normal_weights(j, p, offset, n, nw);
    const float *restrict zc = g->depth + p, *restrict zq = g->depth + q;
    const float *restrict sc = j->inv_z + p, *restrict sq = j->inv_z + q;
    const float *restrict lc = j->lum + p, *restrict lq = j->lum + q;
    const float *restrict ac0 = g->albedo[0] + p, *restrict aq0 = g->albedo[0] + q;
    const float *restrict ac1 = g->albedo[1] + p, *restrict aq1 = g->albedo[1] + q;
    const float *restrict ac2 = g->albedo[2] + p, *restrict aq2 = g->albedo[2] + q;
    const float *restrict cc0 = g->color[0] + p, *restrict cq0 = g->color[0] + q;
    const float *restrict cc1 = g->color[1] + p, *restrict cq1 = g->color[1] + q;
    const float *restrict cc2 = g->color[2] + p, *restrict cq2 = g->color[2] + q;
    float *restrict sum0 = j->out[0] + p, *restrict sum1 = j->out[1] + p,
                    *restrict sum2 = j->out[2] + p, *restrict wsum = j->wsum + p;
    const float inv_albedo = j->inv_albedo, inv_color = j->inv_color;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        float dz = fabsf(zc[i] - zq[i]);
        float a0 = ac0[i] - aq0[i], a1 = ac1[i] - aq1[i], a2 = ac2[i] - aq2[i];
        float albedo = (a0 * a0 + a1 * a1 + a2 * a2) * inv_albedo;
        float ep = dz * sc[i], eq = dz * sq[i];
        ep += albedo;
        eq += albedo;
        if (color) {
            float c0 = cc0[i] - cq0[i], c1 = cc1[i] - cq1[i], c2 = cc2[i] - cq2[i];
            float mean = 0.5f * (lc[i] + lq[i]) + DENOISE_LUM_EPS;
            float ec = (c0 * c0 + c1 * c1 + c2 * c2) * inv_color / (mean * mean);
            ep += ec;
            eq += ec;
        }
        float hit_c = zc[i] > 0.0f ? 1.0f : 0.0f, hit_q = zq[i] > 0.0f ? 1.0f : 0.0f;
        float keep = hit_c == hit_q ? 1.0f : 0.0f;
        float keep_q = eq <= DENOISE_EXP_CUTOFF ? keep : 0.0f;
        wq[i] = keep_q * wk * nw[i] * exp_neg(eq < DENOISE_EXP_CUTOFF ? eq : DENOISE_EXP_CUTOFF);
        if (mine) {
            float keep_p = ep <= DENOISE_EXP_CUTOFF ? keep : 0.0f;
            float w =
                keep_p * wk * nw[i] * exp_neg(ep < DENOISE_EXP_CUTOFF ? ep : DENOISE_EXP_CUTOFF);
            sum0[i] += w * cq0[i];
            sum1[i] += w * cq1[i];
            sum2[i] += w * cq2[i];
            wsum[i] += w;
        }
    }
}

// q's side of the pairs: pixels [q, q + n) take the colour of their neighbours `offset` away
// (p, a row above) with the weights wq.
static inline DRIFT_ALWAYS_INLINE void add_taken(const atrous_job *j, size_t q, ptrdiff_t offset,
                                                 int32_t n, const float *restrict wq)
{
    size_t p = (size_t)((ptrdiff_t)q + offset);
    const float *restrict cp0 = j->in.color[0] + p, *restrict cp1 = j->in.color[1] + p,
                          *restrict cp2 = j->in.color[2] + p;
    float *restrict sum0 = j->out[0] + q, *restrict sum1 = j->out[1] + q,
                    *restrict sum2 = j->out[2] + q, *restrict wsum = j->wsum + q;
    DRIFT_IVDEP
    for (int32_t i = 0; i < n; ++i) {
        sum0[i] += wq[i] * cp0[i];
        sum1[i] += wq[i] * cp1[i];
        sum2[i] += wq[i] * cp2[i];
        wsum[i] += wq[i];
    }
}

// The pixels [lo, hi) of the run at x0 whose neighbour `shift` pixels along lies in the row.
static bool tap_interval(int32_t w, int32_t x0, int32_t n, int32_t shift, int32_t *lo, int32_t *hi)
{
    *lo = -(x0 + shift) > 0 ? -(x0 + shift) : 0;
    *hi = w - x0 - shift < n ? w - x0 - shift : n;
    return *lo < *hi;
}

// The pairs of row y's run at x0 with row y + dy step below (dy > 0): with `mine`, the run's
// sums take them (dx ascending, the taps' order); the row below's sums take theirs where that
// row lies in [first_row, last_row), dx descending: each pixel there then takes its taps of
// this row from left to right over the runs, the taps' order again.
static inline DRIFT_ALWAYS_INLINE void pair_row(const atrous_job *j, bool color, bool mine,
                                                int32_t y, int32_t x0, int32_t n, int dy,
                                                int32_t first_row, int32_t last_row)
{
    const int32_t w = j->width, radius = j->radius;
    const float *kernel = radius == 1 ? b1 : b3;
    int32_t qy = y + dy * j->step;
    bool theirs = qy >= first_row && qy < last_row;
    if (qy >= j->height || (!mine && !theirs)) {
        return;
    }
    size_t p = (size_t)y * (size_t)w + (size_t)x0;
    float wq[5][ATROUS_RUN];
    int32_t lo[5], hi[5];
    for (int dx = -radius; dx <= radius; ++dx) {
        int32_t shift = dx * j->step;
        if (!tap_interval(w, x0, n, shift, &lo[dx + radius], &hi[dx + radius])) {
            continue;
        }
        ptrdiff_t offset = (ptrdiff_t)dy * j->step * w + shift;
        float wk = kernel[dx + radius] * kernel[dy + radius];
        int32_t l = lo[dx + radius];
        atrous_pair(j, color, mine, p + (size_t)l, offset, hi[dx + radius] - l, wk,
                    wq[dx + radius] + l);
    }
    if (!theirs) {
        return;
    }
    for (int dx = radius; dx >= -radius; --dx) {
        int32_t l = lo[dx + radius], h = hi[dx + radius];
        if (l < h) {
            ptrdiff_t offset = (ptrdiff_t)dy * j->step * w + dx * j->step;
            add_taken(j, (size_t)((ptrdiff_t)(p + (size_t)l) + offset), -offset, h - l,
                      wq[dx + radius] + l);
        }
    }
}

// Rows [y0, y1) of a band: each pixel's sum starts at its centre tap and takes its taps in
// the kernel's order, row above first: those of the rows above come from the pairs computed
// there (the band's own rows, or, above the band, pairs computed again for this band's side
// only), then the taps of its own row, then its side of the pairs with the rows below.
static inline DRIFT_ALWAYS_INLINE void atrous_band(const atrous_job *j, bool color, int32_t y0,
                                                   int32_t y1)
{
    const int32_t w = j->width, radius = j->radius;
    const float *kernel = radius == 1 ? b1 : b3;
    const float centre = kernel[radius] * kernel[radius];
    size_t begin = (size_t)y0 * (size_t)w, end = (size_t)y1 * (size_t)w;
    for (size_t i = begin; i < end; ++i) {
        j->out[0][i] = centre * j->in.color[0][i];
        j->out[1][i] = centre * j->in.color[1][i];
        j->out[2][i] = centre * j->in.color[2][i];
        j->wsum[i] = centre;
    }
    int32_t above = y0 - radius * j->step > 0 ? y0 - radius * j->step : 0;
    for (int32_t y = above; y < y0; ++y) {
        for (int32_t x0 = 0; x0 < w; x0 += ATROUS_RUN) {
            int32_t n = w - x0 < ATROUS_RUN ? w - x0 : ATROUS_RUN;
            for (int dy = 1; dy <= radius; ++dy) {
                pair_row(j, color, false, y, x0, n, dy, y0, y1);
            }
        }
    }
    for (int32_t y = y0; y < y1; ++y) {
        for (int32_t x0 = 0; x0 < w; x0 += ATROUS_RUN) {
            int32_t n = w - x0 < ATROUS_RUN ? w - x0 : ATROUS_RUN;
            size_t p = (size_t)y * (size_t)w + (size_t)x0;
            for (int dx = -radius; dx <= radius; ++dx) {
                int32_t lo, hi, shift = dx * j->step;
                if (dx != 0 && tap_interval(w, x0, n, shift, &lo, &hi)) {
                    atrous_tap(j, color, p + (size_t)lo, shift, hi - lo,
                               kernel[dx + radius] * kernel[radius]);
                }
            }
            for (int dy = 1; dy <= radius; ++dy) {
                pair_row(j, color, true, y, x0, n, dy, y0, y1);
            }
        }
        // Row y has all its taps. wsum >= the centre tap's weight, (3/8)^2 or (1/2)^2, > 0.
        size_t row = (size_t)y * (size_t)w;
        for (size_t i = row; i < row + (size_t)w; ++i) {
            j->out[0][i] /= j->wsum[i];
            j->out[1][i] /= j->wsum[i];
            j->out[2][i] /= j->wsum[i];
        }
    }
}

static DRIFT_AVX2_CLONES void atrous_bands(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const atrous_job *j = user;
    for (size_t b = begin; b < end; ++b) {
        int32_t y0 = (int32_t)b * j->band;
        int32_t y1 = y0 + j->band < j->height ? y0 + j->band : j->height;
        if (j->inv_color > 0.0f) {
            atrous_band(j, true, y0, y1);
        } else {
            atrous_band(j, false, y0, y1);
        }
    }
}

// Each pass's per-pixel terms: |luminance| of its colour and the depth weight's scale.
static DRIFT_AVX2_CLONES void atrous_pixel_terms(size_t begin, size_t end, int thread_index,
                                                 void *user)
{
    (void)thread_index;
    const atrous_job *j = user;
    size_t first = begin * (size_t)j->width, last = end * (size_t)j->width;
    const float *restrict c0 = j->in.color[0], *restrict c1 = j->in.color[1],
                          *restrict c2 = j->in.color[2], *restrict z = j->in.depth;
    float *restrict lum = j->lum, *restrict inv_z = j->inv_z;
    const float inv_depth = j->inv_depth;
    DRIFT_IVDEP
    for (size_t i = first; i < last; ++i) {
        lum[i] = fabsf(0.2126f * c0[i] + 0.7152f * c1[i] + 0.0722f * c2[i]);
        float zc = z[i] > 1e-30f ? z[i] : 1e-30f; // a miss (z = 0): see keep
        inv_z[i] = inv_depth / zc;
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
    // Planes: colour ping and pong (3 each), normal (3), albedo (3), depth, the weights' sum,
    // |luminance| and the depth scale; every one written before it is read. The context keeps
    // them for the next call (core/scratch.h): at 1080p their first touch cost as much as the
    // filter's arithmetic.
    size_t have = 0;
    float *block = drift__scratch_take(ctx, 16 * count * sizeof(float), &have);
    drift_result r = drift_image_create(ctx, w, h, 3, out);
    if (!block || r != DRIFT_OK) {
        drift__scratch_give(ctx, block, have);
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
    // One band a thread (bit-identical for any split: each pixel's sum takes the same taps in
    // the same order), or four where there are several, to balance them; a band is at least
    // 32 rows, as its pairs above it are computed again.
    int threads = drift_context_thread_count(ctx);
    int32_t bands = threads > 1 ? 4 * threads : 1;
    int32_t band = (h + bands - 1) / bands;
    band = band < 32 ? 32 : band;
    atrous_job job = { .width = w,
                       .wsum = block + 13 * count,
                       .lum = block + 14 * count,
                       .inv_z = block + 15 * count,
                       .band = band,
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
        drift_parallel_for(ctx, (size_t)h, 16, atrous_pixel_terms, &job);
        drift_parallel_for(ctx, (size_t)((h + band - 1) / band), 1, atrous_bands, &job);
        for (int k = 0; k < 3; ++k) {
            float *t = planes.color[k];
            planes.color[k] = pong[k];
            pong[k] = t;
        }
    }
    io.out = out;
    drift_parallel_for(ctx, (size_t)h, 8, image_from_planes, &io);
    drift__scratch_give(ctx, block, have);
    return DRIFT_OK;
}
