// AAF indirect light (Mehta, Wang, Ramamoorthi 2013; docs/aaf.md) for one lobe of the first
// bounce: the diffuse lobe here (--indirect aaf, the frame's I term) and the glossy lobe in
// aaf_specular.c (--reflections aaf, R), each in its own buffers, filtered apart (sec. 4.3),
// path-traced per pixel and filtered in world space:
//   1. sparse: a few rays sampled from the lobe; the hit distances of the neighbours' rays
//      give z_min and z_max (escaped rays count as infinitely far), which set beta (eq. 4.4,
//      with the lobe's Omega_h^max of eq. 4.5) and n(x) (eq. 4.6);
//   2. adaptive: the --spp budget spread in proportion to n(x), capped at aaf_max_spp;
//   3. the separable filter on the estimate divided by the lobe's albedo (so texture is not
//      blurred), then multiplied back by the albedo.
// Each sample is one bounce (max_depth 2, the reference's default) or more (max_depth 3:
// two bounces), with next-event estimation at every vertex after the first: emission that a
// bounce ray meets is direct light, which the frame computes apart (shadows technique),
// except along a mirror's sharp ray (aaf_specular.c), where it is R's.
#include "aaf/aaf.h"

#include <math.h>

typedef struct indirect_job {
    const drift_aaf_lobe *lobe;
    uint32_t key;
    uint32_t sparse;
    float shrink;
    bool uniform;
    bool random;
    int32_t bounces;
} indirect_job;

static size_t pixel_index(const drift_frame_state *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

// Direct light leaving surface y toward wo: one sample of every light and of the environment,
// each with its shadow ray.
static drift_vec3 next_event(drift_frame_state *f, const drift_surface *y, const drift_bsdf *bsdf,
                             drift_vec3 wo, drift_aaf_sampler *sampler, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    uint32_t count = f->light_count + (drift_scene_has_environment(f->scene) ? 1u : 0u);
    for (uint32_t l = 0; l < count; ++l) {
        float pick = drift_aaf_next1(sampler);
        drift_vec2 u = drift_aaf_next2(sampler);
        drift_light_sample ls =
            l < f->light_count
                ? drift_raster_light_sample(f->scene, &f->lights[l], y->position, pick, u)
                : drift_environment_sample(f->scene, u);
        if (!(ls.pdf > 0.0f) || drift_vec3_is_zero(ls.radiance)) {
            continue;
        }
        drift_vec3 fr = drift_bsdf_eval(bsdf, wo, ls.wi);
        float cos_i = fabsf(drift_vec3_dot(ls.wi, y->ns));
        drift_vec3 c = drift_vec3_scale(drift_vec3_mul(fr, ls.radiance), cos_i / ls.pdf);
        if (drift_vec3_is_zero(c) || !drift_vec3_is_finite(c)) {
            continue;
        }
        drift_ray shadow = { .origin = drift_offset_origin(y->position, y->ng, ls.wi),
                             .dir = ls.wi,
                             .tmin = 0.0f,
                             .tmax =
                                 isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        ++*rays;
        if (!drift_accel_occluded(f->accel, &shadow)) {
            sum = drift_vec3_add(sum, c);
        }
    }
    return sum;
}

// Radiance arriving at the pixel's surface along one direction sampled from the lobe, times
// the sample's weight over the albedo. *out_distance: the first hit, INFINITY for none.
static drift_vec3 trace_path(drift_frame_state *f, const indirect_job *job, const drift_surface *s,
                             const drift_bsdf *first, drift_vec3 wo, drift_aaf_sampler *sampler,
                             float *out_distance, uint64_t *rays)
{
    *out_distance = INFINITY;
    drift_vec3 total = drift_vec3_splat(0.0f);
    drift_vec3 dir;
    float weight;
    bool emission;
    job->lobe->sample(first, wo, drift_aaf_next2(sampler), &dir, &weight, &emission);
    if (!(weight > 0.0f) || !(drift_vec3_dot(dir, s->ng) > 0.0f)) {
        return total; // below the geometric surface: no light arrives this way
    }
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    drift_vec3 throughput = drift_vec3_splat(weight);
    for (int32_t bounce = 0; bounce < job->bounces; ++bounce) {
        drift_hit hit;
        ++*rays;
        bool seen = bounce == 0 && emission;
        if (!drift_accel_intersect(f->accel, &ray, &hit)) {
            // The environment seen by a bounce ray is direct light (or was NEE's), but a
            // mirror's.
            if (seen && drift_scene_has_environment(f->scene)) {
                total = drift_vec3_mul(throughput, drift_environment_eval(f->scene, ray.dir));
            }
            break;
        }
        if (bounce == 0) {
            *out_distance = hit.t;
        }
        drift_surface y = drift_scene_surface(f->scene, &ray, &hit);
        if (seen) {
            total = drift_vec3_add(total, drift_vec3_mul(throughput, y.emission));
        }
        if (y.material == DRIFT_INVALID_INDEX) {
            break; // a light's shape: its emission is counted by next-event estimation
        }
        drift_bsdf bsdf = drift_bsdf_make(f->scene, &y);
        drift_vec3 wo_y = drift_vec3_neg(ray.dir);
        total = drift_vec3_add(
            total, drift_vec3_mul(throughput, next_event(f, &y, &bsdf, wo_y, sampler, rays)));
        if (bounce + 1 == job->bounces) {
            break;
        }
        float u_lobe = drift_aaf_next1(sampler);
        drift_bsdf_sample bs = drift_bsdf_sample_wi(&bsdf, wo_y, u_lobe, drift_aaf_next2(sampler));
        if (!(bs.pdf > 0.0f) || bs.is_delta) {
            break; // after a mirror only emission would follow; NEE has none to add
        }
        throughput = drift_vec3_mul(throughput, bs.weight);
        ray = (drift_ray){ .origin = drift_offset_origin(y.position, y.ng, bs.wi),
                           .dir = bs.wi,
                           .tmin = 0.0f,
                           .tmax = INFINITY };
    }
    return drift_vec3_is_finite(total) ? total : drift_vec3_splat(0.0f);
}

// Running sums a pixel keeps between the passes, in state->aux and the lobe's radiance.
// lum_sq: the samples' squared luminance, summed (the denoiser's variance, --aaf-denoise).
typedef struct indirect_sums {
    float z_min, z_max, count, has_lobe, lum_sq;
} indirect_sums;

// Whether the pixel has the job's lobe, with its albedo and Omega_h^max.
static bool lobe_at(const drift_frame_state *f, const indirect_job *job, int32_t x, int32_t y,
                    drift_vec3 *albedo, float *omega)
{
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    if (s->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    return job->lobe->at(&bsdf, drift_pass_wo(f, x, y), albedo, omega);
}

static void add_samples(drift_frame_state *f, const indirect_job *job, int32_t x, int32_t y,
                        uint32_t first, uint32_t end, uint64_t *rays)
{
    size_t i = pixel_index(f, x, y);
    const drift_surface *s = &f->gbuffer.surfaces[i];
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    drift_vec3 wo = drift_pass_wo(f, x, y);
    // Reflection edits re-aim the glossy and mirror lobes (the diffuse one does not change).
    drift_reflection_edits_aim_bsdf(f->params.reflection_edits, s, wo, &bsdf);
    indirect_sums *sums = (indirect_sums *)&drift_aaf_of(f)->aux[DRIFT_AAF_AUX * i];
    float *radiance = drift_image_pixel(&job->lobe->buffers->radiance, x, y);
    drift_vec3 sum =
        drift_vec3_scale(drift_vec3_make(radiance[0], radiance[1], radiance[2]), sums->count);
    for (uint32_t k = first; k < end; ++k) {
        drift_aaf_sampler sampler = drift_aaf_sampler_make(job->key, (uint32_t)i, k, job->random);
        float distance;
        drift_vec3 sample = trace_path(f, job, s, &bsdf, wo, &sampler, &distance, rays);
        float lum = drift_luminance(sample);
        sum = drift_vec3_add(sum, sample);
        sums->lum_sq += lum * lum;
        if (isfinite(distance)) {
            sums->z_min = fminf(sums->z_min, distance);
            sums->z_max = fmaxf(sums->z_max, distance);
        }
    }
    sums->count = (float)end;
    drift_vec3 mean = end > 0 ? drift_vec3_scale(sum, 1.0f / (float)end) : sum;
    radiance[0] = mean.x;
    radiance[1] = mean.y;
    radiance[2] = mean.z;
}

float drift_aaf_indirect_beta(float z_min, float footprint, float omega, float pixel_width)
{
    return fmaxf(2.0f * z_min / omega, pixel_width * footprint);
}

float drift_aaf_omega_specular(float phong_exponent)
{
    return 3.6f + 0.084f * (4.0f * phong_exponent);
}

static void sparse_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const indirect_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    drift_aaf_lobe_buffers *b = job->lobe->buffers;
    size_t i = pixel_index(f, x, y);
    indirect_sums *sums = (indirect_sums *)&st->aux[DRIFT_AAF_AUX * i];
    *sums = (indirect_sums){ INFINITY, 0.0f, 0.0f, 0.0f, 0.0f };
    drift_image_set3(&b->radiance, x, y, drift_vec3_splat(0.0f));
    drift_image_pixel(&b->beta, x, y)[0] = 0.0f;
    st->want[i] = -1.0f; // outside the budget
    drift_vec3 albedo;
    float omega;
    if (!lobe_at(f, job, x, y, &albedo, &omega)) {
        return;
    }
    st->want[i] = 0.0f; // set by rates_pixel; a mirror keeps its sparse samples
    sums->has_lobe = 1.0f;
    add_samples(f, job, x, y, 0, job->uniform ? f->params.spp : job->sparse, rays);
}

// z_min and z_max of the pixel for eq. 4.4 and 4.6: the means of its neighbours' (on the same
// surface, within DRIFT_AAF_DILATE pixels; the pixel's own left out). Taking a pixel's own
// sparse distances made beta and n(x) functions of the very samples they filter: in an open
// scene a pixel whose few rays all escaped (an estimate of 0) got no filter and no adaptive
// samples, one whose rays met the near plant got more, and the frame came out 23-28% dark
// (issue 17). From the neighbours, beta and n(x) hardly depend on the pixel's own estimate,
// so the adaptive pass and the filter stay unbiased. Escaped rays count as infinitely far:
// returns false when no neighbour's ray hit anything (the pixel is open to the sky, whose
// light, the environment, reaches this term only through next-event estimation later on:
// low frequency, filtered at the widest width).
static bool neighbour_distances(const drift_frame_state *f, int32_t x, int32_t y, float *z_min,
                                float *z_max)
{
    const drift_aaf_state *st = drift_aaf_of(f);
    const drift_gbuffer *g = &f->gbuffer;
    float depth = drift_image_pixel(&g->depth, x, y)[0];
    drift_vec3 normal = drift_image_get3(&g->normal, x, y);
    float sum_min = 0.0f, sum_max = 0.0f;
    int32_t count = 0;
    for (int32_t ny = y - DRIFT_AAF_DILATE; ny <= y + DRIFT_AAF_DILATE; ++ny) {
        for (int32_t nx = x - DRIFT_AAF_DILATE; nx <= x + DRIFT_AAF_DILATE; ++nx) {
            if (nx < 0 || ny < 0 || nx >= f->params.width || ny >= f->params.height ||
                (nx == x && ny == y)) {
                continue;
            }
            const indirect_sums *n =
                (const indirect_sums *)&st->aux[DRIFT_AAF_AUX * pixel_index(f, nx, ny)];
            if (!(n->has_lobe > 0.0f) || !isfinite(n->z_min) ||
                fabsf(drift_image_pixel(&g->depth, nx, ny)[0] - depth) >
                    DRIFT_AAF_DEPTH_TOLERANCE * depth ||
                drift_vec3_dot(drift_image_get3(&g->normal, nx, ny), normal) <
                    DRIFT_AAF_NORMAL_COS) {
                continue;
            }
            sum_min += n->z_min;
            sum_max += n->z_max;
            ++count;
        }
    }
    if (count == 0) {
        return false;
    }
    *z_min = fmaxf(sum_min / (float)count, 1e-4f);
    *z_max = fmaxf(sum_max / (float)count, *z_min);
    return true;
}

// beta (eq. 4.4) and n(x) (eq. 4.6) from the neighbours' sparse distances.
static void rates_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const indirect_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    size_t i = pixel_index(f, x, y);
    drift_vec3 albedo;
    float omega;
    if (!(((const indirect_sums *)&st->aux[DRIFT_AAF_AUX * i])->has_lobe > 0.0f) ||
        !lobe_at(f, job, x, y, &albedo, &omega) || !(omega > 0.0f)) {
        return; // no lobe, or a mirror: nothing to filter
    }
    float d = drift_image_pixel(&st->footprint, x, y)[0];
    float z_min, z_max, beta;
    if (neighbour_distances(f, x, y, &z_min, &z_max)) {
        beta = drift_aaf_indirect_beta(z_min, d, omega, job->lobe->pixel_width);
        // eq. 4.6 with sqrt(A_p) = d.
        float a = 0.9f * omega * d / z_min + 0.3f;
        float c = 1.0f + 0.9f * z_max / z_min;
        st->want[i] = fmaxf(0.4f * a * a * omega * omega * c * c, 1e-3f);
    } else {
        // Open: eq. 4.4 as z_min grows without bound, held to the filter's widest reach.
        beta = fmaxf(job->lobe->pixel_width, (float)DRIFT_AAF_MAX_RADIUS / 3.0f) * d;
        st->want[i] = 1e-3f;
    }
    drift_image_pixel(&job->lobe->buffers->beta, x, y)[0] = beta * job->shrink;
}

static void adaptive_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const indirect_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    size_t i = pixel_index(f, x, y);
    // The sparse pass recorded whether the pixel has the lobe.
    bool has = ((const indirect_sums *)&st->aux[DRIFT_AAF_AUX * i])->has_lobe > 0.0f;
    uint32_t taken = job->uniform ? f->params.spp : job->sparse;
    uint32_t n = job->uniform ? taken : st->counts[i];
    if (has && n > taken) {
        add_samples(f, job, x, y, taken, n, rays);
    }
    drift_image_pixel(&job->lobe->buffers->spp, x, y)[0] =
        has ? (float)(n > taken ? n : taken) : 0.0f;
}

// The variance of the pixel's mean luminance from its samples, into scratch1.
static void variance_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    drift_aaf_state *st = drift_aaf_of(f);
    const drift_aaf_lobe *lobe = ((const indirect_job *)user)->lobe;
    const indirect_sums *sums =
        (const indirect_sums *)&st->aux[DRIFT_AAF_AUX * pixel_index(f, x, y)];
    float n = sums->count, mean = drift_luminance(drift_image_get3(&lobe->buffers->radiance, x, y));
    float var = n > 1.0f ? fmaxf(sums->lum_sq / n - mean * mean, 0.0f) / (n - 1.0f) : 0.0f;
    drift_image_pixel(&st->scratch1, x, y)[0] = var;
}

// b->filtered from b->radiance: AAF's filter, or (--aaf-denoise) the denoiser instead of it
// or before it.
static drift_result filter_lobe(drift_frame_state *f, indirect_job *job)
{
    drift_aaf_state *st = drift_aaf_of(f);
    drift_aaf_lobe_buffers *b = job->lobe->buffers;
    drift_aaf_denoise mode = f->params.aaf.denoise;
    bool aaf_filter = !f->params.aaf.unfiltered && mode != DRIFT_AAF_DENOISE_ON;
    const drift_image *in = &b->radiance;
    drift_image denoised = { 0 }; // with both: the denoiser's output, AAF's filter's input
    drift_result r = DRIFT_OK;
    if (mode != DRIFT_AAF_DENOISE_OFF) {
        drift_pass_for_each_pixel(f, variance_pixel, job);
        if (aaf_filter) {
            r = drift_image_create(f->ctx, f->params.width, f->params.height, 3, &denoised);
        }
        drift_image *to = aaf_filter ? &denoised : &b->filtered;
        if (r == DRIFT_OK) {
            r = drift_aaf_denoise_estimate(f, in, &st->scratch1, to);
        }
        in = to;
    }
    if (r == DRIFT_OK && aaf_filter) {
        drift_aaf_filter_desc desc = { .beta = &b->beta,
                                       .footprint = &st->footprint,
                                       .gbuffer = &f->gbuffer,
                                       .max_radius = DRIFT_AAF_MAX_RADIUS,
                                       .workspace = st->filter_workspace };
        r = drift_aaf_filter_separable(f->ctx, &desc, in, &st->scratch3, &b->filtered);
    } else if (r == DRIFT_OK && in != &b->filtered) {
        drift_pass_copy_rgb(in, &b->filtered);
    }
    drift_image_destroy(f->ctx, &denoised);
    return r;
}

static void modulate_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const indirect_job *job = user;
    drift_aaf_lobe_buffers *b = job->lobe->buffers;
    drift_vec3 albedo;
    float omega;
    if (!lobe_at(f, job, x, y, &albedo, &omega)) {
        albedo = drift_vec3_splat(0.0f);
    }
    drift_image_set3(&b->unfiltered, x, y,
                     drift_vec3_mul(albedo, drift_image_get3(&b->radiance, x, y)));
    drift_image_set3(job->lobe->out, x, y,
                     drift_vec3_mul(albedo, drift_image_get3(&b->filtered, x, y)));
}

drift_result drift_aaf_lobe_pass(drift_frame_state *f, const drift_aaf_lobe *lobe)
{
    drift_result r = drift_aaf_prepare(f, NULL);
    if (r == DRIFT_OK) {
        r = drift_aaf_lobe_buffers_ensure(f->ctx, lobe->buffers, f->params.width, f->params.height);
    }
    if (r != DRIFT_OK) {
        return r;
    }
    drift_aaf_state *st = drift_aaf_of(f);
    drift_aaf_lobe_buffers *b = lobe->buffers;
    drift_hybrid_stats *stats = &f->stats;
    size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    indirect_job job = { .lobe = lobe,
                         .key = drift_hash_combine(f->params.seed, lobe->stream),
                         .sparse = drift_aaf_sparse_count(f->params.spp),
                         .shrink = drift_aaf_beta_shrink(f->params.spp, lobe->shrink_from_spp,
                                                         lobe->shrink_exponent),
                         .uniform = f->params.aaf.uniform,
                         .random = f->params.aaf.random,
                         .bounces = f->params.max_depth - 1 };
    double t = drift_time_now();
    if (job.bounces > 0) {
        stats->rays[DRIFT_PASS_AAF_SAMPLING] += drift_pass_for_each_pixel(f, sparse_pixel, &job);
        drift_pass_for_each_pixel(f, rates_pixel, &job);
        // The average --spp is over the pixels that have the lobe: a glossy floor in a diffuse
        // room must not receive the budget of every diffuse pixel.
        size_t active = 0;
        for (size_t i = 0; i < pixels; ++i) {
            active += ((const indirect_sums *)&st->aux[DRIFT_AAF_AUX * i])->has_lobe > 0.0f;
        }
        if (!job.uniform) {
            drift_aaf_allocate(st->want, pixels, active, job.sparse, f->params.spp,
                               f->params.aaf.max_spp, job.key, st->counts);
        }
        stats->rays[DRIFT_PASS_AAF_SAMPLING] += drift_pass_for_each_pixel(f, adaptive_pixel, &job);
    } else {
        for (int32_t y = 0; y < f->params.height; ++y) {
            for (int32_t x = 0; x < f->params.width; ++x) {
                drift_image_set3(&b->radiance, x, y, drift_vec3_splat(0.0f));
                drift_image_pixel(&b->beta, x, y)[0] = 0.0f;
                drift_image_pixel(&b->spp, x, y)[0] = 0.0f;
            }
        }
    }
    stats->ms[DRIFT_PASS_AAF_SAMPLING] += 1000.0 * (drift_time_now() - t);

    t = drift_time_now();
    r = filter_lobe(f, &job);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_pass_for_each_pixel(f, modulate_pixel, &job);
    stats->ms[DRIFT_PASS_AAF_FILTER] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}

// --- THE DIFFUSE LOBE (--indirect aaf) ---

static bool diffuse_at(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 *albedo, float *omega)
{
    (void)wo;
    *albedo = bsdf->diffuse;
    *omega = DRIFT_AAF_OMEGA_DIFFUSE;
    return !drift_bsdf_is_delta(bsdf) && !drift_vec3_is_zero(bsdf->diffuse);
}

// Cosine-weighted: f cos / (pdf albedo) = 1.
static void diffuse_sample(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec2 u, drift_vec3 *wi,
                           float *weight, bool *emission)
{
    (void)wo;
    *wi = drift_frame_to_world(&bsdf->frame, drift_sample_cosine_hemisphere(u));
    *weight = 1.0f;
    *emission = false;
}

drift_result drift_aaf_pass_indirect(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    drift_result r = drift_aaf_state_ensure(f);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_aaf_lobe lobe = { .stream = DRIFT_STREAM_AAF_INDIRECT,
                            .buffers = &drift_aaf_of(f)->indirect,
                            .out = &f->indirect,
                            .shrink_from_spp = DRIFT_AAF_INDIRECT_SHRINK_SPP,
                            .shrink_exponent = DRIFT_AAF_INDIRECT_SHRINK_EXP,
                            .pixel_width = 1.0f / 0.15f,
                            .at = diffuse_at,
                            .sample = diffuse_sample };
    return drift_aaf_lobe_pass(f, &lobe);
}
