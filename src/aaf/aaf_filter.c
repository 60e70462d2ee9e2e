// AAF's filter and sample budget, shared by soft shadows and indirect light: the separable
// Gaussian of eq. 3.7 (two 1-D passes, each with the centre pixel's beta), the exact 2-D
// filter of eq. 3.2 it approximates, and the split of an average spp target into a sparse
// pass plus adaptive counts in proportion to eq. 3.5 or 4.6.
#include "aaf/aaf.h"

#include <math.h>

float drift_aaf_beta_shrink(uint32_t spp, float from_spp, float exponent)
{
    // Bias of a Gaussian of width beta grows as beta^2 and its variance falls as
    // 1/(spp beta^2), so a width falling as a power of spp lets both vanish; past the rates
    // the paper's fixed beta was designed for, the width follows spp^-exponent.
    float s = (float)spp;
    return s <= from_spp ? 1.0f : powf(s / from_spp, -exponent);
}

float drift_aaf_pixel_footprint(const drift_camera *camera, int32_t image_height, float z)
{
    return z * 2.0f * tanf(0.5f * camera->fov_y) / (float)image_height;
}

uint32_t drift_aaf_sparse_count(uint32_t spp)
{
    uint32_t k = spp / 4;
    k = k < DRIFT_AAF_SPARSE_MIN ? DRIFT_AAF_SPARSE_MIN : k;
    return k < spp ? k : spp;
}

static double allocated(const float *want, size_t count, double scale, double lo, double hi)
{
    double total = 0.0;
    for (size_t i = 0; i < count; ++i) {
        if (want[i] > 0.0f) {
            double n = scale * (double)want[i];
            total += n < lo ? lo : (n > hi ? hi : n);
        }
    }
    return total;
}

void drift_aaf_allocate(const float *want, size_t count, size_t active, uint32_t sparse,
                        uint32_t spp, uint32_t max_spp, uint32_t seed, uint32_t *counts)
{
    size_t adaptive = 0, flat = 0;
    for (size_t i = 0; i < count; ++i) {
        adaptive += want[i] > 0.0f;
        flat += want[i] == 0.0f;
    }
    // Pixels that get adaptive samples take at least the target: eq. 3.5 and 4.6 peak steeply
    // (as 1/s2^4 near contact), and with a lower floor the contact pixels took the budget from
    // the other penumbra pixels. The adaptive pass then only moves to them what the flat pixels
    // (exactly lit or hidden) do not need. With half the target as the floor, the Breakfast
    // Room's sun through the blinds (penumbra over 60% of the image, few flat pixels) left
    // 11645 of its 19200 pixels at 2 samples of 4 and AAF at 0.39x of uniform sampling.
    double lo = (double)spp; // never under `sparse`: the counts are held at it below
    double hi = fmax((double)max_spp, lo);
    // What the adaptive pixels may spend: the whole budget less the sparse-only pixels.
    double budget = (double)spp * (double)active - (double)sparse * (double)(active - adaptive);
    // And at least DRIFT_AAF_FLOOR_SHARE of the adaptive pixels' mean: where flat pixels are
    // many, that mean is far above the target, and n(x) alone (from the neighbours' few sparse
    // rays at low spp) gave the open glossy room's dragon at 4 spp 488 pixels 39 samples or more
    // while 233 penumbra pixels kept 4 and held half the error. n(x) places the rest.
    if (adaptive > 0) {
        lo = fmax(lo, DRIFT_AAF_FLOOR_SHARE * budget / (double)adaptive);
        hi = fmax(hi, lo);
    }
    // When the adaptive pixels cannot spend the budget under the cap (few pixels in penumbra,
    // a small light), the cap doubles until they can, up to 8 times: samples at contact edges
    // lower the error, samples in flat pixels (exactly 0 or 1 already) hardly do.
    for (int k = 0; k < 3 && adaptive > 0 && hi * (double)adaptive < budget; ++k) {
        hi *= 2.0;
    }
    double scale = 0.0;
    if (adaptive > 0 && budget <= lo * (double)adaptive) {
        lo = budget / (double)adaptive; // the floor is all there is: spread the budget evenly
    } else if (adaptive > 0 && hi > lo) {
        double a = 0.0, b = 1.0;
        while (allocated(want, count, b, lo, hi) < budget && b < 1e30) {
            b *= 2.0;
        }
        for (int k = 0; k < 60; ++k) {
            double m = 0.5 * (a + b);
            if (allocated(want, count, m, lo, hi) < budget) {
                a = m;
            } else {
                b = m;
            }
        }
        scale = b;
    }
    // What the adaptive pixels cannot take even so (none, or very few, in penumbra) goes to the
    // flat ones, evenly, so the mean stays the budget.
    double left = budget - (adaptive > 0 ? allocated(want, count, scale, lo, hi) : 0.0);
    double extra = flat > 0 && left > 0.0 ? left / (double)flat : 0.0;
    for (size_t i = 0; i < count; ++i) {
        // Randomised rounding keeps the expected total on budget.
        double u = (double)drift_u32_to_unit(drift_hash_combine(seed, (uint32_t)i));
        if (!(want[i] > 0.0f)) {
            counts[i] = sparse + (want[i] == 0.0f ? (uint32_t)floor(extra + u) : 0u);
            continue;
        }
        double n = scale * (double)want[i];
        n = n < lo ? lo : (n > hi ? hi : n);
        counts[i] = (uint32_t)floor(n + u);
        counts[i] = counts[i] > (uint32_t)hi ? (uint32_t)hi : counts[i];
        counts[i] = counts[i] < sparse ? sparse : counts[i];
    }
}

// --- THE FILTER ---

// What the filter reads of a pixel, packed so a tap touches one cache line, not six planes.
typedef struct filter_texel {
    drift_vec3 position;
    float depth; // negative: no surface
    drift_vec3 normal;
    float beta;
} filter_texel;

typedef struct filter_job {
    const drift_aaf_filter_desc *desc;
    const filter_texel *texels;
    const drift_image *in;
    drift_image *out;
    int dx, dy; // the 1-D pass's step; both 0 for the exact 2-D filter
} filter_job;

static float distance_sq(const drift_aaf_filter_desc *d, drift_vec3 a, drift_vec3 b)
{
    drift_vec3 v = drift_vec3_sub(b, a);
    if (d->has_axis) {
        v = drift_vec3_sub(v, drift_vec3_scale(d->axis, drift_vec3_dot(v, d->axis)));
    }
    return drift_vec3_dot(v, v);
}

// The centre's tests, precomputed once for all its taps.
typedef struct centre_tests {
    float depth, depth_tolerance;
    drift_vec3 normal;
    float beta_low, beta_high;
} centre_tests;

static centre_tests centre_tests_make(const filter_texel *c)
{
    return (centre_tests){ .depth = c->depth,
                           .depth_tolerance = DRIFT_AAF_DEPTH_TOLERANCE * c->depth,
                           .normal = c->normal,
                           .beta_low = c->beta / DRIFT_AAF_BETA_RATIO,
                           .beta_high = c->beta * DRIFT_AAF_BETA_RATIO };
}

// Whether a neighbour may share its samples with the centre: a surface like it (depth,
// normal) whose filter width is not too different (eq. 3.7 holds while beta varies slowly).
// The beta ratio test is max(a, b) / min(a, b) <= ratio, written without the division.
static bool accept(const centre_tests *c, const filter_texel *n)
{
    if (n->depth < 0.0f || fabsf(n->depth - c->depth) > c->depth_tolerance ||
        drift_vec3_dot(n->normal, c->normal) < DRIFT_AAF_NORMAL_COS) {
        return false;
    }
    return !(n->beta > 0.0f) || (n->beta <= c->beta_high && n->beta >= c->beta_low);
}

static int32_t filter_radius(const drift_aaf_filter_desc *d, const filter_texel *c, float footprint)
{
    float reach = footprint > 0.0f ? ceilf(3.0f * c->beta / footprint) : (float)d->max_radius;
    return reach < (float)d->max_radius ? (int32_t)reach : d->max_radius;
}

static bool filtered(const filter_texel *c)
{
    return c->depth >= 0.0f && c->beta > 0.0f;
}

static void copy_pixel(const float *in, float *out, int channels)
{
    for (int k = 0; k < channels; ++k) {
        out[k] = in[k];
    }
}

// The exact 2-D filter (eq. 3.2) at one pixel.
static void filter_pixel_exact(const filter_job *job, int32_t x, int32_t y)
{
    const drift_aaf_filter_desc *d = job->desc;
    int channels = job->in->channels;
    int32_t w = job->in->width, h = job->in->height;
    float *out = drift_image_pixel(job->out, x, y);
    const filter_texel *c = &job->texels[(size_t)y * (size_t)w + (size_t)x];
    if (!filtered(c)) {
        copy_pixel(drift_image_pixel(job->in, x, y), out, channels);
        return;
    }
    int32_t radius = filter_radius(d, c, drift_image_pixel(d->footprint, x, y)[0]);
    centre_tests tests = centre_tests_make(c);
    float inv = -0.5f / (c->beta * c->beta);
    float sum[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    float weight = 0.0f;
    for (int32_t ny = y - radius; ny <= y + radius; ++ny) {
        for (int32_t nx = x - radius; nx <= x + radius; ++nx) {
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) {
                continue;
            }
            const filter_texel *n = &job->texels[(size_t)ny * (size_t)w + (size_t)nx];
            bool self = n == c;
            if (!self && !accept(&tests, n)) {
                continue;
            }
            float wk = self ? 1.0f : expf(inv * distance_sq(d, c->position, n->position));
            const float *v = drift_image_pixel(job->in, nx, ny);
            for (int m = 0; m < channels; ++m) {
                sum[m] += wk * v[m];
            }
            weight += wk;
        }
    }
    for (int m = 0; m < channels; ++m) {
        out[m] = sum[m] / weight;
    }
}

// One pixel of a 1-D pass (eq. 3.3 along dx, dy) for an image of `channels` channels (a
// constant where it is inlined, so the sums stay in registers): the taps are clamped to the
// image once and walked by pointer steps, so the loop holds only the tests and the Gaussian.
// The sums run in the same order as the exact filter's, so the output is that of a plain loop.
static inline void filter_pixel_line_n(const filter_job *job, int32_t x, int32_t y,
                                       const int channels)
{
    const drift_aaf_filter_desc *d = job->desc;
    const int32_t w = job->in->width;
    const filter_texel *c = &job->texels[(size_t)y * (size_t)w + (size_t)x];
    const float *centre = drift_image_pixel(job->in, x, y);
    float *out = drift_image_pixel(job->out, x, y);
    if (!filtered(c)) {
        copy_pixel(centre, out, channels);
        return;
    }
    int32_t radius = filter_radius(d, c, drift_image_pixel(d->footprint, x, y)[0]);
    int32_t at = job->dx ? x : y, last = (job->dx ? w : job->in->height) - 1 - at;
    int32_t lo = at < radius ? -at : -radius, hi = last < radius ? last : radius;
    ptrdiff_t texel_step = job->dx ? 1 : (ptrdiff_t)w;
    ptrdiff_t value_step = job->dx ? (ptrdiff_t)channels : job->in->stride;
    centre_tests tests = centre_tests_make(c);
    const drift_aaf_filter_desc axis = { .has_axis = d->has_axis, .axis = d->axis };
    const drift_vec3 p = c->position;
    float inv = -0.5f / (c->beta * c->beta);
    float sum[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    float weight = 0.0f;
    const filter_texel *n = c + lo * texel_step;
    const float *v = centre + lo * value_step;
    for (int32_t k = lo; k <= hi; ++k, n += texel_step, v += value_step) {
        float wk = 1.0f;
        if (k != 0) {
            if (!accept(&tests, n)) {
                continue;
            }
            wk = expf(inv * distance_sq(&axis, p, n->position));
        }
        for (int m = 0; m < channels; ++m) {
            sum[m] += wk * v[m];
        }
        weight += wk;
    }
    for (int m = 0; m < channels; ++m) {
        out[m] = sum[m] / weight;
    }
}

static void filter_pixel_line(const filter_job *job, int32_t x, int32_t y)
{
    switch (job->in->channels) {
    case 1:
        filter_pixel_line_n(job, x, y, 1);
        break;
    case 3:
        filter_pixel_line_n(job, x, y, 3);
        break;
    default:
        filter_pixel_line_n(job, x, y, job->in->channels);
        break;
    }
}

typedef struct pack_job {
    const drift_aaf_filter_desc *desc;
    filter_texel *texels;
    int32_t width;
} pack_job;

static void pack_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const pack_job *job = user;
    const drift_gbuffer *g = job->desc->gbuffer;
    for (size_t y = begin; y < end; ++y) {
        for (int32_t x = 0; x < job->width; ++x) {
            int32_t yy = (int32_t)y;
            bool surface = drift_image_pixel(&g->material_id, x, yy)[0] >= 0.0f;
            job->texels[y * (size_t)job->width + (size_t)x] =
                (filter_texel){ .position = drift_image_get3(&g->position, x, yy),
                                .depth = surface ? drift_image_pixel(&g->depth, x, yy)[0] : -1.0f,
                                .normal = drift_image_get3(&g->normal, x, yy),
                                .beta = drift_image_pixel(job->desc->beta, x, yy)[0] };
        }
    }
}

size_t drift_aaf_filter_workspace_bytes(int32_t width, int32_t height)
{
    return sizeof(filter_texel) * (size_t)width * (size_t)height;
}

// The packed inputs, in the caller's workspace when it gives one (no allocation, no page
// faults per call), else in a buffer of the filter's own.
static filter_texel *pack(drift_context *ctx, const drift_aaf_filter_desc *desc, int32_t width,
                          int32_t height)
{
    filter_texel *texels = desc->workspace
                               ? desc->workspace
                               : drift_alloc(ctx, drift_aaf_filter_workspace_bytes(width, height));
    if (texels) {
        pack_job job = { desc, texels, width };
        drift_parallel_for(ctx, (size_t)height, 8, pack_rows, &job);
    }
    return texels;
}

static void filter_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const filter_job *job = user;
    bool exact = job->dx == 0 && job->dy == 0;
    for (size_t y = begin; y < end; ++y) {
        for (int32_t x = 0; x < job->in->width; ++x) {
            if (exact) {
                filter_pixel_exact(job, x, (int32_t)y);
            } else {
                filter_pixel_line(job, x, (int32_t)y);
            }
        }
    }
}

// The vertical pass by strips of columns: a strip's taps (2 radius + 1 rows of a few
// columns) stay in the cache while the strip walks down, where whole rows would not.
#define FILTER_STRIP 16

static void filter_strips(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const filter_job *job = user;
    for (size_t s = begin; s < end; ++s) {
        int32_t x0 = (int32_t)s * FILTER_STRIP;
        int32_t x1 = x0 + FILTER_STRIP < job->in->width ? x0 + FILTER_STRIP : job->in->width;
        for (int32_t y = 0; y < job->in->height; ++y) {
            for (int32_t x = x0; x < x1; ++x) {
                filter_pixel_line(job, x, y);
            }
        }
    }
}

static void run_filter(drift_context *ctx, filter_job *job)
{
    if (job->dy) {
        size_t strips = ((size_t)job->in->width + FILTER_STRIP - 1) / FILTER_STRIP;
        drift_parallel_for(ctx, strips, 1, filter_strips, job);
    } else {
        drift_parallel_for(ctx, (size_t)job->in->height, 4, filter_rows, job);
    }
}

drift_result drift_aaf_filter_separable(drift_context *ctx, const drift_aaf_filter_desc *desc,
                                        const drift_image *in, drift_image *scratch,
                                        drift_image *out)
{
    filter_texel *texels = pack(ctx, desc, in->width, in->height);
    if (!texels) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    filter_job job = { .desc = desc, .texels = texels, .in = in, .out = scratch, .dx = 1 };
    run_filter(ctx, &job);
    job = (filter_job){ .desc = desc, .texels = texels, .in = scratch, .out = out, .dy = 1 };
    run_filter(ctx, &job);
    if (texels != desc->workspace) {
        drift_free(ctx, texels);
    }
    return DRIFT_OK;
}

drift_result drift_aaf_filter_exact(drift_context *ctx, const drift_aaf_filter_desc *desc,
                                    const drift_image *in, drift_image *out)
{
    filter_texel *texels = pack(ctx, desc, in->width, in->height);
    if (!texels) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    filter_job job = { .desc = desc, .texels = texels, .in = in, .out = out };
    run_filter(ctx, &job);
    if (texels != desc->workspace) {
        drift_free(ctx, texels);
    }
    return DRIFT_OK;
}
