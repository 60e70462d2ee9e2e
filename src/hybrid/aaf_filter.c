// AAF's filter and sample budget, shared by soft shadows and indirect light: the separable
// Gaussian of eq. 3.7 (two 1-D passes, each with the centre pixel's beta), the exact 2-D
// filter of eq. 3.2 it approximates, and the split of an average spp target into a sparse
// pass plus adaptive counts in proportion to eq. 3.5 or 4.6.
#include "hybrid/aaf_internal.h"

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
    size_t adaptive = 0;
    for (size_t i = 0; i < count; ++i) {
        adaptive += want[i] > 0.0f;
    }
    // Pixels that get adaptive samples take at least half the target: eq. 3.5 and 4.6 peak
    // steeply (as 1/s2^4 near contact), and without a floor a few contact pixels took the
    // budget from every penumbra (the Breakfast Room's sun through the blinds). The floor
    // bounds the loss against uniform sampling by 2x in variance where n(x) is wrong.
    double lo = fmax((double)sparse, 0.5 * (double)spp);
    double hi = fmax((double)max_spp, lo);
    // What the adaptive pixels may spend: the whole budget less the sparse-only pixels.
    double budget = (double)spp * (double)active - (double)sparse * (double)(active - adaptive);
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
    for (size_t i = 0; i < count; ++i) {
        if (!(want[i] > 0.0f)) {
            counts[i] = sparse;
            continue;
        }
        double n = scale * (double)want[i];
        n = n < lo ? lo : (n > hi ? hi : n);
        // Randomised rounding keeps the expected total on budget.
        double u = (double)drift_u32_to_unit(drift_hash_combine(seed, (uint32_t)i));
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

// Whether a neighbour may share its samples with the centre: a surface like it (depth,
// normal) whose filter width is not too different (eq. 3.7 holds while beta varies slowly).
static bool accept(const filter_texel *centre, const filter_texel *n)
{
    if (n->depth < 0.0f || fabsf(n->depth - centre->depth) > DRIFT_AAF_DEPTH_TOLERANCE * centre->depth ||
        drift_vec3_dot(n->normal, centre->normal) < DRIFT_AAF_NORMAL_COS) {
        return false;
    }
    if (n->beta > 0.0f) {
        float ratio = n->beta > centre->beta ? n->beta / centre->beta : centre->beta / n->beta;
        return ratio <= DRIFT_AAF_BETA_RATIO;
    }
    return true;
}

static void filter_pixel(const filter_job *job, int32_t x, int32_t y)
{
    const drift_aaf_filter_desc *d = job->desc;
    int channels = job->in->channels;
    int32_t w = job->in->width, h = job->in->height;
    float *out = drift_image_pixel(job->out, x, y);
    const float *centre = drift_image_pixel(job->in, x, y);
    const filter_texel *c = &job->texels[(size_t)y * (size_t)w + (size_t)x];
    if (c->depth < 0.0f || !(c->beta > 0.0f)) {
        for (int k = 0; k < channels; ++k) {
            out[k] = centre[k];
        }
        return;
    }
    float footprint = drift_image_pixel(d->footprint, x, y)[0];
    float reach = footprint > 0.0f ? ceilf(3.0f * c->beta / footprint) : (float)d->max_radius;
    int32_t radius = reach < (float)d->max_radius ? (int32_t)reach : d->max_radius;
    float inv = -0.5f / (c->beta * c->beta);
    float sum[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    float weight = 0.0f;
    bool exact = job->dx == 0 && job->dy == 0;
    for (int32_t j = exact ? -radius : 0; j <= (exact ? radius : 0); ++j) {
        for (int32_t k = -radius; k <= radius; ++k) {
            int32_t nx = exact ? x + k : x + k * job->dx;
            int32_t ny = exact ? y + j : y + k * job->dy;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) {
                continue;
            }
            const filter_texel *n = &job->texels[(size_t)ny * (size_t)w + (size_t)nx];
            bool self = n == c;
            if (!self && !accept(c, n)) {
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
            job->texels[y * (size_t)job->width + (size_t)x] = (filter_texel){
                .position = drift_image_get3(&g->position, x, yy),
                .depth = surface ? drift_image_pixel(&g->depth, x, yy)[0] : -1.0f,
                .normal = drift_image_get3(&g->normal, x, yy),
                .beta = drift_image_pixel(job->desc->beta, x, yy)[0]
            };
        }
    }
}

static filter_texel *pack(drift_context *ctx, const drift_aaf_filter_desc *desc, int32_t width,
                          int32_t height)
{
    filter_texel *texels = drift_alloc(ctx, sizeof(filter_texel) * (size_t)width * (size_t)height);
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
    for (size_t y = begin; y < end; ++y) {
        for (int32_t x = 0; x < job->in->width; ++x) {
            filter_pixel(job, x, (int32_t)y);
        }
    }
}

static void run_filter(drift_context *ctx, filter_job *job)
{
    drift_parallel_for(ctx, (size_t)job->in->height, 4, filter_rows, job);
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
    drift_free(ctx, texels);
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
    drift_free(ctx, texels);
    return DRIFT_OK;
}
